//! The report page as one self-contained HTML document: headings collected into a table of
//! contents, figures inline as `<svg>` elements, one style sheet in the head, no scripts, no
//! links to other files or to the network (only `#anchors` within the page).

use std::fmt::Write as _;

/// A figure of the report: an SVG drawn inline, with its caption.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Anchor of the figure within the page (letters, digits, `-`).
    pub id: String,
    /// Caption below the figure.
    pub caption: String,
    /// The SVG text (plotters' output).
    pub svg: String,
}

/// Text made safe inside HTML.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// An anchor made of `text`: ASCII letters and digits kept (lower case), everything else `-`.
pub(crate) fn anchor(text: &str) -> String {
    let mut a = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            a.push(c.to_ascii_lowercase());
        } else if !a.ends_with('-') {
            a.push('-');
        }
    }
    a.trim_matches('-').to_string()
}

/// The SVG text of `svg` made fit to stand inside HTML: the XML namespace declaration (an
/// `http:` address, and redundant in HTML) dropped, scaled to the page width by the style
/// sheet, and labelled for screen readers.
pub(crate) fn inline_svg(svg: &str, label: &str) -> String {
    let svg = svg.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1);
    svg.replacen(
        "<svg ",
        &format!(
            "<svg class=\"fig\" role=\"img\" aria-label=\"{}\" ",
            escape(label)
        ),
        1,
    )
}

/// The style sheet of the page.
const STYLE: &str = "body{font-family:sans-serif;margin:24px;color:#222;max-width:1400px}\
h1{font-size:26px;margin-bottom:6px}h2{font-size:21px;margin-top:36px;border-bottom:1px solid #ccc}\
h3{font-size:16px;margin-bottom:4px}h4{font-size:14px;margin-bottom:2px}\
table{border-collapse:collapse;margin:8px 0 16px 0;font-size:13px}\
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right;white-space:nowrap}\
th{background:#f0f0f0}td.l,th.l{text-align:left}td.w{white-space:normal;text-align:left;max-width:640px}\
table.head td,table.head th{border:none;padding:1px 10px 1px 0;text-align:left;white-space:normal}\
table.head th{background:none;white-space:nowrap;vertical-align:top}\
table.head{font-size:14px}\
figure{margin:8px 0 24px 0}figcaption{font-size:13px;color:#444}\
svg.fig{max-width:100%;height:auto;border:1px solid #ddd;display:block}\
.row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}\
.verdict{border:2px solid #888;padding:4px 14px;margin:10px 0;background:#fafafa}\
.verdict.v-ok{border-color:#2a7a2a}.verdict.v-weak{border-color:#c80}.verdict.v-bad{border-color:#b22}\
.ok{color:#1f6f1f}.weak{color:#a66a00}.bad{color:#b22;font-weight:bold}\
ul.warn li{color:#a33;font-size:13px;margin:3px 0}\
.warn{color:#a33;font-size:13px}\
nav.toc{font-size:14px;columns:2;border:1px solid #ddd;padding:6px 12px;margin:10px 0}\
nav.toc ul{margin:0;padding-left:18px}nav.toc li{break-inside:avoid}\
p.note{font-size:13px;color:#444}\
.badge{display:inline-block;padding:1px 8px;border-radius:3px;font-weight:bold;font-size:13px;color:#fff}\
.badge.v-pass{background:#1f6f1f}.badge.v-fail{background:#b22}.badge.v-none{background:#777}\
p.v-fail,li.v-fail{color:#b22}\
td.v-pass{background:#e3f1e3;color:#1f6f1f}td.v-fail{background:#f9e0e0;color:#b22;font-weight:bold}\
td.ns{color:#999}table.diag td small{color:#555}\
div.diag{margin:0 0 14px 0}p.diag-head{margin:4px 0;font-size:14px}\
ul.notes{font-size:12px;color:#444;margin:2px 0;padding-left:18px}\
.certificate{border:1px solid #bbb;padding:2px 14px 8px 14px;margin:14px 0}\
table.cert{font-size:12px}table.cert td,table.cert th{padding:2px 5px}\
p.cert-verdict{font-size:16px}p.sign{margin-top:18px;font-size:13px}\
table.history td.trend{padding:0}table.history svg.fig{border:none;width:280px}\
@page{size:A4;margin:12mm}\
@media print{body{margin:0;max-width:none;font-size:11px;-webkit-print-color-adjust:exact;print-color-adjust:exact}\
nav.toc{display:none}h2{margin-top:14px}figure,table,div.diag{break-inside:avoid}h2,h3,h4{break-after:avoid}\
.row{display:block}svg.fig{max-width:100%}\
.certificate{break-before:page;break-after:page;border:none;padding:0;margin:0}\
.certificate h2{font-size:17px;margin:0 0 4px 0}.certificate table.head{font-size:10px}\
.certificate p{margin:4px 0}.certificate p.note{font-size:9px}p.cert-verdict{font-size:13px}\
table.cert{font-size:9.5px;margin:4px 0 6px 0}table.cert td,table.cert th{padding:0 3px}\
table.cert td.w{max-width:260px}.certificate .badge{font-size:9px;padding:0 4px}}";

