//! Unit tests of the measurement records, the CSV, the checks and the atomic writer.

use std::path::Path;

use super::csv_file::Dialect;
use super::*;

fn parse(txt: &str) -> Result<Record, DataError> {
    parse_csv(txt, Path::new("f.csv"), "f", &Columns::default())
}

#[test]
fn reads_optional_columns() {
    let r =
        parse("t_s,delta_deg,r_degps,psi_deg,u_mps\n0,1,0,10,1.5\n0.5,1,0.1,10.1,1.5\n").unwrap();
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.psi, Some(vec![10.0, 10.1]));
    assert_eq!(r.speed, Some(vec![1.5, 1.5]));
    assert!(r.wind_speed.is_none());
}

#[test]
fn course_over_ground_has_holes_not_errors() {
    // a GPS drop-out leaves the course empty or NaN: missing, kept as NaN
    let txt =
        "t_s,delta_deg,r_degps,u_mps,cog_deg\n0,1,0,2,359\n1,1,0,2,\n2,1,0,2,NaN\n3,1,0,2,1\n";
    let r = parse(txt).unwrap();
    let c = r.cog.as_ref().unwrap();
    assert_eq!(c[0], 359.0);
    assert!(c[1].is_nan() && c[2].is_nan());
    assert_eq!(c[3], 1.0);
    // degrees whatever --angle-unit says (as the navigation reader takes it)
    let rad = Columns {
        angle_scale: 180.0 / std::f64::consts::PI,
        ..Columns::default()
    };
    let r2 = parse_csv(txt, Path::new("f.csv"), "f", &rad).unwrap();
    assert_eq!(r2.cog.as_ref().unwrap()[3], 1.0);
    // text that is not a number is still an error naming row and column
    let e = parse("t_s,delta_deg,r_degps,cog_deg\n0,1,0,1\n1,1,0,east\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 2") && e.contains("cog_deg") && e.contains("east"),
        "{e}"
    );
    // written and read back, holes included
    let back = parse(&csv_text(&r)).unwrap();
    assert_eq!(back.cog.as_ref().unwrap()[0], 359.0);
    assert!(back.cog.as_ref().unwrap()[1].is_nan());
    assert!(csv_text(&r).starts_with("t_s,delta_deg,r_degps,u_mps,cog_deg\n"));
    // resampled through north along the short way (359° → 1° passes 0°, not 180°)
    let mut g = r.clone();
    g.cog = Some(vec![359.0, 1.0, 1.0, 1.0]);
    let h = resample(&g, 0.5, Path::new("f.csv")).unwrap();
    let mid = h.cog.as_ref().unwrap()[1];
    assert!(!(1e-9..=360.0 - 1e-9).contains(&mid), "{mid}");
}

#[test]
fn missing_column_is_named() {
    let e = parse("t_s,delta_deg\n0,1\n1,1\n").unwrap_err().to_string();
    assert!(e.contains("r_degps") && e.contains("f.csv"), "{e}");
}

#[test]
fn bad_cell_names_row_and_column() {
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,x,0\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 2") && e.contains("delta_deg") && e.contains("`x`"),
        "{e}"
    );
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,NaN\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("r_degps") && e.contains("NaN"), "{e}");
}

#[test]
fn jittered_time_stamps_keep_the_loggers_period() {
    // a 2 Hz logger whose stamps jitter by up to ±0.1 s (20 % of a period)
    let mut txt = String::from("t_s,delta_deg,r_degps\n");
    for i in 0..200 {
        let jitter = 0.1 * (((i * 7919) % 11) as f64 / 5.0 - 1.0);
        txt.push_str(&format!("{},1,0\n", 0.5 * i as f64 + jitter));
    }
    let r = parse(&txt).unwrap();
    assert_eq!(r.ts, 0.5);
    // a period far from three significant digits is kept as it is
    let t: Vec<f64> = (0..10).map(|i| i as f64 * 0.123_456_7).collect();
    let ts = check_uniform(&t, Path::new("x")).unwrap();
    assert!((ts - 0.123_456_7).abs() < 1e-15, "{ts}");
}

