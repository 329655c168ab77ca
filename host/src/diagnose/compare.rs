//! Compare a model with measurements: fit % per record and horizon (MATLAB `compare`
//! semantics: `fit = 100·(1 − ‖y − ŷ‖/‖y − ȳ‖)` per record), and the measured and predicted
//! series for CSV files and plots.
//!
//! Horizons are k-step-ahead predictions (`"1"`, `"5"`, …) or pure simulation (`"sim"`), with
//! x̂(0) estimated from each record by least squares on the one-step errors
//! ([`crate::identify::predict::estimate_x0`]).
//!
//! The input checks shared by `compare`, [`crate::diagnose::resid`], [`crate::diagnose`] and
//! [`crate::diagnose::augment`] live here too ([`check_inputs`], [`InputError`]).

use std::collections::BTreeMap;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::identify::model::{Model, ModelError};
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;

/// Why records or a model cannot be compared, diagnosed or augmented.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum InputError {
    /// No record was given.
    #[error("no {0} records given")]
    NoRecords(&'static str),
    /// The model itself does not validate (order, lengths, non-finite numbers, ts).
    #[error("the model is invalid: {0}")]
    Model(#[from] ModelError),
    /// A record's sample time differs from the model's.
    #[error(
        "{set} record `{record}` is sampled every {found} s but the model's sample time is \
         {expected} s"
    )]
    SampleTime {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// The record's sample time.
        found: f64,
        /// The model's.
        expected: f64,
    },
    /// A record is too short for the model order or the analysis.
    #[error("{set} record `{record}` has {found} samples; at least {needed} are needed ({why})")]
    TooShort {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// Samples found.
        found: usize,
        /// Samples needed.
        needed: usize,
        /// What needs them.
        why: String,
    },
    /// Channels of a record have different lengths.
    #[error(
        "{set} record `{record}`: channel `{channel}` has {found} samples, `r` has {expected}"
    )]
    Ragged {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// Offending channel.
        channel: &'static str,
        /// Its length.
        found: usize,
        /// Length of the yaw-rate channel.
        expected: usize,
    },
    /// A sample is NaN or infinite.
    #[error("{set} record `{record}`: channel `{channel}` sample {sample} is not finite")]
    NonFinite {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// Channel.
        channel: &'static str,
        /// 0-based sample index.
        sample: usize,
    },
    /// The command of a record turns the ship the other way round from the records the model
    /// was identified on ([`predict::command_flipped`]).
    #[error(
        "{set} record `{record}`: the model simulates it at {given_pct:.0} % fit with the \
         command as logged and at {negated_pct:.0} % with the command negated, so its command \
         (or its yaw rate) is signed the other way round from the records the model was \
         identified on; negate its command column (--command-scale -1 negates every record read), or \
         its yaw-rate column if that is the one (yawcast needs one sign convention: a positive command \
         turns the ship as it did in those records, and the yaw rate is positive when the \
         heading grows)"
    )]
    CommandSign {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// Simulation fit (%) with the command as logged.
        given_pct: f64,
        /// Simulation fit (%) with the command negated.
        negated_pct: f64,
    },
    /// The command of a record is in another unit than the records the model was
    /// identified on ([`predict::command_other_unit`]).
    #[error(
        "{set} record `{record}`: the model simulates it at {given_pct:.1} % fit with the \
         command as logged and at {scaled_pct:.1} % with the command multiplied by \
         {scale:.4}, so its command is in another unit than the records the model was \
         identified on (radians against degrees give 57.3, degrees against radians 0.0175); \
         give --angle-unit rad for a command in radians, or rescale its command column so \
         that every record shares the model's unit"
    )]
    CommandUnit {
        /// The set it belongs to ("trial", "reference", …).
        set: &'static str,
        /// Record name.
        record: String,
        /// Simulation fit (%) with the command as logged.
        given_pct: f64,
        /// The factor on the command that simulates the record best.
        scale: f64,
        /// Simulation fit (%) with the command multiplied by `scale`.
        scaled_pct: f64,
    },
    /// An effect name that is not in the library.
    #[error("unknown effect `{0}`; the library has {names}", names = library_names())]
    UnknownEffect(String),
    /// A configuration value is out of range.
    #[error("bad setting: {0}")]
    Config(String),
}

