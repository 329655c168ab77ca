//! Unit tests of the predictor: both paths, prediction, the actuator chain, each effect, errors.

extern crate std;
use super::*;
use yawcast_shared::model::{Effect, Units, EVERY_EFFECT};

// the shift-form row (−0.1, 0.2, −0.3, 0.6) in difference form (spectral radius 0.57)
const A: [f32; 4] = [-0.6, -2.6, -4.5, -3.4];
const B: [f32; 4] = [0.01, 0.01, 0.005, 0.002];
const K: [f32; 4] = [0.3, -0.1, 0.02, 0.05];

fn model(effects: &[Effect]) -> ModelSpec {
    ModelSpec::new(4, 0.5, &A, &B, &K, Units::default(), effects).unwrap()
}

/// Deterministic pseudo-random inputs: (u, y, psi).
fn inputs(n: usize) -> std::vec::Vec<(f32, f32, Option<f32>)> {
    let mut s = 0x1234_5678_9abc_def0u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32 - 0.5
    };
    (0..n)
        .map(|i| {
            let y = if i % 17 == 5 { f32::NAN } else { 4.0 * next() };
            let psi = if i % 3 == 0 {
                Some(720.0 * next())
            } else {
                None
            };
            (20.0 * next(), y, psi)
        })
        .collect()
}

#[test]
fn plain_path_equals_general_path_bit_for_bit() {
    let m = model(&[]);
    let mut fast = Predictor::<4>::new(&m).unwrap();
    let mut slow = fast.clone();
    slow.plain = false;
    let fu: std::vec::Vec<f32> = (0..19).map(|i| (i as f32 * 0.7).sin() * 5.0).collect();
    for (u, y, psi) in inputs(500) {
        assert_eq!(
            fast.update_with_heading(u, y, psi),
            slow.update_with_heading(u, y, psi)
        );
        let (sf, ss) = (fast.state(), slow.state());
        for i in 0..4 {
            assert_eq!(sf.x[i].to_bits(), ss.x[i].to_bits());
        }
        assert_eq!(sf.psi.to_bits(), ss.psi.to_bits());
        assert_eq!(sf.u_prev.to_bits(), ss.u_prev.to_bits());
        let (mut of, mut os) = ([0.0f32; 20], [0.0f32; 20]);
        fast.predict_into(&mut of, &fu).unwrap();
        slow.predict_into(&mut os, &fu).unwrap();
        assert_eq!(of.map(f32::to_bits), os.map(f32::to_bits));
    }
}

#[test]
fn prediction_equals_updates_without_measurements() {
    let all = EVERY_EFFECT;
    for effects in [&[][..], &all[..]] {
        let mut p = Predictor::<4>::new(&model(effects)).unwrap();
        let data = inputs(300);
        for (t, &(u, y, psi)) in data.iter().enumerate() {
            p.update_with_heading(u, y, psi);
            let fu: std::vec::Vec<f32> = data[t + 1..].iter().take(15).map(|d| d.0).collect();
            let h = fu.len() + 1;
            let mut out = [0.0f32; 16];
            p.predict_into(&mut out[..h], &fu).unwrap();
            // the same steps as updates with a missing measurement
            let mut q = p.clone();
            assert_eq!(out[0].to_bits(), q.prediction().to_bits());
            for j in 1..h {
                assert_eq!(
                    q.update(fu[j - 1], f32::NAN),
                    UpdateStatus::SkippedCorrection
                );
                assert_eq!(out[j].to_bits(), q.prediction().to_bits(), "t={t} j={j}");
            }
        }
    }
}

#[test]
fn actuator_chain() {
    // dead time 3: ũ(t) = u(t−3)
    let mut p = Predictor::<4>::new(&model(&[Effect::DeadTime { samples: 3 }])).unwrap();
    let mut seen = std::vec::Vec::new();
    for u in 1..=6 {
        p.update(u as f32, 0.0);
        seen.push(p.state().u_prev);
    }
    assert_eq!(seen, [0.0, 0.0, 0.0, 1.0, 2.0, 3.0]);
    // dead band 1.5: the pod stays until the command is more than 1.5 away, then
    // follows 1.5 behind (the chain of limits together: yawcast_shared::kernel's tests)
    let mut p = Predictor::<4>::new(&model(&[Effect::DeadBand { width: 1.5 }])).unwrap();
    let mut seen = std::vec::Vec::new();
    for u in [1.0, 2.0, 4.0, 3.0, 2.0, -1.0, 0.0] {
        p.update(u, 0.0);
        seen.push(p.state().u_prev);
    }
    assert_eq!(seen, [0.0, 0.5, 2.5, 2.5, 2.5, 0.5, 0.5]);
}

/// From the zero state one update gives x̂'_i = ((0 + 0) + b_i·v) + k_i·e, so v can be
/// checked against a hand evaluation of each effect.
fn x_after_one(effects: &[Effect], u: f32, y: f32, psi: Option<f32>) -> [f32; 4] {
    let mut p = Predictor::<4>::new(&model(effects)).unwrap();
    p.update_with_heading(u, y, psi);
    p.state().x
}

fn expected(v: f32, e: f32) -> [f32; 4] {
    core::array::from_fn(|i| 0.0 + B[i] * v + K[i] * e)
}