#[test]
fn heading_is_unwrapped_through_north() {
    let r =
        parse("t_s,delta_deg,r_degps,psi_deg\n0,1,0,359\n1,1,0,1\n2,1,0,3\n3,1,0,0.5\n").unwrap();
    assert_eq!(r.psi, Some(vec![359.0, 361.0, 363.0, 360.5]));
    let mut west = vec![-179.0, 179.0, 170.0, -170.0];
    unwrap_degrees(&mut west);
    assert_eq!(west, vec![-179.0, -181.0, -190.0, -170.0]);
}

#[test]
fn non_uniform_and_non_monotonic_time() {
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n2.5,1,0\n3.5,1,0\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 3"), "{e}");
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n0.5,1,0\n").unwrap_err();
    assert!(matches!(e, DataError::NonUniform { row: 3, .. }), "{e}");
    assert!(e.to_string().contains("time goes back"), "{e}");
    // a gap of three samples, an extra sample, a repeated stamp: each named with its row
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n2,1,0\n6,1,0\n7,1,0\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row 4") && e.contains("3 samples missing") && e.contains("sample time is 1 s"),
        "{e}"
    );
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n1.3,1,0\n2,1,0\n3,1,0\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 3") && e.contains("extra sample"), "{e}");
    let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n1,1,0\n2,1,0\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 3") && e.contains("repeats"), "{e}");
}

