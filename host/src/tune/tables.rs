//! Reports in the paper's shape: the parameter table with value, STD and STD% for the
//! conventional and the GA-tuned model side by side (its Tables 3 and 6), and the fit at 5,
//! 10 and 20 steps on the trial records against the MPC reference (its Tables 4 and 5) — as
//! Markdown and JSON written beside the model.
//!
//! "Oscillations" (Table 4's last column) is measured, not judged by eye: a model oscillates
//! when its 10-step predictions on the trial records move more from sample to sample than
//! the measurement does — the RMS of the first difference of the predictions exceeds
//! [`OSCILLATION_RATIO`] times that of the measured yaw rate (mean over the records).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::identify::model::Model;
use crate::identify::pem::{self, reliability, Reliability};
use crate::identify::predict;
use crate::io::data::{self, Record};
use crate::tune::ga::GaReport;

/// The paper's MPC reference: 80 % at 5 steps, 65 % at 10 steps.
pub const MPC_REFERENCE: [(usize, f64); 2] = [(5, 80.0), (10, 65.0)];
/// Horizons of the fit table.
pub const HORIZONS: [usize; 3] = [5, 10, 20];
/// Prediction/measurement roughness ratio above which a model "oscillates".
pub const OSCILLATION_RATIO: f64 = 1.5;

/// A model to tabulate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Label ("conventional", "GA-tuned").
    pub label: String,
    /// The model.
    pub model: Model,
    /// STD per parameter (`Model::param_names` order).
    pub std: Vec<f64>,
    /// R_i per parameter, when regularised.
    pub r: Option<Vec<f64>>,
    /// λ, when regularised.
    pub lambda: Option<f64>,
}

/// Value, STD and STD% of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Value.
    pub value: f64,
    /// Standard deviation.
    pub std: f64,
    /// 100·STD/|value|.
    pub std_pct: f64,
}

/// One parameter's line (Tables 3 and 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamRow {
    /// Parameter name (`a1`, …, `bias.beta`).
    pub name: String,
    /// Conventional model.
    pub conventional: Cell,
    /// Tuned model.
    pub tuned: Cell,
    /// R_i of the tuned model.
    pub r: Option<f64>,
}

/// One model's line of the fit table (Tables 4 and 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRow {
    /// Label.
    pub model: String,
    /// Mean fit % on the trial records per horizon (`"5"`, `"10"`, `"20"`).
    pub fit: BTreeMap<String, f64>,
    /// Percentage points above the MPC reference (`"5"`, `"10"`).
    pub above_reference: BTreeMap<String, f64>,
    /// Meets the reference at every horizon it has.
    pub meets_reference: bool,
    /// Roughness ratio of the 10-step predictions (see the module docs).
    pub roughness: f64,
    /// `roughness > OSCILLATION_RATIO`.
    pub oscillations: bool,
}

/// Both tables.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tables {
    /// λ of the tuned model.
    pub lambda: Option<f64>,
    /// Parameters side by side.
    pub params: Vec<ParamRow>,
    /// The paper's verdict for the conventional model.
    pub conventional_reliability: Reliability,
    /// The paper's verdict for the tuned model.
    pub tuned_reliability: Reliability,
    /// Fit lines: conventional, tuned.
    pub fits: Vec<FitRow>,
    /// Tuned minus conventional, percentage points per horizon.
    pub improvement: BTreeMap<String, f64>,
    /// Trial records scored.
    pub trial_records: usize,
}

/// Errors building the tables.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum TablesError {
    /// The two models have different parameters.
    #[error("the models have different parameters ({0} vs {1}); they cannot share a table")]
    Mismatch(String, String),
    /// A STD list has the wrong length.
    #[error("`{label}` has {found} STDs for {expected} parameters")]
    StdLength {
        /// Which column.
        label: String,
        /// STDs given.
        found: usize,
        /// Parameters.
        expected: usize,
    },
    /// No trial records.
    #[error("no trial records to score on")]
    NoTrials,
    /// The GA report has no conventional model to compare with.
    #[error("the GA report has no conventional model (its identification failed)")]
    NoConventional,
}

