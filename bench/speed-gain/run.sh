#!/usr/bin/env bash
# What a rudder effectiveness that grows with the square of the speed would win, measured
# before it is built: per world and seed, effect-free trials and a validation record are
# simulated as in bench/worlds/run.sh --won-back (3 PRBS trials of 1 800 s, seeds 100·s + 0…2;
# validation seed 100·s + 50 with the world's own 10-step predictor), and a linear model is
# identified on the trials twice: on the command as logged, and on the command scaled by
# (U/Ū)², U the logged speed over ground and Ū its mean over the trials. Both are scored at
# 1, 10 and 50 steps (`compare`) on the validation record, scaled the same way. The scaled
# command uses the speed `--lag` samples earlier (default 10), so a 10-step prediction needs
# no speed beyond its origin, as a predictor on the controller would have.
#
# A controller need not log the speed for this: in a turn the speed falls with the square of
# the yaw rate, through the surge's time constant. `--turn-tau LIST` adds, per time constant
# T (s), the command scaled the same way by a stand-in for the speed, Û = b₀ + b₁·s with s the
# yaw rate squared through a first-order lag of T (s(t) = a·s(t−1) + (1 − a)·r(t)², a =
# e^(−Ts/T), started at r(0)²) and b₀, b₁ fitted by least squares to the trials' logged speed
# (the stand-in for a gain the identification would estimate from the yaw rate alone).
#
#   bench/speed-gain/run.sh [--yawcast PATH] [--work DIR] [--worlds LIST] [--seeds N]
#                           [--lag K] [--turn-tau LIST]
#
# Prints one line per world and seed: the oracle's 10-step fit, then the fits (1/10/50
# steps) as logged and scaled, and the 10-step difference; with --turn-tau, per T the fits
# with the stand-in and their 10-step difference from the command as logged.
set -euo pipefail
{
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
yawcast=""
work="$repo/target/bench-speed-gain"
worlds="lng,kvlcc2,mariner"
seeds=3
lag=10
taus=""
while [ $# -gt 0 ]; do
    case "$1" in
        --yawcast) yawcast="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --work) work="$2"; shift 2 ;;
        --worlds) worlds="$2"; shift 2 ;;
        --seeds) seeds="$2"; shift 2 ;;
        --lag) lag="$2"; shift 2 ;;
        --turn-tau) taus="$2"; shift 2 ;;
        -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
        *) echo "unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$yawcast" ]; then
    (cd "$repo" && cargo build -q --profile ci -p yawcast)
    yawcast="${CARGO_TARGET_DIR:-$repo/target}/ci/yawcast"
fi
mkdir -p "$work"

# scale.py SRC DST U0 LAG: the command times (U(t − LAG)/U0)² (the first LAG samples use U(0))
scale='import csv, sys
src, dst, u0, lag = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
rows = list(csv.reader(open(src)))
h = rows[0]
iu, idl = h.index("u_mps"), h.index("delta_deg")
us = [float(r[iu]) for r in rows[1:]]
out = [h]
for t, r in enumerate(rows[1:]):
    r = list(r)
    r[idl] = repr(float(r[idl]) * (us[max(t - lag, 0)] / u0) ** 2)
    out.append(r)
csv.writer(open(dst + ".tmp", "w", newline="")).writerows(out)
import os
os.replace(dst + ".tmp", dst)'
# the command scaled by the stand-in, fitted on the trials (bench/speed-gain/turn.py)
turn="$repo/bench/speed-gain/turn.py"
mean_u='import csv, sys
us = [float(r["u_mps"]) for f in sys.argv[1:] for r in csv.DictReader(open(f))]
print(sum(us) / len(us))'
fits='import json, sys
f = json.load(open(sys.argv[1]))["records"][0]["fit"]
print("/".join(f"{f[k]:.2f}" for k in ("1", "10", "50")))'

IFS=, read -r -a tau_list <<<"$taus"
head='| world | seed | oracle 10 | as logged 1/10/50 | scaled by (U/Ū)² 1/10/50 | Δ 10 steps (pp) |'
rule='|---|---|---|---|---|---|'
for T in "${tau_list[@]}"; do
    head="$head by the turn, T = $T s 1/10/50 | Δ 10 steps (pp) |"
    rule="$rule---|---|"
done
printf '%s\n%s\n' "$head" "$rule"
IFS=, read -r -a world_list <<<"$worlds"
for w in "${world_list[@]}"; do
    for s in $(seq 1 "$seeds"); do
        d="$work/$w-$s"
        mkdir -p "$d"
        "$yawcast" simulate --world "$w" --records 3 --seed $((100 * s)) --input prbs \
            --gyro-noise 0.03 --heading-noise 0.2 --speed-noise 0.02 --out "$d/trial.csv" \
            >"$d/log" 2>&1
        "$yawcast" simulate --world "$w" --records 1 --seed $((100 * s + 50)) --input prbs \
            --gyro-noise 0.03 --heading-noise 0.2 --speed-noise 0.02 --oracle-horizon 10 \
            --out "$d/val.csv" --json "$d/val.json" >>"$d/log" 2>&1
        oracle=$(python3 -c 'import json,sys
o = json.load(open(sys.argv[1]))["records"][0]["oracle_fit_pct"]
print(f"{o:.2f}")' "$d/val.json")
        u0=$(python3 -c "$mean_u" "$d"/trial-[123].csv)
        for f in trial-1 trial-2 trial-3 val; do
            python3 -c "$scale" "$d/$f.csv" "$d/$f-scaled.csv" "$u0" "$lag"
        done
        for v in "" "-scaled"; do
            "$yawcast" identify --data "$d/trial-1$v.csv" --data "$d/trial-2$v.csv" \
                --data "$d/trial-3$v.csv" --out "$d/model$v" >>"$d/log" 2>&1
            "$yawcast" compare --model "$d/model$v.postcard" --data "$d/val$v.csv" \
                --horizons 1,10,50 --json "$d/fit$v.json" >>"$d/log" 2>&1
        done
        a=$(python3 -c "$fits" "$d/fit.json")
        b=$(python3 -c "$fits" "$d/fit-scaled.json")
        diff=$(python3 -c 'import sys
a, b = (float(x.split("/")[1]) for x in sys.argv[1:3])
print(f"{b - a:+.2f}")' "$a" "$b")
        line="| $w | $s | $oracle | $a | $b | $diff |"
        for T in "${tau_list[@]}"; do
            python3 "$turn" "$T" "$lag" "-turn$T" "$d"/trial-[123].csv -- "$d"/trial-[123].csv \
                "$d/val.csv"
            "$yawcast" identify --data "$d/trial-1-turn$T.csv" --data "$d/trial-2-turn$T.csv" \
                --data "$d/trial-3-turn$T.csv" --out "$d/model-turn$T" >>"$d/log" 2>&1
            "$yawcast" compare --model "$d/model-turn$T.postcard" --data "$d/val-turn$T.csv" \
                --horizons 1,10,50 --json "$d/fit-turn$T.json" >>"$d/log" 2>&1
            c=$(python3 -c "$fits" "$d/fit-turn$T.json")
            dc=$(python3 -c 'import sys
a, b = (float(x.split("/")[1]) for x in sys.argv[1:3])
print(f"{b - a:+.2f}")' "$a" "$c")
            line="$line $c | $dc |"
        done
        printf '%s\n' "$line"
    done
done
exit 0
}
