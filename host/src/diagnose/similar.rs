//! The reference as its hull would have sailed it at the trials' speed: records re-timed by
//! similarity, the model re-identified on them, scored on the trials.
//!
//! A hull's manoeuvres at another speed through the water are, to first order, the same
//! manoeuvres in distance sailed: the manoeuvring derivatives made dimensionless by the
//! length and the speed hardly change with speed (Nomoto's `K' = K·L/U`, `T' = T·U/L`), so at
//! `s` times the speed the same commands give the same headings `1/s` times sooner, and yaw
//! rates `s` times larger. A current along the course changes the speed over the ground and
//! not how the hull answers the helm. So where the trials ran at another speed over the
//! ground than the reference ([`Caveat::OtherSpeed`]) and their records cannot tell a
//! current from it, the model re-identified on the reference re-timed to the trials' speed
//! tells them apart: it predicts the trials better where the speed through the water
//! differs, worse where a current carried them ([`Caveat::SpeedSimilar`]).
//!
//! It does not stand in for a reference sailed at the trials' speed: the re-timed records
//! scale the steering gear's slew rate and dead time with the hull (a real gear keeps them),
//! so the re-timed model also mimics a slower or faster gear. Measured against it, a hidden
//! slew limit of the container ship at 73 % of its speed lost most of its statistic
//! (docs/method.md), so the statistics stay measured against the reference as given.

use super::caveat::Caveat;
use super::compare::mean_fit;
use super::reference::refit_config;
use super::rule::GAIN_PP;
use crate::identify::model::Model;
use crate::identify::pem;
use crate::identify::predict::Horizon;
use crate::io::data::Record;

/// Speed ratios (trials over reference) outside which the reference is not re-timed: a
/// hull's manoeuvres are similar in distance sailed over a speed range, not at any speed.
const RATIO_RANGE: (f64, f64) = (0.25, 4.0);

/// `rec` as its hull would have sailed it at `s` times the speed, sampled at the record's
/// own sample time: at time `t` the re-timed record holds the original's at `s·t` (the
/// command held from the sample before, the rest interpolated linearly, angles the short
/// way round),
/// its yaw rate, speed over ground and apparent wind speed times `s`. `None` when `s` is not
/// finite and positive, or the record would keep fewer than two samples.
pub(super) fn retime(rec: &Record, s: f64) -> Option<Record> {
    let n = rec.len();
    if !(s.is_finite() && s > 0.0) || n < 2 {
        return None;
    }
    let m = ((n - 1) as f64 / s).floor() as usize + 1;
    if m < 2 {
        return None;
    }
    // original fractional index of each new sample: its sample before and the weight
    let at: Vec<(usize, f64)> = (0..m)
        .map(|j| {
            let x = (j as f64 * s).min((n - 1) as f64);
            let i = (x.floor() as usize).min(n - 2);
            (i, x - i as f64)
        })
        .collect();
    let lin = |v: &[f64], k: f64| -> Vec<f64> {
        at.iter()
            .map(|&(i, w)| k * (v[i] + w * (v[i + 1] - v[i])))
            .collect()
    };
    // an angle (deg) interpolated the short way round; NaN where a neighbour is missing
    let ang = |v: &[f64], wrap: fn(f64) -> f64| -> Vec<f64> {
        at.iter()
            .map(|&(i, w)| {
                let d = (v[i + 1] - v[i] + 180.0).rem_euclid(360.0) - 180.0;
                wrap(v[i] + w * d)
            })
            .collect()
    };
    let compass = |a: f64| a.rem_euclid(360.0);
    let signed = |a: f64| (a + 180.0).rem_euclid(360.0) - 180.0;
    let t0 = rec.t.first().copied().unwrap_or(0.0);
    Some(Record {
        name: rec.name.clone(),
        ts: rec.ts,
        t: (0..m).map(|j| t0 + j as f64 * rec.ts).collect(),
        u: at
            .iter()
            .map(|&(i, w)| rec.u[if w >= 1.0 { i + 1 } else { i }])
            .collect(),
        y: lin(&rec.y, s),
        psi: rec.psi.as_deref().map(|v| ang(v, compass)),
        speed: rec.speed.as_deref().map(|v| lin(v, s)),
        wind_speed: rec.wind_speed.as_deref().map(|v| lin(v, s)),
        wind_angle: rec.wind_angle.as_deref().map(|v| ang(v, signed)),
        cog: rec.cog.as_deref().map(|v| ang(v, compass)),
    })
}

