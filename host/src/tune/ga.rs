//! Genetic-algorithm tuning of the regularisation (λ, R) — the paper's §2.4.
//!
//! Each individual codes λ and the diagonal of R as 13-bit genes (linear over
//! [1e-8, 200] for R and [1e-8, 100] for λ, or log-scaled). Its fitness is the mean fit % of
//! the k-step predictions (k = 5 and 10 by default) on the *trial* records of the model
//! identified, with that (λ, R), on the *simulation* records; a model breaking the 10 % STD
//! rule, unstable, or failing to identify is rejected (fitness −∞, counted by cause).
//! Population 8, rank-based scaling with stochastic universal sampling, crossover
//! probability 0.25 (randomly chosen genes exchanged), per-gene mutation probability 0.05
//! (bit flips), one elite, stop at fit > 99.5 %, when the best fit moves less than 0.001 pp
//! over `stall_generations`, or at the generation cap. The first population holds the
//! conventional individual (λ = R = 1e-8), so the tuned model can only match or beat it.
//! Evaluation is parallel (rayon) and memoised; the RNG is a seeded ChaCha8, so the same seed
//! gives the same model.

mod encoding;
mod eval;
#[cfg(test)]
mod tests;
use std::collections::{BTreeMap, HashMap};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::identify::model::Model;
use crate::identify::pem::{self, IdentError, PemConfig, PemReport};
use crate::io::data::Record;
use encoding::{next_generation, Genome};
use eval::{average_reports, score, trial_fits, Ctx, Outcome};

pub use encoding::decode;

/// How the models of several simulation records become one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Combine {
    /// One model per record, parameters averaged (the paper). The averaged model's STD is
    /// `√(Σ σ²_i)/R` per parameter (independent experiments).
    Average,
    /// One multi-record identification (one cost, one x̂(0) per record).
    Joint,
}

/// Settings of [`tune`]; `Default` holds the paper's values.
#[derive(Debug, Clone, PartialEq)]
pub struct GaConfig {
    /// Individuals per generation (paper: 8).
    pub population: usize,
    /// Bits per gene (paper: 13).
    pub bits: u32,
    /// Range of each R_i (paper: [1e-8, 200]).
    pub r_range: (f64, f64),
    /// Range of λ (paper: [1e-8, 100]).
    pub lambda_range: (f64, f64),
    /// Crossover probability per pair (paper: 0.25).
    pub crossover: f64,
    /// Mutation probability per gene (paper: 0.05).
    pub mutation: f64,
    /// Best individuals copied unchanged into the next generation.
    pub elite: usize,
    /// Stop when the best fit exceeds this (paper: 99.5 %).
    pub target_fit: f64,
    /// Stop when the best fit moved less than this many percentage points … (paper: 0.001)
    pub fit_tol: f64,
    /// … over this many generations (the paper's rule read literally is 1; a plateau of one
    /// generation is common with elitism, so the default waits for 10).
    pub stall_generations: usize,
    /// Generation cap.
    pub max_generations: usize,
    /// Prediction horizons of the fitness (mean fit over them and the trial records).
    pub horizons: Vec<usize>,
    /// Decode genes on a log scale instead of linearly.
    pub log_scale: bool,
    /// Grouped genes (R_a, R_b, R_k [, R_effects], λ) or one gene per parameter plus λ.
    pub grouped: bool,
    /// How several simulation records give one model.
    pub combine: Combine,
    /// STD% above which a candidate is rejected (paper: 10).
    pub std_limit: f64,
    /// Candidate centres θ₀ of the penalty λ (θ − θ₀)ᵀ R (θ − θ₀) (`None`: θ₀ = 0, the
    /// paper). With two or more, one GA runs per centre and the best fitness wins, so the
    /// tuning chooses the prior that predicts the trials best — e.g. zero (shrinks the
    /// dynamics, which can suit trials with actuator effects the simulator lacks) and the
    /// model identified on all simulation records (keeps the simulator's dynamics and only
    /// steadies the scattered parameters). Empty: `pem.nominal` is the one centre.
    pub centres: Vec<Option<Vec<f64>>>,
    /// RNG seed.
    pub seed: u64,
    /// Settings of the inner identifications (λ and R are set by the GA).
    pub pem: PemConfig,
    /// Show a progress bar on stderr (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for GaConfig {
    fn default() -> Self {
        GaConfig {
            population: 8,
            bits: 13,
            r_range: (1e-8, 200.0),
            lambda_range: (1e-8, 100.0),
            crossover: 0.25,
            mutation: 0.05,
            elite: 1,
            target_fit: 99.5,
            fit_tol: 0.001,
            stall_generations: 10,
            max_generations: 50,
            horizons: vec![5, 10],
            log_scale: false,
            grouped: true,
            combine: Combine::Average,
            std_limit: pem::STD_PCT_UNRELIABLE,
            centres: Vec::new(),
            seed: 0,
            pem: PemConfig {
                max_iter: 40,
                tol: 1e-7,
                parallel: false,
                ..PemConfig::default()
            },
            progress: true,
        }
    }
}

