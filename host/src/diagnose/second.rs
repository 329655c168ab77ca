//! The second effect of a ranked verdict: every other effect measured again on the trials
//! against the model with the verdict's effect added.

use yawcast_shared::model::EffectKind;

use super::channels::Channels;
use super::compare::mean_fit;
use super::evidence::{trial_stats, Set, Version};
use super::rule::{compared_gains, outpredicts, GAIN_PP};
use super::verdict::{effect_evidence, frozen_gain, rank, Evidence};
use super::DiagnoseConfig;
use crate::effects::{def, Channel};
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
/// first stage's rule ([`rank`]); the second effect is the first of them that is significant
/// at `level` and improves prediction on `held` (estimation part, held-out part) by
/// [`GAIN_PP`] or more — θ frozen leaves part of the first effect in the errors, which reads
/// as its neighbour (a saturation's remainder as an asymmetry) without improving prediction
/// — or that its own channel shows with no yaw-rate part (a gyro offset, a current from
/// speed over ground alone); `None` without one. When that is current or wind and the other
/// is significant too, the one that predicts the held-out records better at both horizons
/// ([`outpredicts`]: the ranking rule's second clause) is named.
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
) -> Option<Evidence> {
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
    // significant effect that improves held-out prediction by the ranking rule's GAIN_PP
    // (what a second effect adds beside the first is judged on prediction, not on the
    // statistic alone: θ frozen leaves part of the first in the errors), or that its own
    // channel shows with nothing in the yaw rate to gain (a gyro offset from the heading, a
    // current from speed over ground alone)
    let trial = Set::new(with_first, est);
    rank(with_first, &trial, &mut ev, &rest, level, cfg, ch);
    let before = mean_fit(with_first, held.1, &Horizon::REPORT);
    let est_set = Set::new(with_first, held.0);
    let pick = ev.iter().position(|e| {
        e.p < level
            && ((e.channel_material && (e.speed_only || def(e.kind).channel == Channel::Heading))
                || frozen_gain(with_first, e, &est_set, held.1, &before, cfg.parallel).0 >= GAIN_PP)
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
            return Some(ev.swap_remove(j));
        }
    }
    Some(ev.swap_remove(pick))
}
