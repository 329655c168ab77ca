#!/usr/bin/env bash
# Memory and time footprint of every subcommand on long records (default 1 000 000 samples).
#
#   bench/footprint/run.sh [--samples N] [--yawcast PATH] [--work DIR] [--only LIST]
#                          [--timeout S]
#
#   --samples N      samples per record (default 1000000; ts = 1 s, so N seconds of sailing)
#   --yawcast PATH   the binary to measure (default: build the ci profile and use it)
#   --work DIR       where records and outputs go (default target/bench-footprint/N); records
#                    already there are reused
#   --only LIST      comma-separated subcommands to run (default: all); the model the
#                    others read is identified first whenever it is missing
#   --timeout S      stop a subcommand after S seconds (default 1800); it then fails, its
#                    peak memory up to then is still reported
#
# Records (built with `yawcast simulate`, seeds fixed, reused when present):
#   ref.csv            the clean built-in ship, PRBS input, N samples (seed 1)
#   half-1/2.csv       the same ship, N/2 samples each (seeds 2, 3): --data of average and tune
#   trial.csv          the ship with a dead time, N samples (seed 11)
#   trial-val.csv      the same, N samples (seed 12)
# Subcommands (each under /usr/bin/time -v; wall clock and peak RSS):
#   simulate  writes trial.csv once more (N samples)
#   identify  --data ref.csv (order 4)                      → model.{postcard,json}
#   average   --data half-1 half-2 --validate trial-val
#   tune      --data half-1 half-2 --validate trial-val --generations 2 (population 8,
#             the default) --centre zero
#   compare   --model model --data trial.csv
#   resid     --model model --data trial.csv
#   diagnose  --model model --data trial.csv --reference ref.csv (40 replicates, the default)
#   augment   --model model --effect dead-time --data trial.csv --validate trial-val.csv
#   export    --model model --data trial.csv
# Targets (set for 1 000 000 samples, applied as they are to any --samples): peak RSS
# ≤ 300 MB for every subcommand; diagnose ≤ 30 s.
#
# Prints a Markdown table; the raw `time -v` outputs stay in DIR/time/.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"

samples=1000000
yawcast=""
work=""
only=""
timeout_s=1800
while [[ $# -gt 0 ]]; do
    case "$1" in
        --samples) samples="$2"; shift 2 ;;
        --yawcast) yawcast="$2"; shift 2 ;;
        --work) work="$2"; shift 2 ;;
        --only) only="$2"; shift 2 ;;
        --timeout) timeout_s="$2"; shift 2 ;;
        -h|--help) sed -n '2,35p' "$0"; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
done
if ! [[ $samples =~ ^[0-9]+$ ]] || (( samples < 2000 )); then
    echo "run.sh: --samples must be a whole number ≥ 2000" >&2
    exit 2
fi
if [[ ! -x /usr/bin/time ]]; then
    echo "run.sh: /usr/bin/time is missing (apt-get install -y --no-install-recommends time)" >&2
    exit 1
fi

target_dir="${CARGO_TARGET_DIR:-$repo/target}"
if [[ -z $yawcast ]]; then
    echo "building the ci-profile binary..." >&2
    (cd "$repo" && cargo build -q --profile ci -p yawcast --bin yawcast)
    yawcast="$target_dir/ci/yawcast"
fi
[[ -x $yawcast ]] || { echo "run.sh: $yawcast is not an executable" >&2; exit 2; }
yawcast="$(realpath "$yawcast")"
work="${work:-$target_dir/bench-footprint/$samples}"
mkdir -p "$work/time" "$work/out"
cd "$work"

