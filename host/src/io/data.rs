//! Measurement records: the uniform-sampled time series every tool works on, and the CSV format.
//!
//! CSV header (units in the names): `t_s,delta_deg,r_degps[,psi_deg][,u_mps][,wind_speed_mps,wind_angle_deg]`.
//! `delta_deg` is the *commanded* angle, held over `[t, t+Ts)`.

use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Relative distance within which the fitted sample period is snapped to a value with at
/// most three significant digits (timestamp jitter leaves the fit a hair off the logger's
/// period, and records identified together must share one sample time).
pub const SNAP_TOL: f64 = 1e-3;

/// One uniformly sampled record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Record {
    /// A name for reports (usually the file stem).
    pub name: String,
    /// Sample time in seconds.
    pub ts: f64,
    /// Time stamps (s).
    pub t: Vec<f64>,
    /// Commanded pod/rudder angle δ (deg).
    pub u: Vec<f64>,
    /// Measured yaw rate r (deg/s).
    pub y: Vec<f64>,
    /// Measured heading ψ (deg), when logged.
    pub psi: Option<Vec<f64>>,
    /// Speed over ground (m/s), when logged (`u_mps`).
    pub speed: Option<Vec<f64>>,
    /// Relative wind speed (m/s), when logged.
    pub wind_speed: Option<Vec<f64>>,
    /// Relative wind angle from the bow (deg), when logged.
    pub wind_angle: Option<Vec<f64>>,
}

/// Errors reading or writing records.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DataError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The CSV layer failed (quoting, ragged rows, …).
    #[error("{path}: {message}")]
    Csv {
        /// File concerned.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A required column is absent.
    #[error("{path}: missing column `{column}` (found: {found})")]
    MissingColumn {
        /// File concerned.
        path: PathBuf,
        /// Expected column name.
        column: String,
        /// Columns actually present.
        found: String,
    },
    /// A cell is not a finite number.
    #[error("{path}: row {row}, column `{column}`: expected a finite number, found `{value}`")]
    BadCell {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row (header is row 0).
        row: usize,
        /// Column name.
        column: String,
        /// Offending text.
        value: String,
    },
    /// Time does not advance one sample per period.
    #[error(
        "{path}: row {row}: time step {step} s breaks uniform sampling (the record's sample \
         time is {expected} s): {what}"
    )]
    NonUniform {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row where the step ends.
        row: usize,
        /// Step found.
        step: f64,
        /// The record's sample time (its median step).
        expected: f64,
        /// What the step means and what to do about it.
        what: String,
    },
    /// Two columns share a name, so which one is meant cannot be told.
    #[error(
        "{path}: column `{column}` appears more than once in the header (columns {first} and \
         {second}): rename one, or map the one you mean with the --col-* options"
    )]
    DuplicateColumn {
        /// File concerned.
        path: PathBuf,
        /// The repeated name.
        column: String,
        /// 1-based position of its first appearance.
        first: usize,
        /// 1-based position of its second appearance.
        second: usize,
    },
    /// A value is finite but beyond what the quantity can physically be.
    #[error(
        "{path}: row {row}, column `{column}`: {value} is beyond the plausible {limit} for {what} \
         (a corrupted cell or another unit; raise the limit with {option} if it is real)"
    )]
    Implausible {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row (header is row 0).
        row: usize,
        /// Column name.
        column: String,
        /// The value found, in the record's units after scaling.
        value: f64,
        /// The limit (±).
        limit: f64,
        /// The quantity, in words.
        what: &'static str,
        /// The option that sets the limit.
        option: &'static str,
    },
    /// A channel never moves, so nothing can be learnt from the record.
    #[error("{path}: column `{column}` {what}")]
    NoExcitation {
        /// File concerned.
        path: PathBuf,
        /// Column name.
        column: String,
        /// What is wrong and what to do.
        what: String,
    },
    /// The process was interrupted (SIGINT, SIGTERM) before its outputs were all written: none
    /// was, and files it would have replaced keep their content.
    #[error("interrupted by signal {signal}: no output written, earlier files left as they were")]
    Interrupted {
        /// The signal number.
        signal: i32,
    },
    /// Too few samples to be of any use.
    #[error("{path}: {found} samples, at least {needed} needed")]
    TooShort {
        /// File concerned.
        path: PathBuf,
        /// Samples found.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
}

impl Record {
    /// Number of samples.
    ///
    /// ```
    /// let r = yawcast::io::data::Record::from_uy("x", 1.0, vec![0.0; 3], vec![0.0; 3]);
    /// assert_eq!(r.len(), 3);
    /// ```
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// Whether the record holds no samples.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// A record with only input and output; time starts at 0.
    ///
    /// ```
    /// let r = yawcast::io::data::Record::from_uy("x", 0.5, vec![1.0, 2.0], vec![0.0, 0.1]);
    /// assert_eq!(r.t, vec![0.0, 0.5]);
    /// ```
    pub fn from_uy(name: &str, ts: f64, u: Vec<f64>, y: Vec<f64>) -> Record {
        let t = (0..y.len()).map(|i| i as f64 * ts).collect();
        Record {
            name: name.to_string(),
            ts,
            t,
            u,
            y,
            ..Record::default()
        }
    }

    /// Samples `start..end` as a new record (all channels).
    ///
    /// ```
    /// let r = yawcast::io::data::Record::from_uy("x", 1.0, vec![1.0, 2.0, 3.0], vec![0.0; 3]);
    /// assert_eq!(r.slice(1, 3).u, vec![2.0, 3.0]);
    /// ```
    pub fn slice(&self, start: usize, end: usize) -> Record {
        let cut = |v: &Option<Vec<f64>>| v.as_ref().map(|v| v[start..end].to_vec());
        Record {
            name: self.name.clone(),
            ts: self.ts,
            t: self.t[start..end].to_vec(),
            u: self.u[start..end].to_vec(),
            y: self.y[start..end].to_vec(),
            psi: cut(&self.psi),
            speed: cut(&self.speed),
            wind_speed: cut(&self.wind_speed),
            wind_angle: cut(&self.wind_angle),
        }
    }
}

/// Column names of the measurement CSV (overridable for other loggers).
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// Time (s).
    pub t: String,
    /// Commanded angle.
    pub u: String,
    /// Yaw rate.
    pub y: String,
    /// Heading (optional column).
    pub psi: String,
    /// Speed over ground (optional column).
    pub speed: String,
    /// Relative wind speed (optional column).
    pub wind_speed: String,
    /// Relative wind angle (optional column).
    pub wind_angle: String,
    /// Multiply the angle columns (`u`, `psi`, `wind_angle`) by this to get degrees.
    pub angle_scale: f64,
    /// Multiply the yaw-rate column by this to get deg/s.
    pub rate_scale: f64,
    /// Resample onto a uniform grid of this step (s) instead of requiring uniform time stamps.
    pub resample: Option<f64>,
}

impl Default for Columns {
    fn default() -> Self {
        Columns {
            t: "t_s".into(),
            u: "delta_deg".into(),
            y: "r_degps".into(),
            psi: "psi_deg".into(),
            speed: "u_mps".into(),
            wind_speed: "wind_speed_mps".into(),
            wind_angle: "wind_angle_deg".into(),
            angle_scale: 1.0,
            rate_scale: 1.0,
            resample: None,
        }
    }
}

/// Reads a measurement CSV with the default column names.
///
/// # Errors
/// [`DataError`] naming the file, row and column for missing columns, non-numeric or
/// non-finite cells, non-monotonic or non-uniform time, or fewer than 2 samples.
pub fn read_csv(path: &Path) -> Result<Record, DataError> {
    read_csv_with(path, &Columns::default())
}

