//! The settings of an identification and what it reports: starts, termination, reliability, errors.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::choose;
use crate::identify::model::Model;

/// STD% above which the paper calls a model unreliable.
pub const STD_PCT_UNRELIABLE: f64 = 10.0;
/// STD% above which the paper calls a model unusable.
pub const STD_PCT_UNUSABLE: f64 = 50.0;

/// Where a search starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// ARX(n, n) least squares, converted to the canonical form (K from the ARX noise model).
    Arx,
    /// ARMAX(n, n, n) by extended least squares (pseudo-linear regression), converted.
    Armax,
    /// The template model itself (used only when it has the requested order and is stable).
    Template,
    /// A subspace (N4SID) estimate of order n, converted: it weighs prediction horizons up to
    /// its block size and so starts in a basin of the one-step cost that the ARX(n, n) fit
    /// misses when the order cannot hold the system (an actuator delay, a nonlinearity).
    Subspace,
}

/// Settings of [`identify`](super::identify).
#[derive(Debug, Clone, PartialEq)]
pub struct PemConfig {
    /// Model order n (2..=8).
    pub order: usize,
    /// Regularisation weight λ ≥ 0 (0: plain PEM).
    pub lambda: f64,
    /// Diagonal of R, one weight per estimated parameter (θ then effect gains);
    /// `None`: identity.
    pub r: Option<Vec<f64>>,
    /// θ* the penalty pulls towards (same length as `r`); `None`: zero, as in the paper.
    pub nominal: Option<Vec<f64>>,
    /// Levenberg–Marquardt iteration cap per start.
    pub max_iter: usize,
    /// Stop when an accepted step lowers the cost by less than `tol` (relative).
    pub tol: f64,
    /// Starts to try; the template is added when given and usable.
    pub starts: Vec<Start>,
    /// Evaluate records in parallel (rayon).
    pub parallel: bool,
    /// Horizons (samples) that decide between minima whose one-step costs do not differ
    /// significantly (see [`choose`]); empty: the lowest cost always wins.
    pub select_horizons: Vec<usize>,
}

impl Default for PemConfig {
    fn default() -> Self {
        PemConfig {
            order: 4,
            lambda: 0.0,
            r: None,
            nominal: None,
            max_iter: 100,
            tol: 1e-8,
            starts: vec![Start::Arx, Start::Armax, Start::Subspace],
            parallel: true,
            select_horizons: vec![5, 10, 20],
        }
    }
}

/// Why the Levenberg–Marquardt search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// The relative cost decrease of a trusted step fell below the tolerance.
    Converged,
    /// The step became negligible relative to the parameters.
    SmallStep,
    /// No step lowers the cost any more (damping exhausted): a minimum to working precision.
    Stalled,
    /// The iteration cap was reached.
    MaxIterations,
}

impl Termination {
    /// Short description.
    ///
    /// ```
    /// assert_eq!(yawcast::identify::pem::Termination::MaxIterations.describe(), "iteration cap reached");
    /// ```
    pub fn describe(&self) -> &'static str {
        match self {
            Termination::Converged => "converged (cost change below tolerance)",
            Termination::SmallStep => "converged (step below tolerance)",
            Termination::Stalled => "no further decrease possible",
            Termination::MaxIterations => "iteration cap reached",
        }
    }
}

/// The paper's reliability verdict from the STD%s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Reliability {
    /// Every STD% ≤ 10.
    Reliable,
    /// Some STD% > 10, none > 50.
    Unreliable,
    /// Some STD% > 50.
    Unusable,
}

/// The paper's rule applied to a list of STD%s.
///
/// ```
/// use yawcast::identify::pem::{reliability, Reliability};
/// assert_eq!(reliability(&[1.0, 9.9]), Reliability::Reliable);
/// assert_eq!(reliability(&[1.0, 27.7]), Reliability::Unreliable);
/// assert_eq!(reliability(&[539.9, 2.0]), Reliability::Unusable);
/// ```
pub fn reliability(std_pct: &[f64]) -> Reliability {
    let worst = std_pct
        .iter()
        .map(|v| if v.is_nan() { f64::INFINITY } else { *v })
        .fold(0.0, f64::max);
    if worst > STD_PCT_UNUSABLE {
        Reliability::Unusable
    } else if worst > STD_PCT_UNRELIABLE {
        Reliability::Unreliable
    } else {
        Reliability::Reliable
    }
}

/// Result of an identification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PemReport {
    /// The identified model (structure of the template).
    pub model: Model,
    /// x̂(0) per record.
    pub x0: Vec<Vec<f64>>,
    /// Parameter names, in the order of `std`, `std_pct`, `cov`.
    pub names: Vec<String>,
    /// V(θ) at the optimum (including the penalty); see `choice` when that is not the
    /// lowest minimum the starts reached.
    pub cost: f64,
    /// Residual variance Σε²/(N − p).
    pub sigma2: f64,
    /// Parameter covariance (p × p, row-major rows).
    pub cov: Vec<Vec<f64>>,
    /// Standard deviation per parameter.
    pub std: Vec<f64>,
    /// 100·STD/|value| per parameter.
    pub std_pct: Vec<f64>,
    /// Levenberg–Marquardt iterations of the winning start.
    pub iterations: usize,
    /// Why the winning search stopped.
    pub termination: Termination,
    /// Which start won.
    pub start: Start,
    /// Akaike's criterion `N ln(Σε²/N) + 2p + N(ln 2π + 1)`, Σε² of the lowest minimum
    /// any start reached (the structure's maximum likelihood).
    pub aic: f64,
    /// Bayesian criterion `N ln(Σε²/N) + p ln N + N(ln 2π + 1)`, Σε² as for `aic`.
    pub bic: f64,
    /// Samples used (measured y, all records).
    pub samples: usize,
    /// The paper's verdict from `std_pct`.
    pub reliability: Reliability,
    /// λ used.
    pub lambda: f64,
    /// R used (diagonal).
    pub r: Vec<f64>,
    /// One-step fit % per record (with its x̂(0)).
    pub fit: Vec<f64>,
    /// Set when the winning minimum is not the lowest-cost one: why (see [`choose`]).
    #[serde(default)]
    pub choice: Option<choose::StartChoice>,
}