fn cells(col: &Column) -> Result<Vec<Cell>, TablesError> {
    let values = pem::params_of(&col.model);
    if col.std.len() != values.len() {
        return Err(TablesError::StdLength {
            label: col.label.clone(),
            found: col.std.len(),
            expected: values.len(),
        });
    }
    Ok(values
        .iter()
        .zip(&col.std)
        .map(|(v, s)| Cell {
            value: *v,
            std: *s,
            std_pct: if *v == 0.0 {
                f64::INFINITY
            } else {
                100.0 * s / v.abs()
            },
        })
        .collect())
}

fn rms_diff(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return 0.0;
    }
    (v.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

fn fit_row(label: &str, model: &Model, trials: &[Record]) -> FitRow {
    let x0s: Vec<Vec<f64>> = trials
        .iter()
        .map(|r| predict::estimate_x0(model, r))
        .collect();
    let mut fit = BTreeMap::new();
    let mut rough = 0.0;
    for &k in &HORIZONS {
        let mut sum = 0.0;
        for (r, x0) in trials.iter().zip(&x0s) {
            let p = predict::k_step(model, r, x0, k);
            sum += predict::fit(&r.y, &p);
            if k == 10 {
                let m = rms_diff(&r.y);
                rough += if m > 0.0 { rms_diff(&p) / m } else { 0.0 };
            }
        }
        fit.insert(k.to_string(), sum / trials.len() as f64);
    }
    let roughness = rough / trials.len() as f64;
    let above_reference: BTreeMap<String, f64> = MPC_REFERENCE
        .iter()
        .map(|(k, r)| (k.to_string(), fit[&k.to_string()] - r))
        .collect();
    FitRow {
        model: label.into(),
        meets_reference: above_reference.values().all(|v| *v >= 0.0),
        fit,
        above_reference,
        roughness,
        oscillations: !roughness.is_finite() || roughness > OSCILLATION_RATIO,
    }
}

impl Tables {
    /// Tabulates two models of the same structure and scores both on `trials`.
    ///
    /// # Errors
    /// [`TablesError`] when the models' parameters differ, a STD list has the wrong length,
    /// or there are no trial records.
    pub fn compare(
        conventional: &Column,
        tuned: &Column,
        trials: &[Record],
    ) -> Result<Tables, TablesError> {
        if trials.is_empty() {
            return Err(TablesError::NoTrials);
        }
        let names = conventional.model.param_names();
        let tn = tuned.model.param_names();
        if names != tn {
            return Err(TablesError::Mismatch(names.join(","), tn.join(",")));
        }
        let c = cells(conventional)?;
        let t = cells(tuned)?;
        let params: Vec<ParamRow> = names
            .iter()
            .enumerate()
            .map(|(i, n)| ParamRow {
                name: n.clone(),
                conventional: c[i],
                tuned: t[i],
                r: tuned.r.as_ref().and_then(|r| r.get(i).copied()),
            })
            .collect();
        let fits = vec![
            fit_row(&conventional.label, &conventional.model, trials),
            fit_row(&tuned.label, &tuned.model, trials),
        ];
        let improvement = HORIZONS
            .iter()
            .map(|k| {
                let key = k.to_string();
                (key.clone(), fits[1].fit[&key] - fits[0].fit[&key])
            })
            .collect();
        let pct = |v: &[Cell]| v.iter().map(|c| c.std_pct).collect::<Vec<_>>();
        Ok(Tables {
            lambda: tuned.lambda,
            conventional_reliability: reliability(&pct(&c)),
            tuned_reliability: reliability(&pct(&t)),
            params,
            fits,
            improvement,
            trial_records: trials.len(),
        })
    }

    /// The tables of a GA run: its conventional model against its tuned model.
    ///
    /// # Errors
    /// [`TablesError::NoConventional`] when the run has no conventional model, else as
    /// [`Tables::compare`].
    pub fn from_ga(rep: &GaReport, trials: &[Record]) -> Result<Tables, TablesError> {
        let conv = rep
            .conventional
            .as_ref()
            .ok_or(TablesError::NoConventional)?;
        Tables::compare(
            &Column {
                label: "conventional".into(),
                model: conv.model.clone(),
                std: conv.std.clone(),
                r: None,
                lambda: None,
            },
            &Column {
                label: "GA-tuned".into(),
                model: rep.best_model.clone(),
                std: rep.tuned.std.clone(),
                r: Some(rep.r.clone()),
                lambda: Some(rep.lambda),
            },
            trials,
        )
    }

    /// The tables as Markdown.
    ///
    /// ```
    /// use yawcast::{io::data::Record, identify::model::Model, identify::predict, tune::tables::{Column, Tables}};
    /// let m = Model::new(1.0, vec![0.0, 0.5], vec![1.0, 0.5], vec![0.1, 0.0]).unwrap();
    /// let u: Vec<f64> = (0..200).map(|i| if i % 9 < 4 { 1.0 } else { -1.0 }).collect();
    /// let mut r = Record::from_uy("lake", 1.0, u, vec![0.0; 200]);
    /// r.y = predict::simulate(&m, &r, &[0.0, 0.0]);
    /// let col = |label: &str| Column { label: label.into(), model: m.clone(), std: vec![0.01; 6], r: None, lambda: None };
    /// let t = Tables::compare(&col("conventional"), &col("GA-tuned"), &[r]).unwrap();
    /// assert!(t.to_markdown().contains("| a2 |"));
    /// assert_eq!(t.improvement["5"], 0.0);
    /// ```
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "## Model parameters (paper Tables 3 and 6)\n");
        if let Some(l) = self.lambda {
            let _ = writeln!(s, "GA-tuned with λ = {}.\n", num(l));
        }
        let has_r = self.params.iter().any(|p| p.r.is_some());
        let _ = write!(
            s,
            "| parameter | conventional | STD | STD % | GA-tuned | STD | STD % |"
        );
        let _ = writeln!(s, "{}", if has_r { " R_i |" } else { "" });
        let _ = writeln!(
            s,
            "|---|---:|---:|---:|---:|---:|---:|{}",
            if has_r { "---:|" } else { "" }
        );
        for p in &self.params {
            let _ = write!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} |",
                p.name,
                num(p.conventional.value),
                num(p.conventional.std),
                pct(p.conventional.std_pct),
                num(p.tuned.value),
                num(p.tuned.std),
                pct(p.tuned.std_pct)
            );
            let _ = writeln!(
                s,
                "{}",
                match (has_r, p.r) {
                    (true, Some(r)) => format!(" {} |", num(r)),
                    (true, None) => " — |".into(),
                    _ => String::new(),
                }
            );
        }
        let verdict = |r: Reliability| match r {
            Reliability::Reliable => "reliable (every STD% ≤ 10)",
            Reliability::Unreliable => "unreliable (some STD% > 10, none > 50)",
            Reliability::Unusable => "unusable (some STD% > 50)",
        };
        let _ = writeln!(
            s,
            "\nConventional model: {}. GA-tuned model: {}.\n",
            verdict(self.conventional_reliability),
            verdict(self.tuned_reliability)
        );
        let _ = writeln!(
            s,
            "## Prediction fit on {} trial record(s) (paper Tables 4 and 5)\n",
            self.trial_records
        );
        let _ = writeln!(s, "| model | 5-step | 10-step | 20-step | oscillations |");
        let _ = writeln!(s, "|---|---:|---:|---:|---|");
        let _ = writeln!(s, "| MPC reference | 80 % | 65 % | — | NO |");
        for f in &self.fits {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                f.model,
                fit(f.fit["5"]),
                fit(f.fit["10"]),
                fit(f.fit["20"]),
                if f.oscillations { "YES" } else { "NO" }
            );
        }
        let _ = writeln!(
            s,
            "\n| model | 5-step vs reference | 10-step vs reference | meets reference |"
        );
        let _ = writeln!(s, "|---|---:|---:|---|");
        for f in &self.fits {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                f.model,
                pp(f.above_reference["5"]),
                pp(f.above_reference["10"]),
                if f.meets_reference {
                    "fulfils"
                } else {
                    "does not meet"
                }
            );
        }
        let _ = writeln!(
            s,
            "\nGA-tuned minus conventional: {} at 5 steps, {} at 10 steps, {} at 20 steps.",
            pp(self.improvement["5"]),
            pp(self.improvement["10"]),
            pp(self.improvement["20"])
        );
        s
    }

    /// `<out>.tables.md` and `<out>.tables.json` (a `.postcard`/`.json` extension on `out` is
    /// dropped first).
    ///
    /// ```
    /// use std::path::Path;
    /// let (md, js) = yawcast::tune::tables::Tables::paths(Path::new("runs/ship.postcard"));
    /// assert_eq!(md, Path::new("runs/ship.tables.md"));
    /// assert_eq!(js, Path::new("runs/ship.tables.json"));
    /// ```
    pub fn paths(out: &Path) -> (PathBuf, PathBuf) {
        let (blob, _) = crate::io::export::paths(out);
        let stem = blob.with_extension("");
        (
            PathBuf::from(format!("{}.tables.md", stem.display())),
            PathBuf::from(format!("{}.tables.json", stem.display())),
        )
    }

    /// The two files of [`Tables::write`] with their bytes, for a caller that writes them
    /// together with its other outputs.
    ///
    /// ```
    /// use std::path::Path;
    /// use yawcast::{io::data::Record, identify::model::Model, identify::predict, tune::tables::{Column, Tables}};
    /// let m = Model::new(1.0, vec![0.0, 0.5], vec![1.0, 0.5], vec![0.1, 0.0]).unwrap();
    /// let u: Vec<f64> = (0..200).map(|i| if i % 9 < 4 { 1.0 } else { -1.0 }).collect();
    /// let mut r = Record::from_uy("lake", 1.0, u, vec![0.0; 200]);
    /// r.y = predict::simulate(&m, &r, &[0.0, 0.0]);
    /// let col = |label: &str| Column { label: label.into(), model: m.clone(), std: vec![0.01; 6], r: None, lambda: None };
    /// let t = Tables::compare(&col("conventional"), &col("GA-tuned"), &[r]).unwrap();
    /// let files = t.files(Path::new("runs/ship"));
    /// assert_eq!(files[0].0, Path::new("runs/ship.tables.md"));
    /// assert_eq!(files[0].1, t.to_markdown().into_bytes());
    /// assert_eq!(files[1].0, Path::new("runs/ship.tables.json"));
    /// let v: serde_json::Value = serde_json::from_slice(&files[1].1).unwrap();
    /// assert_eq!(v["trial_records"], 1);
    /// ```
    pub fn files(&self, out: &Path) -> Vec<(PathBuf, Vec<u8>)> {
        let (md, js) = Self::paths(out);
        let json = serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".into());
        vec![
            (md, self.to_markdown().into_bytes()),
            (js, json.into_bytes()),
        ]
    }

    /// Writes `<out>.tables.md` and `<out>.tables.json` ([`Tables::paths`]) together or not
    /// at all; returns their paths.
    ///
    /// # Errors
    /// [`data::DataError::Io`] when a file cannot be written (then neither is).
    pub fn write(&self, out: &Path) -> Result<(PathBuf, PathBuf), data::DataError> {
        data::write_all_atomic(&self.files(out))?;
        Ok(Self::paths(out))
    }
}

