//! Acceptance tests of the simulator: manoeuvres, effects, seeds, errors.

use super::*;
use crate::{pem, predict::{self, Horizon}};
use yawcast_shared::model::EffectKind;

#[test]
fn probe() {
    let ship = Ship::default_lng();
    let train: Vec<_> = (1..=3).map(|s| simulate(&ship, &Scenario::default(), s).unwrap()).collect();
    let rep = pem::identify(&train, None, &pem::PemConfig::default()).unwrap();
    let m = rep.model;
    let hs = [Horizon::Steps(10), Horizon::Steps(50), Horizon::Sim];
    let eval = |sc: &Scenario| -> Vec<f64> {
        let mut acc = vec![0.0; hs.len()];
        for seed in 100..104 {
            let r = simulate(&ship, sc, seed).unwrap();
            for (i, h) in hs.iter().enumerate() { acc[i] += predict::fit_at(&m, &r, *h) / 4.0; }
        }
        acc
    };
    println!("ref {:?}", eval(&Scenario::default()));
    for k in EffectKind::ALL {
        for s in [0.5, 1.0] {
            let sc = Scenario::with_effect(SimEffect::hidden(k, s));
            println!("{} {s} {:?}", k.name(), eval(&sc));
        }
    }
}
