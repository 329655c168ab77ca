//! What the trials' commands alone say the records cannot tell: an angle limit from a dead
//! band, or an asymmetry from a steady moment, on commands of one magnitude; a slew limit
//! from a dead time on changes of one size; and the hull's own nonlinearity on other
//! commands than the reference's.

use std::collections::{BTreeMap, BTreeSet};

use yawcast_shared::model::EffectKind;

use super::caveat::Caveat;
use crate::io::data::Record;

/// Share of the commanded samples at one magnitude from which [`clip_or_dead_band`] says
/// the records cannot tell an angle limit from a dead band: nine in ten. The two differ
/// on every command of another magnitude (by up to the dead band's width), so a tenth of
/// the samples at other magnitudes — three minutes of a half-hour record — tells them.
const ONE_MAGNITUDE_SHARE: f64 = 0.9;

/// The caveat for an angle limit or a dead band named on commands of one magnitude
/// ([`Caveat::ClipOrDeadBand`]): `named`, the verdict's effect and its second; `est`, the
/// trials; `damping`, the held-out gains (10 steps, simulation) of a significant nonlinear
/// damping that improves prediction, when one is. The magnitude is the commonest |δ| to
/// 0.1°, the share is over the samples whose command is not 0. The damping is said only
/// where it is not named itself.
pub(super) fn clip_or_dead_band(
    named: &[EffectKind],
    est: &[Record],
    damping: Option<[f64; 2]>,
) -> Option<Caveat> {
    let (magnitude_deg, share) =
        names_one_magnitude(named, EffectKind::Saturation, EffectKind::DeadBand, est)?;
    Some(Caveat::ClipOrDeadBand {
        magnitude_deg,
        share,
        damping_gains_pp: damping.filter(|_| !named.contains(&EffectKind::NonlinearDamping)),
    })
}

/// The caveat for a port/starboard asymmetry or a steady moment named on commands of one
/// magnitude ([`Caveat::AsymmetryOrBias`]): on ±A an asymmetry β (gain on max(δ, 0)) is a
/// steady moment of β·A/2 and a rudder effectiveness changed by β/2, and only that change
/// tells it from a steady moment. Given on the share of [`clip_or_dead_band`].
pub(super) fn asymmetry_or_bias(named: &[EffectKind], est: &[Record]) -> Option<Caveat> {
    let (magnitude_deg, share) =
        names_one_magnitude(named, EffectKind::Asymmetry, EffectKind::Bias, est)?;
    Some(Caveat::AsymmetryOrBias {
        magnitude_deg,
        share,
    })
}

/// When `a` or `b` is among `named`: the commonest |δ| of the trials' commanded samples and
/// its share ([`commonest`]), when that share is [`ONE_MAGNITUDE_SHARE`] or more.
fn names_one_magnitude(
    named: &[EffectKind],
    a: EffectKind,
    b: EffectKind,
    est: &[Record],
) -> Option<(f64, f64)> {
    if !named.iter().any(|k| *k == a || *k == b) {
        return None;
    }
    commonest(est.iter().flat_map(|r| r.u.iter().copied()))
        .filter(|(_, share)| *share >= ONE_MAGNITUDE_SHARE)
}

/// Relative width within which magnitudes (or changes) count as one: 5 %. A logged rudder
/// angle differs by a few tenths of a degree between the two sides of a zig-zag (the Esso
/// Osaka model's ±20°: 19.5° to starboard, 20.2° to port), where a PRBS's magnitudes lie
/// 5° or more apart.
const SAME_WITHIN: f64 = 0.05;

