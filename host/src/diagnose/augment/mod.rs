//! Augment a model with one library effect: add it, re-identify, and keep it only when it
//! improves prediction on held-out records.
//!
//! # Method
//!
//! 1. **Baseline.** The input structure (with whatever effects it already carries) is
//!    re-identified on the estimation records, so the comparison with the candidate is fair:
//!    both have seen the same data. Baseline and candidate are each identified as
//!    [`pem::identify`] does (its starts plus warm starts, and its choice between minima that
//!    predict one step equally well, [`pem::choose`]); the searches *inside* step 2 compare
//!    one-step costs and take the lowest minimum, as do ΔAIC and ΔBIC.
//! 2. **Candidate.** The effect is appended (stacked on the model's effects).
//!    - *Linear-gain effects* (bias, gyro bias, asymmetry, nonlinear damping, wind, current):
//!      PEM from the ARX, ARMAX and subspace starts, from the input model with the new gain
//!      at zero and from the baseline with the new gain at zero. A gyro offset on records
//!      that log heading is held at what the heading measures (the gyro against the
//!      compass's turn) and the model re-identified on the yaw rate less it: on the yaw rate
//!      alone it looks like a steady yaw moment (see `heading.rs`).
//!    - *Actuator effects* (dead time d, gear rate ρ, angle limit δ_max, dead band b): a
//!      grid of the structural parameter, the effect's own search
//!      ([`crate::effects::Def::search`]: d = 1..=[`MAX_DEAD_TIME`] samples; ρ on a log grid
//!      from 0.5 °/s to what still binds on the records' largest command step — diagnose's
//!      range, finer —, which covers real steering gears' 2.3–9 °/s; δ_max over the
//!      quantiles of the recorded |δ|; b over 0.2–6°). Every grid value is scored cheaply with θ frozen (one-step cost
//!      of the input and of the baseline model with the effect added) and once more after a
//!      warm-started re-identification (θ frozen without the effect can miss a sharp optimum);
//!      the best few of each ranking are re-identified fully, and a continuous parameter is
//!      refined by golden-section search between the neighbours of the best, each point
//!      re-identified from a warm start; the best value's structure is then identified as
//!      the baseline was.
//! 3. **Held-out judgement.** Fit % per horizon on the validation records of the input model
//!    (`before`), the baseline and the candidate (`after`). When no validation record is
//!    given, the last third of each estimation record is held out (or, for short records,
//!    the last third of the records); the candidate kept is then re-identified on the whole
//!    records from its held-out-tested parameters.
//! 4. **Decision.** The effect is kept when the candidate is stable, predicts finitely and
//!    survives the f32 export round trip, its ΔBIC against the baseline is negative (an
//!    actuator parameter counts as one parameter), its paired held-out fit gain over the
//!    baseline at 10 steps or in simulation is significant against the spread of the gain
//!    over records (one-sided Student t at 95 %; records are cut into blocks so that at
//!    least twelve units carry the spread) — or, when ΔBIC ≤ −10 (decisive evidence on the
//!    estimation records), the gain is merely not negative: a re-identified 4th-order model
//!    can absorb a short delay into its poles and predict as well, and the physical model is
//!    then preferred — neither horizon is significantly worse, and it does not validate
//!    worse than the input model at 10 steps or in simulation. Otherwise the effect is not
//!    kept, with the reason, and the model returned is the baseline when it validates better
//!    than the input model (10 steps better, simulation no worse) — the same structure fitted
//!    to the records at hand — or else the input model unchanged ([`Written`]).
//!
//! # Forward selection
//!
//! [`forward`] searches the library for the best predictor: each round tries every effect the
//! model lacks, exactly as above against one shared baseline, adds the kept one with the best
//! held-out 10-step fit, and repeats until a round keeps none. It finds what the diagnosis
//! rightly leaves out — physics the simulator has but a linear model lacks on every record,
//! above all the hull's own nonlinear damping (`yawcast augment --more`).
//!
//! [`pem::identify`]: crate::identify::pem::identify
//! [`pem::choose`]: crate::identify::pem::choose

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};
use thiserror::Error;
use yawcast_shared::model::EffectKind;

