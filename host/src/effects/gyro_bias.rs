//! `gyro-bias`: a rate-sensor offset, `y = x₁ + d_y`.

use super::{
    no_search, Channel, Def, Effect, Field, Fields, HullScale, Regressor, Role, SimEffect, SimKnobs,
};
use yawcast_shared::model::EffectKind;

/// Hidden `gyro-bias` at full strength (deg/s); it scales linearly with the strength.
pub const HIDDEN_GYRO_BIAS_DEGPS: f64 = 0.25;

pub(super) const DEF: Def = Def {
    kind: EffectKind::GyroBias,
    phrase: "a rate-gyro offset",
    role: Role::Output,
    own: false,
    channel: Channel::Heading,
    slow: true,
    gains: &[("d_y", Regressor::Offset)],
    hidden: |s| SimEffect::GyroBias {
        bias_degps: HIDDEN_GYRO_BIAS_DEGPS * s,
    },
    candidates: |_| vec![Effect::GyroBias { d_y: 0.0 }],
    search: no_search,
};

pub(super) fn describe(d_y: f64) -> String {
    format!("a rate-gyro offset of {d_y:+.3} °/s")
}

pub(super) fn evidence(d_y: f64, pct: f64, slow_h: usize) -> (Option<f64>, String) {
    (
        Some(d_y),
        format!(
            "the yaw rate reads {d_y:+.3} °/s off on the {slow_h}-step errors ({pct:.0} % of their energy)"
        ),
    )
}

pub(super) fn describe_sim(bias_degps: f64) -> String {
    format!("a rate-gyro offset of {bias_degps:.3} °/s")
}

pub(super) fn fields(v: f64) -> Fields {
    [Field::new("bias_degps", v, true, "finite"), None]
}

pub(super) fn apply(bias_degps: f64, k: &mut SimKnobs) {
    k.gyro_bias_degps += bias_degps;
}

/// A rate: scales with the inverse of the hull's time.
pub(super) fn on_hull(bias_degps: f64, s: &HullScale) -> SimEffect {
    SimEffect::GyroBias {
        bias_degps: bias_degps / s.time,
    }
}

pub(super) fn to_sim(d_y: f64) -> SimEffect {
    SimEffect::GyroBias { bias_degps: d_y }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_physics() {
        assert_eq!(describe(-0.25), "a rate-gyro offset of -0.250 °/s");
        assert_eq!(describe_sim(0.25), "a rate-gyro offset of 0.250 °/s");
        let mut k = SimKnobs::default();
        apply(0.2, &mut k);
        assert_eq!(k.gyro_bias_degps, 0.2);
    }
}