/// The commonest |v| to 0.1° among `values` (those that round to 0, and non-finite ones,
/// not counted) and the share of the counted within [`SAME_WITHIN`] of it.
fn commonest(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let counted: Vec<f64> = values
        .map(f64::abs)
        .filter(|m| m.is_finite() && (m * 10.0).round() > 0.0)
        .collect();
    let mut bins: BTreeMap<i64, usize> = BTreeMap::new();
    for m in &counted {
        *bins.entry((m * 10.0).round() as i64).or_default() += 1;
    }
    let (&bin, _) = bins.iter().max_by_key(|(b, c)| (**c, -**b))?;
    let centre = bin as f64 / 10.0;
    let within = counted
        .iter()
        .filter(|m| (*m - centre).abs() <= SAME_WITHIN * centre)
        .count();
    Some((centre, within as f64 / counted.len() as f64))
}

/// Share of the command's changes at one size from which [`slew_or_dead_time`] says the
/// records may not tell a slew limit from a dead time: a half. A basin's zig-zag holds as
/// few as three swings between its start from midships and its return there, each half a
/// swing (the Esso Osaka model's ±20°: three changes of 39.7° in five); a PRBS of 5–20°
/// puts at most a third of its changes at one size (the three test worlds).
const ONE_STEP_SHARE: f64 = 0.5;

/// The command's changes |Δδ| between consecutive samples of `recs` (deg), the finite ones.
fn changes(recs: &[Record]) -> impl Iterator<Item = f64> + '_ {
    recs.iter()
        .flat_map(|r| r.u.windows(2).map(|w| (w[1] - w[0]).abs()))
        .filter(|d| d.is_finite())
}

/// The caveat for a slew limit or a dead time named on command changes of one size
/// ([`Caveat::SlewOrDeadTime`]): `named`, the verdict's effect and its second; `est`, the
/// trials. The size is the commonest |Δδ| between samples ([`commonest`]); the changes
/// counted are those of a tenth of the largest or more — a logged angle's jitter of a
/// degree between a zig-zag's 40° swings is not a command.
pub(super) fn slew_or_dead_time(named: &[EffectKind], est: &[Record]) -> Option<Caveat> {
    if !named
        .iter()
        .any(|k| matches!(k, EffectKind::RateLimit | EffectKind::DeadTime))
    {
        return None;
    }
    let changes: Vec<f64> = changes(est).collect();
    let largest = changes.iter().copied().fold(0.0, f64::max);
    let commands = changes.into_iter().filter(|d| *d >= 0.1 * largest);
    let (step_deg, share) = commonest(commands).filter(|(_, share)| *share >= ONE_STEP_SHARE)?;
    Some(Caveat::SlewOrDeadTime { step_deg, share })
}

/// Distance between the trials' and the reference's commands from which [`other_manoeuvre`]
/// says they were sailed with other manoeuvres: half the trials' command magnitudes where
/// the reference's are not. Two PRBS sets of other switching times lie 0.06–0.16 apart on
/// the three test worlds (189 cases each), a zig-zag of ±20° and a PRBS of 5–20° 0.75–0.77.
const OTHER_MANOEUVRE: f64 = 0.5;

/// The caveat for trials sailed with other commands than the reference's
/// ([`Caveat::OtherManoeuvre`]): the total-variation distance between the two sets'
/// distributions of |δ| in 1° bins, given from [`OTHER_MANOEUVRE`] on (with no `hull`:
/// the driver adds what the nulls simulate); `None` without a reference.
pub(super) fn other_manoeuvre(est: &[Record], reference: &[Record]) -> Option<Caveat> {
    let hist = |recs: &[Record]| -> (BTreeMap<i64, f64>, f64) {
        let mut h: BTreeMap<i64, f64> = BTreeMap::new();
        let mut n = 0.0;
        for u in recs.iter().flat_map(|r| r.u.iter()) {
            if u.is_finite() {
                *h.entry(u.abs().round() as i64).or_default() += 1.0;
                n += 1.0;
            }
        }
        (h, n)
    };
    let ((ht, nt), (hr, nr)) = (hist(est), hist(reference));
    if nt == 0.0 || nr == 0.0 {
        return None;
    }
    let bins: BTreeSet<i64> = ht.keys().chain(hr.keys()).copied().collect();
    let distance = 0.5
        * bins
            .iter()
            .map(|b| {
                let f = |h: &BTreeMap<i64, f64>, n: f64| h.get(b).copied().unwrap_or(0.0) / n;
                (f(&ht, nt) - f(&hr, nr)).abs()
            })
            .sum::<f64>();
    (distance >= OTHER_MANOEUVRE).then_some(Caveat::OtherManoeuvre {
        distance,
        hull: Vec::new(),
    })
}

