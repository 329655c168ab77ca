#!/usr/bin/env bash
# HSVA's free-running zig-zags of the 7 m KVLCC2 model (SIMMAN 2008) through `diagnose`.
#
#   bench/real/hsva.sh SOURCE_DIR [--yawcast PATH] [--work DIR] [--seeds N]
#
#   SOURCE_DIR        the 13 files HSVA_CPMC_KVLCC2_Z_*.dat (the raw_data folder of
#                     data/01_raw/kvlcc2_hsva in github.com/martinlarsalbert/
#                     System-identification-of-Vessel-Manoeuvring-Models, commit 4b7ce53;
#                     no licence is stated for the data, so yawcast does not ship them)
#   --yawcast PATH    the binary (default: build the release profile and use it)
#   --work DIR        records, models and diagnoses (default target/bench-hsva)
#   --seeds N         also diagnose case D under seeds 1…N (default 3)
#
# The records log the rudder's own angle (its gear slews at about 16 °/s at this scale;
# SIMMAN's 2.34 °/s at full scale) at 20 Hz; `kvlcc2_hsva.py` keeps every third row (Ts
# 0.15 s) and writes them twice: with the angle as `delta_deg` (angle/) and with the
# zig-zag's command reconstructed from it (command/). Cases:
#   A  reference: `simulate --world kvlcc2 --scale 7` (±10°, ±20°, ±30° zig-zags, 200 s,
#      Ts 0.15 s, seeds 1–3; commands through the simulator's gear); trials: the 13
#      records, angle
#   B  the same reference; trials: the 13 records, command
#   C  reference: 4 records (z10_05, z20_10_p, z30_05, z15_01), angle, the model identified
#      on the first three (the fourth validating); trials: the other 9, angle
#   D  the same reference (angle); trials: the other 9, command — the gear lies between
#      the two: a slew limit near the angle's largest rate is the physics to name
#   E  no reference (C's model); trials: the other 9, command
#   F  reference: A's simulator logging its gear's angle (`simulate --log-angle`);
#      trials: the 13 records, angle — the same signal in both
# Prints per case the verdict, the second effect, the slew limit's p and estimate, and the
# `command-steps`, `noise-gain`, `noisier-trials` and `quieter-trials` caveats' figures
# (`lib.sh`); DIR/summary.tsv holds the same.
set -euo pipefail
{
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
[ $# -ge 1 ] || { sed -n '2,31p' "$0"; exit 2; }
src="$1"; shift
yawcast=""
work="$repo/target/bench-hsva"
seeds=3
while [ $# -gt 0 ]; do
    case "$1" in
        --yawcast) yawcast="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --work) work="$2"; shift 2 ;;
        --seeds) seeds="$2"; shift 2 ;;
        *) echo "unknown argument $1" >&2; exit 2 ;;
    esac
done
# shellcheck source=bench/real/lib.sh
. "$repo/bench/real/lib.sh"
yawcast="$(yawcast_binary "$repo" "$yawcast")"
mkdir -p "$work/ref"
python3 "$repo/bench/real/kvlcc2_hsva.py" "$src" "$work/angle"
python3 "$repo/bench/real/kvlcc2_hsva.py" "$src" "$work/command" --command > /dev/null

# the simulator reference at the model's scale and speed
i=0
for z in 10/10 20/20 30/30; do
    i=$((i + 1))
    for log in command angle; do
        extra=()
        [ "$log" = angle ] && extra=(--log-angle)
        "$yawcast" simulate --world kvlcc2 --scale 7 --input "zigzag:$z" --duration 200 \
            --ts 0.15 --seed "$i" "${extra[@]}" --out "$work/ref/sim-$log-$i.csv" > /dev/null
    done
done
for log in command angle; do
    "$yawcast" identify --data "$work/ref/sim-$log-1.csv" --data "$work/ref/sim-$log-2.csv" \
        --validate "$work/ref/sim-$log-3.csv" --out "$work/ref/sim-$log" > /dev/null
done
refs=(z10_05 z20_10_p z30_05 z15_01)
trials=(z05_01 z10_01 z10_10_p z10_10_s z15_05 z20_05 z20_10_s z25_05 z35_05)
"$yawcast" identify --data "$work/angle/z10_05.csv" --data "$work/angle/z20_10_p.csv" \
    --data "$work/angle/z30_05.csv" --validate "$work/angle/z15_01.csv" \
    --out "$work/ref/records" > /dev/null

sim_ref=(--model "$work/ref/sim-command.postcard")
sim_angle=(--model "$work/ref/sim-angle.postcard")
for i in 1 2 3; do
    sim_ref+=(--reference "$work/ref/sim-command-$i.csv")
    sim_angle+=(--reference "$work/ref/sim-angle-$i.csv")
done
rec_ref=(--model "$work/ref/records.postcard")
for r in "${refs[@]}"; do rec_ref+=(--reference "$work/angle/$r.csv"); done
all=()
for f in "$work"/angle/z*.csv; do all+=("$(basename "$f" .csv)"); done
summary_header "$work/summary.tsv"
mapfile -t a < <(data "$work" angle "${all[@]}")
mapfile -t c < <(data "$work" command "${all[@]}")
mapfile -t ta < <(data "$work" angle "${trials[@]}")
mapfile -t tc < <(data "$work" command "${trials[@]}")
diag "$work" A data "${sim_ref[@]}" "${a[@]}"
diag "$work" B data "${sim_ref[@]}" "${c[@]}"
diag "$work" C data "${rec_ref[@]}" "${ta[@]}"
diag "$work" D data "${rec_ref[@]}" "${tc[@]}"
for s in $(seq 1 "$seeds"); do diag "$work" D "$s" "${rec_ref[@]}" "${tc[@]}"; done
diag "$work" E data --model "$work/ref/records.postcard" "${tc[@]}"
diag "$work" F data "${sim_angle[@]}" "${a[@]}"
column -t -s "$(printf '\t')" "$work/summary.tsv"
}
