#!/usr/bin/env bash
# CPU time of one eij command for two builds, run alternately (B A, A B, …) so that a drift of
# the machine's load falls on both alike; each build in a scratch folder holding the machines/
# and measurements/ of its own checkout. Prints each run (build, load average, CPU ms) and the
# median and range per build.
#
#   scripts/cpu-alternate.sh RUNS BEFORE_REPO BEFORE_BIN AFTER_REPO AFTER_BIN ARGS…
#   e.g. scripts/cpu-alternate.sh 6 ../before ../before/target/release/eij . target/release/eij identify --quiet
#
# CPU time is `perf stat -e task-clock` (all threads), less sensitive to other processes than
# wall time on a loaded machine.
set -u
if [ $# -lt 6 ]; then
    echo "usage: $0 RUNS BEFORE_REPO BEFORE_BIN AFTER_REPO AFTER_BIN ARGS…" >&2
    exit 2
fi
runs=$1
before_bin=$(realpath "$3") after_bin=$(realpath "$5")
scratch() {
    local d
    d=$(mktemp -d)
    ln -s "$(realpath "$1")/machines" "$(realpath "$1")/measurements" "$d/"
    mkdir "$d/out"
    echo "$d"
}
before_dir=$(scratch "$2")
after_dir=$(scratch "$4")
shift 5
log=$(mktemp)
trap 'rm -rf "$before_dir" "$after_dir" "$log"' EXIT
one() {
    local side=$1 bin=$2 dir=$3 load ms
    shift 3
    load=$(cut -d' ' -f1 /proc/loadavg)
    ms=$(cd "$dir" && perf stat -x, -e task-clock "$bin" "$@" 2>&1 >/dev/null | grep task-clock | cut -d, -f1)
    printf '%s\t%s\t%s\n' "$side" "$load" "$ms"
}
for r in $(seq 1 "$runs"); do
    if [ $((r % 2)) -eq 1 ]; then
        one BEFORE "$before_bin" "$before_dir" "$@"; one AFTER "$after_bin" "$after_dir" "$@"
    else
        one AFTER "$after_bin" "$after_dir" "$@"; one BEFORE "$before_bin" "$before_dir" "$@"
    fi
done | tee "$log"
python3 - "$log" <<'PY'
import statistics, sys
runs = {}
for line in open(sys.argv[1]):
    side, load, ms = line.split()
    runs.setdefault(side, []).append(float(ms))
for side, v in sorted(runs.items()):
    print(f"  {side:6} median {statistics.median(v):.0f} ms CPU of {len(v)} (range {min(v):.0f}–{max(v):.0f})")
PY