use crate::diagnose::compare::{check_command, check_inputs, InputError};
use crate::effects::GridSpan;
use crate::identify::model::{Effect, Model};
use crate::identify::pem::{IdentError, PemConfig, PemReport};
use crate::identify::predict::Horizon;
use crate::io::data::Record;

mod actuator;
mod again;
mod agree;
mod auto;
mod forward;
mod heading;
mod judge;
mod refit;
mod simulator;
#[cfg(test)]
pub(crate) mod tests;
mod words;

pub use again::{reestimate, refit, Reestimated, Refitted};
pub(crate) use agree::sig;
pub use agree::{check_estimate, EstimateCheck};
pub(crate) use auto::own_search;
pub use auto::{auto_kinds, own_base, OwnBase};
pub use forward::{forward, forward_ranked, ForwardReport, Round, Tried};
pub use judge::{HeldOutGain, Reason};
pub use simulator::to_sim_effect;
pub use words::describe;

use actuator::actuator_candidate;
use judge::{evaluate, holdout, judge, ljung_box_p, round_trips, without_effect, Eval};
use refit::{reidentify_final, reidentify_warm};
use words::explanation;

/// Largest dead time tried (samples): the firmware's delay-line length.
pub const MAX_DEAD_TIME: usize = yawcast_shared::model::MAX_DEAD_TIME as usize;

/// Settings of [`augment`].
#[derive(Debug, Clone, PartialEq)]
pub struct AugmentConfig {
    /// PEM settings for the re-identifications (`order` is taken from the model; `r` and
    /// `nominal`, when given for the input structure, get zero weights for the new gains).
    pub pem: PemConfig,
    /// Horizons reported (default 1, 5, 10, 20 and sim; 10 and sim are always evaluated,
    /// they carry the decision).
    pub horizons: Vec<Horizon>,
    /// Evaluate grid points and records in parallel (rayon).
    pub parallel: bool,
    /// The input model was identified on the whole estimation records, the held-out part
    /// included, so its held-out fit is in-sample: it is then no yardstick, and a candidate
    /// is judged against the input structure re-identified on the estimation part alone
    /// (the reason "validates worse than the input model" is not applied). Default false.
    pub input_in_sample: bool,
    /// The form nonlinear damping is fitted in: `Some(false)` `y|y|`, `Some(true)` `y³`, or
    /// `None` (default) both, the one with the lower estimation cost kept. `diagnose` and
    /// `augment --effect auto` pass the form the diagnosis measured, so that both report
    /// one parameter in one unit.
    pub damping_form: Option<bool>,
}

impl Default for AugmentConfig {
    fn default() -> Self {
        AugmentConfig {
            pem: PemConfig::default(),
            horizons: Horizon::REPORT.to_vec(),
            parallel: true,
            input_in_sample: false,
            damping_form: None,
        }
    }
}

/// Why a model cannot be augmented.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum AugmentError {
    /// The model or the records are unusable (sample time, lengths, non-finite data, …).
    #[error(transparent)]
    Input(#[from] InputError),
    /// Re-identification failed for the baseline (the input structure itself).
    #[error("re-identifying the model failed: {0}")]
    Ident(#[from] IdentError),
    /// The model already carries this effect.
    #[error(
        "the model already carries the effect `{}`; effects stack, but each kind only once",
        .0.name()
    )]
    AlreadyPresent(EffectKind),
    /// The model does not carry this effect (nothing to re-estimate).
    #[error("the model does not carry the effect `{}`: nothing to re-estimate", .0.name())]
    Absent(EffectKind),
}

fn ser_kind<S: Serializer>(k: &EffectKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(k.name())
}