/// The library's effect names, comma-separated, in library order.
fn library_names() -> String {
    yawcast_shared::model::EffectKind::ALL
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Checks `model` and that every record in `recs` matches it: same sample time (relative
/// tolerance 1e-6), equal channel lengths, finite samples, at least `min_len` samples.
/// `what` names the record set in the error ("trial", "reference", …).
///
/// # Errors
/// [`InputError`] naming the record and channel at fault.
///
/// ```
/// use yawcast::{diagnose::compare::{check_inputs, InputError}, io::data::Record, identify::model::Model};
/// let m = Model::new(0.5, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
/// let r = Record::from_uy("trial", 1.0, vec![0.0; 50], vec![0.0; 50]);
/// let e = check_inputs(&m, &[r], 20, "trial").unwrap_err();
/// assert!(matches!(e, InputError::SampleTime { .. }));
/// ```
pub fn check_inputs(
    model: &Model,
    recs: &[Record],
    min_len: usize,
    what: &'static str,
) -> Result<(), InputError> {
    model.validate()?;
    if recs.is_empty() {
        return Err(InputError::NoRecords(what));
    }
    let needed = min_len.max(4 * model.n + 4);
    for r in recs {
        if !(r.ts.is_finite() && (r.ts - model.ts).abs() <= 1e-6 * model.ts) {
            return Err(InputError::SampleTime {
                set: what,
                record: r.name.clone(),
                found: r.ts,
                expected: model.ts,
            });
        }
        let n = r.y.len();
        let mut chans: Vec<(&'static str, &[f64])> = vec![("u", &r.u), ("r", &r.y)];
        for (name, c) in [
            ("psi", &r.psi),
            ("speed", &r.speed),
            ("wind_speed", &r.wind_speed),
            ("wind_angle", &r.wind_angle),
        ] {
            if let Some(c) = c {
                chans.push((name, c));
            }
        }
        for (name, c) in &chans {
            if c.len() != n {
                return Err(InputError::Ragged {
                    set: what,
                    record: r.name.clone(),
                    channel: name,
                    found: c.len(),
                    expected: n,
                });
            }
            if let Some(i) = c.iter().position(|v| !v.is_finite()) {
                return Err(InputError::NonFinite {
                    set: what,
                    record: r.name.clone(),
                    channel: name,
                    sample: i,
                });
            }
        }
        if n < needed {
            return Err(InputError::TooShort {
                set: what,
                record: r.name.clone(),
                found: n,
                needed,
                why: format!("order {} model and this analysis", model.n),
            });
        }
    }
    Ok(())
}

/// [`InputError::CommandSign`] or [`InputError::CommandUnit`] for the first record of `recs`
/// whose command is signed the other way round from the model's records
/// ([`predict::command_flipped`]) or in another unit ([`predict::command_other_unit`]).
///
/// # Errors
/// [`InputError::CommandSign`] or [`InputError::CommandUnit`] naming the set and record.
pub fn check_command(model: &Model, recs: &[Record], what: &'static str) -> Result<(), InputError> {
    for r in recs {
        if let Some((given_pct, negated_pct)) = predict::command_flipped(model, r) {
            return Err(InputError::CommandSign {
                set: what,
                record: r.name.clone(),
                given_pct,
                negated_pct,
            });
        }
        if let Some(s) = predict::command_other_unit(model, r) {
            return Err(InputError::CommandUnit {
                set: what,
                record: r.name.clone(),
                given_pct: s.given_pct,
                scale: s.scale,
                scaled_pct: s.scaled_pct,
            });
        }
    }
    Ok(())
}

/// Settings of [`compare`].
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// Horizons to evaluate (default 1, 5, 10, 20 and sim).
    pub horizons: Vec<Horizon>,
    /// Keep the predicted series in the report (for CSV files and plots).
    pub keep_series: bool,
}

impl Default for CompareConfig {
    fn default() -> Self {
        CompareConfig {
            horizons: Horizon::REPORT.to_vec(),
            keep_series: true,
        }
    }
}

/// One record compared.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordCompare {
    /// Record name.
    pub name: String,
    /// Samples.
    pub samples: usize,
    /// Fit % keyed by horizon (`"1"`, `"5"`, `"10"`, `"20"`, `"sim"`).
    pub fit: BTreeMap<String, f64>,
    /// Root-mean-square error keyed by horizon (deg/s).
    pub rmse: BTreeMap<String, f64>,
    /// The x̂(0) used.
    pub x0: Vec<f64>,
    /// Time stamps (s); empty unless series are kept.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub t: Vec<f64>,
    /// Measured yaw rate (deg/s); empty unless series are kept.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub measured: Vec<f64>,
    /// Predicted yaw rate per horizon; empty unless series are kept.
    #[serde(skip_serializing_if = "BTreeMap::is_empty", default)]
    pub predicted: BTreeMap<String, Vec<f64>>,
}

/// The result of [`compare`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompareReport {
    /// Horizon keys in the order evaluated.
    pub horizons: Vec<String>,
    /// Per-record results.
    pub records: Vec<RecordCompare>,
    /// Mean fit over the records, keyed by horizon.
    pub mean_fit: BTreeMap<String, f64>,
}

