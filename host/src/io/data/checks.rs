//! Plausibility of a record: physical limits, units, heading unwrapping and a uniform time grid.

use std::path::Path;

use super::{Columns, DataError, Record, SNAP_TOL};

/// Physical limits a record's values must respect (after unit scaling): a value beyond them
/// is a corrupted cell or another unit, never a measurement to identify from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest |commanded angle| (deg). Rudders and pods turn at most 35–45°, azimuth units 180°.
    pub angle_deg: f64,
    /// Largest |yaw rate| (deg/s).
    pub rate_degps: f64,
    /// Largest |speed over ground| and relative wind speed (m/s).
    pub speed_mps: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            angle_deg: 180.0,
            rate_degps: 30.0,
            speed_mps: 100.0,
        }
    }
}

/// Smallest span (max − min) of the command for a record to carry information (deg).
pub const MIN_COMMAND_SPAN_DEG: f64 = 0.05;
/// Smallest span of the yaw rate for a record to carry information (deg/s).
pub const MIN_RATE_SPAN_DEGPS: f64 = 1e-3;

/// Checks a record before any work is done on it: every value within `limits`, no isolated
/// spike in the yaw rate ([`super::spikes`]), and both the command and the yaw rate moving
/// (a command held at one angle, or a yaw rate stuck at one value, cannot be identified,
/// tuned on, compared or diagnosed). `cols` names the columns in the messages; rows are
/// 1-based samples of the record (for an NMEA log, of its grid).
///
/// # Errors
/// [`DataError::Implausible`] naming the row and column of the first value beyond a limit,
/// [`DataError::Spike`] naming the first row where the yaw rate spikes ([`super::spikes`]),
/// [`DataError::NoExcitation`] naming the column that never moves, or the heading, course or
/// speed over ground column that holds one value (a speed: 0) while the yaw rate turns the
/// ship through [`MIN_TURN_DEG`] or more.
///
/// ```
/// use yawcast::io::data::{validate_record, Columns, DataError, Limits, Record};
/// let ok = Record::from_uy("r", 1.0, vec![0.0, 5.0, -5.0], vec![0.0, 0.4, -0.2]);
/// assert!(validate_record(&ok, "r.csv".as_ref(), &Limits::default(), &Columns::default()).is_ok());
/// let wild = Record::from_uy("r", 1.0, vec![0.0, 2e6, -5.0], vec![0.0, 0.4, -0.2]);
/// let e = validate_record(&wild, "r.csv".as_ref(), &Limits::default(), &Columns::default());
/// assert!(matches!(e, Err(DataError::Implausible { row: 2, .. })));
/// let still = Record::from_uy("r", 1.0, vec![5.0; 3], vec![0.0, 0.4, -0.2]);
/// let e = validate_record(&still, "r.csv".as_ref(), &Limits::default(), &Columns::default());
/// assert!(matches!(e, Err(DataError::NoExcitation { .. })));
/// ```
pub fn validate_record(
    rec: &Record,
    path: &Path,
    limits: &Limits,
    cols: &Columns,
) -> Result<(), DataError> {
    let within =
        |v: &[f64], col: &str, limit: f64, what: &'static str, option: &'static str| match v
            .iter()
            .position(|x| x.is_nan() || x.abs() > limit)
        {
            Some(i) => Err(DataError::Implausible {
                path: path.to_path_buf(),
                row: i + 1,
                column: col.to_string(),
                value: v[i],
                limit,
                what,
                option,
            }),
            None => Ok(()),
        };
    within(
        &rec.u,
        &cols.u,
        limits.angle_deg,
        "a commanded angle (deg)",
        "--max-angle",
    )?;
    within(
        &rec.y,
        &cols.y,
        limits.rate_degps,
        "a yaw rate (deg/s)",
        "--max-rate",
    )?;
    let spikes = super::spikes(&rec.y);
    if let Some(first) = spikes.first() {
        return Err(DataError::Spike {
            path: path.to_path_buf(),
            row: first.index + 1,
            column: cols.y.clone(),
            value: first.value,
            fitted: first.fitted,
            count: spikes.len(),
            rows: super::spike_rows(&spikes),
        });
    }
    if let Some(v) = &rec.speed {
        within(
            v,
            &cols.speed,
            limits.speed_mps,
            "a speed (m/s)",
            "--max-speed",
        )?;
    }
    if let Some(v) = &rec.wind_speed {
        within(
            v,
            &cols.wind_speed,
            limits.speed_mps,
            "a wind speed (m/s)",
            "--max-speed",
        )?;
    }
    let span = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        (hi - lo, lo, hi)
    };
    let still = |col: &str, v: &[f64], min: f64, unit: &str, why: &str| {
        let (s, lo, hi) = span(v);
        if s < min {
            let held = if s == 0.0 {
                format!("is constant ({lo} {unit} throughout)")
            } else {
                format!("is constant to within {s:.3e} {unit} ({lo} … {hi})")
            };
            return Err(DataError::NoExcitation {
                path: path.to_path_buf(),
                column: col.to_string(),
                what: format!("{held}: {why}"),
            });
        }
        Ok(())
    };
    still(
        &cols.u,
        &rec.u,
        MIN_COMMAND_SPAN_DEG,
        "deg",
        "the command must move for the yaw dynamics to show; a record held at one angle \
         cannot be identified, tuned on, compared or diagnosed",
    )?;
    still(
        &cols.y,
        &rec.y,
        MIN_RATE_SPAN_DEGPS,
        "deg/s",
        "the yaw rate never moves; check that the rate sensor is logged, and its column and \
         unit (--col-rate, --rate-unit)",
    )?;
    // an optional channel a logger fills with a placeholder (a sensor not connected) holds
    // one value while the yaw rate turns the ship: no heading, course or speed over ground
    // does that, and every use of the channel would read it as the ship's
    let mut turned = 0.0f64;
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for r in &rec.y {
        turned += r * rec.ts;
        lo = lo.min(turned);
        hi = hi.max(turned);
    }
    let turn = hi - lo;
    if turn >= MIN_TURN_DEG {
        let placeholder = |col: &str, v: Option<&Vec<f64>>, what: &str| {
            let Some(v) = v else { return Ok(()) };
            let logged: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            let (s, value, _) = span(&logged);
            if logged.len() >= 2 && s == 0.0 {
                return Err(DataError::NoExcitation {
                    path: path.to_path_buf(),
                    column: col.to_string(),
                    what: format!(
                        "holds one value ({value}) throughout while the yaw rate turns the ship \
                         through {turn:.0}°: {what} not logged? Leave the channel out (its \
                         --col-… option naming no column)"
                    ),
                });
            }
            Ok(())
        };
        placeholder(&cols.psi, rec.psi.as_ref(), "a heading sensor")?;
        placeholder(&cols.cog, rec.cog.as_ref(), "a course over ground")?;
        if rec
            .speed
            .as_ref()
            .is_some_and(|v| v.iter().all(|x| *x == 0.0))
        {
            placeholder(&cols.speed, rec.speed.as_ref(), "a speed over ground")?;
        }
    }
    Ok(())
}

