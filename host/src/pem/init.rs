//! Starting models for the prediction-error search: ARX least squares and an ARMAX fit by
//! pseudo-linear regression (extended least squares), both converted to the canonical form.

use nalgebra::{DMatrix, DVector};

use super::poly;
use crate::data::Record;
use crate::model::Model;
use crate::predict::Stepper;

/// The actuator output ũ of `template` over a record (θ plays no part in it).
pub(crate) fn actuator_output(template: &Model, rec: &Record) -> Vec<f64> {
    let s = Stepper::new(template);
    let mut st = s.initial(&[], 0.0);
    rec.u.iter().map(|u| s.actuator(&mut st, *u)).collect()
}

/// Solves the symmetric positive (semi-)definite system `h x = b` with Jacobi scaling, falling
/// back to a tiny ridge and then to an SVD pseudo-inverse. `None` when nothing works.
pub(crate) fn spd_solve(h: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let n = h.nrows();
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let v = h[(i, i)];
            if v > 0.0 && v.is_finite() {
                1.0 / v.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let mut s = h.clone();
    for i in 0..n {
        for j in 0..n {
            s[(i, j)] *= d[i] * d[j];
        }
    }
    let sb = DVector::from_iterator(n, (0..n).map(|i| b[i] * d[i]));
    let solve = |m: &DMatrix<f64>| m.clone().cholesky().map(|c| c.solve(&sb));
    let x = solve(&s).or_else(|| {
        let mut r = s.clone();
        for i in 0..n {
            r[(i, i)] += 1e-10;
        }
        solve(&r)
    });
    let x = match x {
        Some(x) => x,
        None => s.clone().svd(true, true).solve(&sb, 1e-12).ok()?,
    };
    let out = DVector::from_iterator(n, (0..n).map(|i| x[i] * d[i]));
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// Least squares on accumulated normal equations.
struct Normal {
    ata: DMatrix<f64>,
    atb: DVector<f64>,
    rows: usize,
}

impl Normal {
    fn new(m: usize) -> Normal {
        Normal {
            ata: DMatrix::zeros(m, m),
            atb: DVector::zeros(m),
            rows: 0,
        }
    }
    fn add(&mut self, phi: &[f64], y: f64) {
        let m = phi.len();
        for i in 0..m {
            self.atb[i] += phi[i] * y;
            for j in i..m {
                self.ata[(i, j)] += phi[i] * phi[j];
            }
        }
        self.rows += 1;
    }
    fn solve(mut self) -> Option<Vec<f64>> {
        let m = self.ata.nrows();
        if self.rows < m {
            return None;
        }
        for i in 0..m {
            for j in 0..i {
                self.ata[(i, j)] = self.ata[(j, i)];
            }
        }
        spd_solve(&self.ata, &self.atb).map(|v| v.iter().copied().collect())
    }
}

/// ARX(n, n): `y(t) = Σ α_i y(t−i) + Σ β_i ũ(t−i) + e(t)` over all records. Returns (α, β).
pub(crate) fn arx(recs: &[Record], uts: &[Vec<f64>], n: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let mut ne = Normal::new(2 * n);
    let mut phi = vec![0.0; 2 * n];
    for (rec, ut) in recs.iter().zip(uts) {
        for t in n..rec.len() {
            if !rec.y[t - n..=t].iter().all(|v| v.is_finite()) {
                continue;
            }
            for i in 1..=n {
                phi[i - 1] = rec.y[t - i];
                phi[n + i - 1] = ut[t - i];
            }
            ne.add(&phi, rec.y[t]);
        }
    }
    let th = ne.solve()?;
    Some((th[..n].to_vec(), th[n..].to_vec()))
}

/// ARMAX(n, n, n) by extended least squares, started from ARX. Returns (α, β, c).
pub(crate) fn armax(
    recs: &[Record],
    uts: &[Vec<f64>],
    n: usize,
    iterations: usize,
) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let (mut alpha, mut beta) = arx(recs, uts, n)?;
    let mut c = vec![0.0; n];
    for _ in 0..iterations {
        // residuals of the current ARMAX predictor, then the pseudo-linear regression
        let mut ne = Normal::new(3 * n);
        let mut phi = vec![0.0; 3 * n];
        for (rec, ut) in recs.iter().zip(uts) {
            let len = rec.len();
            let mut eps = vec![0.0; len];
            for t in n..len {
                if !rec.y[t - n..=t].iter().all(|v| v.is_finite()) {
                    continue;
                }
                let mut pred = 0.0;
                for i in 1..=n {
                    phi[i - 1] = rec.y[t - i];
                    phi[n + i - 1] = ut[t - i];
                    phi[2 * n + i - 1] = eps[t - i];
                    pred += alpha[i - 1] * rec.y[t - i]
                        + beta[i - 1] * ut[t - i]
                        + c[i - 1] * eps[t - i];
                }
                eps[t] = rec.y[t] - pred;
                if !eps[t].is_finite() {
                    return Some((alpha, beta, vec![0.0; n]));
                }
                ne.add(&phi, rec.y[t]);
            }
        }
        let th = ne.solve()?;
        alpha = th[..n].to_vec();
        beta = th[n..2 * n].to_vec();
        // keep C(q) minimum phase so the residual recursion stays bounded
        let mut cp = vec![1.0];
        cp.extend_from_slice(&th[2 * n..]);
        let cs = poly::stabilise(&cp, 0.98);
        c = cs[1..].to_vec();
    }
    Some((alpha, beta, c))
}

/// A stable canonical model (structure and gains of `template`) from (α, β, c).
pub(crate) fn canonical_start(template: &Model, alpha: &[f64], beta: &[f64], c: &[f64]) -> Model {
    let n = alpha.len();
    // A(q) stable: reflect roots of zⁿ − α₁zⁿ⁻¹ − … − αₙ.
    let mut ap = vec![1.0];
    ap.extend(alpha.iter().map(|v| -v));
    let ap = poly::stabilise(&ap, 0.995);
    let alpha: Vec<f64> = ap[1..].iter().map(|v| -v).collect();
    let mut cp = vec![1.0];
    cp.extend_from_slice(c);
    cp.resize(n + 1, 0.0);
    let cp = poly::stabilise(&cp, 0.98);
    let (a, b, k) = poly::tf_to_canonical(&alpha, beta, &cp[1..]);
    let mut m = template.clone();
    m.n = n;
    m.a = a;
    m.b = b;
    m.k = k;
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arx_recovers_an_arx_system() {
        // y(t) = 0.5 y(t−1) − 0.1 y(t−2) + 0.2 u(t−1) + 0.05 u(t−2), no noise
        let n = 400;
        let u: Vec<f64> = (0..n)
            .map(|i| if (i * 7919 / 13) % 3 == 0 { 1.0 } else { -1.0 })
            .collect();
        let mut y = vec![0.0; n];
        for t in 2..n {
            y[t] = 0.5 * y[t - 1] - 0.1 * y[t - 2] + 0.2 * u[t - 1] + 0.05 * u[t - 2];
        }
        let r = Record::from_uy("x", 1.0, u.clone(), y);
        let (al, be) = arx(&[r], &[u], 2).unwrap();
        assert!(
            (al[0] - 0.5).abs() < 1e-9 && (al[1] + 0.1).abs() < 1e-9,
            "{al:?}"
        );
        assert!(
            (be[0] - 0.2).abs() < 1e-9 && (be[1] - 0.05).abs() < 1e-9,
            "{be:?}"
        );
    }
}
