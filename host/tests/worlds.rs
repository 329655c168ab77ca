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
