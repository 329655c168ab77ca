//! Records that each hold one course: a yaw moment that changes with the course (a wind's,
//! or a current's that turns the ship) shows as prediction errors whose offset differs from
//! record to record, while the manoeuvre's own mismatch with the linear model, the same on
//! every course, moves them all alike.
//!
//! Over one course the heading harmonics of a record are its own offset plus a slope on
//! how far it has turned (`separation.rs`), and so is what a linear model misses of the
//! hull in every swing: on such records the yaw channel's harmonic regression cannot tell
//! a wind from the manoeuvre. But the manoeuvre's part is the same on every course, and a
//! wind's is not: from one side it pushes the ship one way, from the other the other way,
//! and how fast it grows with the heading changes with the course too. So each record's
//! `h`-step errors are regressed on an offset and the heading about its own mean, and the
//! test is whether the offsets differ between the trial records by more than their noise
//! (a χ² against the weighted mean, `m − 1` df for `m` records; the slopes, where the
//! manoeuvre's own mismatch shows most, are not compared: [`between`]). The noise is
//! estimated within each record (Newey–West: the errors of overlapping horizons are
//! correlated) and calibrated on the reference records, which sail no wind of their own:
//! their χ² per degree of freedom, where above 1, divides the trials' (an F test then, on
//! the reference's degrees of freedom), as the ground velocity's lanes are calibrated.

use super::evidence::{error_stride, errors_at};
use crate::identify::model::Model;
use crate::io::data::Record;
use crate::stats::f_sf;

/// What the trials' error offsets on their own courses show of a yaw moment that changes
/// with the course.
#[derive(Debug, Clone, Copy)]
pub(super) struct CourseEvidence {
    /// χ² of the trial records' error offsets against their weighted mean, divided by
    /// `inflation`.
    pub(super) chi: f64,
    /// Its degrees of freedom, `m − 1`.
    pub(super) df: f64,
    /// The reference records' own χ² per degree of freedom (≥ 1).
    pub(super) inflation: f64,
    /// Its degrees of freedom (∞ where the inflation is 1).
    pub(super) inflation_df: f64,
    /// p-value: F on (`df`, `inflation_df`), which is χ² where the inflation is 1.
    pub(super) p: f64,
    /// The smallest and largest of the trial records' error offsets (yaw-rate units, °/s).
    pub(super) offsets: [f64; 2],
    /// The widest angle between two trial records' mean headings (deg, 0–180): how far
    /// apart the courses compared lie.
    pub(super) span_deg: f64,
}

/// Each record's `h`-step errors and the headings (rad) of the samples they predict.
fn record_errors(model: &Model, rec: &Record, h: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let psi = rec.psi.as_ref()?;
    let (e, at) = errors_at(model, rec, h);
    let x = at.iter().map(|&t| psi[t].to_radians()).collect();
    Some((e, x))
}

