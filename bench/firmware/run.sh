#!/usr/bin/env bash
# Firmware benchmarks: instruction counts of one `update` and one 20-step `predict_into` of
# the base 4th-order model on the Cortex-M4F (QEMU single-step execution trace) and on
# x86_64 (callgrind), and the section sizes of the release firmware.
#
# Method: `yawcast-bench` runs each kernel N and 2N times; the difference of the two counts
# divided by N is the cost of one call. Two counts are reported: the instructions executed
# inside `yawcast_firmware` and `libm` functions (the predictor itself and the sin/cos it
# calls; on the M4 by PC range from the
# symbol table, on x86_64 from callgrind's per-function costs), and the whole loop iteration
# (harness, wrapper call and predictor). The same loop around an empty call shows the harness.
#
# Usage: bash bench/firmware/run.sh         (needs qemu-system-arm, valgrind, binutils)
# Output: a Markdown table on stdout and in target/bench-firmware/results.md.
set -euo pipefail
cd "$(dirname "$0")/../.."

THUMB=thumbv7em-none-eabihf
TGT="${CARGO_TARGET_DIR:-target}"
OUT="$TGT/bench-firmware"
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
BENCH_M4="$TGT/$THUMB/release/yawcast-bench"
FW="$TGT/$THUMB/release/yawcast-fw"
BENCH_X86="$TGT/release/yawcast-bench"

# --- Cortex-M4F: one trace, phases separated by calls to bench_marker -------------------
# Counted per phase: every instruction, and those whose PC lies in a yawcast_firmware
# function (the library's own instructions, wrapper and loop excluded).
echo "tracing on the Cortex-M4F (QEMU, one instruction per block)..." >&2
rm -f "$OUT/m4.trace.log"
timeout 300 qemu-system-arm -machine netduinoplus2 -nographic -monitor none \
    -semihosting-config enable=on,target=native \
    -singlestep -d exec,nochain -D "$OUT/m4.trace.log" \
    -kernel "$BENCH_M4" >"$OUT/m4.stdout" 2>&1
hex8() { printf '%08x' $(( $1 )); }
marker_sym=$(nm "$BENCH_M4" | awk '/bench_marker/ && !f { print $1; f = 1 }')
[ -n "$marker_sym" ] || { echo "bench_marker not found in $BENCH_M4" >&2; exit 1; }
marker=$(hex8 "0x$marker_sym & ~1")
ranges=""
while read -r addr size; do
    lo=$((0x$addr & ~1))
    ranges+="$(hex8 "$lo") $(hex8 "$lo + 0x$size") "
