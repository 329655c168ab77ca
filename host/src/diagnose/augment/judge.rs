//! The held-out judgement (steps 3 and 4): the hold-out split, the evaluation per horizon,
//! the paired gain and its t test, the keep/decline rule and the model written when the
//! effect is declined.

use std::collections::BTreeMap;

use serde::Serialize;
use yawcast_shared::model::EffectKind;

use super::refit::reidentify_warm;
use super::{AugmentConfig, Prepared, Written};
use crate::diagnose::compare::InputError;
use crate::diagnose::resid;
use crate::identify::model::Model;
use crate::identify::pem::PemReport;
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;

/// ΔBIC at or below which the estimation evidence for an effect counts as decisive ("very
/// strong", Kass and Raftery 1995): the effect is then kept when it predicts no worse.
pub(super) const DECISIVE_BIC: f64 = -10.0;

/// Held-out evaluation of one model.
pub(super) struct Eval {
    pub(super) mean: BTreeMap<String, f64>,
    pub(super) units10: Vec<f64>,
    pub(super) units_sim: Vec<f64>,
    pub(super) resid: Vec<Vec<f64>>,
    pub(super) finite: bool,
}

/// Splits the estimation records into estimation and held-out parts.
pub(super) fn holdout(
    est: &[Record],
    n: usize,
) -> Result<(Vec<Record>, Vec<Record>, String), InputError> {
    let min_part = (12 * n + 12).max(100);
    if est.iter().all(|r| r.len() / 3 >= min_part) {
        let mut e = Vec::new();
        let mut v = Vec::new();
        for r in est {
            let cut = r.len() - r.len() / 3;
            let mut a = r.slice(0, cut);
            let mut b = r.slice(cut, r.len());
            a.name = format!("{} (first two thirds)", r.name);
            b.name = format!("{} (last third)", r.name);
            e.push(a);
            v.push(b);
        }
        return Ok((
            e,
            v,
            "no validation records given: the last third of each estimation record was held out"
                .into(),
        ));
    }
    if est.len() >= 3 {
        let k = est.len().div_ceil(3);
        let split = est.len() - k;
        return Ok((
            est[..split].to_vec(),
            est[split..].to_vec(),
            format!(
                "no validation records given: the last {k} of {} estimation records were held out",
                est.len()
            ),
        ));
    }
    let short = est
        .iter()
        .min_by_key(|r| r.len())
        .map(|r| (r.name.clone(), r.len()))
        .unwrap_or_default();
    Err(InputError::TooShort {
        set: "estimation",
        record: short.0,
        found: short.1,
        needed: 3 * min_part,
        why: "holding out its last third for validation (no validation records given; \
              give --validate records or at least three estimation records)"
            .into(),
    })
}

/// Units the paired held-out gain is computed on, at least.
const MIN_UNITS: usize = 12;

/// Number of blocks each held-out record is cut into so that the spread of the gain is
/// estimated from at least [`MIN_UNITS`] units.
fn blocks_per_record(records: usize) -> usize {
    MIN_UNITS.div_ceil(records.max(1))
}

pub(super) fn evaluate(
    model: &Model,
    val: &[Record],
    horizons: &[Horizon],
    parallel: bool,
) -> Eval {
    let nb = blocks_per_record(val.len());
    let one = |rec: &Record| {
        let x0 = predict::estimate_x0(model, rec);
        let mut fits = BTreeMap::new();
        let mut u10 = Vec::new();
        let mut usim = Vec::new();
        let mut res = Vec::new();
        for h in horizons {
            let yhat = predict::predict(model, rec, &x0, *h);
            fits.insert(h.key(), predict::fit(&rec.y, &yhat));
            let len = rec.len();
            let blocks: Vec<f64> = (0..nb)
                .map(|b| {
                    let (s, e) = (b * len / nb, (b + 1) * len / nb);
                    predict::fit(&rec.y[s..e], &yhat[s..e])
                })
                .collect();
            match h {
                Horizon::Steps(10) => u10 = blocks,
                Horizon::Sim => usim = blocks,
                Horizon::Steps(1) => {
                    res = rec.y.iter().zip(&yhat).map(|(a, b)| a - b).collect();
                }
                _ => {}
            }
        }
        (fits, u10, usim, res)
    };
    let per: Vec<_> = crate::par::map(val, parallel, one);
    let keys: Vec<String> = horizons.iter().map(Horizon::key).collect();
    let mean = crate::diagnose::compare::mean_fits(per.iter().map(|p| &p.0), &keys);
    let finite = mean.values().all(|v| v.is_finite());
    let mut e = Eval {
        mean,
        units10: Vec::new(),
        units_sim: Vec::new(),
        resid: Vec::new(),
        finite,
    };
    for (_, a, b, r) in per {
        e.units10.extend(a);
        e.units_sim.extend(b);
        e.resid.push(r);
    }
    e
}

