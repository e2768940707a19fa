#!/usr/bin/env bash
# Byte-compares what two builds of `eij` write for every command on the bundled demo data,
# times and dates masked: the check that a refactoring left behaviour unchanged.
#
#   tests/outputs-equal.sh BEFORE_BIN AFTER_BIN
#
# e.g. build main first and keep its binary:
#   git stash; cargo build --release; cp target/release/eij /tmp/eij-before; git stash pop
#   cargo build --release; tests/outputs-equal.sh /tmp/eij-before target/release/eij
#
# Each build runs in its own folder holding links to machines/, measurements/ and tests/, so
# both write the same relative paths. Standard output, standard error, the exit code and every
# file written are compared. Dates come from SOURCE_DATE_EPOCH; masked before comparing are ISO
# dates and times all the same and identify's run time (`3 iterations, 0.1 s`). Exit 0 when all equal;
# otherwise the differing files are listed with a unified diff of the first few lines.
set -u
if [ $# -ne 2 ]; then
    echo "usage: $0 BEFORE_BIN AFTER_BIN" >&2
    exit 2
fi
repo=$(cd "$(dirname "$0")/.." && pwd)
before=$(realpath "$1")
after=$(realpath "$2")
work=$(mktemp -d)
[ -n "${KEEP:-}" ] || trap 'rm -rf "$work"' EXIT

# One line per command: a name (the folder of its outputs) and the arguments.
commands=(
    "identify|identify --out out/id.toml --report out/id.json --stiffness-out out/id-stiffness.csv --plot out/id.svg --tables"
    "identify-time|identify --solver time --param z.guideway_normal --param z.guideway_lateral --measured measurements/demo-vmc/pos-a --report out/idt.json --out out/idt.toml"
    "identify-nm|identify --method nelder-mead --param y.guideway_normal --measured measurements/demo-vmc/pos-b --report out/idnm.json --out out/idnm.toml --quiet"
    "identify-table|identify --measured measurements/paper/eij_table.csv --param x.guideway_normal --report out/idp.json --out out/idp.toml"
    "evaluate|evaluate measurements/demo-vmc/pos-a measurements/demo-vmc/pos-b --csv-out out/eij.csv"
    "evaluate-json|evaluate measurements/demo-vmc/pos-a measurements/demo-vmc/pos-b --json"
    "evaluate-pooled|evaluate measurements/demo-vmc/pos-a/xy_c*.csv --pooled --json"
    "evaluate-pooled-table|evaluate measurements/demo-vmc/pos-b/zx_c*.csv --pooled"
    "evaluate-offset|evaluate measurements/demo-vmc/pos-b/zx_cw_8.csv --fit-time-offset --radius-mm 2 --json"
    "evaluate-plot|evaluate measurements/demo-vmc/pos-a/xy_ccw_5.csv --plot out/circle.svg"
    "bad-evaluate|evaluate measurements/paper/eij_table.csv --json"
    "bad-identify|identify --machine measurements/demo-vmc/pos-a/rtest.toml"
    "bad-conditions|evaluate bad/folder"
    "bad-conditions-identify|identify --measured bad/folder"
    "bad-table|identify --measured bad/table.csv"
    "bad-number|evaluate bad/number.csv"
    "simulate-circle|simulate circle --machine machines/demo-vmc.toml --out out/c.csv --plane zx --radius-mm 2 --accel-m-s2 5 --direction ccw --noise-um 1.4 --plot out/c.svg"
    "simulate-move|simulate move --machine machines/demo-vmc.toml --out out/m.csv --axis y --distance-mm 100 --feed-mm-min 20000 --accel-m-s2 4 --jerk-m-s3 100 --plot out/m.svg"
    "modal|modal --machine machines/demo-vmc.toml --json"
    "modal-table|modal --machine machines/demo-vmc.toml --position-mm 100,50,-20"
    "export|export --machine machines/demo-vmc.toml --out out/export.json"
    "stiffness|stiffness --machine machines/demo-vmc.toml"
    "map|map --machine machines/demo-vmc.toml --plane xy --accel-m-s2 5 --grid x=-200:200:3 --out out/map.csv --plot out/map.svg"
    "verify|verify"
)
# Commands that read what an earlier one wrote (run after it, in the same folder).
followers=(
    "compensation|compensation --machine out/id.toml --out out/comp.csv --points 3"
    "evaluate-move|evaluate-move out/m.csv --axis y --json"
    "report|report --measured measurements/demo-vmc/pos-a --identify-report out/id.json --move out/m.csv --map out/map.csv --out out/report"
    "simulate-comp|simulate circle --machine out/id.toml --compensation out/comp.csv --out out/cc.csv --plane xy --radius-mm 2 --accel-m-s2 5 --direction cw"
)

export SOURCE_DATE_EPOCH=1767225600
run_all() {
    local bin=$1 dir=$2
    mkdir -p "$dir/out"
    ln -s "$repo/machines" "$repo/measurements" "$dir/"
    mkdir -p "$dir/tests" && ln -s "$repo/tests/known-good" "$dir/tests/known-good"
    # Broken inputs: their error lines are outputs too.
    mkdir -p "$dir/bad/folder"
    cp "$repo/measurements/demo-vmc/pos-a/xy_ccw_2.csv" "$dir/bad/folder/"
    printf 'radius_mm = 2.0\nposition_mm = [150.0, -100.0]\nspeed = 3\n' >"$dir/bad/folder/rtest.toml"
    sed '2s/,[0-9.-]*$/,x/' "$repo/measurements/paper/eij_table.csv" >"$dir/bad/table.csv"
    sed '5s/^[0-9.]*,/0.0.1,/' "$repo/measurements/demo-vmc/pos-a/xy_ccw_2.csv" >"$dir/bad/number.csv"
    local entry name args
    for entry in "${commands[@]}" "${followers[@]}"; do
        name=${entry%%|*}
        args=${entry#*|}
        # shellcheck disable=SC2086 # the argument lists above are meant to be split
        (cd "$dir" && "$bin" $args >"out/$name.stdout" 2>"out/$name.stderr"; echo $? >"out/$name.rc")
    done
}

# Times and dates differ from run to run; nothing else may.
mask() {
    sed -E \
        -e 's/[0-9]{4}-[0-9]{2}-[0-9]{2}[T ][0-9]{2}:[0-9]{2}(:[0-9]{2}(\.[0-9]+)?)?(Z|[+-][0-9]{2}:?[0-9]{2})?( UTC)?/<date>/g' \
        -e 's/(iterations?), [0-9]+(\.[0-9]+)? s/\1, <time> s/g' \
        "$1"
}

run_all "$before" "$work/before"
run_all "$after" "$work/after"

status=0
count=0
while IFS= read -r -d '' file; do
    rel=${file#"$work/before/"}
    count=$((count + 1))
    if [ ! -f "$work/after/$rel" ]; then
        echo "only in BEFORE: $rel"
        status=1
    elif ! cmp -s <(mask "$file") <(mask "$work/after/$rel"); then
        echo "differs: $rel"
        diff -u <(mask "$file") <(mask "$work/after/$rel") | head -20
        status=1
    fi
done < <(find "$work/before/out" -type f -print0 | sort -z)
while IFS= read -r -d '' file; do
    rel=${file#"$work/after/"}
    [ -f "$work/before/$rel" ] || { echo "only in AFTER: $rel"; status=1; }
done < <(find "$work/after/out" -type f -print0 | sort -z)
if [ $status -eq 0 ]; then
    echo "outputs equal: $count files of ${#commands[@]}+${#followers[@]} commands (times and dates masked)"
fi
exit $status