/// [`Caveat::SpeedSimilar`]: the reference re-timed to the trials' speed ([`retime`] by
/// `ratio`, the trials' speed over the reference's), `model` re-identified on it (its
/// structure kept), and whether that predicts the trials `est` 10 steps ahead by [`GAIN_PP`]
/// or more better than `model` does. `None` where the ratio is outside [`RATIO_RANGE`], a
/// record cannot be re-timed or the identification fails.
pub(super) fn at_trials_speed(
    ratio: f64,
    model: &Model,
    reference: &[Record],
    est: &[Record],
) -> Option<Caveat> {
    if !(RATIO_RANGE.0..=RATIO_RANGE.1).contains(&ratio) || reference.is_empty() {
        return None;
    }
    let retimed: Vec<Record> = reference
        .iter()
        .map(|r| retime(r, ratio))
        .collect::<Option<_>>()?;
    let similar = pem::identify_from(&retimed, model, &refit_config(model))
        .ok()?
        .model;
    let fit_10 = |m: &Model| mean_fit(m, est, &[Horizon::Steps(10)])[&Horizon::Steps(10).key()];
    let (given, at_speed) = (fit_10(model), fit_10(&similar));
    if !(given.is_finite() && at_speed.is_finite()) {
        return None;
    }
    Some(Caveat::SpeedSimilar {
        ratio,
        fit_10_given_pct: given,
        fit_10_similar_pct: at_speed,
        shows_speed: at_speed >= given + GAIN_PP,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::channels::course_speed;
    use crate::diagnose::tests::identify;
    use crate::sim::{simulate, InputSpec, Scenario, Ship, SimEffect};

    /// ±20° zig-zags of `ship` heading east at first, in `effects`.
    fn zigzags(ship: &Ship, effects: Vec<SimEffect>, seeds: &[u64]) -> Vec<Record> {
        let sc = Scenario {
            input: InputSpec::ZigZag {
                delta_deg: 20.0,
                psi_deg: 20.0,
            },
            effects,
            initial_heading_deg: Some(90.0),
            ..Scenario::default()
        };
        seeds
            .iter()
            .map(|&s| simulate(ship, &sc, s).unwrap())
            .collect()
    }

    #[test]
    fn a_slower_ship_is_told_from_a_current_along_its_course_by_how_it_answers_the_helm() {
        // the built-in ship's zig-zags about east; trials with a current of 0.4 m/s setting
        // east (along the course: faster over the ground, the same through the water), and
        // trials with the pods at 8.0 instead of 10.5 rev/s (slower through the water)
        let lng = Ship::default_lng();
        let reference = zigzags(&lng, vec![], &[900, 901, 902]);
        let model = identify(&reference);
        let current = SimEffect::Current {
            speed_mps: 0.4,
            towards_deg: 90.0,
        };
        let in_current = zigzags(&lng, vec![current], &[100, 101, 102]);
        let mut slow = lng.clone();
        slow.pods.rps = 8.0;
        let slower = zigzags(&slow, vec![], &[100, 101, 102]);
        let u_ref = course_speed(&reference).unwrap();
        let mut fits = Vec::new();
        for (trials, speed) in [(&in_current, false), (&slower, true)] {
            let ratio = course_speed(trials).unwrap() / u_ref;
            let c = at_trials_speed(ratio, &model, &reference, trials).unwrap();
            let Caveat::SpeedSimilar {
                fit_10_given_pct: given,
                fit_10_similar_pct: similar,
                shows_speed,
                ..
            } = c
            else {
                panic!("{c:?}")
            };
            println!("ratio {ratio:.3}: 10-step fit {given:.2} % given, {similar:.2} % re-timed");
            assert_eq!(shows_speed, speed, "{c:?}");
            fits.push((ratio, given, similar));
        }
        // a current along the course: over the ground 20 % faster or more, and the
        // reference re-timed to that predicts the trials far worse
        assert!(fits[0].0 > 1.2 && fits[0].2 < fits[0].1 - 5.0, "{fits:?}");
        // the slower ship: the re-timed reference predicts it better
        assert!(
            fits[1].0 < 0.85 && fits[1].2 > fits[1].1 + GAIN_PP,
            "{fits:?}"
        );
        // outside the range of similar speeds nothing is tried
        assert!(at_trials_speed(0.2, &model, &reference, &slower).is_none());
    }

    fn rec() -> Record {
        let n = 11;
        let mut r = Record::from_uy(
            "r",
            1.0,
            (0..n).map(|t| if t < 5 { 10.0 } else { -10.0 }).collect(),
            (0..n).map(|t| t as f64).collect(),
        );
        r.psi = Some((0..n).map(|t| (350.0 + 4.0 * t as f64) % 360.0).collect());
        r.speed = Some(vec![2.0; n]);
        r
    }

    #[test]
    fn a_record_re_timed_to_half_the_speed_is_twice_as_long_and_turns_half_as_fast() {
        let r = retime(&rec(), 0.5).unwrap();
        // 10 s sailed at half the speed take 20 s: 21 samples at the same 1 s
        assert_eq!(r.len(), 21);
        assert_eq!(r.ts, 1.0);
        assert_eq!(r.t[20], 20.0);
        // the yaw rate at 3 s is the original's at 1.5 s, halved
        assert_eq!(r.y[3].to_bits(), (0.5f64 * 1.5).to_bits());
        // the command is held from the sample before: it reverses at 10 s, not between
        assert_eq!(r.u[9], 10.0);
        assert_eq!(r.u[10], -10.0);
        // the heading interpolates across north the short way: 358° at 4 s (2 s before)
        let psi = r.psi.as_ref().unwrap();
        assert!((psi[4] - 358.0).abs() < 1e-12, "{}", psi[4]);
        assert!((psi[6] - 2.0).abs() < 1e-12, "{}", psi[6]);
        assert_eq!(r.speed.as_ref().unwrap()[7], 1.0);
        // twice the speed: half as long, yaw rate doubled
        let f = retime(&rec(), 2.0).unwrap();
        assert_eq!(f.len(), 6);
        assert_eq!(f.y[5], 20.0);
        assert_eq!(retime(&rec(), 0.0), None);
        assert_eq!(retime(&rec(), f64::NAN), None);
    }
}