half=$(( samples / 2 ))
make_record() { # file samples seed [simulate flags…]
    local f="$1" n="$2" seed="$3"
    shift 3
    if [[ ! -s $f ]]; then
        echo "simulating $f ($n samples)..." >&2
        "$yawcast" simulate --duration "$n" --ts 1 --seed "$seed" --out "$f" "$@" \
            >"out/simulate-$f.log" 2>&1 || {
            echo "run.sh: simulating $f failed, see $work/out/simulate-$f.log" >&2
            exit 1
        }
    fi
}
make_record ref.csv "$samples" 1
make_record half-1.csv "$half" 2
make_record half-2.csv "$half" 3
make_record trial.csv "$samples" 11 --effect dead-time
make_record trial-val.csv "$samples" 12 --effect dead-time

wanted() { [[ -z $only ]] || [[ ",$only," == *",$1,"* ]]; }

rows=()
measure() { # name samples target_s command…
    local name="$1" n="$2" tmax="$3"
    shift 3
    local tf="time/$name.txt" log="out/$name.log"
    echo "running $name..." >&2
    local t0 t1 rc=0
    t0=$(date +%s.%N)
    /usr/bin/time -v -o "$tf" timeout "$timeout_s" "$@" >"$log" 2>&1 </dev/null || rc=$?
    t1=$(date +%s.%N)
    local wall rss mb verdict
    wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    rss=$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$tf")
    mb=$(awk -v k="${rss:-0}" 'BEGIN { printf "%.0f", k / 1024 }')
    verdict=PASS
    if (( rc == 124 )); then
        verdict="FAIL (stopped after $timeout_s s)"
    elif (( rc != 0 )); then
        verdict="FAIL (exit $rc, see $work/$log)"
    elif (( mb > 300 )); then
        verdict="FAIL (memory)"
    elif [[ $tmax != "—" ]] && awk -v w="$wall" -v m="$tmax" 'BEGIN { exit !(w > m) }'; then
        verdict="FAIL (time)"
    fi
    local tgt="≤ 300 MB"
    [[ $tmax != "—" ]] && tgt="≤ 300 MB, ≤ $tmax s"
    rows+=("| $name | $n | $wall | $mb | $tgt | $verdict |")
}

if wanted simulate; then
    measure simulate "$samples" — "$yawcast" simulate --duration "$samples" --ts 1 --seed 11 \
        --effect dead-time --out out/simulated.csv
fi
if wanted identify || [[ ! -s out/model.json ]]; then
    measure identify "$samples" — "$yawcast" identify --data ref.csv --out out/model
fi
if wanted average; then
    measure average "$samples" — "$yawcast" average --data half-1.csv --data half-2.csv \
        --validate trial-val.csv --out out/average
fi
if wanted tune; then
    measure tune "$samples" — "$yawcast" tune --data half-1.csv --data half-2.csv \
        --validate trial-val.csv --generations 2 --centre zero --seed 1 --out out/tuned
fi
if wanted compare; then
    measure compare "$samples" — "$yawcast" compare --model out/model.json --data trial.csv
fi
if wanted resid; then
    measure resid "$samples" — "$yawcast" resid --model out/model.json --data trial.csv
fi
if wanted diagnose; then
    measure diagnose "$samples" 30 "$yawcast" diagnose --model out/model.json --data trial.csv \
        --reference ref.csv --seed 1
fi
if wanted augment; then
    measure augment "$samples" — "$yawcast" augment --model out/model.json --effect dead-time \
        --data trial.csv --validate trial-val.csv --seed 1 --out out/augmented
fi
if wanted export; then
    measure export "$samples" — "$yawcast" export --model out/model.json --data trial.csv \
        --out out/exported
fi

load=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo "?")
echo "# footprint: $samples samples per record, $(nproc) cores, load $load," \
    "$(date -u +%Y-%m-%dT%H:%MZ), $(cd "$repo" && git rev-parse --short HEAD 2>/dev/null || echo '?')"
echo
echo "| subcommand | samples | wall s | peak RSS MB | target | result |"
echo "|---|---:|---:|---:|---|---|"
printf '%s\n' "${rows[@]}"
fail=0
for r in "${rows[@]}"; do [[ $r == *FAIL* ]] && fail=1; done
exit $fail
