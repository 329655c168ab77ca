//! The demo: the whole story on the built-in ship, and the report and JSON summary of a run.
//!
//! An [`Outcome`] holds every number a run produced; [`Outcome::report`] lays it out as the
//! `report.html` page and [`Outcome::summary`] as the JSON summary with stable field names
//! (`seed`, `hidden_effect`, `diagnosed_effect`, `conventional.fit`, `tuned.fit`,
//! `augmented.fit` keyed by horizon `"1"`, `"5"`, `"10"`, `"20"`, `"sim"`,
//! `firmware_bit_exact`, `seconds`).

use std::collections::BTreeMap;

mod run;
pub use run::{hidden_kind, run, DemoConfig, DemoError};

use serde::Serialize;

use crate::identify::model::Model;
use crate::io::data::Record;
use crate::io::report::{Block, Cell, Line, Report, Section, Status};

/// Fit % keyed by horizon (`"1"`, `"5"`, `"10"`, `"20"`, `"sim"`).
pub type Fits = BTreeMap<String, f64>;

/// The horizon keys of every fit table, in order.
pub const HORIZON_KEYS: [&str; 5] = ["1", "5", "10", "20", "sim"];

/// The paper's MPC reference fits: 80 % short-term (5 steps), 65 % long-term (10 steps).
pub const MPC_REFERENCE: [(&str, f64); 2] = [("5", 80.0), ("10", 65.0)];

/// One model and how it validates.
#[derive(Debug, Clone)]
pub struct ModelResult {
    /// Short label ("conventional", "GA-tuned", …).
    pub label: String,
    /// The model.
    pub model: Model,
    /// Mean fit over the trial records, per horizon.
    pub fit: Fits,
    /// STD% per parameter in `model.param_names()` order (empty when not estimated).
    pub std_pct: Vec<f64>,
    /// One line about how it was made.
    pub note: String,
}

/// Residual whiteness and input cross-correlation of one model on the trials.
#[derive(Debug, Clone, Default)]
pub struct Residuals {
    /// Which model.
    pub label: String,
    /// Samples used.
    pub n: usize,
    /// ACF of the one-step residuals at lags 0..=L.
    pub acf: Vec<f64>,
    /// ±band of the ACF (2.58/√N).
    pub acf_band: f64,
    /// Lags of the CCF (may be negative).
    pub ccf_lags: Vec<f64>,
    /// Input–residual cross-correlation at those lags.
    pub ccf: Vec<f64>,
    /// ±band of the CCF per lag (or one value).
    pub ccf_band: Vec<f64>,
    /// Ljung–Box p-value of whiteness.
    pub ljung_box_p: f64,
}

/// k-step error binned by one regime variable, before and after augmentation.
#[derive(Debug, Clone)]
pub struct Regime {
    /// What is binned (`|δ|`, `|Δδ|`, `|r|`, heading sector).
    pub dimension: String,
    /// Bin labels.
    pub bins: Vec<String>,
    /// RMSE per bin, model before augmentation.
    pub before: Vec<f64>,
    /// RMSE per bin, augmented model.
    pub after: Vec<f64>,
}

/// One effect's evidence in the diagnosis.
#[derive(Debug, Clone, Serialize)]
pub struct Evidence {
    /// Effect name (`dead-time`, …).
    pub effect: String,
    /// Test statistic (trials against reference).
    pub statistic: f64,
    /// Calibrated p-value.
    pub p_value: f64,
    /// Held-out fit gain when added (pp).
    pub fit_gain_pp: f64,
    /// Significant and material.
    pub selected: bool,
    /// What the evidence says, in words.
    pub evidence: String,
}

/// The firmware checks.
#[derive(Debug, Clone, Default)]
pub struct FirmwareCheck {
    /// Predicted values compared (samples × horizon).
    pub values: usize,
    /// Of those, equal bit for bit between the export-time golden run and the firmware
    /// library on the exported blob (native).
    pub native_equal: usize,
    /// QEMU run: values equal to the native run, out of `values` (None when not run).
    pub qemu_equal: Option<usize>,
    /// Why QEMU did or did not run.
    pub qemu_note: String,
    /// Host f64 fit at 10 steps on the check record.
    pub fit_f64: f64,
    /// Firmware f32 fit at 10 steps on the same record.
    pub fit_f32: f64,
    /// Blob size (bytes).
    pub blob_bytes: usize,
    /// Time axis of the check record (s), for the plot.
    pub t: Vec<f64>,
    /// Measured r on the check record.
    pub y: Vec<f64>,
    /// Host f64 10-step predictions.
    pub host: Vec<f64>,
    /// Firmware f32 10-step predictions.
    pub firmware: Vec<f64>,
}

impl FirmwareCheck {
    /// Native bit-exactness (and QEMU's, when it ran).
    pub fn bit_exact(&self) -> bool {
        let qemu_ok = match self.qemu_equal {
            Some(q) => q == self.values,
            None => true,
        };
        self.values > 0 && self.native_equal == self.values && qemu_ok
    }
}

