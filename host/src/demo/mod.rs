//! The demo: the whole story on the built-in ship, and the report and JSON summary of a run.
//!
//! An [`Outcome`] holds every number a run produced; [`Outcome::report`] lays it out as the
//! `report.html` page and [`Outcome::summary`] as the JSON summary with stable field names
//! (`seed`, `hidden_effect`, `diagnosed_effect`, `conventional.fit`, `tuned.fit`,
//! `augmented.fit` keyed by horizon `"1"`, `"5"`, `"10"`, `"20"`, `"sim"`,
//! `firmware_bit_exact`, `seconds`).

use std::collections::BTreeMap;

mod report;
mod run;
pub use run::{hidden_kind, run, DemoConfig, DemoError};

use serde::Serialize;

use crate::identify::model::Model;
use crate::io::data::Record;

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
    /// The heading and track prediction on a current case, or `None` when it failed.
    pub track: Option<TrackCase>,
    /// Seconds per step.
    pub timings: Vec<(String, f64)>,
    /// Total seconds.
    pub seconds: f64,
}

/// The demo's current case: the conventional model with the heading/track part fitted on
/// effect-free simulator records, scored on a record with a current, without and with the
/// track's current estimate (`track` in the JSON summary).
#[derive(Debug, Clone, Serialize)]
pub struct TrackCase {
    /// Current speed (m/s).
    pub current_mps: f64,
    /// The direction the current sets towards (deg).
    pub towards_deg: f64,
    /// Heading fit % of ψ̂(t+k|t) keyed by step horizon.
    pub heading_fit: Fits,
    /// Median track error (m) keyed by seconds ("30", "60", "120"), without the current.
    pub before: Fits,
    /// The same with the track's current estimate.
    pub after: Fits,
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
    /// The heading and track prediction on a current case (absent when it failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track: Option<TrackCase>,
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
            track: self.track.clone(),
        }
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
    ///
    /// Long: one table of the demo's figures, filled in the order the report prints them.
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
            track: Some(TrackCase {
                current_mps: 0.5,
                towards_deg: 60.0,
                heading_fit: HORIZON_KEYS[..4]
                    .iter()
                    .map(|k| (k.to_string(), 99.0))
                    .collect(),
                before: [("30", 7.0), ("60", 15.0), ("120", 33.0)]
                    .iter()
                    .map(|(k, v)| (k.to_string(), *v))
                    .collect(),
                after: [("30", 2.5), ("60", 6.0), ("120", 16.0)]
                    .iter()
                    .map(|(k, v)| (k.to_string(), *v))
                    .collect(),
            }),
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
        assert_eq!(v["track"]["before"]["60"], 15.0);
        assert_eq!(v["track"]["after"]["60"], 6.0);
        let html = sample().report().render();
        assert!(
            html.contains("<section id=\"track\""),
            "track section missing"
        );
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
