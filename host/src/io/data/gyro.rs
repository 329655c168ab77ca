//! The heading channel's gyro offset: the gyro's mean reading less the heading's turn,
//! trials less reference, judged against the noise within the records and against how far
//! the records' own offsets wander.

use super::heading::{rate_less_turn, HeadingBias};
use super::Record;
use crate::stats::{f_quantile, normal_sf, student_t_quantile, student_t_sf};

/// The gyro offset the heading shows: trials less reference, or the trials' own without
/// one (°/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroOffset {
    /// The offset: the sets' pooled `mean r − mean dψ/dt`, trials less reference.
    pub offset: f64,
    /// Its standard error: the block sums' within the records, and how far the records'
    /// own offsets wander beyond that ([`gyro_offset`]).
    pub se: f64,
    /// The degrees of freedom of that error (Satterthwaite's) where the records' wander
    /// adds to it (a Student t); `None` where it adds nothing (a normal).
    pub dof: Option<f64>,
    /// Samples of the trials used (as [`HeadingBias::n`](super::HeadingBias)).
    pub n: usize,
}

impl GyroOffset {
    /// The smallest offset (°/s, either way) significant at `level` (two-sided, as
    /// [`GyroOffset::p`] reads it): the t or normal quantile times the standard error.
    ///
    /// ```
    /// use yawcast::io::data::GyroOffset;
    /// let g = GyroOffset { offset: 0.0, se: 0.01, dof: None, n: 1000 };
    /// // the normal's two-sided 1 % point, 2.576 standard errors
    /// assert!((g.smallest(0.01) - 0.025_758).abs() < 1e-6);
    /// let at = GyroOffset { offset: g.smallest(0.01), ..g };
    /// assert!((at.p() - 0.01).abs() < 1e-9);
    /// ```
    pub fn smallest(&self, level: f64) -> f64 {
        let q = match self.dof {
            Some(d) => student_t_quantile(0.5 * level, d),
            None => f_quantile(level, 1.0, f64::INFINITY).sqrt(),
        };
        q * self.se
    }

    /// Two-sided p-value of a zero offset.
    pub fn p(&self) -> f64 {
        let z = (self.offset / self.se).abs();
        let one = match self.dof {
            Some(d) => student_t_sf(z, d),
            None => normal_sf(z),
        };
        (2.0 * one).min(1.0)
    }
}

