//! Plot helpers shared by the figures: the SVG canvas, a header with title and condition
//! lines, a side panel with legend and notes, the series colours and nice numbers.
//!
//! plotters runs without font libraries (no `ttf` feature): text sizes are estimated and the
//! viewer's sans-serif font draws the `<text>` elements.

use super::ReportError;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The drawing area type of every figure.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Set circle / set values (black).
pub const SET: RGBColor = RGBColor(0, 0, 0);
/// Internal measurement (the axes' own readings).
pub const INTERNAL: RGBColor = RGBColor(31, 119, 180);
/// External measurement (R-Test, TCP).
pub const EXTERNAL: RGBColor = RGBColor(214, 39, 40);
/// Ellipse fitted to the internal path.
pub const ELLIPSE_INT: RGBColor = RGBColor(23, 190, 207);
/// Ellipse fitted to the external path.
pub const ELLIPSE_EXT: RGBColor = RGBColor(255, 127, 14);
/// A fitted model curve (plane fit, final simulation).
pub const FIT: RGBColor = RGBColor(44, 160, 44);
/// A second deviation series (the other cross-talk axis).
pub const SECOND: RGBColor = RGBColor(148, 103, 189);
/// Simulation before identification.
pub(crate) const INITIAL: RGBColor = RGBColor(127, 127, 127);
/// Error bars (distinct from the black tick marks).
pub const ERROR_BAR: RGBColor = RGBColor(90, 90, 90);
/// Grid and frame.
const GRID: RGBColor = RGBColor(225, 225, 225);

/// Font family of all text.
pub(crate) const FONT: &str = "sans-serif";
/// Title size (plotters units; the SVG font-size is this / 1.24).
pub(crate) const TITLE_SIZE: f64 = 22.0;
/// Size of condition lines, legend, notes.
pub(crate) const TEXT_SIZE: f64 = 16.0;
/// Size of tick labels.
pub(crate) const LABEL_SIZE: f64 = 15.0;
/// Size of axis descriptions.
pub(crate) const DESC_SIZE: f64 = 16.0;

/// The colour as plotters writes it into `stroke`/`fill` attributes, e.g. `#D62728`.
pub fn svg_color(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for ReportError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        ReportError::Plot {
            figure: "figure".into(),
            message: e.to_string(),
        }
    }
}

/// Draws a figure of `size` pixels onto a white canvas and returns the SVG text.
pub fn render(
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> Result<(), ReportError>,
) -> Result<String, ReportError> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(buf)
}

/// Text style of a given size and colour.
pub fn text(size: f64, color: RGBColor) -> TextStyle<'static> {
    (FONT, size).into_font().color(&color)
}

/// Draws the title (bold) and condition lines at the top of `area`; returns the area below.
pub fn header<'a>(area: &Area<'a>, title: &str, lines: &[String]) -> Result<Area<'a>, ReportError> {
    let line_h = 22;
    let height = 16 + 30 + line_h * lines.len() as u32 + 6;
    let (top, rest) = area.split_vertically(height);
    top.draw(&Text::new(
        title.to_string(),
        (16, 12),
        (FONT, TITLE_SIZE).into_font().style(FontStyle::Bold),
    ))?;
    for (i, l) in lines.iter().enumerate() {
        top.draw(&Text::new(
            l.clone(),
            (16, 44 + line_h as i32 * i as i32),
            text(TEXT_SIZE, RGBColor(40, 40, 40)),
        ))?;
    }
    Ok(rest)
}

/// How a series appears in the legend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Mark {
    /// A line.
    Line,
    /// Filled dots.
    Dot,
    /// Hollow circles.
    Ring,
    /// A dot with an error bar.
    DotBar,
}

/// One legend line.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    /// Series label.
    pub label: String,
    /// Series colour.
    pub color: RGBColor,
    /// Symbol.
    pub mark: Mark,
}