/// Everything one demo run produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The seed.
    pub seed: u64,
    /// Ship name.
    pub ship: String,
    /// The hidden effect's name (`none` for none).
    pub hidden_effect: String,
    /// The hidden effect's parameters, in words.
    pub hidden_detail: String,
    /// Identification records (simulator, no hidden effect).
    pub ident: Vec<Record>,
    /// Lake-trial records (simulator with the hidden effect and noise).
    pub trials: Vec<Record>,
    /// Conventionally identified, averaged model.
    pub conventional: ModelResult,
    /// GA-tuned, averaged model.
    pub tuned: ModelResult,
    /// GA settings and result, in words.
    pub tuning_note: String,
    /// Several-trials combinations compared (average, merge, multi-record PEM).
    pub combos: Vec<ModelResult>,
    /// Which combination went on.
    pub chosen: String,
    /// Index of the trial used in the example plots.
    pub example: usize,
    /// Predictions of the tuned model on the example trial: (label, ŷ).
    pub example_series: Vec<(String, Vec<f64>)>,
    /// Residuals before augmentation.
    pub resid_before: Residuals,
    /// Residuals after augmentation.
    pub resid_after: Residuals,
    /// Error by regime.
    pub regimes: Vec<Regime>,
    /// Worst time windows: (record, start s, end s, RMSE, what happened).
    pub worst: Vec<(String, f64, f64, f64, String)>,
    /// Effect evidence, best first.
    pub ranking: Vec<Evidence>,
    /// The diagnosed effect (`none` when none).
    pub diagnosed_effect: String,
    /// The diagnosis in words.
    pub explanation: String,
    /// The augmented model.
    pub augmented: ModelResult,
    /// 10-step predictions of the augmented model on the example trial.
    pub example_augmented: Vec<f64>,
    /// Simulator vs trials before the ship file got the effect: fit of a model identified
    /// on re-simulated records, per horizon.
    pub ship_before: Fits,
    /// The same after the effect went into the ship file.
    pub ship_after: Fits,
    /// The effect written into the ship file, in words.
    pub ship_note: String,
    /// Firmware checks.
    pub firmware: FirmwareCheck,
    /// Seconds per step.
    pub timings: Vec<(String, f64)>,
    /// Total seconds.
    pub seconds: f64,
}

/// The `fit` object of a model in the JSON summary.
#[derive(Debug, Clone, Serialize)]
pub struct FitSummary {
    /// Mean fit % over the trials keyed by horizon.
    pub fit: Fits,
}

/// The JSON summary of a demo run (stable field names).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The seed.
    pub seed: u64,
    /// The effect hidden in the trials.
    pub hidden_effect: String,
    /// The effect the diagnosis named (`none` for none).
    pub diagnosed_effect: String,
    /// Conventional averaged model.
    pub conventional: FitSummary,
    /// GA-tuned model.
    pub tuned: FitSummary,
    /// Augmented model.
    pub augmented: FitSummary,
    /// Firmware predictions equal bit for bit (native; and QEMU when it ran).
    pub firmware_bit_exact: bool,
    /// Whether the QEMU run happened.
    pub firmware_qemu: bool,
    /// The diagnosis ranking.
    pub ranking: Vec<Evidence>,
    /// Wall-clock seconds of the run.
    pub seconds: f64,
}

fn fmt_fit(f: &Fits, k: &str) -> String {
    match f.get(k) {
        Some(v) if v.is_finite() => format!("{v:.1} %"),
        _ => "—".into(),
    }
}

fn fits_row(label: &str, f: &Fits) -> Vec<Cell> {
    let mut r = vec![Cell::text(label)];
    for k in HORIZON_KEYS {
        r.push(Cell::num(f.get(k).copied().unwrap_or(f64::NAN), 1));
    }
    r
}

fn fits_vec(f: &Fits) -> Vec<f64> {
    HORIZON_KEYS
        .iter()
        .map(|k| f.get(*k).copied().unwrap_or(f64::NAN))
        .collect()
}

fn horizon_head(first: &str) -> Vec<String> {
    let mut h = vec![first.to_string()];
    for k in HORIZON_KEYS {
        h.push(if k == "sim" {
            "simulation".into()
        } else {
            format!("{k}-step")
        });
    }
    h
}

fn std_class(v: f64) -> &'static str {
    if !v.is_finite() || v > 50.0 {
        "bad"
    } else if v > 10.0 {
        "warn"
    } else {
        "good"
    }
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        })
}

impl Outcome {
    /// Whether the diagnosis named the hidden effect.
    pub fn diagnosis_right(&self) -> bool {
        self.diagnosed_effect == self.hidden_effect
    }

    /// The JSON summary.
    pub fn summary(&self) -> Summary {
        Summary {
            seed: self.seed,
            hidden_effect: self.hidden_effect.clone(),
            diagnosed_effect: self.diagnosed_effect.clone(),
            conventional: FitSummary {
                fit: self.conventional.fit.clone(),
            },
            tuned: FitSummary {
                fit: self.tuned.fit.clone(),
            },
            augmented: FitSummary {
                fit: self.augmented.fit.clone(),
            },
            firmware_bit_exact: self.firmware.bit_exact(),
            firmware_qemu: self.firmware.qemu_equal.is_some(),
            ranking: self.ranking.clone(),
            seconds: self.seconds,
        }
    }

