//! Inputs: help, arguments, CSV and NMEA reading and their errors, records the model cannot use, navigation channels.

use crate::common::*;

#[test]
fn help_lists_every_subcommand() {
    let o = run(&["--help"]);
    assert_eq!(code(&o), 0);
    let out = stdout(&o);
    for c in [
        "simulate", "identify", "tune", "average", "export", "compare", "resid", "diagnose",
        "augment", "demo", "hil", "split",
    ] {
        assert!(
            out.lines().any(|l| l.trim_start().starts_with(c)),
            "`{c}` missing from --help:\n{out}"
        );
    }
}

#[test]
fn bad_arguments_exit_2() {
    let o = run(&["compare", "--no-such-flag"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let o = run(&["no-such-command"]);
    assert_eq!(code(&o), 2);
}

#[test]
fn missing_file_is_bad_input_naming_it() {
    let d = scratch("missing");
    let m = write_model(&d);
    let o = run_compare(m.to_str().unwrap(), "/nonexistent/trial.csv", &[]);
    assert_eq!(code(&o), 2);
    let e = stderr(&o);
    assert!(e.starts_with("error: "), "{e}");
    assert!(e.contains("/nonexistent/trial.csv"), "{e}");
}

#[test]
fn csv_errors_name_file_row_and_column() {
    let d = scratch("csverr");
    let m = write_model(&d);
    let cases: [(&str, String, &[&str]); 3] = [
        (
            "missing.csv",
            "t_s,delta_deg\n0,1\n0.5,1\n".into(),
            &["missing.csv", "missing column `r_degps`"],
        ),
        (
            "nan.csv",
            csv_text(40, 0.5).replacen("\n2.5,", "\n2.5,NaN_", 1),
            &["nan.csv", "row 6", "delta_deg"],
        ),
        (
            // a stamp 1 s late at 0.5 s sampling (jitter within half a period is accepted)
            "nonuniform.csv",
            csv_text(40, 0.5).replacen("\n3,", "\n4,", 1),
            &["nonuniform.csv", "row 7", "uniform", "2 samples missing"],
        ),
    ];
    for (name, text, needles) in cases {
        let f = d.join(name);
        std::fs::write(&f, text).unwrap();
        let o = run_compare(m.to_str().unwrap(), f.to_str().unwrap(), &[]);
        let e = stderr(&o);
        assert_eq!(code(&o), 2, "{name}: {e}");
        let first = e.lines().next().unwrap_or("");
        for n in needles {
            assert!(first.contains(n), "{name}: `{n}` not in first line: {e}");
        }
    }
}

#[test]
fn custom_columns_and_units() {
    let d = scratch("cols");
    let m = write_model(&d);
    // Same data in radians and rad/s under other names: the fit must be identical.
    let deg = csv_text(60, 0.5);
    let mut rad = String::from("time,rudder,rot\n");
    for l in deg.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        rad.push_str(&format!(
            "{},{},{}\n",
            v[0],
            v[1].to_radians(),
            v[2].to_radians()
        ));
    }
    // and as a logger's tab-separated text with ISO 8601 time stamps (not NMEA: no `$`)
    let mut tab = String::from("t_s\tdelta_deg\tr_degps\n");
    for l in deg.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let (min, sec) = ((v[0] / 60.0).floor(), v[0] % 60.0);
        tab.push_str(&format!(
            "2024-05-01T12:{min:02}:{sec:04.1}Z\t{}\t{}\n",
            v[1], v[2]
        ));
    }
    std::fs::write(d.join("deg.csv"), &deg).unwrap();
    std::fs::write(d.join("rad.csv"), rad).unwrap();
    std::fs::write(d.join("tab.txt"), tab).unwrap();
    // and with the other sign convention, read back with --command-scale -1
    let mut flipped = String::from("t_s,delta_deg,r_degps\n");
    for l in deg.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        flipped.push_str(&format!("{},{},{}\n", v[0], -v[1], v[2]));
    }
    std::fs::write(d.join("flipped.csv"), flipped).unwrap();
    let j4 = d.join("flipped.json");
    let j1 = d.join("deg.json");
    let j2 = d.join("rad.json");
    let j3 = d.join("tab.json");
    let compare = |file: &str, extra: &[&str]| {
        let (model, data) = (m.to_str().unwrap(), d.join(file));
        let mut args = vec![
            "compare",
            "--model",
            model,
            "--data",
            data.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert_eq!(code(&o), 0, "{file} {extra:?}: {}", stderr(&o));
    };
    compare("deg.csv", &["--json", j1.to_str().unwrap()]);
    compare(
        "rad.csv",
        &[
            "--col-time",
            "time",
            "--col-delta",
            "rudder",
            "--col-rate",
            "rot",
            "--angle-unit",
            "rad",
            "--rate-unit",
            "radps",
            "--json",
            j2.to_str().unwrap(),
        ],
    );
    compare("tab.txt", &["--json", j3.to_str().unwrap()]);
    compare(
        "flipped.csv",
        &["--command-scale", "-1", "--json", j4.to_str().unwrap()],
    );
    // the speed unit is an option of every reading command (knots, km/h, m/s)
    compare("deg.csv", &["--speed-unit", "kn"]);
    let a: serde_json::Value = serde_json::from_slice(&std::fs::read(j1).unwrap()).unwrap();
    let b: serde_json::Value = serde_json::from_slice(&std::fs::read(j2).unwrap()).unwrap();
    let c: serde_json::Value = serde_json::from_slice(&std::fs::read(j3).unwrap()).unwrap();
    let f: serde_json::Value = serde_json::from_slice(&std::fs::read(j4).unwrap()).unwrap();
    for h in ["1", "5", "10", "20", "sim"] {
        let fa = a["mean_fit"][h].as_f64().unwrap();
        let fb = b["mean_fit"][h].as_f64().unwrap();
        assert!((fa - fb).abs() < 1e-6, "{h}: {fa} vs {fb}");
        assert_eq!(c["mean_fit"][h], a["mean_fit"][h], "{h}");
        assert_eq!(f["mean_fit"][h], a["mean_fit"][h], "{h}");
    }
    // Pinned field names of the compare summary.
    assert_eq!(a["command"], "compare");
    assert!(a["records"][0]["name"].is_string());
    assert!(a["records"][0]["samples"].is_u64());
    assert!(a["records"][0]["fit"]["5"].is_f64());
}

