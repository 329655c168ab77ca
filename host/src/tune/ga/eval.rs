//! Evaluating a candidate (λ, R): identify, check the STD rule and stability, score on the trials.

use std::collections::BTreeMap;

use super::{Combine, GaConfig, Scored};
use crate::identify::merge;
use crate::identify::model::Model;
use crate::identify::pem::{self, IdentError, PemConfig, PemReport};
use crate::identify::predict;
use crate::io::data::Record;

/// The outcome of one candidate.
#[derive(Debug, Clone)]
pub(super) enum Outcome {
    Accepted(Scored),
    StdRule { name: String, pct: f64 },
    Unstable,
    Failed(String),
}

impl Outcome {
    pub(super) fn fitness(&self) -> f64 {
        match self {
            Outcome::Accepted(s) => s.fitness,
            _ => f64::NEG_INFINITY,
        }
    }
}

/// The fixed part of every evaluation.
pub(super) struct Ctx<'a> {
    pub(super) sim: &'a [Record],
    pub(super) trials: &'a [Record],
    /// Warm starts: one per simulation record (Average) or one (Joint).
    pub(super) starts: Vec<Model>,
    pub(super) cfg: &'a GaConfig,
}

/// Combines per-record reports by averaging (see [`Combine::Average`]).
pub(super) fn average_reports(reps: &[PemReport]) -> Result<(Model, Vec<f64>), String> {
    let models: Vec<Model> = reps.iter().map(|r| r.model.clone()).collect();
    let m = merge::average(&models).map_err(|e| e.to_string())?;
    let std = merge::average_std(reps).map_err(|e| e.to_string())?;
    Ok((m, std))
}

/// Mean fit per horizon on the trial records (x̂(0) estimated per record).
pub(super) fn trial_fits(
    model: &Model,
    trials: &[Record],
    horizons: &[usize],
) -> BTreeMap<String, f64> {
    let x0s: Vec<Vec<f64>> = trials
        .iter()
        .map(|r| predict::estimate_x0(model, r))
        .collect();
    horizons
        .iter()
        .map(|&k| {
            let f = trials
                .iter()
                .zip(&x0s)
                .map(|(r, x0)| predict::fit(&r.y, &predict::k_step(model, r, x0, k)))
                .sum::<f64>()
                / trials.len() as f64;
            (k.to_string(), f)
        })
        .collect()
}

impl Ctx<'_> {
    /// Identifies with (λ, R) around the run's penalty centre and scores the model;
    /// `std_limit` applies.
    pub(super) fn evaluate(&self, lambda: f64, r: &[f64]) -> Outcome {
        let mut pc = PemConfig {
            lambda,
            r: Some(r.to_vec()),
            ..self.cfg.pem.clone()
        };
        // one run, one centre (tune_with splits several centres into runs)
        if let Some(c) = self.cfg.centres.first() {
            pc.nominal = c.clone();
        }
        let (model, std) = match self.cfg.combine {
            Combine::Average => {
                let mut reps = Vec::with_capacity(self.sim.len());
                for (rec, start) in self.sim.iter().zip(&self.starts) {
                    match pem::identify_from(std::slice::from_ref(rec), start, &pc) {
                        Ok(rep) => reps.push(rep),
                        Err(IdentError::Unstable) => return Outcome::Unstable,
                        Err(e) => return Outcome::Failed(e.to_string()),
                    }
                }
                match average_reports(&reps) {
                    Ok(v) => v,
                    Err(e) => return Outcome::Failed(e),
                }
            }
            Combine::Joint => match pem::identify_from(self.sim, &self.starts[0], &pc) {
                Ok(rep) => (rep.model, rep.std),
                Err(IdentError::Unstable) => return Outcome::Unstable,
                Err(e) => return Outcome::Failed(e.to_string()),
            },
        };
        score(model, std, self.trials, self.cfg)
    }
}

/// Scores a model on the trials and applies the STD and stability rules.
pub(super) fn score(model: Model, std: Vec<f64>, trials: &[Record], cfg: &GaConfig) -> Outcome {
    if !model.is_stable() {
        return Outcome::Unstable;
    }
    let params = pem::params_of(&model);
    let std_pct: Vec<f64> = std
        .iter()
        .zip(&params)
        .map(|(s, v)| {
            if *v == 0.0 {
                f64::INFINITY
            } else {
                100.0 * s / v.abs()
            }
        })
        .collect();
    let names = model.param_names();
    if let Some((i, pct)) = std_pct
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_nan() || **v > cfg.std_limit)
        .max_by(|a, b| a.1.total_cmp(b.1))
    {
        return Outcome::StdRule {
            name: names[i].clone(),
            pct: *pct,
        };
    }
    let fits = trial_fits(&model, trials, &cfg.horizons);
    let fitness = fits.values().sum::<f64>() / fits.len().max(1) as f64;
    if !fitness.is_finite() {
        return Outcome::Failed("non-finite predictions on the trial records".into());
    }
    Outcome::Accepted(Scored {
        model,
        fits,
        fitness,
        std,
        std_pct,
    })
}