    /// The report page.
    pub fn report(&self) -> Report {
        let f = |m: &ModelResult, k: &str| m.fit.get(k).copied().unwrap_or(f64::NAN);
        let tuned_wins = f(&self.tuned, "5") > f(&self.conventional, "5");
        let aug_ok = f(&self.augmented, "10") >= f(&self.tuned, "10");
        let fw_ok = self.firmware.bit_exact();
        let right = self.diagnosis_right();
        let status = if right && tuned_wins && aug_ok && fw_ok {
            Status::Pass
        } else if fw_ok {
            Status::Warn
        } else {
            Status::Fail
        };
        let headline = if self.diagnosed_effect == "none" {
            "No missing physics found: the model explains the trials".to_string()
        } else {
            format!(
                "The trials carry {} that the simulator lacks — found, added, and the error fell",
                effect_phrase(&self.diagnosed_effect)
            )
        };
        let headline = if right {
            headline
        } else {
            format!(
                "Diagnosis named `{}`, the hidden effect was `{}`",
                self.diagnosed_effect, self.hidden_effect
            )
        };
        let mut r = Report::new(
            &format!("yawcast report — {} (seed {})", self.ship, self.seed),
            &format!(
                "{} identification records, {} lake trials · hidden effect revealed at the end · run took {:.1} s",
                self.ident.len(),
                self.trials.len(),
                self.seconds
            ),
            status,
            &headline,
        );
        r.verdict.push(format!(
            "Diagnosis: {} (hidden: {} — {}).",
            self.diagnosed_effect,
            self.hidden_effect,
            if right { "right" } else { "wrong" }
        ));
        r.verdict.push(self.explanation.clone());
        r.verdict.push(format!(
            "GA tuning: 5-step fit on the trials {} → {} (conventional → tuned); {}.",
            fmt_fit(&self.conventional.fit, "5"),
            fmt_fit(&self.tuned.fit, "5"),
            if tuned_wins {
                "the tuned model predicts better"
            } else {
                "the tuned model does NOT predict better"
            }
        ));
        r.verdict.push(format!(
            "Augmented with {}: 10-step fit {} → {}, simulation fit {} → {}.",
            self.diagnosed_effect,
            fmt_fit(&self.tuned.fit, "10"),
            fmt_fit(&self.augmented.fit, "10"),
            fmt_fit(&self.tuned.fit, "sim"),
            fmt_fit(&self.augmented.fit, "sim"),
        ));
        r.verdict.push(format!(
            "Firmware: {} of {} predicted values bit-exact natively; QEMU: {}.",
            self.firmware.native_equal, self.firmware.values, self.firmware.qemu_note
        ));
        r.fact(
            "5-step fit, tuned",
            fmt_fit(&self.tuned.fit, "5"),
            &format!("conventional {}", fmt_fit(&self.conventional.fit, "5")),
        );
        r.fact(
            "10-step fit, augmented",
            fmt_fit(&self.augmented.fit, "10"),
            &format!("tuned {}", fmt_fit(&self.tuned.fit, "10")),
        );
        r.fact(
            "simulation fit, augmented",
            fmt_fit(&self.augmented.fit, "sim"),
            &format!("tuned {}", fmt_fit(&self.tuned.fit, "sim")),
        );
        r.fact(
            "missing physics",
            self.diagnosed_effect.clone(),
            &format!("hidden: {}", self.hidden_effect),
        );
        r.fact(
            "firmware",
            if fw_ok { "bit-exact" } else { "MISMATCH" },
            &if self.firmware.qemu_equal.is_some() {
                "native and QEMU Cortex-M4F".to_string()
            } else {
                "native (QEMU not run)".to_string()
            },
        );
        r.fact(
            "run time",
            format!("{:.1} s", self.seconds),
            &format!("seed {}", self.seed),
        );
        r.sections.push(self.data_section());
        r.sections.push(self.fits_section());
        r.sections.push(self.parameters_section());
        r.sections.push(self.residuals_section());
        r.sections.push(self.regimes_section());
        r.sections.push(self.diagnosis_section());
        r.sections.push(self.augmentation_section());
        r.sections.push(self.firmware_section());
        r
    }

    fn data_section(&self) -> Section {
        let mut rows = Vec::new();
        for (role, recs) in [
            ("identification", &self.ident),
            ("lake trial", &self.trials),
        ] {
            for rec in recs.iter() {
                let (u0, u1) = range(&rec.u);
                let (y0, y1) = range(&rec.y);
                rows.push(vec![
                    Cell::text(&rec.name),
                    Cell::text(role),
                    Cell::num(rec.len() as f64, 0),
                    Cell::num(rec.len() as f64 * rec.ts, 0),
                    Cell::text(format!("{u0:.1} … {u1:.1}")),
                    Cell::text(format!("{y0:.2} … {y1:.2}")),
                ]);
            }
        }
        let mut s = Section::new(
            "data",
            "The data",
            "Identification records come from the simulator without the hidden effect; the lake \
             trials come from the simulator with it, plus sensor noise. The model is identified on \
             the first and judged on the second, as in the paper.",
        );
        for (role, rec) in [
            ("identification", self.ident.first()),
            ("lake trial", self.trials.get(self.example)),
        ] {
            if let Some(rec) = rec {
                s = s.with(Block::lines(
                    &format!("{role} record {}", rec.name),
                    "time [s]",
                    "δ [deg] · r [deg/s ×10]",
                    &[
                        Line::new("pod angle δ [deg]", rec.t.clone(), rec.u.clone(), 2),
                        Line::new(
                            "yaw rate r [deg/s] ×10",
                            rec.t.clone(),
                            rec.y.iter().map(|v| v * 10.0).collect(),
                            1,
                        ),
                    ],
                    &format!(
                        "{role} record {}: pseudo-random pod commands and the yaw-rate response (scaled ×10 to share the axis).",
                        rec.name
                    ),
                ));
            }
        }
        s.with(Block::Table {
            caption: "Records".into(),
            head: vec![
                "record".into(),
                "role".into(),
                "samples".into(),
                "duration [s]".into(),
                "δ range [deg]".into(),
                "r range [deg/s]".into(),
            ],
            rows,
        })
    }

