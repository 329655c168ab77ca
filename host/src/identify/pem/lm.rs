//! The Levenberg–Marquardt search: the prepared problem, its penalty, steps and information matrix.

use nalgebra::{DMatrix, DVector};

use super::sens::{self, Accum, Layout};
use super::{poly, spd_solve};
use super::{with_params, IdentError, PemConfig, Termination};
use crate::identify::model::Model;
use crate::io::data::Record;

/// The regularisation of a problem.
#[derive(Debug, Clone)]
pub(super) struct Penalty {
    pub(super) lambda: f64,
    pub(super) r: Vec<f64>,
    pub(super) nominal: Vec<f64>,
}

impl Penalty {
    pub(super) fn new(cfg: &PemConfig, p: usize) -> Result<Penalty, IdentError> {
        if !(cfg.lambda >= 0.0 && cfg.lambda.is_finite()) {
            return Err(IdentError::Config(format!(
                "λ = {} must be finite and ≥ 0",
                cfg.lambda
            )));
        }
        let r = cfg.r.clone().unwrap_or_else(|| vec![1.0; p]);
        if r.len() != p {
            return Err(IdentError::Config(format!(
                "R has {} weights, the model has {p} parameters",
                r.len()
            )));
        }
        if let Some(i) = r.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
            return Err(IdentError::Config(format!(
                "R weight {} = {} must be finite and ≥ 0",
                i + 1,
                r[i]
            )));
        }
        let nominal = cfg.nominal.clone().unwrap_or_else(|| vec![0.0; p]);
        if nominal.len() != p || nominal.iter().any(|v| !v.is_finite()) {
            return Err(IdentError::Config(format!(
                "the nominal vector must have {p} finite values"
            )));
        }
        Ok(Penalty {
            lambda: cfg.lambda,
            r,
            nominal,
        })
    }

    pub(super) fn value(&self, params: &[f64]) -> f64 {
        if self.lambda == 0.0 {
            return 0.0;
        }
        let s: f64 = (0..self.r.len())
            .map(|i| {
                let d = params[i] - self.nominal[i];
                self.r[i] * d * d
            })
            .sum();
        self.lambda * s
    }
}

/// A prepared problem: records, structure, penalty.
pub(super) struct Problem<'a> {
    pub(super) recs: &'a [Record],
    pub(super) template: Model,
    pub(super) lay: Layout,
    pub(super) pen: Penalty,
    pub(super) parallel: bool,
}

/// A point of the search: parameters, initial states, Σε², sample count.
#[derive(Debug, Clone)]
pub(super) struct Point {
    pub(super) params: Vec<f64>,
    pub(super) x0: Vec<Vec<f64>>,
    pub(super) sse: f64,
    pub(super) count: usize,
}

/// The outcome of one LM search.
pub(super) struct Search {
    pub(super) pt: Point,
    pub(super) accs: Vec<Accum>,
    pub(super) iterations: usize,
    pub(super) termination: Termination,
}

