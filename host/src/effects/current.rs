//! `current`: a uniform current; on the yaw channel the heading-dependent drift moment
//! `φ = (sin ψ, cos ψ)` through B, on speed over ground its first harmonic in heading.

use super::{
    no_search, Channel, Def, Effect, Field, Fields, HullScale, Regressor, Role, SimEffect, SimKnobs,
};
use yawcast_shared::model::EffectKind;

/// Hidden `current` at full strength (m/s at model scale), setting towards 090°; it scales
/// linearly with the strength.
pub const HIDDEN_CURRENT_MPS: f64 = 0.3;

pub(super) const DEF: Def = Def {
    kind: EffectKind::Current,
    phrase: "a current",
    role: Role::Regressor,
    own: false,
    channel: Channel::SpeedOverGround,
    slow: true,
    gains: &[("beta_s", Regressor::Sin1), ("beta_c", Regressor::Cos1)],
    hidden: |s| SimEffect::Current {
        speed_mps: HIDDEN_CURRENT_MPS * s,
        towards_deg: 90.0,
    },
    candidates: |_| vec![Effect::zero(EffectKind::Current, 0.0)],
    search: no_search,
};

pub(super) fn describe(beta_s: f64, beta_c: f64) -> String {
    format!(
        "a heading-dependent yaw moment (current) of {:.2}° of pod angle, largest to \
         starboard on heading {:.0}°",
        beta_s.hypot(beta_c),
        beta_s.atan2(beta_c).to_degrees().rem_euclid(360.0)
    )
}

pub(super) fn evidence(pct: f64, slow_h: usize, p_yaw: &str) -> (Option<f64>, String) {
    (
        None,
        format!(
            "a yaw moment with the heading's 1st harmonic takes {pct:.0} % of the \
             {slow_h}-step error energy (yaw channel: p {p_yaw})"
        ),
    )
}

pub(super) fn describe_sim(speed_mps: f64, towards_deg: f64) -> String {
    format!("a current of {speed_mps:.3} m/s setting towards {towards_deg:03.0}°")
}

pub(super) fn fields(speed_mps: f64, towards_deg: f64) -> Fields {
    [
        Field::new("speed_mps", speed_mps, speed_mps >= 0.0, ">= 0"),
        Field::new("towards_deg", towards_deg, true, "finite"),
    ]
}

pub(super) fn apply(speed_mps: f64, towards_deg: f64, k: &mut SimKnobs) {
    let a = towards_deg.to_radians();
    k.current_ne = (speed_mps * a.cos(), speed_mps * a.sin());
}

pub(super) fn on_hull(speed_mps: f64, towards_deg: f64, s: &HullScale) -> SimEffect {
    SimEffect::Current {
        speed_mps: speed_mps * s.speed,
        towards_deg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words() {
        assert_eq!(
            describe(1.0, 0.0),
            "a heading-dependent yaw moment (current) of 1.00° of pod angle, largest to starboard on heading 90°"
        );
        assert_eq!(
            describe_sim(0.3, 90.0),
            "a current of 0.300 m/s setting towards 090°"
        );
    }
}
