#!/usr/bin/env bash
# The peer benchmark: yawcast against SIPPY, nfoursid and sysidentpy in one run.
#
#   bench/peers/run.sh            full run; writes bench/RESULTS.md
#   bench/peers/run.sh --smoke    one record, one peer, plain PEM; prints the report
#   bench/peers/run.sh --help     every option (seeds, effects, peers, working folder, ...)
#
# Uses target/release/yawcast (built here when missing; set YAWCAST=path to use another
# binary) and the pinned Python environment made by setup.sh.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"

"$here/setup.sh"

need_bin=1
smoke=0
for a in "$@"; do
    case "$a" in
        --standin|--help|-h|selftest|fit|report) need_bin=0 ;;
        --smoke) smoke=1 ;;
    esac
done
if [[ $need_bin == 1 && -z "${YAWCAST:-}" && ! -x "$repo/target/release/yawcast" ]]; then
    if [[ $smoke == 1 ]]; then
        # the smoke run times nothing that matters: any build will do
        if [[ ! -x "$repo/target/debug/yawcast" ]]; then
            echo "run.sh: building yawcast (debug, for the smoke run)" >&2
            (cd "$repo" && cargo build --quiet --bin yawcast)
        fi
    else
        echo "run.sh: building yawcast (release)" >&2
        (cd "$repo" && cargo build --release --quiet --bin yawcast)
    fi
fi

exec "$here/.venv/bin/python" "$here/run.py" "$@"
