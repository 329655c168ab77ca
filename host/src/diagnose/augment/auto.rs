//! The rule of `augment --effect auto` for the reference's own steering gear: which model
//! the trials are augmented from.

use yawcast_shared::model::EffectKind;

use crate::identify::merge::validation_fits;
use crate::identify::model::{Effect, Model};
use crate::io::data::Record;

/// Which model `--effect auto` augments, when diagnose found steering-gear dynamics the
/// reference records show of their own ([`gear_base`]).
#[derive(Debug, Clone, PartialEq)]
pub enum GearBase {
    /// The reference model with its own gear: the trials are augmented from it.
    Gear {
        /// The gear effects it adds to the model given.
        own: Vec<Effect>,
    },
    /// The verdict is of a kind the gear already has (a slower gear on the trials than the
    /// reference's own): its value is estimated from the model given, as without a gear.
    SameKind(EffectKind),
    /// The model with the gear predicts the check records worse at 10 steps than the model
    /// given (fit %, or NaN when it cannot predict them).
    PredictsWorse {
        /// The gear model's 10-step fit.
        gear: f64,
        /// The given model's.
        given: f64,
    },
    /// The gear adds nothing the model given lacks.
    Nothing,
}

/// The model `--effect auto` augments and why: the reference's gear model `gear` when the
/// verdict is not one of its effects, it adds an effect the model given lacks and it
/// predicts the records `check` at 10 steps at least as well as the model given; otherwise
/// the model given.
///
/// ```
/// use yawcast::diagnose::augment::{gear_base, GearBase};
/// use yawcast::identify::model::{Effect, Model};
/// use yawcast_shared::model::EffectKind;
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let gear = m.clone().with_effect(Effect::DeadTime { samples: 1 });
/// let (chosen, why) = gear_base(&m, gear, Some(EffectKind::DeadTime), &[]);
/// assert_eq!(chosen, m);
/// assert_eq!(why, GearBase::SameKind(EffectKind::DeadTime));
/// ```
pub fn gear_base(
    given: &Model,
    gear: Model,
    verdict: Option<EffectKind>,
    check: &[Record],
) -> (Model, GearBase) {
    if let Some(k) = verdict.filter(|k| gear.effect(*k).is_some()) {
        return (given.clone(), GearBase::SameKind(k));
    }
    let own: Vec<Effect> = gear
        .effects
        .iter()
        .filter(|e| given.effect(e.kind()).is_none())
        .copied()
        .collect();
    if own.is_empty() {
        return (given.clone(), GearBase::Nothing);
    }
    let fit10 = |m: &Model| {
        validation_fits(m, check)
            .get("10")
            .copied()
            .unwrap_or(f64::NAN)
    };
    let (fg, fm) = (fit10(&gear), fit10(given));
    if fg.is_nan() || fg < fm {
        return (
            given.clone(),
            GearBase::PredictsWorse {
                gear: fg,
                given: fm,
            },
        );
    }
    (gear, GearBase::Gear { own })
}

impl GearBase {
    /// The decision in words (`ts`: the model's sample time), or `None` when there is
    /// nothing to say.
    pub fn explain(&self, ts: f64) -> Option<String> {
        match self {
            GearBase::Gear { own } => Some(format!(
                "augmenting the reference model with the steering-gear dynamics the reference \
                 records show of their own: {}",
                own.iter()
                    .map(|e| e.describe(ts))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
            GearBase::PredictsWorse { gear, given } => Some(format!(
                "the reference's own steering gear is left out: the reference model with it \
                 predicts the trials worse at 10 steps ({gear:.2} < {given:.2} %)"
            )),
            GearBase::SameKind(_) | GearBase::Nothing => None,
        }
    }
}
