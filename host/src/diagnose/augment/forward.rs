//! Forward selection over the effects library ([`forward`], CLI `--more`): per round one
//! shared baseline, every lacking effect tried by the same rule, the best kept one added.

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};
use yawcast_shared::model::EffectKind;

use super::judge::without_effect;
use super::words::forward_explanation;
use super::{
    check_records, prepare, ser_kind, try_effect, AugmentConfig, AugmentError, AugmentReport,
    Written,
};
use crate::identify::model::Model;
use crate::io::data::Record;
/// One effect tried in a round of [`forward`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tried {
    /// The effect (serialised as its name).
    #[serde(serialize_with = "ser_kind")]
    pub effect: EffectKind,
    /// Whether [`augment`]'s rule would keep it on the round's model.
    ///
    /// [`augment`]: super::augment
    pub kept: bool,
    /// Held-out 10-step fit % of the model with it (NaN when it could not be identified).
    pub fit_10: f64,
    /// Its held-out gain at 10 steps over the round's model re-identified (pp).
    pub fit_gain_pp: f64,
    /// ΔBIC against the round's model re-identified.
    pub delta_bic: f64,
    /// Why it has no fit (the effect could not be identified, its fits are NaN): the
    /// refusal in words; `None` when it was identified.
    pub note: Option<String>,
}

/// One round of [`forward`]: every library effect the model lacks, tried on it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Round {
    /// Every effect tried, in library order.
    pub tried: Vec<Tried>,
    /// The report of the effect added in this round (of those kept, the one with the best
    /// held-out 10-step fit); `None` in the last round, where none was kept.
    pub added: Option<AugmentReport>,
}

/// What [`forward`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForwardReport {
    /// The input model with every added effect, re-identified.
    pub model: Model,
    /// The effects added, in order (serialised as names).
    #[serde(serialize_with = "ser_kinds")]
    pub added: Vec<EffectKind>,
    /// The rounds, the last one adding nothing (unless the candidates ran out).
    pub rounds: Vec<Round>,
    /// Held-out fit % of the input model, keyed by horizon.
    pub before: BTreeMap<String, f64>,
    /// Held-out fit % of the returned model (before its final refit on whole records).
    pub after: BTreeMap<String, f64>,
    /// What `model` is: the input with the added effects (`Augmented`), or, when nothing
    /// was added, as for [`augment`] (`Refit` or `Input`).
    ///
    /// [`augment`]: super::augment
    pub written: Written,
    /// Physical words with numbers: what was added, what each bought, what was not and why.
    pub explanation: String,
}

impl ForwardReport {
    /// Held-out 10-step fit % of the structure the first round re-identified without any
    /// added effect, and of the returned model (NaN where missing); `None` when nothing was
    /// added.
    pub fn fit10_without_and_with(&self) -> Option<(f64, f64)> {
        let first = self.rounds.first().and_then(|r| r.added.as_ref())?;
        let fit10 = |m: &BTreeMap<String, f64>| m.get("10").copied().unwrap_or(f64::NAN);
        Some((fit10(&first.baseline), fit10(&self.after)))
    }
}

fn ser_kinds<S: Serializer>(k: &[EffectKind], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(k.iter().map(|k| k.name()))
}

/// Forward selection over the effects library: tries every effect of `candidates` the model
/// lacks, each as [`augment`] would (same estimation and held-out records, same decision
/// rule, one shared baseline per round), adds the kept one with the best held-out 10-step
/// fit, and repeats on the augmented model until no effect is kept or none is left.
///
/// This is for the predictor, not for the diagnosis: a linear model of a nonlinear hull
/// lacks the hull's own nonlinear damping on *any* record, including the simulator's, so
/// [`crate::diagnose`] (which looks for what the trials have and the reference lacks) rightly
/// does not name it — yet adding it can buy several points of k-step fit.
///
/// # Errors
/// As [`augment`]: [`AugmentError::Input`] for unusable model or records, and
/// [`AugmentError::Ident`] when a round's input structure cannot be re-identified. A
/// candidate that fails is reported as not kept.
///
/// ```
/// use yawcast::{diagnose::augment::{forward, AugmentConfig}, io::data::Record, identify::model::{Effect, Model}, identify::predict};
/// use yawcast_shared::model::EffectKind;
/// // a 2nd-order ship whose commands arrive two samples late
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let delayed = truth.clone().with_effect(Effect::DeadTime { samples: 2 });
/// let rec = |seed: usize| {
///     let u: Vec<f64> = (0..400).map(|i| if ((i + seed) * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
///     let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
///     r.y = predict::simulate(&delayed, &r, &[0.0, 0.0]).iter().enumerate()
///         .map(|(i, v)| v + 0.01 * ((i * 7919 + seed) % 13) as f64).collect();
///     r
/// };
/// let cands = [EffectKind::DeadTime, EffectKind::Saturation, EffectKind::Bias];
/// let rep = forward(&truth, &[rec(1), rec(2)], &[rec(3), rec(4)], &cands,
///                   &AugmentConfig::default()).unwrap();
/// assert_eq!(rep.added[0], EffectKind::DeadTime);
/// assert_eq!(rep.model.effect(EffectKind::DeadTime), Some(&Effect::DeadTime { samples: 2 }));
/// assert!(rep.after["10"] > rep.before["10"]);
/// ```
///
/// [`augment`]: super::augment
pub fn forward(
    model: &Model,
    est: &[Record],
    val: &[Record],
    candidates: &[EffectKind],
    cfg: &AugmentConfig,
) -> Result<ForwardReport, AugmentError> {
    forward_ranked(model, est, val, candidates, None, cfg)
}