/// The offset of errors `e` on headings `x` (their mean, about the headings' own mean),
/// with its Newey–West variance over what is left beyond the offset and a slope on the
/// heading. `None` for too few samples.
fn fit(e: &[f64], x: &[f64], h: usize) -> Option<(f64, f64)> {
    let n = e.len();
    if n < 8 {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let x: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let a = e.iter().sum::<f64>() / n as f64;
    let b = x.iter().zip(e).map(|(xi, ei)| xi * ei).sum::<f64>() / sxx;
    let r: Vec<f64> = e.iter().zip(&x).map(|(ei, xi)| ei - a - b * xi).collect();
    // Newey–West over the residuals: overlapping horizons, a slow disturbance
    let lags = (2 * h / error_stride(h)).clamp(1, n / 4);
    let mut s = 0.0;
    for l in 0..=lags {
        let w = if l == 0 {
            1.0
        } else {
            1.0 - l as f64 / (lags + 1) as f64
        };
        let g: f64 = (l..n).map(|t| r[t] * r[t - l]).sum();
        s += if l == 0 { g } else { (g + g) * w };
    }
    let inv = 1.0 / n as f64;
    Some((a, inv * s * inv))
}

/// χ² of the pieces' offsets ([`fit`]: each the mean error about the record's own mean
/// heading, its slope on the heading taken out) against their precision-weighted mean, and
/// its degrees of freedom (one fewer than the pieces); the offsets' range. `None` for fewer
/// than two pieces.
///
/// The slopes are not compared: within a ±20° swing a wind's moment changes little, while
/// the slope is where the manoeuvre's own mismatch with the hull shows (Mariner's
/// effect-free zig-zag reference records' slopes differ by χ² = 5.2 on 2 df, their offsets
/// by 0.4), so the (offset, slope) pairs on `2(m − 1)` df were calibrated by the slopes'
/// spread and lost the offsets' difference: Mariner's hidden winds on zig-zags, offsets
/// χ² = 25–70 on 2 df, read p = 0.011–0.065 that way.
fn between(pieces: &[(&[f64], &[f64])], h: usize) -> Option<(f64, f64, [f64; 2])> {
    let fits: Vec<(f64, f64)> = pieces
        .iter()
        .map(|(e, x)| fit(e, x, h))
        .collect::<Option<_>>()?;
    if fits.len() < 2 {
        return None;
    }
    let w: Vec<f64> = fits.iter().map(|(_, v)| 1.0 / v).collect();
    let total: f64 = w.iter().sum();
    if !total.is_finite() || total <= 0.0 {
        return None;
    }
    let mean = fits.iter().zip(&w).map(|((a, _), w)| w * a).sum::<f64>() / total;
    let chi: f64 = fits
        .iter()
        .zip(&w)
        .map(|((a, _), w)| w * (a - mean) * (a - mean))
        .sum();
    let offsets = fits.iter().map(|(a, _)| *a);
    let lo = offsets.clone().fold(f64::INFINITY, f64::min);
    let hi = offsets.fold(f64::NEG_INFINITY, f64::max);
    Some((chi.max(0.0), (fits.len() - 1) as f64, [lo, hi]))
}

/// Each record of `set` whole, as (errors, headings).
fn whole(set: &[(Vec<f64>, Vec<f64>)]) -> Vec<(&[f64], &[f64])> {
    set.iter().map(|(e, x)| (&e[..], &x[..])).collect()
}

/// [`CourseEvidence`] of the trials `est` against `reference`, on `model`'s `h`-step errors.
/// `None` with fewer than two trial records, a record without heading or too short, a
/// singular fit, or courses not [`set_apart`].
pub(super) fn course_evidence(
    model: &Model,
    est: &[Record],
    reference: &[Record],
    h: usize,
) -> Option<CourseEvidence> {
    let errs = |recs: &[Record]| -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
        recs.iter().map(|r| record_errors(model, r, h)).collect()
    };
    let (trial, refs) = (errs(est)?, errs(reference)?);
    let (raw, df, offsets) = between(&whole(&trial), h)?;
    // the noise: the reference's records against each other, on their own courses
    let (inflation, inflation_df) = match between(&whole(&refs), h) {
        Some((c, d, _)) if c / d > 1.0 => (c / d, d),
        _ => (1.0, f64::INFINITY),
    };
    let chi = raw / inflation;
    // F on (df, ∞) is χ²(df)/df: one form for an inflation of 1 too
    let p = f_sf(chi / df, df, inflation_df);
    // each record's mean heading (the circular mean of the samples its errors predict)
    let courses: Vec<f64> = trial
        .iter()
        .map(|(_, x)| {
            let (s, c) = x
                .iter()
                .fold((0.0, 0.0), |(s, c), v| (s + v.sin(), c + v.cos()));
            s.atan2(c).to_degrees()
        })
        .collect();
    let span_deg = widest_span(&courses);
    if !set_apart(span_deg, est) {
        return None;
    }
    Some(CourseEvidence {
        chi,
        df,
        inflation,
        inflation_df,
        p,
        offsets,
        span_deg,
    })
}