#[test]
fn nmea_logs_are_read_and_their_errors_named() {
    let d = scratch("nmea");
    let p = d.join("m.json");
    std::fs::write(
        &p,
        r#"{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#,
    )
    .unwrap();
    let log = data_dir().join("trial.nmea");
    let o = run_compare(p.to_str().unwrap(), log.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("trial"), "{}", stdout(&o));

    let bad = data_dir().join("trial-bad-checksum.nmea");
    let o = run_compare(p.to_str().unwrap(), bad.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("line 49: bad checksum"),
        "{}",
        stderr(&o)
    );

    let gap = data_dir().join("trial-gap.nmea");
    let o = run_compare(p.to_str().unwrap(), gap.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("gap of 3.50 s in ROT (rate of turn) after 12:00:03.50"),
        "{}",
        stderr(&o)
    );

    // a log with no rate gyro on the bus (no ROT): refused, naming --rate-from-heading;
    // with it the heading's change is the yaw rate
    let sentence = |body: String| {
        let sum = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{sum:02X}\n")
    };
    let mut log = String::new();
    for s in 0..120 {
        log += &sentence(format!(
            "GPZDA,12{:02}{:02}.00,14,06,2024,00,00",
            s / 60,
            s % 60
        ));
        for half in 0..2 {
            let t = s as f64 + 0.5 * half as f64;
            let delta = if (t / 8.0).floor() as i64 % 2 == 0 {
                10.0
            } else {
                -10.0
            };
            log += &sentence(format!("IIRSA,{delta:.1},A,,V"));
            log += &sentence(format!("HEHDT,{:.2},T", 90.0 + 8.0 * (0.15 * t).sin()));
        }
    }
    let no_rot = d.join("no-rot.nmea");
    std::fs::write(&no_rot, log).unwrap();
    let compare =
        |extra: &[&str]| run_compare(p.to_str().unwrap(), no_rot.to_str().unwrap(), extra);
    let o = compare(&[]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("no valid ROT sentence") && stderr(&o).contains("--rate-from-heading"),
        "{}",
        stderr(&o)
    );
    let o = compare(&["--rate-from-heading"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("no-rot"), "{}", stdout(&o));
    // the ROT count is no clock for it
    let o = compare(&["--rate-from-heading", "--nmea-rate", "2"]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("ZDA/RMC clock"), "{}", stderr(&o));
}

#[test]
fn model_and_data_must_agree() {
    let d = scratch("mismatch");
    let m = write_model(&d);
    let f = d.join("ts1.csv");
    std::fs::write(&f, csv_text(60, 1.0)).unwrap();
    let o = run_compare(m.to_str().unwrap(), f.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("sampled every 1 s, the model every 0.5 s"));
    let bad_model = d.join("bad.json");
    std::fs::write(
        &bad_model,
        r#"{"n":2,"ts":0.5,"a":[1.0],"b":[0,0],"k":[0,0]}"#,
    )
    .unwrap();
    let o = run_compare(bad_model.to_str().unwrap(), f.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("bad.json"), "{}", stderr(&o));
}

/// Records that cannot be right are refused before any work, with the file, row and column
/// named, exit 2 and no output written: a corrupted cell (3.4e200, which once made
/// `identify` run forever), a rudder angle of 2e6°, an all-zero trial, a yaw rate stuck at
/// zero, a command that never moves, a duplicated column; and a `;`-separated file with
/// decimal commas is read.
#[test]
fn implausible_or_still_records_are_refused_before_any_work() {
    let d = scratch("plausible");
    let good = csv_text(200, 0.5);
    let mut lines: Vec<String> = good.lines().map(String::from).collect();
    let cases: Vec<(&str, String, &str, &str)> = {
        let mut corrupt = lines.clone();
        corrupt[40] = format!("{},10,3.4e200", 39.0 * 0.5);
        let mut rudder = lines.clone();
        rudder[12] = format!("{},2000000,0.01", 11.0 * 0.5);
        let zero: String = std::iter::once("t_s,delta_deg,r_degps".to_string())
            .chain((0..200).map(|i| format!("{},0,0", f64::from(i) * 0.5)))
            .collect::<Vec<_>>()
            .join("\n");
        let stuck: String = std::iter::once("t_s,delta_deg,r_degps".to_string())
            .chain((0..200).map(|i| {
                let u = if (i / 7) % 2 == 0 { 10 } else { -10 };
                format!("{},{u},0", f64::from(i) * 0.5)
            }))
            .collect::<Vec<_>>()
            .join("\n");
        let mut spike = lines.clone();
        let r: f64 = spike[75].split(',').nth(2).unwrap().parse().unwrap();
        spike[75] = format!("{},10,{}", 74.0 * 0.5, r + 1.0);
        let mut dup = lines.clone();
        dup[0] = "t_s,delta_deg,r_degps,r_degps".into();
        for l in dup.iter_mut().skip(1) {
            l.push_str(",0");
        }
        vec![
            ("corrupt", corrupt.join("\n"), "row 40", "r_degps"),
            ("rudder", rudder.join("\n"), "row 12", "delta_deg"),
            ("zero", zero, "constant", "delta_deg"),
            ("stuck", stuck, "constant", "r_degps"),
            ("dup", dup.join("\n"), "more than once", "r_degps"),
            ("spike", spike.join("\n"), "row 75", "r_degps"),
        ]
    };
    for (name, text, what, col) in &cases {
        let f = d.join(format!("{name}.csv"));
        std::fs::write(&f, text).unwrap();
        let out = d.join(format!("{name}-model"));
        let o = run(&[
            "identify",
            "--data",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let e = stderr(&o);
        assert_eq!(code(&o), 2, "{name}: {e}");
        assert!(e.contains(&format!("{name}.csv")), "{name}: {e}");
        assert!(e.contains(what) && e.contains(col), "{name}: {e}");
        assert!(!out.with_extension("postcard").exists(), "{name}");
        assert!(!out.with_extension("json").exists(), "{name}");
    }
    // A spike is replaced with --despike, which names its row: the fits are the clean
    // record's to within 0.05 pp, where without it the record is refused (above).
    let m = write_model(&d);
    std::fs::write(d.join("clean.csv"), &good).unwrap();
    let fits = |f: &str, extra: &[&str]| -> Vec<f64> {
        let o = run_compare(m.to_str().unwrap(), d.join(f).to_str().unwrap(), extra);
        assert_eq!(code(&o), 0, "{f}: {}", stderr(&o));
        if !extra.is_empty() {
            let e = stderr(&o);
            assert!(e.contains("spike.csv") && e.contains("1 spike(s)"), "{e}");
            assert!(e.contains("rows 75") && e.contains("--despike"), "{e}");
        }
        let last = stdout(&o).lines().last().unwrap().to_string();
        last.split_whitespace()
            .skip(1)
            .map(|v| v.trim_end_matches('%').parse().unwrap())
            .collect()
    };
    let (clean, despiked) = (fits("clean.csv", &[]), fits("spike.csv", &["--despike"]));
    assert_eq!(clean.len(), despiked.len());
    assert!(!clean.is_empty());
    for (a, b) in clean.iter().zip(&despiked) {
        assert!((a - b).abs() < 0.05, "{clean:?} {despiked:?}");
    }
    // The limit is the user's to raise (a positive number).
    let f = d.join("rudder.csv");
    let o = run(&[
        "compare",
        "--model",
        m.to_str().unwrap(),
        "--data",
        f.to_str().unwrap(),
        "--max-angle",
        "3e6",
    ]);
    // Read now, the 2e6° command drives the model's prediction far off: a numerical failure
    // naming the record (exit 1), never a fit of −1e6 % printed as a result.
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("rudder.csv") && stderr(&o).contains("diverges"),
        "{}",
        stderr(&o)
    );
    assert!(!stdout(&o).contains("fit@"), "{}", stdout(&o));
    let o = run(&[
        "compare",
        "--model",
        m.to_str().unwrap(),
        "--data",
        f.to_str().unwrap(),
        "--max-angle",
        "-1",
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-angle"), "{}", stderr(&o));
    // A `;`-separated file with decimal commas reads as its comma twin.
    lines[0] = "t_s;delta_deg;r_degps".into();
    for l in lines.iter_mut().skip(1) {
        *l = l.replace(',', ";").replace('.', ",");
    }
    std::fs::write(d.join("semi.csv"), lines.join("\n")).unwrap();
    std::fs::write(d.join("comma.csv"), &good).unwrap();
    let fits: Vec<String> = ["semi.csv", "comma.csv"]
        .iter()
        .map(|f| {
            let o = run_compare(m.to_str().unwrap(), d.join(f).to_str().unwrap(), &[]);
            assert_eq!(code(&o), 0, "{f}: {}", stderr(&o));
            stdout(&o)
                .lines()
                .last()
                .unwrap()
                .split_whitespace()
                .skip(1)
                .collect()
        })
        .collect();
    assert_eq!(fits[0], fits[1]);
}

/// A horizon as long as the record is bad input, named with the record, and nothing is written.
#[test]
fn compare_refuses_horizons_as_long_as_the_record() {
    let d = scratch("diverge");
    let m = write_model(&d);
    let f = d.join("r.csv");
    std::fs::write(&f, csv_text(200, 0.5)).unwrap();
    let args = |h: &str| {
        vec![
            "compare".to_string(),
            "--model".into(),
            m.to_str().unwrap().into(),
            "--data".into(),
            f.to_str().unwrap().into(),
            "--horizons".into(),
            h.into(),
            "--json".into(),
            d.join("c.json").to_str().unwrap().into(),
        ]
    };
    let argv = args("5000");
    let o = run(&argv.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("r.csv") && stderr(&o).contains("5000"),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("c.json").exists());
}

/// Settings that cannot be honoured are bad input named before any work: a focus horizon
/// longer than a quarter of a record, a hardware-in-the-loop run of no step, and a tuning
/// record too short to score (found before the GA, not after it).
#[test]
fn settings_the_records_cannot_hold_are_refused_up_front() {
    let d = scratch("settings");
    let f = d.join("s.csv");
    std::fs::write(&f, csv4(300, 1, 0.02)).unwrap();
    let short = d.join("short.csv");
    std::fs::write(&short, csv4(30, 2, 0.02)).unwrap();
    let (fs, ss) = (f.to_str().unwrap(), short.to_str().unwrap());
    let o = run(&["identify", "--data", fs, "--focus", "5000"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("s.csv") && stderr(&o).contains("--focus 5000"));
    let m = write_model(&d);
    let o = run(&["hil", "--model", m.to_str().unwrap(), "--steps", "0"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("--steps 0"), "{}", stderr(&o));
    let o = run(&["tune", "--data", fs, "--validate", ss, "--seed", "1"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("short.csv") && stderr(&o).contains("30 samples"));
    // Refused on reading, before the starting model is identified.
    assert!(!stderr(&o).contains("generation"), "{}", stderr(&o));
}

/// A `.json` model passes the checks a `.postcard` blob gets: huge coefficients and an
/// unstable predictor are refused with the file named (exit 2), before any record is read.
#[test]
fn json_models_pass_the_checks_a_blob_gets() {
    let d = scratch("jsonmodel");
    let f = d.join("r.csv");
    std::fs::write(&f, csv_text(200, 0.5)).unwrap();
    for (name, text) in [
        (
            "huge.json",
            r#"{"n":2,"ts":0.5,"a":[1e308,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#,
        ),
        (
            "unstable.json",
            r#"{"n":2,"ts":0.5,"a":[0.0,1.3],"b":[0.01,0.02],"k":[0.0,0.0],"effects":[]}"#,
        ),
    ] {
        let m = d.join(name);
        std::fs::write(&m, text).unwrap();
        let o = run_compare(m.to_str().unwrap(), f.to_str().unwrap(), &[]);
        assert_eq!(code(&o), 2, "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(name), "{name}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{name}: {}", stdout(&o));
    }
}

/// Bad navigation input names its file, row and column; a position jump of kilometres and a
/// NaN fix are skipped and counted, never followed.
#[test]
fn navigation_input_errors_name_row_and_column_and_jumps_are_counted() {
    let d = scratch("nav-input");
    // a model with a heading/track part (no current), as identify writes it into the twin
    let m = d.join("m.json");
    std::fs::write(
        &m,
        r#"{"model":{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]},
           "track":{"speed":1.0,"sway":0.0,"speed_loss":0.0,"current":false,"gain_speed":0.05,
                    "gain_current":0.0,"gain_position":0.5,"fix_speed":0.02,"fix_current":0.0,
                    "gate_velocity":3.0,"gate_position":200.0}}"#,
    )
    .unwrap();
    let mut rows = String::from("t_s,delta_deg,r_degps,psi_deg,u_mps,cog_deg,north_m,east_m\n");
    for (i, line) in csv_text(400, 0.5).lines().skip(1).enumerate() {
        let n = 0.5 * i as f64;
        let (north, east) = match i {
            150 => ("5000".to_string(), "0".to_string()),
            200 => ("NaN".to_string(), "0".to_string()),
            _ => (format!("{n}"), "0".to_string()),
        };
        rows.push_str(&format!(
            "{line},0,1.0,{},{north},{east}\n",
            if i % 2 == 0 { 359.5 } else { 0.5 }
        ));
    }
    std::fs::write(d.join("nav.csv"), &rows).unwrap();
    let js = d.join("c.json");
    let o = run(&[
        "compare",
        "--model",
        m.to_str().unwrap(),
        "--data",
        d.join("nav.csv").to_str().unwrap(),
        "--json",
        js.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2 navigation correction(s) skipped"),
        "{}",
        stderr(&o)
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js).unwrap()).unwrap();
    let r = &j["records"][0];
    assert_eq!(r["nav_skipped"]["fix_gated"], 1);
    assert_eq!(r["nav_skipped"]["fix_rejected"], 1);
    assert_eq!(r["nav_skipped"]["velocity_gated"], 0);
    // straight north at 1 m/s: the track prediction follows it (the jump is not followed)
    let e30 = r["track_error_m"]["30"].as_f64().unwrap();
    assert!(e30 < 1.0, "median 30-s track error {e30} m");
    // (a constant heading has no spread to score a fit against, but the key is there)
    assert!(r["heading_fit"].is_object());
    // export carries the track part into a format 3 blob and the twin
    let o = run(&[
        "export",
        "--model",
        m.to_str().unwrap(),
        "--data",
        d.join("nav.csv").to_str().unwrap(),
        "--out",
        d.join("exp").to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let blob = std::fs::read(d.join("exp.postcard")).unwrap();
    assert_eq!(&blob[4..6], &[3, 0]);
    let twin: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("exp.json")).unwrap()).unwrap();
    assert_eq!(twin["blob_format_version"], 3);
    assert_eq!(twin["track"]["gate_position"], 200.0);
    // bad cells: the error names file, row and column
    for (name, header, cell, want) in [
        (
            "neg.csv",
            "u_mps,cog_deg",
            "-0.5,10",
            "row 3, column `u_mps`: speed over ground -0.5 m/s is negative",
        ),
        (
            "text.csv",
            "u_mps,cog_deg",
            "1.0,north",
            "row 3, column `cog_deg`: expected a number (or an empty cell), found `north`",
        ),
        (
            "lat.csv",
            "lat_deg,lon_deg",
            "95,10",
            "row 3, column `lat_deg`: latitude 95 is outside ±90°",
        ),
        (
            "half.csv",
            "north_m",
            "1",
            "column `north_m` is there but `east_m` is not",
        ),
    ] {
        let mut t = String::new();
        for (i, line) in csv_text(300, 0.5).lines().enumerate() {
            let extra = match i {
                0 => header.to_string(),
                3 => cell.to_string(),
                _ => cell
                    .replace("-0.5", "1.0")
                    .replace("north", "10")
                    .replace("95", "60"),
            };
            t.push_str(&format!("{line},{extra}\n"));
        }
        let p = d.join(name);
        std::fs::write(&p, t).unwrap();
        let o = run_compare(m.to_str().unwrap(), p.to_str().unwrap(), &[]);
        assert_eq!(code(&o), 2, "{name}: {}", stderr(&o));
        let first = stderr(&o).lines().next().unwrap_or_default().to_string();
        assert!(
            first.starts_with("error: ") && first.contains(name),
            "{name}: {first}"
        );
        assert!(first.contains(want), "{name}: {first}");
    }
}

#[test]
fn split_cuts_a_log_at_its_gaps_and_clock_restarts_into_records_read_whole() {
    let d = scratch("split");
    let m = write_model(&d);
    // one logger file: 200 rows, 5 missing, 395 rows; a second run from t = 0 (300 rows);
    // 20 samples missing, then a 50-row fragment
    let run1: Vec<String> = csv_text(600, 0.5).lines().map(str::to_string).collect();
    let run2: Vec<String> = csv_text(300, 0.5).lines().map(str::to_string).collect();
    let mut rows: Vec<String> = run1[1..=200].to_vec();
    rows.extend_from_slice(&run1[206..]);
    rows.extend_from_slice(&run2[1..]);
    for i in 0..50 {
        rows.push(format!("{},10,0.1", 160.0 + 0.5 * i as f64));
    }
    let header = &run1[0];
    let log = d.join("log.csv");
    std::fs::write(&log, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
    let o = run_compare(m.to_str().unwrap(), log.to_str().unwrap(), &[]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("row 201") && stderr(&o).contains("yawcast split"),
        "{}",
        stderr(&o)
    );
    let (out, json) = (d.join("pieces"), d.join("split.json"));
    let o = run(&[
        "split",
        "--data",
        log.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("before row 201: a gap of 3.000 s (5 samples missing)")
            && text.contains("before row 596: the clock goes back 299.500 s")
            && text.contains("left out: rows 896–945 (50 samples"),
        "{text}"
    );
    // the pieces hold the header and their rows byte for byte
    let piece = |k: usize| std::fs::read_to_string(out.join(format!("log_{k}.csv"))).unwrap();
    let want = |r: &[String]| format!("{header}\n{}\n", r.join("\n"));
    assert_eq!(piece(1), want(&rows[..200]));
    assert_eq!(piece(2), want(&rows[200..595]));
    assert_eq!(piece(3), want(&rows[595..895]));
    assert!(!out.join("log_4.csv").exists());
    for k in 1..=3 {
        let p = out.join(format!("log_{k}.csv"));
        let o = run_compare(m.to_str().unwrap(), p.to_str().unwrap(), &[]);
        assert_eq!(code(&o), 0, "piece {k}: {}", stderr(&o));
    }
    // the summary's field names are a contract
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(v["min_samples"], 100);
    let f = &v["files"][0];
    assert_eq!(f["data"], log.to_str().unwrap());
    assert_eq!(f["period_s"], 0.5);
    let breaks: Vec<(u64, &str, f64)> = f["breaks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            (
                b["row"].as_u64().unwrap(),
                b["kind"].as_str().unwrap(),
                b["step_s"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        breaks,
        vec![
            (201, "gap", 3.0),
            (596, "clock-back", -299.5),
            (896, "gap", 10.5)
        ]
    );
    let pieces = f["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 4);
    assert_eq!(pieces[1]["file"], out.join("log_2.csv").to_str().unwrap());
    assert_eq!(
        (
            &pieces[1]["first_row"],
            &pieces[1]["rows"],
            &pieces[1]["start_s"],
            &pieces[1]["duration_s"]
        ),
        (
            &serde_json::json!(201),
            &serde_json::json!(395),
            &serde_json::json!(102.5),
            &serde_json::json!(197.0)
        )
    );
    assert!(pieces[3]["file"].is_null());
    // NMEA logs are not tables
    let nmea = data_dir().join("trial.nmea");
    let o = run(&[
        "split",
        "--data",
        nmea.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("NMEA"), "{}", stderr(&o));
}
