#!/usr/bin/env bash
# Two builds' criterion bench executables run back to back, alternating, so that a drift of
# the machine's load falls on both alike; prints each run's point estimates with the load
# average at its start, and the medians per build and bench.
#
#   scripts/bench-alternate.sh ROUNDS FILTER BEFORE_BENCH AFTER_BENCH
#
# BEFORE_BENCH, AFTER_BENCH: the bench executables (`cargo bench --bench identification
# --no-run` prints where it wrote one; they read the demo files of the checkout they were built
# in). FILTER: criterion's filter (a regular expression on the bench names). Each round runs
# BEFORE then AFTER, the next round AFTER then BEFORE. Criterion's options: 10 samples (the
# bench's own), 2 s warm-up, 5 s measurement.
set -u
if [ $# -ne 4 ]; then
    echo "usage: $0 ROUNDS FILTER BEFORE_BENCH AFTER_BENCH" >&2
    exit 2
fi
rounds=$1 filter=$2 before=$3 after=$4
log=$(mktemp)
trap 'rm -f "$log"' EXIT
one() {
    local side=$1 exe=$2 load
    load=$(cut -d' ' -f1 /proc/loadavg)
    # criterion prints `name  time: [low estimate high]`, the name on its own line when long.
    "$exe" --bench --warm-up-time 2 --measurement-time 5 "$filter" 2>/dev/null |
        awk -v side="$side" -v load="$load" '
            /time:/ { sub(/^ */, ""); if ($1 != "time:") { name = $0; sub(/ *time:.*/, "", name) }
                      split($0, p, "["); split(p[2], v, " "); print side "\t" load "\t" name "\t" v[3] " " v[4] }
            !/time:/ && NF > 0 && !/^(Benchmarking|Found|Warning|  )/ { name = $0 }'
}
for r in $(seq 1 "$rounds"); do
    if [ $((r % 2)) -eq 1 ]; then
        one BEFORE "$before"; one AFTER "$after"
    else
        one AFTER "$after"; one BEFORE "$before"
    fi
done | tee "$log"
echo "medians:"
python3 - "$log" <<'PY'
import statistics, sys
scale = {"ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
runs = {}
for line in open(sys.argv[1]):
    side, load, name, est = line.rstrip("\n").split("\t")
    value, unit = est.split()
    runs.setdefault((name, side), []).append((float(value) * scale[unit], float(load)))
for (name, side), vals in sorted(runs.items()):
    times = [t for t, _ in vals]
    loads = [l for _, l in vals]
    print(f"  {side:6} {name}: median {statistics.median(times) * 1e3:.1f} ms of {len(times)}"
          f" (range {min(times) * 1e3:.1f}–{max(times) * 1e3:.1f} ms; load {min(loads)}–{max(loads)})")
PY