impl Entry {
    /// A legend entry.
    pub(crate) fn new(label: impl Into<String>, color: RGBColor, mark: Mark) -> Self {
        Entry {
            label: label.into(),
            color,
            mark,
        }
    }
}

/// A legend (symbol + label per entry) and then note lines, top-left in `area`.
pub(crate) fn side_panel(
    area: &Area,
    legend: &[Entry],
    notes: &[String],
) -> Result<(), ReportError> {
    let x0 = 8;
    let mut y = 16;
    for e in legend {
        let cy = y + 8;
        match e.mark {
            Mark::Line => {
                area.draw(&PathElement::new(
                    vec![(x0, cy), (x0 + 28, cy)],
                    e.color.stroke_width(3),
                ))?;
            }
            Mark::Dot => {
                area.draw(&Circle::new((x0 + 14, cy), 4, e.color.filled()))?;
            }
            Mark::Ring => {
                area.draw(&Circle::new((x0 + 14, cy), 5, e.color.stroke_width(2)))?;
            }
            Mark::DotBar => {
                area.draw(&PathElement::new(
                    vec![(x0 + 14, cy - 8), (x0 + 14, cy + 8)],
                    ERROR_BAR.stroke_width(1),
                ))?;
                area.draw(&Circle::new((x0 + 14, cy), 4, e.color.filled()))?;
            }
        }
        area.draw(&Text::new(
            e.label.clone(),
            (x0 + 36, y),
            text(TEXT_SIZE, SET),
        ))?;
        y += 24;
    }
    y += 10;
    for n in notes {
        area.draw(&Text::new(n.clone(), (x0, y), text(TEXT_SIZE, SET)))?;
        y += 21;
    }
    Ok(())
}

/// The largest number of the 1-2-5 sequence not above `x` (x > 0).
pub(crate) fn nice_floor(x: f64) -> f64 {
    let decade = 10f64.powf(x.log10().floor());
    let m = x / decade;
    let step = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    step * decade
}

/// Decimals that resolve a tick step over `span`: about five ticks.
pub(crate) fn decimals_for(span: f64) -> usize {
    if !(span.is_finite() && span > 0.0) {
        return 1;
    }
    let step = nice_floor(span / 5.0);
    (-step.log10().floor()).clamp(0.0, 8.0) as usize
}

/// A padded range around the finite values of `values` (±1 around a single value).
pub(crate) fn padded_range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(1.0) {
        let d = if lo.abs() > 0.0 { 0.1 * lo.abs() } else { 1.0 };
        return (lo - d, hi + d);
    }
    (lo - pad * span, hi + pad * span)
}

/// Draws the mesh of a Cartesian chart with axis descriptions and `decimals`-digit labels.
pub fn mesh<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    x_desc: &str,
    y_desc: &str,
    x_decimals: usize,
    y_decimals: usize,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let xf = move |v: &f64| super::short(*v, x_decimals);
    let yf = move |v: &f64| super::short(*v, y_decimals);
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(GRID)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style((FONT, LABEL_SIZE))
        .axis_desc_style((FONT, DESC_SIZE))
        .draw()
}

/// Every `stride`-th index so that at most `max` points remain (the last index kept).
pub(crate) fn decimate(n: usize, max: usize) -> impl Iterator<Item = usize> {
    let stride = n.div_ceil(max.max(1)).max(1);
    (0..n)
        .step_by(stride)
        .chain((n > 0 && (n - 1) % stride != 0).then_some(n - 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_floor(48.0), 20.0);
        assert_eq!(nice_floor(50.0), 50.0);
        assert_eq!(nice_floor(0.7), 0.5);
        assert_eq!(nice_floor(1999.0), 1000.0);
        assert_eq!(decimate(10, 3).collect::<Vec<_>>(), vec![0, 4, 8, 9]);
        assert_eq!(decimate(3, 10).collect::<Vec<_>>(), vec![0, 1, 2]);
        assert_eq!(svg_color(EXTERNAL), "#D62728");
    }
}