/// Ratio of one set's largest one-sample command change to the other's from which
/// [`command_steps`] says that set's commands step where the other's inputs never do. Commands sailed by `simulate` step by 40° (PRBS, ±20° zig-zags) or 20° (the
/// autopilot) on every world, so any two kinds lie within 2 of each other; a rudder angle
/// logged by a steering gear of 16 °/s at 0.15 s moves 2.45° a sample (HSVA's KVLCC2
/// model), 4 to 29 times less than the steps of its zig-zags' commands of ±5–35°.
pub(super) const STEP_RATIO: f64 = 3.0;

/// The caveat for one set whose commands step where the other's inputs never move so fast
/// ([`Caveat::CommandSteps`]): the largest change of δ over one sample of each set, given
/// where one is [`STEP_RATIO`] times the other's or more (`ts`: the sample time, s); `None`
/// without a reference or where either set's inputs never move.
pub(super) fn command_steps(est: &[Record], reference: &[Record], ts: f64) -> Option<Caveat> {
    let largest = |recs: &[Record]| changes(recs).fold(0.0, f64::max);
    let (trial_step_deg, reference_step_deg) = (largest(est), largest(reference));
    let slower = trial_step_deg.min(reference_step_deg);
    (slower > 0.0 && trial_step_deg.max(reference_step_deg) >= STEP_RATIO * slower).then_some(
        Caveat::CommandSteps {
            trial_step_deg,
            reference_step_deg,
            slew_degps: slower / ts,
        },
    )
}

/// The words of [`Caveat::CommandSteps`]: each set's largest change over one sample (deg)
/// and the slower one's over the sample time (deg/s).
pub(super) fn steps_words(trial_step_deg: f64, reference_step_deg: f64, slew_degps: f64) -> String {
    let (fast, slow, logs, fast_step, slow_step) = if trial_step_deg > reference_step_deg {
        (
            "trials'",
            "reference's",
            "the reference logs the rudder/pod angle and the trials the command",
            trial_step_deg,
            reference_step_deg,
        )
    } else {
        (
            "reference's",
            "trials'",
            "the trials log the rudder/pod angle and the reference the command",
            reference_step_deg,
            trial_step_deg,
        )
    };
    let judged = if trial_step_deg > reference_step_deg {
        " The reference shows how the ship answers inputs no faster, not steps: a \
         slew limit is judged against the reference's own spread, the bootstrap's \
         replicates measuring how the model answers steps it never saw."
    } else {
        " The model identified on the reference carries that gear in its dynamics \
         and meets it again in the trials' inputs."
    };
    format!(
        "The {fast} commands change by up to {fast_step:.1}° in one sample, the \
         {slow} inputs by {slow_step:.2}° at most ({slew_degps:.1} °/s): where \
         {logs}, a steering gear slewing at most about {slew_degps:.1} °/s lies between \
         them.{judged} Log the same signal in both sets (`simulate --log-angle` \
         logs a simulator's gear angle)."
    )
}

/// Whether `c` is a [`Caveat::CommandSteps`] whose trials step (a slew limit is then judged
/// by [`slew_on_spread`]).
pub(super) fn trials_step(c: Option<&Caveat>) -> bool {
    matches!(c, Some(Caveat::CommandSteps { trial_step_deg, reference_step_deg, .. })
        if trial_step_deg > reference_step_deg)
}

