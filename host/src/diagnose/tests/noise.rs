//! Trials logged by other sensors than the reference: noisier (the reference given their
//! noise, the model's Kalman gain re-fitted) and quieter (the trials given the reference's).

use super::*;

/// Mariner's records as `bench/worlds/run.sh` sails them: the world's identification input,
/// `noise` the gyro (°/s), heading (°) and speed (m/s) noise, the hidden effects given.
fn mariner(noise: [f64; 3], effects: Vec<SimEffect>, seeds: &[u64]) -> Vec<Record> {
    let k = crate::sim::WorldKind::Mariner;
    super::worlds::noisy_records(k, effects, seeds, false, noise)
}

/// Mariner's hidden effect `kind` at full strength.
fn hidden(kind: EffectKind) -> Vec<SimEffect> {
    let w = crate::sim::World::new(crate::sim::WorldKind::Mariner, None).unwrap();
    vec![w.hidden(kind, 1.0)]
}

#[test]
fn trials_logged_with_noisier_sensors_are_measured_against_a_reference_as_noisy() {
    // Mariner's reference sailed as the suite sails it (gyro 0.02 °/s, heading 0.1°), the
    // trials logged with sensors 4 times noisier (a ship's MEMS gyro against a quiet rig;
    // `run.sh --trial-noise-scale 4`, seed 1). Against the reference as given the
    // effect-free trials read `nonlinear-damping`, the trials' noise carried through a
    // Kalman gain fitted to quieter records; against the reference given the trials' noise
    // and the gain re-fitted on it, `none`, and a hidden dead time is still named
    let reference = mariner([0.02, 0.1, 0.02], Vec::new(), &[900, 901, 902]);
    let model = identify(&reference);
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    for (kind, named) in [(None, "none"), (Some(EffectKind::DeadTime), "dead-time")] {
        let trials = mariner(
            [0.12, 0.8, 0.08],
            kind.map(hidden).unwrap_or_default(),
            &[101, 102, 103],
        );
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        let matched = d.caveats.iter().find_map(|c| match c {
            Caveat::NoisierTrials {
                trials_noise_degps,
                reference_noise_degps,
                gain_10_given,
                gain_10,
                ..
            } => Some([
                *trials_noise_degps,
                *reference_noise_degps,
                *gain_10_given,
                *gain_10,
            ]),
            _ => None,
        });
        println!("{kind:?}: {} ({:?}); {matched:?}", d.verdict, d.then);
        assert_eq!(d.verdict, named, "{}", d.explanation);
        let [noise, r, given, gain] = matched.expect("noisier-trials caveat");
        // the gyros' 0.12 and 0.02 °/s (the hull's own motion adds a little to both)
        assert!(
            (noise - 0.12).abs() < 0.012 && (r - 0.02).abs() < 0.004,
            "{noise} {r}"
        );
        assert!(gain < given, "{gain} {given}");
        assert!(d.explanation.contains("Kalman gain re-fitted on them"));
        if kind.is_none() {
            // the method against the reference as given: a false alarm
            let given = run(&model, &reference, &trials, None, &[], &cfg, Against::Given).unwrap();
            println!("as given: {} ({:?})", given.verdict, given.then);
            assert_eq!(given.verdict, "nonlinear-damping", "{}", given.explanation);
        }
    }
}

#[test]
fn trials_logged_with_quieter_sensors_are_given_the_references_noise() {
    // Mariner's reference as the suite sails it (gyro 0.02 °/s), the trials logged with
    // sensors 10 times quieter than the suite's (a tank's or a simulator's clean records
    // against a reference sailed with a ship's gyro; `run.sh --trial-noise-scale 0.1`, seed
    // 1). Against the reference's noise the hull's own nonlinearity, which the linear model
    // misses alike in both sets, shows in the quiet trials alone: effect-free, they read
    // `nonlinear-damping`; given the reference's noise, `none`, and a hidden angle limit is
    // still named
    let reference = mariner([0.02, 0.1, 0.02], Vec::new(), &[900, 901, 902]);
    let model = identify(&reference);
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    let quiet = [0.003, 0.02, 0.002];
    for (kind, named) in [(None, "none"), (Some(EffectKind::Saturation), "saturation")] {
        let trials = mariner(
            quiet,
            kind.map(hidden).unwrap_or_default(),
            &[100, 101, 102],
        );
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        let quieted = d.caveats.iter().find_map(|c| match c {
            Caveat::QuieterTrials {
                trials_noise_degps,
                reference_noise_degps,
                added_noise_degps,
            } => Some([
                *trials_noise_degps,
                *reference_noise_degps,
                *added_noise_degps,
            ]),
            _ => None,
        });
        println!("{kind:?}: {} ({:?}); {quieted:?}", d.verdict, d.then);
        assert_eq!(d.verdict, named, "{}", d.explanation);
        assert_eq!(d.then, None, "{}", d.explanation);
        let [noise, r, added] = quieted.expect("quieter-trials caveat");
        // the gyros' 0.003 and 0.02 °/s
        assert!(
            (noise - 0.003).abs() < 0.0006 && (r - 0.02).abs() < 0.004,
            "{noise} {r}"
        );
        assert!((added * added + noise * noise - r * r).abs() < 1e-12);
        assert!(d.explanation.contains("the trials were given white noise"));
        assert!(!d
            .caveats
            .iter()
            .any(|c| matches!(c, Caveat::NoisierTrials { .. })));
        if kind.is_none() {
            // the method on the trials as logged: a false alarm
            let logged = run(&model, &reference, &trials, None, &[], &cfg, Against::Given).unwrap();
            println!("as logged: {} ({:?})", logged.verdict, logged.then);
            assert_eq!(
                logged.verdict, "nonlinear-damping",
                "{}",
                logged.explanation
            );
        }
    }
}
