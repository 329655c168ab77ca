#!/usr/bin/env bash
# MARIN's free-running records of the KVLCC2 (SIMMAN 2008, given at full scale) through
# `diagnose`, against a simulator of the hull and against HSVA's records of the same hull.
#
#   bench/real/marin.sh MARIN_DIR HSVA_DIR [--yawcast PATH] [--work DIR]
#
#   MARIN_DIR         the 6 files MARIN_FREE_KVLCC2_*_m.dat (data/01_raw/kvlcc2 in
#                     github.com/martinlarsalbert/System-identification-of-Vessel-
#                     Manoeuvring-Models, commit 4b7ce53)
#   HSVA_DIR          the 13 files HSVA_CPMC_KVLCC2_Z_*.dat of the same repository
#                     (data/01_raw/kvlcc2_hsva/raw_data); no licence is stated for either
#                     set, so yawcast does not ship them
#   --yawcast PATH    the binary (default: build the release profile and use it)
#   --work DIR        records, models and diagnoses (default target/bench-marin)
#
# MARIN's 4 zig-zags (±10°, ±20°, each starting to either side, 520–684 s) log the rudder's
# own angle, which its gear moves at up to 2.7–3.0 °/s (SIMMAN gives 2.34 °/s). They are
# kept at every 5th row (Ts 0.676 s), with the angle as `delta_deg` (angle/) and with the
# command rebuilt from it (command/). HSVA's 13 zig-zags of the 7 m model, Froude-scaled to
# the ship and kept at every 2nd row, sample the same (hsva/). Cases:
#   A  reference: `simulate --world kvlcc2` (±10°, ±20°, ±15° zig-zags, 700 s, seeds 1–3,
#      the model identified on the first two; commands through the simulator's gear);
#      trials: the 4 records, angle
#   B  the same reference; trials: the 4 records, command
#   F  reference: A's simulator logging its gear's angle (`simulate --log-angle`); trials:
#      the 4 records, angle — the same signal in both
#   G  reference: 4 of HSVA's records (z10_05, z20_10_p, z30_05, z15_01), angle, the model
#      identified on the first three; trials: MARIN's 4, angle — the same hull in another
#      tank: nothing is missing
#   H  the same reference; trials: MARIN's 4, command — the gear lies between the two
#   I  G's reference with its yaw rate written to 3 significant figures, as MARIN's, and
#      the model identified on it; trials: MARIN's 4, angle — identified on records as
#      fine as the trials', the model's Kalman gain no longer carries their noise 1 661
#      times over into its 10-step prediction (where the trials are noisier than the
#      reference, diagnose gives the reference their noise and re-fits the gain: caveat
#      `noisier-trials` in G and H; `noise-gain` where it could not)
# Prints per case the verdict, the second effect, the slew limit's p and estimate, and the
# `command-steps`, `noise-gain`, `noisier-trials` and `quieter-trials` caveats' figures
# (`lib.sh`); DIR/summary.tsv holds the same.
set -euo pipefail
{
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
[ $# -ge 2 ] || { sed -n '2,39p' "$0"; exit 2; }
marin="$1"; hsva="$2"; shift 2
yawcast=""
work="$repo/target/bench-marin"
while [ $# -gt 0 ]; do
    case "$1" in
        --yawcast) yawcast="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --work) work="$2"; shift 2 ;;
        *) echo "unknown argument $1" >&2; exit 2 ;;
    esac
done
# shellcheck source=bench/real/lib.sh
. "$repo/bench/real/lib.sh"
yawcast="$(yawcast_binary "$repo" "$yawcast")"
mkdir -p "$work/ref"
python3 "$repo/bench/real/kvlcc2_marin.py" "$marin" "$work/angle"
python3 "$repo/bench/real/kvlcc2_marin.py" "$marin" "$work/command" --command > /dev/null
python3 "$repo/bench/real/kvlcc2_hsva.py" "$hsva" "$work/hsva" --every 2 --froude 45.7 > /dev/null
python3 "$repo/bench/real/kvlcc2_hsva.py" "$hsva" "$work/hsva3" --every 2 --froude 45.7 \
    --rate-digits 3 > /dev/null

ts=$(sed -n 3p "$work/angle/zz10.csv" | cut -d, -f1)
i=0
for z in 10/10 20/20 15/15; do
    i=$((i + 1))
    for log in command angle; do
        extra=()
        [ "$log" = angle ] && extra=(--log-angle)
        "$yawcast" simulate --world kvlcc2 --input "zigzag:$z" --duration 700 --ts "$ts" \
            --seed "$i" "${extra[@]}" --out "$work/ref/sim-$log-$i.csv" > /dev/null
    done
done
for log in command angle; do
    "$yawcast" identify --data "$work/ref/sim-$log-1.csv" --data "$work/ref/sim-$log-2.csv" \
        --validate "$work/ref/sim-$log-3.csv" --out "$work/ref/sim-$log" > /dev/null
done
refs=(z10_05 z20_10_p z30_05 z15_01)
for h in hsva hsva3; do
    "$yawcast" identify --data "$work/$h/z10_05.csv" --data "$work/$h/z20_10_p.csv" \
        --data "$work/$h/z30_05.csv" --validate "$work/$h/z15_01.csv" \
        --out "$work/ref/$h" > /dev/null
done

sim_ref=(--model "$work/ref/sim-command.postcard")
sim_angle=(--model "$work/ref/sim-angle.postcard")
for i in 1 2 3; do
    sim_ref+=(--reference "$work/ref/sim-command-$i.csv")
    sim_angle+=(--reference "$work/ref/sim-angle-$i.csv")
done
hsva_ref=(--model "$work/ref/hsva.postcard")
hsva3_ref=(--model "$work/ref/hsva3.postcard")
for r in "${refs[@]}"; do
    hsva_ref+=(--reference "$work/hsva/$r.csv")
    hsva3_ref+=(--reference "$work/hsva3/$r.csv")
done
trials=(zz10 zz-10 zz20 zz-20)
summary_header "$work/summary.tsv"
mapfile -t a < <(data "$work" angle "${trials[@]}")
mapfile -t c < <(data "$work" command "${trials[@]}")
diag "$work" A data "${sim_ref[@]}" "${a[@]}"
diag "$work" B data "${sim_ref[@]}" "${c[@]}"
diag "$work" F data "${sim_angle[@]}" "${a[@]}"
diag "$work" G data "${hsva_ref[@]}" "${a[@]}"
diag "$work" H data "${hsva_ref[@]}" "${c[@]}"
diag "$work" I data "${hsva3_ref[@]}" "${a[@]}"
column -t -s "$(printf '\t')" "$work/summary.tsv"
}
