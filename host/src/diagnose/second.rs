//! The second effect of a ranked verdict: every other effect measured again on the trials
//! against the model with the verdict's effect added.

use yawcast_shared::model::EffectKind;

use super::channels::Channels;
use super::compare::mean_fit;
use super::evidence::{trial_stats, Set, Version};
use super::rule::{compared_gains, outpredicts, NO_GAIN_PP};
use super::verdict::{effect_evidence, frozen_gain, rank, Evidence};
use super::DiagnoseConfig;
use crate::identify::model::{Effect, Model};
use crate::identify::predict::Horizon;
use crate::io::data::Record;

/// What the trials show beside the verdict's effect `first`: each other effect's statistic
/// `D` measured on the trials against the model with `first` (its trial version, θ frozen as
/// in the first stage), from the first stage's reference versions (`versions[i]` for
/// `grids[i]`, found against `base`: the reference lacks `first`), judged against the first stage's null replicates
/// (`nulls[i]` for `grids[i]`: the null of an effect's statistic depends on its grid and the
/// records, not on what else the model carries). Current and wind share speed over ground's
/// evidence, so beside either the other is not a second effect. The others are ranked by the
/// first stage's rule ([`rank`]); the second effect is the first of them that [`named_second`]
/// accepts, its held-out gain measured on `held` (estimation part, held-out part); `None`
/// without one. When that is current or wind and the other is significant too, the one that
/// predicts the held-out records better at both horizons ([`outpredicts`]: the ranking rule's
/// second clause) is named. Beside the effect, why it is named, in words (its channel, its
/// held-out gain, or the second clause).
#[allow(clippy::too_many_arguments)]
pub(super) fn second_effect(
    base: &Model,
    first: &Effect,
    versions: &[Version],
    est: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    nulls: &[Vec<f64>],
    level: f64,
    has_ref: bool,
    cfg: &DiagnoseConfig,
    ch: &Channels,
    held: (&[Record], &[Record]),
) -> Option<(Evidence, String)> {
    let k1 = first.kind();
    let with_first = &base.clone().with_effect(*first);
    let shares_speed = |k: EffectKind| {
        matches!(
            (k1, k),
            (EffectKind::Current, EffectKind::Wind) | (EffectKind::Wind, EffectKind::Current)
        )
    };
    let keep: Vec<usize> = (0..grids.len())
        .filter(|&i| grids[i].0 != k1 && !shares_speed(grids[i].0))
        .collect();
    let rest: Vec<(EffectKind, Vec<Effect>)> = keep.iter().map(|&i| grids[i].clone()).collect();
    let kept: Vec<Version> = keep.iter().map(|&i| versions[i].clone()).collect();
    let stats = trial_stats(with_first, est, &rest, &kept, cfg.parallel);
    let mut ev: Vec<Evidence> = keep
        .iter()
        .zip(&stats)
        .map(|(&i, st)| effect_evidence(with_first, grids[i].0, st, &nulls[i], has_ref, cfg, ch))
        .collect();
    // the first stage's ranking, on the model with the first effect; then the first
    // effect `named_second` accepts
    let trial = Set::new(with_first, est);
    rank(with_first, &trial, &mut ev, &rest, level, cfg, ch);
    let before = mean_fit(with_first, held.1, &Horizon::REPORT);
    let est_set = Set::new(with_first, held.0);
    let mut gain = f64::NAN;
    let pick = ev.iter().position(|e| {
        named_second(e, level, || {
            gain = frozen_gain(with_first, e, &est_set, held.1, &before, cfg.parallel).0;
            gain
        })
    })?;
    // current or wind: the ranking rule's second clause between the two, as in the first
    // stage — the one that predicts the held-out records better at both horizons is named
    let partner = match ev[pick].kind {
        EffectKind::Current => Some(EffectKind::Wind),
        EffectKind::Wind => Some(EffectKind::Current),
        _ => None,
    };
    if let Some(j) = partner.and_then(|k| ev.iter().position(|e| e.kind == k && e.p < level)) {
        let held_out = |e: &Evidence| {
            let (_, fits) = frozen_gain(with_first, e, &est_set, held.1, &before, cfg.parallel);
            compared_gains(&fits, &before)
        };
        let (gp, gj) = (held_out(&ev[pick]), held_out(&ev[j]));
        if outpredicts(gj, gp) {
            let words = format!(
                "; named ahead of {} beside the first effect: it predicts the held-out \
                 records better at 10 steps ({:+.2} pp against {:+.2}) and in simulation \
                 ({:+.2} pp against {:+.2})",
                ev[pick].kind.name(),
                gj[0],
                gp[0],
                gj[1],
                gp[1]
            );
            ev[j].words.push_str(&words);
            let why = format!(
                "named ahead of {}: it predicts the held-out records better at 10 steps and in \
                 simulation",
                ev[pick].kind.name()
            );
            return Some((ev.swap_remove(j), why));
        }
    }
    let why = if ev[pick].channel_material {
        "its own channel shows it".to_string()
    } else {
        format!("held-out fit gain {gain:+.2} pp")
    };
    Some((ev.swap_remove(pick), why))
}

/// Is `e` named as the second effect of a ranked verdict? It must be significant at `level`,
/// and either its own channel must show it (`channel_material`: a gyro offset from the
/// heading, a current or wind from speed over ground, course over ground, the anemometer —
/// the channels that carry them, whatever the yaw rate gains) or it must improve held-out
/// prediction (`held_out_gain`, pp, computed only when needed) by [`NO_GAIN_PP`] or more,
/// the level below which the ranking rule counts an effect as not improving prediction. What
/// a second effect adds beside the first is judged on prediction, not on the statistic
/// alone: θ frozen leaves part of the first effect in the errors, which can read as its
/// neighbour (a saturation's remainder as an asymmetry) without improving prediction.
pub(super) fn named_second(e: &Evidence, level: f64, held_out_gain: impl FnOnce() -> f64) -> bool {
    e.p < level && (e.channel_material || held_out_gain() >= NO_GAIN_PP)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::tests::evidence;

    #[test]
    fn a_second_effect_is_named_by_its_channel_or_by_what_it_wins_back() {
        let level = 1e-3;
        // a wind the speed over ground and the yaw moment's harmonics show (lng, a slew
        // limit and wind hidden, seed 1: p 6e-14, +0.20 pp held out): its channels name it
        let wind = evidence(EffectKind::Wind, 6e-14, 5e-7, true);
        assert!(named_second(&wind, level, || 0.20));
        // a damping beside a saturation (Mariner, seed 1: +0.69 pp at 10 steps, θ frozen)
        let nld = evidence(EffectKind::NonlinearDamping, 3e-12, 3e-12, false);
        assert!(named_second(&nld, level, || 0.69));
        assert!(named_second(&nld, level, || NO_GAIN_PP));
        // a remainder of the first effect that wins nothing back is not a second effect
        assert!(!named_second(&nld, level, || 0.49));
        assert!(!named_second(&nld, level, || f64::NEG_INFINITY));
        // nor is an effect that is not significant, whatever it gains: its held-out
        // gain is not even computed
        let weak = evidence(EffectKind::NonlinearDamping, 2e-3, 2e-3, true);
        assert!(!named_second(&weak, level, || unreachable!("not computed")));
    }
}
