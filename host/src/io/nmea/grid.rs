//! Pass 3 of the NMEA reader: every channel checked for gaps and resampled onto one uniform
//! grid; the navigation channels interpolated onto it with their holes kept.

use std::path::Path;

use super::{hms, Chan, NmeaError, NmeaOptions, Series};
use crate::io::data::{uniform_grid, Record};

/// The median positive spacing of a channel's samples (s).
pub(super) fn median_step(v: &[(f64, f64, usize)]) -> f64 {
    let mut d: Vec<f64> = v
        .windows(2)
        .map(|w| w[1].0 - w[0].0)
        .filter(|d| *d > 0.0)
        .collect();
    if d.is_empty() {
        return f64::INFINITY;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// Linear interpolation of `v` at `grid` (angular channels unwrapped first), `NaN` outside
/// the samples' span and inside holes longer than `limit`; no rounding (positions).
pub(super) fn interp_gaps(
    v: &[(f64, f64, usize)],
    grid: &[f64],
    angular: bool,
    limit: f64,
) -> Vec<f64> {
    let (ts, xs) = samples(v, angular);
    let mut j = 0;
    grid.iter()
        .map(|&g| {
            if ts.len() < 2 || g < ts[0] || g > ts[ts.len() - 1] {
                return f64::NAN;
            }
            while j + 2 < ts.len() && ts[j + 1] < g {
                j += 1;
            }
            let (t0, t1) = (ts[j], ts[j + 1]);
            if t1 - t0 > limit {
                return f64::NAN;
            }
            let w = ((g - t0) / (t1 - t0)).clamp(0.0, 1.0);
            xs[j] + w * (xs[j + 1] - xs[j])
        })
        .collect()
}

/// Pass 3: gap check and resampling onto the grid.
pub(super) fn resample(
    mut series: Series,
    path: &Path,
    name: &str,
    opts: &NmeaOptions,
) -> Result<Record, NmeaError> {
    // the channel that sets the grid: the rate of turn, or the heading it is formed from
    let (base, required) = if opts.rate_from_heading {
        series.remove(&Chan::Rate);
        (Chan::Heading, (Chan::Heading, "HDT/HDG", "heading"))
    } else {
        (Chan::Rate, (Chan::Rate, "ROT", "rate of turn"))
    };
    let has = |ch: Chan| series.get(&ch).is_some_and(|v| v.len() >= 2);
    for (ch, sentence, what) in [required, (Chan::Angle, "RSA", "rudder sensor angle")] {
        if !has(ch) {
            let hint = if ch == Chan::Rate && has(Chan::Heading) {
                "; without a rate gyro, --rate-from-heading forms the yaw rate from the \
                 HDT/HDG heading"
            } else {
                ""
            };
            return Err(NmeaError::Missing {
                path: path.to_path_buf(),
                sentence,
                what,
                hint,
            });
        }
    }
    let ts = match opts.ts {
        Some(ts) => ts,
        None => {
            let s = median_step(&series[&base]);
            ((s * 1000.0).round() / 1000.0).max(0.001)
        }
    };
    let t_start = series
        .values()
        .map(|v| v[0].0)
        .fold(f64::NEG_INFINITY, f64::max);
    let t_end = series
        .values()
        .map(|v| v[v.len() - 1].0)
        .fold(f64::INFINITY, f64::min);
    // Gap check within the common span.
    for (&ch, v) in &series {
        let limit = opts
            .max_gap
            .unwrap_or_else(|| (2.0 * ts).max(2.5 * median_step(v)));
        for w in v.windows(2) {
            let (a, b) = (w[0].0, w[1].0);
            if b > t_start && a < t_end && b - a > limit {
                return Err(NmeaError::Gap {
                    path: path.to_path_buf(),
                    sentence: ch.sentence(),
                    what: ch.what(),
                    at: hms(a),
                    line: w[0].2,
                    length: b - a,
                    limit,
                });
            }
        }
    }
    let grid = uniform_grid(t_start, t_end, ts);
    let n = grid.len();
    if n < 2 {
        return Err(NmeaError::TooShort {
            path: path.to_path_buf(),
            found: n,
            needed: 2,
        });
    }
    let mut rec = Record {
        name: name.to_string(),
        ts,
        t: (0..n).map(|i| round_us(i as f64 * ts)).collect(),
        ..Record::default()
    };
    for (&ch, v) in &series {
        let vals = interp(v, &grid, ch.angular());
        match ch {
            Chan::Rate => rec.y = vals,
            Chan::Angle => rec.u = vals,
            Chan::Heading => rec.psi = Some(vals),
            Chan::Speed => rec.speed = Some(vals),
            Chan::WindSpeed => rec.wind_speed = Some(vals),
            Chan::WindAngle => {
                rec.wind_angle = Some(vals.into_iter().map(|a| a.rem_euclid(360.0)).collect())
            }
            // read by parse_nmea_nav, filtered out before
            Chan::Course | Chan::Lat | Chan::Lon => {}
        }
    }
    if opts.rate_from_heading {
        if let Some(psi) = rec.psi.as_ref() {
            rec.y = crate::io::data::heading_rate(psi, ts);
        }
    }
    Ok(rec)
}

fn round_us(t: f64) -> f64 {
    (t * 1e6).round() / 1e6
}

/// Linear interpolation of `v` (sorted by time; equal times keep the last) at `grid`;
/// angular channels are unwrapped first.
fn interp(v: &[(f64, f64, usize)], grid: &[f64], angular: bool) -> Vec<f64> {
    let (ts, xs) = samples(v, angular);
    let mut j = 0;
    grid.iter()
        .map(|&g| {
            while j + 2 < ts.len() && ts[j + 1] < g {
                j += 1;
            }
            if ts.len() == 1 {
                return xs[0];
            }
            let (t0, t1) = (ts[j], ts[j + 1]);
            let w = ((g - t0) / (t1 - t0)).clamp(0.0, 1.0);
            let x = xs[j] + w * (xs[j + 1] - xs[j]);
            round_us(x)
        })
        .collect()
}

/// A channel's samples as times and values, sorted by time as logged (equal times keep the
/// last value), angular channels unwrapped.
fn samples(v: &[(f64, f64, usize)], angular: bool) -> (Vec<f64>, Vec<f64>) {
    let mut ts: Vec<f64> = Vec::with_capacity(v.len());
    let mut xs: Vec<f64> = Vec::with_capacity(v.len());
    for &(t, x, _) in v {
        let x = match (angular, xs.last()) {
            (true, Some(&prev)) => prev + (x - prev + 180.0).rem_euclid(360.0) - 180.0,
            _ => x,
        };
        match xs.last_mut() {
            Some(l) if ts.last() == Some(&t) => *l = x,
            _ => {
                ts.push(t);
                xs.push(x);
            }
        }
    }
    (ts, xs)
}
