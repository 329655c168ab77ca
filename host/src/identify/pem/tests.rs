//! Tests of the identification: recovery of a known model, calibrated STDs, regularisation,
//! effects, order selection and bad input.

use super::testdata::{self, truth};
use super::*;
use crate::identify::model::Effect;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

#[test]
fn recovers_the_true_model_within_three_std() {
    let rec = testdata::record(1, 2000);
    let rep = identify(&[rec], None, &PemConfig::default()).unwrap();
    let th = params_of(&truth());
    let est = params_of(&rep.model);
    for i in 0..th.len() {
        let z = (est[i] - th[i]) / rep.std[i];
        assert!(
            z.abs() < 3.0,
            "{}: est {} truth {} std {} ({:?})",
            rep.names[i],
            est[i],
            th[i],
            rep.std[i],
            rep.termination
        );
    }
    // the innovation variance is recovered
    assert!((rep.sigma2 / 0.0025 - 1.0).abs() < 0.1, "σ² {}", rep.sigma2);
    assert!(rep.model.is_stable());
}

#[test]
fn held_out_five_step_fit_matches_the_true_model() {
    let est = identify(&[testdata::record(2, 2000)], None, &PemConfig::default())
        .unwrap()
        .model;
    let val = testdata::record(1002, 2000);
    let f_est = predict::fit_at(&est, &val, Horizon::Steps(5));
    let f_true = predict::fit_at(&truth(), &val, Horizon::Steps(5));
    assert!(
        (f_est - f_true).abs() < 0.5,
        "estimated {f_est:.3} % vs true {f_true:.3} %"
    );
}

/// 50 seeds: the reported STDs match the empirical spread of the estimates within a factor
/// of two, and the mean estimate is within 3 standard errors of the truth.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with --release")]
fn reported_std_matches_empirical_spread_over_50_seeds() {
    let reps: Vec<PemReport> = (0..50u64)
        .into_par_iter()
        .map(|s| {
            let cfg = PemConfig {
                parallel: false,
                ..PemConfig::default()
            };
            identify(&[testdata::record(100 + s, 2000)], None, &cfg).unwrap()
        })
        .collect();
    let th = params_of(&truth());
    let p = th.len();
    for i in 0..p {
        let vals: Vec<f64> = reps.iter().map(|r| params_of(&r.model)[i]).collect();
        let mean = vals.iter().sum::<f64>() / 50.0;
        let emp = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 49.0).sqrt();
        let rep_std = reps.iter().map(|r| r.std[i]).sum::<f64>() / 50.0;
        let ratio = rep_std / emp;
        assert!(
            (0.5..2.0).contains(&ratio),
            "{}: reported {rep_std:.3e} empirical {emp:.3e}",
            reps[0].names[i]
        );
        assert!(
            (mean - th[i]).abs() < 3.0 * emp / 50f64.sqrt() + 1e-12,
            "{}: mean {mean} truth {}",
            reps[0].names[i],
            th[i]
        );
    }
}

#[test]
fn larger_lambda_shrinks_the_parameters_and_their_std_pct() {
    // Mild regularisation (the penalty stays below the residual sum): every step up in λ
    // pulls ‖θ‖ and the mean STD% down.
    let rec = testdata::record(3, 2000);
    let norm = |m: &Model| params_of(m).iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut last_norm = f64::INFINITY;
    let mut last_pct = f64::INFINITY;
    for lambda in [0.0, 1e-3, 3e-3, 1e-2] {
        let cfg = PemConfig {
            lambda,
            ..PemConfig::default()
        };
        let rep = identify(std::slice::from_ref(&rec), None, &cfg).unwrap();
        let nm = norm(&rep.model);
        let pct = rep.std_pct.iter().sum::<f64>() / rep.std_pct.len() as f64;
        assert!(nm < last_norm, "λ={lambda}: ‖θ‖ {nm} !< {last_norm}");
        assert!(pct < last_pct, "λ={lambda}: mean STD% {pct} !< {last_pct}");
        last_norm = nm;
        last_pct = pct;
    }
}

