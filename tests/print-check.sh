#!/usr/bin/env bash
# Print check of a report's certificate (docs/diagnosis.md, "The report"): headless Chromium
# prints report.html to PDF under the page's own print style sheet (@page A4); the certificate
# must start and end on one A4 page. Writes that page as a PNG beside the PDF, to look at
# (labels must not overlap). Needs chromium and poppler-utils (pdftotext, pdfinfo, pdftoppm).
#
#   bash tests/print-check.sh out/report/report.html [WORK_DIR]
set -euo pipefail
html=${1:?usage: tests/print-check.sh REPORT.html [WORK_DIR]}
work=${2:-$(mktemp -d)}
mkdir -p "$work"
chromium --headless --no-sandbox --disable-gpu --no-pdf-header-footer \
  --print-to-pdf="$work/report.pdf" "$html" 2>/dev/null
size=$(pdfinfo "$work/report.pdf" | sed -n 's/^Page size: *//p')
pages=$(pdfinfo "$work/report.pdf" | sed -n 's/^Pages: *//p')
case $size in *"(A4)"*) ;; *) echo "print-check: page size $size, expected A4"; exit 1 ;; esac
pdftotext -layout "$work/report.pdf" "$work/report.txt"
read -r start end < <(awk 'BEGIN { RS = "\f" }
  /Certificate of the circle tests/ && !s { s = NR }
  /End of certificate\./ && !e { e = NR }
  END { print s + 0, e + 0 }' "$work/report.txt")
if [ "$start" -eq 0 ] || [ "$end" -eq 0 ]; then
  echo "print-check: no certificate in $html"; exit 1
fi
if [ "$start" -ne "$end" ]; then
  echo "print-check: the certificate runs from page $start to page $end of $pages"; exit 1
fi
pdftoppm -f "$start" -l "$start" -r 110 -png "$work/report.pdf" "$work/certificate"
echo "print-check: certificate on page $start of $pages (A4), picture: $(ls "$work"/certificate*.png)"
