//! Acceptance tests of the simulator: manoeuvres, effects, seeds, errors.

use super::*;
use crate::identify::predict::{self, Horizon};
use yawcast_shared::model::EffectKind;

#[test]
fn turning_circle_and_zigzag_look_like_a_ship() {
    let ship = Ship::default_lng();
    let l = ship.main.lpp_m;
    let tc = turning_circle(&ship, 35.0).unwrap();
    println!("35° turning circle: {tc:?} (Lpp {l} m)");
    assert!(
        (2.0 * l..6.0 * l).contains(&tc.tactical_diameter_m),
        "tactical diameter {} m",
        tc.tactical_diameter_m
    );
    assert!(
        (2.0 * l..6.0 * l).contains(&tc.advance_m),
        "advance {} m",
        tc.advance_m
    );
    // Port and starboard turns mirror each other on a symmetric ship.
    let port = turning_circle(&ship, -35.0).unwrap();
    assert!((port.tactical_diameter_m - tc.tactical_diameter_m).abs() < 0.01 * l);
    assert!(port.steady_r_degps < 0.0 && tc.steady_r_degps > 0.0);
    // The ship slows down in the turn.
    assert!(tc.steady_speed_mps > 0.0);

    let z = zigzag(&ship, 10.0, 10.0).unwrap();
    println!("10/10 zig-zag: {z:?}");
    assert!(
        (2.0..20.0).contains(&z.first_overshoot_deg),
        "first overshoot {}°",
        z.first_overshoot_deg
    );
    assert!(z.second_overshoot_deg > 0.0 && z.time_to_switch_s > 0.0);
}

#[test]
fn steady_yaw_rate_grows_with_the_pod_angle() {
    let ship = Ship::default_lng();
    let rates: Vec<f64> = [5.0, 10.0, 20.0, 35.0]
        .iter()
        .map(|&d| turning_circle(&ship, d).unwrap().steady_r_degps)
        .collect();
    println!("steady r at 5/10/20/35°: {rates:?}");
    for w in rates.windows(2) {
        assert!(w[1] > w[0] * 1.05, "{rates:?}");
    }
}

fn quiet(effects: Vec<SimEffect>) -> Scenario {
    Scenario {
        noise: NoiseSpec::none(),
        initial_heading_deg: Some(30.0),
        n_samples: 900,
        effects,
        ..Scenario::default()
    }
}