#[test]
fn round_trip_and_atomic_write() {
    let dir = std::env::temp_dir().join(format!("yawcast-data-{}", std::process::id()));
    let p = dir.join("r.csv");
    let mut r = Record::from_uy("r", 0.25, vec![1.0, -2.5, 3.0], vec![0.125, 0.0, -1.0]);
    r.psi = Some(vec![0.0, 1.0, 2.0]);
    write_csv(&p, &r).unwrap();
    let back = read_csv(&p).unwrap();
    assert_eq!(back.u, r.u);
    assert_eq!(back.y, r.y);
    assert_eq!(back.psi, r.psi);
    assert_eq!(back.ts, 0.25);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains(".tmp")
        })
        .collect();
    assert!(leftovers.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every entry of `dir` (recursively), as sorted relative paths with their bytes.
fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            if p.is_dir() {
                out.push((rel + "/", Vec::new()));
                stack.push(p);
            } else {
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

fn fresh_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("yawcast-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A rename that fails on the `n`-th file (1-based), counting its calls.
fn failing_on(n: usize, calls: &mut usize) -> impl FnMut(&Path, &Path) -> std::io::Result<()> + '_ {
    move |from, to| {
        *calls += 1;
        if *calls == n {
            return Err(std::io::Error::other("injected rename failure"));
        }
        std::fs::rename(from, to)
    }
}

#[test]
fn a_rename_failing_after_the_first_output_leaves_no_output() {
    let d = fresh_dir("fault-new");
    let files = vec![
        (d.join("model.postcard"), vec![1u8, 2, 3]),
        (d.join("sub/deeper/model.json"), b"{}".to_vec()),
        (d.join("summary.json"), b"{\"a\":1}".to_vec()),
    ];
    let mut calls = 0;
    let e = write_all_atomic_with(&files, &mut failing_on(2, &mut calls)).unwrap_err();
    assert_eq!(
        calls, 2,
        "the first file was renamed into place before the failure"
    );
    assert!(
        matches!(&e, DataError::Io { path, .. } if path == &d.join("sub/deeper/model.json")),
        "{e}"
    );
    assert!(e.to_string().contains("injected rename failure"), "{e}");
    // no output, no temporary file, no directory created for the outputs
    assert_eq!(listing(&d), Vec::<(String, Vec<u8>)>::new());
    // and the same files go through when nothing fails
    let mut calls = 0;
    write_all_atomic_with(&files, &mut failing_on(0, &mut calls)).unwrap();
    assert_eq!(calls, 3);
    assert_eq!(
        std::fs::read(d.join("model.postcard")).unwrap(),
        vec![1u8, 2, 3]
    );
    let names: Vec<String> = listing(&d).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "model.postcard",
            "sub/",
            "sub/deeper/",
            "sub/deeper/model.json",
            "summary.json"
        ]
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_failed_write_restores_every_file_it_would_have_replaced() {
    let d = fresh_dir("fault-old");
    let old: Vec<(PathBuf, Vec<u8>)> = vec![
        (d.join("ship.postcard"), vec![0xde, 0xad, 0xbe, 0xef, 0]),
        (d.join("ship.json"), b"{\"old\": true}\n".to_vec()),
        (d.join("tables.md"), b"| old |\n".to_vec()),
    ];
    for (p, b) in &old {
        std::fs::write(p, b).unwrap();
    }
    let before = listing(&d);
    let new: Vec<(PathBuf, Vec<u8>)> = old
        .iter()
        .map(|(p, _)| (p.clone(), b"new content".to_vec()))
        .chain([(d.join("fresh.json"), b"{}".to_vec())])
        .collect();
    for fail_at in 1..=4 {
        let mut calls = 0;
        let e = write_all_atomic_with(&new, &mut failing_on(fail_at, &mut calls)).unwrap_err();
        assert!(
            matches!(&e, DataError::Io { path, .. } if path == &new[fail_at - 1].0),
            "{e}"
        );
        assert_eq!(listing(&d), before, "failing at rename {fail_at}");
    }
    // a write that goes through replaces all and leaves no backup
    write_all_atomic(&new).unwrap();
    let after = listing(&d);
    assert_eq!(after.len(), 4, "{after:?}");
    assert!(after.iter().all(|(_, b)| b == b"new content" || b == b"{}"));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn two_outputs_to_one_file_are_refused_before_any_write() {
    let d = fresh_dir("dup");
    let files = vec![
        (d.join("a.json"), b"1".to_vec()),
        (d.join("a.json"), b"2".to_vec()),
    ];
    let e = write_all_atomic(&files).unwrap_err();
    assert!(e.to_string().contains("two outputs"), "{e}");
    assert!(listing(&d).is_empty());
    let e = check_outputs(&[&d.join("x"), &d.join("x")]).unwrap_err();
    assert!(e.to_string().contains("two outputs"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// An interrupt arriving between two renames: the writer rolls back under its lock before
/// `interrupt` returns, and writes nothing afterwards.
#[test]
fn an_interrupt_during_the_renames_rolls_back_before_it_returns() {
    let d = fresh_dir("interrupt");
    std::fs::write(d.join("model.postcard"), b"old blob").unwrap();
    let before = listing(&d);
    let writer = std::sync::Arc::new(AtomicWriter::new());
    let files = vec![
        (d.join("model.json"), b"new twin".to_vec()),
        (d.join("model.postcard"), b"new blob".to_vec()),
    ];
    let (renamed_tx, renamed_rx) = std::sync::mpsc::channel();
    let w = writer.clone();
    let f = files.clone();
    let handle = std::thread::spawn(move || {
        let mut first = true;
        w.write_all(&f, &mut |from, to| {
            std::fs::rename(from, to)?;
            if first {
                first = false;
                // The twin is in place, the blob not yet: wait here for the signal.
                renamed_tx.send(()).unwrap();
                while w.interrupted().is_none() {
                    std::thread::yield_now();
                }
            }
            Ok(())
        })
    });
    renamed_rx.recv().unwrap();
    assert_eq!(std::fs::read(d.join("model.json")).unwrap(), b"new twin");
    let guard = writer.interrupt(15);
    // The lock is ours: the write has rolled back already.
    assert_eq!(listing(&d), before);
    drop(guard);
    let res = handle.join().unwrap();
    assert!(
        matches!(res, Err(DataError::Interrupted { signal: 15 })),
        "{res:?}"
    );
    // later writes touch nothing
    let e = writer
        .write_all(&files, &mut |a, b| std::fs::rename(a, b))
        .unwrap_err();
    assert!(matches!(e, DataError::Interrupted { signal: 15 }), "{e}");
    assert!(e.to_string().contains("no output written"), "{e}");
    assert_eq!(listing(&d), before);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn duplicate_columns_are_named_not_resolved() {
    let e = parse("t_s,delta_deg,r_degps,delta_deg\n0,1,0,2\n1,2,1,3\n").unwrap_err();
    assert!(
        matches!(&e, DataError::DuplicateColumn { column, first: 2, second: 4, .. } if column == "delta_deg"),
        "{e}"
    );
}

#[test]
fn semicolon_files_with_decimal_commas_are_read() {
    let r = parse("t_s;delta_deg;r_degps\n0;1,5;0\n0,5;-2;0,25\n1;3;-0,125\n").unwrap();
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.u, vec![1.5, -2.0, 3.0]);
    assert_eq!(r.y, vec![0.0, 0.25, -0.125]);
    // A comma file whose cells hold `;` stays a comma file (and fails on the cell).
    assert_eq!(Dialect::of("t_s,delta_deg;x,r_degps\n").delimiter, b',');
    // the header decides, after blank and comment lines
    assert_eq!(
        Dialect::of("\n# logger v2\nt_s;delta_deg\n").delimiter,
        b';'
    );
}

#[test]
fn tab_separated_files_are_read_with_either_decimal_mark() {
    let r = parse("t_s\tdelta_deg\tr_degps\n0\t1.5\t0\n0.5\t-2\t0,25\n1\t3\t-0.125\n").unwrap();
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.u, vec![1.5, -2.0, 3.0]);
    assert_eq!(r.y, vec![0.0, 0.25, -0.125]);
    assert_eq!(
        Dialect::of("t_s\tdelta_deg\n"),
        Dialect {
            delimiter: b'\t',
            decimal_comma: true
        }
    );
    // a bad cell is still named by its row and column
    let e = parse("t_s\tdelta_deg\tr_degps\n0\t1\t0\n1\tx\t0\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "f.csv: row 2, column `delta_deg`: expected a finite number, found `x`"
    );
}

#[test]
fn implausible_values_and_still_channels_are_named() {
    let cols = Columns::default();
    let lim = Limits::default();
    let path = Path::new("trial.csv");
    let mut r = Record::from_uy(
        "r",
        1.0,
        vec![0.0, 4.0, -4.0, 2.0],
        vec![0.0, 0.5, -0.5, 0.1],
    );
    assert!(validate_record(&r, path, &lim, &cols).is_ok());
    r.y[2] = 3.4e200;
    let e = validate_record(&r, path, &lim, &cols).unwrap_err();
    assert!(
        matches!(&e, DataError::Implausible { row: 3, column, limit, .. } if column == "r_degps" && *limit == 30.0),
        "{e}"
    );
    assert!(e.to_string().contains("--max-rate"), "{e}");
    r.y[2] = -0.5;
    r.speed = Some(vec![1.0, 1.0, 150.0, 1.0]);
    let e = validate_record(&r, path, &lim, &cols).unwrap_err();
    assert!(matches!(e, DataError::Implausible { row: 3, .. }), "{e}");
    r.speed = None;
    let zero = Record::from_uy("z", 1.0, vec![0.0; 4], vec![0.0; 4]);
    let e = validate_record(&zero, path, &lim, &cols).unwrap_err();
    assert!(
        matches!(&e, DataError::NoExcitation { column, .. } if column == "delta_deg"),
        "{e}"
    );
    let tiny = Record::from_uy(
        "t",
        1.0,
        vec![0.0, 5.0, 0.0, 5.0],
        vec![1e-300, 0.0, 2e-300, 0.0],
    );
    let e = validate_record(&tiny, path, &lim, &cols).unwrap_err();
    assert!(
        matches!(&e, DataError::NoExcitation { column, .. } if column == "r_degps"),
        "{e}"
    );
    assert!(e.to_string().contains("constant"), "{e}");
}

#[test]
fn resampling_absorbs_gaps_and_another_rate() {
    // A 2 s gap that uniform reading refuses is resampled onto 0.5 s.
    let txt = "t_s,delta_deg,r_degps,psi_deg\n0,1,0,358\n1,1,1,359\n3,-1,3,1\n4,-1,2,2\n";
    assert!(parse(txt).is_err());
    let cols = Columns {
        resample: Some(0.5),
        ..Columns::default()
    };
    let r = parse_csv(txt, "g.csv".as_ref(), "g", &cols).unwrap();
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.t.len(), 9);
    assert_eq!(r.u, vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -1.0, -1.0, -1.0]);
    assert_eq!(r.y[3], 1.5);
    assert_eq!(r.y[8], 2.0);
    // Heading through north: 359 → 361 (unwrapped), half-way 360.
    assert_eq!(r.psi.as_ref().unwrap()[4], 360.0);
    let back = "t_s,delta_deg,r_degps\n0,1,0\n1,1,1\n1,2,2\n";
    let e = parse_csv(back, "b.csv".as_ref(), "b", &cols).unwrap_err();
    assert!(matches!(e, DataError::NonUniform { row: 3, .. }), "{e}");
}

#[test]
fn the_heading_tells_a_yaw_rate_in_rad_per_s_or_of_the_other_sign() {
    // a ship weaving ±amp° about a course that creeps round, heading logged in [0, 360) with
    // compass noise; the gyro reads 0.05 °/s high
    let weave = |amp: f64| {
        let n = 1_800;
        let mut rec = Record::from_uy(
            "weave",
            1.0,
            (0..n)
                .map(|t| if (t / 60) % 2 == 0 { 15.0 } else { -15.0 })
                .collect(),
            (0..n)
                .map(|t| amp * 0.02 * (0.02 * t as f64).cos() + 0.01 + 0.05)
                .collect(),
        );
        rec.psi = Some(
            (0..n)
                .map(|t| {
                    let t = t as f64;
                    let noise = 0.2 * ((t * 12.9898).sin() * 43_758.547).fract();
                    (200.0 + amp * (0.02 * t).sin() + 0.01 * t + noise).rem_euclid(360.0)
                })
                .collect(),
        );
        rec
    };
    let scaled = |mut r: Record, k: f64| {
        r.y.iter_mut().for_each(|y| *y *= k);
        unit_warnings(&r)
    };
    let rad = std::f64::consts::PI / 180.0;
    // rates of up to 4.8 °/s: in rad/s (0.08) beyond the span test's ±0.05
    let fast = weave(240.0);
    assert!(
        unit_warnings(&fast).is_empty(),
        "{:?}",
        unit_warnings(&fast)
    );
    let w = scaled(fast.clone(), rad);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("57.") && w[0].contains("--rate-unit radps"),
        "{w:?}"
    );
    let w = scaled(fast.clone(), -rad);
    assert!(w.len() == 1 && w[0].contains("opposite sign"), "{w:?}");
    let w = scaled(fast, -1.0);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("-1.00 times") && w[0].contains("negate"),
        "{w:?}"
    );
    // weaving ±60° (rates of up to 1.2 °/s): the sign is told as well
    let w = scaled(weave(60.0), -1.0);
    assert!(w.len() == 1 && w[0].contains("negate"), "{w:?}");
    // weaving ±5°: too little turning to tell, nothing said either way
    assert!(scaled(weave(5.0), -1.0).is_empty());
}

#[test]
fn speeds_in_knots_or_km_per_h_are_read_as_m_per_s() {
    let txt = "t_s,delta_deg,r_degps,psi_deg,u_mps,wind_speed_mps,wind_angle_deg\n\
               0,5,0.1,10,14,20,30\n1,-5,0.2,10.1,14.5,19,31\n";
    let read = |speed_scale: f64| {
        let cols = Columns {
            speed_scale,
            ..Columns::default()
        };
        parse_csv(txt, "kn.csv".as_ref(), "kn", &cols).unwrap()
    };
    let mps = read(1.0);
    assert_eq!(mps.speed.as_deref(), Some(&[14.0, 14.5][..]));
    let kn = read(1852.0 / 3600.0);
    let sp = kn.speed.unwrap();
    assert!(
        (sp[0] - 7.202_222).abs() < 1e-6 && (sp[1] - 7.459_444).abs() < 1e-6,
        "{sp:?}"
    );
    let ws = kn.wind_speed.unwrap();
    assert!((ws[0] - 10.288_889).abs() < 1e-6, "{ws:?}");
    // the other columns are untouched
    assert_eq!((kn.u, kn.y), (mps.u, mps.y));
    assert_eq!(kn.wind_angle, mps.wind_angle);
}

#[test]
fn iso_date_times_in_the_time_column_are_seconds_from_the_first() {
    let txt = "t_s,delta_deg,r_degps\n\
               2024-05-01T23:59:59.5Z,1,0\n\
               2024-05-02T00:00:00.0Z,2,0.5\n\
               2024-05-02T02:00:00.5+02:00,3,0.25\n";
    let r = parse(txt).unwrap();
    assert_eq!(r.t, vec![0.0, 0.5, 1.0]);
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.u, vec![1.0, 2.0, 3.0]);
    // one stamp that is not a date-time is named with its row
    let bad = txt.replace("2024-05-02T00:00:00.0Z", "0.5");
    let e = parse(&bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        "f.csv: row 2, column `t_s`: expected a time stamp like the first row's (an ISO \
         8601 date-time such as 2024-05-01T12:00:00.5Z, or a time of day such as 12:00:00.5), \
         found `0.5`"
    );
    // times of day alone, across midnight
    let day = parse(
        "t_s,delta_deg,r_degps\n23:59:59.0,0,0\n23:59:59.5,0,0\n00:00:00.0,0,0\n\
                     00:00:00.5,0,0\n",
    )
    .unwrap();
    assert_eq!((day.t.clone(), day.ts), (vec![0.0, 0.5, 1.0, 1.5], 0.5));
    // numeric stamps in milliseconds, scaled to seconds
    let ms = parse_csv(
        "t_s,delta_deg,r_degps\n1000,0,0\n1500,0,0\n2000,0,0\n",
        Path::new("f.csv"),
        "f",
        &Columns {
            time_scale: 1e-3,
            ..Columns::default()
        },
    )
    .unwrap();
    assert_eq!((ms.t.clone(), ms.ts), (vec![1.0, 1.5, 2.0], 0.5));
    // a missing sample is a gap, as with seconds
    let gap = "t_s,delta_deg,r_degps\n2024-05-01 12:00:00,0,0\n2024-05-01 12:00:01,0,0\n\
               2024-05-01 12:00:02,0,0\n2024-05-01 12:00:04,0,0\n";
    let e = parse(gap).unwrap_err();
    assert!(matches!(&e, DataError::NonUniform { row: 4, .. }), "{e}");
}