/// One-sided 95 % Student t quantile for `dof` degrees of freedom (+∞ for none).
fn t_crit(dof: usize) -> f64 {
    crate::stats::student_t_quantile(0.05, dof as f64)
}

/// Mean held-out fit difference (pp) below which two models predict the same: half the
/// printed resolution (0.01 pp). A model re-identified from another start — the offset held
/// at the heading's measurement, the yaw rate shifted by it — predicts what the baseline
/// does to a few ten-thousandths of a point, a spread so small that such a difference would
/// otherwise read as significant.
const ROUNDING_PP: f64 = 0.005;

/// Is held-out fit % `after` worse than `before`? Not by what prints as 0.00 pp
/// ([`ROUNDING_PP`]): "91.5 < 91.5 %" is no reason.
fn worse_fit(after: f64, before: f64) -> bool {
    after < before - ROUNDING_PP
}

/// Paired gain statistics: (mean, standard error, t).
fn paired(after: &[f64], base: &[f64]) -> (f64, f64, f64) {
    let g: Vec<f64> = after.iter().zip(base).map(|(a, b)| a - b).collect();
    let k = g.len();
    if k == 0 || g.iter().any(|v| !v.is_finite()) {
        return (f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    }
    let m = g.iter().sum::<f64>() / k as f64;
    if k < 2 {
        return (m, f64::INFINITY, 0.0);
    }
    let var = g.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (k - 1) as f64;
    let se = (var / k as f64).sqrt();
    // a difference that prints as 0.00 pp is none, whatever its spread
    let t = if m.abs() < ROUNDING_PP {
        0.0
    } else if se > 0.0 {
        m / se
    } else if m > 0.0 {
        f64::INFINITY
    } else if m < 0.0 {
        f64::NEG_INFINITY
    } else {
        0.0
    };
    (m, se, t)
}

pub(super) fn ljung_box_p(resid: &[Vec<f64>]) -> f64 {
    let n: usize = resid.iter().map(Vec::len).sum();
    if resid.iter().flatten().any(|v| !v.is_finite()) || n < 30 {
        return f64::NAN;
    }
    let acf = resid::acf(resid, 25);
    resid::ljung_box(&acf, n, 25).1
}

/// Whether the model survives the f32 export schema and comes back with the same structure.
pub(super) fn round_trips(m: &Model) -> bool {
    let Ok(spec) = m.to_spec() else {
        return false;
    };
    let Ok(back) = Model::from_spec(&spec) else {
        return false;
    };
    back.effects.len() == m.effects.len()
        && back
            .effects
            .iter()
            .zip(&m.effects)
            .all(|(a, b)| a.kind() == b.kind())
        && back.is_stable()
}

/// The model to keep when no effect is added: the baseline (the input structure
/// re-identified on the estimation part, then on the whole estimation records when a part
/// was held out) when it validates better than the input model at 10 steps and no worse in
/// simulation on the held-out records, else the input model; with a sentence saying so.
pub(super) fn without_effect(
    model: &Model,
    est: &[Record],
    prep: &Prepared,
    cfg: &AugmentConfig,
) -> (Model, Written, Option<String>) {
    let get = |e: &Eval, k: &str| e.mean.get(k).copied().unwrap_or(f64::NAN);
    let (b10, bsim) = (get(&prep.baseline, "10"), get(&prep.baseline, "sim"));
    let (i10, isim) = (get(&prep.before, "10"), get(&prep.before, "sim"));
    if !(b10 > i10 && bsim >= isim) {
        return (model.clone(), Written::Input, None);
    }
    let mut refit = prep.base.model.clone();
    if prep.held_note.is_some() {
        if let Ok(full) = reidentify_warm(est, &refit, cfg) {
            if full.model.is_stable() && round_trips(&full.model) {
                refit = full.model;
            }
        }
    }
    if !(refit.is_stable() && round_trips(&refit)) {
        return (model.clone(), Written::Input, None);
    }
    let note = format!(
        "The model written is the input structure re-identified on the estimation records: \
         it validates better than the input model on the held-out records (10 steps {i10:.2} \
         → {b10:.2} %, simulation {isim:.2} → {bsim:.2} %)."
    );
    (refit, Written::Refit, Some(note))
}

/// The held-out gains of a candidate over the re-identified baseline (pp) and their
/// standard errors over the held-out records.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HeldOutGain {
    /// Gain at 10 steps.
    pub g10: f64,
    /// Its standard error.
    pub se10: f64,
    /// Gain in simulation.
    pub gsim: f64,
    /// Its standard error.
    pub sesim: f64,
}

