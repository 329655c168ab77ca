//! Acceptance of the heading and track prediction: on the built-in ship with a current, the
//! track part's current estimate halves the 60-s track error of the model identified on the
//! effect-free simulator; on current-free records it costs at most 2 %; the heading
//! prediction is no worse than the yaw-rate prediction integrated alone.

use yawcast::identify::model::Model;
use yawcast::identify::pem::{self, PemConfig};
use yawcast::identify::track::{evaluate, fit_track, TrackEval};
use yawcast::io::data::Record;
use yawcast::io::nav::{ground_velocity, Nav};
use yawcast::sim::{simulate_with_nav, Scenario, Ship, SimEffect, SimNav};
use yawcast_shared::nav::TrackSpec;

/// The navigation channels of a simulated record: ground velocity and position fixes.
fn nav_of(rec: &Record, sn: &SimNav) -> Nav {
    let sog = rec
        .speed
        .as_ref()
        .expect("the simulator logs speed over ground");
    let v = sog
        .iter()
        .zip(&sn.cog_deg)
        .map(|(s, c)| ground_velocity(*s, *c))
        .collect();
    let fix = sn
        .north_m
        .iter()
        .zip(&sn.east_m)
        .map(|(n, e)| [*n, *e])
        .collect();
    Nav::new(rec.ts, Some(v), Some(fix), "simulator").expect("channels")
}

/// The model of three effect-free simulator records and the track part fitted on them
/// (speed, speed loss in turns, sway), without and with the current.
fn reference_model(ship: &Ship) -> (Model, TrackSpec, TrackSpec) {
    let sims: Vec<(Record, Nav)> = (101..104)
        .map(|s| {
            let (rec, sn) = simulate_with_nav(ship, &Scenario::default(), s).expect("simulation");
            let nav = nav_of(&rec, &sn);
            (rec, nav)
        })
        .collect();
    let recs: Vec<Record> = sims.iter().map(|(r, _)| r.clone()).collect();
    let model = pem::identify(&recs, None, &PemConfig::default())
        .expect("identification")
        .model;
    let pairs: Vec<(&Record, &Nav)> = sims.iter().map(|(r, n)| (r, n)).collect();
    let plain = fit_track(model.ts, model.d_y(), &pairs, false).expect("track part");
    let with_current = fit_track(model.ts, model.d_y(), &pairs, true).expect("track part");
    // the ship drifts outwards in a turn and loses speed
    assert!(plain.sway < -0.05 && plain.sway > -0.1, "{}", plain.sway);
    assert!(plain.speed_loss > 0.0, "{}", plain.speed_loss);
    assert!((plain.speed - 1.28).abs() < 0.02, "{}", plain.speed);
    (model, plain, with_current)
}

fn eval(model: &Model, track: &TrackSpec, rec: &Record, nav: &Nav) -> TrackEval {
    evaluate(
        model,
        track,
        rec,
        Some(nav),
        &[10, 20],
        &[30.0, 60.0, 120.0],
    )
    .expect("evaluation")
}

fn err60(e: &TrackEval) -> f64 {
    e.track_error_m[1].1.expect("a 60-s error")
}

#[test]
fn current_part_halves_the_track_error_and_costs_nothing_without_current() {
    let ship = Ship::default_lng();
    let (model, plain, with_current) = reference_model(&ship);
    let currents = [(1u64, 0.3, 90.0), (2, 0.6, 200.0), (3, 1.0, 330.0)];
    for (seed, speed, towards) in currents {
        let sc = Scenario::with_effect(SimEffect::Current {
            speed_mps: speed,
            towards_deg: towards,
        });
        let (rec, sn) = simulate_with_nav(&ship, &sc, seed).expect("simulation");
        assert_eq!(rec.len(), 1800);
        let nav = nav_of(&rec, &sn);
        let before = eval(&model, &plain, &rec, &nav);
        let after = eval(&model, &with_current, &rec, &nav);
        eprintln!(
            "current {speed} m/s: 60-s track error {:.2} m -> {:.2} m; {:?} {:?}; heading {:?} vs {:?}",
            err60(&before),
            err60(&after),
            before.track_error_m,
            after.track_error_m,
            after.heading_fit,
            after.heading_fit_rate_only
        );
        assert!(
            err60(&after) <= 0.5 * err60(&before),
            "current {speed} m/s: {} m -> {} m",
            err60(&before),
            err60(&after)
        );
        for (h, r) in after.heading_fit.iter().zip(&after.heading_fit_rate_only) {
            assert!(
                h.1 >= r.1 - 1e-9,
                "heading fit at {} steps: {} < {}",
                h.0,
                h.1,
                r.1
            );
        }
        assert_eq!(after.velocity_counts, [1800, 0, 0]);
    }
    for seed in [11u64, 12, 13] {
        let (rec, sn) = simulate_with_nav(&ship, &Scenario::default(), seed).expect("simulation");
        let nav = nav_of(&rec, &sn);
        let before = eval(&model, &plain, &rec, &nav);
        let after = eval(&model, &with_current, &rec, &nav);
        eprintln!(
            "no current: 60-s track error {:.3} m -> {:.3} m",
            err60(&before),
            err60(&after)
        );
        assert!(
            err60(&after) <= 1.02 * err60(&before),
            "no current, seed {seed}: {} m -> {} m",
            err60(&before),
            err60(&after)
        );
    }
}