/// What [`augment`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AugmentReport {
    /// The effect tried (serialised as its name, e.g. `"dead-time"`).
    #[serde(serialize_with = "ser_kind")]
    pub effect: EffectKind,
    /// The model with the effect added and re-identified.
    pub candidate: Model,
    /// The model to write: `candidate` when kept; otherwise the model without the effect
    /// that validates better — the input structure re-identified on the estimation records
    /// when it beats the input model on the held-out records, else the input model
    /// unchanged (`written` says which).
    pub model: Model,
    /// Whether the effect was kept.
    pub kept: bool,
    /// What `model` is.
    pub written: Written,
    /// Held-out fit % of the input model, keyed by horizon (`"1"`, `"5"`, `"10"`, `"20"`, `"sim"`).
    pub before: BTreeMap<String, f64>,
    /// Held-out fit % of the input structure re-identified on the estimation records.
    pub baseline: BTreeMap<String, f64>,
    /// Held-out fit % of the candidate.
    pub after: BTreeMap<String, f64>,
    /// `after − baseline` at 10 steps (pp): the gain the decision judges.
    pub fit_gain_pp: f64,
    /// AIC of the candidate minus the baseline's, on the estimation records.
    pub delta_aic: f64,
    /// BIC of the candidate minus the baseline's, on the estimation records.
    pub delta_bic: f64,
    /// Ljung–Box p-value (25 lags) of the input model's held-out one-step residuals.
    pub ljung_box_p_before: f64,
    /// The same for the candidate.
    pub ljung_box_p_after: f64,
    /// STD% of the candidate's estimated parameters (θ then effect gains).
    pub std_pct: Vec<f64>,
    /// Why the effect is not kept (empty when it is): the typed reasons the explanation
    /// words.
    pub reasons: Vec<Reason>,
    /// Physical words with numbers: the effect's size, the fits, the decision and why.
    pub explanation: String,
}

/// What an augmentation returns as its model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Written {
    /// The input model unchanged.
    Input,
    /// The input structure (no effect added) re-identified on the estimation records: it
    /// validates better than the input model at 10 steps and no worse in simulation.
    Refit,
    /// The input model with the effect(s) added and re-identified.
    Augmented,
}

/// Adds `kind` to `model`, re-identifies it on `est`, and judges it on `val` (or on a
/// held-out part of `est` when `val` is empty). See the module documentation for the method.
///
/// # Errors
/// [`AugmentError::AlreadyPresent`] when the model carries the effect already;
/// [`AugmentError::Input`] for an invalid model, no estimation records, records that do not
/// match the model (sample time, ragged or non-finite channels, too short); and
/// [`AugmentError::Ident`] when even the input structure cannot be re-identified. A candidate
/// that fails to identify, is unstable or predicts non-finitely is not an error: it is
/// reported as not kept.
///
/// ```
/// use yawcast::{diagnose::augment::{augment, AugmentConfig}, io::data::Record, identify::model::Model, identify::predict};
/// use yawcast_shared::model::EffectKind;
/// // a 2nd-order ship whose commands arrive two samples late
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let delayed = truth.clone().with_effect(yawcast::identify::model::Effect::DeadTime { samples: 2 });
/// let rec = |seed: usize| {
///     let u: Vec<f64> = (0..400).map(|i| if ((i + seed) * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
///     let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
///     r.y = predict::simulate(&delayed, &r, &[0.0, 0.0]).iter().enumerate()
///         .map(|(i, v)| v + 0.01 * ((i * 7919 + seed) % 13) as f64).collect();
///     r
/// };
/// let rep = augment(&truth, EffectKind::DeadTime, &[rec(1), rec(2)], &[rec(3), rec(4)],
///                   &AugmentConfig::default()).unwrap();
/// assert!(rep.kept);
/// assert_eq!(rep.model.effect(EffectKind::DeadTime),
///            Some(&yawcast::identify::model::Effect::DeadTime { samples: 2 }));
/// ```
pub fn augment(
    model: &Model,
    kind: EffectKind,
    est: &[Record],
    val: &[Record],
    cfg: &AugmentConfig,
) -> Result<AugmentReport, AugmentError> {
    check_records(model, est, val)?;
    if model.effect(kind).is_some() {
        return Err(AugmentError::AlreadyPresent(kind));
    }
    let prep = prepare(model, est, val, cfg)?;
    let mut rep = try_effect(model, kind, est, &prep, cfg);
    if !rep.kept {
        let (m, written, note) = without_effect(model, est, &prep, cfg);
        rep.model = m;
        rep.written = written;
        if let Some(n) = note {
            rep.explanation.push_str(&format!(" {n}"));
        }
    }
    Ok(rep)
}

