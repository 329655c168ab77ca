//! `asymmetry`: port and starboard steer differently, `φ = max(ũ, 0)` through B.

use super::{no_search, Channel, Def, Effect, Field, Fields, Regressor, Role, SimEffect, SimKnobs};
use yawcast_shared::model::EffectKind;

/// Hidden `asymmetry` at full strength (relative extra effectiveness to starboard); it
/// scales linearly with the strength.
pub const HIDDEN_ASYMMETRY: f64 = 0.4;

pub(super) const DEF: Def = Def {
    kind: EffectKind::Asymmetry,
    phrase: "a port/starboard steering asymmetry",
    role: Role::Regressor,
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[("beta", Regressor::Starboard)],
    hidden: |s| SimEffect::Asymmetry {
        starboard_gain: HIDDEN_ASYMMETRY * s,
    },
    candidates: |_| vec![Effect::Asymmetry { beta: 0.0 }],
    search: no_search,
};

pub(super) fn describe(beta: f64) -> String {
    format!(
        "starboard pod deflections {:.0} % {} effective than port ones",
        100.0 * beta.abs(),
        if beta >= 0.0 { "more" } else { "less" }
    )
}

pub(super) fn evidence(beta: f64, pct: f64) -> (Option<f64>, String) {
    (
        Some(beta),
        format!(
            "starboard commands act {} than port ones (gain {beta:+.3} on max(δ,0)); explains \
             {pct:.0} % of the one-step error energy",
            if beta > 0.0 { "harder" } else { "softer" }
        ),
    )
}

pub(super) fn describe_sim(starboard_gain: f64) -> String {
    format!(
        "pods {:+.0} % more effective to starboard",
        100.0 * starboard_gain
    )
}

pub(super) fn fields(v: f64) -> Fields {
    [Field::new("starboard_gain", v, v > -1.0, "> -1"), None]
}

pub(super) fn apply(starboard_gain: f64, k: &mut SimKnobs) {
    k.starboard_gain = starboard_gain;
}

/// The model's gain on `max(ũ, 0)` relative to the gain on `ũ` is the simulator's relative
/// extra effectiveness (kept above −0.95: a pod never stops steering).
pub(super) fn to_sim(beta: f64) -> SimEffect {
    SimEffect::Asymmetry {
        starboard_gain: beta.max(-0.95),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_physics() {
        assert_eq!(
            describe(-0.2),
            "starboard pod deflections 20 % less effective than port ones"
        );
        assert_eq!(describe_sim(0.4), "pods +40 % more effective to starboard");
        assert_eq!(
            to_sim(-3.0),
            SimEffect::Asymmetry {
                starboard_gain: -0.95
            }
        );
    }
}