/// The turn (deg) the yaw rate integrates to over a record from which a heading, course or
/// speed over ground that holds one value is refused as a placeholder ([`validate_record`]).
pub const MIN_TURN_DEG: f64 = 5.0;

/// The largest angle a rudder turns (deg); a logged command beyond it is asked about by
/// [`unit_warnings`] (a rudder in per cent of its largest angle).
pub const RUDDER_MAX_DEG: f64 = 45.0;

/// Warnings about the scale of a record's columns that suggest a unit mix-up: commands that
/// never leave ±1.6 (radians under a degree header: π/2 rad is 90°) and yaw rates that never
/// leave ±0.05 °/s while the commands reach 2° (rad/s under a °/s header: a ship turning
/// visibly does more than 3°/min), and a sample time above a minute (milliseconds under a
/// seconds header: no yaw predictor samples that slowly), and commands beyond
/// [`RUDDER_MAX_DEG`] (a rudder logged in per cent of its largest angle: rudders turn
/// 35–45°; azimuth pods turn further, so this is a question, not a refusal). Where the
/// heading is logged and
/// the record turns, the heading says it outright: it turns about 57.3 times what a yaw rate
/// in rad/s integrates to, and −1 times what one of the other sign does (a gyro positive to
/// port). Empty when nothing looks wrong.
///
/// ```
/// use yawcast::io::data::{unit_warnings, Record};
/// let r = Record::from_uy("r", 1.0, vec![0.1, -0.2, 0.35], vec![0.001, 0.004, -0.002]);
/// let w = unit_warnings(&r);
/// assert_eq!(w.len(), 1);
/// assert!(w[0].contains("radians"));
/// let r = Record::from_uy("r", 1.0, vec![10.0, -20.0], vec![0.002, -0.01]);
/// assert!(unit_warnings(&r)[0].contains("rad/s"));
/// assert!(unit_warnings(&Record::from_uy("r", 1.0, vec![10.0, -20.0], vec![0.4, -0.9])).is_empty());
/// let ms = Record::from_uy("r", 1000.0, vec![10.0, -20.0], vec![0.4, -0.9]);
/// assert!(unit_warnings(&ms)[0].contains("milliseconds"));
/// let pct = Record::from_uy("r", 1.0, vec![57.1, -57.1], vec![0.4, -0.9]);
/// assert!(unit_warnings(&pct)[0].contains("--command-scale"));
/// ```
pub fn unit_warnings(rec: &Record) -> Vec<String> {
    let span = |v: &[f64]| {
        v.iter()
            .filter(|x| x.is_finite())
            .fold(0.0f64, |m, x| m.max(x.abs()))
    };
    let (du, dy) = (span(&rec.u), span(&rec.y));
    let mut out = Vec::new();
    if rec.ts > 60.0 {
        out.push(format!(
            "the sample time is {} s: if the time column is in milliseconds, give --time-unit ms",
            rec.ts
        ));
    }
    if du > RUDDER_MAX_DEG {
        out.push(format!(
            "the commands reach ±{du:.1}, more than a rudder turns (35–45°): if they are per \
             cent of the rudder's largest angle, give --command-scale (0.35 for a 35° rudder); \
             an azimuth pod's angle is right as logged"
        ));
    }
    if du > 0.0 && du <= 1.6 {
        out.push(format!(
            "the commands never leave ±{du:.3}: if they are radians, give --angle-unit rad"
        ));
    } else if du >= 2.0 && dy > 0.0 && dy <= 0.05 {
        out.push(format!(
            "the yaw rate never leaves ±{dy:.4} °/s while the commands reach {du:.0}°: if it \
             is in rad/s, give --rate-unit radps"
        ));
        return out;
    }
    // the heading, where logged, says outright how the yaw rate is scaled and signed
    if let Some(b) = heading_turn_ratio(rec) {
        let rad = 180.0 / std::f64::consts::PI;
        if (0.6 * rad..=1.6 * rad).contains(&b) {
            out.push(format!(
                "the heading turns {b:.1} times what the yaw rate integrates to (57.3 is \
                 rad/s under a °/s header): if the yaw rate is in rad/s, give --rate-unit radps"
            ));
        } else if (-1.6 * rad..=-0.6 * rad).contains(&b) {
            out.push(format!(
                "the heading turns {b:.1} times what the yaw rate integrates to: the yaw rate \
                 looks like rad/s of the opposite sign (give --rate-unit radps and negate it)"
            ));
        } else if (-1.5..=-0.67).contains(&b) {
            out.push(format!(
                "the heading turns {b:.2} times what the yaw rate integrates to: the yaw rate \
                 is positive the other way round (yawcast's is positive when the heading \
                 grows, to starboard); negate the yaw-rate column"
            ));
        }
    }
    out
}

