#!/usr/bin/env bash
# The error won back again, with another binary, on the records of a `run.sh --won-back`
# run: every effect case's `augment --effect auto` is run again from the run's reference
# model and records, and its model scored at 10 steps on the case's validation record. The
# oracle and the best linear model are the run's own, so the figure is `run.sh`'s won back
# with the new augment: (augmented − linear) / (oracle − linear), over the cases where the
# linear model is ≥ 3 pp below the oracle. It measures a change of augment; where the new
# binary's diagnose gives other verdicts, `run.sh --won-back` must be run again instead.
#
#   bench/worlds/won-back-again.sh --runs DIR [--yawcast PATH] [--worlds LIST]
#                                  [--name NAME] [--jobs N]
#
# DIR is the `--work` of a `run.sh --won-back` run; NAME (default `again`) names the new
# model and its scores in each case directory. Prints one line per case (world, effect,
# strength, seed, oracle, linear, augmented as run, augmented again, the effects of the model
# written again, both won back) and the median per world and strength of both.
set -euo pipefail
{
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
yawcast=""
runs=""
worlds=""
name=again
jobs=2
while [ $# -gt 0 ]; do
    case "$1" in
        --runs) runs="$(cd "$2" && pwd)"; shift 2 ;;
        --yawcast) yawcast="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --worlds) worlds="$2"; shift 2 ;;
        --name) name="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
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
export YAWCAST="$yawcast" RUNS="$runs" NAME="$name"

# one case: WORLD CASEDIR → a tab-separated line, or nothing where the run scored none
case_again() {
    local w="$1" c="$2" case seed
    case=$(basename "$c")
    seed="${case##*-}"
    [ -f "$c/val-won.json" ] && [ -f "$c/val.json" ] || return 0
    local refs=() data=()
    for i in 1 2 3; do
        refs+=(--reference "$RUNS/$w/ref-$i.csv")
        data+=(--data "$c/trial-$i.csv")
    done
    if "$YAWCAST" augment --model "$RUNS/$w/ref.postcard" --effect auto "${refs[@]}" \
        "${data[@]}" --seed "$seed" --out "$c/$NAME" \
        >"$c/$NAME.log" 2>&1 \
        && "$YAWCAST" compare --model "$c/$NAME.postcard" --data "$c/val.csv" \
            --horizons 10 --json "$c/val-$NAME.json" >>"$c/$NAME.log" 2>&1; then
        python3 -c 'import json, sys
w, case, c, name = sys.argv[1:5]
f = lambda m: json.load(open(f"{c}/val-{m}.json"))["records"][0]["fit"]["10"]
o = json.load(open(f"{c}/val.json"))["records"][0]["oracle_fit_pct"]
lin = max(f("linear"), f("ref"))
e, st, s = case.rsplit("-", 2)
model = json.load(open(f"{c}/{name}.json"))["model"]
effects = "+".join(e["effect"] for e in model["effects"]) or "none"
print("\t".join([w, e, st, s] + [f"{x:.2f}" for x in (o, lin, f("won"), f(name))] + [effects]))' \
            "$w" "$case" "$c" "$NAME"
    fi
}
export -f case_again

IFS=, read -r -a world_list <<<"$worlds"
for w in "${world_list[@]}"; do
    find "$runs/$w" -mindepth 1 -maxdepth 1 -type d -name '*-*-*' ! -name 'none-*' \
        -printf "$w %p\n"
done | sort | xargs -P "$jobs" -L 1 bash -c 'case_again "$@"' _ | sort >"$runs/$name.tsv"

python3 "$repo/bench/worlds/won_back_table.py" "$runs/$name.tsv" "$name" "its effects"
exit 0
}