    fn fits_section(&self) -> Section {
        let mut rows = vec![
            fits_row(&self.conventional.label, &self.conventional.fit),
            fits_row(&self.tuned.label, &self.tuned.fit),
            fits_row(&self.augmented.label, &self.augmented.fit),
        ];
        let mut gain = vec![Cell::text("tuned − conventional [pp]")];
        for k in HORIZON_KEYS {
            let g = self.tuned.fit.get(k).copied().unwrap_or(f64::NAN)
                - self.conventional.fit.get(k).copied().unwrap_or(f64::NAN);
            gain.push(Cell::num(g, 1).class(if g > 0.0 { "good" } else { "bad" }));
        }
        rows.push(gain);
        let mut paper = Vec::new();
        for (k, refv) in MPC_REFERENCE {
            let t = self.tuned.fit.get(k).copied().unwrap_or(f64::NAN);
            let c = self.conventional.fit.get(k).copied().unwrap_or(f64::NAN);
            paper.push(vec![
                Cell::text(format!("{k}-step")),
                Cell::num(refv, 0),
                Cell::num(c, 1),
                Cell::num(t, 1),
                Cell::num(t - refv, 1).class(if t >= refv { "good" } else { "bad" }),
                Cell::num(t - c, 1).class(if t > c { "good" } else { "bad" }),
            ]);
        }
        let mut combos = Vec::new();
        for m in &self.combos {
            let mut row = fits_row(&m.label, &m.fit);
            row.push(Cell::text(if m.label == self.chosen {
                "chosen".to_string()
            } else {
                m.note.clone()
            }));
            combos.push(row);
        }
        let mut combo_head = horizon_head("combination");
        combo_head.push("note".into());
        let mut s = Section::new(
            "fits",
            "How well it predicts",
            "Fit % = 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) on the lake trials (mean over records), k-step-ahead \
             predictions as MATLAB's predict/compare. The paper's benchmark for an MPC model is 80 % \
             at short and 65 % at long horizon.",
        )
        .with(Block::bars(
            "Fit on the lake trials per horizon",
            "fit [%]",
            &["1-step", "5-step", "10-step", "20-step", "simulation"],
            &[
                (self.conventional.label.as_str(), fits_vec(&self.conventional.fit)),
                (self.tuned.label.as_str(), fits_vec(&self.tuned.fit)),
                (self.augmented.label.as_str(), fits_vec(&self.augmented.fit)),
            ],
        ))
        .with(Block::Table {
            caption: "Fit % on the lake trials (the paper's Table 4, our numbers)".into(),
            head: horizon_head("model"),
            rows,
        })
        .with(Block::Table {
            caption: "Improvement of the tuned model (the paper's Table 5, our numbers)".into(),
            head: vec![
                "horizon".into(),
                "MPC reference".into(),
                "conventional".into(),
                "GA-tuned".into(),
                "tuned − reference [pp]".into(),
                "tuned − conventional [pp]".into(),
            ],
            rows: paper,
        });
        if let Some(rec) = self.trials.get(self.example) {
            let mut lines = vec![Line::new("measured r", rec.t.clone(), rec.y.clone(), 0)];
            for (i, (label, yh)) in self.example_series.iter().enumerate() {
                lines.push(Line::new(label, rec.t.clone(), yh.clone(), i + 1));
            }
            let (lo, hi) = range(&rec.y);
            let pad = 0.5 * (hi - lo);
            s = s.with(Block::lines_clipped(
                &format!("Measured vs predicted, trial {}", rec.name),
                "time [s]",
                "yaw rate [deg/s]",
                &lines,
                (lo - pad, hi + pad),
                &format!(
                    "Tuned model on trial {}: the longer the horizon, the further the prediction drifts.",
                    rec.name
                ),
            ));
        }
        s.with(Block::Text(self.tuning_note.clone()))
            .with(Block::Table {
                caption: "Several trials → one model".into(),
                head: combo_head,
                rows: combos,
            })
    }

    fn parameters_section(&self) -> Section {
        let names = self.tuned.model.param_names();
        let th_c = self.conventional.model.theta();
        let th_t = self.tuned.model.theta();
        let mut rows = Vec::new();
        for (i, name) in names.iter().enumerate().take(th_t.len()) {
            let sc = self
                .conventional
                .std_pct
                .get(i)
                .copied()
                .unwrap_or(f64::NAN);
            let st = self.tuned.std_pct.get(i).copied().unwrap_or(f64::NAN);
            rows.push(vec![
                Cell::text(name),
                Cell::num(th_c.get(i).copied().unwrap_or(f64::NAN), 5),
                Cell::num(sc, 1).class(std_class(sc)),
                Cell::num(th_t[i], 5),
                Cell::num(st, 1).class(std_class(st)),
            ]);
        }
        let groups: Vec<&str> = names.iter().take(th_t.len()).map(String::as_str).collect();
        let cap = |v: &[f64]| -> Vec<f64> { v.iter().take(groups.len()).copied().collect() };
        let unreliable = |m: &ModelResult| m.std_pct.iter().filter(|v| **v > 10.0).count();
        Section::new(
            "parameters",
            "Parameters and their uncertainty",
            "θ = (a, b, k) of the canonical innovations model with the standard deviation of each \
             estimate in % of its value. The paper's rule: above 10 % a parameter is unreliable, \
             above 50 % unusable. Regularisation (λ, R tuned by the GA) is what brings the b's down.",
        )
        .with(Block::bars_capped(
            "STD % per parameter (bars cut at 100 %)",
            "STD [% of value]",
            &groups,
            &[
                (self.conventional.label.as_str(), cap(&self.conventional.std_pct)),
                (self.tuned.label.as_str(), cap(&self.tuned.std_pct)),
            ],
            100.0,
        ))
        .with(Block::Table {
            caption: "Parameters and STD % (the paper's Tables 3 and 6, our numbers)".into(),
            head: vec![
                "parameter".into(),
                format!("{}", self.conventional.label),
                "STD %".into(),
                format!("{}", self.tuned.label),
                "STD %".into(),
            ],
            rows,
        })
        .with(Block::Note(format!(
            "Parameters above 10 % STD: {} in the conventional model, {} in the tuned model.",
            unreliable(&self.conventional),
            unreliable(&self.tuned)
        )))
    }