#[test]
fn without_a_rate_gyro_the_heading_gives_the_rate_when_asked() {
    let txt = "t_s,delta_deg,psi_deg\n0,1,359.5\n0.5,1,0.0\n1,1,1.0\n1.5,1,1.0\n";
    let e = parse(txt).unwrap_err();
    assert_eq!(
        e.to_string(),
        "f.csv: missing column `r_degps` (found: t_s,delta_deg,psi_deg); the heading \
         `psi_deg` is logged: --rate-from-heading takes the yaw rate as its change over each \
         sample"
    );
    let cols = Columns {
        rate_from_heading: true,
        ..Columns::default()
    };
    let r = parse_csv(txt, Path::new("f.csv"), "f", &cols).unwrap();
    // unwrapped through north first: 359.5 → 360 → 361
    assert_eq!(r.y, vec![1.0, 1.0, 2.0, 0.0]);
    assert_eq!(r.ts, 0.5);
    // a logged rate column is not read then
    let both = "t_s,delta_deg,r_degps,psi_deg\n0,1,9,10\n1,1,9,11\n2,1,9,13\n";
    let r = parse_csv(both, Path::new("f.csv"), "f", &cols).unwrap();
    assert_eq!(r.y, vec![1.0, 1.0, 2.0]);
    // resampled first, then differenced on the grid
    let jitter = "t_s,delta_deg,psi_deg\n0,0,0\n0.9,0,0.9\n2.1,0,2.1\n3,0,3\n";
    let r = parse_csv(
        jitter,
        Path::new("f.csv"),
        "f",
        &Columns {
            resample: Some(1.0),
            ..cols.clone()
        },
    )
    .unwrap();
    assert_eq!(r.y.len(), r.psi.as_ref().unwrap().len());
    assert!(r.y.iter().all(|v| (v - 1.0).abs() < 1e-9), "{:?}", r.y);
    // no heading, nothing to take it from
    let e = parse_csv("t_s,delta_deg\n0,1\n1,1\n", Path::new("f.csv"), "f", &cols).unwrap_err();
    assert!(
        matches!(&e, DataError::MissingColumn { column, .. } if column == "psi_deg"),
        "{e}"
    );
}

