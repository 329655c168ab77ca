//! The effects and the decisions in physical words: [`describe`], the explanation of an
//! augmentation and of a forward selection.

use std::collections::BTreeMap;

use yawcast_shared::model::EffectKind;

use super::forward::Round;
use super::judge::{Eval, Judgement, Reason, DECISIVE_BIC};
use crate::identify::model::{Effect, Model};
/// The effect in physical words (`ts`: the model's sample time, s): the effect's own
/// ([`Effect::describe`]).
///
/// ```
/// use yawcast::{diagnose::augment::describe, identify::model::Effect};
/// assert_eq!(describe(&Effect::Saturation { limit: 8.04 }, 1.0), "a pod angle limit of ±8.0°");
/// assert_eq!(
///     describe(&Effect::DeadTime { samples: 4 }, 0.5),
///     "a command dead time of 4 samples (2.0 s)"
/// );
/// ```
pub fn describe(effect: &Effect, ts: f64) -> String {
    effect.describe(ts)
}

/// The explanation of one candidate: the effect in words, the fits, the decision and why
/// (`evals`: the held-out evaluations of the input model, the baseline and the candidate).
pub(super) fn explanation(
    kind: EffectKind,
    model: &Model,
    cand_model: &Model,
    [before, baseline, after]: [&Eval; 3],
    j: &Judgement,
    search_note: &str,
    held_note: Option<String>,
) -> String {
    let &Judgement {
        delta_bic,
        g10,
        se10,
        gsim,
        sesim,
        sig,
        stable,
        ref reasons,
        kept,
        ..
    } = j;
    let get = |e: &Eval, k: &str| e.mean.get(k).copied().unwrap_or(f64::NAN);
    let eff = cand_model
        .effect(kind)
        .copied()
        .unwrap_or(Effect::zero(kind, 0.0));
    let mut text = format!(
        "{}; 10-step fit {:.1} → {:.1} % on held-out records (the model re-identified without it: {:.1} %), \
         simulation fit {:.1} → {:.1} %; ΔBIC {:+.1}",
        describe(&eff, model.ts),
        get(before, "10"),
        get(after, "10"),
        get(baseline, "10"),
        get(before, "sim"),
        get(after, "sim"),
        delta_bic
    );
    if !search_note.is_empty() {
        text.push_str(&format!(" ({search_note})"));
    }
    if kept && sig {
        text.push_str(&format!(
            ". Kept: the gain of {g10:+.2} pp at 10 steps and {gsim:+.2} pp in simulation is \
             significant against its spread over held-out records"
        ));
    } else if kept {
        text.push_str(&format!(
            ". Kept: the estimation records support it decisively (ΔBIC {delta_bic:+.1} ≤ \
             {DECISIVE_BIC}) and it predicts the held-out records as well as the model \
             re-identified without it ({g10:+.2} ± {se10:.2} pp at 10 steps, {gsim:+.2} ± \
             {sesim:.2} pp in simulation), which absorbs the effect into its poles; the \
             physical model is preferred"
        ));
    } else {
        let why: Vec<String> = reasons.iter().map(Reason::explain).collect();
        text.push_str(&format!(". Not kept: {}", why.join("; ")));
        if !sig && after.finite && stable {
            text.push_str(
                " — the Kalman gain already re-anchors the prediction on the measured yaw rate, \
                 so this effect adds nothing the predictor needs; the model is kept without it",
            );
        } else {
            text.push_str("; the model is kept without it");
        }
    }
    if let Some(n) = held_note {
        text.push_str(&format!(". Note: {n}"));
    }
    text.push('.');
    text
}

pub(super) fn forward_explanation(
    model: &Model,
    added: &[EffectKind],
    rounds: &[Round],
    before: &BTreeMap<String, f64>,
    after: &BTreeMap<String, f64>,
    held_note: Option<String>,
) -> String {
    let get = |m: &BTreeMap<String, f64>, k: &str| m.get(k).copied().unwrap_or(f64::NAN);
    let mut text = if added.is_empty() {
        "no further effect pays for itself on the held-out records; the model is kept as it is"
            .to_string()
    } else {
        let steps: Vec<String> = rounds
            .iter()
            .filter_map(|r| r.added.as_ref())
            .map(|a| {
                let eff = model
                    .effect(a.effect)
                    .copied()
                    .unwrap_or(Effect::zero(a.effect, 0.0));
                format!(
                    "{} ({}), {:+.2} pp at 10 steps over the model re-identified without it",
                    a.effect.name(),
                    describe(&eff, model.ts),
                    a.fit_gain_pp
                )
            })
            .collect();
        format!(
            "added, one at a time while the held-out records paid for each: {}; 10-step fit \
             {:.1} → {:.1} %, simulation fit {:.1} → {:.1} %",
            steps.join(", then "),
            get(before, "10"),
            get(after, "10"),
            get(before, "sim"),
            get(after, "sim")
        )
    };
    if let Some(last) = rounds.last().filter(|r| r.added.is_none()) {
        let best = last
            .tried
            .iter()
            .filter(|t| t.fit_gain_pp.is_finite())
            .max_by(|a, b| a.fit_gain_pp.total_cmp(&b.fit_gain_pp));
        if let Some(t) = best {
            text.push_str(&format!(
                ". Of the rest none was kept (the closest: {}, {:+.2} pp at 10 steps, ΔBIC {:+.1})",
                t.effect.name(),
                t.fit_gain_pp,
                t.delta_bic
            ));
        }
    }
    if let Some(n) = held_note {
        text.push_str(&format!(". Note: {n}"));
    }
    text.push('.');
    text
}
