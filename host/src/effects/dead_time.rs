//! `dead-time`: a command delay of whole samples, `ũ(t) = u(t − d)`.

use super::{Channel, Def, Effect, Field, Fields, GridSpan, HullScale, Role, SimEffect, SimKnobs};
use yawcast_shared::model::{EffectKind, MAX_DEAD_TIME};

/// Hidden `dead-time` at full strength (s); it scales linearly with the strength.
pub const HIDDEN_DEAD_TIME_S: f64 = 2.0;

pub(super) const DEF: Def = Def {
    kind: EffectKind::DeadTime,
    phrase: "a command dead time",
    role: Role::Actuator { dynamics: true },
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[],
    hidden: |s| SimEffect::DeadTime {
        delay_s: HIDDEN_DEAD_TIME_S * s,
    },
    candidates,
    search,
};

/// Diagnose: what augment searches and the firmware can carry ([`search`]), every whole
/// sample up to the delay line or a tenth of the shortest record, whatever the hull.
fn candidates(g: &GridSpan) -> Vec<Effect> {
    search(g)
        .into_iter()
        .map(|d| Effect::DeadTime {
            samples: d as usize,
        })
        .collect()
}

/// Augment: every whole sample up to the firmware's delay line or a tenth of the shortest
/// record.
fn search(g: &GridSpan) -> Vec<f64> {
    let max = (MAX_DEAD_TIME as usize).min(g.shortest / 10).max(1);
    (1..=max).map(|d| d as f64).collect()
}

pub(super) fn describe(samples: usize, ts: f64) -> String {
    format!(
        "a command dead time of {samples} sample{} ({:.1} s)",
        if samples == 1 { "" } else { "s" },
        samples as f64 * ts
    )
}

pub(super) fn evidence(samples: usize, ts: f64, pct: f64) -> (Option<f64>, String) {
    let s = samples as f64 * ts;
    (
        Some(s),
        format!(
            "errors follow the steering commands late; a dead time of {s:.1} s removes {pct:.0} % of \
             the one-step error energy the reference version leaves"
        ),
    )
}

pub(super) fn describe_sim(delay_s: f64) -> String {
    format!("a command dead time of {delay_s:.1} s")
}

pub(super) fn fields(v: f64) -> Fields {
    [
        Field::new("delay_s", v, (0.0..=60.0).contains(&v), "in 0..=60 s"),
        None,
    ]
}

pub(super) fn apply(delay_s: f64, k: &mut SimKnobs) {
    k.dead_time_s += delay_s;
}

pub(super) fn on_hull(delay_s: f64, s: &HullScale) -> SimEffect {
    SimEffect::DeadTime {
        delay_s: delay_s * s.time,
    }
}

pub(super) fn to_sim(samples: usize, ts: f64) -> SimEffect {
    SimEffect::DeadTime {
        delay_s: samples as f64 * ts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids() {
        let g = GridSpan {
            ts: 1.0,
            shortest: 100,
            ..GridSpan::default()
        };
        assert_eq!(candidates(&g).len(), 10);
        assert_eq!(search(&g), (1..=10).map(f64::from).collect::<Vec<_>>());
        let g = GridSpan {
            ts: 0.1,
            shortest: 10_000,
            ..g
        };
        assert_eq!(candidates(&g).len(), MAX_DEAD_TIME as usize);
        assert_eq!(search(&g).len(), MAX_DEAD_TIME as usize);
        assert_eq!(describe(1, 0.5), "a command dead time of 1 sample (0.5 s)");
    }
}