/// Whether records whose courses span `span_deg` ([`widest_span`]) were sailed on courses
/// set apart, and not on one course the manoeuvre alone moves: the span at least the
/// median of the records' heading swings (each record's standard deviation of heading
/// about its mean; `false` where a record logs none). A manoeuvre moves each record's
/// mean heading by a part of its swing, so records closer than that hold one course, over
/// which a current or a moment changing with the course is read from the manoeuvre's own
/// offsets: HSVA's 9 free-running zig-zags of the KVLCC2 model (±5–35°, swings of
/// 2.8–18.3°, median 12.9°), on courses within 3° of each other in the towing tank, read a current of 1.43 m/s beside −0.28 m/s
/// through the water (p = 5.7·10⁻⁴). The simulated suites' ±20° zig-zag sets span 46–168°
/// against swings of 19–23°, their autopilot logs 47–174° against 7–9°.
pub(super) fn set_apart(span_deg: f64, recs: &[Record]) -> bool {
    let swings: Option<Vec<f64>> = recs
        .iter()
        .map(|r| {
            let psi = r.psi.as_deref().filter(|p| !p.is_empty())?;
            let n = psi.len() as f64;
            let mean = psi.iter().sum::<f64>() / n;
            Some((psi.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt())
        })
        .collect();
    swings
        .and_then(|mut s| crate::identify::track::median(&mut s))
        .is_some_and(|median| span_deg >= median)
}

/// The widest angle (deg, 0–180) between two of `courses` (deg).
pub(super) fn widest_span(courses: &[f64]) -> f64 {
    let mut span: f64 = 0.0;
    for (i, a) in courses.iter().enumerate() {
        for b in &courses[i + 1..] {
            span = span.max(((a - b + 180.0).rem_euclid(360.0) - 180.0).abs());
        }
    }
    span
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn courses_closer_than_the_records_swing_are_one_course() {
        // headings swinging ±20° (a standard deviation of 20°) about course `c`
        let zz = |c: f64| {
            let psi: Vec<f64> = (0..400)
                .map(|i| c + if (i / 50) % 2 == 0 { 20.0 } else { -20.0 })
                .collect();
            let mut r = Record::from_uy("r", 1.0, vec![0.0; 400], vec![0.0; 400]);
            r.psi = Some(psi);
            r
        };
        let tank = [zz(-1.8), zz(0.5), zz(1.7)];
        let courses = [-1.8, 0.5, 1.7];
        assert!((widest_span(&courses) - 3.5).abs() < 1e-12);
        assert!(!set_apart(widest_span(&courses), &tank));
        // courses 98° apart: set apart
        let sea = [zz(10.0), zz(60.0), zz(108.0)];
        assert!(set_apart(widest_span(&[10.0, 60.0, 108.0]), &sea));
        // the edge: the median swing is the records' standard deviation, 20°
        assert!(set_apart(20.0, &tank) && !set_apart(19.99, &tank));
        // a record without heading: no reading
        let mut blind = sea.to_vec();
        blind[1].psi = None;
        assert!(!set_apart(98.0, &blind));
    }

    /// Errors `offset + slope·x` plus a deterministic noise of std ≈ 0.01 on headings that
    /// swing ±0.35 rad about the course.
    fn piece(offset: f64, slope: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut s = seed;
        let mut noise = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.035
        };
        let x: Vec<f64> = (0..200).map(|t| 0.35 * (t as f64 / 15.0).sin()).collect();
        let e = x.iter().map(|&xi| offset + slope * xi + noise()).collect();
        (e, x)
    }

    #[test]
    fn records_whose_offsets_differ_with_the_course_stand_out_and_alike_ones_do_not() {
        // three records with the manoeuvre's own slope (0.2) and offset (0.05): alike
        let alike: Vec<_> = (0..3).map(|i| piece(0.05, 0.2, i)).collect();
        let (chi, df, offsets) = between(&whole(&alike), 1).unwrap();
        assert_eq!(df, 2.0);
        assert!(chi < 9.21, "{chi}"); // χ²₂ at 0.01
        assert!(offsets[1] - offsets[0] < 0.01, "{offsets:?}");
        // slopes that differ (the manoeuvre's own mismatch, swing by swing) are not compared
        let swung: Vec<_> = [0.0, 0.2, 0.4]
            .iter()
            .enumerate()
            .map(|(i, &b)| piece(0.05, b, i as u64))
            .collect();
        let (chi, _, _) = between(&whole(&swung), 1).unwrap();
        assert!(chi < 9.21, "{chi}");
        // a wind's: each course its own offset and slope
        let wind: Vec<_> = [(0.02, 0.1), (0.08, 0.3), (0.05, -0.1)]
            .iter()
            .enumerate()
            .map(|(i, &(a, b))| piece(a, b, i as u64))
            .collect();
        let (chi, _, offsets) = between(&whole(&wind), 1).unwrap();
        assert!(chi > 100.0, "{chi}");
        assert!((offsets[0] - 0.02).abs() < 0.005, "{offsets:?}");
        assert!((offsets[1] - 0.08).abs() < 0.005, "{offsets:?}");
        // one record: nothing to compare
        assert!(between(&whole(&wind[..1]), 1).is_none());
    }
}
