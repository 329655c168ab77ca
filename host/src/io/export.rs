//! Export: the firmware blob (`<out>.postcard`) and its JSON twin (`<out>.json`), written only
//! after the model, read back from the blob and run by the firmware's own f32 predictor
//! (`yawcast_firmware::Predictor`), predicts a check record as well as the host's f64
//! predictor does: fit within 0.01 pp at horizons 1, 5, 10 and 20, both started from the
//! host's x̂(0) estimate.
//!
//! # Golden vectors (`ExportConfig::golden`)
//!
//! A text file, one record per line, numbers as IEEE-754 `f32` bit patterns in 8-digit
//! lower-case hex (so they survive any text tool bit for bit):
//!
//! ```text
//! yawcast-golden 1
//! order <n> horizon <H> samples <N>
//! x0 <n hex words>            initial state (difference coordinates) restored first
//! psi0 <hex>                  initial heading (deg)
//! <u> <y> <psi|-> <p_1> … <p_H>   one line per sample t
//! ```
//!
//! For sample t the firmware first runs `update_with_heading(u, y, psi)` (psi `-` = not
//! logged), then `predict_into(&mut [f32; H], u(t+1) … u(t+H−1))` (the last command repeated
//! past the end of the record) giving `p_1 … p_H` = ŷ(t+1|t) … ŷ(t+H|t).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;
use yawcast_firmware::PredictorError;
use yawcast_shared::blob::{self, FORMAT_VERSION, MAX_BLOB_LEN, MODEL_ONLY_VERSION};
use yawcast_shared::model::ModelSpec;
use yawcast_shared::nav::TrackSpec;

use crate::identify::model::Model;
use crate::identify::predict::{self, Horizon};
use crate::io::data::{self, Record};
use crate::io::hil::NativePredictor;

/// Version of the JSON twin's layout.
pub const JSON_FORMAT_VERSION: u32 = 1;

/// Settings of [`export_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExportConfig {
    /// Horizons checked (default 1, 5, 10, 20).
    pub horizons: Vec<usize>,
    /// Largest allowed |host fit − firmware fit| in percentage points (default 0.01).
    pub tolerance_pp: f64,
    /// Also write golden vectors to this file (format in the module docs).
    pub golden: Option<PathBuf>,
    /// Horizon of the golden vectors (default 20).
    pub golden_horizon: usize,
    /// The model's heading/track part: written into the blob (format 3) and the twin
    /// (`track`); `None` writes a format 2 blob as before.
    pub track: Option<TrackSpec>,
}

impl Default for ExportConfig {
    fn default() -> Self {
        ExportConfig {
            horizons: vec![1, 5, 10, 20],
            tolerance_pp: 0.01,
            golden: None,
            golden_horizon: 20,
            track: None,
        }
    }
}

/// Host vs firmware at one horizon.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HorizonCheck {
    /// k.
    pub horizon: usize,
    /// Fit % of the host's f64 predictor.
    pub host_fit: f64,
    /// Fit % of the firmware's f32 predictor on the blob as written.
    pub firmware_fit: f64,
}

/// The JSON twin written beside the blob.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelJson {
    /// Always `"yawcast-model"`.
    pub format: String,
    /// [`JSON_FORMAT_VERSION`].
    pub format_version: u32,
    /// Format version of the blob beside it.
    pub blob_format_version: u16,
    /// The model (f64, as identified; the blob holds it rounded to f32).
    pub model: Model,
    /// Parameter names in θ order then effect gains.
    pub param_names: Vec<String>,
    /// Name of the check record.
    pub check_record: String,
    /// Host fit % on the check record per horizon (`"1"`, `"5"`, …).
    pub fit: BTreeMap<String, f64>,
    /// Firmware fit % on the check record per horizon.
    pub firmware_fit: BTreeMap<String, f64>,
    /// The heading/track part, when the model has one (blob format 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track: Option<TrackSpec>,
}

/// What [`export`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExportReport {
    /// The blob.
    pub blob_path: PathBuf,
    /// The JSON twin.
    pub json_path: PathBuf,
    /// Golden vectors, when written.
    pub golden_path: Option<PathBuf>,
    /// Blob size in bytes.
    pub blob_len: usize,
    /// Host vs firmware per horizon.
    pub checks: Vec<HorizonCheck>,
    /// x̂(0) used by both.
    pub x0: Vec<f64>,
}

