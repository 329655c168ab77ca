#!/usr/bin/env bash
# Firmware benchmarks: instruction counts of one `update` and one 20-step `predict_into` of
# the base 4th-order model on the Cortex-M4F (QEMU single-step execution trace) and on
# x86_64 (callgrind), and the section sizes of the release firmware.
#
# Method: `yawcast-bench` runs each kernel N and 2N times; the difference of the two counts
# divided by N is the cost of one loop iteration (call, predictor, loop). The same loop
# around an empty call gives the harness cost, subtracted for the "net" column.
#
# Usage: bash bench/firmware/run.sh         (needs qemu-system-arm, valgrind, binutils)
# Output: a Markdown table on stdout and in target/bench-firmware/results.md.
set -euo pipefail
cd "$(dirname "$0")/../.."

THUMB=thumbv7em-none-eabihf
OUT=target/bench-firmware
N=200 # must match `N` in firmware/src/bin/yawcast-bench.rs
mkdir -p "$OUT"

for tool in qemu-system-arm valgrind size nm; do
    command -v "$tool" >/dev/null || {
        echo "missing $tool (apt-get install qemu-system-arm valgrind binutils)" >&2
        exit 1
    }
done

echo "building (release, $THUMB and host)..." >&2
cargo build -q -p yawcast-firmware --bins --release --target "$THUMB"
cargo build -q -p yawcast-firmware --bin yawcast-bench --release
BENCH_M4="target/$THUMB/release/yawcast-bench"
FW="target/$THUMB/release/yawcast-fw"
BENCH_X86="target/release/yawcast-bench"

# --- Cortex-M4F: one trace, phases separated by calls to bench_marker -------------------
echo "tracing on the Cortex-M4F (QEMU, one instruction per block)..." >&2
rm -f "$OUT/m4.trace.log"
timeout 300 qemu-system-arm -machine netduinoplus2 -nographic -monitor none \
    -semihosting-config enable=on,target=native \
    -singlestep -d exec,nochain -D "$OUT/m4.trace.log" \
    -kernel "$BENCH_M4" >"$OUT/m4.stdout" 2>&1
marker_sym=$(nm "$BENCH_M4" | awk '/bench_marker/ { print $1; exit }')
[ -n "$marker_sym" ] || { echo "bench_marker not found in $BENCH_M4" >&2; exit 1; }
marker=$(printf '%08x' $((0x$marker_sym & ~1)))
read -r -a marks < <(awk -v m="$marker" '
    /^Trace/ {
        n++
        if (match($0, /\[[0-9a-f]+\/[0-9a-f]+\//)) {
            split(substr($0, RSTART + 1, RLENGTH - 2), f, "/")
            if (f[2] == m) printf "%d ", n
        }
    }
    END { print "" }' "$OUT/m4.trace.log")
if [ "${#marks[@]}" -ne 7 ]; then
    echo "expected 7 marker hits in the trace, found ${#marks[@]}" >&2
    exit 1
fi
per() { echo $(( ((${marks[$2]} - ${marks[$1]}) - (${marks[$1]} - ${marks[$(($1 - 1))]})) / N )); }
m4_update=$(per 1 2)
m4_predict=$(per 3 4)
m4_empty=$(per 5 6)
rm -f "$OUT/m4.trace.log"

# --- x86_64: callgrind, collecting only inside the kernel loop ----------------------------
x86_count() { # mode n -> instructions collected inside run_<mode>
    local mode=$1 n=$2 fn
    case $mode in update) fn=run_updates ;; predict) fn=run_predicts ;; empty) fn=run_empty ;; esac
    valgrind --tool=callgrind --callgrind-out-file="$OUT/cg.$mode.$n" \
        --toggle-collect="*$fn*" "$BENCH_X86" "$mode" "$n" >/dev/null 2>&1
    awk '/^(summary|totals):/ { print $2; exit }' "$OUT/cg.$mode.$n"
}
x86_per() { echo $(( ($(x86_count "$1" $((2 * N))) - $(x86_count "$1" "$N")) / N )); }
echo "counting on x86_64 (callgrind)..." >&2
x86_update=$(x86_per update)
x86_predict=$(x86_per predict)
x86_empty=$(x86_per empty)

# --- sizes ---------------------------------------------------------------------------------
sec() { size -A "$FW" | awk -v s="$1" '$1 == s { print $2 + 0; f = 1 } END { if (!f) print 0 }'; }
text=$(sec .text); rodata=$(sec .rodata); data=$(sec .data); bss=$(sec .bss)

{
    echo "| measure | Cortex-M4F (QEMU) | x86_64 (callgrind) | target |"
    echo "|---|---|---|---|"
    echo "| \`update\`, per call incl. call + loop | $m4_update | $x86_update | |"
    echo "| \`update\`, net of the empty-call harness | $((m4_update - m4_empty)) | $((x86_update - x86_empty)) | ≤ 60 (M4) |"
    echo "| 20-step \`predict_into\`, per call incl. call + loop | $m4_predict | $x86_predict | |"
    echo "| 20-step \`predict_into\`, net of the harness | $((m4_predict - m4_empty)) | $((x86_predict - x86_empty)) | ≤ 400 (M4) |"
    echo "| empty-call harness | $m4_empty | $x86_empty | |"
    echo
    echo "| section of \`yawcast-fw\` (release, defmt) | bytes | target |"
    echo "|---|---|---|"
    echo "| .text | $text | ≤ 32768 |"
    echo "| .rodata | $rodata | |"
    echo "| .data + .bss (static RAM) | $((data + bss)) | ≤ 8192 |"
} | tee "$OUT/results.md"