/// Reads a measurement CSV with the given column names and unit scales.
///
/// # Errors
/// As [`read_csv`].
pub fn read_csv_with(path: &Path, cols: &Columns) -> Result<Record, DataError> {
    let text = std::fs::read_to_string(path).map_err(|source| DataError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse_csv(&text, path, &name, cols)
}

/// Parses CSV text (`path` only labels errors).
///
/// # Errors
/// As [`read_csv`].
///
/// ```
/// use yawcast::io::data::{parse_csv, Columns};
/// let txt = "t_s,delta_deg,r_degps\n0,1,0\n1,1,0.5\n2,-1,0.2\n";
/// let r = parse_csv(txt, "x.csv".as_ref(), "x", &Columns::default()).unwrap();
/// assert_eq!(r.ts, 1.0);
/// assert_eq!(r.y, vec![0.0, 0.5, 0.2]);
/// ```
pub fn parse_csv(text: &str, path: &Path, name: &str, cols: &Columns) -> Result<Record, DataError> {
    let csv_err = |e: csv::Error| DataError::Csv {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let semicolons = semicolon_separated(text);
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .delimiter(if semicolons { b';' } else { b',' })
        .from_reader(text.as_bytes());
    let headers: Vec<String> = rdr
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(|s| s.to_string())
        .collect();
    for (j, h) in headers.iter().enumerate() {
        if let Some(k) = headers[..j].iter().position(|g| g == h) {
            return Err(DataError::DuplicateColumn {
                path: path.to_path_buf(),
                column: h.clone(),
                first: k + 1,
                second: j + 1,
            });
        }
    }
    let find = |c: &str| headers.iter().position(|h| h == c);
    let need = |c: &str| {
        find(c).ok_or_else(|| DataError::MissingColumn {
            path: path.to_path_buf(),
            column: c.to_string(),
            found: headers.join(","),
        })
    };
    let it = need(&cols.t)?;
    let iu = need(&cols.u)?;
    let iy = need(&cols.y)?;
    let ipsi = find(&cols.psi);
    let isp = find(&cols.speed);
    let iws = find(&cols.wind_speed);
    let iwa = find(&cols.wind_angle);
    let mut rec = Record {
        name: name.to_string(),
        psi: ipsi.map(|_| Vec::new()),
        speed: isp.map(|_| Vec::new()),
        wind_speed: iws.map(|_| Vec::new()),
        wind_angle: iwa.map(|_| Vec::new()),
        ..Record::default()
    };
    for (i, row) in rdr.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let rown = i + 1;
        let cell = |idx: usize| -> Result<f64, DataError> {
            let s = row.get(idx).unwrap_or("");
            // A `;`-separated file writes decimals with a comma (`1,5`).
            let parsed = if semicolons {
                s.replace(',', ".").parse::<f64>()
            } else {
                s.parse::<f64>()
            };
            match parsed {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(DataError::BadCell {
                    path: path.to_path_buf(),
                    row: rown,
                    column: headers[idx].clone(),
                    value: s.to_string(),
                }),
            }
        };
        rec.t.push(cell(it)?);
        rec.u.push(cell(iu)? * cols.angle_scale);
        rec.y.push(cell(iy)? * cols.rate_scale);
        if let (Some(i), Some(v)) = (ipsi, rec.psi.as_mut()) {
            v.push(cell(i)? * cols.angle_scale);
        }
        if let (Some(i), Some(v)) = (isp, rec.speed.as_mut()) {
            v.push(cell(i)?);
        }
        if let (Some(i), Some(v)) = (iws, rec.wind_speed.as_mut()) {
            v.push(cell(i)?);
        }
        if let (Some(i), Some(v)) = (iwa, rec.wind_angle.as_mut()) {
            v.push(cell(i)? * cols.angle_scale);
        }
    }
    if rec.t.len() < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            found: rec.t.len(),
            needed: 2,
        });
    }
    if let Some(psi) = rec.psi.as_mut() {
        unwrap_degrees(psi);
    }
    match cols.resample {
        Some(dt) => resample(&rec, dt, path),
        None => {
            rec.ts = check_uniform(&rec.t, path)?;
            Ok(rec)
        }
    }
}

/// Resamples a record onto the uniform grid `t_0, t_0 + dt, …` within its time span: the
/// command zero-order held (it is held over each logged interval), every other channel
/// linearly interpolated (heading and wind angle after unwrapping). The time stamps only need
/// to increase; a logger's jitter, gaps and another rate are all absorbed.
///
/// # Errors
/// [`DataError::NonUniform`] naming the first row whose time does not increase,
/// [`DataError::TooShort`] when the grid holds fewer than 2 samples, and
/// [`DataError::Csv`] when `dt` is not a positive number.
///
/// ```
/// use yawcast::io::data::{resample, Record};
/// let mut r = Record::from_uy("r", 0.0, vec![1.0, 2.0, 3.0], vec![0.0, 1.0, 3.0]);
/// r.t = vec![0.0, 0.4, 1.1];
/// let g = resample(&r, 0.5, "r.csv".as_ref()).unwrap();
/// assert_eq!(g.t, vec![0.0, 0.5, 1.0]);
/// assert_eq!(g.u, vec![1.0, 2.0, 2.0]);
/// assert!((g.y[1] - (1.0 + 2.0 * 0.1 / 0.7)).abs() < 1e-12);
/// assert_eq!(g.ts, 0.5);
/// ```
pub fn resample(rec: &Record, dt: f64, path: &Path) -> Result<Record, DataError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(DataError::Csv {
            path: path.to_path_buf(),
            message: format!("--resample {dt}: expected a positive number of seconds"),
        });
    }
    if let Some(i) = rec
        .t
        .windows(2)
        .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(DataError::NonUniform {
            path: path.to_path_buf(),
            row: i + 2,
            step: rec.t[i + 1] - rec.t[i],
            expected: dt,
            what: "time must increase from row to row, even when resampling".into(),
        });
    }
    let (t0, t1) = (rec.t[0], rec.t[rec.t.len() - 1]);
    let n = ((t1 - t0) / dt + 1e-9).floor() as usize + 1;
    if n < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            found: n,
            needed: 2,
        });
    }
    let grid: Vec<f64> = (0..n).map(|k| t0 + k as f64 * dt).collect();
    // For each grid time, the logged interval [t_j, t_{j+1}) that holds it and where in it.
    let mut at = Vec::with_capacity(n);
    let mut j = 0;
    for &tg in &grid {
        while j + 2 < rec.t.len() && rec.t[j + 1] <= tg {
            j += 1;
        }
        let w = ((tg - rec.t[j]) / (rec.t[j + 1] - rec.t[j])).clamp(0.0, 1.0);
        at.push((j, w));
    }
    let held = |v: &[f64]| -> Vec<f64> {
        at.iter()
            .map(|&(j, w)| if w >= 1.0 { v[j + 1] } else { v[j] })
            .collect()
    };
    let linear = |v: &[f64]| -> Vec<f64> {
        at.iter()
            .map(|&(j, w)| v[j] + w * (v[j + 1] - v[j]))
            .collect()
    };
    let unwrapped = |v: &[f64]| {
        let mut v = v.to_vec();
        unwrap_degrees(&mut v);
        linear(&v)
    };
    Ok(Record {
        name: rec.name.clone(),
        ts: dt,
        t: grid,
        u: held(&rec.u),
        y: linear(&rec.y),
        psi: rec.psi.as_deref().map(unwrapped),
        speed: rec.speed.as_deref().map(linear),
        wind_speed: rec.wind_speed.as_deref().map(linear),
        wind_angle: rec.wind_angle.as_deref().map(unwrapped),
    })
}