/// Export errors. When one is returned no file has been written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The model is invalid or refused by the shared schema (e.g. unstable once in f32).
    #[error("the model cannot be exported: {0}")]
    Model(String),
    /// The blob could not be encoded or did not read back.
    #[error("blob: {0}")]
    Blob(String),
    /// The firmware library refused the model or failed to predict.
    #[error("firmware predictor: {0}")]
    Firmware(String),
    /// The check record is unusable.
    #[error("check record `{record}`: {what}")]
    Check {
        /// Record name.
        record: String,
        /// What is wrong.
        what: String,
    },
    /// Host and firmware disagree.
    #[error(
        "firmware f32 fit {firmware:.4} % differs from host f64 fit {host:.4} % at {horizon} steps \
         by more than {tolerance} pp: the model is numerically too sensitive for f32"
    )]
    Mismatch {
        /// k.
        horizon: usize,
        /// Host fit.
        host: f64,
        /// Firmware fit.
        firmware: f64,
        /// Allowed difference.
        tolerance: f64,
    },
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] data::DataError),
}

/// `<out>.postcard` and `<out>.json` (a `.postcard` or `.json` extension on `out` is replaced).
///
/// ```
/// use std::path::Path;
/// let (b, j) = yawcast::io::export::paths(Path::new("runs/ship.postcard"));
/// assert_eq!(b, Path::new("runs/ship.postcard"));
/// assert_eq!(j, Path::new("runs/ship.json"));
/// ```
pub fn paths(out: &Path) -> (PathBuf, PathBuf) {
    let stem = match out.extension().and_then(|e| e.to_str()) {
        Some("postcard") | Some("json") => out.with_extension(""),
        _ => out.to_path_buf(),
    };
    let add = |ext: &str| {
        let mut s = stem.as_os_str().to_owned();
        s.push(".");
        s.push(ext);
        PathBuf::from(s)
    };
    (add("postcard"), add("json"))
}

/// The firmware run over a record: predictions from the restored initial state (before any
/// update) and after each update.
struct FwRun {
    initial: Vec<f32>,
    after: Vec<Vec<f32>>,
}

fn fw_err(e: PredictorError) -> ExportError {
    ExportError::Firmware(e.to_string())
}

fn run_firmware(
    spec: &ModelSpec,
    x0: &[f64],
    psi0: f64,
    rec: &Record,
    h: usize,
) -> Result<FwRun, ExportError> {
    let mut p = NativePredictor::new(spec).map_err(fw_err)?;
    p.start_from(x0, psi0).map_err(fw_err)?;
    let u: Vec<f32> = rec.u.iter().map(|v| *v as f32).collect();
    let future = |t: Option<usize>| -> Vec<f32> {
        let last = u.last().copied().unwrap_or(0.0);
        let from = t.map_or(0, |t| t + 1);
        (0..h.saturating_sub(1))
            .map(|j| u.get(from + j).copied().unwrap_or(last))
            .collect()
    };
    let mut initial = vec![0.0f32; h];
    p.predict(&mut initial, &future(None)).map_err(fw_err)?;
    let mut after = Vec::with_capacity(rec.len());
    for t in 0..rec.len() {
        let psi = rec.psi.as_ref().map(|v| v[t] as f32);
        p.update(u[t], rec.y[t] as f32, psi);
        let mut out = vec![0.0f32; h];
        p.predict(&mut out, &future(Some(t))).map_err(fw_err)?;
        after.push(out);
    }
    Ok(FwRun { initial, after })
}

/// The firmware's k-step predictions ŷ(t|t−k) for every t (host semantics: the first k
/// samples are simulation from x̂(0)).
fn firmware_k_step(run: &FwRun, k: usize, len: usize) -> Vec<f64> {
    (0..len)
        .map(|t| {
            if t < k {
                f64::from(run.initial[t])
            } else {
                f64::from(run.after[t - k][k - 1])
            }
        })
        .collect()
}