#[test]
fn each_effect_enters_as_specified() {
    let (u, y) = (3.0f32, -2.0f32);
    assert_eq!(x_after_one(&[], u, y, None), expected(u, y));
    assert_eq!(
        x_after_one(&[Effect::Bias { beta: 0.5 }], u, y, None),
        expected(u + 0.5, y)
    );
    assert_eq!(
        x_after_one(&[Effect::GyroBias { d_y: 0.25 }], u, y, None),
        expected(u, y - 0.25)
    );
    assert_eq!(
        x_after_one(&[Effect::Asymmetry { beta: 0.5 }], u, y, None),
        expected(u + 0.5 * u, y)
    );
    assert_eq!(
        x_after_one(&[Effect::Asymmetry { beta: 0.5 }], -u, y, None),
        expected(-u + 0.5 * 0.0, y)
    );
    let nld = |cubic| Effect::NonlinearDamping { beta: 0.5, cubic };
    assert_eq!(
        x_after_one(&[nld(false)], u, y, None),
        expected(u + 0.5 * (y * 2.0), y)
    );
    assert_eq!(
        x_after_one(&[nld(true)], u, y, None),
        expected(u + 0.5 * (y * y * y), y)
    );
    // missing y: y_used = ŷ = 0, e = 0
    assert_eq!(
        x_after_one(&[nld(false)], u, f32::NAN, None),
        expected(u + 0.5 * 0.0, 0.0)
    );
    let psi = 30.0f32;
    let r = psi * <f32 as yawcast_shared::kernel::Real>::DEG2RAD;
    let (s1, c1) = libm::sincosf(r);
    let (s2, c2) = libm::sincosf(r + r);
    assert!((s1 - 0.5).abs() < 1e-6 && (s2 - 0.866_025_4).abs() < 1e-6);
    let wind = Effect::Wind {
        beta_s2: 0.1,
        beta_c2: 0.2,
        beta_s1: 0.3,
        beta_c1: 0.4,
    };
    let v = u + 0.1 * s2 + 0.2 * c2 + 0.3 * s1 + 0.4 * c1;
    assert_eq!(x_after_one(&[wind], u, y, Some(psi)), expected(v, y));
    let cur = Effect::Current {
        beta_s: 0.5,
        beta_c: -0.5,
    };
    let v = u + 0.5 * s1 + -0.5 * c1;
    assert_eq!(x_after_one(&[cur], u, y, Some(psi)), expected(v, y));
    // non-finite heading falls back to the integrated one (0 at start)
    assert_eq!(
        x_after_one(&[cur], u, y, Some(f32::NAN)),
        expected(u + 0.5 * 0.0 + -0.5 * 1.0, y)
    );
}

#[test]
fn heading_integrates_rate_minus_gyro_bias() {
    let current = Effect::Current {
        beta_s: 0.0,
        beta_c: 0.0,
    };
    let m = model(&[Effect::GyroBias { d_y: 0.5 }, current]);
    let mut p = Predictor::<4>::new(&m).unwrap();
    p.update_with_heading(0.0, 2.5, Some(10.0));
    assert_eq!(p.state().psi, 10.0 + 0.5 * (2.5 - 0.5));
    p.update(0.0, 4.5);
    assert_eq!(p.state().psi, 11.0 + 0.5 * 4.0);
    // without a heading effect nothing reads ψ: it is neither taken nor integrated
    let mut p = Predictor::<4>::new(&model(&[Effect::GyroBias { d_y: 0.5 }])).unwrap();
    p.update_with_heading(0.0, 2.5, Some(10.0));
    p.update(0.0, 4.5);
    assert_eq!(p.state().psi, 0.0);
    let mut p = Predictor::<4>::new(&model(&[])).unwrap();
    p.update_with_heading(0.0, 2.5, Some(10.0));
    assert_eq!(p.state().psi, 0.0);
}

#[test]
fn failures_are_values() {
    let mut p = Predictor::<4>::new(&model(&[])).unwrap();
    p.update(1.0, 1.0);
    let before = p.state();
    let mut out = [0.0f32; 65];
    assert_eq!(
        p.predict_into(&mut out, &[0.0; 64]),
        Err(PredictorError::HorizonOutOfRange(65))
    );
    assert_eq!(
        p.predict_into(&mut [], &[]),
        Err(PredictorError::HorizonOutOfRange(0))
    );
    assert_eq!(
        p.predict_into(&mut out[..5], &[1.0, f32::NAN, 0.0, 0.0]),
        Err(PredictorError::NonFinite)
    );
    assert_eq!(
        p.predict_into(&mut out[..5], &[1.0, 1.0, 1.0, f32::INFINITY]),
        Err(PredictorError::NonFinite)
    );
    assert_eq!(p.state(), before);
    assert_eq!(p.update(f32::NAN, 0.0), UpdateStatus::NonFiniteReset);
    assert_eq!(p.state(), PredictorState::ZERO);
    let m = model(&[Effect::DeadTime { samples: 2 }]);
    let mut p = Predictor::<4>::new(&m).unwrap();
    let mut s = p.state();
    s.delay_head = 2;
    assert_eq!(p.restore(s), Err(PredictorError::InvalidState));
    s.delay_head = 1;
    s.delay[5] = f32::NAN; // beyond the dead time: unused
    assert_eq!(p.restore(s), Ok(()));
    let mut bad = model(&[]);
    bad.k[0] = 3.0;
    assert_eq!(
        Predictor::<4>::new(&bad).unwrap_err(),
        PredictorError::InvalidModel(ModelError::UnstablePredictor)
    );
}
