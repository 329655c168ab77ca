#!/usr/bin/env bash
# Host identification benchmarks: PEM and the GA (criterion benches in host/benches/).
#
#   bench/host/run.sh           PEM (2 000 samples, order 4; against N = 500…8000), one GA
#                               generation, the full GA run (15 + 15 records × 1 800 samples,
#                               50 generations) and the GA against trials and record length
#                               and the simulator, diagnose and augment on 3 + 3 records
#   bench/host/run.sh --quick   the same with short measurement times
#
# Prints one line per figure; criterion's own reports land in target/criterion/.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$repo"

quick=0
for a in "$@"; do
    case "$a" in
        --quick) quick=1 ;;
        -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
        *) echo "run.sh: unknown option $a" >&2; exit 2 ;;
    esac
done

if [[ $quick == 1 ]]; then
    times=(--warm-up-time 1 --measurement-time 3)
    full=0
else
    times=(--warm-up-time 2 --measurement-time 10)
    full=1
fi

echo "# host benchmarks on $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ), $(git rev-parse --short HEAD)"

summarise() {
    # "pem/identify_n4_N2000  time: [a b c]" → "pem/identify_n4_N2000: b (a … c)"
    awk '
        /^[a-z_]+\/[^ ]+/ { name = $1 }
        /time:/ {
            line = $0; sub(/.*\[/, "", line); sub(/\].*/, "", line)
            split(line, v, " ")
            printf "%-40s %s %s  (%s %s … %s %s)\n", name, v[3], v[4], v[1], v[2], v[5], v[6]
        }
        /^pem n=4|^GA |^diagnose verdict/ { print }
    '
}

cargo bench -p yawcast --bench pem -- "${times[@]}" 2>&1 | summarise
YAWCAST_BENCH_FULL=$full cargo bench -p yawcast --bench ga -- "${times[@]}" 2>&1 | summarise
cargo bench -p yawcast --bench diagnose -- "${times[@]}" 2>&1 | summarise