fn golden_text(spec: &ModelSpec, x0: &[f64], psi0: f64, rec: &Record, run: &FwRun) -> String {
    let h = run.initial.len();
    let hex = |v: f32| format!("{:08x}", v.to_bits());
    let mut s = String::new();
    let _ = writeln!(s, "yawcast-golden 1");
    let _ = writeln!(s, "order {} horizon {h} samples {}", spec.order, rec.len());
    let xs: Vec<String> = x0.iter().map(|v| hex(*v as f32)).collect();
    let _ = writeln!(s, "x0 {}", xs.join(" "));
    let _ = writeln!(s, "psi0 {}", hex(psi0 as f32));
    for t in 0..rec.len() {
        let psi = rec
            .psi
            .as_ref()
            .map_or("-".to_string(), |p| hex(p[t] as f32));
        let preds: Vec<String> = run.after[t].iter().map(|v| hex(*v)).collect();
        let _ = writeln!(
            s,
            "{} {} {psi} {}",
            hex(rec.u[t] as f32),
            hex(rec.y[t] as f32),
            preds.join(" ")
        );
    }
    s
}

/// [`export_with`] with the default settings (horizons 1, 5, 10, 20; 0.01 pp; no golden
/// vectors).
///
/// # Errors
/// As [`export_with`].
pub fn export(model: &Model, out: &Path, check: &Record) -> Result<ExportReport, ExportError> {
    export_with(model, out, check, &ExportConfig::default())
}

/// Checks `model` through the firmware on `check`, then writes `<out>.postcard`, `<out>.json`
/// and, when asked, the golden vectors — all together or none ([`data::write_all_atomic`]).
///
/// # Errors
/// [`ExportError::Model`] for an invalid model or one the f32 schema refuses (unstable after
/// rounding, out of range); [`ExportError::Check`] for a check record that is too short or
/// not finite; [`ExportError::Firmware`] when the firmware library refuses the model or its
/// prediction goes non-finite; [`ExportError::Mismatch`] when host and firmware fits differ
/// by more than the tolerance; [`ExportError::Io`] when a file cannot be written (then none
/// is, and files it would have replaced keep their content).
pub fn export_with(
    model: &Model,
    out: &Path,
    check: &Record,
    cfg: &ExportConfig,
) -> Result<ExportReport, ExportError> {
    let (report, files) = prepare_with(model, out, check, cfg)?;
    data::write_all_atomic(&files)?;
    Ok(report)
}