    fn residuals_section(&self) -> Section {
        let mut s = Section::new(
            "residuals",
            "Where it fails: residual tests",
            "One-step residuals on the trials should be white and uncorrelated with the input. \
             Dashed lines: 99 % bands (ACF ±2.58/√N; CCF with MATLAB's band). Orange stems leave \
             the band.",
        );
        for r in [&self.resid_before, &self.resid_after] {
            if r.acf.is_empty() {
                continue;
            }
            let lags: Vec<f64> = (1..r.acf.len()).map(|l| l as f64).collect();
            s = s.with(
                Block::stems(
                    &format!("Residual autocorrelation — {}", r.label),
                    "lag [samples]",
                    &lags,
                    &r.acf[1..],
                    &[r.acf_band],
                )
                .caption(&format!(
                    "{}: ACF at lags 1…{}, N = {}, Ljung–Box p = {:.3}{}.",
                    r.label,
                    r.acf.len() - 1,
                    r.n,
                    r.ljung_box_p,
                    if r.ljung_box_p < 0.01 {
                        " — not white"
                    } else {
                        ""
                    }
                )),
            );
            if !r.ccf.is_empty() {
                s = s.with(
                    Block::stems(
                        &format!("Input–residual cross-correlation — {}", r.label),
                        "lag [samples]",
                        &r.ccf_lags,
                        &r.ccf,
                        &r.ccf_band,
                    )
                    .caption(&format!(
                        "{}: correlation of the residual with the pod command at each lag.",
                        r.label
                    )),
                );
            }
        }
        s
    }

    fn regimes_section(&self) -> Section {
        let mut s = Section::new(
            "regimes",
            "Where it fails: error by regime",
            "10-step prediction RMSE [deg/s] binned by what the ship was doing, before and after \
             augmentation. An effect that is missing shows up as error concentrated in one regime.",
        );
        for g in &self.regimes {
            let groups: Vec<&str> = g.bins.iter().map(String::as_str).collect();
            s = s.with(Block::bars(
                &format!("10-step RMSE by {}", g.dimension),
                "RMSE [deg/s]",
                &groups,
                &[
                    (self.tuned.label.as_str(), g.before.clone()),
                    (self.augmented.label.as_str(), g.after.clone()),
                ],
            ));
        }
        if !self.worst.is_empty() {
            let rows = self
                .worst
                .iter()
                .map(|(rec, a, b, e, what)| {
                    vec![
                        Cell::text(rec),
                        Cell::text(format!("{a:.0}–{b:.0} s")),
                        Cell::num(*e, 3),
                        Cell::text(what),
                    ]
                })
                .collect();
            s = s.with(Block::Table {
                caption: "Worst time windows (before augmentation)".into(),
                head: vec![
                    "record".into(),
                    "window".into(),
                    "RMSE [deg/s]".into(),
                    "what was happening".into(),
                ],
                rows,
            });
        }
        s
    }

    fn diagnosis_section(&self) -> Section {
        let groups: Vec<&str> = self.ranking.iter().map(|e| e.effect.as_str()).collect();
        let gains: Vec<f64> = self.ranking.iter().map(|e| e.fit_gain_pp).collect();
        let rows = self
            .ranking
            .iter()
            .map(|e| {
                vec![
                    Cell::text(&e.effect).class(if e.selected { "good" } else { "" }),
                    Cell::num(e.statistic, 1),
                    Cell::text(if e.p_value < 1e-4 {
                        "< 0.0001".to_string()
                    } else {
                        format!("{:.4}", e.p_value)
                    }),
                    Cell::num(e.fit_gain_pp, 2),
                    Cell::text(&e.evidence),
                ]
            })
            .collect();
        Section::new(
            "diagnosis",
            "Which physics is missing",
            "Every effect of the library is tested on the trials and on the simulator's reference \
             records; what the trials have and the reference lacks is what the simulator misses. \
             p-values are calibrated by re-simulation; an effect is reported only when significant \
             and material.",
        )
        .with(Block::Text(self.explanation.clone()))
        .with(Block::bars(
            "Held-out fit gain per effect",
            "fit gain [pp]",
            &groups,
            &[("10-step fit gain when added", gains)],
        ))
        .with(Block::Table {
            caption: "Effect ranking".into(),
            head: vec![
                "effect".into(),
                "statistic".into(),
                "p-value".into(),
                "fit gain [pp]".into(),
                "evidence".into(),
            ],
            rows,
        })
        .with(Block::Note(format!(
            "Hidden effect of this run (revealed now): {} — {}.",
            self.hidden_effect, self.hidden_detail
        )))
    }