/// A page under construction: the body text and the headings for the table of contents.
#[derive(Debug, Default)]
pub(crate) struct Page {
    body: String,
    /// (level, anchor, title) of every h2 and h3.
    toc: Vec<(u8, String, String)>,
}

impl Page {
    /// A heading of `level` (2 or 3) with anchor `id`, listed in the table of contents.
    pub(crate) fn heading(&mut self, level: u8, id: &str, title: &str) {
        let _ = writeln!(
            self.body,
            "<h{level} id=\"{id}\">{}</h{level}>",
            escape(title)
        );
        self.toc.push((level, id.to_string(), title.to_string()));
    }

    /// Raw HTML appended to the body.
    pub(crate) fn push(&mut self, html: &str) {
        self.body.push_str(html);
    }

    /// A figure with its caption, the SVG inline.
    pub(crate) fn figure(&mut self, f: &Figure) {
        self.push(&figure_html(f));
    }

    /// A figure with `beside` (HTML, e.g. a table) to its right where the page is wide enough,
    /// else below it.
    pub(crate) fn figure_beside(&mut self, f: &Figure, beside: &str) {
        let width = svg_width(&f.svg).unwrap_or(800);
        let fig = figure_html(f).replacen(
            "<figure ",
            &format!("<figure style=\"flex:0 1 {width}px;min-width:0\" "),
            1,
        );
        self.push(&format!(
            "<div class=\"row\">{fig}<div style=\"flex:1 1 300px\">{beside}</div></div>\n"
        ));
    }

    /// The whole document: title, `header` (HTML), the table of contents, the body.
    pub(crate) fn finish(self, title: &str, header: &str) -> String {
        let mut h = String::new();
        let _ = writeln!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>",
            escape(title),
            escape(title)
        );
        h.push_str(header);
        let _ = writeln!(h, "<nav class=\"toc\"><b>Contents</b>\n<ul>");
        let link = |id: &str, title: &str| format!("<a href=\"#{id}\">{}</a>", escape(title));
        let mut i = 0;
        while i < self.toc.len() {
            let (_, id, title) = &self.toc[i];
            let _ = write!(h, "<li>{}", link(id, title));
            i += 1;
            let subs: Vec<String> = self.toc[i..]
                .iter()
                .take_while(|(level, _, _)| *level > 2)
                .map(|(_, id, title)| format!("<li>{}</li>", link(id, title)))
                .collect();
            if !subs.is_empty() {
                let _ = write!(h, "<ul>{}</ul>", subs.join(""));
            }
            i += subs.len();
            let _ = writeln!(h, "</li>");
        }
        let _ = writeln!(h, "</ul></nav>");
        h.push_str(&self.body);
        let _ = writeln!(h, "</body>\n</html>");
        h
    }
}

/// The `width` attribute of an SVG's root element, px.
fn svg_width(svg: &str) -> Option<u32> {
    let head = &svg[..svg.find('>')?];
    let rest = &head[head.find(" width=\"")? + 8..];
    rest[..rest.find('"')?].parse().ok()
}

/// A figure as HTML: the SVG inline, the caption below.
pub(crate) fn figure_html(f: &Figure) -> String {
    format!(
        "<figure id=\"{}\">{}<figcaption>{}</figcaption></figure>\n",
        f.id,
        inline_svg(&f.svg, &f.caption),
        escape(&f.caption)
    )
}
