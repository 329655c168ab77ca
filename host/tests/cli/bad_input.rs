//! The bad-input suite: every case a clear error, its exit code, no output left.

use crate::common::*;

/// One bad-input case: the arguments (`{d}` is the case's scratch directory, `{good}` a good
/// record, `{model}` a good model), the words the error must hold, and the exit code.
struct Bad {
    name: &'static str,
    args: &'static str,
    expect: &'static [&'static str],
    code: i32,
}

const fn bad(name: &'static str, args: &'static str, expect: &'static [&'static str]) -> Bad {
    Bad {
        name,
        args,
        expect,
        code: 2,
    }
}

/// The bad-input suite: every case exits with its documented code and a message naming the
/// file, row, field or flag at fault, within a time limit, and leaves no output file behind
/// (every case that writes anything is given `--out {d}/out…` and `--json {d}/out.json`).
#[test]
fn bad_input_suite() {
    let root = scratch("badsuite");
    let good = csv4(400, 1, 0.02);
    let rows = |f: &dyn Fn(usize, &str) -> String| -> String {
        good.lines()
            .enumerate()
            .map(|(i, l)| if i == 0 { l.to_string() } else { f(i, l) })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let set = |i: usize, row: usize, col: usize, v: &str, l: &str| {
        if i != row {
            return l.to_string();
        }
        let mut c: Vec<String> = l.split(',').map(String::from).collect();
        c[col] = v.into();
        c.join(",")
    };
    let t = |i: usize| (i - 1) as f64 * 0.5;
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("good.csv", good.clone().into_bytes()),
        ("good2.csv", csv4(400, 2, 0.02).into_bytes()),
        ("short.csv", csv4(12, 3, 0.02).into_bytes()),
        ("no_rate.csv", good.replace("r_degps", "r_other").into_bytes()),
        ("word.csv", rows(&|i, l| set(i, 17, 2, "fast", l)).into_bytes()),
        ("nan.csv", rows(&|i, l| set(i, 23, 1, "NaN", l)).into_bytes()),
        ("inf.csv", rows(&|i, l| set(i, 29, 2, "inf", l)).into_bytes()),
        ("huge_cell.csv", rows(&|i, l| set(i, 40, 2, "3.4e200", l)).into_bytes()),
        ("rudder.csv", rows(&|i, l| set(i, 12, 1, "2000000", l)).into_bytes()),
        ("spike.csv", rows(&|i, l| {
            let r: f64 = l.split(',').nth(2).unwrap().parse().unwrap();
            set(i, 77, 2, &format!("{}", r + 5.0), l)
        }).into_bytes()),
        ("zero.csv", rows(&|i, _| format!("{},0,0", t(i))).into_bytes()),
        ("flipped.csv", rows(&|i, l| {
            let c: Vec<&str> = l.split(',').collect();
            let d: f64 = c[1].parse().unwrap();
            set(i, i, 1, &format!("{}", -d), l)
        }).into_bytes()),
        ("radians.csv", rows(&|i, l| {
            let c: Vec<&str> = l.split(',').collect();
            let d: f64 = c[1].parse().unwrap();
            set(i, i, 1, &format!("{}", d.to_radians()), l)
        }).into_bytes()),
        ("held.csv", rows(&|i, l| set(i, i, 1, "7", l)).into_bytes()),
        ("stuck.csv", rows(&|i, l| set(i, i, 2, "0", l)).into_bytes()),
        ("tiny.csv", rows(&|i, l| set(i, i, 2, &format!("{}e-300", i % 3), l)).into_bytes()),
        (
            "dup.csv",
            rows(&|_, l| format!("{l},1"))
                .replacen("r_degps", "r_degps,delta_deg", 1)
                .into_bytes(),
        ),
        ("back.csv", rows(&|i, l| set(i, 50, 0, "3", l)).into_bytes()),
        ("gap.csv", rows(&|i, l| set(i, i, 0, &format!("{}", t(i) + if i >= 60 { 2.0 } else { 0.0 }), l)).into_bytes()),
        ("repeat.csv", rows(&|i, l| set(i, 70, 0, &format!("{}", t(69)), l)).into_bytes()),
        ("one_row.csv", b"t_s,delta_deg,r_degps\n0,1,0.1\n".to_vec()),
        ("empty.csv", Vec::new()),
        ("header.csv", b"t_s,delta_deg,r_degps\n".to_vec()),
        ("ragged.csv", rows(&|i, l| if i == 33 { l.rsplit_once(',').unwrap().0.to_string() } else { l.to_string() }).into_bytes()),
        ("binary.csv", (0..400u32).map(|i| (i * 37 % 251) as u8).collect()),
        ("fast.csv", csv_text(400, 0.1).into_bytes()),
        (
            "speed.csv",
            rows(&|i, l| format!("{l},{}", if i == 44 { "1e9" } else { "1.5" }))
                .replacen("r_degps", "r_degps,u_mps", 1)
                .into_bytes(),
        ),
        (
            "wind.csv",
            rows(&|i, l| format!("{l},{},30", if i == 45 { "-250" } else { "5" }))
                .replacen("r_degps", "r_degps,wind_speed_mps,wind_angle_deg", 1)
                .into_bytes(),
        ),
        ("semi_bad.csv", b"t_s;delta_deg;r_degps\n0;1,5;x\n0,5;2;0\n".to_vec()),
        ("not_json.json", b"{ this is not json".to_vec()),
        // the model the good records were made with (`csv4`)
        ("csv4.json", br#"{"n":4,"ts":0.5,"a":[-0.08645,0.6135,-1.785,2.25],"b":[0.02,0.035,0.045,0.05],"k":[0.0,0.0,0.0,0.0],"effects":[]}"#.to_vec()),
        ("schema.json", br#"{"n":2,"ts":0.5,"a":[1,2]}"#.to_vec()),
        ("huge.json", br#"{"n":2,"ts":0.5,"a":[1e308,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#.to_vec()),
        ("unstable.json", br#"{"n":2,"ts":0.5,"a":[0.0,1.3],"b":[0.01,0.02],"k":[0.0,0.0],"effects":[]}"#.to_vec()),
        ("order1.json", br#"{"n":1,"ts":0.5,"a":[0.5],"b":[0.01],"k":[0.5],"effects":[]}"#.to_vec()),
        ("order9.json", format!(r#"{{"n":9,"ts":0.5,"a":{z},"b":{z},"k":{z},"effects":[]}}"#, z = serde_json::to_string(&[0.0; 9]).unwrap()).into_bytes()),
        ("neg_ts.json", br#"{"n":2,"ts":-0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#.to_vec()),
        ("null.json", br#"{"n":2,"ts":0.5,"a":[null,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#.to_vec()),
        ("effect.json", br#"{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[{"effect":"waves","beta":1}]}"#.to_vec()),
        ("lengths.json", br#"{"n":2,"ts":0.5,"a":[-0.2,0.7,0.1],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#.to_vec()),
        ("text.postcard", b"hello, I am not a blob".to_vec()),
        ("empty.postcard", Vec::new()),
        ("bad.toml", b"[hull\nlength = ".to_vec()),
        ("neg.toml", b"[hull]\nlength_m = -3\n".to_vec()),
        ("trial.nmea", std::fs::read(data_dir().join("trial-bad-checksum.nmea")).unwrap()),
    ];
    let cases = [
        // reading records
        bad("missing file", "identify --data {d}/nowhere.csv --out {d}/out --json {d}/out-summary.json", &["nowhere.csv"]),
        bad("missing column", "identify --data {d}/no_rate.csv --out {d}/out --json {d}/out-summary.json", &["no_rate.csv", "r_degps"]),
        bad("word in a cell", "identify --data {d}/word.csv --out {d}/out", &["word.csv", "row 17", "fast"]),
        bad("NaN cell", "identify --data {d}/nan.csv --out {d}/out", &["nan.csv", "row 23", "delta_deg"]),
        bad("inf cell", "identify --data {d}/inf.csv --out {d}/out", &["inf.csv", "row 29"]),
        bad("3.4e200 cell", "identify --data {d}/huge_cell.csv --out {d}/out", &["huge_cell.csv", "row 40", "r_degps"]),
        bad("3.4e200 cell, tune", "tune --data {d}/good.csv --validate {d}/huge_cell.csv --out {d}/out --generations 2", &["huge_cell.csv", "row 40"]),
        bad("3.4e200 cell, average", "average --data {d}/good.csv --data {d}/huge_cell.csv --validate {d}/good2.csv --out {d}/out", &["huge_cell.csv", "row 40"]),
        bad("3.4e200 cell, diagnose reference", "diagnose --model {model} --data {d}/good.csv --reference {d}/huge_cell.csv --out {d}/outdir --json {d}/out-summary.json", &["huge_cell.csv", "row 40"]),
        bad("3.4e200 cell, augment", "augment --model {model} --effect bias --data {d}/huge_cell.csv --out {d}/out --json {d}/out-summary.json", &["huge_cell.csv", "row 40"]),
        bad("2e6° rudder", "identify --data {d}/rudder.csv --out {d}/out", &["rudder.csv", "row 12", "delta_deg", "--max-angle"]),
        bad("2e6° rudder, compare", "compare --model {model} --data {d}/rudder.csv --json {d}/out-summary.json", &["rudder.csv", "row 12"]),
        bad("gyro spike", "identify --data {d}/spike.csv --out {d}/out", &["spike.csv", "row 77", "r_degps", "spike", "--despike"]),
        bad("gyro spike, diagnose reference", "diagnose --model {model} --data {d}/good.csv --reference {d}/spike.csv --json {d}/out-summary.json", &["spike.csv", "row 77", "--despike"]),
        bad("all-zero trial", "diagnose --model {model} --data {d}/zero.csv --reference {d}/good.csv --json {d}/out-summary.json", &["zero.csv", "constant"]),
        bad("command of the other sign, diagnose", "diagnose --model {d}/csv4.json --data {d}/flipped.csv --reference {d}/good.csv --json {d}/out-summary.json", &["trial record `flipped`", "with the command negated", "negate its command column"]),
        bad("command of the other sign, augment", "augment --model {d}/csv4.json --effect bias --data {d}/flipped.csv --out {d}/out --json {d}/out-summary.json", &["estimation record `flipped`", "negate its command column"]),
        bad("command of the other sign, average", "average --data {d}/good.csv --data {d}/good2.csv --data {d}/flipped.csv --validate {d}/good.csv --out {d}/out --json {d}/out-summary.json", &["estimation record `flipped`", "signed the other way round"]),
        bad("command in radians, diagnose", "diagnose --model {d}/csv4.json --data {d}/radians.csv --reference {d}/good.csv --json {d}/out-summary.json", &["trial record `radians`", "multiplied by 57.", "another unit", "--angle-unit rad"]),
        bad("command in radians, augment", "augment --model {d}/csv4.json --effect bias --data {d}/radians.csv --out {d}/out --json {d}/out-summary.json", &["estimation record `radians`", "multiplied by 57."]),
        bad("command in radians, average", "average --data {d}/good.csv --data {d}/good2.csv --data {d}/radians.csv --validate {d}/good.csv --out {d}/out --json {d}/out-summary.json", &["estimation record `radians`", "another unit", "2 of the 2 models"]),
        bad("rudder never moves", "tune --data {d}/good.csv --validate {d}/held.csv --out {d}/out", &["held.csv", "delta_deg", "constant"]),
        bad("yaw rate stuck at zero", "identify --data {d}/stuck.csv --out {d}/out", &["stuck.csv", "r_degps", "constant"]),
        bad("1e-300 yaw rate", "compare --model {model} --data {d}/tiny.csv --json {d}/out-summary.json", &["tiny.csv", "r_degps"]),
        bad("duplicate column", "compare --model {model} --data {d}/dup.csv", &["dup.csv", "delta_deg", "more than once"]),
        bad("time going back", "identify --data {d}/back.csv --out {d}/out", &["back.csv", "row 50"]),
        bad("gap in time", "identify --data {d}/gap.csv --out {d}/out", &["gap.csv", "row 60"]),
        bad("repeated time", "identify --data {d}/repeat.csv --out {d}/out", &["repeat.csv", "row 70"]),
        bad("one row", "identify --data {d}/one_row.csv --out {d}/out", &["one_row.csv", "1 samples"]),
        bad("empty file", "identify --data {d}/empty.csv --out {d}/out", &["empty.csv"]),
        bad("header only", "identify --data {d}/header.csv --out {d}/out", &["header.csv", "0 samples"]),
        bad("ragged row", "identify --data {d}/ragged.csv --out {d}/out", &["ragged.csv"]),
        bad("binary garbage", "identify --data {d}/binary.csv --out {d}/out", &["binary.csv"]),
        bad("short record", "identify --data {d}/short.csv --out {d}/out", &["short.csv"]),
        bad("short reference, diagnose", "diagnose --model {model} --data {d}/good.csv --reference {d}/short.csv --json {d}/out-summary.json", &["reference record `short`", "12 samples"]),
        bad("short trial, diagnose", "diagnose --model {model} --data {d}/short.csv --reference {d}/good.csv --json {d}/out-summary.json", &["trial record `short`", "12 samples"]),
        bad("speed 1e9 m/s", "compare --model {model} --data {d}/speed.csv", &["speed.csv", "row 44", "u_mps"]),
        bad("wind speed −250", "compare --model {model} --data {d}/wind.csv", &["wind.csv", "row 45", "wind_speed_mps"]),
        bad(";-file with a bad cell", "compare --model {model} --data {d}/semi_bad.csv", &["semi_bad.csv", "row 1", "x"]),
        bad("another sample time", "compare --model {model} --data {d}/fast.csv --json {d}/out-summary.json", &["fast.csv", "0.1"]),
        bad("bad NMEA checksum", "compare --model {model} --data {d}/trial.nmea", &["trial.nmea", "checksum"]),
        bad("--format csv on NMEA", "compare --model {model} --data {d}/trial.nmea --format csv", &["trial.nmea"]),
        // models
        bad("missing model", "compare --model {d}/nowhere.json --data {d}/good.csv", &["nowhere.json"]),
        bad("model not JSON", "compare --model {d}/not_json.json --data {d}/good.csv", &["not_json.json", "not JSON"]),
        bad("model missing fields", "compare --model {d}/schema.json --data {d}/good.csv", &["schema.json"]),
        bad("model a1 = 1e308", "compare --model {d}/huge.json --data {d}/good.csv", &["huge.json", "a[0]"]),
        bad("unstable model", "compare --model {d}/unstable.json --data {d}/good.csv", &["unstable.json", "unit circle"]),
        bad("order 1 model", "compare --model {d}/order1.json --data {d}/good.csv", &["order1.json", "order"]),
        bad("order 9 model", "compare --model {d}/order9.json --data {d}/good.csv", &["order9.json", "order"]),
        bad("negative sample time", "compare --model {d}/neg_ts.json --data {d}/good.csv", &["neg_ts.json"]),
        bad("null coefficient", "compare --model {d}/null.json --data {d}/good.csv", &["null.json"]),
        bad("unknown effect in a model", "compare --model {d}/effect.json --data {d}/good.csv", &["effect.json", "waves"]),
        bad("coefficient lengths", "compare --model {d}/lengths.json --data {d}/good.csv", &["lengths.json"]),
        bad("text as a blob", "compare --model {d}/text.postcard --data {d}/good.csv", &["text.postcard"]),
        bad("empty blob", "compare --model {d}/empty.postcard --data {d}/good.csv", &["empty.postcard"]),
        bad("blob model for export", "export --model {d}/text.postcard --data {d}/good.csv --out {d}/out", &["text.postcard"]),
        bad("unstable model for diagnose", "diagnose --model {d}/unstable.json --data {d}/good.csv --json {d}/out-summary.json", &["unstable.json"]),
        bad("unstable model for augment", "augment --model {d}/unstable.json --effect bias --data {d}/good.csv --out {d}/out", &["unstable.json"]),
        bad("unstable model for resid", "resid --model {d}/unstable.json --data {d}/good.csv --json {d}/out-summary.json", &["unstable.json"]),
        bad("unstable model for hil", "hil --model {d}/unstable.json --steps 10", &["unstable.json"]),
        // arguments
        bad("unknown flag", "compare --model {model} --data {d}/good.csv --no-such-flag", &["--no-such-flag"]),
        bad("no --data", "identify --out {d}/out", &["--data"]),
        bad("horizon 0", "compare --model {model} --data {d}/good.csv --horizons 0", &["--horizons", "0"]),
        bad("horizon word", "compare --model {model} --data {d}/good.csv --horizons soon", &["--horizons", "soon"]),
        bad("horizon 5000", "compare --model {model} --data {d}/good.csv --horizons 5000 --json {d}/out-summary.json", &["good.csv", "5000"]),
        bad("order 1", "identify --data {d}/good.csv --order 1 --out {d}/out", &["order"]),
        bad("order 9", "identify --data {d}/good.csv --order 9 --out {d}/out", &["order"]),
        bad("orders 1..9", "identify --data {d}/good.csv --orders 1..9", &["--orders"]),
        bad("focus 0", "identify --data {d}/good.csv --focus 0 --out {d}/out", &["--focus"]),
        bad("focus 5000", "identify --data {d}/good.csv --focus 5000 --out {d}/out", &["good.csv", "--focus 5000"]),
        bad("negative λ", "identify --data {d}/good.csv --lambda -1 --out {d}/out", &["--lambda"]),
        bad("λ not a number", "identify --data {d}/good.csv --lambda NaN --out {d}/out", &["--lambda"]),
        bad("--json is the twin", "identify --data {d}/good.csv --out {d}/out --json {d}/out.json", &["JSON twin"]),
        bad("tune horizon 0", "tune --data {d}/good.csv --validate {d}/good2.csv --horizons 0 --out {d}/out", &["--horizons"]),
        bad("tune 0 generations", "tune --data {d}/good.csv --validate {d}/good2.csv --generations 0 --out {d}/out", &["generation"]),
        bad("tune short trial", "tune --data {d}/good.csv --validate {d}/short.csv --out {d}/out", &["short.csv", "12 samples"]),
        bad("tune without trials", "tune --data {d}/good.csv --out {d}/out", &["--validate"]),
        bad("average without records", "average --out {d}/out", &["--data"]),
        bad("alpha 0", "diagnose --model {model} --data {d}/good.csv --alpha 0", &["--alpha"]),
        bad("alpha 1.5", "diagnose --model {model} --data {d}/good.csv --alpha 1.5", &["--alpha"]),
        bad("null reps 0", "diagnose --model {model} --data {d}/good.csv --null-reps 0 --json {d}/out-summary.json", &["--null-reps"]),
        bad("augment unknown effect", "augment --model {model} --effect waves --data {d}/good.csv --out {d}/out", &["waves"]),
        bad("augment null reps 0", "augment --model {model} --effect auto --data {d}/good.csv --null-reps 0 --out {d}/out", &["--null-reps"]),
        bad("augment bad ship file", "augment --model {model} --effect bias --data {d}/good.csv --ship {d}/bad.toml --out {d}/out --json {d}/out-summary.json", &["bad.toml"]),
        bad("max-angle −1", "compare --model {model} --data {d}/good.csv --max-angle -1", &["--max-angle"]),
        bad("max-rate 0", "compare --model {model} --data {d}/good.csv --max-rate 0", &["--max-rate"]),
        bad("resample 0", "compare --model {model} --data {d}/good.csv --resample 0", &["good.csv", "--resample"]),
        bad("resample −1", "compare --model {model} --data {d}/good.csv --resample -1", &["--resample"]),
        bad("resid max-lag 0", "resid --model {model} --data {d}/good.csv --max-lag 0", &["--max-lag"]),
        bad("hil steps 0", "hil --model {model} --steps 0", &["--steps 0"]),
        bad("hil horizon 0", "hil --model {model} --horizon 0", &["--horizon"]),
        bad("hil horizon 9999", "hil --model {model} --horizon 9999", &["--horizon"]),
        bad("simulate duration 0", "simulate --duration 0 --out {d}/out.csv --json {d}/out-summary.json", &["--duration"]),
        bad("simulate duration −5", "simulate --duration -5 --out {d}/out.csv", &["--duration"]),
        bad("simulate ts 0", "simulate --ts 0 --out {d}/out.csv", &["--ts"]),
        bad("simulate unknown effect", "simulate --effect waves --out {d}/out.csv", &["waves"]),
        bad("simulate strength −1", "simulate --effect bias --strength -1 --out {d}/out.csv", &["--strength"]),
        bad("simulate unknown input", "simulate --input sawtooth --out {d}/out.csv", &["sawtooth"]),
        bad("simulate 0 records", "simulate --records 0 --out {d}/out.csv", &["--records"]),
        bad("simulate negative noise", "simulate --gyro-noise -1 --out {d}/out.csv", &["--gyro-noise"]),
        bad("simulate bad ship", "simulate --ship {d}/bad.toml --out {d}/out.csv", &["bad.toml"]),
        bad("simulate negative hull", "simulate --ship {d}/neg.toml --out {d}/out.csv", &["neg.toml"]),
        bad("demo duration 0", "demo --duration 0 --out {d}/outdir", &["--duration"]),
        bad("demo bad ship", "demo --ship {d}/bad.toml --out {d}/outdir", &["bad.toml"]),
        // outputs that cannot be written, refused before any work
        bad("--json under a file", "identify --data {d}/good.csv --out {d}/out --json {d}/good.csv/out.json", &["good.csv/out.json", "is a file, not a directory"]),
        bad("tune --json under a file", "tune --data {d}/good.csv --validate {d}/good2.csv --out {d}/out --json {d}/good.csv/out.json", &["good.csv/out.json", "is a file"]),
        bad("export --golden a directory", "export --model {model} --data {d}/good.csv --out {d}/out --golden {d}", &["a directory stands where the file should go"]),
        bad("compare --out under a file", "compare --model {model} --data {d}/good.csv --out {d}/good.csv/series --json {d}/out-summary.json", &["good.csv/series", "is a file"]),
        bad("diagnose --out under a file", "diagnose --model {model} --data {d}/good.csv --out {d}/good.csv/plots --json {d}/out-summary.json", &["good.csv/plots", "is a file"]),
        bad("augment --ship under a file", "augment --model {model} --effect bias --data {d}/good.csv --out {d}/out --ship {d}/good.csv/ship.toml", &["good.csv/ship.toml", "is a file"]),
        bad("simulate --save-ship under a file", "simulate --out {d}/out.csv --save-ship {d}/good.csv/ship.toml", &["good.csv/ship.toml", "is a file"]),
        bad("resid --out under a file", "resid --model {model} --data {d}/good.csv --out {d}/good.csv/plots --json {d}/out-summary.json", &["good.csv/plots", "is a file"]),
    ];
    assert!(cases.len() >= 80, "{} cases", cases.len());
    let mut failures = Vec::new();
    for (i, c) in cases.iter().enumerate() {
        let d = root.join(format!("case{i:02}"));
        std::fs::create_dir_all(&d).unwrap();
        for (name, bytes) in &files {
            std::fs::write(d.join(name), bytes).unwrap();
        }
        let model = write_model(&d);
        let args: Vec<String> = c
            .args
            .split_whitespace()
            .map(|a| {
                a.replace("{d}", d.to_str().unwrap())
                    .replace("{model}", model.to_str().unwrap())
            })
            .collect();
        let Some(o) = run_limited(&args, std::time::Duration::from_secs(60)) else {
            failures.push(format!("{}: hangs (over 60 s)", c.name));
            continue;
        };
        let e = stderr(&o);
        if code(&o) != c.code {
            failures.push(format!(
                "{}: exit {} (expected {}): {e}",
                c.name,
                code(&o),
                c.code
            ));
            continue;
        }
        for w in c.expect {
            if !e.contains(w) {
                failures.push(format!("{}: message lacks `{w}`: {e}", c.name));
            }
        }
        if e.contains("panicked") || e.contains("RUST_BACKTRACE") {
            failures.push(format!("{}: panics: {e}", c.name));
        }
        let left: Vec<String> = std::fs::read_dir(&d)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with("out") || n.contains(".tmp"))
            .collect();
        if !left.is_empty() {
            failures.push(format!("{}: left {left:?}", c.name));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases fail:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
