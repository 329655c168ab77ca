//! Unit tests of the NMEA reader: the sample logs, the small parsers, clocks, gaps and errors.

use super::*;

const TRIAL: &str = include_str!("../../../tests/data/trial.nmea");
const BAD: &str = include_str!("../../../tests/data/trial-bad-checksum.nmea");
const GAP: &str = include_str!("../../../tests/data/trial-gap.nmea");

fn parse(text: &str, opts: &NmeaOptions) -> Result<Record, NmeaError> {
    parse_nmea(text, Path::new("trial.nmea"), "trial", opts)
}

#[test]
fn golden_log_every_sentence_type() {
    let r = parse(TRIAL, &NmeaOptions::default()).unwrap();
    assert_eq!(r.ts, 0.5);
    assert_eq!(r.len(), 19);
    let t: Vec<f64> = (0..19).map(|i| i as f64 * 0.5).collect();
    assert_eq!(r.t, t);
    // ROT 6·t deg/min = 0.1·t deg/s; the invalid ROT at 2.5 s is interpolated over.
    for (i, &ti) in t.iter().enumerate() {
        assert!((r.y[i] - 0.1 * ti).abs() < 1e-9, "r at {ti}: {}", r.y[i]);
        let d = if ti < 5.0 { 10.0 } else { -10.0 };
        assert_eq!(r.u[i], d, "δ at {ti}");
    }
    // HDT 358 + 0.5 t, unwrapped across north; HDG is ignored when HDT is logged.
    let psi = r.psi.as_ref().unwrap();
    assert_eq!(psi[0], 358.0);
    assert_eq!(psi[1], 358.25);
    assert_eq!(psi[18], 362.5);
    // VTG 3 kn; MWV relative 10 kn at 356 + t deg (wrapped), true-wind MWV ignored.
    assert!(r.speed.as_ref().unwrap().iter().all(|&v| v == 1.543333));
    assert!(r
        .wind_speed
        .as_ref()
        .unwrap()
        .iter()
        .all(|&v| v == 5.144444));
    let wa = r.wind_angle.as_ref().unwrap();
    assert_eq!(wa[0], 356.0);
    assert_eq!(wa[8], 0.0);
    assert_eq!(wa[18], 5.0);
}

