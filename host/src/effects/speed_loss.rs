//! `speed-loss`: the rudder's force lost with the speed in turns, `φ = ũ·s` through B, `s`
//! the squared rate the hull turns at through a first-order lag.
//!
//! A turn costs a ship speed (the hull's drag grows with the drift angle and the turn), the
//! speed follows the turn with the surge's own lag, and the rudder's or pod's force falls
//! with the square of the speed: a linear model, identified at the mean speed, steers too
//! hard after a long turn and too softly on a straight course. A stand-in for the speed
//! from the yaw rate alone, `Û = b₀ + b₁·s`, explains most of the logged speed's variance on
//! zig-zags (Mariner: R² 0.89–0.90 with a lag of 100–200 s, 0.06 without a lag), so the
//! effect needs no speed on the controller. Every record the ship sails has it, the
//! reference's too: it is the ship's own physics, which `augment --effect auto` adds when
//! the reference records pay for it; diagnose does not name it on trials
//! ([`Def::diagnosed`]).

use super::{geometric, Channel, Def, Effect, Field, Fields, GridSpan, Regressor, Role};
use super::{SimEffect, SimKnobs};
use yawcast_shared::model::EffectKind;

/// Hidden `speed-loss` at full strength: an extra surge resistance in turns
/// `X = −x_rr·½ρL³d·r²` (non-dimensional `x_rr`); it scales linearly with the strength.
pub const HIDDEN_X_RR: f64 = 0.1;

/// Number of lags searched.
const LAGS: usize = 6;

pub(super) const DEF: Def = Def {
    kind: EffectKind::SpeedLoss,
    phrase: "the rudder's force lost with the speed in turns",
    role: Role::Regressor,
    own: true,
    diagnosed: false,
    channel: Channel::None,
    slow: false,
    gains: &[("beta", Regressor::SpeedLoss)],
    hidden: |s| SimEffect::SpeedLoss {
        x_rr: HIDDEN_X_RR * s,
    },
    candidates,
    search: |_| Vec::new(),
};

/// The versions searched, gains zero: lags of 5 samples to a quarter of the shortest
/// record, geometric ([`LAGS`] values).
fn candidates(g: &GridSpan) -> Vec<Effect> {
    let hi = (g.shortest as f64 / 4.0).max(6.0);
    geometric(5.0, hi, LAGS)
        .into_iter()
        .map(|lag| Effect::SpeedLoss {
            beta: 0.0,
            keep: keep_of(lag),
        })
        .collect()
}

/// The lag's factor kept per sample for a lag of `samples` samples: `e^(−1/samples)`.
pub(super) fn keep_of(samples: f64) -> f64 {
    (-1.0 / samples).exp()
}

/// The lag in samples of a factor kept per sample: `−1/ln keep`.
pub(super) fn lag_of(keep: f64) -> f64 {
    -1.0 / keep.ln()
}

pub(super) fn describe(beta: f64, keep: f64, ts: f64) -> String {
    format!(
        "the rudder's force {} with the speed in turns: {beta:+.4} of it per (°/s)² of the \
         squared yaw rate through a {:.0} s lag",
        if beta <= 0.0 { "lost" } else { "gained" },
        lag_of(keep) * ts
    )
}

pub(super) fn evidence(beta: f64, keep: f64, ts: f64, pct: f64) -> (Option<f64>, String) {
    (
        Some(beta),
        format!(
            "after a turn the rudder acts {} than the model expects (gain {beta:+.4} on δ·r² \
             through a {:.0} s lag); explains {pct:.0} % of the one-step error energy",
            if beta < 0.0 { "softer" } else { "harder" },
            lag_of(keep) * ts
        ),
    )
}

pub(super) fn describe_sim(x_rr: f64) -> String {
    format!("extra surge resistance in turns x_rr = {x_rr:.3}")
}

pub(super) fn fields(x_rr: f64) -> Fields {
    [Field::new("x_rr", x_rr, x_rr >= 0.0, ">= 0"), None]
}

pub(super) fn apply(x_rr: f64, k: &mut SimKnobs) {
    k.x_rr = x_rr;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lags_and_words() {
        let g = GridSpan::of(1.0, [&vec![0.0; 1800][..]]);
        let c = candidates(&g);
        let lags: Vec<f64> = c
            .iter()
            .map(|e| match e {
                Effect::SpeedLoss { keep, .. } => lag_of(*keep),
                _ => f64::NAN,
            })
            .collect();
        assert_eq!(lags.len(), LAGS);
        assert!(
            (lags[0] - 5.0).abs() < 1e-9 && (lags[5] - 450.0).abs() < 1e-6,
            "{lags:?}"
        );
        assert!((keep_of(100.0) - 0.990_049_833_749_168).abs() < 1e-15);
        assert_eq!(
            describe(-0.0125, keep_of(50.0), 2.0),
            "the rudder's force lost with the speed in turns: -0.0125 of it per (°/s)² of the \
             squared yaw rate through a 100 s lag"
        );
        assert_eq!(
            describe_sim(0.1),
            "extra surge resistance in turns x_rr = 0.100"
        );
    }
}
