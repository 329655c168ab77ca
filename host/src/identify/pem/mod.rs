//! Prediction-error identification (PEM) of the canonical innovations model, with optional
//! regularisation, over one or several records.
//!
//! Cost: `V(θ) = (1/N) Σ ε(t,θ)² + (1/N) λ (θ−θ*)ᵀ R (θ−θ*)` over all samples of all records
//! (θ* = 0 unless a nominal vector is given), minimised by Levenberg–Marquardt with the exact
//! sensitivities of the one-step predictor ([`crate::identify::predict::Stepper`]). θ holds (a, b, k)
//! and the linear gains of the template's effects; actuator effects (dead time, rate limit,
//! saturation) stay as given. Each record has its own x̂(0), estimated jointly with θ (the
//! initial states are eliminated from the normal equations, so they cost nothing extra).
//!
//! Starts: ARX least squares, an ARMAX fit by extended least squares and a subspace (N4SID)
//! estimate, converted to the canonical form and stabilised, plus the template when it is a
//! full model. Steps that would make A or A − KC unstable are refused. Among the end points
//! whose predictor forgets its initial state, the lowest cost wins, unless another is as good
//! one step ahead and significantly better over several steps ([`choose`]); AIC and BIC are
//! those of the lowest.
//!
//! Parameter covariance `P = σ̂² (M + λR)⁻¹ M (M + λR)⁻¹` with `M = JᵀJ` (x̂(0) eliminated),
//! `σ̂² = Σε²/(N − p)`. The paper's reliability rule is reported: any STD% above 10 makes the
//! model unreliable, above 50 unusable.

pub mod choose;
pub mod focus;
mod init;
pub mod offset;
pub(crate) mod poly;
pub(crate) mod sens;

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::identify::model::Model;
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;
use sens::{Accum, Layout};

pub(crate) use init::spd_solve;
pub(crate) use sens::{params_of, with_params};

/// STD% above which the paper calls a model unreliable.
pub const STD_PCT_UNRELIABLE: f64 = 10.0;
/// STD% above which the paper calls a model unusable.
pub const STD_PCT_UNUSABLE: f64 = 50.0;

/// Where a search starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// ARX(n, n) least squares, converted to the canonical form (K from the ARX noise model).
    Arx,
    /// ARMAX(n, n, n) by extended least squares (pseudo-linear regression), converted.
    Armax,
    /// The template model itself (used only when it has the requested order and is stable).
    Template,
    /// A subspace (N4SID) estimate of order n, converted: it weighs prediction horizons up to
    /// its block size and so starts in a basin of the one-step cost that the ARX(n, n) fit
    /// misses when the order cannot hold the system (an actuator delay, a nonlinearity).
    Subspace,
}

/// Settings of [`identify`].
#[derive(Debug, Clone, PartialEq)]
pub struct PemConfig {
    /// Model order n (2..=8).
    pub order: usize,
    /// Regularisation weight λ ≥ 0 (0: plain PEM).
    pub lambda: f64,
    /// Diagonal of R, one weight per estimated parameter (θ then effect gains);
    /// `None`: identity.
    pub r: Option<Vec<f64>>,
    /// θ* the penalty pulls towards (same length as `r`); `None`: zero, as in the paper.
    pub nominal: Option<Vec<f64>>,
    /// Levenberg–Marquardt iteration cap per start.
    pub max_iter: usize,
    /// Stop when an accepted step lowers the cost by less than `tol` (relative).
    pub tol: f64,
    /// Starts to try; the template is added when given and usable.
    pub starts: Vec<Start>,
    /// Evaluate records in parallel (rayon).
    pub parallel: bool,
    /// Horizons (samples) that decide between minima whose one-step costs do not differ
    /// significantly (see [`choose`]); empty: the lowest cost always wins.
    pub select_horizons: Vec<usize>,
}

impl Default for PemConfig {
    fn default() -> Self {
        PemConfig {
            order: 4,
            lambda: 0.0,
            r: None,
            nominal: None,
            max_iter: 100,
            tol: 1e-8,
            starts: vec![Start::Arx, Start::Armax, Start::Subspace],
            parallel: true,
            select_horizons: vec![5, 10, 20],
        }
    }
}

