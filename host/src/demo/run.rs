//! The demo pipeline: simulate identification records and lake trials with a hidden effect,
//! identify, GA-tune, merge, compare, diagnose, augment (the model and the ship file),
//! export, check the firmware, and collect everything into an [`Outcome`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use thiserror::Error;
use yawcast_shared::model::EffectKind;

use super::{Evidence, FirmwareCheck, Fits, ModelResult, Outcome, Regime, Residuals};
use crate::diagnose::augment::{self, AugmentConfig};
use crate::diagnose::resid::{self, ResidConfig, ResidReport};
use crate::diagnose::{self, DiagnoseConfig};
use crate::identify::merge;
use crate::identify::model::Model;
use crate::identify::pem::{self, PemConfig};
use crate::identify::predict::{self, Horizon};
use crate::io::data::{self, Record};
use crate::sim::{self, NoiseSpec, Scenario, Ship, SimEffect};
use crate::tune::ga::{self, GaConfig};

/// Settings of [`run`].
#[derive(Debug, Clone)]
pub struct DemoConfig {
    /// Seed of every random choice (the hidden effect, inputs, noise, GA, bootstrap).
    pub seed: u64,
    /// The ship (default: the built-in 1:24 LNG carrier).
    pub ship: Ship,
    /// Identification records from the simulator (paper: 15).
    pub ident_records: usize,
    /// Lake-trial records with the hidden effect (paper: 15); the last `validation` of them
    /// are held out of tuning, diagnosis and augmentation and score every model.
    pub trial_records: usize,
    /// Held-out trials.
    pub validation: usize,
    /// Record length (s).
    pub duration_s: f64,
    /// The hidden effect; `None` draws one of the library's effects from the seed.
    pub hidden: Option<SimEffect>,
    /// GA settings (seed and progress are set from this config).
    pub ga: GaConfig,
    /// Firmware ELF for the QEMU check (`None`: native check only).
    pub elf: Option<PathBuf>,
    /// Samples streamed through QEMU.
    pub qemu_samples: usize,
    /// Directory for the records, models, ship file and report.
    pub out: PathBuf,
    /// Progress bars on stderr.
    pub progress: bool,
}

impl Default for DemoConfig {
    fn default() -> Self {
        DemoConfig {
            seed: 1,
            ship: Ship::default_lng(),
            ident_records: 15,
            trial_records: 15,
            validation: 5,
            duration_s: 1800.0,
            hidden: None,
            // λ and R on a log scale: the regularisation that helps spans decades, and a
            // linear 13-bit gene cannot come near λ = 0.
            ga: GaConfig {
                log_scale: true,
                max_generations: 20,
                stall_generations: 6,
                ..GaConfig::default()
            },
            elf: None,
            qemu_samples: 300,
            out: PathBuf::from("runs/demo"),
            progress: true,
        }
    }
}