/// Whether the CSV text is `;`-separated (the spreadsheet export of locales with a decimal
/// comma): its header has a `;` and no `,`.
fn semicolon_separated(text: &str) -> bool {
    let header = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    header.contains(';') && !header.contains(',')
}

/// Physical limits a record's values must respect (after unit scaling): a value beyond them
/// is a corrupted cell or another unit, never a measurement to identify from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest |commanded angle| (deg). Rudders and pods turn at most 35–45°, azimuth units 180°.
    pub angle_deg: f64,
    /// Largest |yaw rate| (deg/s).
    pub rate_degps: f64,
    /// Largest |speed over ground| and relative wind speed (m/s).
    pub speed_mps: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            angle_deg: 180.0,
            rate_degps: 30.0,
            speed_mps: 100.0,
        }
    }
}

/// Smallest span (max − min) of the command for a record to carry information (deg).
pub const MIN_COMMAND_SPAN_DEG: f64 = 0.05;
/// Smallest span of the yaw rate for a record to carry information (deg/s).
pub const MIN_RATE_SPAN_DEGPS: f64 = 1e-3;

/// Checks a record before any work is done on it: every value within `limits`, and both the
/// command and the yaw rate moving (a command held at one angle, or a yaw rate stuck at one
/// value, cannot be identified, tuned on, compared or diagnosed). `cols` names the columns
/// in the messages; rows are 1-based samples of the record (for an NMEA log, of its grid).
///
/// # Errors
/// [`DataError::Implausible`] naming the row and column of the first value beyond a limit,
/// [`DataError::NoExcitation`] naming the column that never moves.
///
/// ```
/// use yawcast::io::data::{validate_record, Columns, DataError, Limits, Record};
/// let ok = Record::from_uy("r", 1.0, vec![0.0, 5.0, -5.0], vec![0.0, 0.4, -0.2]);
/// assert!(validate_record(&ok, "r.csv".as_ref(), &Limits::default(), &Columns::default()).is_ok());
/// let wild = Record::from_uy("r", 1.0, vec![0.0, 2e6, -5.0], vec![0.0, 0.4, -0.2]);
/// let e = validate_record(&wild, "r.csv".as_ref(), &Limits::default(), &Columns::default());
/// assert!(matches!(e, Err(DataError::Implausible { row: 2, .. })));
/// let still = Record::from_uy("r", 1.0, vec![5.0; 3], vec![0.0, 0.4, -0.2]);
/// let e = validate_record(&still, "r.csv".as_ref(), &Limits::default(), &Columns::default());
/// assert!(matches!(e, Err(DataError::NoExcitation { .. })));
/// ```
pub fn validate_record(
    rec: &Record,
    path: &Path,
    limits: &Limits,
    cols: &Columns,
) -> Result<(), DataError> {
    let within =
        |v: &[f64], col: &str, limit: f64, what: &'static str, option: &'static str| match v
            .iter()
            .position(|x| x.is_nan() || x.abs() > limit)
        {
            Some(i) => Err(DataError::Implausible {
                path: path.to_path_buf(),
                row: i + 1,
                column: col.to_string(),
                value: v[i],
                limit,
                what,
                option,
            }),
            None => Ok(()),
        };
    within(
        &rec.u,
        &cols.u,
        limits.angle_deg,
        "a commanded angle (deg)",
        "--max-angle",
    )?;
    within(
        &rec.y,
        &cols.y,
        limits.rate_degps,
        "a yaw rate (deg/s)",
        "--max-rate",
    )?;
    if let Some(v) = &rec.speed {
        within(
            v,
            &cols.speed,
            limits.speed_mps,
            "a speed (m/s)",
            "--max-speed",
        )?;
    }
    if let Some(v) = &rec.wind_speed {
        within(
            v,
            &cols.wind_speed,
            limits.speed_mps,
            "a wind speed (m/s)",
            "--max-speed",
        )?;
    }
    let span = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        (hi - lo, lo, hi)
    };
    let still = |col: &str, v: &[f64], min: f64, unit: &str, why: &str| {
        let (s, lo, hi) = span(v);
        if s < min {
            let held = if s == 0.0 {
                format!("is constant ({lo} {unit} throughout)")
            } else {
                format!("is constant to within {s:.3e} {unit} ({lo} … {hi})")
            };
            return Err(DataError::NoExcitation {
                path: path.to_path_buf(),
                column: col.to_string(),
                what: format!("{held}: {why}"),
            });
        }
        Ok(())
    };
    still(
        &cols.u,
        &rec.u,
        MIN_COMMAND_SPAN_DEG,
        "deg",
        "the command must move for the yaw dynamics to show; a record held at one angle \
         cannot be identified, tuned on, compared or diagnosed",
    )?;
    still(
        &cols.y,
        &rec.y,
        MIN_RATE_SPAN_DEGPS,
        "deg/s",
        "the yaw rate never moves; check that the rate sensor is logged, and its column and \
         unit (--col-rate, --rate-unit)",
    )
}

/// Warnings about the scale of a record's columns that suggest a unit mix-up: commands that
/// never leave ±1.6 (radians under a degree header: π/2 rad is 90°) and yaw rates that never
/// leave ±0.05 °/s while the commands reach 2° (rad/s under a °/s header: a ship turning
/// visibly does more than 3°/min), and a sample time above a minute (milliseconds under a
/// seconds header: no yaw predictor samples that slowly). Empty when nothing looks wrong.
///
/// ```
/// use yawcast::io::data::{unit_warnings, Record};
/// let r = Record::from_uy("r", 1.0, vec![0.1, -0.2, 0.35], vec![0.001, 0.004, -0.002]);
/// let w = unit_warnings(&r);
/// assert_eq!(w.len(), 1);
/// assert!(w[0].contains("radians"));
/// let r = Record::from_uy("r", 1.0, vec![10.0, -20.0], vec![0.002, -0.01]);
/// assert!(unit_warnings(&r)[0].contains("rad/s"));
/// assert!(unit_warnings(&Record::from_uy("r", 1.0, vec![10.0, -20.0], vec![0.4, -0.9])).is_empty());
/// let ms = Record::from_uy("r", 1000.0, vec![10.0, -20.0], vec![0.4, -0.9]);
/// assert!(unit_warnings(&ms)[0].contains("milliseconds"));
/// ```
pub fn unit_warnings(rec: &Record) -> Vec<String> {
    let span = |v: &[f64]| {
        v.iter()
            .filter(|x| x.is_finite())
            .fold(0.0f64, |m, x| m.max(x.abs()))
    };
    let (du, dy) = (span(&rec.u), span(&rec.y));
    let mut out = Vec::new();
    if rec.ts > 60.0 {
        out.push(format!(
            "the sample time is {} s: if the time column is in milliseconds, divide it by 1000",
            rec.ts
        ));
    }
    if du > 0.0 && du <= 1.6 {
        out.push(format!(
            "the commands never leave ±{du:.3}: if they are radians, give --angle-unit rad"
        ));
    } else if du >= 2.0 && dy > 0.0 && dy <= 0.05 {
        out.push(format!(
            "the yaw rate never leaves ±{dy:.4} °/s while the commands reach {du:.0}°: if it \
             is in rad/s, give --rate-unit radps"
        ));
    }
    out
}