#[test]
fn regularised_std_pct_falls_for_weak_parameters() {
    // λR pulls on the small b's (large STD%) only: their STD% falls.
    let rec = testdata::record(4, 600);
    let plain = identify(std::slice::from_ref(&rec), None, &PemConfig::default()).unwrap();
    let mut r = vec![0.0; 12];
    for w in &mut r[4..8] {
        *w = 1.0;
    }
    let cfg = PemConfig {
        lambda: 5.0,
        r: Some(r),
        ..PemConfig::default()
    };
    let reg = identify(&[rec], None, &cfg).unwrap();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        reg.std[4..8]
            .iter()
            .zip(&plain.std[4..8])
            .all(|(a, b)| a < b),
        "{:?} vs {:?}",
        reg.std,
        plain.std
    );
    assert!(mean(&reg.std[..4]) > 0.0);
}

#[test]
fn multi_record_identification_uses_one_initial_state_per_record() {
    let recs: Vec<Record> = (0..3).map(|s| testdata::record(10 + s, 700)).collect();
    let rep = identify(&recs, None, &PemConfig::default()).unwrap();
    assert_eq!(rep.x0.len(), 3);
    assert_eq!(rep.fit.len(), 3);
    assert_eq!(rep.samples, 2100);
    let f = predict::fit_at(&rep.model, &testdata::record(99, 1000), Horizon::Steps(5));
    let t = predict::fit_at(&truth(), &testdata::record(99, 1000), Horizon::Steps(5));
    assert!((f - t).abs() < 1.0, "{f} vs {t}");
}

#[test]
fn effects_are_estimated_with_the_linear_part() {
    // DC gain ≈ 18 (deg/s per deg): small commands, gentle damping
    let t = truth()
        .with_effect(Effect::Bias { beta: 0.1 })
        .with_effect(Effect::NonlinearDamping {
            beta: -2e-4,
            cubic: false,
        })
        .with_effect(Effect::GyroBias { d_y: 0.5 });
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let u = testdata::prbs(&mut rng, 3000, &[0.5, 1.0, 2.0]);
    let rec = testdata::simulate_innovations(&t, &u, 0.05, &mut rng, "fx", false);
    let template = t.clone();
    let rep = identify(&[rec], Some(&template), &PemConfig::default()).unwrap();
    let th = params_of(&t);
    let est = params_of(&rep.model);
    for i in 12..15 {
        let z = (est[i] - th[i]) / rep.std[i];
        assert!(
            z.abs() < 4.0,
            "{}: {} vs {} ± {}",
            rep.names[i],
            est[i],
            th[i],
            rep.std[i]
        );
    }
}

#[test]
fn order_selection_prefers_four() {
    let recs = vec![testdata::record(7, 2000)];
    let lines = select_order(&recs, &[2, 3, 4, 5, 6], &PemConfig::default()).unwrap();
    assert_eq!(lines.len(), 5);
    let best_bic = lines
        .iter()
        .filter(|l| l.error.is_none())
        .min_by(|a, b| a.bic.total_cmp(&b.bic))
        .unwrap();
    assert_eq!(best_bic.order, 4, "{lines:#?}");
    assert!(lines[0].fit["5"] < lines[2].fit["5"]);
}

