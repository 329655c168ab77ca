//! The second effect of a ranked verdict: every other effect measured again on the trials
//! against the model with the verdict's effect added.

use yawcast_shared::model::EffectKind;

use super::channels::Channels;
use super::compare::mean_fit;
use super::evidence::{trial_stats, Set, Version};
use super::null::Nulls;
use super::rule::{compared_gains, current_and_wind, outpredicts, NO_GAIN_PP};
use super::verdict::{effect_evidence, frozen_gain, rank, Evidence};
use super::DiagnoseConfig;
use crate::identify::model::{Effect, Model};
use crate::identify::predict::Horizon;
use crate::io::data::Record;

/// What the trials show beside the verdict's effect `first`: each other effect's statistic
/// `D` measured on the trials against the model with `first` (its trial version, θ frozen as
/// in the first stage), from the first stage's reference versions (`versions[i]` for
/// `grids[i]`, found against `base`: the reference lacks `first`), judged against the first
/// stage's null replicates (`nulls[i]` for `grids[i]`: the null of an effect's statistic
/// depends on its grid and the records, not on what else the model carries). Current and
/// wind share speed over ground's evidence, so beside either the other is not a second
/// effect. The others are ranked by the first stage's rule ([`rank`]); the second effect is
/// the first of them that [`named_second`] accepts, its held-out gain measured on `held`
/// (estimation part, held-out part); `None` without one. When that is current or wind and
/// the other is significant too, the one that predicts the held-out records better at both
/// horizons ([`outpredicts`]: the ranking rule's second clause) is named — unless the records
/// log the anemometer, whose true wind decides between them as in the first stage
/// ([`super::rule::outpredicted`]). Beside the effect, why it is named, in words (its
/// channel, its held-out gain, or the second clause).
#[allow(clippy::too_many_arguments)]
pub(super) fn second_effect(
    base: &Model,
    first: &Effect,
    versions: &[Version],
    est: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    nulls: &[Nulls],
    level: f64,
    has_ref: bool,
    cfg: &DiagnoseConfig,
    ch: &Channels,
    held: (&[Record], &[Record]),
) -> Option<(Evidence, String)> {
    let k1 = first.kind();
    let with_first = &base.clone().with_effect(*first);
    let keep: Vec<usize> = (0..grids.len())
        .filter(|&i| grids[i].0 != k1 && !current_and_wind(k1, grids[i].0))
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
    // the held-out fits of the effect picked, when its gain named it (kept for the
    // partner clause below)
    let mut pick_fits = None;
    let (pick, named) = ev.iter().enumerate().find_map(|(i, e)| {
        pick_fits = None;
        named_second(e, level, || {
            let (g, fits) = frozen_gain(with_first, e, &est_set, held.1, &before, cfg.parallel);
            pick_fits = Some(fits);
            g
        })
        .map(|n| (i, n))
    })?;
    // current or wind: the ranking rule's second clause between the two, as in the first
    // stage — the one that predicts the held-out records better at both horizons is named;
    // an anemometer decides between them instead
    let partner = ev.iter().position(|e| {
        ch.anemometer.is_none() && current_and_wind(ev[pick].kind, e.kind) && e.p < level
    });
    if let Some(j) = partner {
        let held_out = |e: &Evidence| {
            let (_, fits) = frozen_gain(with_first, e, &est_set, held.1, &before, cfg.parallel);
            compared_gains(&fits, &before)
        };
        let gp = match &pick_fits {
            Some(fits) => compared_gains(fits, &before),
            None => held_out(&ev[pick]),
        };
        let gj = held_out(&ev[j]);
        // current and wind: not gear dynamics
        if outpredicts(gj, gp, false) {
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
    Some((ev.swap_remove(pick), named.to_string()))
}

/// Why a second effect is named ([`named_second`]); its `Display` is the explanation's words.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Named {
    /// Its own channel shows it.
    Channel,
    /// It improves held-out prediction by this many pp (≥ [`NO_GAIN_PP`]).
    Gain(f64),
}

impl core::fmt::Display for Named {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Named::Channel => f.write_str("its own channel shows it"),
            Named::Gain(g) => write!(f, "held-out fit gain {g:+.2} pp"),
        }
    }
}