/// Demo failures (each names the step).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DemoError {
    /// Settings out of range.
    #[error("demo settings: {0}")]
    Config(String),
    /// The simulator failed.
    #[error("simulating the records: {0}")]
    Sim(#[from] sim::SimError),
    /// A file could not be written.
    #[error("writing the run directory: {0}")]
    Data(#[from] data::DataError),
    /// A step failed.
    #[error("{step}: {cause}")]
    Step {
        /// Which step.
        step: &'static str,
        /// Why.
        cause: String,
    },
}

fn step<E: std::fmt::Display>(step: &'static str) -> impl Fn(E) -> DemoError {
    move |e| DemoError::Step {
        step,
        cause: e.to_string(),
    }
}

/// The effect a seed hides: one of the library's nine, drawn uniformly.
///
/// ```
/// use yawcast::demo::hidden_kind;
/// use yawcast_shared::model::EffectKind;
/// assert!(EffectKind::ALL.contains(&hidden_kind(3)));
/// assert_eq!(hidden_kind(3), hidden_kind(3));
/// ```
pub fn hidden_kind(seed: u64) -> EffectKind {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(7);
    EffectKind::ALL[rng.random_range(0..EffectKind::ALL.len())]
}

fn fits_of(model: &Model, recs: &[Record]) -> Fits {
    merge::validation_fits(model, recs)
}

fn residuals(label: &str, r: &ResidReport) -> Residuals {
    Residuals {
        label: label.into(),
        n: r.samples,
        acf: r.acf.values.clone(),
        acf_band: r.acf.band,
        ccf_lags: r.ccf.lags.iter().map(|&l| l as f64).collect(),
        ccf: r.ccf.values.clone(),
        ccf_band: vec![r.ccf.band],
        ljung_box_p: r.ljung_box.p_value,
    }
}

fn regimes(before: &ResidReport, after: &ResidReport) -> Vec<Regime> {
    before
        .regimes
        .iter()
        .map(|b| {
            let a = after.regimes.iter().find(|a| a.key == b.key);
            Regime {
                dimension: b.dimension.clone(),
                bins: b.bins.iter().map(|x| x.label.clone()).collect(),
                before: b.bins.iter().map(|x| x.rmse).collect(),
                after: b
                    .bins
                    .iter()
                    .enumerate()
                    .map(|(i, _)| a.and_then(|a| a.bins.get(i)).map_or(f64::NAN, |x| x.rmse))
                    .collect(),
            }
        })
        .collect()
}

/// A bar on stderr for one step (hidden unless `on`).
fn spinner(on: bool, msg: &str) -> indicatif::ProgressBar {
    if !on {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new_spinner();
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// Runs the whole demo; `say` gets one line per finished step (for the terminal).
///
/// Writes into `cfg.out`: `data/ident-NN.csv`, `data/trial-NN.csv` (the records),
/// `conventional.json`, `tuned.json` (model twins), `model.postcard` + `model.json` (the
/// exported, augmented model), `ship.toml` (the ship with the diagnosed effect) — every file
/// written atomically. The report page and the JSON summary are written by the caller from
/// the returned [`Outcome`].
///
/// # Errors
/// [`DemoError`] naming the step that failed (bad settings, a simulator, identification,
/// export or file error). A GA run in which every candidate is rejected is not an error:
/// the conventional model goes on and the report says so.
///
/// Long: the demo is a script: its steps in the order of the story the report tells, each a
/// few lines with its output.
pub fn run(cfg: &DemoConfig, say: &mut dyn FnMut(&str)) -> Result<Outcome, DemoError> {
    let t0 = Instant::now();
    let mut timings: Vec<(String, f64)> = Vec::new();
    let mut lap = Instant::now();
    let mut tick = |name: &str, timings: &mut Vec<(String, f64)>| {
        timings.push((name.to_string(), lap.elapsed().as_secs_f64()));
        lap = Instant::now();
    };
    if cfg.ident_records == 0 || cfg.validation == 0 || cfg.trial_records <= cfg.validation {
        return Err(DemoError::Config(format!(
            "need ≥ 1 identification record and more trials ({}) than held-out trials ({}) ≥ 1",
            cfg.trial_records, cfg.validation
        )));
    }
    let seed = cfg.seed;
    let hidden = cfg
        .hidden
        .unwrap_or_else(|| SimEffect::hidden(hidden_kind(seed), 1.0));
    let hidden_kind = hidden.kind();

    // 1. Records: identification (the simulator as it is) and lake trials (the hidden effect).
    let pb = spinner(cfg.progress, "simulating");
    let n_samples = (cfg.duration_s / 1.0).round() as usize;
    let noise = NoiseSpec {
        gyro_std_degps: 0.03,
        heading_std_deg: 0.1,
        speed_std_mps: 0.01,
    };
    let base_sc = Scenario {
        name: "ident".into(),
        n_samples,
        noise,
        ..Scenario::default()
    };
    let trial_sc = Scenario {
        name: "trial".into(),
        noise: NoiseSpec {
            gyro_std_degps: 0.05,
            ..noise
        },
        effects: vec![hidden],
        ..base_sc.clone()
    };
    let base_seed = seed.wrapping_mul(10_007);
    let ident_seeds: Vec<u64> = (0..cfg.ident_records as u64)
        .map(|i| base_seed.wrapping_add(i))
        .collect();
    let trial_seeds: Vec<u64> = (0..cfg.trial_records as u64)
        .map(|i| base_seed.wrapping_add(5_000 + i))
        .collect();
    let mut ident = sim::simulate_many(&cfg.ship, &base_sc, &ident_seeds)?;
    let mut trials = sim::simulate_many(&cfg.ship, &trial_sc, &trial_seeds)?;
    for (i, r) in ident.iter_mut().enumerate() {
        r.name = format!("ident-{:02}", i + 1);
    }
    for (i, r) in trials.iter_mut().enumerate() {
        r.name = format!("trial-{:02}", i + 1);
    }
    let data_dir = cfg.out.join("data");
    std::fs::create_dir_all(&data_dir).map_err(|e| data::DataError::Io {
        path: data_dir.clone(),
        source: e,
    })?;
    for r in ident.iter().chain(&trials) {
        data::write_csv(&data_dir.join(format!("{}.csv", r.name)), r)?;
    }
    let n_est = cfg.trial_records - cfg.validation;
    let (est, val) = trials.split_at(n_est);
    pb.finish_and_clear();
    tick("simulate", &mut timings);
    say(&format!(
        "simulated {} identification records and {} lake trials ({} held out) of {} s; the trials hide one effect",
        ident.len(),
        trials.len(),
        val.len(),
        cfg.duration_s
    ));

    // 2. Conventional vs GA-tuned (the paper: identify on simulation, score on the trials).
    let pem_cfg = PemConfig::default();
    let base = pem::identify(&ident[..1], None, &pem_cfg).map_err(step("identification"))?;
    let conv_rep = pem::identify(&ident, None, &pem_cfg).map_err(step("identification"))?;
    // Two penalty centres, one GA run each: zero (the paper) and the model of all simulation
    // records together (a prior from the simulator); the run that predicts the trials best wins.
    let mut ga_cfg = GaConfig {
        seed,
        progress: cfg.progress,
        ..cfg.ga.clone()
    };
    ga_cfg.centres = vec![None, Some(conv_rep.model.theta())];
    let (conventional, tuned, tuning_note) = match ga::tune(&ident, est, &base.model, &ga_cfg) {
        Ok(rep) => {
            let conv = match &rep.conventional {
                Some(c) => ModelResult {
                    label: "conventional".into(),
                    fit: fits_of(&c.model, val),
                    model: c.model.clone(),
                    std_pct: c.std_pct.clone(),
                    note: "PEM per simulation record (λ = 0), averaged (the paper's way)".into(),
                },
                None => conventional_from(&conv_rep, val),
            };
            let kept = rep.gain.as_ref().map_or(true, |g| g.tuned_kept);
            let tuned = ModelResult {
                label: if kept {
                    "GA-tuned".into()
                } else {
                    "GA-tuned (gain within its spread: conventional kept)".into()
                },
                fit: fits_of(&rep.best_model, val),
                model: rep.best_model.clone(),
                std_pct: rep.tuned.std_pct.clone(),
                note: format!(
                    "regularised PEM, λ = {:.3e}, penalty centre {}, averaged",
                    rep.lambda,
                    if rep.centre == 0 {
                        "zero"
                    } else {
                        "the all-records model"
                    }
                ),
            };
            let note = format!(
                "GA: {} generations ({}), {} candidates evaluated, {} rejected by the STD rule or stability; λ = {:.3e}, R = [{}]; fitness {:.2} % on the {} tuning trials",
                rep.generations,
                format!("{:?}", rep.termination).to_lowercase(),
                rep.evaluations,
                rep.rejected,
                rep.lambda,
                rep.r.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(", "),
                rep.best_fit,
                est.len()
            ) + &rep.gain.as_ref().map_or(String::new(), |g| {
                format!(
                    "; gain over the conventional model {:+.2} ± {:.2} pp record by record — {}",
                    g.mean,
                    g.se,
                    if g.tuned_kept {
                        "the tuned model goes on"
                    } else {
                        "within its spread, so the conventional model goes on"
                    }
                )
            });
            (conv, tuned, note)
        }
        Err(e) => {
            let conv = conventional_from(&conv_rep, val);
            let mut tuned = conv.clone();
            tuned.label = "GA-tuned (fell back to conventional)".into();
            (conv, tuned, format!("GA tuning gave no model: {e}"))
        }
    };
    tick("identify + GA", &mut timings);
    say(&format!(
        "identified: conventional 5-step fit {:.1} %, GA-tuned {:.1} % on the held-out trials",
        conventional.fit["5"], tuned.fit["5"]
    ));

    // 3. Several trials → one model: the three combinations compared.
    let combos_rep = merge::compare(&ident, val, Some(&base.model), &pem_cfg)
        .map_err(step("combining the records"))?;
    let mut combos: Vec<ModelResult> = combos_rep
        .combinations
        .iter()
        .map(|c| ModelResult {
            label: c.name.clone(),
            model: c.model.clone(),
            fit: c.fits.clone(),
            std_pct: Vec::new(),
            note: c.note.clone(),
        })
        .collect();
    combos.push(tuned.clone());
    let chosen = tuned.label.clone();
    tick("merge", &mut timings);

    // 4. Where it fails, and which physics is missing.
    let rcfg = ResidConfig::default();
    let resid_before = resid::resid(&tuned.model, val, &rcfg).map_err(step("residuals"))?;
    let dcfg = DiagnoseConfig {
        seed,
        ..DiagnoseConfig::default()
    };
    let pb = spinner(cfg.progress, "diagnosing");
    let diag =
        diagnose::diagnose(&tuned.model, &ident, est, val, &dcfg).map_err(step("diagnosis"))?;
    pb.finish_and_clear();
    tick("diagnose", &mut timings);
    say(&format!("diagnosis: {}", diag.verdict));

    // 5. Augment the model with the diagnosed effect.
    let pb = spinner(cfg.progress, "augmenting");
    let aug_rep = match (diag.verdict_kind(), &diag.augment) {
        (Some(k), Some(a)) if a.effect == k => Some(a.clone()),
        (Some(k), _) => Some(
            augment::augment(&tuned.model, k, est, val, &AugmentConfig::default())
                .map_err(step("augmentation"))?,
        ),
        (None, _) => None,
    };
    pb.finish_and_clear();
    // The demo ships the refitted model when it predicts the held-out trials better than the
    // tuned model it started from (augment's own `kept` judges the effect against a refit
    // without it, which is the stricter question of whether the effect itself adds).
    let adopt = |a: &augment::AugmentReport| {
        let gain = |k: &str| a.after.get(k).copied().unwrap_or(f64::NAN) - tuned.fit[k];
        a.kept || (a.candidate.is_stable() && gain("10") >= 0.0 && gain("5") >= 0.0)
    };
    let augmented = match &aug_rep {
        Some(a) if adopt(a) => ModelResult {
            label: format!("augmented (+{})", a.effect.name()),
            fit: fits_of(&a.candidate, val),
            model: a.candidate.clone(),
            std_pct: a.std_pct.clone(),
            note: a.explanation.clone(),
        },
        _ => ModelResult {
            label: "augmented (nothing added)".into(),
            note: "no effect improved held-out prediction; the tuned model stands".into(),
            ..tuned.clone()
        },
    };
    let resid_after =
        resid::resid(&augmented.model, val, &rcfg).map_err(step("residuals after"))?;
    tick("augment", &mut timings);

    // 6. Close the loop on the physics: the effect into the ship file, re-simulate, re-identify.
    let (ship_before, ship_after, ship_note, ship_out) = ship_loop(
        cfg,
        &augmented.model,
        &aug_rep,
        &base_sc,
        base_seed,
        val,
        &ident,
    )?;
    if let Some(text) = ship_out {
        data::write_atomic(&cfg.out.join("ship.toml"), text.as_bytes())?;
    }
    tick("ship file", &mut timings);

    // 7. Export and the firmware check.
    write_twin(&cfg.out.join("conventional.json"), &conventional.model)?;
    write_twin(&cfg.out.join("tuned.json"), &tuned.model)?;
    let check = &val[0];
    let exp = crate::io::export::export(&augmented.model, &cfg.out.join("model.postcard"), check)
        .map_err(step("export"))?;
    let blob = std::fs::read(&exp.blob_path).map_err(|e| data::DataError::Io {
        path: exp.blob_path.clone(),
        source: e,
    })?;
    let pb = spinner(cfg.progress, "firmware check");
    let firmware: FirmwareCheck = super::firmware_check(
        &augmented.model,
        &blob,
        check,
        cfg.elf.as_deref(),
        cfg.qemu_samples,
    )
    .map_err(step("firmware check"))?;
    pb.finish_and_clear();
    tick("export + firmware", &mut timings);

    // 8. Example series and the outcome.
    let x0 = predict::estimate_x0(&tuned.model, check);
    let example_series = [5usize, 10, 20]
        .iter()
        .map(|&k| {
            (
                format!("{k}-step"),
                predict::predict(&tuned.model, check, &x0, Horizon::Steps(k)),
            )
        })
        .collect();
    let xa = predict::estimate_x0(&augmented.model, check);
    let example_augmented = predict::predict(&augmented.model, check, &xa, Horizon::Steps(10));
    let ranking = diag
        .ranking
        .iter()
        .map(|r| Evidence {
            effect: r.effect.clone(),
            statistic: r.statistic,
            p_value: r.p_value,
            fit_gain_pp: r.fit_gain_pp,
            selected: r.effect == diag.verdict,
            evidence: r.evidence.clone(),
        })
        .collect();
    let worst = resid_before
        .worst
        .iter()
        .map(|w| (w.record.clone(), w.t_start, w.t_end, w.rmse, w.what.clone()))
        .collect();
    let track = match track_case(&cfg.ship, &conventional.model, seed) {
        Ok(t) => Some(t),
        Err(e) => {
            say(&format!("heading and track case skipped: {e}"));
            None
        }
    };
    tick("heading and track", &mut timings);
    Ok(Outcome {
        seed,
        ship: cfg.ship.name.clone(),
        hidden_effect: hidden_kind.name().to_string(),
        hidden_detail: hidden.describe(),
        ident,
        trials: trials.clone(),
        conventional,
        tuned: tuned.clone(),
        tuning_note,
        combos,
        chosen,
        example: n_est,
        example_series,
        resid_before: residuals(&tuned.label, &resid_before),
        resid_after: residuals(&augmented.label, &resid_after),
        regimes: regimes(&resid_before, &resid_after),
        worst,
        ranking,
        diagnosed_effect: diag.verdict.clone(),
        explanation: diag.explanation.clone(),
        augmented,
        example_augmented,
        ship_before,
        ship_after,
        ship_note,
        firmware,
        track,
        timings,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// The demo's current case ([`super::TrackCase`]): the track part fitted on three effect-free
/// records of `ship`, a record with a 0.5 m/s current setting towards 60°, the model's
/// heading fit and track error without and with the track's current estimate.
fn track_case(ship: &Ship, model: &Model, seed: u64) -> Result<super::TrackCase, String> {
    use crate::identify::track::{evaluate, fit_track};
    use crate::io::nav::{ground_velocity, Nav};
    let with_nav = |sc: &Scenario, s: u64| -> Result<(Record, Nav), String> {
        let (rec, sn) = sim::simulate_with_nav(ship, sc, s).map_err(|e| e.to_string())?;
        let sog = rec.speed.clone().ok_or("no speed over ground")?;
        let v = sog
            .iter()
            .zip(&sn.cog_deg)
            .map(|(u, c)| ground_velocity(*u, *c))
            .collect();
        let fix = sn
            .north_m
            .iter()
            .zip(&sn.east_m)
            .map(|(n, e)| [*n, *e])
            .collect();
        let nav = Nav::new(rec.ts, Some(v), Some(fix), "simulator").ok_or("no channels")?;
        Ok((rec, nav))
    };
    let base = seed.wrapping_mul(1000).wrapping_add(900);
    let refs = (1..=3)
        .map(|i| with_nav(&Scenario::default(), base + i))
        .collect::<Result<Vec<_>, _>>()?;
    let pairs: Vec<(&Record, &Nav)> = refs.iter().map(|(r, n)| (r, n)).collect();
    let plain = fit_track(model.ts, model.d_y(), &pairs, false)?;
    let current = fit_track(model.ts, model.d_y(), &pairs, true)?;
    let (current_mps, towards_deg) = (0.5, 60.0);
    let sc = Scenario::with_effect(SimEffect::Current {
        speed_mps: current_mps,
        towards_deg,
    });
    let (rec, nav) = with_nav(&sc, base + 4)?;
    let secs = [30.0, 60.0, 120.0];
    let before = evaluate(model, &plain, &rec, Some(&nav), &[1, 5, 10, 20], &secs)?;
    let after = evaluate(model, &current, &rec, Some(&nav), &[], &secs)?;
    let keyed = |e: &crate::identify::track::TrackEval| -> Fits {
        e.track_error_m
            .iter()
            .filter_map(|(s, m)| m.map(|m| (format!("{s}"), m)))
            .collect()
    };
    Ok(super::TrackCase {
        current_mps,
        towards_deg,
        heading_fit: before
            .heading_fit
            .iter()
            .map(|(k, f)| (k.to_string(), *f))
            .collect(),
        before: keyed(&before),
        after: keyed(&after),
    })
}

fn conventional_from(rep: &pem::PemReport, val: &[Record]) -> ModelResult {
    ModelResult {
        label: "conventional".into(),
        fit: fits_of(&rep.model, val),
        model: rep.model.clone(),
        std_pct: rep.std_pct.clone(),
        note: "PEM on all simulation records at once (λ = 0)".into(),
    }
}

fn write_twin(path: &Path, model: &Model) -> Result<(), DemoError> {
    let mut bytes = serde_json::to_vec_pretty(model).map_err(step("model JSON"))?;
    bytes.push(b'\n');
    data::write_atomic(path, &bytes)?;
    Ok(())
}

/// The ship file with the diagnosed effect; the simulator's records before and after, each
/// identified and scored on the held-out trials.
#[allow(clippy::type_complexity)]
fn ship_loop(
    cfg: &DemoConfig,
    augmented: &Model,
    aug: &Option<augment::AugmentReport>,
    base_sc: &Scenario,
    base_seed: u64,
    val: &[Record],
    ident: &[Record],
) -> Result<(Fits, Fits, String, Option<String>), DemoError> {
    let pem_cfg = PemConfig::default();
    let n_loop = ident.len().min(5);
    let before_model = pem::identify(&ident[..n_loop], None, &pem_cfg)
        .map_err(step("re-identification"))?
        .model;
    let before = fits_of(&before_model, val);
    let added = aug.as_ref().and_then(|a| {
        let e = augmented.effect(a.effect)?;
        augment::to_sim_effect(e, augmented, &cfg.ship)
    });
    let Some(sim_effect) = added else {
        return Ok((
            before.clone(),
            before,
            "nothing was added, so the ship file is unchanged".into(),
            None,
        ));
    };
    let ship = cfg.ship.clone().with_effect(sim_effect);
    let seeds: Vec<u64> = (0..n_loop as u64)
        .map(|i| base_seed.wrapping_add(9_000 + i))
        .collect();
    let resim = sim::simulate_many(&ship, base_sc, &seeds)?;
    let template = Model {
        effects: augmented.effects.clone(),
        ..before_model.clone()
    };
    let after_model = pem::identify(&resim, Some(&template), &pem_cfg)
        .or_else(|_| pem::identify(&resim, None, &pem_cfg))
        .map_err(step("re-identification on the new simulator"))?
        .model;
    let after = fits_of(&after_model, val);
    let text = ship.to_toml_string().map_err(step("ship file"))?;
    let note = format!(
        "{} written into ship.toml; a model identified on {} re-simulated records now scores {} → {} % at 10 steps on the held-out trials",
        sim_effect.describe(),
        n_loop,
        fmt1(before.get("10")),
        fmt1(after.get("10"))
    );
    Ok((before, after, note, Some(text)))
}

fn fmt1(v: Option<&f64>) -> String {
    v.map_or("—".into(), |v| format!("{v:.1}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GA on the built-in scenario: identify on 15 clean simulation records, score on 15
    /// lake trials with noise and one hidden effect (a 2 s dead time). The tuned averaged model
    /// keeps every parameter within the paper's STD rule where the conventional one does not,
    /// and the same seed gives the same model. (Its fit on these trials stays within a pp of
    /// the conventional model's; see the printed figures.)
    #[test]
    fn ga_beats_conventional_on_dead_time_trials_within_the_std_rule_reproducibly() {
        let ship = Ship::default_lng();
        let noise = NoiseSpec {
            gyro_std_degps: 0.03,
            heading_std_deg: 0.1,
            speed_std_mps: 0.01,
        };
        let clean = Scenario {
            noise,
            ..Scenario::default()
        };
        let trial = Scenario {
            effects: vec![SimEffect::hidden(EffectKind::DeadTime, 1.0)],
            ..clean.clone()
        };
        let seeds: Vec<u64> = (1..=15).collect();
        let sim_recs = sim::simulate_many(&ship, &clean, &seeds).unwrap();
        let trial_seeds: Vec<u64> = (101..=115).collect();
        let trials = sim::simulate_many(&ship, &trial, &trial_seeds).unwrap();
        let pem_cfg = PemConfig::default();
        let base = pem::identify(&sim_recs[..1], None, &pem_cfg).unwrap().model;
        let all = pem::identify(&sim_recs, None, &pem_cfg).unwrap().model;
        let mut cfg = DemoConfig::default().ga;
        cfg.seed = 3;
        cfg.progress = false;
        cfg.centres = vec![None, Some(all.theta())];
        let rep = ga::tune(&sim_recs, &trials, &base, &cfg).unwrap();
        let conv = rep.conventional.as_ref().unwrap();
        let f = |m: &Model, k: usize| {
            trials
                .iter()
                .map(|r| predict::fit_at(m, r, Horizon::Steps(k)))
                .sum::<f64>()
                / trials.len() as f64
        };
        let (c5, t5, c10, t10) = (
            f(&conv.model, 5),
            f(&rep.best_model, 5),
            f(&conv.model, 10),
            f(&rep.best_model, 10),
        );
        let worst_std = rep.tuned.std_pct.iter().fold(0.0_f64, |a, &b| a.max(b));
        println!(
            "conventional 5/10: {c5:.3}/{c10:.3} %, tuned {t5:.3}/{t10:.3} %, λ {:.3e}, worst STD% {worst_std:.1}, {} generations",
            rep.lambda, rep.generations
        );
        let conv_worst = conv.std_pct.iter().fold(0.0_f64, |a, &b| a.max(b));
        println!("conventional worst STD% {conv_worst:.1}");
        assert!(worst_std <= cfg.std_limit, "{:?}", rep.tuned.std_pct);
        assert!(conv_worst > worst_std);
        // the issue's acceptance: the tuned model beats the conventional one at 5 and 10 steps
        assert!(
            t5 > c5 && t10 > c10,
            "tuned {t5}/{t10} vs conventional {c5}/{c10}"
        );
        let again = ga::tune(&sim_recs, &trials, &base, &cfg).unwrap();
        assert_eq!(again.best_model, rep.best_model);
    }
}
