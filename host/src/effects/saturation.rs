//! `saturation`: an angle limit below the gear's own, `τ = clamp(u, ±δ_max)`.

use super::{geometric, Channel, Def, Effect, Field, Fields, GridSpan, Role, SimEffect, SimKnobs};
use yawcast_shared::model::EffectKind;

/// Hidden `saturation` at full strength (deg); strength `s` gives
/// `20° − s·(20° − limit)` (20° is the largest identification amplitude), at least 2°.
pub const HIDDEN_LIMIT_DEG: f64 = 8.0;

pub(super) const DEF: Def = Def {
    kind: EffectKind::Saturation,
    phrase: "a rudder/pod angle limit",
    // static: θ cannot absorb it (it changes the gain at large angles, not the dynamics)
    role: Role::Actuator { dynamics: false },
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[],
    hidden: |s| SimEffect::Saturation {
        limit_deg: (20.0 - s * (20.0 - HIDDEN_LIMIT_DEG)).max(2.0),
    },
    candidates: |g| {
        geometric(0.2 * g.u_max, 0.95 * g.u_max, 12)
            .into_iter()
            .map(|limit| Effect::Saturation { limit })
            .collect()
    },
    search,
};

/// Augment: the quantiles of |u| (10 % … 99 %) and 16 even steps from the 10 % quantile to
/// the largest command, below it.
fn search(g: &GridSpan) -> Vec<f64> {
    let a = &g.abs_u;
    if a.is_empty() {
        return Vec::new();
    }
    let q = |p: f64| a[((a.len() - 1) as f64 * p).round() as usize];
    let top = a[a.len() - 1];
    let lo = q(0.1).max(1e-3 * top);
    let mut v: Vec<f64> = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99]
        .iter()
        .map(|p| q(*p))
        .chain((0..16).map(|i| lo + (top - lo) * i as f64 / 16.0))
        .filter(|v| *v > 0.0 && *v < top * (1.0 - 1e-9))
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-6 * b.abs().max(1e-9));
    v
}

pub(super) fn describe(limit: f64) -> String {
    format!("a pod angle limit of ±{limit:.1}°")
}

pub(super) fn evidence(limit: f64, pct: f64) -> (Option<f64>, String) {
    (
        Some(limit),
        format!(
            "large rudder/pod angles turn the ship less than the model expects; an angle limit of \
             {limit:.1}° explains {pct:.0} % of the one-step error energy"
        ),
    )
}

pub(super) fn describe_sim(limit_deg: f64) -> String {
    format!("a pod angle limit of ±{limit_deg:.1}°")
}

pub(super) fn fields(v: f64) -> Fields {
    [Field::new("limit_deg", v, v > 0.0, "> 0"), None]
}

/// The tightest limit wins.
pub(super) fn apply(limit_deg: f64, k: &mut SimKnobs) {
    k.limit_deg = k.limit_deg.min(limit_deg);
}

pub(super) fn to_sim(limit: f64) -> SimEffect {
    SimEffect::Saturation { limit_deg: limit }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_and_strengths() {
        assert_eq!(
            SimEffect::hidden(EffectKind::Saturation, 0.5),
            SimEffect::Saturation { limit_deg: 14.0 }
        );
        let g = GridSpan::of(1.0, [&[0.0, 10.0, -5.0, 2.0][..]]);
        let s = search(&g);
        assert!(s.iter().all(|v| *v > 0.0 && *v < 10.0), "{s:?}");
        assert!(s.windows(2).all(|w| w[0] < w[1]));
        let c = (DEF.candidates)(&g);
        assert_eq!(c.len(), 12);
        assert_eq!(c[0], Effect::Saturation { limit: 2.0 });
    }
}