/// Why the GA stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GaTermination {
    /// The best fit exceeded the target.
    FitTarget,
    /// The best fit stopped improving (less than `fit_tol` over `stall_generations`).
    Stalled,
    /// The generation cap was reached.
    MaxGenerations,
}

/// One generation's summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GenStats {
    /// Generation number (1 = the initial population).
    pub generation: usize,
    /// Best fitness so far (−∞ while every candidate was rejected).
    pub best_fit: f64,
    /// Mean fitness of the accepted members of this generation.
    pub mean_fit: f64,
    /// Members of this generation that were rejected.
    pub rejected: usize,
    /// New (not memoised) evaluations in this generation.
    pub evaluations: usize,
}

/// Rejected candidates by cause.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rejections {
    /// Broke the STD% rule.
    pub std_rule: usize,
    /// Unstable model (A, A − KC, or the averaged model).
    pub unstable: usize,
    /// Identification failed or predictions went non-finite.
    pub failed: usize,
}

impl Rejections {
    /// Total.
    pub fn total(&self) -> usize {
        self.std_rule + self.unstable + self.failed
    }
}

/// A model and how it scores on the trial records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    /// The (combined) model.
    pub model: Model,
    /// Mean fit % on the trial records per horizon (keys `"5"`, `"10"`, …).
    pub fits: BTreeMap<String, f64>,
    /// Fitness: the mean of `fits`.
    pub fitness: f64,
    /// STD per parameter of the (combined) model.
    pub std: Vec<f64>,
    /// STD% per parameter.
    pub std_pct: Vec<f64>,
}

/// Result of [`tune`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GaReport {
    /// The model to use: the GA's best candidate when its gain over the conventional model
    /// on the tuning trials is above its spread ([`GaReport::gain`]), else the conventional
    /// model (then `lambda`, `r` and `genes` are zero and [`GaReport::tuned`] still shows
    /// the GA's candidate).
    pub best_model: Model,
    /// Its λ.
    pub lambda: f64,
    /// Its R diagonal (one weight per parameter, `Model::param_names` order).
    pub r: Vec<f64>,
    /// Index into [`GaConfig::centres`] of the winning run's penalty centre (0 with one).
    pub centre: usize,
    /// Its genes (codes).
    pub genes: Vec<u16>,
    /// Its fitness (mean k-step fit % on the trials).
    pub best_fit: f64,
    /// The tuned model in detail.
    pub tuned: Scored,
    /// The conventional model (λ = 0) from the same records, for comparison; `None` when
    /// its identification failed.
    pub conventional: Option<Scored>,
    /// Generations run.
    pub generations: usize,
    /// Per-generation summary.
    pub history: Vec<GenStats>,
    /// Distinct candidates evaluated.
    pub evaluations: usize,
    /// Distinct candidates rejected.
    pub rejected: usize,
    /// Rejections by cause.
    pub rejected_by: Rejections,
    /// Why the GA stopped.
    pub termination: GaTermination,
    /// The seed.
    pub seed: u64,
    /// The GA's gain over the conventional model on the tuning trials, record by record, and
    /// whether it is large enough to keep the tuned model; `None` without a conventional model.
    #[serde(default)]
    pub gain: Option<TuningGain>,
}