/// Removes the 360° jumps of a heading logged in [0, 360) (or (−180, 180]): each sample
/// moves to within 180° of the one before, so the heading is continuous through north and
/// its differences are turn angles. Sines and cosines of it are unchanged.
///
/// ```
/// let mut psi = vec![358.0, 359.5, 0.5, 2.0, 1.0, 359.0];
/// yawcast::io::data::unwrap_degrees(&mut psi);
/// assert_eq!(psi, vec![358.0, 359.5, 360.5, 362.0, 361.0, 359.0]);
/// ```
pub fn unwrap_degrees(psi: &mut [f64]) {
    let mut offset = 0.0;
    for i in 1..psi.len() {
        let raw = psi[i] + offset;
        let step = raw - psi[i - 1];
        let turns = ((step + 180.0) / 360.0).floor();
        offset -= 360.0 * turns;
        psi[i] = raw - 360.0 * turns;
    }
}

/// Checks that `t` advances one sample per period and returns the period.
///
/// The period is the median of the steps that go forward. Logged time stamps jitter: a row
/// may come late or early (the step before it is then longer or shorter, the one after it
/// the opposite), and each row still holds one sample as long as every step is within half
/// a period of the period — stamps off their grid by up to a quarter period each. The
/// sample time returned is the slope of the least-squares line through the stamps, snapped
/// to a value of at most three significant digits within [`SNAP_TOL`] of it (a logger at
/// 1 Hz with jitter gives 1 s, not 0.99943 s).
///
/// # Errors
/// [`DataError::NonUniform`] naming the first row whose step is not positive (time going
/// back or repeated), spans two or more periods (missing samples) or less than half of one
/// (an extra sample).
///
/// ```
/// use std::path::Path;
/// let t = [0.0, 1.01, 1.99, 3.0, 4.0, 5.0];
/// assert_eq!(yawcast::io::data::check_uniform(&t, Path::new("x.csv")).unwrap(), 1.0);
/// let gap = [0.0, 1.0, 2.0, 4.0, 5.0];
/// let e = yawcast::io::data::check_uniform(&gap, Path::new("x.csv")).unwrap_err();
/// assert!(e.to_string().contains("row 4") && e.to_string().contains("1 sample missing"));
/// ```
pub fn check_uniform(t: &[f64], path: &Path) -> Result<f64, DataError> {
    let n = t.len();
    // the period: the median of the steps that go forward
    let mut steps: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|s| *s > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    let h = if steps.is_empty() {
        f64::NAN
    } else if steps.len() % 2 == 1 {
        steps[steps.len() / 2]
    } else {
        0.5 * (steps[steps.len() / 2 - 1] + steps[steps.len() / 2])
    };
    // the first row that breaks the sampling, in row order
    for i in 0..n - 1 {
        let step = t[i + 1] - t[i];
        let what = if step.is_nan() || step < 0.0 {
            Some("time goes back".to_string())
        } else if step == 0.0 {
            Some("the time stamp repeats the row before".to_string())
        } else {
            let periods = (step / h).round();
            if periods >= 2.0 {
                let missing = periods - 1.0;
                Some(format!(
                    "{missing} sample{} missing; split the record there or fill the gap",
                    if missing == 1.0 { "" } else { "s" }
                ))
            } else if periods < 1.0 {
                Some(
                    "less than half a period after the row before (an extra sample); remove it"
                        .to_string(),
                )
            } else {
                None
            }
        };
        if let Some(what) = what {
            return Err(DataError::NonUniform {
                path: path.to_path_buf(),
                row: i + 2,
                step,
                expected: h,
                what,
            });
        }
    }
    // the least-squares slope of t against the sample index
    let mid = (n - 1) as f64 / 2.0;
    let t_mean = t.iter().sum::<f64>() / n as f64;
    let (num, den) = t.iter().enumerate().fold((0.0, 0.0), |(a, b), (i, ti)| {
        let di = i as f64 - mid;
        (a + di * (ti - t_mean), b + di * di)
    });
    Ok(snap((num / den).max(f64::MIN_POSITIVE)))
}

/// `ts` rounded to the fewest significant digits (one to three) that move it by at most
/// [`SNAP_TOL`] (relative); `ts` itself when none does.
fn snap(ts: f64) -> f64 {
    for digits in 1..=3 {
        let k = digits - 1 - ts.log10().floor() as i32;
        let snapped = if k >= 0 {
            let s = 10f64.powi(k);
            (ts * s).round() / s
        } else {
            let s = 10f64.powi(-k);
            (ts / s).round() * s
        };
        if (snapped - ts).abs() <= SNAP_TOL * ts {
            return snapped;
        }
    }
    ts
}

/// Writes a record as a measurement CSV ([`csv_text`]), atomically (temp file, then rename).
///
/// # Errors
/// [`DataError::Io`] when the file cannot be written.
pub fn write_csv(path: &Path, rec: &Record) -> Result<(), DataError> {
    write_atomic(path, csv_text(rec).as_bytes())
}

/// A record as a measurement CSV: the header, then one row per sample (numbers in Rust's
/// shortest round-trip form).
///
/// ```
/// let r = yawcast::io::data::Record::from_uy("r", 0.5, vec![1.0, -2.5], vec![0.125, 0.0]);
/// assert_eq!(yawcast::io::data::csv_text(&r), "t_s,delta_deg,r_degps\n0,1,0.125\n0.5,-2.5,0\n");
/// ```
pub fn csv_text(rec: &Record) -> String {
    let mut out = String::new();
    out.push_str("t_s,delta_deg,r_degps");
    let opt = [
        (&rec.psi, "psi_deg"),
        (&rec.speed, "u_mps"),
        (&rec.wind_speed, "wind_speed_mps"),
        (&rec.wind_angle, "wind_angle_deg"),
    ];
    for (v, name) in &opt {
        if v.is_some() {
            out.push(',');
            out.push_str(name);
        }
    }
    out.push('\n');
    for i in 0..rec.len() {
        out.push_str(&format!("{},{},{}", rec.t[i], rec.u[i], rec.y[i]));
        for (v, _) in &opt {
            if let Some(v) = v {
                out.push_str(&format!(",{}", v[i]));
            }
        }
        out.push('\n');
    }
    out
}

/// Writes bytes to `path` through a temporary file in the same directory and a rename, so a
/// reader never sees a half-written file (one file of [`write_all_atomic`], under the same
/// interruption rules).
///
/// # Errors
/// [`DataError::Io`] when the file cannot be written or renamed; [`DataError::Interrupted`]
/// when the process was interrupted (nothing written).
///
/// ```
/// use yawcast::io::data::write_atomic;
/// let p = std::env::temp_dir().join(format!("yawcast-doc-one-{}.txt", std::process::id()));
/// write_atomic(&p, b"42").unwrap();
/// assert_eq!(std::fs::read(&p).unwrap(), b"42");
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), DataError> {
    OUTPUTS.write_all_refs(&[(path, bytes)], &mut |from, to| std::fs::rename(from, to))
}

/// Writes several files as one: every file goes to a temporary file beside its destination
/// first, and only when all of them are written are they renamed into place. A destination
/// that already exists is kept as a backup (a hard link, or a copy where links are not
/// possible) until every rename has succeeded: when a write or a rename fails, the files
/// already renamed are removed, the backups put back byte for byte, every temporary file and
/// every directory created for the outputs removed. A command's outputs appear all together
/// or not at all.
///
/// The writes of a process are serialised with [`AtomicWriter::interrupt`] on the shared
/// [`OUTPUTS`]: a signal handler calling it waits for a write in progress to finish or to
/// roll back.
///
/// # Errors
/// [`DataError::Io`] naming the first file that could not be written (or renamed), or two
/// outputs with one destination; [`DataError::Interrupted`] when the process was interrupted
/// before or during the renames (then nothing was written).
///
/// ```
/// use yawcast::io::data::write_all_atomic;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-all-{}", std::process::id()));
/// let ok = [(dir.join("a.txt"), b"a".to_vec()), (dir.join("b.txt"), b"b".to_vec())];
/// write_all_atomic(&ok).unwrap();
/// assert_eq!(std::fs::read(dir.join("b.txt")).unwrap(), b"b");
/// // A destination that cannot be written (a directory stands there): nothing else appears.
/// std::fs::create_dir_all(dir.join("c.txt")).unwrap();
/// let bad = [(dir.join("new.txt"), b"n".to_vec()), (dir.join("c.txt"), b"c".to_vec())];
/// assert!(write_all_atomic(&bad).is_err());
/// assert!(!dir.join("new.txt").exists());
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> Result<(), DataError> {
    write_all_atomic_with(files, &mut |from, to| std::fs::rename(from, to))
}