/// The gyro offset the heading shows on `est` less `reference` (none: the trials' own).
///
/// Within a record the block sums of `r − dψ/dt` measure the white noise and what varies
/// within a block. A real rate gyro's offset also wanders more slowly than a record (a
/// fibre-optic gyro's bias instability over minutes; a MEMS gyro's at each switch-on), and
/// then each record's offset differs from the next by more than the block sums say (the
/// Seiun Maru at model scale: records 0.003–0.004 °/s apart against a block error of
/// 0.001 °/s, an effect-free set read as a gyro offset at p = 9·10⁻⁴). As in a one-way
/// analysis of variance with the record as a random effect, the records' spread about their
/// set's mean, pooled over the sets, less what the block sums already give each record's
/// mean, is that wander's variance σ²; it adds σ²(1/k_trials + 1/k_reference) to the
/// offset's variance, and the test is a Student t on Satterthwaite's degrees of freedom
/// (records less sets for the wander's part; the block sums' taken as many). Where the
/// spread is no more than the block sums give (σ² = 0), or a set has one record and the
/// other none to spare, it is the normal test on the block sums alone. `None` without
/// heading.
///
/// ```
/// use yawcast::io::data::{gyro_offset, Record};
/// // three records on one course, the gyro reading 0, 0.01 and 0.02 °/s more than the
/// // heading turns (each with ±0.03 °/s of alternating noise): the offset is their mean,
/// // its error their spread over √3, on 2 degrees of freedom
/// let recs: Vec<Record> = [0.0, 0.01, 0.02]
///     .iter()
///     .map(|&o| {
///         let y = (0..900).map(|i| o + if i % 2 == 0 { 0.03 } else { -0.03 }).collect();
///         let mut r = Record::from_uy("r", 1.0, vec![0.0; 900], y);
///         r.psi = Some(vec![90.0; 900]);
///         r
///     })
///     .collect();
/// let g = gyro_offset(&recs, &[]).unwrap();
/// assert!((g.offset - 0.01).abs() < 1e-4);
/// assert!((g.se - 0.01 / 3f64.sqrt()).abs() < 2e-4, "{g:?}");
/// assert!(g.dof.is_some_and(|d| (d - 2.0).abs() < 0.1) && g.p() > 0.2);
/// ```
pub fn gyro_offset(est: &[Record], reference: &[Record]) -> Option<GyroOffset> {
    // each record's `r − dψ/dt`, formed once for the set's offset and each record's own
    let has_reference = !reference.is_empty();
    let est = rate_less_turn(est)?;
    let reference = if has_reference {
        rate_less_turn(reference)?
    } else {
        Vec::new()
    };
    let t = HeadingBias::of(&est)?;
    let r = if has_reference {
        Some(HeadingBias::of(&reference)?)
    } else {
        None
    };
    let (offset, within) = match r {
        Some(r) => (t.bias - r.bias, t.se.hypot(r.se)),
        None => (t.bias, t.se),
    };
    // each record's own offset and its block-sum variance
    let own = |set: &[Vec<f64>]| -> Vec<(f64, f64)> {
        set.iter()
            .filter_map(|s| HeadingBias::of(std::slice::from_ref(s)))
            .map(|h| (h.bias, h.se * h.se))
            .collect()
    };
    let (mut ss, mut own_var, mut dof, mut inv_k, mut k_all) = (0.0, 0.0, 0usize, 0.0, 0usize);
    for set in [own(&est), own(&reference)]
        .iter()
        .filter(|s| !s.is_empty())
    {
        let k = set.len();
        let mean = set.iter().map(|b| b.0).sum::<f64>() / k as f64;
        ss += set.iter().map(|b| (b.0 - mean).powi(2)).sum::<f64>();
        own_var += set.iter().map(|b| b.1).sum::<f64>();
        dof += k - 1;
        k_all += k;
        inv_k += 1.0 / k as f64;
    }
    let wander = if dof > 0 {
        (ss / dof as f64 - own_var / k_all as f64).max(0.0) * inv_k
    } else {
        0.0
    };
    let var = within * within + wander;
    Some(GyroOffset {
        n: t.n,
        offset,
        se: var.sqrt(),
        dof: (wander > 0.0).then(|| var * var / (wander * wander / dof as f64)),
    })
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// Records of `n` samples at 1 Hz holding one course, the gyro reading each record's
    /// `offsets[i]` plus white noise of 0.03 °/s.
    fn gyro_set(offsets: &[f64], n: usize, seed: u64) -> Vec<Record> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        offsets
            .iter()
            .map(|&o| {
                let y: Vec<f64> = (0..n)
                    .map(|_| o + 0.03 * crate::stats::standard_normal(&mut rng))
                    .collect();
                let mut r = Record::from_uy("g", 1.0, vec![0.0; n], y);
                r.psi = Some(vec![90.0; n]);
                r
            })
            .collect()
    }

    #[test]
    fn a_gyro_offset_wandering_from_record_to_record_is_judged_on_that_spread() {
        // each record's offset 0.003–0.004 °/s from the next, as a gyro's bias instability
        // makes them, and no offset hidden: the block sums alone (0.0004 °/s a set) would
        // call the sets' difference of −0.005 °/s an offset at p ≈ 10⁻¹⁹
        let trials = gyro_set(&[0.0007, -0.0050, -0.0023], 2_000, 1);
        let reference = gyro_set(&[-0.0007, 0.0045, 0.0041], 2_000, 2);
        let g = gyro_offset(&trials, &reference).unwrap();
        assert!(g.dof.is_some_and(|d| (4.0..4.5).contains(&d)), "{g:?}");
        assert!((g.offset + 0.0048).abs() < 0.0015, "{g:?}");
        assert!(g.se > 0.002 && g.se < 0.004, "{g:?}");
        let within = normal_sf((g.offset / 0.00055).abs()) * 2.0;
        assert!(within < 1e-8 && g.p() > 0.01, "{within} {g:?}");
        // a real offset of 0.05 °/s on every trial stands far above that spread
        let shifted = gyro_set(&[0.0507, 0.0450, 0.0477], 2_000, 1);
        let g = gyro_offset(&shifted, &reference).unwrap();
        assert!((g.offset - 0.0452).abs() < 0.0015 && g.p() < 1e-4, "{g:?}");
        // one offset for every record: the spread is the noise's, and the block sums set
        // the error (the wander's part, if any, small, on many degrees of freedom)
        let alike = gyro_set(&[0.02; 3], 2_000, 3);
        let g = gyro_offset(&alike, &gyro_set(&[0.0; 3], 2_000, 4)).unwrap();
        assert!((g.offset - 0.02).abs() < 0.002 && g.p() < 1e-12, "{g:?}");
        assert!(
            g.se < 0.0008 && !matches!(g.dof, Some(d) if d <= 30.0),
            "{g:?}"
        );
        // one record a set: no spread to measure; the block sums, a normal
        let g = gyro_offset(&trials[..1], &reference[..1]).unwrap();
        assert_eq!(g.dof, None);
        // without a reference: the trials' own offset, their wander on 2 df
        let g = gyro_offset(&trials, &[]).unwrap();
        assert!(g.dof.is_some_and(|d| (2.0..2.5).contains(&d)), "{g:?}");
    }
}
