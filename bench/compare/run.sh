#!/usr/bin/env bash
# Side by side in one run: the benchmarks of a base revision and of the working tree — the
# criterion benchmarks (PEM, GA, diagnose; each bench run for the base, then for the tree,
# so both see the same machine load) and the firmware instruction counts (bench/firmware).
#
# Usage: bash bench/compare/run.sh [BASE_REV] [CRITERION_FILTER]
#   BASE_REV defaults to HEAD~1; CRITERION_FILTER (a regex over benchmark ids) to all.
# Needs what bench/firmware/run.sh needs (qemu-system-arm, valgrind, binutils).
# Output: a Markdown table on stdout and in target/bench-compare/results.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
BASE=${1:-HEAD~1}
FILTER=${2:-}
OUT=$ROOT/target/bench-compare
WT=$OUT/base-tree
mkdir -p "$OUT"
rev=$(git rev-parse --short "$BASE")
if [ -d "$WT" ]; then git worktree remove --force "$WT"; fi
git worktree add --detach "$WT" "$BASE" >/dev/null
trap 'git worktree remove --force "$WT" >/dev/null 2>&1 || true' EXIT

# mean estimate (the middle of criterion's [low mean high]) per benchmark id, in ms
crit() { # dir target-dir bench
    (cd "$1" && CARGO_TARGET_DIR=$2 cargo bench -q -p yawcast --bench "$3" -- --noplot ${FILTER:+"$FILTER"} 2>/dev/null) |
        awk '
        /time:/ {
            id = $0; sub(/ *time:.*/, "", id); gsub(/^ +| +$/, "", id)
            if (id == "") { id = prev; gsub(/^ +| +$/, "", id) }
            split($0, a, "["); split(a[2], v, " ")
            x = v[3]; u = v[4]
            if (u == "s") x *= 1000; else if (u == "µs" || u == "us") x /= 1000; else if (u == "ns") x /= 1e6
            printf "%s\t%.4f\n", id, x
        }
        { prev = $0 }'
}

: >"$OUT/base.tsv"
: >"$OUT/head.tsv"
for b in pem ga diagnose; do
    echo "criterion $b: base $rev..." >&2
    crit "$WT" "$OUT/target-base" "$b" >>"$OUT/base.tsv"
    echo "criterion $b: working tree..." >&2
    crit "$ROOT" "$ROOT/target" "$b" >>"$OUT/head.tsv"
done

echo "firmware: base $rev..." >&2
# older revisions of the script build into ./target whatever CARGO_TARGET_DIR says
(cd "$WT" && env -u CARGO_TARGET_DIR bash bench/firmware/run.sh >"$OUT/fw-base.md")
echo "firmware: working tree..." >&2
bash bench/firmware/run.sh >"$OUT/fw-head.md"

{
    echo "# Side by side: $rev (base) and the working tree ($(git rev-parse --short HEAD)$(git diff --quiet || echo '+changes'))"
    echo
    echo "Machine: $(nproc) cores, $(uname -m), load before the run $(cut -d' ' -f1-3 /proc/loadavg)."
    echo
    echo "| benchmark | base (ms) | tree (ms) | tree / base |"
    echo "|---|---:|---:|---:|"
    join -t $'\t' <(sort "$OUT/base.tsv") <(sort "$OUT/head.tsv") |
        awk -F'\t' '{ printf "| %s | %.2f | %.2f | %.3f |\n", $1, $2, $3, $3 / $2 }'
    echo
    echo "## Firmware, base $rev"
    echo
    cat "$OUT/fw-base.md"
    echo
    echo "## Firmware, working tree"
    echo
    cat "$OUT/fw-head.md"
} | tee "$OUT/results.md"
