//! `nonlinear-damping`: hull damping beyond linear (Norrbin), `φ = ρ|ρ|` or `ρ³`, `ρ = y − d_y`.

use super::{no_search, Channel, Def, Effect, Field, Fields, Regressor, Role, SimEffect, SimKnobs};
use yawcast_shared::model::EffectKind;

/// Hidden `nonlinear-damping` at full strength (non-dimensional `n_rr`); it scales linearly
/// with the strength.
pub const HIDDEN_N_RR: f64 = 0.15;

pub(super) const DEF: Def = Def {
    kind: EffectKind::NonlinearDamping,
    phrase: "extra nonlinear yaw damping",
    role: Role::Regressor,
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[("beta", Regressor::Damping)],
    hidden: |s| SimEffect::NonlinearDamping {
        n_rr: HIDDEN_N_RR * s,
        cubic: false,
    },
    // both forms searched, the gain fitted
    candidates: |_| {
        vec![
            Effect::NonlinearDamping {
                beta: 0.0,
                cubic: false,
            },
            Effect::NonlinearDamping {
                beta: 0.0,
                cubic: true,
            },
        ]
    },
    search: no_search,
};

pub(super) fn describe(beta: f64, cubic: bool) -> String {
    format!(
        "{} yaw damping beyond linear: {beta:+.4}° of pod angle per {}",
        if beta <= 0.0 { "extra" } else { "less" },
        if cubic {
            "(°/s)³"
        } else {
            "(°/s)² of r·|r|"
        }
    )
}

pub(super) fn evidence(beta: f64, cubic: bool, pct: f64) -> (Option<f64>, String) {
    (
        Some(beta),
        format!(
            "fast turns are damped {} than the model expects ({} gain {beta:+.4}); explains \
             {pct:.0} % of the one-step error energy",
            if beta < 0.0 { "more" } else { "less" },
            if cubic { "r³" } else { "r|r|" }
        ),
    )
}

pub(super) fn describe_sim(n_rr: f64, cubic: bool) -> String {
    format!(
        "extra Norrbin yaw damping n_rr = {n_rr:.3}{}",
        if cubic { " (cubic)" } else { "" }
    )
}

pub(super) fn fields(n_rr: f64) -> Fields {
    [Field::new("n_rr", n_rr, n_rr >= 0.0, ">= 0"), None]
}

pub(super) fn apply(n_rr: f64, cubic: bool, k: &mut SimKnobs) {
    k.n_rr = n_rr;
    k.cubic = cubic;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words() {
        assert_eq!(
            describe(-0.01, false),
            "extra yaw damping beyond linear: -0.0100° of pod angle per (°/s)² of r·|r|"
        );
        assert_eq!(
            describe_sim(0.15, true),
            "extra Norrbin yaw damping n_rr = 0.150 (cubic)"
        );
    }
}
