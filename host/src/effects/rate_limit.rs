//! `rate-limit`: a slow steering gear, the rudder/pod moves at most `ρ·Ts` per step
//! towards its target, `ũ = ũ_prev + clamp(τ − ũ_prev, ±ρ·Ts)`.

use super::{
    geometric, Channel, Def, Effect, Field, Fields, GridSpan, HullScale, Role, SimEffect, SimKnobs,
};
use yawcast_shared::model::EffectKind;

/// Hidden `rate-limit` at full strength (deg/s); strength `s` gives `rate / s`.
pub const HIDDEN_RATE_DEGPS: f64 = 3.0;

/// The slowest gear searched (deg/s).
const SLOWEST: f64 = 0.5;

pub(super) const DEF: Def = Def {
    kind: EffectKind::RateLimit,
    phrase: "a rudder/pod slew-rate limit",
    role: Role::Actuator { dynamics: true },
    own: true,
    channel: Channel::None,
    slow: false,
    gains: &[],
    hidden: |s| SimEffect::RateLimit {
        rate_degps: HIDDEN_RATE_DEGPS / s,
    },
    candidates: |g| {
        rates(g, GRID)
            .into_iter()
            .map(|rate| Effect::RateLimit { rate })
            .collect()
    },
    search: |g| rates(g, GRID),
};

/// Rates on the grid: 25, each 13 % above the last on a 10° step at 1 Hz (15 % on 17°). A
/// gear only somewhat slower than the reference's own is told from a dead time by its rate:
/// on the container ship's trials at half strength a slew limit of 2.1 °/s behind the
/// reference's 2.5 read `dead-time` on a grid of 12 (37 % apart; its nearest rate 2.37).
const GRID: usize = 25;

/// The one grid of gear rates, diagnose's and augment's alike ([`GRID`] rates; augment then
/// refines between the neighbours of the best): geometric from 0.5 °/s to 90 % of the rate of the
/// records' largest command step — a gear at or above it is no limit at all on these
/// commands.
///
/// ```text
/// du_max = 10°, ts = 1 s:  0.5 … 9 °/s;   du_max = 60°, ts = 0.4 s:  0.5 … 135 °/s
/// ```
fn rates(g: &GridSpan, n: usize) -> Vec<f64> {
    let hi = (g.du_max / g.ts).max(1.0);
    let lo = SLOWEST.min(hi / 2.0);
    geometric(lo, 0.9 * hi, n)
}

pub(super) fn describe(rate: f64) -> String {
    format!("a slew limit of {rate:.1} °/s")
}

pub(super) fn evidence(rate: f64, pct: f64) -> (Option<f64>, String) {
    (
        Some(rate),
        format!(
            "errors grow right after fast steering reversals; a slew limit of {rate:.1} °/s explains \
             {pct:.0} % of the one-step error energy"
        ),
    )
}

pub(super) fn describe_sim(rate_degps: f64) -> String {
    format!("a pod slew limit of {rate_degps:.2} °/s")
}

pub(super) fn fields(v: f64) -> Fields {
    [Field::new("rate_degps", v, v > 0.0, "> 0"), None]
}

/// The slowest gear wins.
pub(super) fn apply(rate_degps: f64, k: &mut SimKnobs) {
    k.max_rate_degps = k.max_rate_degps.min(rate_degps);
}

/// A rate: scales with the inverse of the hull's time.
pub(super) fn on_hull(rate_degps: f64, s: &HullScale) -> SimEffect {
    SimEffect::RateLimit {
        rate_degps: rate_degps / s.time,
    }
}

