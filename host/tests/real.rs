//! Measured records: free-running zig-zags of the 3.0 m Esso Osaka model (Osaka University's
//! Inukai pond, FRT-DS-ESSO, CC BY-NC-SA 4.0; `tests/data/real/esso_osaka/PROVENANCE.md`),
//! run through the CLI: identify → compare on held-out records → diagnose → augment.
//!
//! Two references. First the rig itself: the model is identified on the ±15° and one ±20°
//! zig-zag and the trials are the other ±20° and the ±30° zig-zag of the same day, hull,
//! propeller revolutions (12 rps) and sampling (0.4 s), and `diagnose` answers what the
//! larger zig-zags show that the smaller ones lack. Then a simulator of the same hull
//! (`simulate --world esso-osaka --scale 3 --speed 0.3`: the records' length and speed)
//! sailing the same zig-zags in a calm, against which the four records must show the wind
//! the pond's anemometer measured, as the source itself derived it.
//!
//! The floors below are the figures the pipeline gave on these records, less a margin; the
//! diagnosis is run under three seeds and only what held under five (1–5) is asserted.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/real/esso_osaka")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("yawcast-real-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_yawcast"))
        .args(args)
        .output()
        .expect("runs the binary");
    assert!(
        o.status.success(),
        "yawcast {}\nstdout:\n{}\nstderr:\n{}",
        args.join(" "),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn json(p: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

fn fit(v: &Value, horizon: &str) -> f64 {
    v[horizon]
        .as_f64()
        .unwrap_or_else(|| panic!("no fit at {horizon}: {v}"))
}

const REFERENCE: [&str; 2] = ["zz15_n12.csv", "zz20_n12_a.csv"];
const TRIALS: [&str; 2] = ["zz30_n12.csv", "zz20_n12_b.csv"];

/// Rows of a converted record: (t, δ, r).
fn rows(name: &str) -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(data(name)).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,delta_deg,r_degps,psi_deg,u_mps,wind_speed_mps,wind_angle_deg,cog_deg"
    );
    lines
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (c[0], c[1], c[2])
        })
        .collect()
}

/// The records are what the source documents: its zig-zag amplitudes (in degrees, so the
/// units were converted), uniform 0.4 s sampling, and a positive rudder angle turning the
/// ship to starboard, yawcast's convention.
#[test]
fn records_match_the_documented_zigzags() {
    for (name, amplitude) in [
        ("zz15_n12.csv", 15.0),
        ("zz20_n12_a.csv", 20.0),
        ("zz20_n12_b.csv", 20.0),
        ("zz30_n12.csv", 30.0),
    ] {
        let r = rows(name);
        assert!(r.len() >= 200, "{name}: {} rows", r.len());
        for (k, &(t, _, _)) in r.iter().enumerate() {
            assert!(
                (t - 0.4 * k as f64).abs() < 1e-6,
                "{name}: t = {t} at row {k}"
            );
        }
        let mut held: Vec<f64> = r
            .iter()
            .map(|&(_, d, _)| d.abs())
            .filter(|&d| d >= 0.5 * amplitude)
            .collect();
        held.sort_by(f64::total_cmp);
        let median = held[held.len() / 2];
        assert!(
            (median - amplitude).abs() < 1.0,
            "{name}: zig-zag rudder {median:.2}°, documented ±{amplitude}°"
        );
        let (mut c, mut n) = (0.0, 0.0);
        for &(_, d, y) in &r {
            c += d * y;
            n += d * d;
        }
        assert!(c / n > 0.0, "{name}: rudder and yaw rate of opposite signs");
    }
}

