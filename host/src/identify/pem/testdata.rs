//! Seeded test data: a known stable 4th-order canonical model driven by a PRBS-like input
//! with white-noise innovations.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::poly;
use crate::identify::model::Model;
use crate::identify::predict::Stepper;
use crate::io::data::Record;

/// The true model: A poles 0.95, 0.85, 0.6 ± 0.25i; predictor (C) roots 0.5, 0.3, −0.2, 0.1.
pub(crate) fn truth() -> Model {
    let a_roots = [
        nalgebra::Complex::new(0.95, 0.0),
        nalgebra::Complex::new(0.85, 0.0),
        nalgebra::Complex::new(0.6, 0.25),
        nalgebra::Complex::new(0.6, -0.25),
    ];
    let c_roots = [
        nalgebra::Complex::new(0.5, 0.0),
        nalgebra::Complex::new(0.3, 0.0),
        nalgebra::Complex::new(-0.2, 0.0),
        nalgebra::Complex::new(0.1, 0.0),
    ];
    let ap = poly::from_roots(&a_roots);
    let cp = poly::from_roots(&c_roots);
    let alpha: Vec<f64> = ap[1..].iter().map(|v| -v).collect();
    let beta = [0.02, 0.015, -0.01, 0.005];
    let (a, b, k) = poly::tf_to_canonical(&alpha, &beta, &cp[1..]);
    Model::new(1.0, a, b, k).unwrap()
}

pub(crate) use crate::stats::standard_normal as normal;

/// PRBS-like command: levels from `amps` (random sign), held for 3..=15 samples.
pub(crate) fn prbs(rng: &mut ChaCha8Rng, len: usize, amps: &[f64]) -> Vec<f64> {
    let mut u = Vec::with_capacity(len);
    while u.len() < len {
        let hold = rng.random_range(3..=15);
        let a = amps[rng.random_range(0..amps.len())];
        let s = if rng.random::<bool>() { a } else { -a };
        for _ in 0..hold {
            u.push(s);
        }
    }
    u.truncate(len);
    u
}

/// Simulates the innovations model `model` (with its effects) on command `u` with innovation
/// std `sigma`: `y = x̂₁ + d_y + e`, then the predictor step with that y (so e is exactly the
/// innovation). Heading is integrated from y when `heading` is set.
pub(crate) fn simulate_innovations(
    model: &Model,
    u: &[f64],
    sigma: f64,
    rng: &mut ChaCha8Rng,
    name: &str,
    heading: bool,
) -> Record {
    let s = Stepper::new(model);
    let mut st = s.initial(&[], 0.0);
    let mut y = Vec::with_capacity(u.len());
    let mut psi = Vec::with_capacity(u.len());
    let mut p = 0.0;
    for &ut in u {
        let yt = s.output(&st) + sigma * normal(rng);
        psi.push(p);
        s.step(&mut st, ut, yt, heading.then_some(p));
        p += model.ts * yt;
        y.push(yt);
    }
    let mut r = Record::from_uy(name, model.ts, u.to_vec(), y);
    if heading {
        r.psi = Some(psi);
    }
    r
}

/// One seeded record of the truth: N samples, innovation std 0.05.
pub(crate) fn record(seed: u64, len: usize) -> Record {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let u = prbs(&mut rng, len, &[5.0, 10.0, 20.0]);
    simulate_innovations(&truth(), &u, 0.05, &mut rng, &format!("seed{seed}"), false)
}

/// Records of the built-in ship with `kind` hidden at full strength, one per seed.
pub(crate) fn ship_records(kind: yawcast_shared::model::EffectKind, seeds: &[u64]) -> Vec<Record> {
    use crate::sim::{simulate_many, Scenario, Ship, SimEffect};
    let sc = Scenario {
        effects: vec![SimEffect::hidden(kind, 1.0)],
        ..Scenario::default()
    };
    simulate_many(&Ship::default_lng(), &sc, seeds).unwrap()
}