/// Checks the model and the records [`augment`] and [`forward`] are given.
fn check_records(model: &Model, est: &[Record], val: &[Record]) -> Result<(), AugmentError> {
    check_inputs(model, est, 0, "estimation")?;
    check_command(model, est, "estimation")?;
    if !val.is_empty() {
        check_inputs(model, val, 0, "validation")?;
        check_command(model, val, "validation")?;
    }
    Ok(())
}

/// What every candidate effect on one input model is compared with: the held-out split,
/// the horizons, and the input structure re-identified (the baseline) with both evaluated.
struct Prepared {
    est_part: Vec<Record>,
    val_part: Vec<Record>,
    held_note: Option<String>,
    horizons: Vec<Horizon>,
    base: PemReport,
    before: Eval,
    baseline: Eval,
}

/// Splits the records and identifies and evaluates the baseline (step 1 and the `before`
/// and `baseline` columns of step 3).
fn prepare(
    model: &Model,
    est: &[Record],
    val: &[Record],
    cfg: &AugmentConfig,
) -> Result<Prepared, AugmentError> {
    let (est_part, val_part, held_note) = if val.is_empty() {
        let (e, v, note) = holdout(est, model.n)?;
        (e, v, Some(note))
    } else {
        (est.to_vec(), val.to_vec(), None)
    };
    let mut horizons = cfg.horizons.clone();
    for h in [Horizon::Steps(1), Horizon::Steps(10), Horizon::Sim] {
        if !horizons.contains(&h) {
            horizons.push(h);
        }
    }
    // baseline: the input structure re-identified on the same estimation records
    let base = reidentify_final(&est_part, model, &[], cfg)?;
    let before = evaluate(model, &val_part, &horizons, cfg.parallel);
    let baseline = evaluate(&base.model, &val_part, &horizons, cfg.parallel);
    Ok(Prepared {
        est_part,
        val_part,
        held_note,
        horizons,
        base,
        before,
        baseline,
    })
}

/// The forms a regressor or output effect is fitted in, gains at zero: the effect's own
/// candidates ([`crate::effects::Def::candidates`]: nonlinear damping's `y|y|` and `y³`,
/// one for the others), the damping held to the form [`AugmentConfig::damping_form`] names.
fn forms(kind: EffectKind, cfg: &AugmentConfig, est: &[Record], ts: f64) -> Vec<Effect> {
    let span = GridSpan::of(ts, est.iter().map(|r| &r.u[..]));
    (crate::effects::def(kind).candidates)(&span)
        .into_iter()
        .filter(|e| {
            kind != EffectKind::NonlinearDamping
                || cfg.damping_form.map_or(true, |c| e.cubic() == c)
        })
        .collect()
}

