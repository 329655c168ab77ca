//! `dead-band`: steering-gear backlash, the rudder/pod stays put until the command is more
//! than `b` away and then follows `b` behind, `ũ = clamp(ũ_prev, τ − b, τ + b)`.

use super::{geometric, Channel, Def, Effect, Field, Fields, Role, SimEffect, SimKnobs};
use yawcast_shared::model::EffectKind;

/// Hidden `dead-band` at full strength (deg): the backlash of a worn steering gear; it
/// scales linearly with the strength.
pub const HIDDEN_DEAD_BAND_DEG: f64 = 2.0;

pub(super) const DEF: Def = Def {
    kind: EffectKind::DeadBand,
    phrase: "a steering-gear dead band",
    role: Role::Actuator { dynamics: false },
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[],
    hidden: |s| SimEffect::DeadBand {
        width_deg: HIDDEN_DEAD_BAND_DEG * s,
    },
    candidates: |g| {
        widths(g.u_max)
            .into_iter()
            .map(|width| Effect::DeadBand { width })
            .collect()
    },
    search: |g| widths(g.u_max),
};

/// The widths searched, by diagnose and by augment alike: 12 geometric steps from 0.2° to
/// 6° (worn steering gears show 0.5–3°), or to 40 % of the largest command when that is
/// smaller. A wider "band" on large-amplitude records (zig-zags) only trades the command's
/// amplitude against the model's gain, so it is not searched.
fn widths(u_max: f64) -> Vec<f64> {
    geometric(0.2, 6.0_f64.min(0.4 * u_max), 12)
}

pub(super) fn describe(width: f64) -> String {
    format!("a steering-gear dead band of {width:.2}°")
}

pub(super) fn evidence(width: f64, pct: f64) -> (Option<f64>, String) {
    (
        Some(width),
        format!(
            "small steering corrections do not reach the ship and reversals arrive short; a \
             dead band of {width:.2}° explains {pct:.0} % of the one-step error energy"
        ),
    )
}

pub(super) fn describe_sim(width_deg: f64) -> String {
    format!("a steering-gear dead band of {width_deg:.2}°")
}

pub(super) fn fields(v: f64) -> Fields {
    [
        Field::new("width_deg", v, v > 0.0 && v <= 45.0, "in (0, 45] deg"),
        None,
    ]
}

pub(super) fn apply(width_deg: f64, k: &mut SimKnobs) {
    k.band_deg += width_deg;
}

pub(super) fn to_sim(width: f64) -> SimEffect {
    SimEffect::DeadBand { width_deg: width }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_grid_for_diagnose_and_augment() {
        // inputs hidden from the optimiser: a constant-folded `powf`/`powi` may round
        // differently from the run-time one, and the point is one grid at run time
        let w = widths(std::hint::black_box(20.0));
        assert_eq!(w.len(), 12);
        assert!((w[0] - 0.2).abs() < 1e-12 && (w[11] - 6.0).abs() < 1e-9);
        assert!((widths(5.0)[11] - 2.0).abs() < 1e-9);
        let g = super::super::GridSpan::of(1.0, [&std::hint::black_box([0.0, 20.0])[..]]);
        assert_eq!((DEF.search)(&g), w);
        assert_eq!((DEF.candidates)(&g).len(), 12);
    }
}