#[test]
fn identify_compare_diagnose_augment_on_measured_zigzags() {
    let dir = scratch("pipeline");
    let model = dir.join("ref");
    let model_blob = dir.join("ref.postcard");
    let mut args: Vec<String> = vec!["identify".into()];
    for r in REFERENCE {
        args.extend(["--data".into(), data(r)]);
    }
    for t in TRIALS {
        args.extend(["--validate".into(), data(t)]);
    }
    args.extend([
        "--out".into(),
        model.to_string_lossy().into_owned(),
        "--json".into(),
        dir.join("identify.json").to_string_lossy().into_owned(),
    ]);
    run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let id = json(&dir.join("identify.json"));
    assert_eq!(id["order"], 4);

    // Held-out records, per record. Measured: 1 step 99.95 / 99.97 %, 5 steps 96.84 / 97.80 %,
    // 10 steps 81.12 / 83.80 % (zz20_n12_b / zz30_n12); mean 10 steps 82.46 %.
    let cmp_json = dir.join("compare.json");
    let mut args: Vec<String> = vec![
        "compare".into(),
        "--model".into(),
        model_blob.to_string_lossy().into_owned(),
    ];
    for t in TRIALS {
        args.extend(["--data".into(), data(t)]);
    }
    args.extend(["--json".into(), cmp_json.to_string_lossy().into_owned()]);
    run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let cmp = json(&cmp_json);
    for rec in cmp["records"].as_array().unwrap() {
        let name = rec["name"].as_str().unwrap();
        assert!(fit(&rec["fit"], "1") > 99.0, "{name}: {}", rec["fit"]);
        assert!(fit(&rec["fit"], "5") > 93.0, "{name}: {}", rec["fit"]);
        assert!(fit(&rec["fit"], "10") > 75.0, "{name}: {}", rec["fit"]);
    }
    assert!(fit(&cmp["mean_fit"], "10") > 78.0, "{}", cmp["mean_fit"]);

    // The trials against the reference records, three seeds.
    for seed in ["1", "2", "3"] {
        let diag_json = dir.join(format!("diagnose-{seed}.json"));
        let mut args: Vec<String> = vec![
            "diagnose".into(),
            "--model".into(),
            model_blob.to_string_lossy().into_owned(),
        ];
        for r in REFERENCE {
            args.extend(["--reference".into(), data(r)]);
        }
        for t in TRIALS {
            args.extend(["--data".into(), data(t)]);
        }
        args.extend([
            "--seed".into(),
            seed.into(),
            "--json".into(),
            diag_json.to_string_lossy().into_owned(),
        ]);
        run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let d = json(&diag_json);
        let verdict = d["verdict"].as_str().unwrap().to_string();
        let ranking = d["ranking"].as_array().unwrap();
        let named: Vec<&str> = ranking
            .iter()
            .filter(|r| r["significant"] == true && r["material"] == true)
            .map(|r| r["effect"].as_str().unwrap())
            .collect();
        // The verdict agrees with the table printed beside it.
        if verdict == "none" {
            assert!(named.is_empty(), "seed {seed}: verdict none but {named:?}");
        } else {
            assert!(
                named.contains(&verdict.as_str()),
                "seed {seed}: verdict {verdict} not significant and material in {named:?}"
            );
        }
        // Measured under seeds 1–5: `none` (1, 5) or `asymmetry` (2–4); the asymmetry's
        // bootstrap p straddles α = 0.01 (starboard rudder 38 % less effective on the
        // trials, which a single-screw hull can show; its held-out gain is +0.03 pp).
        assert!(
            verdict == "none" || verdict == "asymmetry",
            "seed {seed}: verdict {verdict}: {}",
            d["explanation"]
        );
        // Held-out fit of the reference model on the trials' last part. Measured: 83.40 %.
        assert!(
            fit(&d["before"]["fit"], "10") > 78.0,
            "{}",
            d["before"]["fit"]
        );

        // augment --effect auto runs the same diagnosis and follows it.
        let out = dir.join(format!("aug-{seed}"));
        let aug_json = dir.join(format!("augment-{seed}-report.json"));
        let mut args: Vec<String> = vec![
            "augment".into(),
            "--model".into(),
            model_blob.to_string_lossy().into_owned(),
            "--effect".into(),
            "auto".into(),
        ];
        for r in REFERENCE {
            args.extend(["--reference".into(), data(r)]);
        }
        for t in TRIALS {
            args.extend(["--data".into(), data(t)]);
        }
        args.extend([
            "--seed".into(),
            seed.into(),
            "--out".into(),
            out.to_string_lossy().into_owned(),
            "--json".into(),
            aug_json.to_string_lossy().into_owned(),
        ]);
        run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let a = json(&aug_json);
        assert_eq!(a["effect"].as_str().unwrap(), verdict, "seed {seed}");
        assert!(dir.join(format!("aug-{seed}.postcard")).exists());
        if a["kept"] == true {
            assert!(a["fit_gain_pp"].as_f64().unwrap() > 0.0, "seed {seed}: {a}");
        } else {
            // Measured: never kept here (ΔBIC ≥ 0: the Kalman gain already re-anchors the
            // prediction on the measured yaw rate); the input model is written unchanged, or
            // re-identified, or with the ship's own physics the reference records show —
            // which the text then says.
            let w = a["written"].as_str().unwrap();
            let why = a["explanation"].as_str().unwrap();
            assert!(
                w == "input"
                    || w == "refit"
                    || (w == "augmented" && why.contains("the ship's own physics")),
                "seed {seed}: written {w}: {why}"
            );
        }
    }

    // The search for the best predictor over the whole library keeps an effect only where the
    // held-out records pay for it. Measured: one round, none kept (closest: wind +0.27 pp and
    // current +0.26 pp at 10 steps, ΔBIC +18.9).
    let more_json = dir.join("more-report.json");
    let mut args: Vec<String> = vec![
        "augment".into(),
        "--model".into(),
        model_blob.to_string_lossy().into_owned(),
        "--effect".into(),
        "none".into(),
        "--more".into(),
    ];
    for t in TRIALS {
        args.extend(["--data".into(), data(t)]);
    }
    args.extend([
        "--seed".into(),
        "1".into(),
        "--out".into(),
        dir.join("more").to_string_lossy().into_owned(),
        "--json".into(),
        more_json.to_string_lossy().into_owned(),
    ]);
    run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let m = json(&more_json);
    let added: Vec<&str> = m["more"]["added"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap())
        .collect();
    for round in m["more"]["rounds"].as_array().unwrap() {
        for t in round["tried"].as_array().unwrap() {
            if t["kept"] == true {
                assert!(t["fit_gain_pp"].as_f64().unwrap() > 0.0, "{t}");
                assert!(added.contains(&t["effect"].as_str().unwrap()), "{t}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The source's own true wind (`wind_velo_true`, `wind_dir_true`) over the rows kept of all
/// four records, as a mean vector: speed (m/s) and the direction it comes from (deg, the
/// heading's frame). Printed by `bench/real/esso_osaka.py`; documented in PROVENANCE.md.
const SOURCE_TRUE_WIND: (f64, f64) = (1.466, 277.6);

/// The speed and direction of the true wind `diagnose` writes in the wind's evidence
/// ("the anemometer shows a true wind of S m/s from D°").
fn true_wind_words(evidence: &str) -> (f64, f64) {
    let rest = evidence
        .split("the anemometer shows a true wind of ")
        .nth(1)
        .unwrap_or_else(|| panic!("no true wind in {evidence}"));
    let (speed, rest) = rest.split_once(" m/s from ").unwrap();
    let from = rest.split('°').next().unwrap();
    (speed.parse().unwrap(), from.parse().unwrap())
}

/// The simulator reference of the pond records in `dir` (`ref-{1,2,3}.csv`, the model
/// `ref.postcard`): the hull at the model's 3.0 m, at approach speed `speed` m/s (`None`: its
/// design speed), the records' three amplitudes, their length and sampling, in a calm, its
/// anemometer logged.
fn simulator_reference(dir: &Path, speed: Option<&str>) {
    let path = |n: &str| dir.join(n).to_string_lossy().into_owned();
    for (i, z) in ["15/15", "20/20", "30/30"].iter().enumerate() {
        let seed = (i + 1).to_string();
        let input = format!("zigzag:{z}");
        let out = path(&format!("ref-{seed}.csv"));
        let mut args = vec!["simulate", "--world", "esso-osaka", "--scale", "3"];
        if let Some(u) = speed {
            args.extend(["--speed", u]);
        }
        args.extend([
            "--input",
            &input,
            "--duration",
            "120",
            "--ts",
            "0.4",
            "--log-wind",
            "--seed",
            &seed,
            "--out",
            &out,
        ]);
        run(&args);
    }
    run(&[
        "identify",
        "--data",
        &path("ref-1.csv"),
        "--data",
        &path("ref-2.csv"),
        "--validate",
        &path("ref-3.csv"),
        "--out",
        &path("ref"),
    ]);
}

/// `args` with the simulator reference in `dir` ([`simulator_reference`]) and the four pond
/// records as trials.
fn with_pond(dir: &Path, mut args: Vec<String>) -> Vec<String> {
    let path = |n: &str| dir.join(n).to_string_lossy().into_owned();
    for i in 1..=3 {
        args.extend(["--reference".into(), path(&format!("ref-{i}.csv"))]);
    }
    for t in [
        "zz30_n12.csv",
        "zz20_n12_b.csv",
        "zz15_n12.csv",
        "zz20_n12_a.csv",
    ] {
        args.extend(["--data".into(), data(t)]);
    }
    args
}

#[test]
fn against_a_simulator_of_the_hull_the_trials_show_the_wind_the_pond_measured() {
    let dir = scratch("simulator");
    let path = |n: &str| dir.join(n).to_string_lossy().into_owned();
    // The reference: the hull at the model's 3.0 m and the records' 0.3 m/s (their speed
    // over the zig-zags: 0.27–0.35 m/s on average).
    simulator_reference(&dir, Some("0.3"));
    let with_records = |args: Vec<String>| with_pond(&dir, args);
    for seed in ["1", "2", "3"] {
        let out = path(&format!("diagnose-{seed}.json"));
        let args = with_records(vec![
            "diagnose".into(),
            "--model".into(),
            path("ref.postcard"),
        ]);
        let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
        args.extend(["--seed", seed, "--json", &out]);
        run(&args);
        let d = json(Path::new(&out));
        // Measured under seeds 1–5: the verdict wind, then nothing or a port/starboard
        // asymmetry (starboard helm acting harder than in the simulator: a single screw).
        assert_eq!(d["verdict"], "wind", "seed {seed}: {}", d["explanation"]);
        // sailed at the records' speed: no other speed is said
        assert!(other_speed(&d).is_none(), "seed {seed}: {}", d["caveats"]);
        assert!(
            d["then"].is_null() || d["then"] == "asymmetry",
            "seed {seed}: then {}",
            d["then"]
        );
        let wind = ranked(&d, "wind");
        assert_eq!(wind["significant"], true, "{wind}");
        assert_eq!(wind["material"], true, "{wind}");
        // The true wind the anemometer channel reads (ground velocity less the apparent
        // wind, trials less the calm reference) is the source's own: measured 1.467 ±
        // 0.106 m/s from 278° against the source's 1.466 m/s from 277.6°. The two agree to
        // the CSVs' rounding only if the angle conventions (relative wind clockwise from the
        // bow, the direction it comes from; course over ground in the heading's frame) are
        // read as the source means them.
        let speed = wind["parameter"].as_f64().unwrap();
        let se = wind["parameter_uncertainty"].as_f64().unwrap();
        let (said, from) = true_wind_words(wind["evidence"].as_str().unwrap());
        assert!((speed - SOURCE_TRUE_WIND.0).abs() < 0.02, "{speed} m/s");
        assert!((said - speed).abs() < 0.006, "{said} against {speed}");
        assert!(se > 0.0 && se < 0.2, "{se}");
        let off = (from - SOURCE_TRUE_WIND.1 + 180.0).rem_euclid(360.0) - 180.0;
        assert!(off.abs() < 2.0, "from {from}°");
    }
    // augment --effect auto: on zig-zags that each hold one course the wind's moment cannot
    // be told from the manoeuvre's own (measured: a refit of 1179° of rudder, simulation fit
    // 1.0 → −52.6 %), so it is not kept; the model written carries the simulator gear's slew
    // limit the reference records show (21.5 °/s), and says so.
    let report = path("augment-report.json");
    let args = with_records(vec![
        "augment".into(),
        "--model".into(),
        path("ref.postcard"),
        "--effect".into(),
        "auto".into(),
        "--seed".into(),
        "1".into(),
        "--out".into(),
        path("aug"),
        "--json".into(),
        report.clone(),
    ]);
    run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let a = json(Path::new(&report));
    assert_eq!(a["effect"], "wind", "{a}");
    assert_eq!(a["kept"], false, "{a}");
    assert_eq!(a["written"], "augmented", "{a}");
    assert_eq!(a["effects"], serde_json::json!(["rate-limit"]), "{a}");
    assert!(
        a["explanation"]
            .as_str()
            .unwrap()
            .ends_with("it carries the ship's own physics the reference records show."),
        "{}",
        a["explanation"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The row of `effect` in a diagnosis' ranking.
fn ranked<'a>(d: &'a Value, effect: &str) -> &'a Value {
    d["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["effect"] == effect)
        .unwrap_or_else(|| panic!("no {effect} ranked: {}", d["ranking"]))
}

/// The caveat `name` of a diagnosis, if it has one.
fn caveat<'a>(d: &'a Value, name: &str) -> Option<&'a Value> {
    d["caveats"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["caveat"] == name)
}

/// The `other-speed` caveat of a diagnosis, if it has one.
fn other_speed(d: &Value) -> Option<&Value> {
    caveat(d, "other-speed")
}

#[test]
fn against_a_simulator_at_its_design_speed_the_trials_are_diagnosed_at_their_own_speed() {
    // The same reference sailed at the hull's design speed (0.72 m/s at 3 m), more than
    // twice the records'. On zig-zags that each hold one course the ground track cannot
    // tell that from a current along the course (it resolves one only from about 2 m/s
    // on), so the caveat says both readings and names the speed to sail the reference at.
    // How the hull answers the helm tells them apart: the reference re-timed to the
    // trials' speed by similarity predicts them far better, which a current would not, and
    // the diagnosis is measured against it.
    let dir = scratch("design-speed");
    let path = |n: &str| dir.join(n).to_string_lossy().into_owned();
    simulator_reference(&dir, None);
    let out = path("diagnose.json");
    let args = with_pond(
        &dir,
        vec!["diagnose".into(), "--model".into(), path("ref.postcard")],
    );
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    args.extend(["--seed", "1", "--json", &out]);
    run(&args);
    let d = json(Path::new(&out));
    // measured: trials 0.259 m/s over the ground on their courses, the reference 0.757
    let c = other_speed(&d).unwrap_or_else(|| panic!("no other speed: {}", d["caveats"]));
    let t = c["trials_mps"].as_f64().unwrap();
    let r = c["reference_mps"].as_f64().unwrap();
    assert!((0.22..0.32).contains(&t), "{c}");
    assert!((0.65..0.8).contains(&r), "{c}");
    assert_eq!(c["told_from_current"], false, "{c}");
    let words = d["explanation"].as_str().unwrap();
    assert!(
        words.contains("another speed through the water, or a current of about"),
        "{words}"
    );
    assert!(words.contains("`simulate --speed 0.2"), "{words}");
    // measured: the re-timed reference predicts the trials 10 steps ahead at 70.1 %
    // against 37.0 % for the model given
    let s = caveat(&d, "speed-similar").unwrap_or_else(|| panic!("not re-timed: {}", d["caveats"]));
    assert_eq!(s["shows_speed"], true, "{s}");
    assert!((s["ratio"].as_f64().unwrap() - t / r).abs() < 1e-12, "{s}");
    let [given, similar] = ["fit_10_given_pct", "fit_10_similar_pct"].map(|k| fit(s, k));
    assert!(given < 45.0 && similar > 65.0, "{s}");
    assert!(
        words.contains("so the trials ran at another speed through the water"),
        "{words}"
    );
    // so the statistics are measured against the reference at the trials' speed, where the
    // verdict is the wind the pond measured, as against the simulator sailed at 0.3 m/s;
    // against the reference as given it was an angle limit, the speed's own mimic
    // (measured: `saturation, then wind`)
    let at = caveat(&d, "at-trials-speed")
        .unwrap_or_else(|| panic!("not diagnosed at the trials' speed: {}", d["caveats"]));
    assert_eq!(at["ratio"], s["ratio"], "{at}");
    assert_eq!(at["verdict_as_given"], "saturation", "{at}");
    assert_eq!(at["then_as_given"], "wind", "{at}");
    assert_eq!(d["verdict"], "wind", "{}", d["explanation"]);
    assert!(
        words.contains("So every statistic is measured against the reference re-timed"),
        "{words}"
    );
    // the wind the anemometer shows does not depend on the reference's speed: the source's
    let wind = ranked(&d, "wind");
    assert_eq!(wind["significant"], true, "{wind}");
    assert_eq!(wind["material"], true, "{wind}");
    let speed = wind["parameter"].as_f64().unwrap();
    assert!((speed - SOURCE_TRUE_WIND.0).abs() < 0.02, "{speed} m/s");
    let _ = std::fs::remove_dir_all(&dir);
}