#[test]
fn dropouts_in_the_optional_channels_are_named_or_filled() {
    let txt = "t_s,delta_deg,r_degps,psi_deg,u_mps\n\
               0,1,0,359,5\n1,1,0,,5\n2,1,0,NaN,\n3,1,0,2,6\n4,1,0,3,6\n";
    let e = parse(txt).unwrap_err();
    assert_eq!(
        e.to_string(),
        "f.csv: row 2, column `psi_deg`: expected a finite number, found `` (a dropout? \
         --fill-gaps N interpolates up to N missing samples in a row of the heading, speed \
         and wind channels)"
    );
    let fill = |n| Columns {
        fill_gaps: n,
        ..Columns::default()
    };
    let r = parse_csv(txt, Path::new("f.csv"), "f", &fill(2)).unwrap();
    // the heading the shorter way round, then unwrapped: 359 → 360 → 361 → 362
    assert_eq!(r.psi.unwrap(), vec![359.0, 360.0, 361.0, 362.0, 363.0]);
    assert_eq!(r.speed.unwrap(), vec![5.0, 5.0, 5.5, 6.0, 6.0]);
    // a longer run than allowed is named where it starts
    let e = parse_csv(txt, Path::new("f.csv"), "f", &fill(1)).unwrap_err();
    assert!(
        matches!(&e, DataError::Gap { first: 2, missing: 2, limit: 1, column, .. } if column == "psi_deg"),
        "{e}"
    );
    // the command and the yaw rate are never filled
    let e = parse_csv(
        "t_s,delta_deg,r_degps\n0,1,0\n1,,0\n",
        Path::new("f.csv"),
        "f",
        &fill(5),
    )
    .unwrap_err();
    assert!(matches!(&e, DataError::BadCell { row: 2, .. }), "{e}");
}

