//! Criterion benchmarks of the simulator (one 1 800-sample record), `diagnose` on 3 + 3
//! records of 1 800 samples (with and without the confirming refit) and on 3 600 samples
//! (one reference and one trial record, the CLI's smallest honest use; again with the trial
//! logged by a noisier gyro), and `augment` with a dead time.

use criterion::{criterion_group, criterion_main, Criterion};
use yawcast::diagnose::augment::{self, AugmentConfig};
use yawcast::diagnose::{self, DiagnoseConfig};
use yawcast::identify::pem::{self, PemConfig};
use yawcast::sim::{self, NoiseSpec, Scenario, Ship, SimEffect};
use yawcast_shared::model::EffectKind;

fn scenario(effects: Vec<SimEffect>) -> Scenario {
    Scenario {
        noise: NoiseSpec {
            gyro_std_degps: 0.03,
            heading_std_deg: 0.1,
            speed_std_mps: 0.01,
        },
        effects,
        ..Scenario::default()
    }
}

fn bench(c: &mut Criterion) {
    let ship = Ship::default_lng();
    let clean = scenario(Vec::new());
    let trial = scenario(vec![SimEffect::hidden(EffectKind::DeadTime, 1.0)]);
    c.bench_function("sim/record_1800", |b| {
        b.iter(|| sim::simulate(&ship, &clean, 1).unwrap())
    });
    let reference = sim::simulate_many(&ship, &clean, &[1, 2, 3]).unwrap();
    let est = sim::simulate_many(&ship, &trial, &[11, 12, 13]).unwrap();
    let val = sim::simulate_many(&ship, &trial, &[21]).unwrap();
    let model = pem::identify(&reference, None, &PemConfig::default())
        .unwrap()
        .model;
    let cfg = DiagnoseConfig::default();
    let d = diagnose::diagnose(&model, &reference, &est, &val, &cfg).unwrap();
    eprintln!("diagnose verdict on a 2 s dead time: {}", d.verdict);
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(10);
    g.bench_function("ref3_trials3_N1800", |b| {
        b.iter(|| diagnose::diagnose(&model, &reference, &est, &val, &cfg).unwrap())
    });
    let quick = DiagnoseConfig {
        confirm: false,
        ..DiagnoseConfig::default()
    };
    g.bench_function("ref3_trials3_N1800_no_confirm", |b| {
        b.iter(|| diagnose::diagnose(&model, &reference, &est, &val, &quick).unwrap())
    });
    // 3 600 samples in all: one reference record, one trial record (its last 30 % held out)
    g.bench_function("ref1_trial1_3600_samples", |b| {
        b.iter(|| diagnose::diagnose(&model, &reference[..1], &est[..1], &[], &cfg).unwrap())
    });
    // the same, the trial logged with a gyro 4 times noisier than the reference's: the
    // reference given the trial's noise and the Kalman gain re-fitted on it first
    let noisy = Scenario {
        noise: NoiseSpec {
            gyro_std_degps: 0.12,
            ..trial.noise
        },
        ..trial.clone()
    };
    let noisy = sim::simulate_many(&ship, &noisy, &[11]).unwrap();
    g.bench_function("ref1_trial1_3600_samples_noisier_trial", |b| {
        b.iter(|| diagnose::diagnose(&model, &reference[..1], &noisy, &[], &cfg).unwrap())
    });
    g.bench_function("augment_dead_time_trials3_N1800", |b| {
        b.iter(|| {
            augment::augment(
                &model,
                EffectKind::DeadTime,
                &est,
                &val,
                &AugmentConfig::default(),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