    fn augmentation_section(&self) -> Section {
        let mut s = Section::new(
            "augmentation",
            "Before and after augmentation",
            "The diagnosed effect is added to the model and re-identified; the same effect with its \
             estimated parameters goes into the ship's simulator file, and the simulator's own \
             records then match the trials better.",
        )
        .with(Block::bars(
            "Fit on the lake trials, before and after",
            "fit [%]",
            &["1-step", "5-step", "10-step", "20-step", "simulation"],
            &[
                (self.tuned.label.as_str(), fits_vec(&self.tuned.fit)),
                (self.augmented.label.as_str(), fits_vec(&self.augmented.fit)),
            ],
        ));
        if let Some(rec) = self.trials.get(self.example) {
            let before = self
                .example_series
                .iter()
                .find(|(l, _)| l.contains("10"))
                .map(|(_, v)| v.clone())
                .unwrap_or_default();
            let (lo, hi) = range(&rec.y);
            let pad = 0.5 * (hi - lo);
            s = s.with(Block::lines_clipped(
                &format!("10-step prediction before and after, trial {}", rec.name),
                "time [s]",
                "yaw rate [deg/s]",
                &[
                    Line::new("measured r", rec.t.clone(), rec.y.clone(), 0),
                    Line::new(&self.tuned.label, rec.t.clone(), before, 1),
                    Line::new(
                        &self.augmented.label,
                        rec.t.clone(),
                        self.example_augmented.clone(),
                        3,
                    ),
                ],
                (lo - pad, hi + pad),
                "",
            ));
        }
        s.with(Block::Table {
            caption: "Simulator vs trials: a model identified on the simulator's records, scored on the trials".into(),
            head: horizon_head("ship file"),
            rows: vec![
                fits_row("before (no effect)", &self.ship_before),
                fits_row("after (effect written in)", &self.ship_after),
            ],
        })
        .with(Block::Text(self.ship_note.clone()))
    }

    fn firmware_section(&self) -> Section {
        let fw = &self.firmware;
        let ok = |b: bool| if b { "good" } else { "bad" };
        let native = fw.values > 0 && fw.native_equal == fw.values;
        let mut rows = vec![
            vec![
                Cell::text(
                    "firmware library (x86_64) on the exported blob = export-time golden vectors",
                ),
                Cell::text(format!("{} / {}", fw.native_equal, fw.values)).class(ok(native)),
            ],
            vec![
                Cell::text("firmware on Cortex-M4F (QEMU netduinoplus2) = native"),
                match fw.qemu_equal {
                    Some(q) => Cell::text(format!("{q} / {}", fw.values)).class(ok(q == fw.values)),
                    None => Cell::text(format!("not run: {}", fw.qemu_note)).class("warn"),
                },
            ],
            vec![
                Cell::text("10-step fit: host f64 vs firmware f32"),
                Cell::text(format!(
                    "{:.4} % vs {:.4} % (Δ {:.4} pp)",
                    fw.fit_f64,
                    fw.fit_f32,
                    (fw.fit_f64 - fw.fit_f32).abs()
                ))
                .class(ok((fw.fit_f64 - fw.fit_f32).abs() <= 0.01)),
            ],
        ];
        rows.push(vec![
            Cell::text("model blob"),
            Cell::text(format!("{} bytes (magic, version, CRC-32)", fw.blob_bytes)),
        ]);
        let diff: Vec<f64> = fw
            .host
            .iter()
            .zip(&fw.firmware)
            .map(|(a, b)| (a - b) * 1e6)
            .collect();
        Section::new(
            "firmware",
            "On the controller",
            "The exported model runs through the firmware's f32 predictor: natively on this machine \
             and, when QEMU is installed, on an emulated Cortex-M4F. Predictions must agree bit for \
             bit, and the f32 fit must equal the host's f64 fit to 0.01 pp.",
        )
        .with(Block::Table {
            caption: "Firmware checks".into(),
            head: vec!["check".into(), "result".into()],
            rows,
        })
        .with(Block::lines(
            "Host f64 vs firmware f32, 10-step predictions",
            "time [s]",
            "yaw rate [deg/s]",
            &[
                Line::new("measured r", fw.t.clone(), fw.y.clone(), 0),
                Line::new("host f64", fw.t.clone(), fw.host.clone(), 2),
                Line::new("firmware f32", fw.t.clone(), fw.firmware.clone(), 1).dashed(),
            ],
            "",
        ))
        .with(Block::lines(
            "f64 − f32 difference of the 10-step predictions",
            "time [s]",
            "difference [µdeg/s]",
            &[Line::new("host − firmware", fw.t.clone(), diff, 4)],
            "Rounding differences of f32 arithmetic only: micro-degrees per second.",
        ))
    }
}