#[test]
fn too_few_samples_says_how_many_are_needed() {
    let rec = testdata::record(8, 40);
    let e = identify(&[rec], None, &PemConfig::default()).unwrap_err();
    assert!(
        matches!(
            e,
            IdentError::TooFewSamples {
                needed: 64,
                found: 40,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("at least 64"), "{e}");
    let short = testdata::record(8, 5);
    let e = identify(&[short], None, &PemConfig::default()).unwrap_err();
    assert!(e.to_string().contains("needs at least 10"), "{e}");
}

#[test]
fn constant_input_names_the_record() {
    let mut rec = testdata::record(9, 500);
    rec.name = "lake-3".into();
    rec.u = vec![5.0; 500];
    let e = identify(&[rec], None, &PemConfig::default()).unwrap_err();
    assert!(e.to_string().contains("`lake-3`"), "{e}");
    assert!(e.to_string().contains("constant"), "{e}");
}

#[test]
fn non_finite_data_is_named() {
    let mut rec = testdata::record(9, 500);
    rec.y[123] = f64::NAN;
    let e = identify(&[rec], None, &PemConfig::default()).unwrap_err();
    assert!(
        matches!(&e, IdentError::NonFinite { record, channel: "y", sample: 123, .. } if record == "seed9"),
        "{e}"
    );
    assert!(e.to_string().contains("y sample 123"), "{e}");
}

#[test]
fn bad_settings_are_refused() {
    let rec = testdata::record(9, 500);
    let cfg = PemConfig {
        lambda: 1.0,
        r: Some(vec![1.0; 3]),
        ..PemConfig::default()
    };
    let e = identify(std::slice::from_ref(&rec), None, &cfg).unwrap_err();
    assert!(e.to_string().contains("R has 3 weights"), "{e}");
    let cfg = PemConfig {
        order: 9,
        ..PemConfig::default()
    };
    assert_eq!(
        identify(&[rec], None, &cfg).unwrap_err(),
        IdentError::Order(9)
    );
    assert_eq!(
        identify(&[], None, &PemConfig::default()).unwrap_err(),
        IdentError::NoRecords
    );
}

#[test]
fn unstable_start_is_refused() {
    let rec = testdata::record(9, 500);
    let mut m = truth();
    m.a[3] = 1.5;
    assert_eq!(
        identify_from(&[rec], &m, &PemConfig::default()).unwrap_err(),
        IdentError::StartUnstable
    );
}

#[test]
fn warm_start_converges_to_the_same_optimum() {
    let rec = testdata::record(12, 1500);
    let cold = identify(std::slice::from_ref(&rec), None, &PemConfig::default()).unwrap();
    let warm = identify_from(&[rec], &truth(), &PemConfig::default()).unwrap();
    assert!(
        (cold.cost - warm.cost).abs() < 1e-9 * cold.cost,
        "{} {}",
        cold.cost,
        warm.cost
    );
    assert!(warm.iterations <= cold.iterations + 5);
}

/// The built-in ship with a hidden 2 s actuator dead time seen through a 4th-order model: the
/// one-step cost has more than one minimum. With the subspace start the search never ends
/// higher than from the ARX and ARMAX starts alone, and on some records it ends clearly lower
/// (a different basin), with better long-horizon predictions on a held-out record.
#[test]
fn subspace_start_reaches_lower_one_step_minima_on_a_dead_time_ship() {
    use yawcast_shared::model::EffectKind;
    let rec = |seed: u64| testdata::ship_records(EffectKind::DeadTime, &[seed]).remove(0);
    // the lowest cost wins here: this is about the minima the starts reach
    let lowest = PemConfig {
        select_horizons: vec![],
        ..PemConfig::default()
    };
    let arx_only = PemConfig {
        starts: vec![Start::Arx, Start::Armax],
        ..lowest.clone()
    };
    let mut lower = 0;
    for seed in 1..=4u64 {
        let est = [rec(seed)];
        let val = rec(100 + seed);
        let old = identify(&est, None, &arx_only).unwrap();
        let new = identify(&est, None, &lowest).unwrap();
        let f = |m: &Model| predict::fit_at(m, &val, Horizon::Steps(10));
        println!(
            "seed {seed}: cost {:.5} → {:.5} ({:?}), held-out 10-step {:.2} → {:.2}",
            old.cost,
            new.cost,
            new.start,
            f(&old.model),
            f(&new.model)
        );
        assert!(
            new.cost <= old.cost * (1.0 + 1e-9),
            "{} > {}",
            new.cost,
            old.cost
        );
        if new.cost < 0.99 * old.cost {
            lower += 1;
            assert_eq!(new.start, Start::Subspace);
            assert!(f(&new.model) > f(&old.model));
        }
    }
    assert!(
        lower >= 3,
        "the subspace start found a lower minimum on {lower} of 4 records"
    );
}

/// Records with a constant yaw moment the structure has no effect for: from the subspace
/// start the search parks the predictor's pole a hair inside the unit circle and lets x̂(0)
/// carry the offset (lower one-step cost). Such a predictor never forgets its initial state,
/// so the search prefers the minimum from the other starts, whose predictor does.
#[test]
fn a_predictor_that_never_forgets_its_initial_state_loses_to_one_that_does() {
    use yawcast_shared::model::EffectKind;
    let est = testdata::ship_records(EffectKind::Bias, &[1, 2, 3]);
    let only = PemConfig {
        starts: vec![Start::Subspace],
        ..PemConfig::default()
    };
    let sub = identify(&est, None, &only).unwrap();
    let all = identify(&est, None, &PemConfig::default()).unwrap();
    let len = est[0].len() as f64;
    let (_, rho_sub) = sub.model.spectral_radii();
    let (_, rho_all) = all.model.spectral_radii();
    println!(
        "subspace alone: cost {:.6}, predictor radius {rho_sub:.9}; all starts: cost {:.6}, radius {rho_all:.6} ({:?})",
        sub.cost, all.cost, all.start
    );
    assert!(rho_sub.powf(len) > 0.01, "{rho_sub}");
    assert!(rho_all.powf(len) <= 0.01, "{rho_all}");
    assert!(sub.cost < all.cost);
    assert_ne!(all.start, Start::Subspace);
}

/// The same ship with a dead time, on seeds where the ARX/ARMAX minimum has the lowest
/// one-step cost by 1.3–1.4 % but predicts poorly beyond one step: the difference in one-step
/// cost is within its sampling spread, the subspace minimum's 5/10/20-step errors are
/// significantly smaller, so it is taken — and predicts a held-out record better. On the
/// clean ship the starts agree (or the lowest is also the better predictor): no choice.
#[test]
fn an_equally_good_one_step_minimum_that_predicts_further_wins() {
    use yawcast_shared::model::EffectKind;
    let rec = |kind, seed: u64| testdata::ship_records(kind, &[seed]).remove(0);
    let lowest = PemConfig {
        select_horizons: vec![],
        ..PemConfig::default()
    };
    for seed in [101u64, 109] {
        let est = [rec(EffectKind::DeadTime, seed)];
        let val = rec(EffectKind::DeadTime, seed + 100);
        let old = identify(&est, None, &lowest).unwrap();
        let new = identify(&est, None, &PemConfig::default()).unwrap();
        let f = |m: &Model| predict::fit_at(m, &val, Horizon::Steps(10));
        let c = new.choice.clone().expect("a choice");
        println!(
            "seed {seed}: {:?} → {:?}, held-out 10-step {:.2} → {:.2}; {}",
            old.start,
            new.start,
            f(&old.model),
            f(&new.model),
            c.describe(new.start)
        );
        assert_eq!(new.start, Start::Subspace);
        assert_eq!(c.lowest, old.start);
        assert!((new.cost / old.cost - c.cost_ratio).abs() < 1e-12);
        assert!(c.cost_ratio > 1.005 && c.z < choose::Z_EQUAL, "{c:?}");
        assert!(
            c.multi_step_z < -choose::Z_EQUAL && c.multi_step_ratio < 0.9,
            "{c:?}"
        );
        assert!(f(&new.model) > f(&old.model) + 1.0);
    }
    for seed in 1..=3u64 {
        let est = [testdata::ship_records(EffectKind::Bias, &[seed]).remove(0)];
        let clean = crate::sim::simulate_many(
            &crate::sim::Ship::default_lng(),
            &crate::sim::Scenario::default(),
            &[seed],
        )
        .unwrap();
        for recs in [&est[..], &clean[..]] {
            let a = identify(recs, None, &lowest).unwrap();
            let b = identify(recs, None, &PemConfig::default()).unwrap();
            assert!(b.choice.is_none(), "seed {seed}: {:?}", b.choice);
            assert_eq!(a.model, b.model);
        }
    }
}