/// How many degrees the heading turns per degree the yaw rate integrates to, `b` in
/// `ψ(t) − ψ(0) = b·∫r dt + c·t` (least squares; `c` takes a gyro offset): 1 when both are
/// in degrees and signed alike. `None` without a heading, or where the record does not turn
/// enough to tell (the heading moves less than 10° rms about its straight line in time) or
/// the fit explains less than 90 % of the heading's variation.
fn heading_turn_ratio(rec: &Record) -> Option<f64> {
    let psi = rec.psi.as_ref()?;
    let n = rec.len();
    if n < 10 || psi.len() != n {
        return None;
    }
    let mut h = psi.clone();
    unwrap_degrees(&mut h);
    // the integrated rate (trapezoid) and time, both from 0
    let mut int = vec![0.0; n];
    for t in 1..n {
        int[t] = int[t - 1] + 0.5 * (rec.y[t - 1] + rec.y[t]) * rec.ts;
    }
    let time: Vec<f64> = (0..n).map(|t| t as f64 * rec.ts).collect();
    let dh: Vec<f64> = h.iter().map(|v| v - h[0]).collect();
    if dh.iter().chain(&int).any(|v| !v.is_finite()) {
        return None;
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let (rr, rt, tt) = (dot(&int, &int), dot(&int, &time), dot(&time, &time));
    let (rh, th) = (dot(&int, &dh), dot(&time, &dh));
    let det = rr * tt - rt * rt;
    if det <= 0.0 || tt <= 0.0 {
        return None;
    }
    // how far the heading moves about its own straight line through 0 in time (rms)
    let hh = dot(&dh, &dh);
    let wiggle = ((hh - th * th / tt) / n as f64).max(0.0).sqrt();
    if wiggle < 10.0 {
        return None;
    }
    let b = (rh * tt - th * rt) / det;
    let c = (rr * th - rt * rh) / det;
    let sse: f64 = (0..n)
        .map(|t| (dh[t] - b * int[t] - c * time[t]).powi(2))
        .sum();
    let mean = dh.iter().sum::<f64>() / n as f64;
    let sst: f64 = dh.iter().map(|v| (v - mean).powi(2)).sum();
    (sst > 0.0 && sse <= 0.1 * sst).then_some(b)
}

/// Removes the 360° jumps of a heading logged in [0, 360) (or (−180, 180]): each sample
/// moves to within 180° of the one before, so the heading is continuous through north and
/// its differences are turn angles. Sines and cosines of it are unchanged.
///
/// ```
/// let mut psi = vec![358.0, 359.5, 0.5, 2.0, 1.0, 359.0];
/// yawcast::io::data::unwrap_degrees(&mut psi);
/// assert_eq!(psi, vec![358.0, 359.5, 360.5, 362.0, 361.0, 359.0]);
/// ```
pub fn unwrap_degrees(psi: &mut [f64]) {
    let mut offset = 0.0;
    for i in 1..psi.len() {
        let raw = psi[i] + offset;
        let step = raw - psi[i - 1];
        let turns = ((step + 180.0) / 360.0).floor();
        offset -= 360.0 * turns;
        psi[i] = raw - 360.0 * turns;
    }
}

/// A logger's period: the median of the time steps that go forward (`NaN` when none does).
pub(crate) fn median_step(t: &[f64]) -> f64 {
    let mut steps: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|s| *s > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    match steps.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => steps[n / 2],
        n => 0.5 * (steps[n / 2 - 1] + steps[n / 2]),
    }
}