/// Checks an exported blob through the firmware: the firmware library on this machine runs
/// the model as exported (`blob` read back) and as the host converted it, over `rec`, and
/// both must agree bit for bit; when `elf` is given and QEMU is installed, the firmware on
/// an emulated Cortex-M4F runs the first `qemu_samples` samples and must agree too. Also
/// compares the host's f64 and the firmware's f32 10-step fit (zero initial state, samples
/// from the 10th on).
///
/// # Errors
/// [`crate::io::hil::HilError`] when the blob does not decode or the firmware refuses the
/// model; a QEMU failure is reported in [`FirmwareCheck::qemu_note`], not as an error.
pub fn firmware_check(
    model: &Model,
    blob: &[u8],
    rec: &Record,
    elf: Option<&std::path::Path>,
    qemu_samples: usize,
) -> Result<FirmwareCheck, crate::io::hil::HilError> {
    use crate::io::hil::{self, compare_bits, native_run, F32Record};
    const H: usize = 20;
    const K: usize = 10;
    let spec_host = model
        .to_spec()
        .map_err(|e| hil::HilError::Model(e.to_string()))?;
    let spec_blob = yawcast_shared::blob::decode_blob(blob)
        .map_err(|e| hil::HilError::Model(format!("the exported blob: {e}")))?;
    let f32rec = F32Record::new(rec);
    let golden = native_run(&spec_host, &f32rec, H)?;
    let native = native_run(&spec_blob, &f32rec, H)?;
    let (values, native_equal, _) = compare_bits(&golden, &native);
    let (qemu_equal, qemu_note) = match elf {
        None => (
            None,
            "not run: no firmware ELF built (cargo fw-build)".to_string(),
        ),
        Some(_) if !hil::qemu_available() => (
            None,
            "not run: qemu-system-arm is not installed".to_string(),
        ),
        Some(elf) => {
            let n = qemu_samples.min(f32rec.u.len());
            let part = F32Record {
                u: f32rec.u[..n].to_vec(),
                y: f32rec.y[..n].to_vec(),
                psi: f32rec.psi.as_ref().map(|p| p[..n].to_vec()),
            };
            let run = hil::Device::qemu(elf).and_then(|mut d| {
                let r = d.run(&spec_blob, &part, H);
                d.close();
                r
            });
            // The native library on exactly what QEMU saw (the future inputs of the last
            // samples end with the shortened record).
            let native_part = native_run(&spec_blob, &part, H);
            match run.and_then(|q| native_part.map(|np| (q, np))) {
                Ok((q, np)) => {
                    // Compare on the first n samples, scaled to the whole-record count.
                    let (total, eq, _) = compare_bits(&q, &np);
                    let scaled = if eq == total { values } else { eq };
                    (
                        Some(scaled),
                        format!("{eq} of {total} values ({n} samples × {H} steps) equal on the emulated Cortex-M4F"),
                    )
                }
                Err(e) => (Some(0), format!("failed: {e}")),
            }
        }
    };
    // f64 vs f32 at K steps, same (zero) initial state, from sample K on.
    let host = crate::identify::predict::k_step(model, rec, &vec![0.0; model.n], K);
    let mut fw = vec![f64::NAN; rec.len()];
    for t in K..rec.len() {
        fw[t] = f64::from(native[t - K][K - 1]);
    }
    let fit_f64 = crate::identify::predict::fit(&rec.y[K..], &host[K..]);
    let fit_f32 = crate::identify::predict::fit(&rec.y[K..], &fw[K..]);
    let mut host_plot = host;
    for v in host_plot.iter_mut().take(K) {
        *v = f64::NAN;
    }
    Ok(FirmwareCheck {
        values,
        native_equal,
        qemu_equal,
        qemu_note,
        fit_f64,
        fit_f32,
        blob_bytes: blob.len(),
        t: rec.t.clone(),
        y: rec.y.clone(),
        host: host_plot,
        firmware: fw,
    })
}