/// RMSE of `y − yhat` (∞ when a prediction is not finite).
fn rmse(y: &[f64], yhat: &[f64]) -> f64 {
    let n = y.len().min(yhat.len());
    if n == 0 {
        return f64::NAN;
    }
    let s: f64 = y.iter().zip(yhat).map(|(a, b)| (a - b).powi(2)).sum();
    if s.is_finite() {
        (s / n as f64).sqrt()
    } else {
        f64::INFINITY
    }
}

/// Fit % of `model` on every record at every horizon of `cfg`, with the predicted series.
///
/// # Errors
/// [`InputError`] when the model is invalid, no record is given, or a record does not match
/// the model (sample time, channel lengths, non-finite samples, too short for the order).
///
/// ```
/// use yawcast::{diagnose::compare::{compare, CompareConfig}, io::data::Record, identify::model::Model, identify::predict};
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let u: Vec<f64> = (0..200).map(|i| if (i / 9) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 200]);
/// r.y = predict::simulate(&m, &r, &[0.0, 0.0]);
/// let rep = compare(&m, &[r], &CompareConfig::default()).unwrap();
/// assert!(rep.mean_fit["sim"] > 99.9);
/// assert_eq!(rep.records[0].predicted["10"].len(), 200);
/// ```
pub fn compare(
    model: &Model,
    data: &[Record],
    cfg: &CompareConfig,
) -> Result<CompareReport, InputError> {
    check_inputs(model, data, 0, "data")?;
    if cfg.horizons.is_empty() {
        return Err(InputError::Config("no horizon to compare at".into()));
    }
    let records: Vec<RecordCompare> = data
        .par_iter()
        .map(|rec| {
            let x0 = predict::estimate_x0(model, rec);
            let mut fit = BTreeMap::new();
            let mut err = BTreeMap::new();
            let mut predicted = BTreeMap::new();
            for &h in &cfg.horizons {
                let yhat = predict::predict(model, rec, &x0, h);
                fit.insert(h.key(), predict::fit(&rec.y, &yhat));
                err.insert(h.key(), rmse(&rec.y, &yhat));
                if cfg.keep_series {
                    predicted.insert(h.key(), yhat);
                }
            }
            RecordCompare {
                name: rec.name.clone(),
                samples: rec.len(),
                fit,
                rmse: err,
                x0,
                t: if cfg.keep_series {
                    rec.t.clone()
                } else {
                    Vec::new()
                },
                measured: if cfg.keep_series {
                    rec.y.clone()
                } else {
                    Vec::new()
                },
                predicted,
            }
        })
        .collect();
    let horizons: Vec<String> = cfg.horizons.iter().map(Horizon::key).collect();
    let mean_fit = mean_fits(records.iter().map(|r| &r.fit), &horizons);
    Ok(CompareReport {
        horizons,
        records,
        mean_fit,
    })
}

/// Mean over records of fits keyed by horizon.
pub(crate) fn mean_fits<'a>(
    fits: impl Iterator<Item = &'a BTreeMap<String, f64>>,
    keys: &[String],
) -> BTreeMap<String, f64> {
    let all: Vec<&BTreeMap<String, f64>> = fits.collect();
    keys.iter()
        .map(|k| {
            let v: f64 = all
                .iter()
                .map(|f| f.get(k).copied().unwrap_or(f64::NAN))
                .sum();
            (k.clone(), v / all.len().max(1) as f64)
        })
        .collect()
}