impl PemReport {
    /// Largest STD% (∞ when a parameter is exactly zero).
    pub fn max_std_pct(&self) -> f64 {
        self.std_pct
            .iter()
            .map(|v| if v.is_nan() { f64::INFINITY } else { *v })
            .fold(0.0, f64::max)
    }
}

/// One order's line of [`select_order`](super::select_order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderReport {
    /// Order n.
    pub order: usize,
    /// Estimated parameters.
    pub params: usize,
    /// V at the optimum (`NaN` when the identification failed).
    pub cost: f64,
    /// AIC.
    pub aic: f64,
    /// BIC.
    pub bic: f64,
    /// Mean fit % over the records at horizons 1, 5, 10 and sim (keys `"1"`, `"5"`, `"10"`, `"sim"`).
    pub fit: std::collections::BTreeMap<String, f64>,
    /// Largest STD%.
    pub max_std_pct: f64,
    /// The paper's verdict.
    pub reliability: Option<Reliability>,
    /// LM iterations.
    pub iterations: usize,
    /// Why this order failed, when it did.
    pub error: Option<String>,
}

/// Identification errors.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum IdentError {
    /// No record given.
    #[error("no records to identify from")]
    NoRecords,
    /// Order outside what the predictor supports.
    #[error("model order {0} is outside 2..=8")]
    Order(usize),
    /// Too little data for the number of unknowns.
    #[error(
        "too few samples for order {order}: {found} samples for {unknowns} unknowns \
         ({params} parameters + x̂(0) per record), at least {needed} needed"
    )]
    TooFewSamples {
        /// Order.
        order: usize,
        /// Samples available.
        found: usize,
        /// Parameters estimated.
        params: usize,
        /// Parameters plus initial states.
        unknowns: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A record is shorter than the order allows.
    #[error(
        "record `{record}` has {found} samples; order {order} needs at least {needed} per record"
    )]
    RecordTooShort {
        /// Record name.
        record: String,
        /// Its samples.
        found: usize,
        /// Order.
        order: usize,
        /// Minimum per record.
        needed: usize,
    },
    /// No record has a varying input.
    #[error("no excitation: the input of {records} is constant, nothing can be identified")]
    ConstantInput {
        /// The record names, comma-separated.
        records: String,
    },
    /// NaN or infinite data.
    #[error("record `{record}`: {channel} sample {sample} is not finite ({value})")]
    NonFinite {
        /// Record name.
        record: String,
        /// Channel (`u`, `y`, `psi`).
        channel: &'static str,
        /// 0-based sample index.
        sample: usize,
        /// The value.
        value: f64,
    },
    /// Channels of unequal length.
    #[error("record `{record}`: channel lengths differ (u {u}, y {y})")]
    Ragged {
        /// Record name.
        record: String,
        /// u length.
        u: usize,
        /// y length.
        y: usize,
    },
    /// Records (or template) with different sample times.
    #[error("sample time of `{record}` is {found} s, expected {expected} s")]
    SampleTime {
        /// Record name (or `template`).
        record: String,
        /// Its sample time.
        found: f64,
        /// The first record's.
        expected: f64,
    },
    /// R or the nominal vector has the wrong length, or a setting is out of range.
    #[error("bad setting: {0}")]
    Config(String),
    /// The given start model is not stable.
    #[error(
        "the start model is unstable (A or A − KC has an eigenvalue on or outside the unit circle)"
    )]
    StartUnstable,
    /// Every start was unstable or failed numerically.
    #[error("every start failed: {0}")]
    AllStartsFailed(String),
    /// The optimum is not stable.
    #[error("the identified model is unstable")]
    Unstable,
    /// Predictions are not finite, or nothing is measured (see
    /// [`focus::refine`](super::focus::refine)).
    #[error("cannot refine: {0}")]
    Refine(String),
}

impl IdentError {
    /// Whether the records or settings are at fault (bad input) rather than the search: a
    /// search that found no stable model (every start failed, an unstable optimum or start)
    /// is not the input's fault.
    ///
    /// ```
    /// use yawcast::identify::pem::IdentError;
    /// assert!(IdentError::NoRecords.is_bad_input());
    /// assert!(!IdentError::Unstable.is_bad_input());
    /// ```
    pub fn is_bad_input(&self) -> bool {
        match self {
            IdentError::NoRecords
            | IdentError::Order(_)
            | IdentError::TooFewSamples { .. }
            | IdentError::RecordTooShort { .. }
            | IdentError::ConstantInput { .. }
            | IdentError::NonFinite { .. }
            | IdentError::Ragged { .. }
            | IdentError::SampleTime { .. }
            | IdentError::Config(_)
            | IdentError::Refine(_) => true,
            IdentError::StartUnstable | IdentError::AllStartsFailed(_) | IdentError::Unstable => {
                false
            }
        }
    }
}