impl Problem<'_> {
    pub(super) fn model(&self, params: &[f64]) -> Model {
        with_params(&self.template, params)
    }

    pub(super) fn stable(&self, params: &[f64]) -> bool {
        let n = self.lay.n;
        poly::canonical_stable(&params[..n], &params[2 * n..3 * n])
    }

    pub(super) fn total(&self, pt: &Point) -> f64 {
        pt.sse + self.pen.value(&pt.params)
    }

    /// Whether records are evaluated in parallel (allowed, and more than one).
    fn parallel_records(&self) -> bool {
        self.parallel && self.recs.len() > 1
    }

    /// Σε² and count at (params, x0).
    pub(super) fn sse(&self, params: &[f64], x0: &[Vec<f64>]) -> (f64, usize) {
        let m = self.model(params);
        let parts = crate::par::map_range(self.recs.len(), self.parallel_records(), |i| {
            sens::sse(&m, &self.recs[i], &x0[i])
        });
        let sse = parts.iter().map(|s| s.sse).sum::<f64>();
        let count = parts.iter().map(|s| s.count).sum();
        (if sse.is_finite() { sse } else { f64::INFINITY }, count)
    }

    /// Normal equations per record at (params, x0).
    fn jac(&self, params: &[f64], x0: &[Vec<f64>]) -> Vec<Accum> {
        let m = self.model(params);
        let q = self.lay.q();
        crate::par::map_range(self.recs.len(), self.parallel_records(), |i| {
            let mut acc = Accum::new(q);
            sens::pass(&m, &self.lay, &self.recs[i], &x0[i], &mut acc);
            acc.finish();
            acc
        })
    }

    /// A point at `params` with x̂(0) solved by least squares (two Gauss–Newton passes on
    /// the initial states alone; exact after one when the predictor is affine in x̂(0)).
    fn point(&self, params: Vec<f64>) -> (Point, Vec<Accum>) {
        let n = self.lay.n;
        let p = self.lay.p;
        let mut x0 = vec![vec![0.0; n]; self.recs.len()];
        let mut accs = self.jac(&params, &x0);
        for _ in 0..2 {
            for (x, acc) in x0.iter_mut().zip(&accs) {
                let (hxx, gx) = x_block(acc, p, n);
                if let Some(d) = spd_solve(&hxx, &gx) {
                    for i in 0..n {
                        x[i] += d[i];
                    }
                }
            }
            accs = self.jac(&params, &x0);
            if !self.lay.heading
                && self
                    .lay
                    .gains
                    .iter()
                    .all(|g| *g != crate::effects::Regressor::Damping)
            {
                break;
            }
        }
        let sse = accs.iter().map(|a| a.sse).sum::<f64>();
        let count = accs.iter().map(|a| a.count).sum();
        (
            Point {
                params,
                x0,
                sse: if sse.is_finite() { sse } else { f64::INFINITY },
                count,
            },
            accs,
        )
    }

    /// Levenberg–Marquardt from `params` (assumed stable).
    pub(super) fn search(&self, params: Vec<f64>, max_iter: usize, tol: f64) -> Search {
        let (mut pt, mut accs) = self.point(params);
        let mut mu = 1e-3;
        let mut nu = 2.0;
        let mut termination = Termination::MaxIterations;
        let mut iterations = 0;
        while iterations < max_iter {
            iterations += 1;
            let f = self.total(&pt);
            let Some((dth, dx, pred)) = self.step(&pt, &accs, mu) else {
                mu *= nu;
                nu *= 2.0;
                if mu > 1e16 {
                    termination = Termination::Stalled;
                    break;
                }
                continue;
            };
            let trial_params: Vec<f64> = pt.params.iter().zip(&dth).map(|(a, d)| a + d).collect();
            let trial_x0: Vec<Vec<f64>> = pt
                .x0
                .iter()
                .zip(&dx)
                .map(|(x, d)| x.iter().zip(d).map(|(a, b)| a + b).collect())
                .collect();
            let (f_new, ok) = if self.stable(&trial_params) {
                let (sse, count) = self.sse(&trial_params, &trial_x0);
                (sse + self.pen.value(&trial_params), count)
            } else {
                (f64::INFINITY, 0)
            };
            if f_new.is_finite() && f_new < f {
                let rho = (f - f_new) / pred.max(f64::MIN_POSITIVE);
                let rel = (f - f_new) / f.max(f64::MIN_POSITIVE);
                let step_norm = dth
                    .iter()
                    .zip(&pt.params)
                    .map(|(d, v)| (d / (v.abs() + 1e-8)).abs())
                    .fold(0.0, f64::max);
                let sse = f_new - self.pen.value(&trial_params);
                pt = Point {
                    params: trial_params,
                    x0: trial_x0,
                    sse,
                    count: ok,
                };
                accs = self.jac(&pt.params, &pt.x0);
                pt.sse = accs.iter().map(|a| a.sse).sum();
                mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                if rel < tol && rho > 0.25 {
                    termination = Termination::Converged;
                    break;
                }
                if step_norm < 1e-10 {
                    termination = Termination::SmallStep;
                    break;
                }
            } else {
                mu *= nu;
                nu *= 2.0;
                if mu > 1e16 {
                    termination = Termination::Stalled;
                    break;
                }
            }
        }
        Search {
            pt,
            accs,
            iterations,
            termination,
        }
    }

    /// One damped Gauss–Newton step: (Δparams, Δx̂(0) per record, predicted reduction).
    #[allow(clippy::type_complexity)]
    pub(super) fn step(
        &self,
        pt: &Point,
        accs: &[Accum],
        mu: f64,
    ) -> Option<(Vec<f64>, Vec<Vec<f64>>, f64)> {
        let n = self.lay.n;
        let p = self.lay.p;
        let (mut hth, mut bth) = theta_block(accs, p);
        // penalty
        for i in 0..p {
            let w = self.pen.lambda * self.pen.r[i];
            hth[(i, i)] += w;
            bth[i] -= w * (pt.params[i] - self.pen.nominal[i]);
        }
        let dth_diag = damping(&hth);
        let b_full = bth.clone();
        let mut red = hth.clone();
        for i in 0..p {
            red[(i, i)] += mu * dth_diag[i];
        }
        let mut rb = bth.clone();
        let mut xs = Vec::with_capacity(accs.len());
        for acc in accs {
            let (hxx, gx) = x_block(acc, p, n);
            let dx_diag = damping(&hxx);
            let mut s = hxx.clone();
            for i in 0..n {
                s[(i, i)] += mu * dx_diag[i];
            }
            let hxt = xt_block(acc, p, n); // n × p
                                           // S⁻¹ [Hxθ | gx]
            let mut rhs = DMatrix::zeros(n, p + 1);
            rhs.view_mut((0, 0), (n, p)).copy_from(&hxt);
            rhs.set_column(p, &gx);
            let sol = solve_many(&s, &rhs)?;
            let w = sol.view((0, 0), (n, p));
            red -= hxt.transpose() * w;
            rb -= hxt.transpose() * sol.column(p);
            xs.push((gx, sol, dx_diag));
        }
        let dth = spd_solve(&red, &rb)?;
        let mut dxs = Vec::with_capacity(accs.len());
        let mut pred =
            dth.dot(&b_full) + mu * (0..p).map(|i| dth_diag[i] * dth[i] * dth[i]).sum::<f64>();
        for (gx, sol, dx_diag) in xs {
            // δx = S⁻¹ (gx − Hxθ δθ)
            let dx = sol.column(p) - sol.view((0, 0), (n, p)) * &dth;
            pred += dx.dot(&gx) + mu * (0..n).map(|i| dx_diag[i] * dx[i] * dx[i]).sum::<f64>();
            dxs.push(dx.iter().copied().collect());
        }
        if pred.is_nan() || pred <= 0.0 || dth.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some((dth.iter().copied().collect(), dxs, pred))
    }

    /// `M = Hθθ − Σ Hθx Hxx⁻¹ Hxθ` at the optimum.
    pub(super) fn information(&self, accs: &[Accum]) -> DMatrix<f64> {
        let n = self.lay.n;
        let p = self.lay.p;
        let (mut m, _) = theta_block(accs, p);
        for acc in accs {
            let (mut hxx, _) = x_block(acc, p, n);
            let tr = hxx.trace().max(f64::MIN_POSITIVE);
            for i in 0..n {
                hxx[(i, i)] += 1e-12 * tr;
            }
            let hxt = xt_block(acc, p, n);
            if let Some(w) = solve_many(&hxx, &hxt) {
                m -= hxt.transpose() * w;
            }
        }
        m
    }
}

