//! Prediction-error identification (PEM) of the canonical innovations model, with optional
//! regularisation, over one or several records.
//!
//! Cost: `V(θ) = (1/N) Σ ε(t,θ)² + (1/N) λ (θ−θ*)ᵀ R (θ−θ*)` over all samples of all records
//! (θ* = 0 unless a nominal vector is given), minimised by Levenberg–Marquardt with the exact
//! sensitivities of the one-step predictor ([`crate::identify::predict::Stepper`]). θ holds (a, b, k)
//! and the linear gains of the template's effects; actuator effects (dead time, gear rate, angle
//! limit, dead band) stay as given. Each record has its own x̂(0), estimated jointly with θ (the
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
pub(crate) use init::jacobi_scale;
pub mod offset;
pub(crate) mod poly;
pub(crate) mod sens;

mod config;
mod lm;
mod starts;

use crate::identify::model::Model;
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;
use lm::{spd_inverse, Penalty, Problem, Search};
use sens::Layout;
use starts::{run_starts, structure_of};

pub use config::{
    reliability, IdentError, OrderReport, PemConfig, PemReport, Reliability, Start, Termination,
    STD_PCT_UNRELIABLE, STD_PCT_UNUSABLE,
};
pub(crate) use init::spd_solve;
pub(crate) use sens::{params_of, with_params};

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

/// `model` with its Kalman gain K re-fitted on `records`, A, B and the effects' gains kept:
/// the predictor of the same ship for records whose sensors are noisier (or quieter) than
/// those it was identified on. A gain fitted to smooth records passes their last
/// measurements on; on noisier ones the best gain trusts them less.
///
/// A, B and the gains are held by a penalty 10¹⁰ times the records' energy (far above the
/// cost's own curvature), and restored exactly afterwards: only K comes from the search
/// (`cfg.max_iter`, `cfg.tol`, `cfg.parallel`).
///
/// # Errors
/// As [`identify_from`]; [`IdentError::Unstable`] when the predictor with the re-fitted gain
/// is not stable.
///
/// ```
/// use rand::SeedableRng;
/// use yawcast::{io::data::Record, identify::model::Model, identify::pem, identify::predict};
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1]).unwrap();
/// let u: Vec<f64> = (0..600).map(|i| if (i * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut rec = Record::from_uy("sim", 1.0, u, vec![0.0; 600]);
/// // the ship without process noise, its yaw rate measured with white noise: the best
/// // predictor is the simulation, K = 0
/// let clean = Model { k: vec![0.0, 0.0], ..m.clone() };
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
/// rec.y = predict::simulate(&clean, &rec, &[0.0, 0.0])
///     .into_iter()
///     .map(|y| y + 0.1 * yawcast::stats::standard_normal(&mut rng))
///     .collect();
/// let refit = pem::refit_gain(&[rec], &m, &pem::PemConfig::default()).unwrap();
/// assert_eq!((refit.a.clone(), refit.b.clone()), (m.a.clone(), m.b.clone()));
/// assert!(refit.k.iter().all(|k| k.abs() < 0.05), "{:?}", refit.k);
/// ```
pub fn refit_gain(records: &[Record], model: &Model, cfg: &PemConfig) -> Result<Model, IdentError> {
    let n = model.n;
    let nominal = params_of(model);
    let energy: f64 = records
        .iter()
        .flat_map(|r| r.y.iter())
        .filter(|v| v.is_finite())
        .map(|v| v * v)
        .sum();
    let hold = 1e10 * energy.max(f64::MIN_POSITIVE);
    let r = (0..nominal.len())
        .map(|i| {
            if (2 * n..3 * n).contains(&i) {
                0.0
            } else {
                hold
            }
        })
        .collect();
    let cfg = PemConfig {
        lambda: 1.0,
        r: Some(r),
        nominal: Some(nominal),
        ..cfg.clone()
    };
    let rep = identify_from(records, model, &cfg)?;
    let out = Model {
        k: rep.model.k,
        ..model.clone()
    };
    if out.is_stable() {
        Ok(out)
    } else {
        Err(IdentError::Unstable)
    }
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
