//! Choosing between PEM minima: a Diebold–Mariano test says whether one-step costs differ
//! significantly; a minimum that predicts one step as well as the lowest-cost one and
//! significantly better several steps ahead is taken instead.
//!
//! When the model structure cannot hold the system (an actuator delay, a nonlinearity), the
//! one-step cost has several minima. The starts find different ones, and their costs can
//! differ by a fraction of their sampling spread while their multi-step predictions differ
//! by several fit points. The lowest cost alone would then pick at random between a good and
//! a poor multi-step predictor; the test separates "lower" from "lower by chance".

use serde::{Deserialize, Serialize};

use super::Start;

/// One-sided 5 % quantile of the standard normal: a minimum whose one-step cost exceeds the
/// lowest by less than this many standard errors predicts one step as well.
pub const Z_EQUAL: f64 = 1.644_853_626_951_472_2;

/// Why a minimum other than the lowest-cost one was taken.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartChoice {
    /// The start whose minimum has the lowest one-step cost.
    pub lowest: Start,
    /// Cost of the chosen minimum / cost of the lowest (≥ 1).
    pub cost_ratio: f64,
    /// Diebold–Mariano statistic of the chosen minimum's squared one-step errors against the
    /// lowest's (below [`Z_EQUAL`]: not significantly worse).
    pub z: f64,
    /// Horizons (samples) of the multi-step comparison.
    pub horizons: Vec<usize>,
    /// Mean over `horizons` of the chosen minimum's k-step mean square error relative to the
    /// lowest's (< 1).
    pub multi_step_ratio: f64,
    /// Diebold–Mariano statistic of the chosen minimum's k-step squared errors (each horizon
    /// scaled by the lowest's mean square) against the lowest's: below −[`Z_EQUAL`],
    /// significantly smaller.
    pub multi_step_z: f64,
}

impl StartChoice {
    /// One line for the user.
    ///
    /// ```
    /// use yawcast::identify::pem::{choose::StartChoice, Start};
    /// let c = StartChoice {
    ///     lowest: Start::Arx,
    ///     cost_ratio: 1.013,
    ///     z: 0.53,
    ///     horizons: vec![5, 10, 20],
    ///     multi_step_ratio: 0.72,
    ///     multi_step_z: -4.1,
    /// };
    /// assert!(c.describe(Start::Subspace).contains("1.30 % above"));
    /// ```
    pub fn describe(&self, chosen: Start) -> String {
        let hs: Vec<String> = self.horizons.iter().map(usize::to_string).collect();
        format!(
            "{} minimum taken: its one-step cost is {:.2} % above the {} minimum's, not a \
             significant difference (Diebold–Mariano z = {:.2} < {:.2}), and its {}-step \
             errors are {:.0} % lower, a significant difference (z = {:.2})",
            start_name(chosen),
            100.0 * (self.cost_ratio - 1.0),
            start_name(self.lowest),
            self.z,
            Z_EQUAL,
            hs.join("/"),
            100.0 * (1.0 - self.multi_step_ratio),
            self.multi_step_z
        )
    }
}

/// Lower-case name of a start, as in the JSON.
pub(crate) fn start_name(s: Start) -> &'static str {
    match s {
        Start::Arx => "ARX",
        Start::Armax => "ARMAX",
        Start::Template => "template",
        Start::Subspace => "subspace",
    }
}

/// Diebold–Mariano statistic for "prediction errors `a` are larger than `b`": the mean of
/// d(t) = a(t)² − b(t)² plus `extra` (a per-sample cost difference outside the errors, such
/// as the regularisation penalty), over its standard error. Samples where either error is
/// not finite are skipped; see [`dm_z_of`] for the variance.
pub(crate) fn dm_z(a: &[Vec<f64>], b: &[Vec<f64>], extra: f64) -> f64 {
    // z does not depend on the scale of d: the scaled differences serve, `extra` scaled alike
    dm_z_of(&scaled_differences(&[a], &[b]), extra / mse(b), 0)
}

/// Diebold–Mariano statistic of the loss differences `ds` (one series per record): their
/// pooled mean plus `extra`, over its standard error. The long-run variance is Newey–West's
/// per record (Bartlett weights, bandwidth ⌊4 (N/100)^{2/9}⌋, at least `min_bw` — k-step
/// errors overlap over k − 1 samples); records are independent. Identical losses give 0; a
/// non-zero mean with zero spread gives ±∞.
pub(crate) fn dm_z_of(ds: &[Vec<f64>], extra: f64, min_bw: usize) -> f64 {
    let n: usize = ds.iter().map(Vec::len).sum();
    if n == 0 {
        return 0.0;
    }
    let nf = n as f64;
    let raw_mean = ds.iter().flatten().sum::<f64>() / nf;
    let mean = raw_mean + extra;
    // Var(mean) = Σ_r N_r·lrv_r / N²
    let mut var = 0.0;
    for d in ds {
        let m = d.len();
        if m == 0 {
            continue;
        }
        let mf = m as f64;
        let bw = ((4.0 * (mf / 100.0).powf(2.0 / 9.0)).floor() as usize).max(min_bw);
        let gamma = |j: usize| {
            d[j..]
                .iter()
                .zip(d)
                .map(|(x, y)| (x - raw_mean) * (y - raw_mean))
                .sum::<f64>()
                / mf
        };
        let mut lrv = gamma(0);
        for j in 1..=bw.min(m - 1) {
            lrv += 2.0 * (1.0 - j as f64 / (bw as f64 + 1.0)) * gamma(j);
        }
        var += mf * lrv.max(0.0);
    }
    let se = (var / (nf * nf)).sqrt();
    if se > 0.0 && se.is_finite() {
        mean / se
    } else if mean == 0.0 {
        0.0
    } else {
        mean.signum() * f64::INFINITY
    }
}

