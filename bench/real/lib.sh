# Shared by bench/real/hsva.sh and bench/real/marin.sh (sourced, not run): the binary, the
# records as `--data` arguments, and one diagnosis with its line in the summary.
#
#   yawcast_binary REPO PATH   prints PATH, or builds the release profile and prints its binary
#   data DIR KIND NAME…        prints `--data DIR/KIND/NAME.csv` for each NAME, one word a line
#   summary_header FILE        writes the summary's header
#   diag WORK CASE SEED ARGS…  `yawcast diagnose ARGS…` (with `--seed SEED` unless SEED is
#                              `data`) into WORK/CASE-SEED.{json,txt}, and its line into
#                              WORK/summary.tsv: the verdict, the second effect, the slew
#                              limit's p and estimate, the `command-steps`, `noise-gain`,
#                              `noisier-trials` and `quieter-trials` caveats' figures
# The caller sets `yawcast` to the binary before calling `diag`.

yawcast_binary() {
    local repo="$1" path="$2"
    if [ -n "$path" ]; then
        echo "$path"
        return
    fi
    (cd "$repo" && cargo build -q --release -p yawcast)
    echo "${CARGO_TARGET_DIR:-$repo/target}/release/yawcast"
}

data() {
    local dir="$1" kind="$2"; shift 2
    for n in "$@"; do printf -- '--data\n%s\n' "$dir/$kind/$n.csv"; done
}

summary_header() {
    printf 'case\tseed\tverdict\tthen\trate_limit_p\trate_limit_degps\tcommand_steps\tnoise_gain\tnoisier_trials\tquieter_trials\n' \
        > "$1"
}

diag() {
    local work="$1" case="$2" seed="$3"; shift 3
    local out="$work/$case-$seed.json"
    local seedargs=()
    [ "$seed" = data ] || seedargs=(--seed "$seed")
    "$yawcast" diagnose "$@" "${seedargs[@]}" --json "$out" > "$work/$case-$seed.txt" 2>&1
    python3 - "$out" "$case" "$seed" >> "$work/summary.tsv" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
rl = next(r for r in d["ranking"] if r["effect"] == "rate-limit")
cs = [c for c in d["caveats"] if c["caveat"] == "command-steps"]
steps = "-" if not cs else "trials {:.1f}, reference {:.2f} deg/sample ({:.1f} deg/s)".format(
    cs[0]["trial_step_deg"], cs[0]["reference_step_deg"], cs[0]["slew_degps"])
ng = [c for c in d["caveats"] if c["caveat"] == "noise-gain"]
noise = "-" if not ng else "{:.0f} x {:.1e} deg/s (reference {:.1e})".format(
    ng[0]["gain_10"], ng[0]["trials_noise_degps"], ng[0]["reference_noise_degps"])
nt = [c for c in d["caveats"] if c["caveat"] == "noisier-trials"]
noisier = "-" if not nt else "{:.1e} against {:.1e} deg/s; gain {:.3g} -> {:.3g}".format(
    nt[0]["trials_noise_degps"], nt[0]["reference_noise_degps"], nt[0]["gain_10_given"],
    nt[0]["gain_10"])
qt = [c for c in d["caveats"] if c["caveat"] == "quieter-trials"]
quieter = "-" if not qt else "{:.1e} against {:.1e} deg/s; {:.1e} added".format(
    qt[0]["trials_noise_degps"], qt[0]["reference_noise_degps"], qt[0]["added_noise_degps"])
print("\t".join([sys.argv[2], sys.argv[3], d["verdict"], d["then"] or "-",
                 "{:.2g}".format(rl["p_value"]), "{:.2f}".format(rl["parameter"]), steps,
                 noise, noisier, quieter]))
PY
}