/// Checks that `t` advances one sample per period and returns the period.
///
/// The period is the median of the steps that go forward. Logged time stamps jitter: a row
/// may come late or early (the step before it is then longer or shorter, the one after it
/// the opposite), and each row still holds one sample as long as every step is within half
/// a period of the period — stamps off their grid by up to a quarter period each. The
/// sample time returned is the slope of the least-squares line through the stamps, snapped
/// to a value of at most three significant digits within [`SNAP_TOL`] of it (a logger at
/// 1 Hz with jitter gives 1 s, not 0.99943 s).
///
/// # Errors
/// [`DataError::NonUniform`] naming the first row whose step is not positive (time going
/// back or repeated), spans two or more periods (missing samples) or less than half of one
/// (an extra sample).
///
/// ```
/// use std::path::Path;
/// let t = [0.0, 1.01, 1.99, 3.0, 4.0, 5.0];
/// assert_eq!(yawcast::io::data::check_uniform(&t, Path::new("x.csv")).unwrap(), 1.0);
/// let gap = [0.0, 1.0, 2.0, 4.0, 5.0];
/// let e = yawcast::io::data::check_uniform(&gap, Path::new("x.csv")).unwrap_err();
/// assert!(e.to_string().contains("row 4") && e.to_string().contains("1 sample missing"));
/// ```
pub fn check_uniform(t: &[f64], path: &Path) -> Result<f64, DataError> {
    let n = t.len();
    let h = median_step(t);
    // the first row that breaks the sampling, in row order
    for i in 0..n - 1 {
        let step = t[i + 1] - t[i];
        let what = if step.is_nan() || step < 0.0 {
            Some(
                "time goes back (a clock restart, or two runs in one file: `yawcast split` \
                 cuts the record there)"
                    .to_string(),
            )
        } else if step == 0.0 {
            Some("the time stamp repeats the row before".to_string())
        } else {
            let periods = (step / h).round();
            if periods >= 2.0 {
                let missing = periods - 1.0;
                Some(format!(
                    "{missing} sample{} missing; split the record there (`yawcast split`) or fill \
                     the gap",
                    if missing == 1.0 { "" } else { "s" }
                ))
            } else if periods < 1.0 {
                Some(
                    "less than half a period after the row before (an extra sample); remove it"
                        .to_string(),
                )
            } else {
                None
            }
        };
        if let Some(what) = what {
            return Err(DataError::NonUniform {
                path: path.to_path_buf(),
                row: i + 2,
                step,
                expected: h,
                what,
            });
        }
    }
    // the least-squares slope of t against the sample index
    let mid = (n - 1) as f64 / 2.0;
    let t_mean = t.iter().sum::<f64>() / n as f64;
    let (num, den) = t.iter().enumerate().fold((0.0, 0.0), |(a, b), (i, ti)| {
        let di = i as f64 - mid;
        (a + di * (ti - t_mean), b + di * di)
    });
    Ok(snap((num / den).max(f64::MIN_POSITIVE)))
}

/// `ts` rounded to the fewest significant digits (one to three) that move it by at most
/// [`SNAP_TOL`] (relative); `ts` itself when none does.
fn snap(ts: f64) -> f64 {
    for digits in 1..=3 {
        let k = digits - 1 - ts.log10().floor() as i32;
        let snapped = if k >= 0 {
            let s = 10f64.powi(k);
            (ts * s).round() / s
        } else {
            let s = 10f64.powi(-k);
            (ts / s).round() * s
        };
        if (snapped - ts).abs() <= SNAP_TOL * ts {
            return snapped;
        }
    }
    ts
}