done < <(nm -C -S --defined-only "$BENCH_M4" | awk '/ (yawcast_firmware|libm)::/ && NF >= 4 { print $1, $2 }')
[ -n "$ranges" ] || { echo "no yawcast_firmware functions in $BENCH_M4" >&2; exit 1; }
# hex strings of equal width compare like numbers when compared as strings ("x" prefix)
read -r -a counts < <(awk -v m="$marker" -v ranges="$ranges" '
    BEGIN {
        n = split(ranges, r, " ")
        for (i = 1; i < n; i += 2) { k++; lo[k] = "x" r[i]; hi[k] = "x" r[i + 1] }
        phase = -1
    }
    /^Trace/ {
        if (!match($0, /\[[0-9a-f]+\/[0-9a-f]+\//)) next
        split(substr($0, RSTART + 1, RLENGTH - 2), f, "/")
        if (f[2] == m) phase++
        if (phase < 0) next
        tot[phase]++
        p = "x" f[2]
        for (j = 1; j <= k; j++) if (p >= lo[j] && p < hi[j]) { lib[phase]++; break }
    }
    END { printf "%d ", phase; for (i = 0; i < 8; i++) printf "%d %d ", tot[i], lib[i]; print "" }
' "$OUT/m4.trace.log")
if [ "${counts[0]}" -ne 8 ]; then
    echo "expected 9 marker hits in the trace, found $((counts[0] + 1))" >&2
    exit 1
fi
# counts: phases; then (total, library) for N update, 2N update, N predict, 2N predict, N empty,
# 2N empty, N cycle, 2N cycle
diff_n() { echo $(( (${counts[$2]} - ${counts[$1]}) / N )); }
m4_update_loop=$(diff_n 1 3);  m4_update_lib=$(diff_n 2 4)
m4_predict_loop=$(diff_n 5 7); m4_predict_lib=$(diff_n 6 8)
m4_empty_loop=$(diff_n 9 11)
m4_cycle_loop=$(diff_n 13 15); m4_cycle_lib=$(diff_n 14 16)
rm -f "$OUT/m4.trace.log"

# --- x86_64: callgrind; instructions in yawcast_firmware functions, and the whole loop ---
x86_counts() { # mode n -> "loop library" instruction counts
    local mode=$1 n=$2 file
    file="$OUT/cg.$mode.$n"
    valgrind --tool=callgrind --callgrind-out-file="$file" \
        "$BENCH_X86" "$mode" "$n" >/dev/null 2>&1
    # the whole program (N more iterations between the two runs), and the library's
    # exclusive costs summed
    callgrind_annotate --auto=no --threshold=100 "$file" 2>/dev/null |
        awk '/PROGRAM TOTALS/ { gsub(",", "", $1); t = $1 }
             $0 ~ /:(yawcast_firmware|libm)::/ { gsub(",", "", $1); s += $1 }
             END { print t + 0, s + 0 }'
}
x86_per() { # mode -> "loop library" per call
    local a b
    read -r -a a < <(x86_counts "$1" "$N")
    read -r -a b < <(x86_counts "$1" $((2 * N)))
    echo "$(( (b[0] - a[0]) / N )) $(( (b[1] - a[1]) / N ))"
}
echo "counting on x86_64 (callgrind)..." >&2
read -r x86_update_loop x86_update_lib < <(x86_per update)
read -r x86_predict_loop x86_predict_lib < <(x86_per predict)
read -r x86_empty_loop _ < <(x86_per empty)
read -r x86_cycle_loop x86_cycle_lib < <(x86_per cycle)

# --- sizes ---------------------------------------------------------------------------------
sec() { size -A "$FW" | awk -v s="$1" '$1 == s { print $2 + 0; f = 1 } END { if (!f) print 0 }'; }
vec=$(sec .vector_table); text=$(sec .text); rodata=$(sec .rodata); data=$(sec .data); bss=$(sec .bss)

{
    echo "| instructions per call | Cortex-M4F (QEMU trace) | x86_64 (callgrind) | target (M4) |"
    echo "|---|---|---|---|"
    echo "| \`update\`: in the library | $m4_update_lib | $x86_update_lib | ≤ 60 |"
    echo "| \`update\`: whole loop iteration (harness + call + library) | $m4_update_loop | $x86_update_loop | |"
    echo "| 20-step \`predict_into\`: in the library | $m4_predict_lib | $x86_predict_lib | ≤ 400 |"
    echo "| 20-step \`predict_into\`: whole loop iteration | $m4_predict_loop | $x86_predict_loop | |"
    echo "| the same loop around an empty call | $m4_empty_loop | $x86_empty_loop | |"
    echo "| cycle: \`update\` + track update + 20-step \`predict_into\` + 20-step heading and track: in the library | $m4_cycle_lib | $x86_cycle_lib | ≤ 700 |"
    echo "| cycle: whole loop iteration | $m4_cycle_loop | $x86_cycle_loop | |"
    echo
    echo "| section of \`yawcast-fw\` (release, defmt) | bytes | target |"
    echo "|---|---|---|"
    echo "| .vector_table | $vec | |"
    echo "| .text | $text | |"
    echo "| .rodata | $rodata | |"
    echo "| flash (the three above) | $((vec + text + rodata)) | ≤ 28672 (32 KiB less a 4 KiB reserve) |"
    echo "| .data + .bss (static RAM) | $((data + bss)) | ≤ 8192 |"
} | tee "$OUT/results.md"