/// Why a candidate is not kept (step 4); [`Reason::explain`] says it in words.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "reason", rename_all = "kebab-case")]
pub enum Reason {
    /// The augmented model could not be identified.
    NotIdentified,
    /// Its held-out predictions go non-finite.
    NonFinite,
    /// It is unstable.
    Unstable,
    /// Rounded to f32 it is no longer a valid stable model.
    NotExportable {
        /// Spectral radius of A.
        radius_a: f64,
        /// Spectral radius of A − KC.
        radius_predictor: f64,
    },
    /// It fails the f32 export.
    ExportFails,
    /// ΔBIC ≥ 0 on the estimation records.
    BicDoesNotPay {
        /// ΔBIC.
        delta_bic: f64,
    },
    /// The held-out gain is within the record-to-record spread.
    WithinSpread(HeldOutGain),
    /// It predicts significantly worse than the re-identified model.
    SignificantlyWorse(HeldOutGain),
    /// It would validate worse than the input model at a horizon.
    WorseThanInput {
        /// `"10"` or `"sim"`.
        horizon: String,
        /// Its fit (%).
        after: f64,
        /// The input model's (%).
        before: f64,
    },
}

impl Reason {
    /// The reason in words.
    ///
    /// ```
    /// use yawcast::diagnose::augment::Reason;
    /// let r = Reason::BicDoesNotPay { delta_bic: 3.21 };
    /// assert_eq!(
    ///     r.explain(),
    ///     "ΔBIC = +3.2 ≥ 0 on the estimation records: the extra parameter does not pay for itself"
    /// );
    /// ```
    pub fn explain(&self) -> String {
        match self {
            Reason::NotIdentified => {
                "the augmented model could not be identified (every start failed or went unstable)"
                    .into()
            }
            Reason::NonFinite => "its held-out predictions go non-finite".into(),
            Reason::Unstable => "it is unstable".into(),
            Reason::NotExportable {
                radius_a,
                radius_predictor,
            } => format!(
                "rounded to f32 for the firmware it is no longer a valid stable model (spectral \
                 radii {radius_a:.7} and {radius_predictor:.7}: a pole on the unit circle, \
                 typically following an offset the model has no effect for)"
            ),
            Reason::ExportFails => "it does not survive the f32 export".into(),
            Reason::BicDoesNotPay { delta_bic } => format!(
                "ΔBIC = {delta_bic:+.1} ≥ 0 on the estimation records: the extra parameter does \
                 not pay for itself"
            ),
            Reason::WithinSpread(g) => format!(
                "the held-out gain over the re-identified model ({:+.2} ± {:.2} pp at 10 steps, \
                 {:+.2} ± {:.2} pp in simulation) is within the record-to-record spread",
                g.g10, g.se10, g.gsim, g.sesim
            ),
            Reason::SignificantlyWorse(g) => format!(
                "it predicts significantly worse than the re-identified model ({:+.2} ± {:.2} pp \
                 at 10 steps, {:+.2} ± {:.2} pp in simulation)",
                g.g10, g.se10, g.gsim, g.sesim
            ),
            Reason::WorseThanInput {
                horizon,
                after,
                before,
            } => format!(
                "it would validate worse than the input model at {} ({after:.1} < {before:.1} %)",
                if horizon == "sim" {
                    "simulation".to_string()
                } else {
                    format!("{horizon} steps")
                }
            ),
        }
    }
}

/// What step 4 weighs for one candidate against the baseline.
pub(super) struct Judgement {
    pub(super) delta_aic: f64,
    pub(super) delta_bic: f64,
    pub(super) g10: f64,
    pub(super) se10: f64,
    pub(super) gsim: f64,
    pub(super) sesim: f64,
    /// The held-out gain is significant at 10 steps or in simulation.
    pub(super) sig: bool,
    pub(super) stable: bool,
    /// Why the candidate is not kept; empty when it is.
    pub(super) reasons: Vec<Reason>,
    /// Whether it is kept (no reason against it).
    pub(super) kept: bool,
}