/// Loss differences of several horizons at once, per record: d(t) = Σ_h (a_h(t)² −
/// b_h(t)²)/s_h with s_h the pooled mean square of `b_h` (each horizon counts alike), over
/// the samples where every error is finite. `a[h][r]` is horizon h's error series on record r.
pub(crate) fn scaled_differences<E: AsRef<[Vec<f64>]>>(a: &[E], b: &[E]) -> Vec<Vec<f64>> {
    let a: Vec<&[Vec<f64>]> = a.iter().map(AsRef::as_ref).collect();
    let b: Vec<&[Vec<f64>]> = b.iter().map(AsRef::as_ref).collect();
    let scale: Vec<f64> = b.iter().map(|e| mse(e)).collect();
    let recs = b.first().map_or(0, |h| h.len());
    (0..recs)
        .map(|r| {
            let len = b[0][r].len();
            (0..len)
                .filter_map(|t| {
                    let mut d = 0.0;
                    for ((ah, bh), s) in a.iter().zip(&b).zip(&scale) {
                        let (x, y) = (ah[r][t], bh[r][t]);
                        if !(x.is_finite() && y.is_finite()) {
                            return None;
                        }
                        d += (x * x - y * y) / s;
                    }
                    Some(d)
                })
                .collect()
        })
        .collect()
}

/// Pooled mean square of the finite errors over all records.
pub(crate) fn mse(errs: &[Vec<f64>]) -> f64 {
    let (s, n) = errs
        .iter()
        .flatten()
        .filter(|e| e.is_finite())
        .fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::pem::testdata::normal;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// With independent errors the statistic is the t-ratio of the mean difference: for
    /// errors of std 1.1 against std 1.0 over 4 000 samples, d has mean 0.21 and std
    /// ≈ √(2·1.1⁴ + 2) ≈ 2.09, so z ≈ 0.21/(2.09/√4000) ≈ 6.4.
    #[test]
    fn dm_z_matches_the_t_ratio_for_independent_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let a: Vec<f64> = (0..4000).map(|_| 1.1 * normal(&mut rng)).collect();
        let b: Vec<f64> = (0..4000).map(|_| normal(&mut rng)).collect();
        let (a, b) = (vec![a], vec![b]);
        let z = dm_z(&a, &b, 0.0);
        let d: Vec<f64> = a[0].iter().zip(&b[0]).map(|(x, y)| x * x - y * y).collect();
        let m = d.iter().sum::<f64>() / 4000.0;
        let s = (d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / 4000.0).sqrt();
        let t = m / (s / 4000f64.sqrt());
        println!("z {z:.3}, t {t:.3}");
        assert!((z - 6.4).abs() < 1.5, "{z}");
        // white d: the Newey–West correction changes little
        assert!((z / t - 1.0).abs() < 0.1, "{z} vs {t}");
        // symmetric, and equal errors are no difference
        assert!((dm_z(&b, &a, 0.0) + z).abs() < 1e-12);
        assert_eq!(dm_z(&a, &a, 0.0), 0.0);
    }

    /// Positively autocorrelated differences carry less information than their count: the
    /// HAC standard error is larger than the naive one, so z is smaller than the t-ratio.
    #[test]
    fn dm_z_discounts_autocorrelated_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        // AR(1) errors with the same innovations, different gain: d is strongly correlated
        let mut xa = 0.0;
        let mut a = Vec::new();
        let mut b = Vec::new();
        for _ in 0..3000 {
            let w = normal(&mut rng);
            xa = 0.9 * xa + w;
            a.push(1.05 * xa + 0.05 * normal(&mut rng));
            b.push(xa + 0.05 * normal(&mut rng));
        }
        let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x * x - y * y).collect();
        let z = dm_z(&[a], &[b], 0.0);
        let n = d.len() as f64;
        let m = d.iter().sum::<f64>() / n;
        let s = (d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt();
        let t = m / (s / n.sqrt());
        println!("z {z:.3}, naive t {t:.3}");
        assert!(z > 0.0 && z < 0.7 * t, "{z} vs {t}");
    }

    /// Two records pool their samples; non-finite errors (missing measurements) are skipped;
    /// an extra per-sample cost shifts the mean.
    #[test]
    fn dm_z_pools_records_and_skips_missing_samples() {
        let a = vec![vec![1.0, 2.0, f64::NAN, 1.0], vec![1.5, 1.0]];
        let b = vec![vec![1.0, 1.0, 0.0, 1.0], vec![1.0, f64::NAN]];
        // d = [0, 3, 0] and [1.25]: mean 1.0625
        let z = dm_z(&a, &b, 0.0);
        assert!(z > 0.0 && z.is_finite(), "{z}");
        let same = vec![vec![0.5, 0.5]];
        assert_eq!(dm_z(&same, &same, 0.0), 0.0);
        assert_eq!(dm_z(&same, &same, 0.1), f64::INFINITY);
        assert!((mse(&a) - (1.0 + 4.0 + 1.0 + 2.25 + 1.0) / 5.0).abs() < 1e-15);
    }
}
