//! Criterion benchmarks of the prediction-error identification: 2 000 samples at order 4
//! (cold start and warm start), and the cost's growth with the record length.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use yawcast::identify::model::Model;
use yawcast::identify::pem::{self, PemConfig};
use yawcast::identify::predict::Stepper;
use yawcast::io::data::Record;

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

/// PRBS-like input, white innovations (std 0.05).
fn record(seed: u64, len: usize) -> Record {
    let m = truth();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut u = Vec::with_capacity(len);
    while u.len() < len {
        let hold = rng.random_range(3..=15);
        let a = [5.0, 10.0, 20.0][rng.random_range(0..3)];
        let s = if rng.random::<bool>() { a } else { -a };
        u.extend(std::iter::repeat(s).take(hold));
    }
    u.truncate(len);
    let s = Stepper::new(&m);
    let mut st = s.initial(&[], 0.0);
    let y: Vec<f64> = u
        .iter()
        .map(|&ut| {
            let yt = s.output(&st) + 0.05 * normal(&mut rng);
            s.step(&mut st, ut, yt, None);
            yt
        })
        .collect();
    Record::from_uy("bench", 1.0, u, y)
}

fn bench_pem(c: &mut Criterion) {
    let rec = vec![record(1, 2000)];
    let cfg = PemConfig::default();
    let rep = pem::identify(&rec, None, &cfg).unwrap();
    eprintln!(
        "pem n=4 N=2000: {} LM iterations ({:?}, start {:?}), cost {:.3e}",
        rep.iterations, rep.termination, rep.start, rep.cost
    );
    let mut g = c.benchmark_group("pem");
    g.sample_size(20);
    g.bench_function("identify_n4_N2000", |b| {
        b.iter(|| pem::identify(&rec, None, &cfg).unwrap())
    });
    let warm = rep.model.clone();
    g.bench_function("identify_from_n4_N2000_warm", |b| {
        b.iter(|| pem::identify_from(&rec, &warm, &cfg).unwrap())
    });
    for n in [500usize, 1000, 2000, 4000, 8000] {
        let r = vec![record(2, n)];
        g.bench_with_input(BenchmarkId::new("identify_n4_vs_N", n), &r, |b, r| {
            b.iter(|| pem::identify(r, None, &cfg).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench_pem);
criterion_main!(benches);
