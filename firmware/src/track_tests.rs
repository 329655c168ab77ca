//! Tests of the f32 heading/track predictor.

use super::*;
use yawcast_shared::model::Units;

fn model(effects: &[Effect]) -> ModelSpec {
    ModelSpec::new(
        2,
        1.0,
        &[-0.7, -1.5],
        &[0.1, -0.05],
        &[0.3, -0.2],
        Units::default(),
        effects,
    )
    .unwrap()
}

/// The prediction from a state equals that many updates without measurements, bit for bit.
#[test]
fn prediction_equals_updates_without_measurements() {
    let m = model(&[Effect::GyroBias { d_y: 0.2 }]);
    let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.7, true).unwrap()).unwrap();
    for i in 0..30 {
        let nav = NavMeasurement {
            velocity: Some([1.0 + 0.01 * i as f32, 0.4]),
            fix: None,
        };
        t.update(0.8, Some(10.0 + i as f32), &nav);
    }
    let rates: [f32; 9] = core::array::from_fn(|i| 0.5 * i as f32 - 1.0);
    let mut out = [[0.0f32; 3]; 10];
    t.predict_into(&mut out, &rates).unwrap();
    let mut u = t.clone();
    assert_eq!(out[0], [u.state().psi, u.state().pos[0], u.state().pos[1]]);
    for j in 1..10 {
        u.update(rates[j - 1], None, &NavMeasurement::default());
        let s = u.state();
        assert_eq!(
            out[j].map(f32::to_bits),
            [s.psi, s.pos[0], s.pos[1]].map(f32::to_bits)
        );
    }
    // gyro offset taken out: rate 0.2 keeps the heading
    let mut v = t.clone();
    let psi = v.state().psi;
    v.update(0.2, None, &NavMeasurement::default());
    assert_eq!(v.state().psi, psi);
}

/// A ship circling at 2 m/s in a current (0.3, −0.4) m/s: the observer finds speed and current.
#[test]
fn observer_finds_speed_and_current_in_a_turn() {
    let m = model(&[]);
    let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, true).unwrap()).unwrap();
    let (u, c) = (2.0f32, [0.3f32, -0.4]);
    for i in 0..8000 {
        let psi = (i as f32 * 1.5) % 360.0;
        let v = ground_velocity(u, psi);
        let nav = NavMeasurement {
            velocity: Some([v[0] + c[0], v[1] + c[1]]),
            fix: None,
        };
        let s = t.update(1.5, Some(psi), &nav);
        assert_eq!(s.velocity, Correction::Applied);
    }
    let s = t.state();
    assert!((s.speed - 2.0).abs() < 0.01, "{}", s.speed);
    assert!((s.current[0] - 0.3).abs() < 0.01, "{:?}", s.current);
    assert!((s.current[1] + 0.4).abs() < 0.01, "{:?}", s.current);
}

/// Without the current part the current stays exactly zero.
#[test]
fn no_current_part_keeps_zero_current() {
    let m = model(&[]);
    let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, false).unwrap()).unwrap();
    for i in 0..200 {
        let nav = NavMeasurement {
            velocity: Some([1.0, 0.7]),
            fix: Some([i as f32, 0.5 * i as f32]),
        };
        t.update(0.3, Some(i as f32), &nav);
    }
    assert_eq!(t.state().current, [0.0, 0.0]);
}