/// Steps 2–4 for one effect against a prepared baseline.
fn try_effect(
    model: &Model,
    kind: EffectKind,
    est: &[Record],
    prep: &Prepared,
    cfg: &AugmentConfig,
) -> AugmentReport {
    let Prepared {
        est_part,
        val_part,
        held_note,
        horizons,
        base,
        before,
        baseline,
    } = prep;
    let (est_part, val_part, horizons) = (&est_part[..], &val_part[..], &horizons[..]);
    let held_note = held_note.clone();

    // candidate
    let offset = heading::measured_offset(kind, est_part);
    let (cand, search_note) = if kind.is_actuator() {
        actuator_candidate(kind, model, &base.model, est_part, cfg)
    } else if let Some(hb) = offset {
        let shifted = heading::shifted(est_part, hb.bias);
        (
            reidentify_final(&shifted, model, std::slice::from_ref(&base.model), cfg)
                .ok()
                .map(|r| heading::with_measured_offset(r, hb)),
            heading::note(hb),
        )
    } else {
        // every form of the effect (nonlinear damping's y|y| and y³, unless the config names
        // one), the lowest estimation cost kept: the forms have one gain each
        let fits = forms(kind, cfg, est_part, model.ts)
            .into_iter()
            .filter_map(|e| {
                let t = model.clone().with_effect(e);
                // nested: from the baseline with the new gain at zero the candidate reaches the
                // baseline's minimum or a lower one on the estimation records
                let nested = base.model.clone().with_effect(e);
                reidentify_final(est_part, &t, &[nested], cfg).ok()
            });
        (fits.min_by(|a, b| a.cost.total_cmp(&b.cost)), String::new())
    };
    let Some(cand) = cand else {
        let candidate = model.clone().with_effect(Effect::zero(kind, 1.0));
        return failed_report(
            kind,
            model,
            candidate,
            before,
            baseline,
            horizons,
            held_note,
            Reason::NotIdentified,
        );
    };
    let after = evaluate(&cand.model, val_part, horizons, cfg.parallel);

    let yardstick = (!cfg.input_in_sample).then_some(before);
    let mut j = judge(kind, &cand, base, yardstick, baseline, &after);
    let get = |e: &Eval, k: &str| e.mean.get(k).copied().unwrap_or(f64::NAN);

    // the candidate finally returned: re-fitted on the whole records when a part was held out
    let mut cand_model = cand.model.clone();
    let mut std_pct = cand.std_pct.clone();
    if j.kept && held_note.is_some() {
        let full = match heading::measured_offset(kind, est) {
            Some(hb) => reidentify_warm(
                &heading::shifted(est, hb.bias),
                &heading::without_offset(&cand.model),
                cfg,
            )
            .map(|r| heading::with_measured_offset(r, hb)),
            None => reidentify_warm(est, &cand.model, cfg),
        };
        if let Ok(full) = full {
            if full.model.is_stable() && round_trips(&full.model) {
                cand_model = full.model;
                std_pct = full.std_pct;
            }
        }
    }
    if j.kept && !round_trips(&cand_model) {
        j.kept = false;
        j.reasons.push(Reason::ExportFails);
    }
    let text = explanation(
        kind,
        model,
        &cand_model,
        [before, baseline, &after],
        &j,
        &search_note,
        held_note,
    );
    let keys: Vec<String> = horizons.iter().map(Horizon::key).collect();
    let pick = |e: &Eval| -> BTreeMap<String, f64> {
        keys.iter()
            .filter(|k| cfg.horizons.iter().any(|h| &h.key() == *k) || *k == "10" || *k == "sim")
            .map(|k| (k.clone(), get(e, k)))
            .collect()
    };
    AugmentReport {
        effect: kind,
        model: if j.kept {
            cand_model.clone()
        } else {
            model.clone()
        },
        candidate: cand_model,
        kept: j.kept,
        written: if j.kept {
            Written::Augmented
        } else {
            Written::Input
        },
        before: pick(before),
        baseline: pick(baseline),
        after: pick(&after),
        fit_gain_pp: get(&after, "10") - get(baseline, "10"),
        delta_aic: j.delta_aic,
        delta_bic: j.delta_bic,
        ljung_box_p_before: ljung_box_p(&before.resid),
        ljung_box_p_after: ljung_box_p(&after.resid),
        std_pct,
        reasons: j.reasons,
        explanation: text,
    }
}

#[allow(clippy::too_many_arguments)]
fn failed_report(
    kind: EffectKind,
    model: &Model,
    candidate: Model,
    before: &Eval,
    baseline: &Eval,
    horizons: &[Horizon],
    held_note: Option<String>,
    why: Reason,
) -> AugmentReport {
    let nan: BTreeMap<String, f64> = horizons.iter().map(|h| (h.key(), f64::NAN)).collect();
    let mut text = format!(
        "{}: not kept: {}; the model is kept without it",
        describe(&Effect::zero(kind, 0.0), model.ts),
        why.explain()
    );
    if let Some(n) = held_note {
        text.push_str(&format!(". Note: {n}"));
    }
    AugmentReport {
        effect: kind,
        candidate,
        model: model.clone(),
        kept: false,
        written: Written::Input,
        before: before.mean.clone(),
        baseline: baseline.mean.clone(),
        after: nan,
        fit_gain_pp: f64::NAN,
        delta_aic: f64::NAN,
        delta_bic: f64::NAN,
        ljung_box_p_before: ljung_box_p(&before.resid),
        ljung_box_p_after: f64::NAN,
        std_pct: Vec::new(),
        reasons: vec![why],
        explanation: text,
    }
}
