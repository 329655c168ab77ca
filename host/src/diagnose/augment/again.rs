//! `augment --effect auto` when the verdict is an effect the model carries already: diagnose
//! tested it for a change (the trials' value differs from the reference's), so its value is
//! re-estimated with the rest of the structure rather than added a second time.

use std::collections::BTreeMap;

use yawcast_shared::model::EffectKind;

use super::{
    check_records, prepare, without_effect, AugmentConfig, AugmentError, Prepared, Written,
};
use crate::identify::model::{Effect, Model};
use crate::io::data::Record;

/// What [`reestimate`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Reestimated {
    /// The model written and why ([`refit`]'s rule); its explanation gives both values of
    /// the effect.
    pub refit: Refitted,
    /// The effect as the model given carries it.
    pub given: Effect,
    /// The effect in the re-identified structure.
    pub reestimated: Effect,
}

/// Re-estimates the effect `kind` that `model` carries on the records `est`, judged on `val`
/// (or on a held-out part of `est` when `val` is empty), as [`augment`](super::augment)
/// judges a model without an added effect.
///
/// # Errors
/// [`AugmentError::Absent`] when the model does not carry `kind`; otherwise as
/// [`augment`](super::augment).
///
/// ```
/// use yawcast::diagnose::augment::{reestimate, AugmentConfig, Written};
/// use yawcast::identify::model::{Effect, Model};
/// use yawcast::identify::predict;
/// use yawcast::io::data::Record;
/// use yawcast_shared::model::EffectKind;
/// let base = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.3, 0.2]).unwrap();
/// // the model carries a steady moment of 0.2; the trials show 1.0
/// let given = base.clone().with_effect(Effect::Bias { beta: 0.2 });
/// let truth = base.with_effect(Effect::Bias { beta: 1.0 });
/// let rec = |seed: usize| {
///     let u: Vec<f64> = (0..400).map(|i| if ((i + seed) * 37 / 11) % 2 == 0 { 2.0 } else { -2.0 }).collect();
///     let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
///     r.y = predict::simulate(&truth, &r, &[0.0, 0.0]).iter().enumerate()
///         .map(|(i, v)| v + 0.01 * ((i * 7919 + seed) % 13) as f64).collect();
///     r
/// };
/// let r = reestimate(&given, EffectKind::Bias, &[rec(1), rec(2)], &[rec(3)],
///                    &AugmentConfig::default()).unwrap();
/// assert_eq!(r.refit.written, Written::Refit);
/// let Effect::Bias { beta } = r.reestimated else { panic!() };
/// assert!((beta - 1.0).abs() < 0.1, "{beta}");
/// ```
pub fn reestimate(
    model: &Model,
    kind: EffectKind,
    est: &[Record],
    val: &[Record],
    cfg: &AugmentConfig,
) -> Result<Reestimated, AugmentError> {
    check_records(model, est, val)?;
    let given = *model.effect(kind).ok_or(AugmentError::Absent(kind))?;
    let prep = prepare(model, est, val, cfg)?;
    let reestimated = prep.base.model.effect(kind).copied().unwrap_or(given);
    let mut r = judged(model, est, &prep, cfg);
    r.explanation = format!(
        "The model carries {} already and the trials show it changed: re-identified on them \
         with the rest of the structure it is {}. {}",
        given.describe(model.ts),
        reestimated.describe(model.ts),
        r.explanation,
    );
    Ok(Reestimated {
        refit: r,
        given,
        reestimated,
    })
}

/// What [`refit`] found: the model to write and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Refitted {
    /// The input structure re-identified on the estimation records when it validates better
    /// than the input model at 10 steps and no worse in simulation, else the input model.
    pub model: Model,
    /// Which of the two.
    pub written: Written,
    /// Held-out fit % of the input model, keyed by horizon.
    pub before: BTreeMap<String, f64>,
    /// Held-out fit % of the re-identified structure.
    pub after: BTreeMap<String, f64>,
    /// In words, with the fits.
    pub explanation: String,
}

/// `augment --effect auto` when diagnose names nothing: no effect to add, but the records
/// the model is augmented on are the ship's own, so the input structure is re-identified
/// on `est` and judged on `val` (or on a held-out part of `est` when `val` is empty) by the
/// rule [`augment`](super::augment) applies to a model without an added effect.
///
/// # Errors
/// As [`augment`](super::augment).
///
/// ```
/// use yawcast::diagnose::augment::{refit, AugmentConfig, Written};
/// use yawcast::identify::model::Model;
/// use yawcast::identify::predict;
/// use yawcast::io::data::Record;
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.3, 0.2]).unwrap();
/// // a model whose input gains are 40 % low
/// let given = Model::new(1.0, vec![-0.3, 0.9], vec![0.3, 0.24], vec![0.3, 0.2]).unwrap();
/// let rec = |seed: usize| {
///     let u: Vec<f64> = (0..400).map(|i| if ((i + seed) * 37 / 11) % 2 == 0 { 2.0 } else { -2.0 }).collect();
///     let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
///     r.y = predict::simulate(&truth, &r, &[0.0, 0.0]).iter().enumerate()
///         .map(|(i, v)| v + 0.01 * ((i * 7919 + seed) % 13) as f64).collect();
///     r
/// };
/// let r = refit(&given, &[rec(1), rec(2)], &[rec(3)], &AugmentConfig::default()).unwrap();
/// assert_eq!(r.written, Written::Refit);
/// assert!(r.after["10"] > r.before["10"] + 5.0);
/// ```
pub fn refit(
    model: &Model,
    est: &[Record],
    val: &[Record],
    cfg: &AugmentConfig,
) -> Result<Refitted, AugmentError> {
    check_records(model, est, val)?;
    let prep = prepare(model, est, val, cfg)?;
    Ok(judged(model, est, &prep, cfg))
}

/// The input model or its structure re-identified (`prep.base`), by [`without_effect`]'s
/// rule, with the fits and the decision in words.
fn judged(model: &Model, est: &[Record], prep: &Prepared, cfg: &AugmentConfig) -> Refitted {
    let (written_model, written, note) = without_effect(model, est, prep, cfg);
    let get = |m: &BTreeMap<String, f64>, k: &str| m.get(k).copied().unwrap_or(f64::NAN);
    let (before, after) = (prep.before.mean.clone(), prep.baseline.mean.clone());
    let mut explanation = note.unwrap_or_else(|| {
        format!(
            "The re-identified model does not validate better than the input model (10 steps \
             {:.2} → {:.2} %, simulation {:.2} → {:.2} %; better at 10 steps and no worse in \
             simulation is asked): the input model is written unchanged.",
            get(&before, "10"),
            get(&after, "10"),
            get(&before, "sim"),
            get(&after, "sim"),
        )
    });
    if let Some(h) = &prep.held_note {
        explanation.push_str(&format!(" Note: {h}."));
    }
    Refitted {
        model: written_model,
        written,
        before,
        after,
        explanation,
    }
}
