//! `bias`: a constant yaw moment (pod misalignment, propeller asymmetry, a steady wind or
//! current on a straight course), `φ = 1` through B.

use super::{
    no_search, Channel, Def, Effect, Field, Fields, HullScale, Regressor, Role, SimEffect, SimKnobs,
};
use yawcast_shared::model::EffectKind;

/// Yaw moment of the default ship's pods at about 4.5° at its approach speed (N·m): the
/// hidden `bias` at full strength; it scales linearly with the strength.
pub const HIDDEN_BIAS_NM: f64 = 60.0;

pub(super) const DEF: Def = Def {
    kind: EffectKind::Bias,
    phrase: "a constant yaw moment",
    role: Role::Regressor,
    own: false,
    channel: Channel::None,
    slow: true,
    gains: &[("beta", Regressor::One)],
    hidden: |s| SimEffect::Bias {
        yaw_moment_nm: HIDDEN_BIAS_NM * s,
    },
    candidates: |_| vec![Effect::Bias { beta: 0.0 }],
    search: no_search,
};

pub(super) fn describe(beta: f64) -> String {
    format!(
        "a constant yaw moment equal to {beta:+.2}° of pod angle ({})",
        if beta >= 0.0 {
            "to starboard"
        } else {
            "to port"
        }
    )
}

pub(super) fn evidence(beta: f64, pct: f64, slow_h: usize) -> (Option<f64>, String) {
    (
        Some(beta),
        format!(
            "a steady yaw moment worth {beta:+.2}° of rudder/pod angle; explains {pct:.0} % of the \
             {slow_h}-step error energy"
        ),
    )
}

pub(super) fn describe_sim(yaw_moment_nm: f64) -> String {
    format!("a constant yaw moment of {yaw_moment_nm:.1} N·m")
}

pub(super) fn fields(v: f64) -> Fields {
    [Field::new("yaw_moment_nm", v, true, "finite"), None]
}

pub(super) fn apply(yaw_moment_nm: f64, k: &mut SimKnobs) {
    k.yaw_moment_nm += yaw_moment_nm;
}

pub(super) fn on_hull(yaw_moment_nm: f64, s: &HullScale) -> SimEffect {
    SimEffect::Bias {
        yaw_moment_nm: yaw_moment_nm * s.moment,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_physics() {
        assert_eq!(
            describe(-1.234),
            "a constant yaw moment equal to -1.23° of pod angle (to port)"
        );
        assert_eq!(describe_sim(60.0), "a constant yaw moment of 60.0 N·m");
        let mut k = SimKnobs::default();
        apply(10.0, &mut k);
        apply(5.0, &mut k);
        assert_eq!(k.yaw_moment_nm, 15.0);
    }
}
