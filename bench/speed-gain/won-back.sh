#!/usr/bin/env bash
# What the speed lost in turns would add to the error won back, measured before it is built:
# on the records of a `bench/worlds/run.sh --won-back` run, every effect case's reference,
# trials and validation record get the command scaled by a stand-in for the speed from the
# turn (as `run.sh --turn-tau`: Û = b₀ + b₁·s, s the yaw rate squared through a first-order
# lag of T seconds, b₀ and b₁ fitted to the logged speed of the reference records for them,
# of the trials for the trials and the validation record; the speed `--lag` samples
# earlier). The reference model is identified again on the scaled reference, `augment
# --effect auto` runs on the scaled records from it, and its model is scored at 10 steps on
# the scaled validation record. The oracle and the best linear model are the run's own, on
# the records as logged, so the figure is `run.sh`'s won back with the stand-in added to
# the augmented model: (augmented − linear) / (oracle − linear), over the cases where the
# linear model is ≥ 3 pp below the oracle.
#
#   bench/speed-gain/won-back.sh --runs DIR [--yawcast PATH] [--worlds LIST]
#                                [--turn-tau T] [--lag K] [--jobs N]
#
# DIR is the `--work` of a `run.sh --won-back` run. Prints one line per case (world,
# effect, strength, seed, oracle, linear, augmented as run, augmented with the stand-in,
# both won back) and the median per world and strength of both.
set -euo pipefail
{
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
yawcast=""
runs=""
worlds=""
tau=100
lag=10
jobs=2
while [ $# -gt 0 ]; do
    case "$1" in
        --runs) runs="$(cd "$2" && pwd)"; shift 2 ;;
        --yawcast) yawcast="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --worlds) worlds="$2"; shift 2 ;;
        --turn-tau) tau="$2"; shift 2 ;;
        --lag) lag="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
        *) echo "unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$runs" ]; then echo "--runs DIR is needed (see --help)" >&2; exit 2; fi
if [ -z "$yawcast" ]; then
    (cd "$repo" && cargo build -q --profile ci -p yawcast)
    yawcast="${CARGO_TARGET_DIR:-$repo/target}/ci/yawcast"
fi
if [ -z "$worlds" ]; then
    worlds=$(find "$runs" -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort | paste -sd,)
fi

turn="$repo/bench/speed-gain/turn.py"
export YAWCAST="$yawcast" RUNS="$runs" TAU="$tau" LAG="$lag" TURN="$turn"

IFS=, read -r -a world_list <<<"$worlds"
for w in "${world_list[@]}"; do
    d="$runs/$w"
    python3 "$turn" "$tau" "$lag" "-turn$tau" "$d"/ref-[123].csv -- "$d"/ref-[123].csv
    "$yawcast" identify --data "$d/ref-1-turn$tau.csv" --data "$d/ref-2-turn$tau.csv" \
        --data "$d/ref-3-turn$tau.csv" --out "$d/ref-turn$tau" >"$d/ref-turn$tau.log" 2>&1
done

# one case: WORLD CASEDIR → a tab-separated line, or nothing where the run scored none
case_turn() {
    local w="$1" c="$2" name seed
    name=$(basename "$c")
    seed="${name##*-}"
    [ -f "$c/val-won.json" ] && [ -f "$c/val.json" ] || return 0
    local x="-turn$TAU"
    python3 "$TURN" "$TAU" "$LAG" "$x" "$c"/trial-[123].csv -- "$c"/trial-[123].csv \
        "$c/val.csv"
    local refs=() data=()
    for i in 1 2 3; do
        refs+=(--reference "$RUNS/$w/ref-$i$x.csv")
        data+=(--data "$c/trial-$i$x.csv")
    done
    if "$YAWCAST" augment --model "$RUNS/$w/ref$x.postcard" --effect auto "${refs[@]}" \
        "${data[@]}" --seed "$seed" --out "$c/won$x" >"$c/won$x.log" 2>&1 \
        && "$YAWCAST" compare --model "$c/won$x.postcard" --data "$c/val$x.csv" \
            --horizons 10 --json "$c/val-won$x.json" >>"$c/won$x.log" 2>&1; then
        python3 -c 'import json, sys
w, name, c = sys.argv[1:4]
f = lambda m: json.load(open(f"{c}/val-{m}.json"))["records"][0]["fit"]["10"]
o = json.load(open(f"{c}/val.json"))["records"][0]["oracle_fit_pct"]
lin = max(f("linear"), f("ref"))
e, st, s = name.rsplit("-", 2)
a, t = f("won"), f(f"won-turn{sys.argv[4]}")
print("\t".join([w, e, st, s] + [f"{x:.2f}" for x in (o, lin, a, t)]))' \
            "$w" "$name" "$c" "$TAU"
    fi
}
export -f case_turn

for w in "${world_list[@]}"; do
    find "$runs/$w" -mindepth 1 -maxdepth 1 -type d -name '*-*-*' ! -name 'none-*' \
        -printf "$w %p\n"
done | sort | xargs -P "$jobs" -L 1 bash -c 'case_turn "$@"' _ | sort >"$runs/turn$tau.tsv"

python3 "$repo/bench/worlds/won_back_table.py" "$runs/turn$tau.tsv" \
    "with the turn's speed (T = $tau s, lag $lag)"
exit 0
}