/// Diagonal used for Marquardt damping, floored so that no direction is undamped.
fn damping(h: &DMatrix<f64>) -> Vec<f64> {
    let n = h.nrows();
    let max = (0..n).map(|i| h[(i, i)]).fold(0.0, f64::max);
    let floor = (1e-12 * max).max(1e-300);
    (0..n).map(|i| h[(i, i)].max(floor)).collect()
}

fn theta_block(accs: &[Accum], p: usize) -> (DMatrix<f64>, DVector<f64>) {
    let mut h = DMatrix::zeros(p, p);
    let mut g = DVector::zeros(p);
    for acc in accs {
        let q = acc.q;
        for i in 0..p {
            g[i] += acc.g[i];
            for j in 0..p {
                h[(i, j)] += acc.h[i * q + j];
            }
        }
    }
    (h, g)
}

fn x_block(acc: &Accum, p: usize, n: usize) -> (DMatrix<f64>, DVector<f64>) {
    let q = acc.q;
    let h = DMatrix::from_fn(n, n, |i, j| acc.h[(p + i) * q + p + j]);
    let g = DVector::from_fn(n, |i, _| acc.g[p + i]);
    (h, g)
}

fn xt_block(acc: &Accum, p: usize, n: usize) -> DMatrix<f64> {
    let q = acc.q;
    DMatrix::from_fn(n, p, |i, j| acc.h[(p + i) * q + j])
}

/// Solves `s X = rhs` for a small SPD `s` (Cholesky, then LU).
fn solve_many(s: &DMatrix<f64>, rhs: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    if let Some(c) = s.clone().cholesky() {
        return Some(c.solve(rhs));
    }
    s.clone().lu().solve(rhs)
}

/// Symmetric inverse with Jacobi scaling; near-singular directions get a tiny ridge (their
/// variance comes out huge rather than wrongly small).
pub(super) fn spd_inverse(h: &DMatrix<f64>) -> DMatrix<f64> {
    let n = h.nrows();
    let d = super::init::jacobi_scale(h);
    let s = DMatrix::from_fn(n, n, |i, j| h[(i, j)] * d[i] * d[j]);
    let inv = s
        .clone()
        .cholesky()
        .map(|c| c.inverse())
        .unwrap_or_else(|| {
            let mut r = s.clone();
            for i in 0..n {
                r[(i, i)] += 1e-12;
            }
            r.cholesky()
                .map(|c| c.inverse())
                .unwrap_or_else(|| DMatrix::from_element(n, n, f64::INFINITY))
        });
    DMatrix::from_fn(n, n, |i, j| inv[(i, j)] * d[i] * d[j])
}
