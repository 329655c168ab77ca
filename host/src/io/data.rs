//! Measurement records: the uniform-sampled time series every tool works on, and the CSV format.
//!
//! CSV header (units in the names):
//! `t_s,delta_deg,r_degps[,psi_deg][,u_mps][,wind_speed_mps,wind_angle_deg][,cog_deg]`.
//! `delta_deg` is the *commanded* angle, held over `[t, t+Ts)`.

use std::path::PathBuf;

use thiserror::Error;

mod atomic;
mod checks;
mod csv_file;
mod gyro;
mod heading;
mod spikes;
mod split;
#[cfg(test)]
mod tests;
mod timestamp;

pub use atomic::{
    check_outputs, write_all_atomic, write_all_atomic_with, write_atomic, AtomicWriter,
    OutputFiles, OUTPUTS,
};
pub use checks::{
    check_uniform, unit_warnings, unwrap_degrees, validate_record, Limits, MIN_COMMAND_SPAN_DEG,
    MIN_RATE_SPAN_DEGPS, MIN_TURN_DEG, RUDDER_MAX_DEG,
};
pub use csv_file::{
    csv_text, decode_text, fill_gaps, heading_rate, parse_csv, read_csv, read_csv_with, resample,
    write_csv, Columns,
};
pub(crate) use csv_file::{uniform_grid, Dialect};
pub use gyro::{gyro_offset, GyroOffset};
pub use heading::{block_mean, heading_bias, HeadingBias};
pub use spikes::{despike, spike_rows, spikes, Spike, NOISE_TIMES, RANGE_SHARE};
pub use split::{split_at_gaps, Break, BreakKind, Piece, Split};
pub(crate) use timestamp::days_from_civil;

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
    /// Course over ground (deg from north, clockwise), when logged; `NaN` where a sample is
    /// missing (a GPS drop-out), which every use skips.
    pub cog: Option<Vec<f64>>,
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
    /// An optional channel's cell is empty or `NaN` (a dropout) and `--fill-gaps` is off.
    #[error(
        "{path}: row {row}, column `{column}`: expected a finite number, found `{value}` (a \
         dropout? --fill-gaps N interpolates up to N missing samples in a row of the heading, \
         speed and wind channels)"
    )]
    Dropout {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row (header is row 0).
        row: usize,
        /// Column name.
        column: String,
        /// Offending text.
        value: String,
    },
    /// A run of missing samples longer than `--fill-gaps` allows.
    #[error(
        "{path}: row {first}, column `{column}`: {missing} samples missing in a row from \
         there (--fill-gaps fills up to {limit}); split the record there, or leave the channel \
         out (its --col-… option naming no column)"
    )]
    Gap {
        /// File concerned.
        path: PathBuf,
        /// Column name.
        column: String,
        /// 1-based data row of the first missing sample.
        first: usize,
        /// How many are missing in a row.
        missing: usize,
        /// The most `--fill-gaps` fills.
        limit: usize,
    },
    /// The yaw-rate column is absent where a heading is logged.
    #[error(
        "{path}: missing column `{column}` (found: {found}); the heading `{heading}` is \
         logged: --rate-from-heading takes the yaw rate as its change over each sample"
    )]
    NoRate {
        /// File concerned.
        path: PathBuf,
        /// The yaw-rate column expected.
        column: String,
        /// The heading column found.
        heading: String,
        /// Columns actually present.
        found: String,
    },
    /// A time cell is not a date-time (ISO 8601) or time of day where the first row's is.
    #[error(
        "{path}: row {row}, column `{column}`: expected a time stamp like the first row's \
         (an ISO 8601 date-time such as 2024-05-01T12:00:00.5Z, or a time of day such as \
         12:00:00.5), found `{value}`"
    )]
    BadTime {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row (header is row 0).
        row: usize,
        /// Column name.
        column: String,
        /// Offending text.
        value: String,
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
    /// The yaw rate leaves its neighbours and comes back within one sample by more than
    /// noise and a ship's motion allow ([`spikes`]).
    #[error(
        "{path}: row {row}, column `{column}`: {value:.4} °/s where its neighbours make \
         {fitted:.4}: an isolated spike (a logger's glitch?), which no ship's yaw rate makes \
         between two samples; {count} such sample(s) in this record (rows {rows}). --despike \
         replaces each by the value its neighbours make, and says which"
    )]
    Spike {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row of the first spike.
        row: usize,
        /// Column name.
        column: String,
        /// The value logged there (°/s).
        value: f64,
        /// The value its neighbours make (°/s).
        fitted: f64,
        /// How many spikes the record holds.
        count: usize,
        /// Their rows (1-based), the first ten.
        rows: String,
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
            cog: cut(&self.cog),
        }
    }
}