/// [`forward`], with `first` taking precedence in the first round: when the rule keeps it,
/// it is added even if another kept effect validates better at 10 steps; the search then
/// goes on as [`forward`] does. This stacks a ranked diagnosis (`yawcast augment --effect
/// auto --more`: the verdict's second effect first): the diagnosis names it from what the
/// trials show and the reference lacks, while the search's own pick rests on prediction
/// alone, where the hull's own nonlinearity can outbid it. When the rule does not keep
/// `first`, the round picks as [`forward`] does.
///
/// # Errors
/// As [`forward`].
///
/// ```
/// use yawcast::{diagnose::augment::{forward_ranked, AugmentConfig}, io::data::Record, identify::model::{Effect, Model}, identify::predict};
/// use yawcast_shared::model::EffectKind;
/// // a 2nd-order ship whose commands arrive two samples late
/// let truth = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let delayed = truth.clone().with_effect(Effect::DeadTime { samples: 2 });
/// let rec = |seed: usize| {
///     let u: Vec<f64> = (0..400).map(|i| if ((i + seed) * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
///     let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
///     r.y = predict::simulate(&delayed, &r, &[0.0, 0.0]).iter().enumerate()
///         .map(|(i, v)| v + 0.01 * ((i * 7919 + seed) % 13) as f64).collect();
///     r
/// };
/// let cands = [EffectKind::DeadTime, EffectKind::Bias];
/// let rep = forward_ranked(&truth, &[rec(1), rec(2)], &[rec(3), rec(4)], &cands,
///                          Some(EffectKind::DeadTime), &AugmentConfig::default()).unwrap();
/// assert_eq!(rep.added.first(), Some(&EffectKind::DeadTime));
/// ```
pub fn forward_ranked(
    model: &Model,
    est: &[Record],
    val: &[Record],
    candidates: &[EffectKind],
    first: Option<EffectKind>,
    cfg: &AugmentConfig,
) -> Result<ForwardReport, AugmentError> {
    check_records(model, est, val)?;
    let mut current = model.clone();
    let mut rounds: Vec<Round> = Vec::new();
    let mut added: Vec<EffectKind> = Vec::new();
    let mut before: Option<BTreeMap<String, f64>> = None;
    let mut held_note = None;
    let mut written = Written::Augmented;
    let mut refit_note = None;
    loop {
        let todo: Vec<EffectKind> = candidates
            .iter()
            .copied()
            .filter(|k| current.effect(*k).is_none())
            .fold(Vec::new(), |mut v, k| {
                if !v.contains(&k) {
                    v.push(k);
                }
                v
            });
        if todo.is_empty() {
            break;
        }
        let prep = prepare(&current, est, val, cfg)?;
        held_note.clone_from(&prep.held_note);
        let first_round = rounds.is_empty();
        let reports = crate::par::map(&todo, cfg.parallel, |k| {
            try_effect(&current, *k, est, &prep, cfg)
        });
        if before.is_none() {
            before = reports.first().map(|r| r.before.clone());
        }
        let tried = reports
            .iter()
            .map(|r| Tried {
                effect: r.effect,
                kept: r.kept,
                fit_10: r.after.get("10").copied().unwrap_or(f64::NAN),
                fit_gain_pp: r.fit_gain_pp,
                delta_bic: r.delta_bic,
                note: (!r.fit_gain_pp.is_finite()).then(|| r.explanation.clone()),
            })
            .collect();
        let ranked =
            first.filter(|k| first_round && reports.iter().any(|r| r.effect == *k && r.kept));
        let best = reports
            .into_iter()
            .filter(|r| r.kept && ranked.map_or(true, |k| r.effect == k))
            .fold(None::<AugmentReport>, |b, r| {
                let f10 = |a: &AugmentReport| a.after.get("10").copied().unwrap_or(f64::NAN);
                match b {
                    Some(b) if f10(&b) >= f10(&r) => Some(b),
                    _ => Some(r),
                }
            });
        let done = best.is_none();
        if let Some(b) = &best {
            current = b.model.clone();
            added.push(b.effect);
        }
        rounds.push(Round { tried, added: best });
        if done {
            if first_round {
                // nothing added at all: the better of the input and its refit
                let (m, w, note) = without_effect(&current, est, &prep, cfg);
                current = m;
                written = w;
                refit_note = note;
            }
            break;
        }
    }
    if added.is_empty() && written == Written::Augmented {
        // no candidate to try at all
        written = Written::Input;
    }
    let before = before.unwrap_or_default();
    let after = rounds
        .iter()
        .rev()
        .find_map(|r| r.added.as_ref().map(|a| a.after.clone()))
        .unwrap_or_else(|| before.clone());
    let mut explanation =
        forward_explanation(&current, &added, &rounds, &before, &after, held_note);
    if let Some(n) = refit_note {
        explanation.push_str(&format!(" {n}"));
    }
    Ok(ForwardReport {
        model: current,
        written,
        added,
        rounds,
        before,
        after,
        explanation,
    })
}