/// [`write_all_atomic`] with the rename of each temporary file onto its destination done by
/// `rename(temporary, destination)`, called once per file in order (fault injection: a
/// rename that fails shows the roll-back; backups are made and restored without it).
///
/// # Errors
/// As [`write_all_atomic`]; an error of `rename` is reported naming its destination.
///
/// ```
/// use yawcast::io::data::write_all_atomic_with;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-with-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("b.txt"), b"old").unwrap();
/// let files = [(dir.join("a.txt"), b"a".to_vec()), (dir.join("b.txt"), b"b".to_vec())];
/// let mut n = 0;
/// let e = write_all_atomic_with(&files, &mut |from, to| {
///     n += 1;
///     if n == 2 { return Err(std::io::Error::other("disk full")); }
///     std::fs::rename(from, to)
/// })
/// .unwrap_err();
/// assert!(e.to_string().contains("b.txt: disk full"), "{e}");
/// assert!(!dir.join("a.txt").exists()); // renamed, then taken back
/// assert_eq!(std::fs::read(dir.join("b.txt")).unwrap(), b"old");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_all_atomic_with(
    files: &[(PathBuf, Vec<u8>)],
    rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
) -> Result<(), DataError> {
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    OUTPUTS.write_all_refs(&refs, rename)
}

/// Files to write together: each destination with its bytes.
pub type OutputFiles = Vec<(PathBuf, Vec<u8>)>;

/// The writer every output of the process goes through ([`write_atomic`],
/// [`write_all_atomic`]).
pub static OUTPUTS: AtomicWriter = AtomicWriter::new();

/// All-or-nothing writes serialised with interruption: one write at a time holds the lock
/// from its first temporary file to its last rename (or roll-back); [`AtomicWriter::interrupt`]
/// marks the writer interrupted and waits for that lock, so a signal handler that calls it
/// and then exits never leaves a temporary file, a backup or a part of a command's outputs.
#[derive(Debug)]
pub struct AtomicWriter {
    lock: std::sync::Mutex<()>,
    signal: std::sync::atomic::AtomicI32,
}

impl Default for AtomicWriter {
    fn default() -> Self {
        AtomicWriter::new()
    }
}

impl AtomicWriter {
    /// A writer not interrupted.
    ///
    /// ```
    /// let w = yawcast::io::data::AtomicWriter::new();
    /// assert_eq!(w.interrupted(), None);
    /// ```
    pub const fn new() -> Self {
        AtomicWriter {
            lock: std::sync::Mutex::new(()),
            signal: std::sync::atomic::AtomicI32::new(0),
        }
    }

    /// The signal the writer was interrupted by, if any.
    ///
    /// ```
    /// let w = yawcast::io::data::AtomicWriter::new();
    /// drop(w.interrupt(2));
    /// assert_eq!(w.interrupted(), Some(2));
    /// ```
    pub fn interrupted(&self) -> Option<i32> {
        match self.signal.load(std::sync::atomic::Ordering::SeqCst) {
            0 => None,
            s => Some(s),
        }
    }

    /// Marks the writer interrupted by `signal` (non-zero) and waits until no write is in
    /// progress: a write that has not reached its renames, or is between two of them, rolls
    /// back; one past its last rename finishes. While the returned guard is held no write
    /// starts, and every later write fails with [`DataError::Interrupted`] without touching
    /// a file.
    ///
    /// ```
    /// use yawcast::io::data::{AtomicWriter, DataError};
    /// let w = AtomicWriter::new();
    /// let _guard = w.interrupt(15);
    /// assert_eq!(w.interrupted(), Some(15));
    /// ```
    pub fn interrupt(&self, signal: i32) -> std::sync::MutexGuard<'_, ()> {
        self.signal
            .store(signal.max(1), std::sync::atomic::Ordering::SeqCst);
        self.lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// [`write_all_atomic_with`] through this writer.
    ///
    /// # Errors
    /// As [`write_all_atomic_with`]; [`DataError::Interrupted`] once [`AtomicWriter::interrupt`]
    /// has been called.
    ///
    /// ```
    /// use yawcast::io::data::{AtomicWriter, DataError};
    /// let w = AtomicWriter::new();
    /// let p = std::env::temp_dir().join(format!("yawcast-doc-w-{}.txt", std::process::id()));
    /// drop(w.interrupt(2));
    /// let e = w.write_all(&[(p.clone(), b"x".to_vec())], &mut |a, b| std::fs::rename(a, b));
    /// assert!(matches!(e, Err(DataError::Interrupted { signal: 2 })));
    /// assert!(!p.exists());
    /// ```
    pub fn write_all(
        &self,
        files: &[(PathBuf, Vec<u8>)],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
    ) -> Result<(), DataError> {
        let refs: Vec<(&Path, &[u8])> = files
            .iter()
            .map(|(p, b)| (p.as_path(), b.as_slice()))
            .collect();
        self.write_all_refs(&refs, rename)
    }

    fn write_all_refs(
        &self,
        files: &[(&Path, &[u8])],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
    ) -> Result<(), DataError> {
        let _held = self
            .lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let mut tx = Transaction::default();
        let res = self.transact(files, rename, &mut tx);
        match res {
            Ok(()) => {
                tx.commit();
                Ok(())
            }
            Err(e) => {
                let unrestored = tx.roll_back();
                let e = match self.interrupted() {
                    Some(signal) => DataError::Interrupted { signal },
                    None => e,
                };
                match (e, unrestored) {
                    (e, None) => Err(e),
                    (DataError::Io { path, source }, Some(what)) => Err(DataError::Io {
                        path,
                        source: std::io::Error::new(source.kind(), format!("{source}; {what}")),
                    }),
                    (e, Some(_)) => Err(e),
                }
            }
        }
    }

    fn transact(
        &self,
        files: &[(&Path, &[u8])],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
        tx: &mut Transaction,
    ) -> Result<(), DataError> {
        let stop = || {
            self.interrupted()
                .map(|signal| DataError::Interrupted { signal })
        };
        if let Some(e) = stop() {
            return Err(e);
        }
        let io = |path: &Path, source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        for (i, (path, _)) in files.iter().enumerate() {
            if files[..i].iter().any(|(p, _)| p == path) {
                return Err(io(
                    path,
                    std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "two outputs of one command go to this file",
                    ),
                ));
            }
        }
        for (path, bytes) in files {
            if path.is_dir() {
                return Err(io(
                    path,
                    std::io::Error::other("a directory stands where the file should go"),
                ));
            }
            if let Some(d) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                let missing: Vec<PathBuf> = d
                    .ancestors()
                    .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
                    .map(Path::to_path_buf)
                    .collect();
                std::fs::create_dir_all(d).map_err(|e| io(path, e))?;
                tx.dirs.extend(missing);
            }
            let tmp = side_name(path, "tmp");
            tx.temps.push(tmp.clone());
            let written = (|| {
                let mut f = std::fs::File::create(&tmp)?;
                f.write_all(bytes)?;
                f.sync_all()
            })();
            written.map_err(|e| io(path, e))?;
            if let Some(e) = stop() {
                return Err(e);
            }
        }
        for (path, _) in files {
            if path.exists() {
                let bak = side_name(path, "bak");
                let _ = std::fs::remove_file(&bak);
                std::fs::hard_link(path, &bak)
                    .or_else(|_| std::fs::copy(path, &bak).map(|_| ()))
                    .map_err(|e| io(path, e))?;
                tx.backups.push((path.to_path_buf(), bak));
            }
        }
        for (i, (path, _)) in files.iter().enumerate() {
            if let Some(e) = stop() {
                return Err(e);
            }
            rename(&tx.temps[i], path).map_err(|e| io(path, e))?;
            tx.renamed.push(path.to_path_buf());
        }
        Ok(())
    }
}

