//! The JSON summary of `yawcast augment` (stable field names, docs/cli.md).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;
use yawcast::demo::FitSummary;
use yawcast::diagnose::augment::{self, Written};
use yawcast::sim::SimEffect;
use yawcast_shared::model::EffectKind;

/// The JSON summary of `augment`.
#[derive(Debug, Serialize)]
pub struct AugmentSummary {
    /// Always "augment".
    pub command: &'static str,
    /// The effect tried (its library name).
    pub effect: String,
    /// Whether `--effect auto` chose it.
    pub auto: bool,
    /// Whether it was kept.
    pub kept: bool,
    /// What the model written is, against the model given: `"augmented"` (it carries effects
    /// that one lacks: the kept effect, those `--more` added, or the reference's own steering
    /// gear that `--effect auto` found), `"refit"` (no effect added; the structure
    /// re-identified on the estimation records validates better) or `"input"` (the model
    /// given, unchanged).
    pub written: Written,
    /// The input model on the held-out records.
    pub before: FitSummary,
    /// The input structure re-identified on the estimation records.
    pub baseline: FitSummary,
    /// The augmented model.
    pub after: FitSummary,
    /// after − baseline at 10 steps (pp).
    pub fit_gain_pp: f64,
    /// ΔAIC candidate − baseline.
    pub delta_aic: f64,
    /// ΔBIC candidate − baseline.
    pub delta_bic: f64,
    /// Ljung–Box p of the input model's held-out one-step residuals.
    pub ljung_box_p_before: f64,
    /// Ljung–Box p of the augmented model's.
    pub ljung_box_p_after: f64,
    /// The augmented model's effect with its estimated parameters.
    pub estimated: Option<yawcast::identify::model::Effect>,
    /// STD% of the augmented model's parameters.
    pub std_pct: Vec<f64>,
    /// Why the effect is not kept, typed (`{"reason": "within-spread", …}`); empty when kept.
    pub reasons: Vec<augment::Reason>,
    /// Physical words with numbers.
    pub explanation: String,
    /// The model blob written.
    pub out: PathBuf,
    /// The ship file written, or null.
    pub ship: Option<PathBuf>,
    /// The effect written into the ship file (physical units), or null.
    pub sim_effect: Option<SimEffect>,
    /// The search of `--more`, or null without it.
    pub more: Option<MoreSummary>,
    /// `--effect auto`: the effect's parameter as augment estimated it beside diagnose's
    /// estimate, with whether they agree within the uncertainty each states and, where they
    /// do not, why; null without `--effect auto` or for an effect without such a parameter
    /// (wind, current).
    pub estimate_check: Option<augment::EstimateCheck>,
    /// The effects of the model written, in the order they act.
    pub effects: Vec<String>,
    /// `--effect current` (or `--effect auto --more` with a current as the ranked verdict's
    /// second effect) on a model with a heading/track part and held-out records with
    /// navigation channels: the track error before and after the track's current estimate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track_error_m: Option<TrackBeforeAfter>,
}

/// The track error (m) of `augment --effect current`, before and after.
#[derive(Debug, Serialize)]
pub struct TrackBeforeAfter {
    /// Mean over the held-out records of the median track error, keyed by horizon in
    /// seconds ("30", "60", "120"), with the model's track part as given.
    pub before: BTreeMap<String, f64>,
    /// The same with the current estimated.
    pub after: BTreeMap<String, f64>,
    /// Whether the current part was kept (it lowers the 60-s error) and written.
    pub kept: bool,
    /// Records scored.
    pub records: usize,
}

/// The `more` object of the JSON summary: the search of `--more`.
#[derive(Debug, Serialize)]
pub struct MoreSummary {
    /// The effects added, in order.
    pub added: Vec<String>,
    /// Held-out fits of the model the search started from.
    pub before: FitSummary,
    /// Held-out fits of the model written.
    pub after: FitSummary,
    /// Every round: each effect tried with its held-out 10-step fit and gain, and the one added.
    pub rounds: Vec<RoundSummary>,
    /// `--effect auto`: the ranked verdict's second effect, which takes precedence in the
    /// first round when the held-out records pay for it; null otherwise.
    pub ranked_first: Option<String>,
    /// Physical words with numbers.
    pub explanation: String,
}

/// One round of the `--more` search in the JSON summary.
#[derive(Debug, Serialize)]
pub struct RoundSummary {
    /// The effect added in this round, or null (the last round).
    pub added: Option<String>,
    /// Every effect tried.
    pub tried: Vec<augment::Tried>,
}

impl MoreSummary {
    pub(super) fn of(f: &augment::ForwardReport, ranked_first: Option<EffectKind>) -> Self {
        MoreSummary {
            ranked_first: ranked_first.map(|k| k.name().to_string()),
            added: f.added.iter().map(|k| k.name().to_string()).collect(),
            before: FitSummary {
                fit: f.before.clone(),
            },
            after: FitSummary {
                fit: f.after.clone(),
            },
            rounds: f
                .rounds
                .iter()
                .map(|r| RoundSummary {
                    added: r.added.as_ref().map(|a| a.effect.name().to_string()),
                    tried: r.tried.clone(),
                })
                .collect(),
            explanation: f.explanation.clone(),
        }
    }
}