#[test]
fn every_effect_changes_the_output_and_the_seed_fixes_the_record() {
    let ship = Ship::default_lng();
    let base = simulate(&ship, &quiet(Vec::new()), 7).unwrap();
    assert_eq!(base, simulate(&ship, &quiet(Vec::new()), 7).unwrap());
    assert_ne!(base.u, simulate(&ship, &quiet(Vec::new()), 8).unwrap().u);
    for k in EffectKind::ALL {
        let rec = simulate(&ship, &quiet(vec![SimEffect::hidden(k, 1.0)]), 7).unwrap();
        assert_eq!(rec.u, base.u, "{}: same command", k.name());
        // Yaw rate, heading or speed over ground must differ measurably.
        let dy = max_abs_diff(&rec.y, &base.y);
        let dpsi = max_abs_diff(rec.psi.as_ref().unwrap(), base.psi.as_ref().unwrap());
        let dv = max_abs_diff(rec.speed.as_ref().unwrap(), base.speed.as_ref().unwrap());
        println!(
            "{}: Δr {dy:.4} °/s, Δψ {dpsi:.2}°, ΔU {dv:.4} m/s",
            k.name()
        );
        assert!(
            dy > 0.02 || dpsi > 1.0 || dv > 0.01,
            "{} changes nothing",
            k.name()
        );
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn hidden_effects_cost_a_linear_model_fit_or_show_in_the_channels() {
    // A model identified on effect-free records predicts effect-free held-out records well;
    // on records with a full-strength hidden effect that changes the yaw dynamics it
    // predicts worse at 10 steps.
    let ship = Ship::default_lng();
    let sc = Scenario::default();
    let train = simulate_many(&ship, &sc, &[1, 2, 3]).unwrap();
    let m =
        crate::identify::pem::identify(&train, None, &crate::identify::pem::PemConfig::default())
            .unwrap()
            .model;
    // Slow effects (bias, gyro bias) show at long horizons: the Kalman gain re-anchors
    // short predictions.
    let fits = |sc: &Scenario| -> [f64; 2] {
        let recs = simulate_many(&ship, sc, &[101, 102]).unwrap();
        let mut f = [0.0; 2];
        for r in &recs {
            f[0] += predict::fit_at(&m, r, Horizon::Steps(10)) / recs.len() as f64;
            f[1] += predict::fit_at(&m, r, Horizon::Steps(50)) / recs.len() as f64;
        }
        f
    };
    let clean = fits(&sc);
    println!("effect-free held-out fit at 10/50 steps {clean:.2?} %");
    assert!(clean[0] > 80.0, "{clean:?}");
    // every effect but the heading ones (their moment depends on the heading history)
    for k in EffectKind::ALL.into_iter().filter(|k| !k.needs_heading()) {
        let f = fits(&Scenario::with_effect(SimEffect::hidden(k, 1.0)));
        println!("{}: fit at 10/50 steps {f:.2?} %", k.name());
        let cost = (clean[0] - f[0]).max(clean[1] - f[1]);
        assert!(cost > 2.0, "{} costs only {cost:.2} pp", k.name());
    }
}

#[test]
fn bad_scenarios_name_the_field() {
    let ship = Ship::default_lng();
    let e = simulate(
        &ship,
        &Scenario {
            ts: -1.0,
            ..Scenario::default()
        },
        1,
    )
    .unwrap_err();
    assert!(e.to_string().contains("scenario.ts"), "{e}");
    let e = simulate(
        &ship,
        &Scenario::with_effect(SimEffect::Saturation { limit_deg: 0.0 }),
        1,
    )
    .unwrap_err();
    assert!(e.to_string().contains("limit_deg"), "{e}");
}

#[test]
fn bisection_finds_a_root_from_either_side_and_keeps_the_last_bracket() {
    // √2 as the root of x² − 2, rising through it.
    let r = bisect(0.0, 2.0, 60, |x| x * x - 2.0 > 0.0);
    assert!((r - 2f64.sqrt()).abs() < 1e-15, "{r}");
    // A falling function: past the root it is no longer positive.
    let f = |x: f64| 3.0 - x;
    let r = bisect(0.0, 10.0, 60, |x| f(x) <= 0.0);
    assert!((r - 3.0).abs() < 1e-14, "{r}");
    // One halving leaves the midpoint of the half that holds the root.
    assert_eq!(bisect(0.0, 8.0, 1, |x| x > 1.0).to_bits(), 2f64.to_bits());
}

#[test]
fn the_gears_angle_is_logged_in_place_of_the_command_and_nothing_else_changes() {
    let ship = Ship::default_lng();
    let cmd = simulate(&ship, &Scenario::default(), 7).unwrap();
    let angle_scenario = Scenario {
        log_angle: true,
        ..Scenario::default()
    };
    let angle = simulate(&ship, &angle_scenario, 7).unwrap();
    // the same run: the ship's channels bit for bit, only the command column differs
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&cmd.y), bits(&angle.y));
    assert_eq!(
        bits(cmd.psi.as_ref().unwrap()),
        bits(angle.psi.as_ref().unwrap())
    );
    let step = |u: &[f64]| {
        u.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max)
    };
    // PRBS commands step by up to 40°; the pod slews at most max_rate over a sample
    assert_eq!(step(&cmd.u), 40.0);
    let slew = ship.actuator.max_rate_degps * angle.ts;
    assert!(step(&angle.u) <= slew + 1e-9, "{} > {slew}", step(&angle.u));
    assert!(step(&angle.u) > 0.5 * slew, "{}", step(&angle.u));
    // and it follows the command: within the gear's lag of it
    let lag = max_abs_diff(&cmd.u, &angle.u);
    assert!(lag > 1.0 && lag <= 40.0, "{lag}");
}