/// Why the Levenberg–Marquardt search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// The relative cost decrease of a trusted step fell below the tolerance.
    Converged,
    /// The step became negligible relative to the parameters.
    SmallStep,
    /// No step lowers the cost any more (damping exhausted): a minimum to working precision.
    Stalled,
    /// The iteration cap was reached.
    MaxIterations,
}

impl Termination {
    /// Short description.
    ///
    /// ```
    /// assert_eq!(yawcast::identify::pem::Termination::MaxIterations.describe(), "iteration cap reached");
    /// ```
    pub fn describe(&self) -> &'static str {
        match self {
            Termination::Converged => "converged (cost change below tolerance)",
            Termination::SmallStep => "converged (step below tolerance)",
            Termination::Stalled => "no further decrease possible",
            Termination::MaxIterations => "iteration cap reached",
        }
    }
}

/// The paper's reliability verdict from the STD%s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Reliability {
    /// Every STD% ≤ 10.
    Reliable,
    /// Some STD% > 10, none > 50.
    Unreliable,
    /// Some STD% > 50.
    Unusable,
}

/// The paper's rule applied to a list of STD%s.
///
/// ```
/// use yawcast::identify::pem::{reliability, Reliability};
/// assert_eq!(reliability(&[1.0, 9.9]), Reliability::Reliable);
/// assert_eq!(reliability(&[1.0, 27.7]), Reliability::Unreliable);
/// assert_eq!(reliability(&[539.9, 2.0]), Reliability::Unusable);
/// ```
pub fn reliability(std_pct: &[f64]) -> Reliability {
    let worst = std_pct
        .iter()
        .map(|v| if v.is_nan() { f64::INFINITY } else { *v })
        .fold(0.0, f64::max);
    if worst > STD_PCT_UNUSABLE {
        Reliability::Unusable
    } else if worst > STD_PCT_UNRELIABLE {
        Reliability::Unreliable
    } else {
        Reliability::Reliable
    }
}

/// Result of an identification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PemReport {
    /// The identified model (structure of the template).
    pub model: Model,
    /// x̂(0) per record.
    pub x0: Vec<Vec<f64>>,
    /// Parameter names, in the order of `std`, `std_pct`, `cov`.
    pub names: Vec<String>,
    /// V(θ) at the optimum (including the penalty); see `choice` when that is not the
    /// lowest minimum the starts reached.
    pub cost: f64,
    /// Residual variance Σε²/(N − p).
    pub sigma2: f64,
    /// Parameter covariance (p × p, row-major rows).
    pub cov: Vec<Vec<f64>>,
    /// Standard deviation per parameter.
    pub std: Vec<f64>,
    /// 100·STD/|value| per parameter.
    pub std_pct: Vec<f64>,
    /// Levenberg–Marquardt iterations of the winning start.
    pub iterations: usize,
    /// Why the winning search stopped.
    pub termination: Termination,
    /// Which start won.
    pub start: Start,
    /// Akaike's criterion `N ln(Σε²/N) + 2p + N(ln 2π + 1)`, Σε² of the lowest minimum
    /// any start reached (the structure's maximum likelihood).
    pub aic: f64,
    /// Bayesian criterion `N ln(Σε²/N) + p ln N + N(ln 2π + 1)`, Σε² as for `aic`.
    pub bic: f64,
    /// Samples used (measured y, all records).
    pub samples: usize,
    /// The paper's verdict from `std_pct`.
    pub reliability: Reliability,
    /// λ used.
    pub lambda: f64,
    /// R used (diagonal).
    pub r: Vec<f64>,
    /// One-step fit % per record (with its x̂(0)).
    pub fit: Vec<f64>,
    /// Set when the winning minimum is not the lowest-cost one: why (see [`choose`]).
    #[serde(default)]
    pub choice: Option<choose::StartChoice>,
}

impl PemReport {
    /// Largest STD% (∞ when a parameter is exactly zero).
    pub fn max_std_pct(&self) -> f64 {
        self.std_pct
            .iter()
            .map(|v| if v.is_nan() { f64::INFINITY } else { *v })
            .fold(0.0, f64::max)
    }
}