/// `.<name>.<what><pid>` beside `path`.
fn side_name(path: &Path, what: &str) -> PathBuf {
    let fname = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{fname}.{what}{}", std::process::id()))
}

/// What one all-or-nothing write has done so far, to undo it.
#[derive(Debug, Default)]
struct Transaction {
    /// Temporary files created (removed in any case).
    temps: Vec<PathBuf>,
    /// Directories created for the outputs, deepest first within each output.
    dirs: Vec<PathBuf>,
    /// (destination, backup of its previous content).
    backups: Vec<(PathBuf, PathBuf)>,
    /// Destinations renamed into place.
    renamed: Vec<PathBuf>,
}

impl Transaction {
    fn commit(self) {
        for (_, bak) in &self.backups {
            let _ = std::fs::remove_file(bak);
        }
    }

    /// Undoes everything; names what could not be restored, if anything.
    fn roll_back(self) -> Option<String> {
        let mut failed = Vec::new();
        for dest in &self.renamed {
            if !self.backups.iter().any(|(d, _)| d == dest) {
                let _ = std::fs::remove_file(dest);
            }
        }
        for (dest, bak) in &self.backups {
            if self.renamed.contains(dest) {
                if let Err(e) = std::fs::rename(bak, dest) {
                    failed.push(format!(
                        "{} could not be restored from {}: {e}",
                        dest.display(),
                        bak.display()
                    ));
                }
            } else {
                let _ = std::fs::remove_file(bak);
            }
        }
        for t in &self.temps {
            let _ = std::fs::remove_file(t);
        }
        for d in &self.dirs {
            let _ = std::fs::remove_dir(d);
        }
        (!failed.is_empty()).then(|| failed.join("; "))
    }
}

/// Checks, before any work, that every output can be written: no two outputs share a
/// destination, no directory stands where a file should go, and the nearest existing
/// directory above each destination is a directory in which a file can be created (probed
/// with a file created and removed at once).
///
/// # Errors
/// [`DataError::Io`] naming the first output that cannot be written and why.
///
/// ```
/// use yawcast::io::data::check_outputs;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-chk-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("file"), b"").unwrap();
/// let ok = dir.join("new/sub/out.json");
/// assert!(check_outputs(&[ok.as_path()]).is_ok());
/// assert!(!dir.join("new").exists()); // nothing created
/// let blocked = dir.join("file/out.json");
/// let e = check_outputs(&[ok.as_path(), blocked.as_path()]).unwrap_err();
/// assert!(e.to_string().contains("is a file, not a directory"), "{e}");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn check_outputs(paths: &[&Path]) -> Result<(), DataError> {
    for (i, path) in paths.iter().enumerate() {
        let io = |kind: std::io::ErrorKind, msg: String| DataError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(kind, msg),
        };
        if paths[..i].contains(path) {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                "two outputs of one command go to this file".into(),
            ));
        }
        if path.is_dir() {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                "a directory stands where the file should go".into(),
            ));
        }
        let parent = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let Some(existing) = parent.ancestors().find(|a| {
            let a = if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            };
            std::fs::symlink_metadata(a).is_ok()
        }) else {
            continue;
        };
        let existing = if existing.as_os_str().is_empty() {
            Path::new(".")
        } else {
            existing
        };
        if !existing.is_dir() {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{} is a file, not a directory: the output cannot go under it",
                    existing.display()
                ),
            ));
        }
        let probe = existing.join(format!(".yawcast-probe{}", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&probe)
        {
            Ok(_) => {
                let _ = std::fs::remove_file(&probe);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => {
                return Err(io(
                    e.kind(),
                    format!("no file can be created in {}: {e}", existing.display()),
                ))
            }
        }
    }
    Ok(())
}

/// Gyro-bias estimate from heading: `mean((r(t)+r(t+1))/2 − Δψ/Ts)` with its standard error
/// from block sums. `None` without heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingBias {
    /// Estimated rate-sensor offset (deg/s).
    pub bias: f64,
    /// Its standard error (deg/s).
    pub se: f64,
    /// Samples used.
    pub n: usize,
}

/// Rate-sensor offset seen by the heading channel over `recs` (pooled), or `None` when a
/// record has no heading.
///
/// ```
/// use yawcast::io::data::{heading_bias, Record};
/// // heading turns at 1 °/s, the gyro reads 1.2 °/s
/// let mut r = Record::from_uy("x", 1.0, vec![0.0; 400], vec![1.2; 400]);
/// r.psi = Some((0..400).map(|i| i as f64).collect());
/// let hb = heading_bias(&[r]).unwrap();
/// assert!((hb.bias - 0.2).abs() < 1e-12);
/// ```
pub fn heading_bias(recs: &[Record]) -> Option<HeadingBias> {
    let mut series = Vec::with_capacity(recs.len());
    for r in recs {
        let psi = r.psi.as_ref()?;
        if r.len() < 3 {
            continue;
        }
        series.push(
            (0..r.len() - 1)
                .map(|t| 0.5 * (r.y[t] + r.y[t + 1]) - (psi[t + 1] - psi[t]) / r.ts)
                .collect::<Vec<f64>>(),
        );
    }
    let (bias, se, n) = block_mean(&series)?;
    Some(HeadingBias { bias, se, n })
}

/// Pooled mean of `series` with its standard error from block sums — blocks of about √m
/// samples (10 to 200) within each series of m values, so serial correlation inside a block
/// counts — and the number of values used. Non-finite values (missing samples) are skipped;
/// `None` when none is left.
///
/// ```
/// // 500 zeros then 500 ones: the mean is 0.5; the blocks see the two halves, so the
/// // standard error is far above the white-noise 0.5/√1000 = 0.016
/// let mut s = vec![0.0; 500];
/// s.extend([1.0; 500]);
/// s.push(f64::NAN); // a missing sample is skipped
/// let (mean, se, n) = yawcast::io::data::block_mean(&[s]).unwrap();
/// assert_eq!((mean, n), (0.5, 1000));
/// assert!(se > 0.05, "{se}");
/// ```
pub fn block_mean(series: &[Vec<f64>]) -> Option<(f64, f64, usize)> {
    let mut sum = 0.0;
    let mut n = 0usize;
    let mut blocks: Vec<f64> = Vec::new();
    for s in series {
        let m = s.iter().filter(|v| v.is_finite()).count();
        if m == 0 {
            continue;
        }
        let l = block_len(m);
        let mut acc = 0.0;
        let mut cnt = 0;
        for &d in s.iter().filter(|v| v.is_finite()) {
            sum += d;
            n += 1;
            acc += d;
            cnt += 1;
            if cnt == l {
                blocks.push(acc);
                acc = 0.0;
                cnt = 0;
            }
        }
        if cnt > 0 {
            blocks.push(acc * l as f64 / cnt as f64);
        }
    }
    if n == 0 {
        return None;
    }
    let mean = sum / n as f64;
    let l = (n as f64 / blocks.len().max(1) as f64).max(1.0);
    let var: f64 = blocks.iter().map(|b| (b - mean * l).powi(2)).sum::<f64>();
    let se = (var.max(0.0)).sqrt() / n as f64;
    Some((mean, se.max(1e-12), n))
}