/// Step 4's rule for a candidate identified on the estimation records and evaluated on
/// the held-out ones (`after`): ΔAIC and ΔBIC against the baseline, the paired held-out
/// gains, and the reasons not to keep it. `before` is the input model's evaluation, the
/// yardstick of [`Reason::WorseThanInput`]; `None` when the input model's held-out fit is
/// in-sample ([`AugmentConfig::input_in_sample`]).
pub(super) fn judge(
    kind: EffectKind,
    cand: &PemReport,
    base: &PemReport,
    before: Option<&Eval>,
    baseline: &Eval,
    after: &Eval,
) -> Judgement {
    let extra = if kind.is_actuator() { 1.0 } else { 0.0 };
    let nf = cand.samples as f64;
    let delta_aic = cand.aic + 2.0 * extra - base.aic;
    let delta_bic = cand.bic + extra * nf.ln() - base.bic;

    let (g10, se10, t10) = paired(&after.units10, &baseline.units10);
    let (gsim, sesim, tsim) = paired(&after.units_sim, &baseline.units_sim);
    let tc = t_crit(after.units10.len().saturating_sub(1));
    let get = |e: &Eval, k: &str| e.mean.get(k).copied().unwrap_or(f64::NAN);
    let stable = cand.model.is_stable();
    let exports = round_trips(&cand.model);
    let mut reasons: Vec<Reason> = Vec::new();
    if !after.finite {
        reasons.push(Reason::NonFinite);
    }
    if !stable {
        reasons.push(Reason::Unstable);
    }
    if stable && !exports {
        let (radius_a, radius_predictor) = cand.model.spectral_radii();
        reasons.push(Reason::NotExportable {
            radius_a,
            radius_predictor,
        });
    }
    if delta_bic.is_nan() || delta_bic >= 0.0 {
        reasons.push(Reason::BicDoesNotPay { delta_bic });
    }
    let sig = t10 > tc || tsim > tc;
    // decisive estimation evidence (ΔBIC ≤ −10, "very strong" on Kass and Raftery's scale)
    // with held-out prediction no worse: the effect explains with physics what the
    // re-identified structure otherwise absorbs into θ (a delay into extra poles), so the
    // physical model is kept — it predicts as well and can go into the simulator
    let decisive = delta_bic <= DECISIVE_BIC && t10 >= -tc && tsim >= -tc;
    let worse = t10 < -tc || tsim < -tc;
    let gains = HeldOutGain {
        g10,
        se10,
        gsim,
        sesim,
    };
    if !sig && !decisive && !worse {
        reasons.push(Reason::WithinSpread(gains));
    }
    if worse {
        reasons.push(Reason::SignificantlyWorse(gains));
    }
    // no yardstick when the input model's held-out fit is in-sample
    if let Some(b) = before {
        for k in ["10", "sim"] {
            if worse_fit(get(after, k), get(b, k)) {
                reasons.push(Reason::WorseThanInput {
                    horizon: k.to_string(),
                    after: get(after, k),
                    before: get(b, k),
                });
            }
        }
    }
    let kept = reasons.is_empty();
    Judgement {
        delta_aic,
        delta_bic,
        g10,
        se10,
        gsim,
        sesim,
        sig,
        stable,
        reasons,
        kept,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_difference_that_prints_as_zero_is_none() {
        // the Mariner gyro-offset case's held-out differences: a few ten-thousandths of a
        // point with a spread smaller still, which a t-test alone calls significant
        let base = [80.0, 81.0, 79.5];
        let after: Vec<f64> = base
            .iter()
            .zip([-2.4e-4, -1.3e-4, -2.5e-4])
            .map(|(b, d)| b + d)
            .collect();
        let (m, se, t) = paired(&after, &base);
        assert!(m < 0.0 && se < 1e-3 && m.abs() / se > 2.0, "{m} {se}");
        assert_eq!(t, 0.0);
        // a real difference keeps its t
        let after: Vec<f64> = base
            .iter()
            .zip([-0.5, -0.6, -0.4])
            .map(|(b, d)| b + d)
            .collect();
        let (m, se, t) = paired(&after, &base);
        assert!(
            (m + 0.5).abs() < 1e-9 && (t - m / se).abs() < 1e-9,
            "{m} {se} {t}"
        );
        assert!(t < -t_crit(2));
        // the same bound for "worse than the input model"
        assert!(!worse_fit(91.5202, 91.5226));
        assert!(worse_fit(91.5202, 91.5299));
    }
}
