//! `wind`: the heading-dependent yaw moment of a steady wind,
//! `φ = (sin 2ψ, cos 2ψ, sin ψ, cos ψ)` through B.

use super::{
    no_search, Channel, Def, Effect, Field, Fields, HullScale, Regressor, Role, SimEffect, SimKnobs,
};
use yawcast_shared::model::EffectKind;

/// Hidden `wind` at full strength (m/s at model scale; 14.7 m/s, Beaufort 7, Froude-scaled
/// by √24), from 045°; it scales linearly with the strength.
pub const HIDDEN_WIND_MPS: f64 = 3.0;

pub(super) const DEF: Def = Def {
    kind: EffectKind::Wind,
    phrase: "a heading-dependent wind moment",
    role: Role::Regressor,
    own: false,
    channel: Channel::SpeedOverGround,
    slow: true,
    gains: &[
        ("beta_s2", Regressor::Sin2),
        ("beta_c2", Regressor::Cos2),
        ("beta_s1", Regressor::Sin1),
        ("beta_c1", Regressor::Cos1),
    ],
    hidden: |s| SimEffect::Wind {
        speed_mps: HIDDEN_WIND_MPS * s,
        from_deg: 45.0,
    },
    candidates: |_| vec![Effect::zero(EffectKind::Wind, 0.0)],
    search: no_search,
};

pub(super) fn describe(g: [f64; 4]) -> String {
    format!(
        "a heading-dependent yaw moment (wind): {:.2}° of pod angle at twice the heading \
         frequency and {:.2}° at once",
        g[0].hypot(g[1]),
        g[2].hypot(g[3])
    )
}

pub(super) fn evidence(pct: f64, slow_h: usize, p_yaw: &str) -> (Option<f64>, String) {
    (
        None,
        format!(
            "a yaw moment with the heading's 1st and 2nd harmonics takes {pct:.0} % of the \
             {slow_h}-step error energy (yaw channel: p {p_yaw})"
        ),
    )
}

pub(super) fn describe_sim(speed_mps: f64, from_deg: f64) -> String {
    format!("a steady wind of {speed_mps:.2} m/s from {from_deg:03.0}°")
}

pub(super) fn fields(speed_mps: f64, from_deg: f64) -> Fields {
    [
        Field::new("speed_mps", speed_mps, speed_mps >= 0.0, ">= 0"),
        Field::new("from_deg", from_deg, true, "finite"),
    ]
}

/// The velocity the wind blows with (towards `from + 180°`), north/east.
pub(super) fn apply(speed_mps: f64, from_deg: f64, k: &mut SimKnobs) {
    let a = from_deg.to_radians();
    k.wind_ne = (-speed_mps * a.cos(), -speed_mps * a.sin());
}

pub(super) fn on_hull(speed_mps: f64, from_deg: f64, s: &HullScale) -> SimEffect {
    SimEffect::Wind {
        speed_mps: speed_mps * s.speed,
        from_deg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words() {
        assert_eq!(
            describe([3.0, 4.0, 0.0, 1.0]),
            "a heading-dependent yaw moment (wind): 5.00° of pod angle at twice the heading frequency and 1.00° at once"
        );
        assert_eq!(
            describe_sim(3.0, 45.0),
            "a steady wind of 3.00 m/s from 045°"
        );
    }
}