#[test]
fn a_placeholder_heading_course_or_speed_is_refused_when_the_ship_turns() {
    let (cols, lim, path) = (Columns::default(), Limits::default(), Path::new("t.csv"));
    // 100 s at 0.1 °/s: the rate turns the ship through 10°
    let mut r = Record::from_uy(
        "r",
        1.0,
        (0..100).map(|i| (i % 7) as f64).collect(),
        vec![0.1; 100],
    );
    r.y[0] = 0.0;
    r.psi = Some(vec![0.0; 100]);
    let e = validate_record(&r, path, &lim, &cols).unwrap_err();
    assert_eq!(
        e.to_string(),
        "t.csv: column `psi_deg` holds one value (0) throughout while the yaw rate turns the \
         ship through 10°: a heading sensor not logged? Leave the channel out (its --col-… \
         option naming no column)"
    );
    // a heading that follows the turn passes; a course stuck at one value does not, with
    // its drop-outs skipped
    r.psi = Some((0..100).map(|i| 0.1 * i as f64).collect());
    r.cog = Some(
        (0..100)
            .map(|i| if i % 9 == 0 { f64::NAN } else { 42.0 })
            .collect(),
    );
    let e = validate_record(&r, path, &lim, &cols).unwrap_err();
    assert!(
        matches!(&e, DataError::NoExcitation { column, .. } if column == "cog_deg"),
        "{e}"
    );
    r.cog = None;
    // a speed is refused only at 0 throughout (a constant nominal speed is a choice)
    r.speed = Some(vec![1.5; 100]);
    assert!(validate_record(&r, path, &lim, &cols).is_ok());
    r.speed = Some(vec![0.0; 100]);
    assert!(validate_record(&r, path, &lim, &cols).is_err());
    // a ship that turns through less than MIN_TURN_DEG may hold its heading
    let mut straight = r.clone();
    straight.speed = None;
    straight.y = vec![0.0; 100];
    straight.y[50] = 0.04;
    straight.psi = Some(vec![7.0; 100]);
    assert!(validate_record(&straight, path, &lim, &cols).is_ok());
}

#[test]
fn commands_beyond_a_rudder_are_asked_about_as_per_cent() {
    let rec = |amp: f64| {
        let u: Vec<f64> = (0..200)
            .map(|t| if (t / 20) % 2 == 0 { amp } else { -amp })
            .collect();
        let y: Vec<f64> = (0..200).map(|t| 0.5 * (0.1 * t as f64).sin()).collect();
        Record::from_uy("r", 1.0, u, y)
    };
    // 20° of a 35° rudder, logged in per cent: 57.1
    let w = unit_warnings(&rec(20.0 / 0.35));
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("±57.1") && w[0].contains("--command-scale (0.35"),
        "{w:?}"
    );
    // at the limit and below it nothing is asked
    assert!(unit_warnings(&rec(RUDDER_MAX_DEG)).is_empty());
    assert!(unit_warnings(&rec(35.0)).is_empty());
    assert_eq!(unit_warnings(&rec(RUDDER_MAX_DEG + 0.1)).len(), 1);
}
