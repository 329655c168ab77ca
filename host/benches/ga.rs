//! Criterion benchmark of the GA: one generation on 15 simulation + 15 trial records of
//! 1 800 samples (population 8). With `YAWCAST_BENCH_FULL=1` it also times, once each, the
//! full 50-generation run and the run against the number of trial records and the record
//! length, and prints the figures.

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use yawcast::identify::model::{Effect, Model};
use yawcast::identify::pem::{self, PemConfig};
use yawcast::identify::predict::Stepper;
use yawcast::io::data::Record;
use yawcast::tune::ga::{self, GaConfig};

/// A stable 4th-order canonical model (A poles 0.95, 0.85, 0.6 ± 0.25i).
fn truth() -> Model {
    Model::new(
        1.0,
        vec![-0.34116875, 1.7295, -3.39, 3.0],
        vec![0.02, 0.075, 0.1472, 0.22694],
        vec![2.3, 3.56, 4.6435, 5.49578125],
    )
    .unwrap()
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn record(m: &Model, seed: u64, len: usize, sigma: f64, name: String) -> Record {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut u = Vec::with_capacity(len);
    while u.len() < len {
        let hold = rng.random_range(3..=15);
        let a = [5.0, 10.0, 20.0][rng.random_range(0..3)];
        let s = if rng.random::<bool>() { a } else { -a };
        u.extend(std::iter::repeat(s).take(hold));
    }
    u.truncate(len);
    let s = Stepper::new(m);
    let mut st = s.initial(&[], 0.0);
    let y: Vec<f64> = u
        .iter()
        .map(|&ut| {
            let yt = s.output(&st) + sigma * normal(&mut rng);
            s.step(&mut st, ut, yt, None);
            yt
        })
        .collect();
    Record::from_uy(&name, 1.0, u, y)
}

/// Clean simulation records of the truth; "lake trials" with a hidden rate limit and noise.
fn scenario(sims: usize, trials: usize, len: usize) -> (Vec<Record>, Vec<Record>) {
    let t = truth();
    let hidden = t.clone().with_effect(Effect::RateLimit { rate: 3.0 });
    let sim = (0..sims as u64)
        .map(|i| record(&t, 1000 + i, len, 0.02, format!("sim{i}")))
        .collect();
    let lake = (0..trials as u64)
        .map(|i| record(&hidden, 5000 + i, len, 0.2, format!("lake{i}")))
        .collect();
    (sim, lake)
}

fn full_run(sims: usize, trials: usize, len: usize, generations: usize) -> (f64, ga::GaReport) {
    full_run_centres(sims, trials, len, generations, false)
}

/// `two_centres`: one GA around zero and one around the all-records model (`yawcast tune`'s
/// default), instead of the paper's zero centre alone.
fn full_run_centres(
    sims: usize,
    trials: usize,
    len: usize,
    generations: usize,
    two_centres: bool,
) -> (f64, ga::GaReport) {
    let (sim, lake) = scenario(sims, trials, len);
    let base = pem::identify(&sim, None, &PemConfig::default())
        .unwrap()
        .model;
    let centres = if two_centres {
        vec![None, Some(base.theta())]
    } else {
        Vec::new()
    };
    let cfg = GaConfig {
        max_generations: generations,
        stall_generations: usize::MAX,
        progress: false,
        seed: 1,
        centres,
        ..GaConfig::default()
    };
    let t0 = Instant::now();
    let rep = ga::tune(&sim, &lake, &base, &cfg).unwrap();
    (t0.elapsed().as_secs_f64(), rep)
}

fn bench_ga(c: &mut Criterion) {
    let threads = rayon::current_num_threads();
    if std::env::var("YAWCAST_BENCH_FULL").is_ok_and(|v| v == "1") {
        let summary = |rep: &ga::GaReport| {
            let conv = rep.conventional.as_ref().unwrap();
            format!(
                "{} evaluations in the winning run, centre {}, {} rejected; 5/10-step fit tuned \
                 {:.2}/{:.2} % vs conventional {:.2}/{:.2} %",
                rep.evaluations,
                rep.centre,
                rep.rejected,
                rep.tuned.fits["5"],
                rep.tuned.fits["10"],
                conv.fits["5"],
                conv.fits["10"]
            )
        };
        let (s, rep) = full_run(15, 15, 1800, 50);
        eprintln!(
            "GA 15+15×1800, 50 generations, {threads} threads: {s:.2} s ({})",
            summary(&rep)
        );
        let (s, rep) = full_run_centres(15, 15, 1800, 50, true);
        eprintln!(
            "GA 15+15×1800, 50 generations per centre, two centres (tune's default), {threads} \
             threads: {s:.2} s ({})",
            summary(&rep)
        );
        for trials in [5usize, 15, 30] {
            let (s, rep) = full_run(15, trials, 1800, 10);
            eprintln!(
                "GA 15 sim + {trials} trials ×1800, 10 generations: {s:.2} s ({} evaluations)",
                rep.evaluations
            );
        }
        for len in [900usize, 1800, 3600] {
            let (s, rep) = full_run(15, 15, len, 10);
            eprintln!(
                "GA 15+15 × {len}, 10 generations: {s:.2} s ({} evaluations)",
                rep.evaluations
            );
        }
    }
    let (sim, lake) = scenario(15, 15, 1800);
    let base = pem::identify(&sim, None, &PemConfig::default())
        .unwrap()
        .model;
    let cfg = GaConfig {
        max_generations: 1,
        progress: false,
        ..GaConfig::default()
    };
    let mut g = c.benchmark_group("ga");
    g.sample_size(10);
    g.bench_function("first_generation_15x15x1800", |b| {
        b.iter(|| ga::tune(&sim, &lake, &base, &cfg).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench_ga);
criterion_main!(benches);