/// Everything [`export_with`] does but the writing: the checks through the firmware, the
/// report, and the files (`<out>.json`, the golden vectors when asked, `<out>.postcard`) with
/// their bytes, for a caller that writes them together with its other outputs.
///
/// # Errors
/// As [`export_with`], without [`ExportError::Io`].
///
/// ```
/// use yawcast::{identify::model::Model, identify::predict, io::data::Record};
/// use yawcast::io::export::{prepare_with, ExportConfig};
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1]).unwrap();
/// let u: Vec<f64> = (0..300).map(|i| if (i * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut check = Record::from_uy("check", 1.0, u, vec![0.0; 300]);
/// check.y = predict::simulate(&m, &check, &[0.0, 0.0]);
/// let out = std::path::Path::new("never/written/ship");
/// let (rep, files) = prepare_with(&m, out, &check, &ExportConfig::default()).unwrap();
/// assert_eq!(files.len(), 2);
/// assert_eq!(files[1].0, rep.blob_path);
/// assert_eq!(files[1].1.len(), rep.blob_len);
/// assert!(!out.parent().unwrap().exists());
/// ```
///
/// Long: the export's checks in the order they can fail (conversion, f32 validation, round
/// trip, bit comparison with the firmware), each with its own error.
pub fn prepare_with(
    model: &Model,
    out: &Path,
    check: &Record,
    cfg: &ExportConfig,
) -> Result<(ExportReport, data::OutputFiles), ExportError> {
    model
        .validate()
        .map_err(|e| ExportError::Model(e.to_string()))?;
    let spec = model
        .to_spec()
        .map_err(|e| ExportError::Model(e.to_string()))?;
    let mut buf = [0u8; MAX_BLOB_LEN];
    let blob_bytes = blob::encode_blob_with_track(&spec, cfg.track.as_ref(), &mut buf)
        .map_err(|e| ExportError::Model(e.to_string()))?
        .to_vec();
    let (spec_back, track_back) = blob::decode_blob_with_track(&blob_bytes)
        .map_err(|e| ExportError::Blob(format!("does not read back: {e}")))?;
    if track_back != cfg.track {
        return Err(ExportError::Blob(
            "the track part does not read back".into(),
        ));
    }
    let hmax = cfg
        .horizons
        .iter()
        .copied()
        .chain(cfg.golden.as_ref().map(|_| cfg.golden_horizon))
        .max()
        .unwrap_or(1)
        .max(1);
    let bad = |what: String| ExportError::Check {
        record: check.name.clone(),
        what,
    };
    if cfg.horizons.contains(&0) || hmax > yawcast_firmware::MAX_HORIZON {
        return Err(ExportError::Firmware(format!(
            "horizons must be in 1..={}",
            yawcast_firmware::MAX_HORIZON
        )));
    }
    if check.u.len() != check.len() || check.psi.as_ref().is_some_and(|p| p.len() != check.len()) {
        return Err(bad("channel lengths differ".into()));
    }
    if check.len() < 2 * hmax + model.n {
        return Err(bad(format!(
            "{} samples; at least {} needed for horizon {hmax}",
            check.len(),
            2 * hmax + model.n
        )));
    }
    let channels: [(&str, Option<&Vec<f64>>); 3] = [
        ("u", Some(&check.u)),
        ("y", Some(&check.y)),
        ("psi", check.psi.as_ref()),
    ];
    for (name, v) in channels {
        if let Some(i) = v.and_then(|v| v.iter().position(|x| !x.is_finite())) {
            return Err(bad(format!("{name} sample {i} is not finite")));
        }
    }
    let x0 = predict::estimate_x0(model, check);
    // the firmware's state is in the difference coordinates of the blob's model
    let x0_fw = crate::identify::model::differences(&x0);
    let psi0 = check.psi.as_ref().map_or(0.0, |p| p[0]);
    let run = run_firmware(&spec_back, &x0_fw, psi0, check, hmax)?;
    let mut checks = Vec::new();
    for &k in &cfg.horizons {
        let host = predict::fit(
            &check.y,
            &predict::predict(model, check, &x0, Horizon::Steps(k)),
        );
        let fw = predict::fit(&check.y, &firmware_k_step(&run, k, check.len()));
        checks.push(HorizonCheck {
            horizon: k,
            host_fit: host,
            firmware_fit: fw,
        });
        let diff = (host - fw).abs();
        if diff.is_nan() || diff > cfg.tolerance_pp {
            return Err(ExportError::Mismatch {
                horizon: k,
                host,
                firmware: fw,
                tolerance: cfg.tolerance_pp,
            });
        }
    }
    let json = ModelJson {
        format: "yawcast-model".into(),
        format_version: JSON_FORMAT_VERSION,
        blob_format_version: if cfg.track.is_some() {
            FORMAT_VERSION
        } else {
            MODEL_ONLY_VERSION
        },
        model: model.clone(),
        param_names: model.param_names(),
        check_record: check.name.clone(),
        fit: checks
            .iter()
            .map(|c| (c.horizon.to_string(), c.host_fit))
            .collect(),
        firmware_fit: checks
            .iter()
            .map(|c| (c.horizon.to_string(), c.firmware_fit))
            .collect(),
        track: cfg.track,
    };
    let json_text =
        serde_json::to_string_pretty(&json).map_err(|e| ExportError::Blob(format!("JSON: {e}")))?;
    let golden = match &cfg.golden {
        Some(p) => {
            let run = if cfg.golden_horizon == hmax {
                run
            } else {
                run_firmware(&spec_back, &x0_fw, psi0, check, cfg.golden_horizon)?
            };
            Some((
                p.clone(),
                golden_text(&spec_back, &x0_fw, psi0, check, &run),
            ))
        }
        None => None,
    };
    let (blob_path, json_path) = paths(out);
    let mut files = vec![(json_path.clone(), json_text.into_bytes())];
    let golden_path = golden.map(|(p, text)| {
        files.push((p.clone(), text.into_bytes()));
        p
    });
    files.push((blob_path.clone(), blob_bytes.clone()));
    Ok((
        ExportReport {
            blob_path,
            json_path,
            golden_path,
            blob_len: blob_bytes.len(),
            checks,
            x0,
        },
        files,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::model::Effect;
    use crate::identify::pem::{self, testdata, PemConfig};

    fn tmpdir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("yawcast-export-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn identified() -> (Model, Record) {
        let rep =
            pem::identify(&[testdata::record(31, 1500)], None, &PemConfig::default()).unwrap();
        (rep.model, testdata::record(32, 600))
    }

    #[test]
    fn export_writes_blob_and_json_that_read_back() {
        let (m, check) = identified();
        let d = tmpdir("ok");
        let rep = export(&m, &d.join("ship"), &check).unwrap();
        assert_eq!(rep.checks.len(), 4);
        for c in &rep.checks {
            assert!((c.host_fit - c.firmware_fit).abs() <= 0.01, "{c:?}");
            assert!(c.host_fit > 80.0, "{c:?}");
        }
        let bytes = std::fs::read(&rep.blob_path).unwrap();
        assert_eq!(bytes.len(), rep.blob_len);
        let spec = blob::decode_blob(&bytes).unwrap();
        assert_eq!(spec, m.to_spec().unwrap());
        let j: ModelJson =
            serde_json::from_str(&std::fs::read_to_string(&rep.json_path).unwrap()).unwrap();
        let close = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-14 * y.abs())
        };
        assert!(close(&j.model.theta(), &m.theta()));
        assert_eq!(j.format_version, JSON_FORMAT_VERSION);
        assert!((j.fit["5"] - rep.checks[1].host_fit).abs() < 1e-12);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn export_with_effects_and_heading_matches_the_firmware() {
        let t = testdata::truth()
            .with_effect(Effect::Bias { beta: 0.05 })
            .with_effect(Effect::Current {
                beta_s: 0.05,
                beta_c: -0.03,
            })
            .with_effect(Effect::DeadTime { samples: 1 });
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
        let u = testdata::prbs(&mut rng, 800, &[0.5, 1.0, 2.0]);
        let check = testdata::simulate_innovations(&t, &u, 0.05, &mut rng, "fx", true);
        let d = tmpdir("fx");
        let cfg = ExportConfig {
            golden: Some(d.join("golden.txt")),
            ..ExportConfig::default()
        };
        let rep = export_with(&t, &d.join("fx.postcard"), &check, &cfg).unwrap();
        for c in &rep.checks {
            assert!((c.host_fit - c.firmware_fit).abs() <= 0.01, "{c:?}");
        }
        let g = std::fs::read_to_string(rep.golden_path.unwrap()).unwrap();
        let mut lines = g.lines();
        assert_eq!(lines.next(), Some("yawcast-golden 1"));
        assert_eq!(lines.next(), Some("order 4 horizon 20 samples 800"));
        assert!(lines.next().unwrap().starts_with("x0 "));
        assert!(lines.next().unwrap().starts_with("psi0 "));
        let first: Vec<&str> = lines.next().unwrap().split(' ').collect();
        assert_eq!(first.len(), 3 + 20);
        assert_eq!(
            u32::from_str_radix(first[0], 16).unwrap(),
            (u[0] as f32).to_bits()
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn failures_write_nothing() {
        let (m, check) = identified();
        let d = tmpdir("bad");
        // unstable model
        let mut bad = m.clone();
        bad.a[3] = 2.0;
        let e = export(&bad, &d.join("x"), &check).unwrap_err();
        assert!(matches!(e, ExportError::Model(_)), "{e}");
        // short check record
        let e = export(&m, &d.join("x"), &check.slice(0, 30)).unwrap_err();
        assert!(e.to_string().contains("at least"), "{e}");
        // non-finite check data
        let mut c2 = check.clone();
        c2.y[5] = f64::INFINITY;
        let e = export(&m, &d.join("x"), &c2).unwrap_err();
        assert!(e.to_string().contains("y sample 5"), "{e}");
        // a tolerance nothing can meet
        let cfg = ExportConfig {
            tolerance_pp: -1.0,
            ..ExportConfig::default()
        };
        let e = export_with(&m, &d.join("x"), &check, &cfg).unwrap_err();
        assert!(matches!(e, ExportError::Mismatch { horizon: 1, .. }), "{e}");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
        let _ = std::fs::remove_dir_all(&d);
    }
}