/// Mean fit % of `model` over `data` at each horizon (x̂(0) estimated per record), keyed by
/// horizon. Non-finite predictions give −∞.
pub fn mean_fit(model: &Model, data: &[Record], horizons: &[Horizon]) -> BTreeMap<String, f64> {
    let per: Vec<BTreeMap<String, f64>> = data
        .par_iter()
        .map(|rec| {
            let x0 = predict::estimate_x0(model, rec);
            horizons
                .iter()
                .map(|h| {
                    (
                        h.key(),
                        predict::fit(&rec.y, &predict::predict(model, rec, &x0, *h)),
                    )
                })
                .collect()
        })
        .collect();
    let keys: Vec<String> = horizons.iter().map(Horizon::key).collect();
    mean_fits(per.iter(), &keys)
}

impl CompareReport {
    /// The measured and predicted series of record `i` as CSV:
    /// `t_s,r_degps,rhat_<h>_degps…` (empty string when the series were not kept or `i` is
    /// out of range).
    ///
    /// ```
    /// use yawcast::{diagnose::compare::{compare, CompareConfig}, io::data::Record, identify::model::Model};
    /// let m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
    /// let r = Record::from_uy("r", 1.0, vec![1.0; 30], vec![0.5; 30]);
    /// let rep = compare(&m, &[r], &CompareConfig::default()).unwrap();
    /// let csv = rep.series_csv(0);
    /// assert!(csv.starts_with("t_s,r_degps,rhat_1_degps,"));
    /// assert_eq!(csv.lines().count(), 31);
    /// ```
    pub fn series_csv(&self, i: usize) -> String {
        let Some(r) = self.records.get(i) else {
            return String::new();
        };
        if r.measured.is_empty() {
            return String::new();
        }
        let mut s = String::from("t_s,r_degps");
        let cols: Vec<&Vec<f64>> = self
            .horizons
            .iter()
            .filter_map(|h| {
                let c = r.predicted.get(h)?;
                s.push_str(&format!(",rhat_{h}_degps"));
                Some(c)
            })
            .collect();
        s.push('\n');
        for j in 0..r.measured.len() {
            s.push_str(&format!("{},{}", r.t[j], r.measured[j]));
            for c in &cols {
                s.push_str(&format!(",{}", c[j]));
            }
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> Model {
        Model::new(
            1.0,
            vec![-0.2, 0.3, -0.1, 0.6],
            vec![0.01, 0.03, 0.05, 0.02],
            vec![0.8, 0.5, 0.3, 0.2],
        )
        .unwrap()
    }

    fn rec(n: usize) -> Record {
        let u = (0..n)
            .map(|i| if (i / 13) % 2 == 0 { 10.0 } else { -7.0 })
            .collect();
        let mut r = Record::from_uy("t", 1.0, u, vec![0.0; n]);
        r.y = predict::simulate(&model(), &r, &[0.0; 4])
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.01 * ((i * 7919) % 13) as f64)
            .collect();
        r
    }

    #[test]
    fn fits_match_predict_and_horizons_are_keyed() {
        let m = model();
        let r = rec(300);
        let rep = compare(&m, std::slice::from_ref(&r), &CompareConfig::default()).unwrap();
        assert_eq!(rep.horizons, vec!["1", "5", "10", "20", "sim"]);
        for h in Horizon::REPORT {
            let want = predict::fit_at(&m, &r, h);
            assert!((rep.records[0].fit[&h.key()] - want).abs() < 1e-12);
        }
        let json = serde_json::to_value(&rep).unwrap();
        assert!(json["mean_fit"]["sim"].is_number());
        assert!(json["records"][0]["fit"]["20"].is_number());
    }

    #[test]
    fn bad_inputs_are_named() {
        let m = model();
        assert_eq!(
            compare(&m, &[], &CompareConfig::default()).unwrap_err(),
            InputError::NoRecords("data")
        );
        let mut r = rec(300);
        r.u.pop();
        let e = compare(&m, &[r], &CompareConfig::default()).unwrap_err();
        assert!(matches!(e, InputError::Ragged { channel: "u", .. }), "{e}");
        let mut r = rec(300);
        r.y[17] = f64::NAN;
        let e = compare(&m, &[r], &CompareConfig::default()).unwrap_err();
        assert!(e.to_string().contains("sample 17"), "{e}");
        let e = compare(&m, &[rec(10)], &CompareConfig::default()).unwrap_err();
        assert!(matches!(e, InputError::TooShort { .. }), "{e}");
        let mut bad = m.clone();
        bad.b.pop();
        let e = compare(&bad, &[rec(300)], &CompareConfig::default()).unwrap_err();
        assert!(matches!(e, InputError::Model(_)), "{e}");
    }
}
