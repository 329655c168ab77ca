//! The parametric-bootstrap nulls: the innovations model simulated on the recorded
//! commands, `D` recomputed on each replicate, and the scaled χ² fitted to the replicates.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use yawcast_shared::model::EffectKind;

use super::evidence::world;
use crate::identify::model::{Effect, Model};
use crate::identify::pem::{self, PemConfig};
use crate::identify::predict::Stepper;
use crate::io::data::Record;
use crate::stats::{chi2_sf, standard_normal as gauss};

/// Simulates the innovations model on the commands of `like` with innovation std `sigma`
/// (heading integrated from the simulated rate, from the record's first heading).
pub(super) fn simulate_innovations(
    model: &Model,
    like: &Record,
    sigma: f64,
    rng: &mut ChaCha8Rng,
) -> Record {
    let s = Stepper::new(model);
    let p0 = like.psi.as_ref().map(|p| p[0]).unwrap_or(0.0);
    let mut st = s.initial(&[], p0);
    let n = like.len();
    let mut y = Vec::with_capacity(n);
    let mut psi = Vec::with_capacity(n);
    let mut p = p0;
    for t in 0..n {
        let yt = s.output(&st) + sigma * gauss(rng);
        psi.push(p);
        s.step(&mut st, like.u[t], yt, Some(p));
        p += model.ts * (yt - s.d_y());
        y.push(yt);
    }
    let mut r = Record::from_uy(&like.name, like.ts, like.u.clone(), y);
    r.psi = Some(psi);
    r
}

/// A scaled χ² `c·χ²_ν` fitted to replicates by their mean and variance (Satterthwaite).
#[derive(Debug, Clone, Copy)]
pub(super) struct Null {
    pub(super) c: f64,
    pub(super) nu: f64,
}

impl Null {
    pub(super) fn fit(reps: &[f64]) -> Null {
        let n = reps.len().max(1) as f64;
        let mean = reps.iter().sum::<f64>() / n;
        let var = reps.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let mean = mean.max(1e-9);
        let var = var.max(1e-12 * mean * mean);
        Null {
            c: var / (2.0 * mean),
            nu: (2.0 * mean * mean / var).max(0.05),
        }
    }

    pub(super) fn p(&self, d: f64) -> f64 {
        chi2_sf(d / self.c, self.nu).clamp(0.0, 1.0)
    }

    /// Likelihood gain above what noise alone gives (`D` minus the null's mean): comparable
    /// across effects judged on the same errors, where far-tail p-values are not.
    pub(super) fn excess(&self, d: f64) -> f64 {
        d - self.c * self.nu
    }
}

/// Null replicates of `D` for every kind: parametric bootstrap of the whole procedure. The
/// innovations model is simulated with its innovation std on the recorded inputs of the
/// reference and trial records, the model is re-identified on the simulated reference (on the
/// simulated trials when there is no reference), and `D` is recomputed.
#[allow(clippy::too_many_arguments)]
pub(super) fn bootstrap(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    sigma: f64,
    reps: usize,
    bar: &indicatif::ProgressBar,
    seed: u64,
    parallel: bool,
) -> Vec<Vec<f64>> {
    let one = |r: usize| -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                .wrapping_add(r as u64),
        );
        let rs: Vec<Record> = reference
            .iter()
            .map(|rec| simulate_innovations(model, rec, sigma, &mut rng))
            .collect();
        let ts: Vec<Record> = est
            .iter()
            .map(|rec| simulate_innovations(model, rec, sigma, &mut rng))
            .collect();
        let pc = PemConfig {
            order: model.n,
            max_iter: 30,
            parallel: false,
            ..PemConfig::default()
        };
        let fit_on = if rs.is_empty() { &ts } else { &rs };
        let m = pem::identify_from(fit_on, model, &pc)
            .map(|r| r.model)
            .unwrap_or_else(|_| model.clone());
        let d = world(&m, &rs, &ts, grids, false)
            .into_iter()
            .map(|w| w.d)
            .collect();
        bar.inc(1);
        d
    };
    let per: Vec<Vec<f64>> = crate::par::map_range(reps, parallel, one);
    (0..grids.len())
        .map(|k| per.iter().map(|v| v[k]).collect())
        .collect()
}
