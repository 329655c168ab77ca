//! CLI tests of `yawcast simulate --world`: the test worlds write the same CSV as the
//! built-in ship, are seeded, and refuse the built-in ship's file options.

use std::path::PathBuf;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yawcast"))
        .args(args)
        .output()
        .expect("runs the binary")
}

/// A fresh scratch directory per test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("yawcast-worlds-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Line `k` of a CSV text (0: the header), its fields as numbers.
fn row(csv: &str, k: usize) -> Vec<f64> {
    csv.lines()
        .nth(k)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn simulate(dir: &std::path::Path, file: &str, extra: &[&str]) -> String {
    let out = dir.join(file);
    let path = out.to_str().unwrap().to_string();
    let mut args = vec!["simulate", "--duration", "120", "--out", &path];
    if !extra.contains(&"--seed") {
        args.extend_from_slice(&["--seed", "5"]);
    }
    args.extend_from_slice(extra);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::read_to_string(&out).unwrap()
}

#[test]
fn kvlcc2_writes_the_usual_columns_seeded() {
    let d = scratch("kvlcc2");
    let a = simulate(
        &d,
        "a.csv",
        &["--world", "kvlcc2", "--effect", "wind", "--log-wind"],
    );
    let b = simulate(
        &d,
        "b.csv",
        &["--world", "kvlcc2", "--effect", "wind", "--log-wind"],
    );
    assert_eq!(a, b, "same seed, same bytes");
    let mut lines = a.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,delta_deg,r_degps,psi_deg,u_mps,wind_speed_mps,wind_angle_deg,cog_deg"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    // 120 s at the default 1 s; a full-scale tanker at about 15.5 kn over ground
    assert_eq!(rows.len(), 120);
    assert_eq!(rows[1][0] - rows[0][0], 1.0);
    assert!((7.0..9.0).contains(&rows[0][4]), "{:?}", rows[0]);
    // a 14.7 m/s wind from 045° on a ship making 8 m/s
    assert!((15.0..30.0).contains(&rows[0][5]), "{:?}", rows[0]);
    let c = simulate(&d, "c.csv", &["--world", "kvlcc2", "--seed", "6"]);
    assert_ne!(a.lines().nth(50), c.lines().nth(50));
    // Froude-scaled to the 7 m model: Ts √(7/320) s, speed 1.18 m/s
    let m = simulate(&d, "m.csv", &["--world", "kvlcc2", "--scale", "7"]);
    let r = row(&m, 2);
    assert!((r[0] - (7.0f64 / 320.0).sqrt()).abs() < 1e-6, "{r:?}");
    assert!((1.0..1.4).contains(&r[4]), "{r:?}");
    // the same model at the approach speed asked: its speed over ground starts there
    let js = d.join("s.json");
    let slow = simulate(
        &d,
        "slow.csv",
        &[
            "--world",
            "kvlcc2",
            "--scale",
            "7",
            "--speed",
            "0.6",
            "--json",
            js.to_str().unwrap(),
        ],
    );
    let r = row(&slow, 1);
    assert!((0.55..0.65).contains(&r[4]), "{r:?}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js).unwrap()).unwrap();
    assert_eq!(summary["ship"], "KVLCC2 (MMG, Lpp 7 m) at 0.6 m/s");
    let mar = simulate(
        &d,
        "mar.csv",
        &[
            "--world",
            "mariner",
            "--input",
            "zigzag:10/10",
            "--json",
            js.to_str().unwrap(),
        ],
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js).unwrap()).unwrap();
    assert_eq!(summary["world"], "mariner");
    assert_eq!(summary["ship"], "Mariner (Abkowitz, Lpp 160.93 m)");
    assert_eq!(summary["records"][0]["samples"], 120);
    assert!(mar.starts_with("t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg\n"));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_lng_world_is_the_default() {
    let d = scratch("lng");
    let a = simulate(&d, "a.csv", &["--effect", "current", "--log-wind"]);
    let b = simulate(
        &d,
        "b.csv",
        &["--world", "lng", "--effect", "current", "--log-wind"],
    );
    assert_eq!(a, b);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn ship_files_and_scales_belong_to_their_worlds() {
    let d = scratch("refuse");
    let out = d.join("x.csv");
    let out = out.to_str().unwrap();
    let ship = d.join("s.toml");
    std::fs::write(&ship, "").unwrap();
    let o = run(&[
        "simulate",
        "--world",
        "kvlcc2",
        "--ship",
        ship.to_str().unwrap(),
        "--out",
        out,
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("--ship") && e.contains("--world lng"), "{e}");
    let o = run(&[
        "simulate", "--world", "mariner", "--scale", "7", "--out", out,
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--scale"), "{}", stderr(&o));
    // an approach speed: not on the Mariner, whose equations are written about theirs, and
    // within 0.25–1.5 times a world's design speed, which the message gives
    for (world, speed, says) in [
        ("mariner", "5", "design speed"),
        ("esso-osaka", "20", "design speed of 8.230 m/s"),
        ("lng", "1", "`rps` under `[pods]`"),
    ] {
        let o = run(&["simulate", "--world", world, "--speed", speed, "--out", out]);
        assert_eq!(o.status.code(), Some(2));
        let e = stderr(&o);
        assert!(e.contains("--speed") && e.contains(says), "{e}");
    }
    let o = run(&["simulate", "--world", "titanic", "--out", out]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("lng, kvlcc2, mariner"), "{e}");
    assert!(!std::path::Path::new(out).exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_worlds_own_predictor_is_scored_beside_the_same_record() {
    let d = scratch("oracle");
    let plain = simulate(&d, "p.csv", &["--world", "mariner"]);
    let js = d.join("o.json");
    let with = simulate(
        &d,
        "o.csv",
        &[
            "--world",
            "mariner",
            "--oracle-horizon",
            "10",
            "--json",
            js.to_str().unwrap(),
        ],
    );
    assert_eq!(plain, with, "the record does not change");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js).unwrap()).unwrap();
    assert_eq!(s["oracle_horizon"], 10);
    let fit = s["records"][0]["oracle_fit_pct"].as_f64().unwrap();
    assert!(fit > 50.0 && fit < 100.0, "{fit}");
    // without the flag neither field is written
    let js2 = d.join("p.json");
    simulate(
        &d,
        "p.csv",
        &["--world", "mariner", "--json", js2.to_str().unwrap()],
    );
    let s2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js2).unwrap()).unwrap();
    assert!(s2.get("oracle_horizon").is_none(), "{s2}");
    assert!(s2["records"][0].get("oracle_fit_pct").is_none(), "{s2}");
    // the built-in ship without gyro noise: its own predictor is exact
    let js3 = d.join("l.json");
    simulate(
        &d,
        "l.csv",
        &[
            "--gyro-noise",
            "0",
            "--oracle-horizon",
            "5",
            "--json",
            js3.to_str().unwrap(),
        ],
    );
    let s3: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js3).unwrap()).unwrap();
    assert_eq!(s3["records"][0]["oracle_fit_pct"], 100.0);
    // a horizon as long as the record is named
    let out = d.join("x.csv");
    let o = run(&[
        "simulate",
        "--duration",
        "120",
        "--oracle-horizon",
        "120",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--oracle-horizon 120"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// Three records of KVLCC2 (PRBS, 1 800 s) from seed `seed` in `dir`, named `{name}-{1,2,3}.csv`
/// (their paths returned), with `extra` options.
fn kvlcc2_set(dir: &std::path::Path, name: &str, seed: &str, extra: &[&str]) -> Vec<String> {
    let out = dir.join(format!("{name}.csv"));
    let path = out.to_str().unwrap().to_string();
    let mut args = vec![
        "simulate",
        "--world",
        "kvlcc2",
        "--records",
        "3",
        "--seed",
        seed,
        "--out",
        &path,
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    (1..=3)
        .map(|i| {
            dir.join(format!("{name}-{i}.csv"))
                .to_string_lossy()
                .into_owned()
        })
        .collect()
}

/// The JSON `diagnose` writes on `trials` against `refs` with `model` (seed 1).
fn diagnose_on(
    dir: &std::path::Path,
    model: &str,
    refs: &[String],
    trials: &[String],
) -> serde_json::Value {
    let json = dir.join("diagnose.json").to_string_lossy().into_owned();
    let mut args = vec!["diagnose", "--model", model, "--seed", "1", "--json", &json];
    for r in refs {
        args.extend_from_slice(&["--reference", r]);
    }
    for t in trials {
        args.extend_from_slice(&["--data", t]);
    }
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

#[test]
fn a_reference_that_logs_the_gears_angle_names_the_gear_the_commands_pass() {
    let d = scratch("log-angle");
    // the reference logs the rudder's angle (the gear slews at 2.34 °/s), as a rig's
    // feedback does; the cross-world suite's noise and seeds (`bench/worlds/run.sh
    // --ref-log-angle`, seed 1)
    let refs = kvlcc2_set(
        &d,
        "ref",
        "900",
        &[
            "--log-angle",
            "--gyro-noise",
            "0.02",
            "--heading-noise",
            "0.1",
        ],
    );
    let csv = std::fs::read_to_string(&refs[0]).unwrap();
    let angle: Vec<f64> = (1..=1800).map(|k| row(&csv, k)[1]).collect();
    let largest = angle
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    assert!((largest - 2.34).abs() < 1e-6, "{largest}");
    let model = d.join("ref").to_string_lossy().into_owned();
    let o = run(&[
        "identify", "--data", &refs[0], "--data", &refs[1], "--data", &refs[2], "--out", &model,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let model = format!("{model}.postcard");
    let noise = [
        "--gyro-noise",
        "0.03",
        "--heading-noise",
        "0.2",
        "--speed-noise",
        "0.02",
    ];
    // effect-free trials that log the command: the gear between is what they lack
    let trials = kvlcc2_set(&d, "cmd", "100", &noise);
    let v = diagnose_on(&d, &model, &refs, &trials);
    assert_eq!(v["verdict"], "rate-limit", "{}", v["explanation"]);
    let steps = v["caveats"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["caveat"] == "command-steps")
        .unwrap_or_else(|| panic!("{}", v["caveats"]));
    assert!(steps["trial_step_deg"].as_f64().unwrap() >= 20.0, "{steps}");
    let slew = steps["slew_degps"].as_f64().unwrap();
    assert!((slew - 2.34).abs() < 0.01, "{steps}");
    // the same trials logging the angle too: nothing lacks, and no caveat
    let mut both = noise.to_vec();
    both.push("--log-angle");
    let trials = kvlcc2_set(&d, "angle", "100", &both);
    let v = diagnose_on(&d, &model, &refs, &trials);
    assert_eq!(v["verdict"], "none", "{}", v["explanation"]);
    assert!(
        !v["caveats"].to_string().contains("command-steps"),
        "{}",
        v["caveats"]
    );
    let _ = std::fs::remove_dir_all(&d);
}