/// The tuned model's gain over the conventional one on the tuning trials: per record, the
/// tuned minus the conventional fitness (mean k-step fit %), averaged.
///
/// The GA picks the best of many candidates on these very records, so a gain that is not
/// larger than its own spread is what picking the best of many noisy scores gives by chance:
/// then the conventional model is kept ([`GaReport::best_model`]), and the output says so.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TuningGain {
    /// Mean gain over the trial records (percentage points).
    pub mean: f64,
    /// Its standard error (pp; 0 with one record).
    pub se: f64,
    /// Trial records.
    pub records: usize,
    /// Whether the tuned model is kept: the mean gain is positive and above twice its
    /// standard error (with one record, above zero).
    pub tuned_kept: bool,
}

/// GA errors.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum GaError {
    /// No simulation records.
    #[error("no simulation records to identify from")]
    NoSimulation,
    /// No trial records.
    #[error("no trial records to score on")]
    NoTrials,
    /// A setting is out of range.
    #[error("bad GA setting: {0}")]
    Config(String),
    /// A trial record cannot be scored.
    #[error("trial record `{record}`: {what}")]
    Trial {
        /// Record name.
        record: String,
        /// What is wrong.
        what: String,
    },
    /// The conventional identification that seeds every search failed.
    #[error("the conventional identification failed: {0}")]
    Identification(#[from] IdentError),
    /// Every candidate was rejected.
    #[error(
        "every one of the {evaluated} candidates was rejected — {cause} \
         (STD rule {std_rule}, unstable {unstable}, failed {failed})"
    )]
    AllRejected {
        /// Candidates evaluated.
        evaluated: usize,
        /// Broke the STD rule.
        std_rule: usize,
        /// Unstable.
        unstable: usize,
        /// Failed.
        failed: usize,
        /// The dominant cause, in words, with an example.
        cause: String,
    },
}

fn check_trials(trials: &[Record], ts: f64) -> Result<(), GaError> {
    for r in trials {
        let bad = |what: String| {
            Err(GaError::Trial {
                record: r.name.clone(),
                what,
            })
        };
        if r.u.len() != r.y.len() || r.psi.as_ref().is_some_and(|p| p.len() != r.y.len()) {
            return bad(format!(
                "channel lengths differ (u {}, y {})",
                r.u.len(),
                r.y.len()
            ));
        }
        if r.len() < 2 {
            return bad(format!("{} samples; at least 2 needed", r.len()));
        }
        if (r.ts - ts).abs() > 1e-9 * ts.abs() {
            return bad(format!(
                "sample time {} s, the simulation records have {ts} s",
                r.ts
            ));
        }
        let channels: [(&str, Option<&Vec<f64>>); 3] = [
            ("u", Some(&r.u)),
            ("y", Some(&r.y)),
            ("psi", r.psi.as_ref()),
        ];
        for (name, v) in channels {
            if let Some(i) = v.and_then(|v| v.iter().position(|x| !x.is_finite())) {
                return bad(format!("{name} sample {i} is not finite"));
            }
        }
    }
    Ok(())
}

