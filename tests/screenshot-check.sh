#!/usr/bin/env bash
# Screen check of a report page (docs/report.md, "Looking at the page"): headless Chromium shows
# the page's top as a browser does on screen (1400 × 1100 px), and then each figure of the page
# alone, under the page's own style sheet at the page's width, one PNG each, to look at: labels
# must not overlap traces or each other. (Headless Chromium does not scroll to an anchor before
# its screenshot, hence one small page per figure.) Needs chromium and python3.
#
#   bash tests/screenshot-check.sh out/report/report.html [WORK_DIR]
set -euo pipefail
html=${1:?usage: tests/screenshot-check.sh REPORT.html [WORK_DIR]}
work=${2:-$(mktemp -d)}
mkdir -p "$work/pages"
shot() { # PAGE PNG
  chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1400,1100 \
    --screenshot="$2" "file://$(cd "$(dirname "$1")" && pwd)/$(basename "$1")" >/dev/null 2>&1
  [ -s "$2" ] || { echo "screenshot-check: no picture of $1"; exit 1; }
}
shot "$html" "$work/page-top.png"
python3 - "$html" "$work/pages" <<'PY'
import re, sys
page = open(sys.argv[1], encoding="utf-8").read()
style = re.search(r"<style>.*?</style>", page, re.S).group(0)
for m in re.finditer(r'<figure[^>]* id="([^"]+)"', page):
    end = page.index("</figure>", m.start()) + len("</figure>")
    with open(f"{sys.argv[2]}/{m.group(1)}.html", "w", encoding="utf-8") as f:
        f.write(f'<!DOCTYPE html><html><head><meta charset="utf-8">{style}</head>'
                f"<body>{page[m.start():end]}</body></html>")
PY
n=0
for p in "$work"/pages/*.html; do
  shot "$p" "$work/$(basename "$p" .html).png"
  n=$((n + 1))
done
[ "$n" -gt 0 ] || { echo "screenshot-check: no figure in $html"; exit 1; }
echo "screenshot-check: the top and $n figures of $html, pictures in $work"