fn block_len(n: usize) -> usize {
    ((n as f64).sqrt().round() as usize).clamp(10, 200)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(txt: &str) -> Result<Record, DataError> {
        parse_csv(txt, Path::new("f.csv"), "f", &Columns::default())
    }

    #[test]
    fn reads_optional_columns() {
        let r = parse("t_s,delta_deg,r_degps,psi_deg,u_mps\n0,1,0,10,1.5\n0.5,1,0.1,10.1,1.5\n")
            .unwrap();
        assert_eq!(r.ts, 0.5);
        assert_eq!(r.psi, Some(vec![10.0, 10.1]));
        assert_eq!(r.speed, Some(vec![1.5, 1.5]));
        assert!(r.wind_speed.is_none());
    }

    #[test]
    fn missing_column_is_named() {
        let e = parse("t_s,delta_deg\n0,1\n1,1\n").unwrap_err().to_string();
        assert!(e.contains("r_degps") && e.contains("f.csv"), "{e}");
    }

    #[test]
    fn bad_cell_names_row_and_column() {
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,x,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("row 2") && e.contains("delta_deg") && e.contains("`x`"),
            "{e}"
        );
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,NaN\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("r_degps") && e.contains("NaN"), "{e}");
    }

    #[test]
    fn jittered_time_stamps_keep_the_loggers_period() {
        // a 2 Hz logger whose stamps jitter by up to ±0.1 s (20 % of a period)
        let mut txt = String::from("t_s,delta_deg,r_degps\n");
        for i in 0..200 {
            let jitter = 0.1 * (((i * 7919) % 11) as f64 / 5.0 - 1.0);
            txt.push_str(&format!("{},1,0\n", 0.5 * i as f64 + jitter));
        }
        let r = parse(&txt).unwrap();
        assert_eq!(r.ts, 0.5);
        // a period far from three significant digits is kept as it is
        let t: Vec<f64> = (0..10).map(|i| i as f64 * 0.123_456_7).collect();
        let ts = check_uniform(&t, Path::new("x")).unwrap();
        assert!((ts - 0.123_456_7).abs() < 1e-15, "{ts}");
    }

    #[test]
    fn heading_is_unwrapped_through_north() {
        let r = parse("t_s,delta_deg,r_degps,psi_deg\n0,1,0,359\n1,1,0,1\n2,1,0,3\n3,1,0,0.5\n")
            .unwrap();
        assert_eq!(r.psi, Some(vec![359.0, 361.0, 363.0, 360.5]));
        let mut west = vec![-179.0, 179.0, 170.0, -170.0];
        unwrap_degrees(&mut west);
        assert_eq!(west, vec![-179.0, -181.0, -190.0, -170.0]);
    }

    #[test]
    fn non_uniform_and_non_monotonic_time() {
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n2.5,1,0\n3.5,1,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 3"), "{e}");
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n0.5,1,0\n").unwrap_err();
        assert!(matches!(e, DataError::NonUniform { row: 3, .. }), "{e}");
        assert!(e.to_string().contains("time goes back"), "{e}");
        // a gap of three samples, an extra sample, a repeated stamp: each named with its row
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n2,1,0\n6,1,0\n7,1,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("row 4")
                && e.contains("3 samples missing")
                && e.contains("sample time is 1 s"),
            "{e}"
        );
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n1.3,1,0\n2,1,0\n3,1,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 3") && e.contains("extra sample"), "{e}");
        let e = parse("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n1,1,0\n2,1,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 3") && e.contains("repeats"), "{e}");
    }

    #[test]
    fn round_trip_and_atomic_write() {
        let dir = std::env::temp_dir().join(format!("yawcast-data-{}", std::process::id()));
        let p = dir.join("r.csv");
        let mut r = Record::from_uy("r", 0.25, vec![1.0, -2.5, 3.0], vec![0.125, 0.0, -1.0]);
        r.psi = Some(vec![0.0, 1.0, 2.0]);
        write_csv(&p, &r).unwrap();
        let back = read_csv(&p).unwrap();
        assert_eq!(back.u, r.u);
        assert_eq!(back.y, r.y);
        assert_eq!(back.psi, r.psi);
        assert_eq!(back.ts, 0.25);
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .contains(".tmp")
            })
            .collect();
        assert!(leftovers.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every entry of `dir` (recursively), as sorted relative paths with their bytes.
    fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut out = Vec::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap() {
                let p = e.unwrap().path();
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                if p.is_dir() {
                    out.push((rel + "/", Vec::new()));
                    stack.push(p);
                } else {
                    out.push((rel, std::fs::read(&p).unwrap()));
                }
            }
        }
        out.sort();
        out
    }

    fn fresh_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("yawcast-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A rename that fails on the `n`-th file (1-based), counting its calls.
    fn failing_on(
        n: usize,
        calls: &mut usize,
    ) -> impl FnMut(&Path, &Path) -> std::io::Result<()> + '_ {
        move |from, to| {
            *calls += 1;
            if *calls == n {
                return Err(std::io::Error::other("injected rename failure"));
            }
            std::fs::rename(from, to)
        }
    }

    #[test]
    fn a_rename_failing_after_the_first_output_leaves_no_output() {
        let d = fresh_dir("fault-new");
        let files = vec![
            (d.join("model.postcard"), vec![1u8, 2, 3]),
            (d.join("sub/deeper/model.json"), b"{}".to_vec()),
            (d.join("summary.json"), b"{\"a\":1}".to_vec()),
        ];
        let mut calls = 0;
        let e = write_all_atomic_with(&files, &mut failing_on(2, &mut calls)).unwrap_err();
        assert_eq!(
            calls, 2,
            "the first file was renamed into place before the failure"
        );
        assert!(
            matches!(&e, DataError::Io { path, .. } if path == &d.join("sub/deeper/model.json")),
            "{e}"
        );
        assert!(e.to_string().contains("injected rename failure"), "{e}");
        // no output, no temporary file, no directory created for the outputs
        assert_eq!(listing(&d), Vec::<(String, Vec<u8>)>::new());
        // and the same files go through when nothing fails
        let mut calls = 0;
        write_all_atomic_with(&files, &mut failing_on(0, &mut calls)).unwrap();
        assert_eq!(calls, 3);
        assert_eq!(
            std::fs::read(d.join("model.postcard")).unwrap(),
            vec![1u8, 2, 3]
        );
        let names: Vec<String> = listing(&d).into_iter().map(|(n, _)| n).collect();
        assert_eq!(
            names,
            [
                "model.postcard",
                "sub/",
                "sub/deeper/",
                "sub/deeper/model.json",
                "summary.json"
            ]
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failed_write_restores_every_file_it_would_have_replaced() {
        let d = fresh_dir("fault-old");
        let old: Vec<(PathBuf, Vec<u8>)> = vec![
            (d.join("ship.postcard"), vec![0xde, 0xad, 0xbe, 0xef, 0]),
            (d.join("ship.json"), b"{\"old\": true}\n".to_vec()),
            (d.join("tables.md"), b"| old |\n".to_vec()),
        ];
        for (p, b) in &old {
            std::fs::write(p, b).unwrap();
        }
        let before = listing(&d);
        let new: Vec<(PathBuf, Vec<u8>)> = old
            .iter()
            .map(|(p, _)| (p.clone(), b"new content".to_vec()))
            .chain([(d.join("fresh.json"), b"{}".to_vec())])
            .collect();
        for fail_at in 1..=4 {
            let mut calls = 0;
            let e = write_all_atomic_with(&new, &mut failing_on(fail_at, &mut calls)).unwrap_err();
            assert!(
                matches!(&e, DataError::Io { path, .. } if path == &new[fail_at - 1].0),
                "{e}"
            );
            assert_eq!(listing(&d), before, "failing at rename {fail_at}");
        }
        // a write that goes through replaces all and leaves no backup
        write_all_atomic(&new).unwrap();
        let after = listing(&d);
        assert_eq!(after.len(), 4, "{after:?}");
        assert!(after.iter().all(|(_, b)| b == b"new content" || b == b"{}"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn two_outputs_to_one_file_are_refused_before_any_write() {
        let d = fresh_dir("dup");
        let files = vec![
            (d.join("a.json"), b"1".to_vec()),
            (d.join("a.json"), b"2".to_vec()),
        ];
        let e = write_all_atomic(&files).unwrap_err();
        assert!(e.to_string().contains("two outputs"), "{e}");
        assert!(listing(&d).is_empty());
        let e = check_outputs(&[&d.join("x"), &d.join("x")]).unwrap_err();
        assert!(e.to_string().contains("two outputs"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// An interrupt arriving between two renames: the writer rolls back under its lock before
    /// `interrupt` returns, and writes nothing afterwards.
    #[test]
    fn an_interrupt_during_the_renames_rolls_back_before_it_returns() {
        let d = fresh_dir("interrupt");
        std::fs::write(d.join("model.postcard"), b"old blob").unwrap();
        let before = listing(&d);
        let writer = std::sync::Arc::new(AtomicWriter::new());
        let files = vec![
            (d.join("model.json"), b"new twin".to_vec()),
            (d.join("model.postcard"), b"new blob".to_vec()),
        ];
        let (renamed_tx, renamed_rx) = std::sync::mpsc::channel();
        let w = writer.clone();
        let f = files.clone();
        let handle = std::thread::spawn(move || {
            let mut first = true;
            w.write_all(&f, &mut |from, to| {
                std::fs::rename(from, to)?;
                if first {
                    first = false;
                    // The twin is in place, the blob not yet: wait here for the signal.
                    renamed_tx.send(()).unwrap();
                    while w.interrupted().is_none() {
                        std::thread::yield_now();
                    }
                }
                Ok(())
            })
        });
        renamed_rx.recv().unwrap();
        assert_eq!(std::fs::read(d.join("model.json")).unwrap(), b"new twin");
        let guard = writer.interrupt(15);
        // The lock is ours: the write has rolled back already.
        assert_eq!(listing(&d), before);
        drop(guard);
        let res = handle.join().unwrap();
        assert!(
            matches!(res, Err(DataError::Interrupted { signal: 15 })),
            "{res:?}"
        );
        // later writes touch nothing
        let e = writer
            .write_all(&files, &mut |a, b| std::fs::rename(a, b))
            .unwrap_err();
        assert!(matches!(e, DataError::Interrupted { signal: 15 }), "{e}");
        assert!(e.to_string().contains("no output written"), "{e}");
        assert_eq!(listing(&d), before);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn duplicate_columns_are_named_not_resolved() {
        let e = parse("t_s,delta_deg,r_degps,delta_deg\n0,1,0,2\n1,2,1,3\n").unwrap_err();
        assert!(
            matches!(&e, DataError::DuplicateColumn { column, first: 2, second: 4, .. } if column == "delta_deg"),
            "{e}"
        );
    }

    #[test]
    fn semicolon_files_with_decimal_commas_are_read() {
        let r = parse("t_s;delta_deg;r_degps\n0;1,5;0\n0,5;-2;0,25\n1;3;-0,125\n").unwrap();
        assert_eq!(r.ts, 0.5);
        assert_eq!(r.u, vec![1.5, -2.0, 3.0]);
        assert_eq!(r.y, vec![0.0, 0.25, -0.125]);
        // A comma file whose cells hold `;` stays a comma file (and fails on the cell).
        assert!(!semicolon_separated("t_s,delta_deg;x,r_degps\n"));
    }

    #[test]
    fn implausible_values_and_still_channels_are_named() {
        let cols = Columns::default();
        let lim = Limits::default();
        let path = Path::new("trial.csv");
        let mut r = Record::from_uy(
            "r",
            1.0,
            vec![0.0, 4.0, -4.0, 2.0],
            vec![0.0, 0.5, -0.5, 0.1],
        );
        assert!(validate_record(&r, path, &lim, &cols).is_ok());
        r.y[2] = 3.4e200;
        let e = validate_record(&r, path, &lim, &cols).unwrap_err();
        assert!(
            matches!(&e, DataError::Implausible { row: 3, column, limit, .. } if column == "r_degps" && *limit == 30.0),
            "{e}"
        );
        assert!(e.to_string().contains("--max-rate"), "{e}");
        r.y[2] = -0.5;
        r.speed = Some(vec![1.0, 1.0, 150.0, 1.0]);
        let e = validate_record(&r, path, &lim, &cols).unwrap_err();
        assert!(matches!(e, DataError::Implausible { row: 3, .. }), "{e}");
        r.speed = None;
        let zero = Record::from_uy("z", 1.0, vec![0.0; 4], vec![0.0; 4]);
        let e = validate_record(&zero, path, &lim, &cols).unwrap_err();
        assert!(
            matches!(&e, DataError::NoExcitation { column, .. } if column == "delta_deg"),
            "{e}"
        );
        let tiny = Record::from_uy(
            "t",
            1.0,
            vec![0.0, 5.0, 0.0, 5.0],
            vec![1e-300, 0.0, 2e-300, 0.0],
        );
        let e = validate_record(&tiny, path, &lim, &cols).unwrap_err();
        assert!(
            matches!(&e, DataError::NoExcitation { column, .. } if column == "r_degps"),
            "{e}"
        );
        assert!(e.to_string().contains("constant"), "{e}");
    }

    #[test]
    fn resampling_absorbs_gaps_and_another_rate() {
        // A 2 s gap that uniform reading refuses is resampled onto 0.5 s.
        let txt = "t_s,delta_deg,r_degps,psi_deg\n0,1,0,358\n1,1,1,359\n3,-1,3,1\n4,-1,2,2\n";
        assert!(parse(txt).is_err());
        let cols = Columns {
            resample: Some(0.5),
            ..Columns::default()
        };
        let r = parse_csv(txt, "g.csv".as_ref(), "g", &cols).unwrap();
        assert_eq!(r.ts, 0.5);
        assert_eq!(r.t.len(), 9);
        assert_eq!(r.u, vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -1.0, -1.0, -1.0]);
        assert_eq!(r.y[3], 1.5);
        assert_eq!(r.y[8], 2.0);
        // Heading through north: 359 → 361 (unwrapped), half-way 360.
        assert_eq!(r.psi.as_ref().unwrap()[4], 360.0);
        let back = "t_s,delta_deg,r_degps\n0,1,0\n1,1,1\n1,2,2\n";
        let e = parse_csv(back, "b.csv".as_ref(), "b", &cols).unwrap_err();
        assert!(matches!(e, DataError::NonUniform { row: 3, .. }), "{e}");
    }
}