/// NaN, infinite and jumping inputs are skipped and reported; a non-finite rate resets.
#[test]
fn bad_navigation_input_is_skipped_and_reported() {
    let m = model(&[]);
    let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, true).unwrap()).unwrap();
    t.update(0.0, Some(0.0), &NavMeasurement::default());
    let before = t.state();
    let nav = NavMeasurement {
        velocity: Some([f32::NAN, 0.0]),
        fix: Some([f32::INFINITY, 0.0]),
    };
    let s = t.update(0.0, Some(0.0), &nav);
    assert_eq!(
        (s.velocity, s.fix, s.reset),
        (Correction::Rejected, Correction::Rejected, false)
    );
    assert_eq!(t.state().speed, before.speed);
    let nav = NavMeasurement {
        velocity: Some([50.0, 0.0]),
        fix: Some([3.0, 3000.0]),
    };
    let s = t.update(0.0, Some(0.0), &nav);
    assert_eq!((s.velocity, s.fix), (Correction::Gated, Correction::Gated));
    assert_eq!(t.state().current, [0.0, 0.0]);
    // a heading through north: 359 → 1 is a 2° step, no jump in the heading vector
    t.update(0.0, Some(359.0), &NavMeasurement::default());
    let h0 = t.state().h;
    t.update(0.0, Some(1.0), &NavMeasurement::default());
    let h1 = t.state().h;
    assert!((h0[0] - h1[0]).abs() < 1e-3 && (h0[1] - h1[1]).abs() < 0.04);
    let s = t.update(f32::NAN, None, &NavMeasurement::default());
    assert!(s.reset);
    assert_eq!(t.state().pos, [0.0, 0.0]);
    assert_eq!(t.state().speed, 1.5);
}

/// Horizon and input checks of the prediction.
#[test]
fn prediction_checks_its_arguments() {
    let m = model(&[]);
    let t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, false).unwrap()).unwrap();
    let mut out = [[0.0f32; 3]; 4];
    assert_eq!(
        t.predict_into(&mut out, &[0.0; 2]),
        Err(PredictorError::NotEnoughInputs { needed: 3, got: 2 })
    );
    assert_eq!(
        t.predict_into(&mut [], &[]),
        Err(PredictorError::HorizonOutOfRange(0))
    );
    let mut big = [[0.0f32; 3]; 65];
    assert_eq!(
        t.predict_into(&mut big, &[0.0; 64]),
        Err(PredictorError::HorizonOutOfRange(65))
    );
    assert_eq!(
        t.predict_into(&mut out, &[0.0, f32::INFINITY, 0.0]),
        Err(PredictorError::NonFinite)
    );
}

/// A fix pulls the position by α and the straight-line prediction follows the estimate.
#[test]
fn fix_pulls_the_position() {
    let m = model(&[]);
    let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 0.0, false).unwrap()).unwrap();
    let nav = NavMeasurement {
        velocity: None,
        fix: Some([10.0, -4.0]),
    };
    let s = t.update(0.0, Some(0.0), &nav);
    assert_eq!(s.fix, Correction::Applied);
    // α = 0.5: (5, −2); U = 0 + k_u·(1·10 + 0·(−4)) ≈ 0.1, then one step at U due north
    let u = 0.01f32 * 10.0;
    assert_eq!(t.state().speed, u);
    assert_eq!(t.state().pos, [5.0 + u, -2.0]);
    // a line due east through the origin: a point north of it is to port
    assert_eq!(cross_track([0.0, 0.0], 90.0, [5.0, -2.0]), -5.0);
}

/// The f32 sine and cosine agree with f64 to 5e-7 over ±720° and beyond, and stay finite.
#[test]
fn sin_cos_deg_is_accurate() {
    let mut worst = 0.0f64;
    for i in -14_400..=14_400 {
        let x = i as f32 * 0.05 + 0.013;
        let (s, c) = sin_cos_deg(x);
        let (s64, c64) = (f64::from(x)).to_radians().sin_cos();
        worst = worst
            .max((f64::from(s) - s64).abs())
            .max((f64::from(c) - c64).abs());
    }
    assert!(worst < 5e-7, "{worst}");
    let (s, c) = sin_cos_deg(123_456.7);
    let (s64, c64) = 123_456.7f64.to_radians().sin_cos();
    // x itself is rounded to f32 (0.0078 deg steps here)
    assert!((f64::from(s) - s64).abs() < 2e-4 && (f64::from(c) - c64).abs() < 2e-4);
    assert!(sin_cos_deg(1e30).0.is_nan());
    assert!(sin_cos_deg(f32::NAN).1.is_nan());
    assert!(ground_velocity(1.0, f32::NAN)[0].is_nan());
}