pub(super) fn to_sim(rate: f64) -> SimEffect {
    SimEffect::RateLimit { rate_degps: rate }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::model::Model;
    use crate::identify::predict;
    use crate::identify::predict::tests::m4;
    use crate::io::data::Record;

    #[test]
    fn one_grid_for_diagnose_and_augment() {
        let g = GridSpan {
            ts: 1.0,
            du_max: 10.0,
            ..GridSpan::default()
        };
        let d: Vec<f64> = (DEF.candidates)(&g)
            .iter()
            .map(|e| match e {
                Effect::RateLimit { rate } => *rate,
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(d.len(), 25);
        assert!(
            (d[0] - 0.5).abs() < 1e-12 && (d[24] - 9.0).abs() < 1e-9,
            "{d:?}"
        );
        // neighbours 12.8 % apart: (9 / 0.5)^(1/24)
        assert!((d[1] / d[0] - 1.128_0).abs() < 1e-4, "{d:?}");
        assert_eq!((DEF.search)(&g), d);
        let g = GridSpan {
            ts: 0.5,
            du_max: 40.0,
            ..g
        };
        assert!((rates(&g, 12)[11] - 72.0).abs() < 1e-9);
        // a step smaller than the slowest rate still gives a grid below it
        let g = GridSpan {
            ts: 1.0,
            du_max: 0.2,
            ..g
        };
        let r = rates(&g, 12);
        assert!(
            (r[0] - 0.5).abs() < 1e-12 && (r[11] - 0.9).abs() < 1e-9,
            "{r:?}"
        );
    }

    #[test]
    fn words_and_physics() {
        assert_eq!(describe(3.04), "a slew limit of 3.0 °/s");
        assert_eq!(describe_sim(3.0), "a pod slew limit of 3.00 °/s");
        assert_eq!(
            SimEffect::hidden(EffectKind::RateLimit, 0.5),
            SimEffect::RateLimit { rate_degps: 6.0 }
        );
        let mut k = SimKnobs::default();
        apply(4.0, &mut k);
        apply(6.0, &mut k);
        assert_eq!(k.max_rate_degps, 4.0);
        let e = SimEffect::RateLimit { rate_degps: -2.0 }
            .validate("effects[0]")
            .unwrap_err();
        assert!(
            e.to_string().contains("effects[0] (rate-limit).rate_degps"),
            "{e}"
        );
    }

    /// The f64 predictor's actuator chain: dead time, limit, then the gear moving at most
    /// ρ·Ts per step; a dead band before the gear.
    #[test]
    fn the_predictor_slews_after_the_limit_and_the_band() {
        let run = |m: &Model, us: &[f64]| -> Vec<f64> {
            let s = predict::Stepper::new(m);
            let mut st = s.initial(&[0.0; 4], 0.0);
            us.iter().map(|u| s.actuator(&mut st, *u)).collect()
        };
        let m = m4()
            .with_effect(Effect::DeadTime { samples: 2 })
            .with_effect(Effect::Saturation { limit: 5.0 })
            .with_effect(Effect::RateLimit { rate: 2.0 });
        assert_eq!(
            run(&m, &[10.0, 10.0, 10.0, 10.0, 10.0, -10.0]),
            vec![0.0, 0.0, 2.0, 4.0, 5.0, 5.0]
        );
        let m = m4()
            .with_effect(Effect::DeadBand { width: 1.5 })
            .with_effect(Effect::RateLimit { rate: 2.0 });
        assert_eq!(
            run(&m, &[1.0, 5.0, 5.0, 5.0, 0.0, 1.0]),
            vec![0.0, 2.0, 3.5, 3.5, 1.5, 1.5]
        );
        // the simulation reads the slewed input: x1(1) = b1·ũ(0)
        let mut m = Model::new(1.0, vec![0.0, 0.5], vec![1.0, 0.0], vec![0.0, 0.0]).unwrap();
        m.effects.push(Effect::RateLimit { rate: 2.0 });
        let rec = Record::from_uy("x", 1.0, vec![10.0; 7], vec![0.0; 7]);
        let y = predict::simulate(&m, &rec, &[0.0, 0.0]);
        assert_eq!(y[1], 2.0);
    }
}

/// The diagnosis and augmentation of a slow gear on the built-in ship's records.
#[cfg(test)]
mod diagnosis {
    use crate::diagnose::augment::tests::kept;
    use crate::diagnose::tests::{identify, records, slow_gear_records};
    use crate::diagnose::{diagnose, Caveat, DiagnoseConfig};
    use crate::identify::model::Effect;
    use yawcast_shared::model::EffectKind;

    #[test]
    fn rate_limit_of_three_degrees_per_second_is_found() {
        let r = kept(EffectKind::RateLimit);
        let Some(Effect::RateLimit { rate }) = r.model.effect(EffectKind::RateLimit) else {
            panic!("no rate limit")
        };
        assert!((rate - 3.0).abs() < 0.3 * 3.0, "{rate}");
        assert!(r.fit_gain_pp > 3.0, "{}", r.explanation);
    }

    #[test]
    fn a_model_of_the_trials_given_with_a_reference_is_said_to_weaken_the_evidence() {
        let reference = records(None, &[61, 62]);
        let est = records(Some((EffectKind::RateLimit, 1.0)), &[63, 64]);
        let cfg = DiagnoseConfig {
            null_reps: 8,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let foreign = |d: &crate::diagnose::Diagnosis| {
            d.caveats
                .iter()
                .any(|c| matches!(c, Caveat::ForeignModel { excess_pct } if *excess_pct > 0.0))
        };
        // the documented use: the reference's model names the slow gear, no warning
        let d = diagnose(&identify(&reference), &reference, &est, &[], &cfg).unwrap();
        assert!(!foreign(&d), "{}", d.explanation);
        assert_eq!(
            d.verdict_kind(),
            Some(EffectKind::RateLimit),
            "{}",
            d.explanation
        );
        // a model identified on the trials themselves: said
        let d = diagnose(&identify(&est), &reference, &est, &[], &cfg).unwrap();
        assert!(foreign(&d), "{}", d.explanation);
        assert!(
            d.explanation
                .contains("does not look identified from the reference records"),
            "{}",
            d.explanation
        );
    }

    #[test]
    fn dead_time_on_a_rate_limited_reference_gear_is_named_dead_time() {
        // the linear reference model absorbs the gear's slew limit into its poles; with θ
        // frozen a slew limit then mimics the trials' extra 2 s delay as well as the delay
        // itself. Measured against the reference model with its own gear, the delay stands out.
        let reference = slow_gear_records(None, &[500, 501]);
        let model = identify(&reference);
        let cfg = DiagnoseConfig {
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let est = slow_gear_records(Some(EffectKind::DeadTime), &[502, 503]);
        let d = diagnose(&model, &reference, &est, &[], &cfg).unwrap();
        assert_eq!(
            d.verdict_kind(),
            Some(EffectKind::DeadTime),
            "{}",
            d.explanation
        );
        let dt = &d.ranking[0];
        assert_eq!(dt.parameter, Some(2.0), "{dt:?}");
        assert!(dt.fit_gain_pp > 10.0, "{dt:?}");
        // the reference's own gear, found with θ re-identified (4 °/s and a 2.5 s lag)
        let own = d.explanation.find("slew limit of ").unwrap() + "slew limit of ".len();
        let rate: f64 = d.explanation[own..]
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!((3.5..6.0).contains(&rate), "{}", d.explanation);
        // the encompassing test in words that say what they mean
        assert!(
            dt.evidence
                .contains("given dead-time, rate-limit adds nothing significant"),
            "{}",
            dt.evidence
        );
        assert!(
            dt.evidence
                .contains("given rate-limit, dead-time still adds"),
            "{}",
            dt.evidence
        );
        let rl = d.ranking.iter().find(|r| r.effect == "rate-limit").unwrap();
        assert!(rl.above_noise < dt.above_noise, "{rl:?}");
        assert!(
            d.explanation.contains("likelihood gain above noise"),
            "{}",
            d.explanation
        );
        // no hidden effect on the same gear: nothing, in particular no slew limit
        let none = slow_gear_records(None, &[502, 503]);
        let d = diagnose(&model, &reference, &none, &[], &cfg).unwrap();
        assert_eq!(d.verdict, "none", "{}", d.explanation);
        assert!(d.ranking.iter().all(|r| !r.significant), "{:?}", d.ranking);
    }
}