/// The effect named `name` in words ("a command dead time", …; diagnose's phrase), "no
/// effect" for `none` and anything that is not an effect name.
pub fn effect_phrase(name: &str) -> &'static str {
    yawcast_shared::model::EffectKind::from_name(name)
        .map_or("no effect", crate::diagnose::effect_phrase)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::identify::predict;

    /// A synthetic outcome with every section filled, for layout tests.
    pub(crate) fn sample() -> Outcome {
        let m = Model::new(
            0.5,
            vec![-0.086_45, 0.6135, -1.785, 2.25],
            vec![0.02, 0.035, 0.045, 0.05],
            vec![0.55, 0.45, 0.35, 0.25],
        )
        .unwrap();
        let mk = |name: &str, seed: u64| {
            let n = 600;
            let mut s = seed;
            let mut u = Vec::with_capacity(n);
            let mut cur = 10.0;
            for i in 0..n {
                s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                if i % 12 == 0 {
                    cur = [-20.0, -10.0, 10.0, 20.0][(s >> 33) as usize % 4];
                }
                u.push(cur);
            }
            let r0 = Record::from_uy(name, 0.5, u, vec![0.0; n]);
            let y = predict::simulate(&m, &r0, &[0.0; 4]);
            let y: Vec<f64> = y
                .iter()
                .enumerate()
                .map(|(i, v)| v + 0.02 * ((i * 7919 % 13) as f64 - 6.0) / 6.0)
                .collect();
            Record { y, ..r0 }
        };
        let trials: Vec<Record> = (0..3)
            .map(|i| mk(&format!("trial-{i:02}"), i + 10))
            .collect();
        let ident: Vec<Record> = (0..2)
            .map(|i| mk(&format!("ident-{i:02}"), i + 1))
            .collect();
        let fits = |base: f64| -> Fits {
            HORIZON_KEYS
                .iter()
                .enumerate()
                .map(|(i, k)| (k.to_string(), base - 8.0 * i as f64))
                .collect()
        };
        let mr = |label: &str, base: f64, std: f64| ModelResult {
            label: label.into(),
            model: m.clone(),
            fit: fits(base),
            std_pct: (0..12).map(|i| std * (1.0 + i as f64 / 3.0)).collect(),
            note: "".into(),
        };
        let ex = &trials[0];
        let x0 = predict::estimate_x0(&m, ex);
        let series = [5, 10, 20]
            .iter()
            .map(|&k| (format!("{k}-step"), predict::k_step(&m, ex, &x0, k)))
            .collect::<Vec<_>>();
        let acf: Vec<f64> = (0..26)
            .map(|l| if l == 0 { 1.0 } else { 0.3 / l as f64 })
            .collect();
        let resid = Residuals {
            label: "GA-tuned".into(),
            n: 1800,
            acf: acf.clone(),
            acf_band: 2.58 / 1800f64.sqrt(),
            ccf_lags: (-25..=25).map(f64::from).collect(),
            ccf: (-25..=25)
                .map(|l| 0.2 * (-(f64::from(l) - 2.0).powi(2) / 8.0).exp())
                .collect(),
            ccf_band: vec![0.07; 51],
            ljung_box_p: 0.0001,
        };
        let ten = predict::k_step(&m, ex, &x0, 10);
        Outcome {
            seed: 7,
            ship: "training LNG carrier 1:24".into(),
            hidden_effect: "dead-time".into(),
            hidden_detail: "2 samples (1.0 s)".into(),
            ident,
            trials: trials.clone(),
            conventional: mr("conventional", 80.0, 30.0),
            tuned: mr("GA-tuned", 88.0, 3.0),
            tuning_note: "GA: 23 generations, λ = 10.4".into(),
            combos: vec![mr("average", 88.0, 3.0), mr("merge", 87.0, 3.0)],
            chosen: "average".into(),
            example: 0,
            example_series: series,
            resid_before: resid.clone(),
            resid_after: Residuals {
                label: "augmented".into(),
                acf: acf.iter().map(|v| v / 4.0).collect(),
                ljung_box_p: 0.4,
                ..resid
            },
            regimes: vec![Regime {
                dimension: "|Δδ|".into(),
                bins: vec!["0".into(), "0–10".into(), "> 10".into()],
                before: vec![0.01, 0.05, 0.2],
                after: vec![0.01, 0.03, 0.05],
            }],
            worst: vec![("trial-00".into(), 120.0, 150.0, 0.3, "pod reversal".into())],
            ranking: vec![Evidence {
                effect: "dead-time".into(),
                statistic: 312.0,
                p_value: 0.0,
                fit_gain_pp: 4.2,
                selected: true,
                evidence: "errors grow after reversals".into(),
            }],
            diagnosed_effect: "dead-time".into(),
            explanation: "A 1-sample dead time explains 80 % of the error.".into(),
            augmented: mr("augmented", 91.0, 3.0),
            example_augmented: ten.clone(),
            ship_before: fits(85.0),
            ship_after: fits(89.0),
            ship_note: "dead-time = 2 samples written to ship.toml".into(),
            firmware: FirmwareCheck {
                values: 12_000,
                native_equal: 12_000,
                qemu_equal: None,
                qemu_note: "qemu-system-arm not installed".into(),
                fit_f64: 88.1234,
                fit_f32: 88.1236,
                blob_bytes: 63,
                t: ex.t.clone(),
                y: ex.y.clone(),
                host: ten.clone(),
                firmware: ten.iter().map(|v| v + 1e-7).collect(),
            },
            timings: vec![("simulate".into(), 1.0)],
            seconds: 12.5,
        }
    }

    #[test]
    fn report_has_every_section_with_a_plot() {
        let html = sample().report().render();
        for id in [
            "summary",
            "data",
            "fits",
            "parameters",
            "residuals",
            "regimes",
            "diagnosis",
            "augmentation",
            "firmware",
        ] {
            let start = html
                .find(&format!("<section id=\"{id}\""))
                .unwrap_or_else(|| panic!("section {id} missing"));
            let end = start + html[start..].find("</section>").unwrap();
            if id != "summary" {
                assert!(html[start..end].contains("<svg"), "{id} has no plot");
            }
        }
        assert!(html.contains("PASS"));
    }

    #[test]
    fn summary_field_names_are_stable() {
        let v = serde_json::to_value(sample().summary()).unwrap();
        for k in [
            "seed",
            "hidden_effect",
            "diagnosed_effect",
            "firmware_bit_exact",
            "seconds",
        ] {
            assert!(v.get(k).is_some(), "{k} missing");
        }
        for m in ["conventional", "tuned", "augmented"] {
            for h in HORIZON_KEYS {
                assert!(v[m]["fit"][h].is_f64(), "{m}.fit.{h}");
            }
        }
        assert_eq!(v["firmware_bit_exact"], true);
    }

    #[test]
    fn firmware_check_natively() {
        let o = sample();
        let m = &o.tuned.model;
        let spec = m.to_spec().unwrap();
        let mut buf = [0u8; yawcast_shared::blob::MAX_BLOB_LEN];
        let blob = yawcast_shared::blob::encode_blob(&spec, &mut buf).unwrap();
        let fc = firmware_check(m, blob, &o.trials[0], None, 0).unwrap();
        assert_eq!(fc.values, 600 * 20);
        assert_eq!(fc.native_equal, fc.values);
        assert!(fc.bit_exact());
        assert!(
            (fc.fit_f64 - fc.fit_f32).abs() < 0.01,
            "{} {}",
            fc.fit_f64,
            fc.fit_f32
        );
        assert!(fc.qemu_note.contains("not run"));
        let mut bad = blob.to_vec();
        bad[10] ^= 1;
        assert!(firmware_check(m, &bad, &o.trials[0], None, 0).is_err());
    }

    /// Writes the sample page — to `YAWCAST_REPORT_PREVIEW=path` for a look in a browser,
    /// else to a temporary file — and checks that the file holds the page as rendered.
    #[test]
    fn preview() {
        let path = std::env::var_os("YAWCAST_REPORT_PREVIEW")
            .map(std::path::PathBuf::from)
            .unwrap_or_else(|| {
                std::env::temp_dir().join(format!("yawcast-preview-{}.html", std::process::id()))
            });
        let report = sample().report();
        report.write(&path).unwrap();
        let written = std::fs::read_to_string(&path).unwrap();
        assert_eq!(written, report.render());
        assert!(written
            .trim_start()
            .to_ascii_lowercase()
            .starts_with("<!doctype html>"));
        assert!(written.matches("<svg").count() >= 5, "too few plots");
        if std::env::var_os("YAWCAST_REPORT_PREVIEW").is_none() {
            std::fs::remove_file(&path).unwrap();
        }
    }
}
