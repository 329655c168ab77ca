//! Unit tests of the genetic algorithm.

use super::*;
use crate::identify::model::Effect;
use crate::identify::pem::testdata;

/// Synthetic "simulator": the known 4th-order model; trials add a dead time of the pods
/// (hidden) and more noise.
fn scenario(records: usize, len: usize) -> (Vec<Record>, Vec<Record>) {
    let t = testdata::truth();
    let hidden = t.clone().with_effect(Effect::DeadTime { samples: 2 });
    let mut sim = Vec::new();
    let mut trials = Vec::new();
    for i in 0..records as u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + i);
        let u = testdata::prbs(&mut rng, len, &[5.0, 10.0, 20.0]);
        sim.push(testdata::simulate_innovations(
            &t,
            &u,
            0.02,
            &mut rng,
            &format!("sim{i}"),
            false,
        ));
        let mut rng = ChaCha8Rng::seed_from_u64(5000 + i);
        let u = testdata::prbs(&mut rng, len, &[5.0, 10.0, 20.0]);
        trials.push(testdata::simulate_innovations(
            &hidden,
            &u,
            0.2,
            &mut rng,
            &format!("lake{i}"),
            false,
        ));
    }
    (sim, trials)
}

fn base(sim: &[Record]) -> Model {
    pem::identify(sim, None, &PemConfig::default())
        .unwrap()
        .model
}

#[test]
fn decode_is_linear_or_logarithmic() {
    let mid = decode(4096, 13, (1e-8, 200.0), false);
    assert!((mid - 200.0 * 4096.0 / 8191.0).abs() < 1e-6);
    let mid = decode(4096, 13, (1e-8, 100.0), true);
    assert!((mid.log10() - (-8.0 + 10.0 * 4096.0 / 8191.0)).abs() < 1e-9);
}

#[test]
fn genome_layouts() {
    let m = testdata::truth();
    let g = Genome::new(&m, true);
    assert_eq!(g.len, 4);
    assert_eq!(g.r_gene, vec![0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]);
    let g = Genome::new(&m, false);
    assert_eq!(g.len, 13);
    let m = m.with_effect(Effect::Bias { beta: 0.0 });
    assert_eq!(Genome::new(&m, true).len, 5);
}

#[test]
fn a_centre_of_the_wrong_length_is_a_config_error() {
    let (sim, trials) = scenario(2, 300);
    let b = base(&sim);
    let cfg = GaConfig {
        max_generations: 1,
        progress: false,
        centres: vec![None, Some(vec![0.0; 5])],
        ..GaConfig::default()
    };
    let e = tune(&sim, &trials, &b, &cfg).unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad GA setting: penalty centre 1 has 5 values (finite ones needed: 12, one per parameter)"
    );
}

#[test]
fn short_run_is_reproducible_and_never_worse_than_conventional() {
    let (sim, trials) = scenario(3, 400);
    let b = base(&sim);
    let cfg = GaConfig {
        max_generations: 4,
        progress: false,
        seed: 7,
        std_limit: f64::INFINITY,
        ..GaConfig::default()
    };
    let a = tune(&sim, &trials, &b, &cfg).unwrap();
    let c = tune(&sim, &trials, &b, &cfg).unwrap();
    assert_eq!(a.best_model, c.best_model);
    assert_eq!(a.genes, c.genes);
    assert_eq!(a.history, c.history);
    // elitism: the best never gets worse
    for w in a.history.windows(2) {
        assert!(w[1].best_fit >= w[0].best_fit);
    }
    let conv = a.conventional.as_ref().unwrap();
    assert!(
        a.best_fit >= conv.fitness - 1e-3,
        "{} vs {}",
        a.best_fit,
        conv.fitness
    );
}

#[test]
fn joint_identification_mode_runs() {
    let (sim, trials) = scenario(3, 400);
    let b = base(&sim);
    let cfg = GaConfig {
        max_generations: 2,
        progress: false,
        combine: Combine::Joint,
        grouped: false,
        log_scale: true,
        std_limit: f64::INFINITY,
        ..GaConfig::default()
    };
    let mut seen = Vec::new();
    let rep = tune_with(&sim, &trials, &b, &cfg, &mut |g| seen.push(g.generation)).unwrap();
    assert_eq!(seen, vec![1, 2]);
    assert_eq!(rep.genes.len(), 13);
    assert_eq!(rep.r.len(), 12);
    let conv = rep.conventional.as_ref().unwrap();
    assert!(rep.best_fit >= conv.fitness - 1e-3);
}

#[test]
fn every_candidate_rejected_is_an_error_naming_the_cause() {
    let (sim, trials) = scenario(2, 300);
    let b = base(&sim);
    let cfg = GaConfig {
        max_generations: 2,
        progress: false,
        std_limit: 1e-9,
        ..GaConfig::default()
    };
    let e = tune(&sim, &trials, &b, &cfg).unwrap_err();
    assert!(
        matches!(e, GaError::AllRejected { std_rule, .. } if std_rule > 0),
        "{e}"
    );
    assert!(e.to_string().contains("STD rule"), "{e}");
}