/// A number with 4 significant digits, scientific when very small or large.
fn num(v: f64) -> String {
    if !v.is_finite() {
        return "∞".into();
    }
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{v:.3e}")
    } else {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    }
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2}")
    } else {
        "∞".into()
    }
}

fn fit(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2} %")
    } else {
        "−∞".into()
    }
}

fn pp(v: f64) -> String {
    if v.is_finite() {
        format!("{v:+.2} pp")
    } else {
        "—".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::pem::{testdata, PemConfig};

    #[test]
    fn tables_in_the_papers_shape() {
        let rec = testdata::record(41, 1200);
        let conv = pem::identify(std::slice::from_ref(&rec), None, &PemConfig::default()).unwrap();
        let cfg = PemConfig {
            lambda: 1e-3,
            ..PemConfig::default()
        };
        let tuned = pem::identify(&[rec], None, &cfg).unwrap();
        let trials = vec![testdata::record(42, 800), testdata::record(43, 800)];
        let t = Tables::compare(
            &Column {
                label: "conventional".into(),
                model: conv.model.clone(),
                std: conv.std.clone(),
                r: None,
                lambda: None,
            },
            &Column {
                label: "GA-tuned".into(),
                model: tuned.model.clone(),
                std: tuned.std.clone(),
                r: Some(vec![1.0; 12]),
                lambda: Some(1e-3),
            },
            &trials,
        )
        .unwrap();
        assert_eq!(t.params.len(), 12);
        assert_eq!(t.params[4].name, "b1");
        assert!((t.params[4].conventional.std_pct - conv.std_pct[4]).abs() < 1e-9);
        assert_eq!(t.fits.len(), 2);
        assert!(
            t.fits[0].fit["5"] > 80.0 && !t.fits[0].oscillations,
            "{:?}",
            t.fits[0]
        );
        assert!(t.fits[0].meets_reference);
        let md = t.to_markdown();
        for needle in ["| b1 |", "R_i", "MPC reference", "fulfils", "λ = 0.001000"] {
            assert!(md.contains(needle), "{needle} missing:\n{md}");
        }
        let d = std::env::temp_dir().join(format!("yawcast-tables-{}", std::process::id()));
        let (m, j) = t.write(&d.join("ship.postcard")).unwrap();
        assert!(m.ends_with("ship.tables.md") && j.ends_with("ship.tables.json"));
        let back: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
        assert_eq!(back["params"][4]["name"], "b1");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn an_oscillating_model_is_flagged() {
        // a lightly damped pole pair near −1: predictions ring at the Nyquist rate
        let m = Model::new(1.0, vec![-0.95, -0.2], vec![1.0, -1.0], vec![0.0, 0.0]).unwrap();
        let trials = vec![testdata::record(44, 400)];
        let row = fit_row("ringing", &m, &trials);
        assert!(row.oscillations, "{row:?}");
    }

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(num(100.327), "100.3");
        assert_eq!(num(3.202), "3.202");
        assert_eq!(num(0.0153), "0.01530");
        assert_eq!(num(7.328e-5), "7.328e-5");
        assert_eq!(num(0.0), "0");
    }

    #[test]
    fn mismatched_models_are_refused() {
        let a = testdata::truth();
        let b = a
            .clone()
            .with_effect(crate::identify::model::Effect::Bias { beta: 0.1 });
        let col = |m: &Model| Column {
            label: "x".into(),
            model: m.clone(),
            std: vec![0.0; pem::params_of(m).len()],
            r: None,
            lambda: None,
        };
        let trials = vec![testdata::record(45, 300)];
        assert!(matches!(
            Tables::compare(&col(&a), &col(&b), &trials),
            Err(TablesError::Mismatch(..))
        ));
        assert_eq!(
            Tables::compare(&col(&a), &col(&a), &[]).unwrap_err(),
            TablesError::NoTrials
        );
    }
}
