//! Long records: the blocks a record set longer than [`WINDOW`] samples is diagnosed on.

use crate::io::data::Record;

#[cfg(doc)]
use super::diagnose;

/// Samples of one record set (the trials, the reference records, the held-out records) that
/// [`diagnose`] works on at most. A longer set is read as blocks of [`WINDOW_BLOCK`] samples
/// spread evenly over each record ([`window`]); every statistic, replicate and refit then runs
/// on the blocks, so the time and memory a diagnosis takes stop growing with the records'
/// length. Each block is a record of its own (its own x̂(0)); the likelihood statistics and
/// their bootstrap nulls are measured on the same blocks, so the test keeps its level. The
/// heading, speed-over-ground and anemometer channels are the exception: they read the
/// records whole (thinned past [`CHANNEL_WINDOW`]: [`channel_records`]), as their calibration
/// compares each record with the others of its set, which pieces of one record cannot stand
/// in for.
pub const WINDOW: usize = 12_000;
/// Length of the blocks of a set longer than [`WINDOW`] (samples).
pub const WINDOW_BLOCK: usize = 2_000;

/// The blocks `diagnose` reads of `recs` (see [`WINDOW`]), or `None` when the set holds at
/// most [`WINDOW`] samples and is used whole. Each record gets a share of the
/// `WINDOW / WINDOW_BLOCK` blocks in proportion to its length (at least one), as blocks of
/// `min(WINDOW_BLOCK, its length)` samples, the first at its start, the last at its end and
/// the others evenly between; block names are `name@first-sample`. `None` too when the
/// blocks would be the whole records (many records shorter than a block).
///
/// ```
/// use yawcast::{diagnose::{window, WINDOW_BLOCK}, io::data::Record};
/// let r = Record::from_uy("long", 1.0, vec![0.0; 100_000], vec![0.0; 100_000]);
/// let blocks = window(std::slice::from_ref(&r)).unwrap();
/// assert_eq!(blocks.len(), 6);
/// assert!(blocks.iter().all(|b| b.len() == WINDOW_BLOCK));
/// assert_eq!(blocks[1].name, "long@19600");
/// assert_eq!(blocks[5].t[WINDOW_BLOCK - 1], 99_999.0);
/// assert!(window(&[r.slice(0, 12_000)]).is_none());
/// // ten records of 1 800 samples: one block each would be each whole record
/// assert!(window(&vec![r.slice(0, 1_800); 10]).is_none());
/// ```
pub fn window(recs: &[Record]) -> Option<Vec<Record>> {
    let total: usize = recs.iter().map(Record::len).sum();
    if total <= WINDOW {
        return None;
    }
    let blocks = WINDOW / WINDOW_BLOCK;
    let mut out = Vec::new();
    for r in recs {
        let len = r.len();
        let l = WINDOW_BLOCK.min(len);
        let k = ((blocks * len + total / 2) / total).clamp(1, len / l.max(1));
        for j in 0..k {
            let st = if k == 1 { 0 } else { j * (len - l) / (k - 1) };
            let mut b = r.slice(st, st + l);
            b.name = format!("{}@{st}", r.name);
            out.push(b);
        }
    }
    // many short records: one whole record each is no window at all
    let kept: usize = out.iter().map(Record::len).sum();
    (kept < total).then_some(out)
}

/// Samples of one record set the heading, speed-over-ground and anemometer channels read at
/// most: a longer set is thinned ([`channel_records`]), so their cost, linear in the samples,
/// stays bounded too.
pub const CHANNEL_WINDOW: usize = 120_000;

/// The records the channels read: `None` when the set holds at most [`CHANNEL_WINDOW`]
/// samples and is read as it is; otherwise every record thinned by the smallest `k` that
/// brings the set within it — the commands and yaw rate averaged over each run of `k`
/// samples (so the rate still integrates to the heading), the heading, speed, course and
/// wind at the run's first sample, the sample time `k` times longer. Every record stays
/// whole: the calibration compares records, so they keep their span of headings.
///
/// ```
/// use yawcast::{diagnose::{channel_records, CHANNEL_WINDOW}, io::data::Record};
/// let r = Record::from_uy("long", 0.25, vec![1.0; 200_000], (0..200_000).map(|t| (t % 2) as f64).collect());
/// let thin = channel_records(std::slice::from_ref(&r)).unwrap();
/// assert_eq!((thin[0].len(), thin[0].ts), (100_000, 0.5));
/// assert_eq!((thin[0].y[7], thin[0].t[1]), (0.5, 0.5));
/// assert!(channel_records(&[r.slice(0, CHANNEL_WINDOW)]).is_none());
/// ```
pub fn channel_records(recs: &[Record]) -> Option<Vec<Record>> {
    let total: usize = recs.iter().map(Record::len).sum();
    if total <= CHANNEL_WINDOW {
        return None;
    }
    let k = total.div_ceil(CHANNEL_WINDOW);
    // a short record among long ones keeps three samples at least
    Some(
        recs.iter()
            .map(|r| thinned(r, k.min(r.len() / 3).max(1)))
            .collect(),
    )
}

/// `r` thinned by `k` ([`channel_records`]).
fn thinned(r: &Record, k: usize) -> Record {
    let n = r.len() / k;
    let mean = |v: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|j| v[j * k..(j + 1) * k].iter().sum::<f64>() / k as f64)
            .collect()
    };
    let first = |v: &[f64]| -> Vec<f64> { (0..n).map(|j| v[j * k]).collect() };
    let first_of = |v: &Option<Vec<f64>>| v.as_deref().map(first);
    Record {
        name: r.name.clone(),
        ts: r.ts * k as f64,
        t: first(&r.t),
        u: mean(&r.u),
        y: mean(&r.y),
        psi: first_of(&r.psi),
        speed: first_of(&r.speed),
        wind_speed: first_of(&r.wind_speed),
        wind_angle: first_of(&r.wind_angle),
        cog: first_of(&r.cog),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::data::heading_bias;

    #[test]
    fn thinned_records_keep_the_gyro_offset_the_heading_shows() {
        // four hours at 4 Hz, turning slowly, the gyro reading 0.01 °/s high: thinned to
        // 120 000 samples (k = 2) and to a tenth of that (k = 20 on a set ten times longer)
        // the rate still integrates to the heading
        let ts = 0.25;
        let n = 240_000;
        let r: Vec<f64> = (0..n)
            .map(|t| 0.4 * (t as f64 * ts / 300.0).sin())
            .collect();
        let mut psi = vec![10.0];
        for t in 0..n - 1 {
            psi.push(psi[t] + 0.5 * ts * (r[t] + r[t + 1]));
        }
        let y: Vec<f64> = r.iter().map(|v| v + 0.01).collect();
        let mut rec = Record::from_uy("gyro", ts, vec![0.0; n], y);
        rec.psi = Some(psi);
        let whole = heading_bias(std::slice::from_ref(&rec)).unwrap();
        let thin = channel_records(std::slice::from_ref(&rec)).unwrap();
        assert_eq!((thin[0].len(), thin[0].ts), (120_000, 0.5));
        let b = heading_bias(&thin).unwrap();
        assert!((whole.bias - 0.01).abs() < 1e-6, "{whole:?}");
        assert!((b.bias - 0.01).abs() < 1e-4, "{b:?}");
        let ten = vec![rec; 10];
        let thin = channel_records(&ten).unwrap();
        assert_eq!(thin[0].len(), 12_000);
        let b = heading_bias(&thin).unwrap();
        assert!((b.bias - 0.01).abs() < 1e-3, "{b:?}");
    }
}
