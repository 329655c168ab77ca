//! The statistics every step shares, written once: ln Γ, the regularised incomplete gamma and
//! beta functions, the χ², normal and Student t tails and quantile, and the seeded normal draw.
//!
//! Residual tests (Ljung–Box), the merge's χ² consistency test, diagnosis p-values and
//! augment's paired t test all come from here, so one correction reaches all of them.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// ln Γ(x) for x > 0 (Lanczos approximation, g = 7, 9 terms; relative error < 1e-14).
///
/// ```
/// use yawcast::stats::ln_gamma;
/// assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
/// assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
/// ```
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // reflection: Γ(x)Γ(1−x) = π / sin(πx)
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).abs().ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised lower incomplete gamma function P(a, x) = γ(a, x)/Γ(a), a > 0, x ≥ 0
/// (series for x < a + 1, Lentz continued fraction otherwise). NaN for invalid arguments.
///
/// ```
/// use yawcast::stats::gamma_p;
/// // P(1, x) = 1 − e^{−x}
/// assert!((gamma_p(1.0, 2.0) - (1.0 - (-2.0f64).exp())).abs() < 1e-14);
/// assert_eq!(gamma_p(3.0, 0.0), 0.0);
/// ```
pub fn gamma_p(a: f64, x: f64) -> f64 {
    if a.is_nan() || a <= 0.0 || x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return 0.0;
    }
    if x.is_infinite() {
        return 1.0;
    }
    let lead = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let mut ap = a;
        let mut del = 1.0 / a;
        let mut sum = del;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum.ln() + lead).exp().min(1.0)
    } else {
        1.0 - gamma_q_cf(a, x, lead)
    }
}

/// Q(a, x) = 1 − P(a, x) by the continued fraction (x ≥ a + 1).
fn gamma_q_cf(a: f64, x: f64, lead: f64) -> f64 {
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..10_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = guard(an * d + b);
        c = guard(b + an / c);
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (lead.exp() * h).clamp(0.0, 1.0)
}

/// Smallest magnitude the Lentz continued fractions let a denominator take.
const TINY: f64 = 1e-300;

fn guard(v: f64) -> f64 {
    if v.abs() < TINY {
        TINY
    } else {
        v
    }
}

/// χ² survival function P(X > x) with `df` degrees of freedom.
///
/// ```
/// use yawcast::stats::chi2_sf;
/// // 95 % quantile of χ²(1) is 3.841459
/// assert!((chi2_sf(3.841_459, 1.0) - 0.05).abs() < 1e-6);
/// // χ²(2) is exponential with mean 2
/// assert!((chi2_sf(4.0, 2.0) - (-2.0f64).exp()).abs() < 1e-13);
/// ```
pub fn chi2_sf(x: f64, df: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let a = 0.5 * df;
    let h = 0.5 * x;
    if h >= a + 1.0 {
        let lead = a * h.ln() - h - ln_gamma(a);
        gamma_q_cf(a, h, lead)
    } else {
        1.0 - gamma_p(a, h)
    }
}

/// Normal upper-tail probability P(Z > z) (erfc via the χ²(1) relation).
///
/// ```
/// use yawcast::stats::normal_sf;
/// assert!((normal_sf(1.959_964) - 0.025).abs() < 1e-6);
/// assert!((normal_sf(0.0) - 0.5).abs() < 1e-12);
/// ```
pub fn normal_sf(z: f64) -> f64 {
    if z.is_nan() {
        return f64::NAN;
    }
    let two_sided = chi2_sf(z * z, 1.0);
    if z >= 0.0 {
        0.5 * two_sided
    } else {
        1.0 - 0.5 * two_sided
    }
}

/// Regularised incomplete beta function I_x(a, b), a, b > 0, 0 ≤ x ≤ 1 (Lentz continued
/// fraction on the side where it converges fast). NaN for invalid arguments.
///
/// ```
/// use yawcast::stats::beta_reg;
/// // I_x(1, 1) = x; I_x(a, b) = 1 − I_{1−x}(b, a)
/// assert!((beta_reg(0.3, 1.0, 1.0) - 0.3).abs() < 1e-14);
/// assert!((beta_reg(0.2, 2.5, 4.0) + beta_reg(0.8, 4.0, 2.5) - 1.0).abs() < 1e-13);
/// ```
pub fn beta_reg(x: f64, a: f64, b: f64) -> f64 {
    if !(a > 0.0 && b > 0.0 && (0.0..=1.0).contains(&x)) {
        return f64::NAN;
    }
    if x == 0.0 || x == 1.0 {
        return x;
    }
    let lead = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    if x < (a + 1.0) / (a + b + 2.0) {
        (lead.exp() * beta_cf(x, a, b) / a).clamp(0.0, 1.0)
    } else {
        (1.0 - lead.exp() * beta_cf(1.0 - x, b, a) / b).clamp(0.0, 1.0)
    }
}

