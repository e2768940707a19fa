#!/usr/bin/env bash
# The demo's outputs of two builds of `eij`, times and dates masked, and where they differ.
#
#   scripts/demo-outputs-diff.sh BEFORE_REPO BEFORE_BIN AFTER_REPO AFTER_BIN [KEEP_DIR]
#
# Each build runs the bundled demo with the machine and measurements of its own checkout
# (BEFORE_REPO, AFTER_REPO: a commit's demo data are part of what it ships; give the same
# checkout twice to compare two builds on the same data):
#
#   identify   eij identify                                  console (stdout, stderr, exit code),
#                                                            out/demo-vmc-identified.toml,
#                                                            out/demo-vmc-identify-report.json
#   evaluate   eij evaluate measurements/demo-vmc/pos-a --json
#   report     eij report --measured measurements/demo-vmc
#                 --identify-report out/demo-vmc-identify-report.json --out out/report
#                                                            out/report/report.html
#
# Dates come from SOURCE_DATE_EPOCH; masked before comparing are ISO dates and times and
# identify's run time (`3 iterations, 0.2 s`), as in tests/outputs-equal.sh. For each file it
# prints `identical` or `differs`; for a differing file three views follow:
#   - JSON: keys only in one build, and the largest relative change of the numbers both have
#     (scripts/json-diff.py);
#   - the lines that differ once every number is replaced by `#` (what is not a number:
#     words, keys, layout), up to 40 lines;
#   - the number of lines that differ in numbers only.
# The masked files stay in KEEP_DIR (default: a temporary folder, removed) as before/ and
# after/ for a full `diff -u`. Exit 0 when every file is identical, 1 otherwise.
# docs/architecture-diff.md holds a run and explains each difference.
set -u
if [ $# -lt 4 ] || [ $# -gt 5 ]; then
    echo "usage: $0 BEFORE_REPO BEFORE_BIN AFTER_REPO AFTER_BIN [KEEP_DIR]" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
before_repo=$(realpath "$1")
before_bin=$(realpath "$2")
after_repo=$(realpath "$3")
after_bin=$(realpath "$4")
if [ $# -eq 5 ]; then
    work=$(realpath -m "$5")
    mkdir -p "$work"
else
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
fi

export SOURCE_DATE_EPOCH=1767225600

# Runs the demo with one build in $dir on the data of $repo.
run_demo() {
    local repo=$1 bin=$2 dir=$3
    rm -rf "$dir" && mkdir -p "$dir/run/out" "$dir/raw"
    ln -s "$repo/machines" "$repo/measurements" "$dir/run/"
    (
        cd "$dir/run" || exit 1
        "$bin" identify >../raw/identify.stdout 2>../raw/identify.stderr
        echo $? >../raw/identify.rc
        "$bin" evaluate measurements/demo-vmc/pos-a --json >../raw/evaluate.json 2>../raw/evaluate.stderr
        echo $? >../raw/evaluate.rc
        "$bin" report --measured measurements/demo-vmc \
            --identify-report out/demo-vmc-identify-report.json --out out/report \
            >../raw/report.stdout 2>../raw/report.stderr
        echo $? >../raw/report.rc
    )
    cp "$dir/run/out/demo-vmc-identified.toml" "$dir/run/out/demo-vmc-identify-report.json" \
        "$dir/raw/" 2>/dev/null
    cp "$dir/run/out/report/report.html" "$dir/raw/" 2>/dev/null
}

# Times and dates differ from run to run; nothing else may.
mask() {
    sed -E \
        -e 's/[0-9]{4}-[0-9]{2}-[0-9]{2}[T ][0-9]{2}:[0-9]{2}(:[0-9]{2}(\.[0-9]+)?)?(Z|[+-][0-9]{2}:?[0-9]{2})?( UTC)?/<date>/g' \
        -e 's/(iterations?), [0-9]+(\.[0-9]+)? s/\1, <time> s/g' \
        "$1"
}

# Every number (sign, digits, decimals, exponent) as `#`.
numbers_masked() {
    sed -E 's/(-|\+|−)?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?/#/g' "$1"
}

run_demo "$before_repo" "$before_bin" "$work/before"
run_demo "$after_repo" "$after_bin" "$work/after"

status=0
for side in before after; do
    mkdir -p "$work/$side/masked"
    for f in "$work/$side/raw/"*; do
        mask "$f" >"$work/$side/masked/$(basename "$f")"
    done
done
for f in "$work/before/masked/"* "$work/after/masked/"*; do
    name=$(basename "$f")
    printf '%s\n' "$name"
done | sort -u | while read -r name; do
    b=$work/before/masked/$name
    a=$work/after/masked/$name
    if [ ! -f "$a" ]; then
        echo "== $name: only BEFORE wrote it"
        continue
    elif [ ! -f "$b" ]; then
        echo "== $name: only AFTER wrote it"
        continue
    elif cmp -s "$b" "$a"; then
        echo "== $name: identical"
        continue
    fi
    echo "== $name: differs"
    case $name in
    *.json) python3 "$here/json-diff.py" "$b" "$a" ;;
    esac
    words=$(diff <(numbers_masked "$b") <(numbers_masked "$a"))
    if [ -n "$words" ]; then
        echo "   not numbers only (numbers as #):"
        printf '%s\n' "$words" | head -40 | cut -c1-300 | sed 's/^/     /'
    fi
    echo "   lines that differ: $(diff "$b" "$a" | grep -c '^<') in BEFORE," \
        "$(diff "$b" "$a" | grep -c '^>') in AFTER; with numbers as #:" \
        "$(printf '%s\n' "$words" | grep -c '^<') and $(printf '%s\n' "$words" | grep -c '^>')"
done | tee "$work/summary.txt"
grep -q ': differs\|only' "$work/summary.txt" && status=1
exit $status
