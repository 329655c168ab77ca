//! Heading statistics: the gyro offset the heading shows and block-sum means.

use super::Record;

/// Gyro-bias estimate from heading: `mean((r(t)+r(t+1))/2 − Δψ/Ts)` with its standard error
/// from block sums. `None` without heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingBias {
    /// Estimated rate-sensor offset (deg/s).
    pub bias: f64,
    /// Its standard error (deg/s).
    pub se: f64,
    /// Samples used.
    pub n: usize,
}

/// Rate-sensor offset seen by the heading channel over `recs` (pooled), or `None` when a
/// record has no heading.
///
/// ```
/// use yawcast::io::data::{heading_bias, Record};
/// // heading turns at 1 °/s, the gyro reads 1.2 °/s
/// let mut r = Record::from_uy("x", 1.0, vec![0.0; 400], vec![1.2; 400]);
/// r.psi = Some((0..400).map(|i| i as f64).collect());
/// let hb = heading_bias(&[r]).unwrap();
/// assert!((hb.bias - 0.2).abs() < 1e-12);
/// ```
pub fn heading_bias(recs: &[Record]) -> Option<HeadingBias> {
    HeadingBias::of(&rate_less_turn(recs)?)
}

impl HeadingBias {
    /// The pooled offset of series formed by [`rate_less_turn`]; `None` when they hold no
    /// value.
    pub(crate) fn of(series: &[Vec<f64>]) -> Option<HeadingBias> {
        let (bias, se, n) = block_mean(series)?;
        Some(HeadingBias { bias, se, n })
    }
}

/// Each record's series `(r(t)+r(t+1))/2 − Δψ/Ts` (records shorter than 3 samples left
/// out), or `None` when a record has no heading: what [`heading_bias`] pools, formed once
/// where a caller wants the set's offset and each record's.
pub(crate) fn rate_less_turn(recs: &[Record]) -> Option<Vec<Vec<f64>>> {
    let mut series = Vec::with_capacity(recs.len());
    for r in recs {
        let psi = r.psi.as_ref()?;
        if r.len() < 3 {
            continue;
        }
        series.push(
            (0..r.len() - 1)
                .map(|t| 0.5 * (r.y[t] + r.y[t + 1]) - (psi[t + 1] - psi[t]) / r.ts)
                .collect::<Vec<f64>>(),
        );
    }
    Some(series)
}

/// Pooled mean of `series` with its standard error from block sums — blocks of about √m
/// samples (10 to 200) within each series of m values, so serial correlation inside a block
/// counts — and the number of values used. Non-finite values (missing samples) are skipped;
/// `None` when none is left.
///
/// ```
/// // 500 zeros then 500 ones: the mean is 0.5; the blocks see the two halves, so the
/// // standard error is far above the white-noise 0.5/√1000 = 0.016
/// let mut s = vec![0.0; 500];
/// s.extend([1.0; 500]);
/// s.push(f64::NAN); // a missing sample is skipped
/// let (mean, se, n) = yawcast::io::data::block_mean(&[s]).unwrap();
/// assert_eq!((mean, n), (0.5, 1000));
/// assert!(se > 0.05, "{se}");
/// ```
pub fn block_mean(series: &[Vec<f64>]) -> Option<(f64, f64, usize)> {
    let mut sum = 0.0;
    let mut n = 0usize;
    let mut blocks: Vec<f64> = Vec::new();
    for s in series {
        let m = s.iter().filter(|v| v.is_finite()).count();
        if m == 0 {
            continue;
        }
        let l = block_len(m);
        let mut acc = 0.0;
        let mut cnt = 0;
        for &d in s.iter().filter(|v| v.is_finite()) {
            sum += d;
            n += 1;
            acc += d;
            cnt += 1;
            if cnt == l {
                blocks.push(acc);
                acc = 0.0;
                cnt = 0;
            }
        }
        if cnt > 0 {
            blocks.push(acc * l as f64 / cnt as f64);
        }
    }
    if n == 0 {
        return None;
    }
    let mean = sum / n as f64;
    let l = (n as f64 / blocks.len().max(1) as f64).max(1.0);
    let var: f64 = blocks.iter().map(|b| (b - mean * l).powi(2)).sum::<f64>();
    let se = (var.max(0.0)).sqrt() / n as f64;
    Some((mean, se.max(1e-12), n))
}

fn block_len(n: usize) -> usize {
    ((n as f64).sqrt().round() as usize).clamp(10, 200)
}