/// One order's line of [`select_order`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderReport {
    /// Order n.
    pub order: usize,
    /// Estimated parameters.
    pub params: usize,
    /// V at the optimum (`NaN` when the identification failed).
    pub cost: f64,
    /// AIC.
    pub aic: f64,
    /// BIC.
    pub bic: f64,
    /// Mean fit % over the records at horizons 1, 5, 10 and sim (keys `"1"`, `"5"`, `"10"`, `"sim"`).
    pub fit: std::collections::BTreeMap<String, f64>,
    /// Largest STD%.
    pub max_std_pct: f64,
    /// The paper's verdict.
    pub reliability: Option<Reliability>,
    /// LM iterations.
    pub iterations: usize,
    /// Why this order failed, when it did.
    pub error: Option<String>,
}

/// Identification errors.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum IdentError {
    /// No record given.
    #[error("no records to identify from")]
    NoRecords,
    /// Order outside what the predictor supports.
    #[error("model order {0} is outside 2..=8")]
    Order(usize),
    /// Too little data for the number of unknowns.
    #[error(
        "too few samples for order {order}: {found} samples for {unknowns} unknowns \
         ({params} parameters + x̂(0) per record), at least {needed} needed"
    )]
    TooFewSamples {
        /// Order.
        order: usize,
        /// Samples available.
        found: usize,
        /// Parameters estimated.
        params: usize,
        /// Parameters plus initial states.
        unknowns: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A record is shorter than the order allows.
    #[error(
        "record `{record}` has {found} samples; order {order} needs at least {needed} per record"
    )]
    RecordTooShort {
        /// Record name.
        record: String,
        /// Its samples.
        found: usize,
        /// Order.
        order: usize,
        /// Minimum per record.
        needed: usize,
    },
    /// No record has a varying input.
    #[error("no excitation: the input of {records} is constant, nothing can be identified")]
    ConstantInput {
        /// The record names, comma-separated.
        records: String,
    },
    /// NaN or infinite data.
    #[error("record `{record}`: {channel} sample {sample} is not finite ({value})")]
    NonFinite {
        /// Record name.
        record: String,
        /// Channel (`u`, `y`, `psi`).
        channel: &'static str,
        /// 0-based sample index.
        sample: usize,
        /// The value.
        value: f64,
    },
    /// Channels of unequal length.
    #[error("record `{record}`: channel lengths differ (u {u}, y {y})")]
    Ragged {
        /// Record name.
        record: String,
        /// u length.
        u: usize,
        /// y length.
        y: usize,
    },
    /// Records (or template) with different sample times.
    #[error("sample time of `{record}` is {found} s, expected {expected} s")]
    SampleTime {
        /// Record name (or `template`).
        record: String,
        /// Its sample time.
        found: f64,
        /// The first record's.
        expected: f64,
    },
    /// R or the nominal vector has the wrong length, or a setting is out of range.
    #[error("bad setting: {0}")]
    Config(String),
    /// The given start model is not stable.
    #[error(
        "the start model is unstable (A or A − KC has an eigenvalue on or outside the unit circle)"
    )]
    StartUnstable,
    /// Every start was unstable or failed numerically.
    #[error("every start failed: {0}")]
    AllStartsFailed(String),
    /// The optimum is not stable.
    #[error("the identified model is unstable")]
    Unstable,
    /// Predictions are not finite, or nothing is measured (see [`focus::refine`]).
    #[error("cannot refine: {0}")]
    Refine(String),
}

/// Samples needed for `unknowns` estimated numbers.
fn samples_needed(unknowns: usize) -> usize {
    4 * unknowns
}

/// Checks the records and returns their common sample time.
fn check_records(records: &[Record], n: usize, params: usize) -> Result<f64, IdentError> {
    let first = records.first().ok_or(IdentError::NoRecords)?;
    let ts = first.ts;
    let per_record = 2 * n + 2;
    let mut total = 0;
    let mut constant = Vec::new();
    for r in records {
        if r.u.len() != r.y.len() || r.psi.as_ref().is_some_and(|p| p.len() != r.y.len()) {
            return Err(IdentError::Ragged {
                record: r.name.clone(),
                u: r.u.len(),
                y: r.y.len(),
            });
        }
        if !(r.ts > 0.0 && r.ts.is_finite()) || (r.ts - ts).abs() > 1e-9 * ts.abs() {
            return Err(IdentError::SampleTime {
                record: r.name.clone(),
                found: r.ts,
                expected: ts,
            });
        }
        let channels: [(&'static str, Option<&Vec<f64>>); 3] = [
            ("u", Some(&r.u)),
            ("y", Some(&r.y)),
            ("psi", r.psi.as_ref()),
        ];
        for (channel, v) in channels {
            if let Some(v) = v {
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(IdentError::NonFinite {
                        record: r.name.clone(),
                        channel,
                        sample: i,
                        value: v[i],
                    });
                }
            }
        }
        if r.len() < per_record {
            return Err(IdentError::RecordTooShort {
                record: r.name.clone(),
                found: r.len(),
                order: n,
                needed: per_record,
            });
        }
        let (lo, hi) =
            r.u.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(*v), b.max(*v))
                });
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1.0) {
            constant.push(format!("`{}`", r.name));
        }
        total += r.len();
    }
    if constant.len() == records.len() {
        return Err(IdentError::ConstantInput {
            records: if constant.len() == 1 {
                format!("record {}", constant[0])
            } else {
                format!("every record ({})", constant.join(", "))
            },
        });
    }
    let unknowns = params + n * records.len();
    let needed = samples_needed(unknowns);
    if total < needed {
        return Err(IdentError::TooFewSamples {
            order: n,
            found: total,
            params,
            unknowns,
            needed,
        });
    }
    Ok(ts)
}