/// A slew limit judged where the trials' commands step and the reference's inputs never do
/// ([`command_steps`]): against the reference's own spread (its parts measured against each
/// other) alone, where that gives the smaller p. The bootstrap's replicates simulate the
/// model on the trials' steps and re-identify it on the reference's inputs, which never
/// show how the ship answers a step; so they measure that ignorance — on HSVA's KVLCC2
/// model, a slew limit reached D = 28 199 in one replicate of 40, and 0 in 22 — and not the
/// steering gear, which the reference's inputs show by never moving faster than it.
pub(super) fn slew_on_spread(e: &mut super::verdict::Evidence, nulls: &super::null::Nulls) {
    let Some(spread) = nulls.spread.as_deref().map(super::null::Null::fit) else {
        return;
    };
    let p = spread.p(e.statistic);
    if p < e.p_yaw {
        e.words.push_str(&format!(
            " (p {} against the reference's own spread alone: the trials' commands step where \
             the reference's inputs never move so fast, so the bootstrap, {}, measures how a \
             model identified on the reference answers a step it never saw)",
            super::verdict::fmt_p(p),
            super::verdict::fmt_p(e.p_yaw),
        ));
        e.null = spread;
        e.score = spread.excess(e.statistic);
        e.p = p;
        e.p_yaw = p;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_that_never_steps_judges_a_slew_limit_on_its_own_spread() {
        let rec = |u: Vec<f64>| Record::from_uy("r", 0.125, u.clone(), vec![0.0; u.len()]);
        // ±20° zig-zag commands, and the rudder angle a gear of 2.5° a sample makes of them
        let cmd: Vec<f64> = (0..400)
            .map(|i| if (i / 50) % 2 == 0 { 20.0 } else { -20.0 })
            .collect();
        let mut angle = vec![0.0];
        for c in &cmd[1..] {
            let a: f64 = angle[angle.len() - 1];
            angle.push(a + (c - a).clamp(-2.5, 2.5));
        }
        let c = command_steps(&[rec(cmd.clone())], &[rec(angle.clone())], 0.125).unwrap();
        let Caveat::CommandSteps {
            trial_step_deg,
            reference_step_deg,
            slew_degps,
        } = c
        else {
            panic!("{c:?}");
        };
        assert_eq!((trial_step_deg, reference_step_deg), (40.0, 2.5));
        assert_eq!(slew_degps, 20.0);
        assert!(
            c.explain().contains("up to 40.0° in one sample"),
            "{}",
            c.explain()
        );
        assert!(
            c.explain().contains("2.50° at most (20.0 °/s)"),
            "{}",
            c.explain()
        );
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["caveat"], "command-steps");
        assert_eq!(json["reference_step_deg"], 2.5);
        assert!(trials_step(Some(&c)));
        // steps in the reference, the angle in the trials: the same figures the other way
        // round, and no slew limit judged on the spread
        let r = command_steps(&[rec(angle.clone())], &[rec(cmd.clone())], 0.125).unwrap();
        assert!(r
            .explain()
            .starts_with("The reference's commands change by up to 40.0°"));
        assert!(r
            .explain()
            .contains("where the trials log the rudder/pod angle"));
        assert!(!trials_step(Some(&r)) && !trials_step(None));
        // commands against commands: none
        let prbs: Vec<f64> = (0..400).map(|i| [5.0, -15.0, 20.0][(i / 7) % 3]).collect();
        assert!(command_steps(&[rec(cmd.clone())], &[rec(prbs)], 0.125).is_none());
        assert!(command_steps(&[rec(cmd.clone())], &[], 0.125).is_none());
        // a set that never moves: nothing to compare with
        assert!(command_steps(&[rec(cmd.clone())], &[rec(vec![5.0; 400])], 0.125).is_none());
        assert!(command_steps(&[rec(vec![5.0; 400])], &[rec(cmd)], 0.125).is_none());

        // a slew limit whose bootstrap is wide (the model answering steps it never saw)
        // and the reference's parts alike: judged on the spread, and the words say why
        let d = 30_000.0;
        let mut e = crate::diagnose::tests::evidence(EffectKind::RateLimit, 5.6e-3, 5.6e-3, false);
        e.statistic = d;
        let boot: Vec<f64> = (0..40)
            .map(|i| {
                if i % 2 == 0 {
                    0.0
                } else {
                    3000.0 * (i % 7) as f64
                }
            })
            .collect();
        let nulls = super::super::null::Nulls {
            boot: boot.clone(),
            spread: Some(vec![81.0, 0.0, 0.0, 0.0]),
        };
        slew_on_spread(&mut e, &nulls);
        let spread = super::super::null::Null::fit(&[81.0, 0.0, 0.0, 0.0]);
        assert_eq!(e.p.to_bits(), spread.p(d).to_bits());
        assert!(e.p < 1e-12, "{}", e.p);
        assert_eq!(
            (e.p_yaw.to_bits(), e.score.to_bits()),
            (e.p.to_bits(), spread.excess(d).to_bits())
        );
        assert!(
            e.words.contains("against the reference's own spread alone"),
            "{}",
            e.words
        );
        // where the spread gives the larger p, nothing changes
        let mut e2 = crate::diagnose::tests::evidence(EffectKind::RateLimit, 1e-200, 1e-200, false);
        e2.statistic = d;
        slew_on_spread(&mut e2, &nulls);
        assert_eq!((e2.p, e2.words.as_str()), (1e-200, ""));
        // no spread (an effect with a free gain, or a reference too short to cut): none
        let mut e3 = crate::diagnose::tests::evidence(EffectKind::RateLimit, 5.6e-3, 5.6e-3, false);
        e3.statistic = d;
        slew_on_spread(&mut e3, &super::super::null::Nulls { boot, spread: None });
        assert_eq!(e3.p, 5.6e-3);
    }

    #[test]
    fn the_commands_say_what_the_records_cannot_tell() {
        let rec = |u: Vec<f64>| Record::from_uy("r", 1.0, u.clone(), vec![0.0; u.len()]);
        // a zig-zag: ±20° throughout, a straight start at 0° not counted
        let zz: Vec<f64> = (0..300)
            .map(|i| match i {
                0..10 => 0.0,
                _ if (i / 40) % 2 == 0 => 20.0,
                _ => -20.0,
            })
            .collect();
        let c = clip_or_dead_band(&[EffectKind::DeadBand], &[rec(zz.clone())], None).unwrap();
        assert_eq!(
            c,
            Caveat::ClipOrDeadBand {
                magnitude_deg: 20.0,
                share: 1.0,
                damping_gains_pp: None,
            }
        );
        assert!(c.explain().contains("±20.0° in 100 %"), "{}", c.explain());
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["caveat"], "clip-or-dead-band");
        assert_eq!(json["magnitude_deg"], 20.0);
        // a significant damping that predicts better beside it: said, with its gains
        let c = clip_or_dead_band(
            &[EffectKind::DeadBand],
            &[rec(zz.clone())],
            Some([12.3, 29.9]),
        )
        .unwrap();
        assert!(
            c.explain().contains("nonlinear damping is significant too (held-out +12.3 pp at 10 steps, +29.9 in simulation)"),
            "{}",
            c.explain()
        );
        assert_eq!(
            serde_json::to_value(&c).unwrap()["damping_gains_pp"],
            serde_json::json!([12.3, 29.9])
        );
        // … but not where the damping is named itself, nor in the JSON without one
        let k = [EffectKind::NonlinearDamping, EffectKind::DeadBand];
        let c = clip_or_dead_band(&k, &[rec(zz.clone())], Some([12.3, 29.9])).unwrap();
        assert!(!c.explain().contains("damping"), "{}", c.explain());
        assert!(serde_json::to_value(&c)
            .unwrap()
            .get("damping_gains_pp")
            .is_none());
        // named second, the same
        let k = [EffectKind::Current, EffectKind::Saturation];
        assert!(clip_or_dead_band(&k, &[rec(zz.clone())], None).is_some());
        // neither named: none
        assert!(clip_or_dead_band(&[EffectKind::DeadTime], &[rec(zz.clone())], None).is_none());
        // a PRBS of four magnitudes: a quarter at each, the records tell them apart
        let prbs: Vec<f64> = (0..392)
            .map(|i| [5.0, -10.0, 15.0, -20.0][(i / 7) % 4])
            .collect();
        assert!(clip_or_dead_band(&[EffectKind::DeadBand], &[rec(prbs.clone())], None).is_none());
        // 85 % at one magnitude: below the share, no caveat; 90 %: the caveat
        let mix =
            |k: usize| -> Vec<f64> { (0..100).map(|i| if i < k { 20.0 } else { 7.5 }).collect() };
        assert!(clip_or_dead_band(&[EffectKind::DeadBand], &[rec(mix(85))], None).is_none());
        let c = clip_or_dead_band(&[EffectKind::DeadBand], &[rec(mix(90))], None).unwrap();
        assert_eq!(
            c,
            Caveat::ClipOrDeadBand {
                magnitude_deg: 20.0,
                share: 0.9,
                damping_gains_pp: None,
            }
        );
        // an asymmetry and a steady moment on the same commands
        let c = asymmetry_or_bias(&[EffectKind::Bias], &[rec(zz.clone())]).unwrap();
        assert_eq!(
            c,
            Caveat::AsymmetryOrBias {
                magnitude_deg: 20.0,
                share: 1.0
            }
        );
        assert!(
            c.explain().contains("steady moment of β·20.0°/2"),
            "{}",
            c.explain()
        );
        assert_eq!(
            serde_json::to_value(&c).unwrap()["caveat"],
            "asymmetry-or-bias"
        );
        let k = [EffectKind::RateLimit, EffectKind::Asymmetry];
        assert!(asymmetry_or_bias(&k, &[rec(zz.clone())]).is_some());
        assert!(asymmetry_or_bias(&[EffectKind::DeadBand], &[rec(zz.clone())]).is_none());
        assert!(asymmetry_or_bias(&[EffectKind::Bias], &[rec(prbs.clone())]).is_none());
        assert!(asymmetry_or_bias(&[EffectKind::Bias], &[rec(mix(85))]).is_none());
        // a slew limit and a dead time: the zig-zag changes by 20° once (from midships) and
        // by 40° seven times after
        let c = slew_or_dead_time(&[EffectKind::RateLimit], &[rec(zz.clone())]).unwrap();
        assert_eq!(
            c,
            Caveat::SlewOrDeadTime {
                step_deg: 40.0,
                share: 7.0 / 8.0
            }
        );
        assert!(
            c.explain().contains("(40.0° in 88 % of the changes)"),
            "{}",
            c.explain()
        );
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["caveat"], "slew-or-dead-time");
        assert_eq!(json["step_deg"], 40.0);
        let k = [EffectKind::Bias, EffectKind::DeadTime];
        assert!(slew_or_dead_time(&k, &[rec(zz.clone())]).is_some());
        assert!(slew_or_dead_time(&[EffectKind::DeadBand], &[rec(zz.clone())]).is_none());
        // the PRBS changes by 15°, 25° and 35°: none holds four in five
        assert!(slew_or_dead_time(&[EffectKind::DeadTime], &[rec(prbs.clone())]).is_none());
        // a basin's zig-zag: from midships, three swings, back to midships — three changes
        // of 40° in five, the caveat; a PRBS-like mix of 20°, 40° and 10°: 40 %, none
        let basin = [0.0, 20.0, -20.0, 20.0, -20.0, 0.0];
        let c = slew_or_dead_time(&[EffectKind::DeadTime], &[rec(basin.to_vec())]).unwrap();
        assert_eq!(
            c,
            Caveat::SlewOrDeadTime {
                step_deg: 40.0,
                share: 0.6
            }
        );
        let mixed = vec![0.0, 20.0, -20.0, 20.0, 0.0, 10.0];
        assert!(slew_or_dead_time(&[EffectKind::DeadTime], &[rec(mixed)]).is_none());
        // a logged angle (the Esso Osaka model's ±20° zig-zag): 19.5° to one side, 20.2° to
        // the other, a degree of jitter between the 40° swings — one magnitude, one size
        let logged: Vec<f64> = (0..200)
            .map(|i| {
                let side = if (i / 25) % 2 == 0 { 19.5 } else { -20.2 };
                side + if i % 5 == 0 { 0.6 } else { 0.0 }
            })
            .collect();
        let c = clip_or_dead_band(&[EffectKind::DeadBand], &[rec(logged.clone())], None).unwrap();
        let Caveat::ClipOrDeadBand {
            magnitude_deg,
            share,
            ..
        } = c
        else {
            panic!("{c:?}")
        };
        assert_eq!((magnitude_deg, share), (19.5, 1.0));
        let c = slew_or_dead_time(&[EffectKind::DeadTime], &[rec(logged)]).unwrap();
        let Caveat::SlewOrDeadTime { step_deg, share } = c else {
            panic!("{c:?}")
        };
        assert!(step_deg > 39.0 && share == 1.0, "{c:?}");
        // the measured zig-zag itself (tests/data/real): the Esso Osaka model's second ±20°
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/real/esso_osaka/zz20_n12_b.csv");
        let esso = crate::io::data::read_csv(&path).unwrap();
        let c = clip_or_dead_band(&[EffectKind::Saturation], std::slice::from_ref(&esso), None);
        let Some(Caveat::ClipOrDeadBand {
            magnitude_deg,
            share,
            ..
        }) = c
        else {
            panic!("{c:?}")
        };
        assert_eq!(magnitude_deg, 19.5);
        assert!(share > 0.95, "{share}");
        let c = slew_or_dead_time(&[EffectKind::DeadTime], std::slice::from_ref(&esso));
        assert_eq!(
            c,
            Some(Caveat::SlewOrDeadTime {
                step_deg: 39.7,
                share: 0.6
            })
        );
        // the zig-zag against the PRBS: three quarters of its magnitudes (20°, 290 of 300
        // samples, against a quarter of the PRBS's) lie where the PRBS's do not
        let c = other_manoeuvre(&[rec(zz.clone())], &[rec(prbs.clone())]).unwrap();
        let Caveat::OtherManoeuvre { distance, .. } = c else {
            panic!("{c:?}")
        };
        let want = 0.5 * ((290.0 / 300.0 - 0.25) + 10.0 / 300.0 + 3.0 * 0.25);
        assert!((distance - want).abs() < 1e-12, "{distance} vs {want}");
        assert!(c.explain().contains("(75 % of"), "{}", c.explain());
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["caveat"], "other-manoeuvre");
        assert_eq!(json["hull"], serde_json::json!([]));
        assert!(
            c.explain().contains("show no hull physics"),
            "{}",
            c.explain()
        );
        // with the hull physics the nulls simulated, named in the field and the words
        let with = Caveat::OtherManoeuvre {
            distance,
            hull: vec!["extra yaw damping".into()],
        };
        assert_eq!(
            serde_json::to_value(&with).unwrap()["hull"][0],
            "extra yaw damping"
        );
        assert!(
            with.explain()
                .contains("records show of their own (extra yaw damping, re-identified"),
            "{}",
            with.explain()
        );
        // alike: none; no reference: none
        assert!(other_manoeuvre(&[rec(zz.clone())], &[rec(zz.clone())]).is_none());
        assert!(other_manoeuvre(&[rec(prbs.clone())], &[rec(mix(25))]).is_some());
        assert!(other_manoeuvre(&[rec(zz)], &[]).is_none());
    }
}