#[test]
fn bad_settings_are_refused() {
    let (sim, trials) = scenario(1, 300);
    let b = base(&sim);
    let cfg = GaConfig {
        population: 1,
        ..GaConfig::default()
    };
    assert!(matches!(
        tune(&sim, &trials, &b, &cfg),
        Err(GaError::Config(_))
    ));
    assert_eq!(
        tune(&[], &trials, &b, &GaConfig::default()).unwrap_err(),
        GaError::NoSimulation
    );
    let mut bad = trials.clone();
    bad[0].y[7] = f64::NAN;
    let e = tune(&sim, &bad, &b, &GaConfig::default()).unwrap_err();
    assert!(e.to_string().contains("y sample 7 is not finite"), "{e}");
    bad[0].y.pop();
    let e = tune(&sim, &bad, &b, &GaConfig::default()).unwrap_err();
    assert!(e.to_string().contains("lengths differ"), "{e}");
    assert_eq!(
        tune(&sim, &[], &b, &GaConfig::default()).unwrap_err(),
        GaError::NoTrials
    );
}

/// 15 + 15 records: the tuned averaged model beats the conventional averaged model at 5
/// and 10 steps on the trials, and no tuned STD% exceeds 50.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with --release")]
fn tuned_model_beats_conventional_on_trials_with_a_hidden_effect() {
    let (sim, trials) = scenario(15, 1800);
    let b = base(&sim);
    let cfg = GaConfig {
        progress: false,
        seed: 1,
        ..GaConfig::default()
    };
    let t0 = std::time::Instant::now();
    let rep = tune(&sim, &trials, &b, &cfg).unwrap();
    let conv = rep.conventional.clone().unwrap();
    eprintln!(
        "GA: {:.1} s, {} generations ({:?}), {} evaluations, {} rejected; λ = {:.4}, \
         tuned {:?} vs conventional {:?}; tuned STD% {:?}; conventional STD% {:?}",
        t0.elapsed().as_secs_f64(),
        rep.generations,
        rep.termination,
        rep.evaluations,
        rep.rejected,
        rep.lambda,
        rep.tuned.fits,
        conv.fits,
        rep.tuned.std_pct,
        conv.std_pct
    );
    for k in ["5", "10"] {
        assert!(
            rep.tuned.fits[k] > conv.fits[k],
            "{k}-step: tuned {} vs conventional {}",
            rep.tuned.fits[k],
            conv.fits[k]
        );
    }
    assert!(
        rep.tuned.std_pct.iter().all(|v| *v <= 50.0),
        "{:?}",
        rep.tuned.std_pct
    );
    let again = tune(&sim, &trials, &b, &cfg).unwrap();
    assert_eq!(again.best_model, rep.best_model);
    // A real gain, record by record: the tuned model is the one to use.
    let g = rep.gain.as_ref().unwrap();
    assert!(g.tuned_kept && g.mean > 2.0 * g.se, "{g:?}");
    assert_eq!(rep.best_model, rep.tuned.model);
}

#[test]
fn a_gain_within_its_spread_keeps_the_conventional_model() {
    let (sim, trials) = scenario(3, 400);
    let b = base(&sim);
    let cfg = GaConfig {
        max_generations: 2,
        progress: false,
        seed: 3,
        std_limit: f64::INFINITY,
        ..GaConfig::default()
    };
    let rep = tune(&sim, &trials, &b, &cfg).unwrap();
    let conv = rep.conventional.clone().unwrap();
    let g = rep.gain.clone().unwrap();
    assert_eq!(g.records, trials.len());
    assert_eq!(g.tuned_kept, g.mean > 0.0 && g.mean > 2.0 * g.se, "{g:?}");
    if g.tuned_kept {
        assert_eq!(rep.best_model, rep.tuned.model);
    } else {
        assert_eq!(rep.best_model, conv.model);
        assert_eq!((rep.lambda, rep.best_fit), (0.0, conv.fitness));
    }
    // The conventional model as the GA's pick gains exactly nothing: it is kept as such,
    // with λ = 0 and R = 0.
    let same = GaReport {
        best_model: conv.model.clone(),
        gain: None,
        lambda: 0.5,
        r: vec![1.0; rep.r.len()],
        ..rep.clone()
    };
    let s = settle(same, &trials, &cfg);
    let g = s.gain.unwrap();
    assert_eq!((g.mean, g.se, g.tuned_kept), (0.0, 0.0, false));
    assert_eq!(s.best_model, conv.model);
    assert_eq!(s.lambda, 0.0);
    assert!(s.r.iter().all(|v| *v == 0.0));
}