/// The continued fraction of the incomplete beta function (modified Lentz).
fn beta_cf(x: f64, a: f64, b: f64) -> f64 {
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..10_000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 / guard(1.0 + aa * d);
        c = guard(1.0 + aa / c);
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 / guard(1.0 + aa * d);
        c = guard(1.0 + aa / c);
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// F-distribution upper-tail probability P(F > f) with `d1` and `d2` degrees of freedom
/// (`d1, d2 > 0`): `I_{d2/(d2 + d1·f)}(d2/2, d1/2)`; `d2 = ∞` gives the χ² limit
/// `P(χ²_{d1} > d1·f)`.
///
/// ```
/// use yawcast::stats::{chi2_sf, f_sf};
/// // F(2, 2): P(F > f) = 1/(1 + f)
/// assert!((f_sf(3.0, 2.0, 2.0) - 0.25).abs() < 1e-13);
/// assert_eq!(f_sf(2.5, 4.0, f64::INFINITY), chi2_sf(10.0, 4.0));
/// assert_eq!(f_sf(0.0, 2.0, 6.0), 1.0);
/// ```
pub fn f_sf(f: f64, d1: f64, d2: f64) -> f64 {
    if f.is_nan() || !(d1 > 0.0 && d2 > 0.0) {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 1.0;
    }
    if d2.is_infinite() {
        return chi2_sf(d1 * f, d1);
    }
    if f.is_infinite() {
        return 0.0;
    }
    beta_reg(d2 / (d2 + d1 * f), 0.5 * d2, 0.5 * d1)
}

/// The F quantile with upper-tail probability `p` (0 < p < 1): the `f` with
/// `P(F > f) = p` for `d1` and `d2` degrees of freedom, by doubling then bisection on
/// [`f_sf`] (100 halvings).
///
/// ```
/// use yawcast::stats::f_quantile;
/// // F(2, 2): P(F > f) = 1/(1 + f), so the 1 % point is 99
/// assert!((f_quantile(0.01, 2.0, 2.0) - 99.0).abs() < 1e-9);
/// ```
pub fn f_quantile(p: f64, d1: f64, d2: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    while f_sf(hi, d1, d2) > p && hi < 1e12 {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f_sf(mid, d1, d2) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Student t upper-tail probability P(T > t) with `dof` degrees of freedom (`dof > 0`).
///
/// ```
/// use yawcast::stats::student_t_sf;
/// // t(1) is Cauchy: P(T > 1) = 1/4
/// assert!((student_t_sf(1.0, 1.0) - 0.25).abs() < 1e-13);
/// assert!((student_t_sf(-1.0, 1.0) - 0.75).abs() < 1e-13);
/// ```
pub fn student_t_sf(t: f64, dof: f64) -> f64 {
    if t.is_nan() || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if t.is_infinite() {
        return if t > 0.0 { 0.0 } else { 1.0 };
    }
    let half = 0.5 * beta_reg(dof / (dof + t * t), 0.5 * dof, 0.5);
    if t >= 0.0 {
        half
    } else {
        1.0 - half
    }
}

/// The Student t quantile with upper-tail probability `p` (0 < p ≤ 1/2): the `t` with
/// `P(T > t) = p`, to 1e-12 relative, by bisection on [`student_t_sf`]. `dof = 0` gives +∞
/// (no degree of freedom, no bound); NaN for `p` outside (0, 1/2].
///
/// ```
/// use yawcast::stats::student_t_quantile;
/// // the one-sided 95 % quantiles of the tables: 6.314 (1), 2.015 (5), 1.697 (30)
/// assert!((student_t_quantile(0.05, 1.0) - 6.313_751_5).abs() < 1e-6);
/// assert!((student_t_quantile(0.05, 5.0) - 2.015_048_4).abs() < 1e-6);
/// assert!((student_t_quantile(0.05, 30.0) - 1.697_260_9).abs() < 1e-6);
/// assert_eq!(student_t_quantile(0.05, 0.0), f64::INFINITY);
/// ```
pub fn student_t_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p <= 0.5) || dof.is_nan() || dof < 0.0 {
        return f64::NAN;
    }
    if dof == 0.0 {
        return f64::INFINITY;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while student_t_sf(hi, dof) > p {
        hi *= 2.0;
        if hi > 1e300 {
            return f64::INFINITY;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_t_sf(mid, dof) > p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// One standard normal draw by Box–Muller (the cosine branch), from two uniforms of `rng`.
///
/// ```
/// use rand_chacha::{rand_core::SeedableRng, ChaCha8Rng};
/// let mut rng = ChaCha8Rng::seed_from_u64(7);
/// let x: Vec<f64> = (0..20_000).map(|_| yawcast::stats::standard_normal(&mut rng)).collect();
/// let mean = x.iter().sum::<f64>() / x.len() as f64;
/// let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
/// assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.03);
/// ```
pub fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    // 1 − U lies in (0, 1]: the logarithm is finite
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_matches_tables() {
        // upper 5 % and 1 % points of χ² for 1, 2, 10 and 25 degrees of freedom
        for (x, df, p) in [
            (3.841_459, 1.0, 0.05),
            (6.634_897, 1.0, 0.01),
            (5.991_465, 2.0, 0.05),
            (18.307_04, 10.0, 0.05),
            (44.314_10, 25.0, 0.01),
        ] {
            assert!((chi2_sf(x, df) - p).abs() < 2e-7, "{x} {df}");
        }
        // exact quantiles to the last digits, and the edges
        assert!((chi2_sf(2.0, 2.0) - (-1.0f64).exp()).abs() < 1e-12);
        assert!((chi2_sf(18.307038053275146, 10.0) - 0.05).abs() < 1e-9);
        assert!((chi2_sf(124.34211340400407, 100.0) - 0.05).abs() < 1e-8);
        assert!((chi2_sf(99.334_129, 100.0) - 0.5).abs() < 1e-6);
        assert_eq!(chi2_sf(0.0, 3.0), 1.0);
        assert_eq!(chi2_sf(-1.0, 3.0), 1.0);
        assert!(chi2_sf(1e4, 3.0) < 1e-300);
    }

    #[test]
    fn student_t_reproduces_the_one_sided_95_table() {
        // the printed table (three decimals) for 1..=30 degrees of freedom
        const T: [f64; 30] = [
            6.314, 2.920, 2.353, 2.132, 2.015, 1.943, 1.895, 1.860, 1.833, 1.812, 1.796, 1.782,
            1.771, 1.761, 1.753, 1.746, 1.740, 1.734, 1.729, 1.725, 1.721, 1.717, 1.714, 1.711,
            1.708, 1.706, 1.703, 1.701, 1.699, 1.697,
        ];
        for (i, t) in T.iter().enumerate() {
            let q = student_t_quantile(0.05, (i + 1) as f64);
            assert!((q - t).abs() <= 0.000_5 + 1e-9, "dof {}: {q} vs {t}", i + 1);
        }
        // large dof tends to the normal quantile 1.644854
        assert!((student_t_quantile(0.05, 1e6) - 1.644_854).abs() < 1e-4);
    }

    #[test]
    fn student_t_tail_agrees_with_closed_form_for_two_dof() {
        // t(2): P(T > t) = 1/2 − t / (2 √(2 + t²))
        for t in [0.0, 0.3, 1.0, 2.5, 10.0] {
            let exact = 0.5 - t / (2.0 * (2.0f64 + t * t).sqrt());
            assert!((student_t_sf(t, 2.0) - exact).abs() < 1e-13, "{t}");
        }
    }

    #[test]
    fn bad_arguments_give_nan_not_a_number_that_looks_right() {
        assert!(gamma_p(-1.0, 1.0).is_nan());
        assert!(beta_reg(1.5, 1.0, 1.0).is_nan());
        assert!(student_t_sf(1.0, 0.0).is_nan());
        assert!(student_t_quantile(0.7, 3.0).is_nan());
    }
}