/// Is `e` named as the second effect of a ranked verdict, and why? It must be significant
/// at `level`, and either its own channel must show it (`channel_material`: a gyro offset
/// from the heading, a current or wind from speed over ground, course over ground, the
/// anemometer — the channels that carry them, whatever the yaw rate gains) or it must
/// improve held-out prediction (`held_out_gain`, pp, computed only when needed) by
/// [`NO_GAIN_PP`] or more, the level below which the ranking rule counts an effect as not
/// improving prediction. What a second effect adds beside the first is judged on
/// prediction, not on the statistic alone: θ frozen leaves part of the first effect in the
/// errors, which can read as its neighbour (a saturation's remainder as an asymmetry)
/// without improving prediction.
pub(super) fn named_second(
    e: &Evidence,
    level: f64,
    held_out_gain: impl FnOnce() -> f64,
) -> Option<Named> {
    if e.p >= level {
        return None;
    }
    if e.channel_material {
        return Some(Named::Channel);
    }
    let g = held_out_gain();
    (g >= NO_GAIN_PP).then_some(Named::Gain(g))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::tests::{evidence, hidden_records, identify, records};
    use crate::diagnose::{diagnose, Caveat};
    use crate::sim::{Ship, SimEffect};

    #[test]
    fn a_current_named_second_from_the_ground_track_carries_its_own_caveat() {
        // the built-in ship, a dead time and a current hidden, no anemometer: the dead
        // time first, then the current, seen on the ground track alone — so the caveat
        // says a wind's leeway would look the same, and the one on how weak a current
        // speed over ground can show (for verdicts without one) is not given
        let refs = records(None, &[900, 901, 902]);
        let model = identify(&refs);
        let cfg = DiagnoseConfig {
            seed: 1,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let hidden = vec![
            SimEffect::hidden(EffectKind::DeadTime, 1.0),
            SimEffect::hidden(EffectKind::Current, 1.0),
        ];
        let two = hidden_records(&Ship::default_lng(), hidden, &[100, 101, 102]);
        let d = diagnose(&model, &refs, &two, &[], &cfg).unwrap();
        assert_eq!(d.verdict, "dead-time", "{}", d.explanation);
        assert_eq!(d.then.as_deref(), Some("current"), "{}", d.explanation);
        let leeway = d.caveats.iter().find_map(|c| match c {
            Caveat::CurrentOrLeeway { p_moment, .. } => Some(*p_moment),
            _ => None,
        });
        // the moment's p (0.14 here) is what the test applied: absent at α
        assert!(leeway.is_some_and(|p| p >= cfg.alpha), "{:?}", d.caveats);
        assert!(
            !d.caveats
                .iter()
                .any(|c| matches!(c, Caveat::CurrentResolution { .. })),
            "{:?}",
            d.caveats
        );
        assert!(d
            .explanation
            .contains("cannot tell a current from the leeway"));
    }

    #[test]
    fn a_second_effect_is_named_by_its_channel_or_by_what_it_wins_back() {
        let level = 1e-3;
        // a wind the speed over ground and the yaw moment's harmonics show (lng, a slew
        // limit and wind hidden, seed 1: p 6e-14, +0.20 pp held out): its channels name it
        let wind = evidence(EffectKind::Wind, 6e-14, 5e-7, true);
        let named = named_second(&wind, level, || unreachable!("its channels name it"));
        assert_eq!(named, Some(Named::Channel));
        assert_eq!(named.unwrap().to_string(), "its own channel shows it");
        // a damping beside a saturation (Mariner, seed 1: +0.69 pp at 10 steps, θ frozen)
        let nld = evidence(EffectKind::NonlinearDamping, 3e-12, 3e-12, false);
        let named = named_second(&nld, level, || 0.69);
        assert_eq!(named, Some(Named::Gain(0.69)));
        assert_eq!(named.unwrap().to_string(), "held-out fit gain +0.69 pp");
        let at = named_second(&nld, level, || NO_GAIN_PP);
        assert_eq!(at, Some(Named::Gain(NO_GAIN_PP)));
        // a remainder of the first effect that wins nothing back is not a second effect,
        // nor one whose gain could not be measured
        assert_eq!(named_second(&nld, level, || 0.49), None);
        assert_eq!(named_second(&nld, level, || f64::NEG_INFINITY), None);
        assert_eq!(named_second(&nld, level, || f64::NAN), None);
        // nor is an effect that is not significant, whatever it gains: its held-out
        // gain is not even computed
        let weak = evidence(EffectKind::NonlinearDamping, 2e-3, 2e-3, true);
        let none = named_second(&weak, level, || unreachable!("not computed"));
        assert_eq!(none, None);
    }
}