#[test]
fn bad_checksum_names_the_line() {
    let e = parse(BAD, &NmeaOptions::default()).unwrap_err();
    assert!(matches!(e, NmeaError::Checksum { line: 49, .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("trial.nmea: line 49: bad checksum"), "{msg}");
    // Dropping the line instead: the ROT sample at 4.0 s is interpolated from its neighbours.
    let opts = NmeaOptions {
        skip_bad_checksums: true,
        ..NmeaOptions::default()
    };
    let r = parse(BAD, &opts).unwrap();
    assert_eq!(r.len(), 19);
}

#[test]
fn gap_names_time_line_and_length() {
    let e = parse(GAP, &NmeaOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            NmeaError::Gap {
                line: 40,
                sentence: "ROT",
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("gap of 3.50 s in ROT (rate of turn) after 12:00:03.50 (line 40)"),
        "{msg}"
    );
    // A generous limit lets it through.
    let opts = NmeaOptions {
        max_gap: Some(4.0),
        ..NmeaOptions::default()
    };
    assert_eq!(parse(GAP, &opts).unwrap().len(), 19);
}

#[test]
fn hdg_and_rmc_clock_without_hdt_and_zda() {
    let log: String = TRIAL
        .lines()
        .filter(|l| !l.contains("HDT") && !l.contains("ZDA"))
        .map(|l| format!("{l}\n"))
        .collect();
    let r = parse(&log, &NmeaOptions::default()).unwrap();
    assert_eq!(r.len(), 19);
    assert_eq!(r.psi.as_ref().unwrap()[18], 362.5);
}

#[test]
fn rate_clock_and_grid_option() {
    let opts = NmeaOptions {
        clock: Clock::Rate(2.0),
        ts: Some(1.0),
        ..NmeaOptions::default()
    };
    let r = parse(TRIAL, &opts).unwrap();
    assert_eq!(r.ts, 1.0);
    // Every ROT ticks the clock (the invalid one too); heading starts at the 2nd tick.
    assert!((r.y[3] - 0.35).abs() < 1e-9, "{:?}", r.y);
}

#[test]
fn clear_errors() {
    let e = parse(
        "$GPZDA,120000.00,14,06,2024,00,00*62\n",
        &NmeaOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("at least 2") && e.contains("--nmea-rate"), "{e}");
    let no_rsa: String = TRIAL
        .lines()
        .filter(|l| !l.contains("RSA"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = parse(&no_rsa, &NmeaOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no valid RSA sentence"), "{e}");
    let e = parse("$HEROT,abc,A*65\n", &NmeaOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 1: ROT") && e.contains("`abc`"), "{e}");
    let e = parse(
        "$GPZDA,120001.00,14,06,2024,00,00*63\n$GPZDA,120000.00,14,06,2024,00,00*62\n",
        &NmeaOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("line 2: clock goes back"), "{e}");
    assert!(!looks_like_nmea(""));
}

#[test]
fn navigation_channels_on_the_record_grid() {
    let opts = NmeaOptions::default();
    let r = parse(TRIAL, &opts).unwrap();
    let nn = parse_nmea_nav(TRIAL, Path::new("trial.nmea"), &opts, &r).unwrap();
    // VTG's true course, on every grid point
    let c = nn.course.as_ref().unwrap();
    assert_eq!(c.len(), 19);
    assert!(c.iter().all(|&v| v == 45.0), "{c:?}");
    // and in the record itself, bit for bit
    let rc = r.cog.as_ref().expect("the record carries the course");
    assert_eq!(
        rc.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        c.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // the one GGA fix comes before the first clock sentence and is dropped (and with a GGA
    // in the log, RMC positions are not used): no position, never a guess
    assert!(nn.position.is_none());
    // without GGA the RMC positions serve: 53°46.8' N, 19°34.6' E
    let rmc_only: String = TRIAL
        .lines()
        .filter(|l| !l.contains("GGA"))
        .map(|l| format!("{l}\n"))
        .collect();
    let r2 = parse(&rmc_only, &opts).unwrap();
    assert_eq!(r2, r, "the navigation sentences do not change the record");
    let nn = parse_nmea_nav(&rmc_only, Path::new("trial.nmea"), &opts, &r2).unwrap();
    let p = nn.position.clone().unwrap();
    assert!((p[3][0] - (53.0 + 46.8 / 60.0)).abs() < 1e-9, "{:?}", p[3]);
    assert!((p[3][1] - (19.0 + 34.6 / 60.0)).abs() < 1e-9, "{:?}", p[3]);
    let nav = crate::io::nav::from_nmea(&r2, &nn).unwrap();
    // 3 kn along 45°: equal north and east components
    let v = nav.velocity(5).unwrap();
    assert!((v[0] - v[1]).abs() < 1e-9 && (v[0] - 1.543333 * 0.5f64.sqrt()).abs() < 1e-6);
}

/// A record written as the NMEA log a ship's logger would keep, one sentence per channel per
/// sample, the `ROT` count the clock ([`Clock::Rate`] at the record's rate): `ROT`, `RSA`,
/// and where the record has them `HDT`, `VTG` (course and speed over ground) and `MWV`
/// (relative wind, m/s).
pub(crate) fn log_of(r: &Record) -> String {
    let line = |body: String| format!("${body}*{:02X}\n", checksum(&body));
    let mut s = String::new();
    for t in 0..r.len() {
        s += &line(format!("HEROT,{:.3},A", 60.0 * r.y[t]));
        s += &line(format!("IIRSA,{:.3},A,,V", r.u[t]));
        if let Some(p) = &r.psi {
            s += &line(format!("HEHDT,{:.3},T", p[t].rem_euclid(360.0)));
        }
        if let (Some(v), Some(c)) = (&r.speed, &r.cog) {
            let kn = v[t] / knots(1.0);
            s += &line(format!(
                "GPVTG,{:.3},T,,M,{kn:.4},N,{:.4},K,A",
                c[t].rem_euclid(360.0),
                v[t] * 3.6
            ));
        }
        if let (Some(w), Some(a)) = (&r.wind_speed, &r.wind_angle) {
            s += &line(format!(
                "WIMWV,{:.2},R,{:.3},M,A",
                a[t].rem_euclid(360.0),
                w[t]
            ));
        }
    }
    s
}

#[test]
fn a_record_written_as_a_log_reads_back() {
    let mut r = Record::from_uy("r", 1.0, vec![5.0, -5.0, 2.0], vec![0.5, -0.25, 0.1]);
    r.psi = Some(vec![359.5, 0.5, 1.0]);
    r.speed = Some(vec![3.0, 3.1, 3.2]);
    r.cog = Some(vec![10.0, 12.0, 14.0]);
    let opts = NmeaOptions {
        clock: Clock::Rate(1.0),
        ..NmeaOptions::default()
    };
    let back = parse(&log_of(&r), &opts).unwrap();
    assert_eq!((back.len(), back.ts), (3, 1.0));
    assert_eq!(back.u, r.u);
    assert!(back.y.iter().zip(&r.y).all(|(a, b)| (a - b).abs() < 1e-4));
    assert_eq!(back.psi.as_ref().unwrap(), &[359.5, 360.5, 361.0]);
    let c = back.cog.as_ref().unwrap();
    assert!(
        c.iter()
            .zip([10.0, 12.0, 14.0])
            .all(|(a, b)| (a - b).abs() < 1e-9),
        "{c:?}"
    );
    let v = back.speed.as_ref().unwrap();
    assert!((v[2] - 3.2).abs() < 1e-4, "{v:?}");
}

#[test]
fn without_rot_the_heading_gives_the_rate_when_asked() {
    let opts = NmeaOptions {
        rate_from_heading: true,
        ..NmeaOptions::default()
    };
    // HDT at 1 Hz, 358 + 0.5 t: the grid is the heading's, the rate its change, ROT unread
    let r = parse(TRIAL, &opts).unwrap();
    assert_eq!(r.ts, 1.0);
    let psi = r.psi.as_ref().unwrap();
    assert_eq!(psi[0], 358.0);
    assert_eq!(r.y, crate::io::data::heading_rate(psi, 1.0));
    assert!(r.y.iter().all(|&y| y == 0.5), "{:?}", r.y);
    assert!(r.len() >= 9, "{}", r.len());
    // a log without ROT: refused, naming the option; read with it
    let no_rot: String = TRIAL
        .lines()
        .filter(|l| !l.contains("ROT,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = parse(&no_rot, &NmeaOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            NmeaError::Missing {
                sentence: "ROT",
                ..
            }
        ) && e.to_string().contains("--rate-from-heading"),
        "{e}"
    );
    assert_eq!(parse(&no_rot, &opts).unwrap().y, r.y);
    // without a heading either, nothing to form it from
    let bare: String = no_rot
        .lines()
        .filter(|l| !l.contains("HDT,") && !l.contains("HDG,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = parse(&bare, &NmeaOptions::default()).unwrap_err();
    assert!(!e.to_string().contains("--rate-from-heading"), "{e}");
    let e = parse(&bare, &opts).unwrap_err();
    assert!(
        matches!(
            e,
            NmeaError::Missing {
                sentence: "HDT/HDG",
                ..
            }
        ),
        "{e}"
    );
    // the ROT count is no clock for it
    let counted = NmeaOptions {
        clock: Clock::Rate(2.0),
        ..opts
    };
    let e = parse(TRIAL, &counted).unwrap_err();
    assert!(e.to_string().contains("ZDA/RMC clock"), "{e}");
}