/// The regularisation of a problem.
#[derive(Debug, Clone)]
struct Penalty {
    lambda: f64,
    r: Vec<f64>,
    nominal: Vec<f64>,
}

impl Penalty {
    fn new(cfg: &PemConfig, p: usize) -> Result<Penalty, IdentError> {
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

    fn value(&self, params: &[f64]) -> f64 {
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
struct Problem<'a> {
    recs: &'a [Record],
    template: Model,
    lay: Layout,
    pen: Penalty,
    parallel: bool,
}

/// A point of the search: parameters, initial states, Σε², sample count.
#[derive(Debug, Clone)]
struct Point {
    params: Vec<f64>,
    x0: Vec<Vec<f64>>,
    sse: f64,
    count: usize,
}

/// The outcome of one LM search.
struct Search {
    pt: Point,
    accs: Vec<Accum>,
    iterations: usize,
    termination: Termination,
}

impl Problem<'_> {
    fn model(&self, params: &[f64]) -> Model {
        with_params(&self.template, params)
    }

    fn stable(&self, params: &[f64]) -> bool {
        let n = self.lay.n;
        poly::canonical_stable(&params[..n], &params[2 * n..3 * n])
    }

    fn total(&self, pt: &Point) -> f64 {
        pt.sse + self.pen.value(&pt.params)
    }

    /// Whether records are evaluated in parallel (allowed, and more than one).
    fn parallel_records(&self) -> bool {
        self.parallel && self.recs.len() > 1
    }

    /// Σε² and count at (params, x0).
    fn sse(&self, params: &[f64], x0: &[Vec<f64>]) -> (f64, usize) {
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
            if !self.lay.heading && self.lay.gains.iter().all(|g| *g != sens::Gain::Damp) {
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
    fn search(&self, params: Vec<f64>, max_iter: usize, tol: f64) -> Search {
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
    fn step(&self, pt: &Point, accs: &[Accum], mu: f64) -> Option<(Vec<f64>, Vec<Vec<f64>>, f64)> {
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
    fn information(&self, accs: &[Accum]) -> DMatrix<f64> {
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
fn spd_inverse(h: &DMatrix<f64>) -> DMatrix<f64> {
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

/// Identifies a model of order `cfg.order` from `records` (one cost over all of them).
///
/// `template` gives the structure: its effects (linear gains estimated, actuator effects held
/// fixed) and, when it has order `cfg.order` and is stable, an extra start.
///
/// # Errors
/// [`IdentError`] for no records, non-finite data, ragged or differently sampled records,
/// a constant input, too few samples for the order, bad regularisation settings, or when no
/// start leads to a stable model.
///
/// ```
/// use yawcast::{io::data::Record, identify::model::Model, identify::pem, identify::predict};
/// // data from a known 2nd-order model, no noise
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let u: Vec<f64> = (0..300).map(|i| if (i * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut rec = Record::from_uy("sim", 1.0, u, vec![0.0; 300]);
/// rec.y = predict::simulate(&truth, &rec, &[0.0, 0.0]);
/// let cfg = pem::PemConfig { order: 2, ..Default::default() };
/// let rep = pem::identify(&[rec], None, &cfg).unwrap();
/// assert!((rep.model.a[1] - 0.9).abs() < 1e-6);
/// assert!(rep.fit[0] > 99.9);
/// ```
pub fn identify(
    records: &[Record],
    template: Option<&Model>,
    cfg: &PemConfig,
) -> Result<PemReport, IdentError> {
    identify_with(records, template, &[], cfg)
}

/// [`identify`] with `extra` models of the template's structure as further starts (warm
/// starts that compete with the others under the same rule).
pub(crate) fn identify_with(
    records: &[Record],
    template: Option<&Model>,
    extra: &[Model],
    cfg: &PemConfig,
) -> Result<PemReport, IdentError> {
    let n = cfg.order;
    if !(2..=8).contains(&n) {
        return Err(IdentError::Order(n));
    }
    let structure = structure_of(template, n, records);
    let lay = Layout::new(&structure);
    let ts = check_records(records, n, lay.p)?;
    if let Some(t) = template {
        if (t.ts - ts).abs() > 1e-9 * ts {
            return Err(IdentError::SampleTime {
                record: "template".into(),
                found: t.ts,
                expected: ts,
            });
        }
    }
    let mut structure = structure;
    structure.ts = ts;
    let pen = Penalty::new(cfg, lay.p)?;
    let prob = Problem {
        recs: records,
        template: structure.clone(),
        lay,
        pen,
        parallel: cfg.parallel,
    };
    let mut starts: Vec<(Start, Vec<f64>)> = Vec::new();
    let uts: Vec<Vec<f64>> = records
        .iter()
        .map(|r| init::actuator_output(&structure, r))
        .collect();
    let mut failures = Vec::new();
    let make = |s: &Start| match s {
        Start::Arx => init::arx(records, &uts, n)
            .map(|(al, be)| init::canonical_start(&structure, &al, &be, &[])),
        Start::Armax => init::armax(records, &uts, n, 8)
            .map(|(al, be, c)| init::canonical_start(&structure, &al, &be, &c)),
        Start::Subspace => init::subspace(records, &uts, n).map(|(a, b, k)| {
            let mut m = structure.clone();
            (m.n, m.a, m.b, m.k) = (n, a, b, k);
            m
        }),
        Start::Template => None,
    };
    // the starts are independent regressions: computed in parallel when allowed
    let made: Vec<Option<Model>> = crate::par::map(&cfg.starts, cfg.parallel, make);
    for (s, m) in cfg.starts.iter().zip(made) {
        match m {
            Some(m) => starts.push((*s, params_of(&m))),
            None => failures.push(format!("{s:?}: singular regression")),
        }
    }
    for t in template.into_iter().chain(extra) {
        if t.n == n && t.theta().iter().any(|v| *v != 0.0) {
            let p = params_of(t);
            if p.len() == prob.lay.p {
                starts.push((Start::Template, p));
            }
        }
    }
    run_starts(&prob, starts, cfg, failures)
}

/// Identifies starting from `start` only (its structure and parameters): the warm start used
/// by the GA and when a model is augmented with an effect. `cfg.order` and `cfg.starts` are
/// ignored.
///
/// # Errors
/// As [`identify`], and [`IdentError::StartUnstable`] when `start` is unstable.
///
/// ```
/// use yawcast::{io::data::Record, identify::model::Model, identify::pem, identify::predict};
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1]).unwrap();
/// let u: Vec<f64> = (0..300).map(|i| if (i * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut rec = Record::from_uy("sim", 1.0, u, vec![0.0; 300]);
/// rec.y = predict::simulate(&truth, &rec, &[0.0, 0.0]);
/// let mut start = truth.clone();
/// start.b = vec![0.4, 0.3];
/// let rep = pem::identify_from(&[rec], &start, &pem::PemConfig::default()).unwrap();
/// assert!((rep.model.b[0] - 0.5).abs() < 1e-6);
/// ```
pub fn identify_from(
    records: &[Record],
    start: &Model,
    cfg: &PemConfig,
) -> Result<PemReport, IdentError> {
    let n = start.n;
    if !(2..=8).contains(&n) {
        return Err(IdentError::Order(n));
    }
    let lay = Layout::new(start);
    let ts = check_records(records, n, lay.p)?;
    if (start.ts - ts).abs() > 1e-9 * ts {
        return Err(IdentError::SampleTime {
            record: "start model".into(),
            found: start.ts,
            expected: ts,
        });
    }
    if !start.is_stable() {
        return Err(IdentError::StartUnstable);
    }
    let pen = Penalty::new(cfg, lay.p)?;
    let prob = Problem {
        recs: records,
        template: start.clone(),
        lay,
        pen,
        parallel: cfg.parallel,
    };
    run_starts(
        &prob,
        vec![(Start::Template, params_of(start))],
        cfg,
        Vec::new(),
    )
}

/// The template's structure at order `n` (effects kept; θ zero when the order differs).
fn structure_of(template: Option<&Model>, n: usize, records: &[Record]) -> Model {
    let ts = records.first().map(|r| r.ts).unwrap_or(1.0);
    match template {
        Some(t) if t.n == n => t.clone(),
        Some(t) => Model {
            n,
            ts: t.ts,
            a: vec![0.0; n],
            b: vec![0.0; n],
            k: vec![0.0; n],
            effects: t.effects.clone(),
        },
        None => Model {
            n,
            ts,
            a: vec![0.0; n],
            b: vec![0.0; n],
            k: vec![0.0; n],
            effects: Vec::new(),
        },
    }
}

fn run_starts(
    prob: &Problem<'_>,
    starts: Vec<(Start, Vec<f64>)>,
    cfg: &PemConfig,
    mut failures: Vec<String>,
) -> Result<PemReport, IdentError> {
    let usable: Vec<(Start, Vec<f64>)> = starts
        .into_iter()
        .filter(|(s, params)| {
            let ok = prob.stable(params) && params.iter().all(|v| v.is_finite());
            if !ok {
                failures.push(format!("{s:?}: unstable"));
            }
            ok
        })
        .collect();
    // the searches are independent: in parallel when allowed (same result either way)
    let searched: Vec<(Start, Search)> = crate::par::map_owned(usable, cfg.parallel, |(s, p)| {
        (s, prob.search(p, cfg.max_iter, cfg.tol))
    });
    let mut found: Vec<(Start, Search)> = Vec::new();
    for (s, res) in searched {
        if res.pt.sse.is_finite() {
            found.push((s, res));
        } else {
            failures.push(format!("{s:?}: non-finite predictions"));
        }
    }
    // Only minima whose predictor forgets its initial state within the records compete
    // (see `forgets`), unless none does.
    let forgetting: Vec<bool> = found
        .iter()
        .map(|(_, r)| forgets(&prob.model(&r.pt.params), prob.recs))
        .collect();
    let any = forgetting.iter().any(|f| *f);
    let pool: Vec<(Start, Search)> = found
        .into_iter()
        .zip(forgetting)
        .filter(|(_, f)| *f || !any)
        .map(|(r, _)| r)
        .collect();
    let Some(lowest) = (0..pool.len()).reduce(|a, b| {
        if prob.total(&pool[b].1.pt) < prob.total(&pool[a].1.pt) {
            b
        } else {
            a
        }
    }) else {
        return Err(IdentError::AllStartsFailed(failures.join(", ")));
    };
    let (pick, choice) = choose_minimum(prob, &pool, lowest, &cfg.select_horizons);
    // AIC and BIC belong to the structure: its maximum likelihood is the lowest minimum
    let ml_sse = pool[lowest].1.pt.sse;
    let (start, search) = pool.into_iter().nth(pick).expect("index from the pool");
    let mut rep = report(prob, start, search, ml_sse)?;
    rep.choice = choice;
    Ok(rep)
}

/// Among the minima whose one-step cost is not significantly above the lowest's
/// ([`choose::dm_z`] below [`choose::Z_EQUAL`]) and whose k-step errors over `horizons` are
/// significantly below the lowest's, the one with the lowest mean relative k-step error;
/// `(lowest, None)` when there is none.
fn choose_minimum(
    prob: &Problem<'_>,
    pool: &[(Start, Search)],
    lowest: usize,
    horizons: &[usize],
) -> (usize, Option<choose::StartChoice>) {
    if pool.len() < 2 || horizons.is_empty() {
        return (lowest, None);
    }
    let mut hs: Vec<usize> = horizons.iter().map(|h| (*h).max(1)).collect();
    hs.sort_unstable();
    hs.dedup();
    // prediction errors per record: one step, or per horizon of `hs`
    let errors_of = |pt: &Point, one: bool| -> Vec<Vec<Vec<f64>>> {
        let m = prob.model(&pt.params);
        let mut out = vec![Vec::with_capacity(prob.recs.len()); if one { 1 } else { hs.len() }];
        for (r, x) in prob.recs.iter().zip(&pt.x0) {
            let preds = if one {
                vec![predict::one_step(&m, r, x)]
            } else {
                predict::k_steps(&m, r, x, &hs)
            };
            for (slot, p) in out.iter_mut().zip(preds) {
                slot.push(r.y.iter().zip(p).map(|(y, p)| y - p).collect());
            }
        }
        out
    };
    let base_pt = &pool[lowest].1.pt;
    let base_total = prob.total(base_pt);
    let base_one = errors_of(base_pt, true).remove(0);
    // the minima as good one step ahead (the cheap test first: k-step errors only for them)
    let equal: Vec<(usize, f64)> = pool
        .iter()
        .enumerate()
        .filter(|(i, (_, s))| {
            // a start that ended in the lowest minimum itself (to well within the sampling
            // spread): its tiny differences may test significant but mean nothing
            *i != lowest && prob.total(&s.pt) - base_total > 1e-6 * base_total
        })
        .filter_map(|(i, (_, s))| {
            let count = s.pt.count.max(1) as f64;
            // the penalty's share of the cost difference (0 for plain PEM)
            let extra = (prob.pen.value(&s.pt.params) - prob.pen.value(&base_pt.params)) / count;
            let z = choose::dm_z(&errors_of(&s.pt, true)[0], &base_one, extra);
            // NaN (no usable samples) never qualifies
            (z < choose::Z_EQUAL).then_some((i, z))
        })
        .collect();
    if equal.is_empty() {
        return (lowest, None);
    }
    let base_multi = errors_of(base_pt, false);
    let base_mse: Vec<f64> = base_multi.iter().map(|e| choose::mse(e)).collect();
    let mut best: Option<choose::StartChoice> = None;
    let mut pick = lowest;
    for (i, z) in equal {
        let pt = &pool[i].1.pt;
        let multi = errors_of(pt, false);
        let ratio = multi
            .iter()
            .zip(&base_mse)
            .map(|(e, b)| choose::mse(e) / b)
            .sum::<f64>()
            / hs.len() as f64;
        let zm = choose::dm_z_of(
            &choose::scaled_differences(&multi, &base_multi),
            0.0,
            hs.last().copied().unwrap_or(1),
        );
        if zm < -choose::Z_EQUAL && best.as_ref().map_or(true, |b| ratio < b.multi_step_ratio) {
            best = Some(choose::StartChoice {
                lowest: pool[lowest].0,
                cost_ratio: prob.total(pt) / base_total,
                z,
                horizons: hs.clone(),
                multi_step_ratio: ratio,
                multi_step_z: zm,
            });
            pick = i;
        }
    }
    (pick, best)
}

/// Whether the one-step predictor A − KC forgets its initial state within the records: its
/// spectral radius ρ satisfies ρ^L ≤ 1 % over the mean record length L.
///
/// x̂(0) is estimated per record, so a predictor pole a hair inside the unit circle lets x̂(0)
/// carry an unmodelled offset through the whole record and wins on the one-step cost. The
/// controller starts from a state it does not know that well and would carry its initial
/// error as long; such a minimum (typically reached from the subspace start when the records
/// hold an offset the structure has no effect for) is taken only when no start gives another.
fn forgets(model: &Model, recs: &[Record]) -> bool {
    let len = recs.iter().map(Record::len).sum::<usize>() as f64 / recs.len().max(1) as f64;
    let (_, rho) = model.spectral_radii();
    len * rho.ln() <= 0.01f64.ln()
}

/// The report of the minimum `s`; AIC and BIC from `ml_sse`, the lowest Σε² any start
/// reached (= `s.pt.sse` unless a minimum other than the lowest was chosen).
fn report(
    prob: &Problem<'_>,
    start: Start,
    s: Search,
    ml_sse: f64,
) -> Result<PemReport, IdentError> {
    let p = prob.lay.p;
    let model = prob.model(&s.pt.params);
    if !model.is_stable() {
        return Err(IdentError::Unstable);
    }
    let nsamp = s.pt.count;
    let sse = s.pt.sse;
    let sigma2 = sse / (nsamp.saturating_sub(p).max(1)) as f64;
    let m = prob.information(&s.accs);
    let mut a = m.clone();
    for i in 0..p {
        a[(i, i)] += prob.pen.lambda * prob.pen.r[i];
    }
    let ai = spd_inverse(&a);
    let cov = (&ai * &m * &ai) * sigma2;
    let std: Vec<f64> = (0..p).map(|i| cov[(i, i)].max(0.0).sqrt()).collect();
    let std_pct: Vec<f64> = std
        .iter()
        .zip(&s.pt.params)
        .map(|(sd, v)| {
            if *v == 0.0 {
                f64::INFINITY
            } else {
                100.0 * sd / v.abs()
            }
        })
        .collect();
    let nf = nsamp as f64;
    let v = (ml_sse.min(sse) / nf).max(f64::MIN_POSITIVE);
    let base = nf * v.ln() + nf * ((2.0 * std::f64::consts::PI).ln() + 1.0);
    let fit = prob
        .recs
        .iter()
        .zip(&s.pt.x0)
        .map(|(r, x)| predict::fit(&r.y, &predict::one_step(&model, r, x)))
        .collect();
    Ok(PemReport {
        names: model.param_names(),
        cost: (sse + prob.pen.value(&s.pt.params)) / nf,
        sigma2,
        cov: (0..p)
            .map(|i| (0..p).map(|j| cov[(i, j)]).collect())
            .collect(),
        reliability: reliability(&std_pct),
        std,
        std_pct,
        iterations: s.iterations,
        termination: s.termination,
        start,
        aic: base + 2.0 * p as f64,
        bic: base + p as f64 * nf.ln(),
        samples: nsamp,
        lambda: prob.pen.lambda,
        r: prob.pen.r.clone(),
        fit,
        x0: s.pt.x0,
        model,
        choice: None,
    })
}

/// Identifies each order in `orders` and reports fit (mean over the records at horizons 1,
/// 5, 10 and sim), AIC and BIC, so the choice of order can be seen. `cfg.r` and
/// `cfg.nominal` are ignored (their length depends on the order).
///
/// # Errors
/// [`IdentError::NoRecords`] without records; [`IdentError::AllStartsFailed`] naming every
/// order's cause when no order could be identified. A single order that fails is reported
/// in its line's `error`.
pub fn select_order(
    records: &[Record],
    orders: &[usize],
    cfg: &PemConfig,
) -> Result<Vec<OrderReport>, IdentError> {
    if records.is_empty() {
        return Err(IdentError::NoRecords);
    }
    let lines: Vec<OrderReport> = orders
        .iter()
        .map(|&n| {
            let c = PemConfig {
                order: n,
                r: None,
                nominal: None,
                ..cfg.clone()
            };
            match identify(records, None, &c) {
                Ok(rep) => {
                    let mut fit = std::collections::BTreeMap::new();
                    for h in [
                        Horizon::Steps(1),
                        Horizon::Steps(5),
                        Horizon::Steps(10),
                        Horizon::Sim,
                    ] {
                        let f: f64 = records
                            .iter()
                            .zip(&rep.x0)
                            .map(|(r, x)| {
                                predict::fit(&r.y, &predict::predict(&rep.model, r, x, h))
                            })
                            .sum::<f64>()
                            / records.len() as f64;
                        fit.insert(h.key(), f);
                    }
                    OrderReport {
                        order: n,
                        params: rep.std.len(),
                        cost: rep.cost,
                        aic: rep.aic,
                        bic: rep.bic,
                        fit,
                        max_std_pct: rep.max_std_pct(),
                        reliability: Some(rep.reliability),
                        iterations: rep.iterations,
                        error: None,
                    }
                }
                Err(e) => OrderReport {
                    order: n,
                    params: 0,
                    cost: f64::NAN,
                    aic: f64::NAN,
                    bic: f64::NAN,
                    fit: Default::default(),
                    max_std_pct: f64::NAN,
                    reliability: None,
                    iterations: 0,
                    error: Some(e.to_string()),
                },
            }
        })
        .collect();
    if !lines.is_empty() && lines.iter().all(|l| l.error.is_some()) {
        let why: Vec<String> = lines
            .iter()
            .map(|l| format!("n={}: {}", l.order, l.error.as_deref().unwrap_or("")))
            .collect();
        return Err(IdentError::AllStartsFailed(why.join("; ")));
    }
    Ok(lines)
}

#[cfg(test)]
pub(crate) mod testdata;
#[cfg(test)]
mod tests;