fn check(cfg: &GaConfig) -> Result<(), GaError> {
    let bad = |m: &str| Err(GaError::Config(m.to_string()));
    if cfg.population < 2 {
        return bad("the population needs at least 2 individuals");
    }
    if !(1..=16).contains(&cfg.bits) {
        return bad("bits per gene must be in 1..=16");
    }
    for (name, (lo, hi)) in [("R", cfg.r_range), ("λ", cfg.lambda_range)] {
        if !(lo > 0.0 && hi > lo && hi.is_finite()) {
            return Err(GaError::Config(format!(
                "{name} range [{lo}, {hi}] must satisfy 0 < lo < hi < ∞"
            )));
        }
    }
    if !(0.0..=1.0).contains(&cfg.crossover) || !(0.0..=1.0).contains(&cfg.mutation) {
        return bad("crossover and mutation probabilities must be in [0, 1]");
    }
    if cfg.elite >= cfg.population {
        return bad("the elite must be smaller than the population");
    }
    if cfg.max_generations == 0 {
        return bad("at least one generation is needed");
    }
    if cfg.horizons.is_empty() || cfg.horizons.contains(&0) {
        return bad("horizons must be non-empty and ≥ 1");
    }
    Ok(())
}

/// Tunes (λ, R) on `trials` for models identified on `sim`, starting from `base` (its
/// structure and parameters), with a progress bar on stderr when `cfg.progress` is set and
/// stderr is a terminal.
///
/// # Errors
/// [`GaError`] for missing records or bad settings, when the conventional identification on
/// the simulation records fails, or when every candidate is rejected (the error names the
/// dominant cause).
pub fn tune(
    sim: &[Record],
    trials: &[Record],
    base: &Model,
    cfg: &GaConfig,
) -> Result<GaReport, GaError> {
    let bar = if cfg.progress {
        let b = indicatif::ProgressBar::with_draw_target(
            Some(cfg.max_generations as u64),
            indicatif::ProgressDrawTarget::stderr(),
        );
        b.set_message(format!("GA (seed {})", cfg.seed));
        Some(b)
    } else {
        None
    };
    let res = tune_with(sim, trials, base, cfg, &mut |g: &GenStats| {
        if let Some(b) = &bar {
            b.set_position(g.generation as u64);
            b.set_message(format!(
                "GA (seed {}): best fit {:.3} %",
                cfg.seed, g.best_fit
            ));
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    res
}

/// [`tune`] with a callback after every generation instead of the progress bar.
///
/// With two or more [`GaConfig::centres`], one GA runs per centre (same seed and settings)
/// and the one with the best fitness wins; its [`GaReport::centre`] says which.
///
/// # Errors
/// As [`tune`]; with several centres, the first centre's error when every run fails.
pub fn tune_with(
    sim: &[Record],
    trials: &[Record],
    base: &Model,
    cfg: &GaConfig,
    on_generation: &mut dyn FnMut(&GenStats),
) -> Result<GaReport, GaError> {
    let p = pem::params_of(base).len();
    for (i, c) in cfg.centres.iter().enumerate() {
        if let Some(v) = c {
            if v.len() != p || v.iter().any(|x| !x.is_finite()) {
                return Err(GaError::Config(format!(
                    "penalty centre {i} has {} values (finite ones needed: {p}, one per parameter)",
                    v.len()
                )));
            }
        }
    }
    if cfg.centres.len() < 2 {
        return tune_one(sim, trials, base, cfg, on_generation).map(|r| settle(r, trials, cfg));
    }
    let mut best: Option<GaReport> = None;
    let mut first_err = None;
    for (i, c) in cfg.centres.iter().enumerate() {
        let one = GaConfig {
            centres: vec![c.clone()],
            ..cfg.clone()
        };
        match tune_one(sim, trials, base, &one, on_generation) {
            Ok(mut r) => {
                r.centre = i;
                if best.as_ref().map_or(true, |b| r.best_fit > b.best_fit) {
                    best = Some(r);
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    best.map(|r| settle(r, trials, cfg))
        .ok_or_else(|| first_err.unwrap_or(GaError::NoSimulation))
}

/// Keeps the tuned model only when its gain over the conventional one on the tuning trials
/// is above its spread ([`TuningGain`]); otherwise the conventional model is the result
/// (`λ = 0`, `R = 0`, the conventional genes), and [`GaReport::tuned`] still shows what the
/// GA found.
fn settle(mut rep: GaReport, trials: &[Record], cfg: &GaConfig) -> GaReport {
    let Some(conv) = rep.conventional.clone() else {
        return rep;
    };
    let per_record = |m: &Model| -> Vec<f64> {
        trials
            .iter()
            .map(|r| {
                let f = trial_fits(m, std::slice::from_ref(r), &cfg.horizons);
                f.values().sum::<f64>() / f.len().max(1) as f64
            })
            .collect()
    };
    let d: Vec<f64> = per_record(&rep.best_model)
        .iter()
        .zip(per_record(&conv.model))
        .map(|(t, c)| t - c)
        .collect();
    let n = d.len();
    let mean = d.iter().sum::<f64>() / n.max(1) as f64;
    let se = if n > 1 {
        let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
        (var / n as f64).sqrt()
    } else {
        0.0
    };
    let tuned_kept = mean.is_finite() && mean > 0.0 && mean > 2.0 * se;
    if !tuned_kept {
        rep.best_model = conv.model.clone();
        rep.best_fit = conv.fitness;
        rep.lambda = 0.0;
        rep.r = vec![0.0; rep.r.len()];
        rep.genes = vec![0; rep.genes.len()];
    }
    rep.gain = Some(TuningGain {
        mean,
        se,
        records: n,
        tuned_kept,
    });
    rep
}

/// One GA run around one penalty centre (`cfg.centres[0]`, else `cfg.pem.nominal`).
///
/// Long: the generation loop (selection, crossover, mutation, evaluation, elitism, stopping)
/// reads as the algorithm's pseudo-code.
fn tune_one(
    sim: &[Record],
    trials: &[Record],
    base: &Model,
    cfg: &GaConfig,
    on_generation: &mut dyn FnMut(&GenStats),
) -> Result<GaReport, GaError> {
    if sim.is_empty() {
        return Err(GaError::NoSimulation);
    }
    if trials.is_empty() {
        return Err(GaError::NoTrials);
    }
    check(cfg)?;
    check_trials(trials, sim[0].ts)?;
    // The conventional model(s): warm starts of every candidate and the reference.
    let conv_cfg = PemConfig {
        lambda: 0.0,
        r: None,
        ..cfg.pem.clone()
    };
    let conv_starts: Vec<PemReport> = match cfg.combine {
        Combine::Average => sim
            .par_iter()
            .map(|r| pem::identify_from(std::slice::from_ref(r), base, &conv_cfg))
            .collect::<Result<_, _>>()?,
        Combine::Joint => vec![pem::identify_from(sim, base, &conv_cfg)?],
    };
    let conventional = {
        let (m, std) = match cfg.combine {
            Combine::Average => average_reports(&conv_starts).map_err(GaError::Config)?,
            Combine::Joint => (conv_starts[0].model.clone(), conv_starts[0].std.clone()),
        };
        // scored without the STD rule: it is the reference, shown whatever its STD%
        let relaxed = GaConfig {
            std_limit: f64::INFINITY,
            ..cfg.clone()
        };
        match score(m, std, trials, &relaxed) {
            Outcome::Accepted(s) => Some(s),
            _ => None,
        }
    };
    let ctx = Ctx {
        sim,
        trials,
        starts: conv_starts.into_iter().map(|r| r.model).collect(),
        cfg,
    };
    let genome = Genome::new(base, cfg.grouped);
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let max_code = ((1u32 << cfg.bits) - 1) as u16;
    let mut pop: Vec<Vec<u16>> = Vec::with_capacity(cfg.population);
    pop.push(vec![0; genome.len]); // the conventional individual
    while pop.len() < cfg.population {
        pop.push(
            (0..genome.len)
                .map(|_| rng.random_range(0..=max_code))
                .collect(),
        );
    }
    let mut memo: HashMap<Vec<u16>, Outcome> = HashMap::new();
    let mut history: Vec<GenStats> = Vec::new();
    let mut rejected_by = Rejections::default();
    let mut example: Option<String> = None;
    let mut best: Option<(Vec<u16>, f64)> = None;
    let mut termination = GaTermination::MaxGenerations;
    for generation in 1..=cfg.max_generations {
        // evaluate the new chromosomes in parallel
        let mut fresh: Vec<Vec<u16>> = pop
            .iter()
            .filter(|c| !memo.contains_key(*c))
            .cloned()
            .collect();
        fresh.sort();
        fresh.dedup();
        let outcomes: Vec<Outcome> = fresh
            .par_iter()
            .map(|c| {
                let (lambda, r) = genome.decode(c, cfg);
                ctx.evaluate(lambda, &r)
            })
            .collect();
        for (c, o) in fresh.iter().zip(outcomes) {
            match &o {
                Outcome::Accepted(_) => {}
                Outcome::StdRule { name, pct } => {
                    rejected_by.std_rule += 1;
                    example.get_or_insert_with(|| format!("{name} has STD {pct:.1} %"));
                }
                Outcome::Unstable => rejected_by.unstable += 1,
                Outcome::Failed(e) => {
                    rejected_by.failed += 1;
                    example.get_or_insert_with(|| e.clone());
                }
            }
            memo.insert(c.clone(), o);
        }
        let fit: Vec<f64> = pop.iter().map(|c| memo[c].fitness()).collect();
        for (c, f) in pop.iter().zip(&fit) {
            if f.is_finite() && best.as_ref().map_or(true, |(_, b)| f > b) {
                best = Some((c.clone(), *f));
            }
        }
        let accepted: Vec<f64> = fit.iter().copied().filter(|f| f.is_finite()).collect();
        let stats = GenStats {
            generation,
            best_fit: best.as_ref().map_or(f64::NEG_INFINITY, |b| b.1),
            mean_fit: if accepted.is_empty() {
                f64::NEG_INFINITY
            } else {
                accepted.iter().sum::<f64>() / accepted.len() as f64
            },
            rejected: fit.len() - accepted.len(),
            evaluations: fresh.len(),
        };
        on_generation(&stats);
        history.push(stats);
        let best_now = history[generation - 1].best_fit;
        if best_now > cfg.target_fit {
            termination = GaTermination::FitTarget;
            break;
        }
        if best_now.is_finite() && generation > cfg.stall_generations {
            let before = history[generation - 1 - cfg.stall_generations].best_fit;
            if before.is_finite() && (best_now - before).abs() < cfg.fit_tol {
                termination = GaTermination::Stalled;
                break;
            }
        }
        if generation == cfg.max_generations {
            break;
        }
        pop = next_generation(&pop, &fit, cfg, &mut rng);
    }
    let evaluations = memo.len();
    let Some((genes, best_fit)) = best else {
        return Err(all_rejected(evaluations, rejected_by, example));
    };
    let Some(Outcome::Accepted(tuned)) = memo.remove(&genes) else {
        return Err(all_rejected(evaluations, rejected_by, example));
    };
    let (lambda, r) = genome.decode(&genes, cfg);
    Ok(GaReport {
        best_model: tuned.model.clone(),
        lambda,
        r,
        centre: 0,
        genes,
        best_fit,
        tuned,
        conventional,
        generations: history.len(),
        history,
        evaluations,
        rejected: rejected_by.total(),
        rejected_by,
        termination,
        seed: cfg.seed,
        gain: None,
    })
}

fn all_rejected(evaluated: usize, by: Rejections, example: Option<String>) -> GaError {
    let ex = example.unwrap_or_default();
    let cause = if by.std_rule >= by.unstable && by.std_rule >= by.failed {
        format!("the STD rule: parameters are not determined to the required precision (e.g. {ex}); more or richer simulation data, or a lower order, should help")
    } else if by.unstable >= by.failed {
        "the identified models are unstable".to_string()
    } else {
        format!("the identification failed ({ex})")
    };
    GaError::AllRejected {
        evaluated,
        std_rule: by.std_rule,
        unstable: by.unstable,
        failed: by.failed,
        cause,
    }
}
