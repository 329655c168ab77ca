//! Which physical effect is the model missing? Evidence for every library effect on the
//! trial records *and* on the reference records the model was identified from; the verdict
//! names what the trials have that the reference lacks, or `none`.
//!
//! The method (for users, in words: docs/method.md, "Diagnose and augment"):
//!
//! - **Frozen linear part.** θ stays at the model's values; each effect is added with its
//!   structural parameter on a grid (dead time d, slew rate ρ, clip level, `y|y|` or `y³`)
//!   and its linear gains fitted by least squares on the prediction errors (one-step errors
//!   for actuator and hull effects, ≈ 50-step errors for the slow effects bias, gyro bias,
//!   wind and current). The likelihood statistic is `N·ln(SSE₀/SSE₁)`, maximised over the grid.
//! - **Difference against the reference.** The same fit on the reference records gives the
//!   version of the effect the reference already shows (a linear model of a nonlinear hull
//!   shows "nonlinear damping" on any data). The trial statistic is measured from that
//!   version: `D = N·ln(SSE(reference version)/SSE(trial's best))`.
//! - **The reference's own steering gear.** A slow or delayed gear (a slew limit, a dead
//!   time) is dynamics: the linear model identified on the reference absorbs it into its
//!   poles, so with θ frozen the reference shows no version of it, and on the trials
//!   whichever gear effect mimics the gear's lag best on their commands stands out — a
//!   2 s dead time on a ship whose own gear slews at 4 °/s looked like a slew limit of
//!   5 °/s, and trials with no hidden effect showed a slew limit. So first the reference's
//!   own gear dynamics are looked for with θ re-identified ([`crate::diagnose::augment::forward`] over
//!   dead time and slew limit on the reference records, its rule for keeping an effect);
//!   when the reference shows some, every statistic below is measured against the reference
//!   model with it (`base`), and a trial's departure from the reference's gear is tested as
//!   that effect's parameter moving. Angle limits are left to the frozen reference version:
//!   static, they cannot hide in the poles.
//! - **Null distribution by parametric bootstrap.** The innovations model (with the
//!   reference's own gear, when it shows one) is simulated with the reference's innovation
//!   variance on the reference and trial inputs; `D` is recomputed on each replicate and a scaled χ² is fitted to the
//!   replicates (Satterthwaite), which gives the p-value. No threshold is set by hand: an
//!   effect is *significant* at level α.
//! - **Every channel.** Heading separates a gyro bias from a yaw moment: over a record,
//!   `mean(r) − mean(dψ/dt)` equals the rate-sensor offset and is ≈ 0 for a true moment.
//!   Speed over ground modulated with heading (harmonics in ψ) reveals current and wind,
//!   once what turning does to the speed is taken out: the speed lost in turns and to
//!   rudder/pod drag (r² and δ² through a bank of first-order lags, 10–270 s, spanning the
//!   surge time constants of model ships to large ships). A trial whose turning history
//!   differs from the reference's has a different heading history too, so speed loss left
//!   in the residual aliases onto the heading harmonics and reads as a current.
//!   Standard errors of these channel statistics come from block (batch-means) sums, so
//!   slow disturbances are accounted for.
//! - **Encompassing test between the top two**: both effects fitted jointly, each over its
//!   whole grid; what each adds given the other, beyond the version the reference shows,
//!   decides between look-alikes (dead time vs slew limit, bias vs current vs wind).
//! - **Ranking.** Effects are ranked by their likelihood gain above noise (`D` less its null
//!   mean; a channel's χ² less its degrees of freedom): p-values far in the tail rest on the
//!   shape fitted to a few dozen null replicates and cannot be compared between effects.
//! - **Significant and material.** Each effect is judged at level α/m (m effects tested,
//!   Bonferroni), and reported only when it also improves held-out prediction (θ frozen, the
//!   effect's gains fitted on the estimation part, fit at 10 steps or in simulation) — or, for
//!   effects the yaw prediction cannot see well, when its own channel shows it (heading for
//!   a gyro bias, speed over ground for current and wind). An effect that speed over ground
//!   alone shows (no heading-dependent yaw moment) and that buys no held-out yaw-rate
//!   prediction is not named ahead of a significant effect that does. The verdict's effect
//!   is then refitted with the model ([`crate::diagnose::augment::augment`]) for the before/after fits.
//! - **Current or wind.** A uniform current carries the ship: speed over ground varies with
//!   heading by the current's speed (first harmonic), but the hull sees the same water
//!   whatever its heading, so the current adds (almost) no heading-dependent yaw moment. Wind
//!   turns the ship through the relative wind angle (first and second harmonics of the yaw
//!   moment) and changes speed over ground only through added drag. "Wind" therefore nests
//!   "current" (both leave the speed harmonics free; wind adds the yaw-moment harmonics), and
//!   the likelihood-ratio test between them is the yaw channel's heading-harmonic statistic
//!   against its bootstrap null: when speed over ground is logged and either is significant,
//!   a yaw moment at level α names wind, none names current.
//!
//! Effects already in the model are skipped, so diagnosing an augmented model looks for the
//! next one.

pub mod augment;
pub mod compare;
pub mod resid;

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use thiserror::Error;
use yawcast_shared::model::EffectKind;

use crate::diagnose::augment::{AugmentConfig, AugmentReport};
use crate::diagnose::compare::{check_inputs, mean_fit, InputError};
use crate::identify::model::{Effect, Model};
use crate::identify::pem::{self, PemConfig};
use crate::identify::predict::{self, Horizon, Stepper};
use crate::io::data::Record;
use crate::stats::{chi2_sf, normal_sf, standard_normal as gauss};

/// Horizon (samples) of the prediction errors the slow effects are fitted on.
pub const SLOW_HORIZON: usize = 50;
/// Every `SLOW_STRIDE`-th sample's 50-step error is used (they overlap heavily anyway).
const SLOW_STRIDE: usize = 10;
/// Shortest record `diagnose` accepts (samples): a few slow-horizon windows.
pub const MIN_SAMPLES: usize = 4 * SLOW_HORIZON;

/// Settings of [`diagnose`].
#[derive(Debug, Clone)]
pub struct DiagnoseConfig {
    /// Seed of the parametric bootstrap (ChaCha8).
    pub seed: u64,
    /// Bootstrap replicates per effect for the null distributions.
    pub null_reps: usize,
    /// Significance level (default 0.01).
    pub alpha: f64,
    /// Refit the top candidate(s) with the effect ([`crate::diagnose::augment::augment`]) and judge
    /// materiality on held-out records.
    pub confirm: bool,
    /// Settings of the confirming refit.
    pub augment: AugmentConfig,
    /// Use rayon.
    pub parallel: bool,
    /// Show a progress bar on stderr (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for DiagnoseConfig {
    fn default() -> Self {
        DiagnoseConfig {
            seed: 1,
            null_reps: 24,
            alpha: 0.01,
            confirm: true,
            augment: AugmentConfig::default(),
            parallel: true,
            progress: false,
        }
    }
}

/// Samples of one record set (the trials, the reference records, the held-out records) that
/// [`diagnose`] works on at most. A longer set is read as blocks of [`WINDOW_BLOCK`] samples
/// spread evenly over each record ([`window`]); every statistic, replicate and refit then runs
/// on the blocks, so the time and memory a diagnosis takes stop growing with the records'
/// length. Each block is a record of its own (its own x̂(0)); the likelihood statistics and
/// their bootstrap nulls are measured on the same blocks, so the test keeps its level.
pub const WINDOW: usize = 12_000;
/// Length of the blocks of a set longer than [`WINDOW`] (samples).
pub const WINDOW_BLOCK: usize = 2_000;

/// The blocks `diagnose` reads of `recs` (see [`WINDOW`]), or `None` when the set holds at
/// most [`WINDOW`] samples and is used whole. Each record gets a share of the
/// `WINDOW / WINDOW_BLOCK` blocks in proportion to its length (at least one), as blocks of
/// `min(WINDOW_BLOCK, its length)` samples, the first at its start, the last at its end and
/// the others evenly between; block names are `name@first-sample`. `None` too when the
/// blocks would be the whole records (many records shorter than a block).
///
/// ```
/// use yawcast::{diagnose::{window, WINDOW_BLOCK}, io::data::Record};
/// let r = Record::from_uy("long", 1.0, vec![0.0; 100_000], vec![0.0; 100_000]);
/// let blocks = window(std::slice::from_ref(&r)).unwrap();
/// assert_eq!(blocks.len(), 6);
/// assert!(blocks.iter().all(|b| b.len() == WINDOW_BLOCK));
/// assert_eq!(blocks[1].name, "long@19600");
/// assert_eq!(blocks[5].t[WINDOW_BLOCK - 1], 99_999.0);
/// assert!(window(&[r.slice(0, 12_000)]).is_none());
/// // ten records of 1 800 samples: one block each would be each whole record
/// assert!(window(&vec![r.slice(0, 1_800); 10]).is_none());
/// ```
pub fn window(recs: &[Record]) -> Option<Vec<Record>> {
    let total: usize = recs.iter().map(Record::len).sum();
    if total <= WINDOW {
        return None;
    }
    let blocks = WINDOW / WINDOW_BLOCK;
    let mut out = Vec::new();
    for r in recs {
        let len = r.len();
        let l = WINDOW_BLOCK.min(len);
        let k = ((blocks * len + total / 2) / total).clamp(1, len / l.max(1));
        for j in 0..k {
            let st = if k == 1 { 0 } else { j * (len - l) / (k - 1) };
            let mut b = r.slice(st, st + l);
            b.name = format!("{}@{st}", r.name);
            out.push(b);
        }
    }
    // many short records: one whole record each is no window at all
    let kept: usize = out.iter().map(Record::len).sum();
    (kept < total).then_some(out)
}

/// Steps of the progress bar besides the bootstrap replicates and the refit: the
/// reference's own gear, the statistics on the records, the encompassing test and materiality.
const PROGRESS_STEPS: u64 = 3;

fn progress_bar(cfg: &DiagnoseConfig, reps: usize) -> indicatif::ProgressBar {
    if !cfg.progress {
        return indicatif::ProgressBar::hidden();
    }
    let len = PROGRESS_STEPS + reps as u64 + u64::from(cfg.confirm);
    let pb = indicatif::ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{prefix:>12} [{bar:30}] {pos}/{len} {elapsed_precise} {wide_msg:.dim}",
    ) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_prefix("diagnose");
    pb
}

/// One effect's evidence.
#[derive(Debug, Clone, Serialize)]
pub struct Ranked {
    /// Effect name ([`EffectKind::name`]).
    pub effect: String,
    /// Test statistic (likelihood statistic on the yaw channel, or the channel's χ² where that
    /// decides).
    pub statistic: f64,
    /// p-value against the calibrated null.
    pub p_value: f64,
    /// Likelihood gain above what noise alone gives: the statistic less its null mean (for
    /// a channel statistic, its χ² less its degrees of freedom). Effects are ranked by it:
    /// far-tail p-values rest on the shape fitted to the null replicates and are not
    /// comparable between effects.
    pub above_noise: f64,
    /// Held-out fit gain (percentage points, at the effect's horizon: 10 steps for actuator and
    /// hull effects, `sim` for slow ones) of the model with the effect added (θ frozen, the
    /// effect's gains fitted on the estimation part); 0 for effects that are not significant.
    pub fit_gain_pp: f64,
    /// p-value below α/m (m: the number of library effects, Bonferroni).
    pub significant: bool,
    /// Held-out improvement on refit, or measurable channel evidence.
    pub material: bool,
    /// The effect's estimated structural parameter in physical units, where it has one
    /// (dead time s, slew °/s, clip level °, gyro bias °/s, current m/s of speed over ground).
    pub parameter: Option<f64>,
    /// The evidence in words.
    pub evidence: String,
}

/// The outcome of [`diagnose`].
#[derive(Debug, Clone, Serialize)]
pub struct Diagnosis {
    /// The effect name, or `"none"`.
    pub verdict: String,
    /// Every library effect not already in the model, best first.
    pub ranking: Vec<Ranked>,
    /// The verdict in physical words, with numbers.
    pub explanation: String,
    /// Whether reference records were given.
    pub reference_used: bool,
    /// The confirming refit of the verdict's effect, when done.
    pub augment: Option<AugmentReport>,
    /// Held-out fit % of the model, keyed by horizon ("1","5","10","20","sim").
    pub before: BTreeMap<String, f64>,
    /// Held-out fit % of the model with the verdict's effect (same as `before` when `none`).
    pub after: BTreeMap<String, f64>,
    /// The reference model with the steering-gear dynamics the reference records show of
    /// their own (θ re-identified on them), when they show some: what the statistics were
    /// measured against, and the better start for augmenting.
    #[serde(skip)]
    pub reference_gear: Option<Model>,
}

impl Diagnosis {
    /// The verdict as an effect kind (`None` for `"none"`).
    ///
    /// ```
    /// use yawcast::diagnose::Diagnosis;
    /// use yawcast_shared::model::EffectKind;
    /// let d = Diagnosis {
    ///     verdict: "dead-time".into(), ranking: vec![], explanation: String::new(),
    ///     reference_used: true, augment: None, before: Default::default(), after: Default::default(),
    ///     reference_gear: None,
    /// };
    /// assert_eq!(d.verdict_kind(), Some(EffectKind::DeadTime));
    /// ```
    pub fn verdict_kind(&self) -> Option<EffectKind> {
        EffectKind::from_name(&self.verdict)
    }
}

/// Errors of [`diagnose`].
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// Bad model or records (names the record and channel).
    #[error(transparent)]
    Input(#[from] InputError),
    /// The trial and reference records disagree with each other.
    #[error("{0}")]
    Mismatch(String),
}

// ---------------------------------------------------------------------------------------
// prediction errors and their sensitivities

fn horizon_of(kind: EffectKind) -> usize {
    match kind {
        EffectKind::Bias | EffectKind::GyroBias | EffectKind::Wind | EffectKind::Current => {
            SLOW_HORIZON
        }
        EffectKind::DeadTime
        | EffectKind::RateLimit
        | EffectKind::Saturation
        | EffectKind::DeadBand
        | EffectKind::Asymmetry
        | EffectKind::NonlinearDamping => 1,
    }
}

/// Prediction errors `y − ŷ` at horizon `h` (all samples for h = 1; every
/// [`SLOW_STRIDE`]-th sample from `h` on otherwise). Open-loop steps use the measured heading.
fn errors(model: &Model, rec: &Record, x0: &[f64], h: usize) -> Vec<f64> {
    let s = Stepper::new(model);
    let psi = |t: usize| rec.psi.as_ref().map(|p| p[t]);
    let p0 = psi(0).unwrap_or(0.0);
    let mut st = s.initial(x0, p0);
    let n = rec.len();
    if h <= 1 {
        return (0..n)
            .map(|t| rec.y[t] - s.step(&mut st, rec.u[t], rec.y[t], psi(t)).yhat)
            .collect();
    }
    // the open-loop pass predicting sample t starts from the filter's state at t + 1 − h: it
    // runs as the filter passes there, so no state sequence is kept
    let mut out = Vec::with_capacity(n / SLOW_STRIDE + 1);
    let mut w = st.clone();
    let mut t = h;
    for start in 0..n {
        if t < n && start == t + 1 - h {
            w.clone_from(&st);
            for j in start..t {
                s.step(&mut w, rec.u[j], f64::NAN, psi(j));
            }
            out.push(rec.y[t] - s.output(&w));
            t += SLOW_STRIDE;
        }
        s.step(&mut st, rec.u[start], rec.y[start], psi(start));
    }
    out
}

/// Least-squares pieces of one candidate on a set of records: `e₀ᵀe₀`, `Sᵀe₀`, `SᵀS` with
/// `S` the sensitivities of ŷ to the effect's gains (so `SSE(β) = ‖e₀ − Sβ‖²`).
#[derive(Debug, Clone)]
struct Quad {
    ee: f64,
    se: DVector<f64>,
    ss: DMatrix<f64>,
    n: usize,
}

impl Quad {
    fn zero(p: usize) -> Quad {
        Quad {
            ee: 0.0,
            se: DVector::zeros(p),
            ss: DMatrix::zeros(p, p),
            n: 0,
        }
    }

    fn add(&mut self, o: &Quad) {
        self.ee += o.ee;
        self.se += &o.se;
        self.ss += &o.ss;
        self.n += o.n;
    }

    fn sse(&self, beta: &DVector<f64>) -> f64 {
        if beta.is_empty() {
            return self.ee;
        }
        (self.ee - 2.0 * beta.dot(&self.se) + beta.dot(&(&self.ss * beta))).max(1e-300)
    }

    fn best(&self) -> (DVector<f64>, f64) {
        let p = self.se.len();
        if p == 0 {
            return (DVector::zeros(0), self.ee.max(1e-300));
        }
        let mut a = self.ss.clone();
        let ridge = 1e-10 * (a.trace() / p as f64).max(1e-300);
        for i in 0..p {
            a[(i, i)] += ridge;
        }
        let beta = a
            .cholesky()
            .map(|c| c.solve(&self.se))
            .unwrap_or_else(|| DVector::zeros(p));
        let s = self.sse(&beta);
        (beta, s)
    }
}

/// Step of the finite-difference sensitivities (effects are affine in their gains apart from
/// the integrated heading, which is not used here).
const FD_STEP: f64 = 1e-3;

fn quad_of(model: &Model, cand: &Effect, rec: &Record, x0: &[f64], h: usize) -> Quad {
    quad_multi(model, std::slice::from_ref(cand), rec, x0, h)
}

/// [`quad_of`] for several effects added together, their gains fitted jointly (in the order
/// of `cands`, each effect's gains in [`Effect::gains`] order).
fn quad_multi(model: &Model, cands: &[Effect], rec: &Record, x0: &[f64], h: usize) -> Quad {
    let zero: Vec<Vec<f64>> = cands.iter().map(|c| vec![0.0; c.gains().len()]).collect();
    let with = |gains: &[Vec<f64>]| {
        let mut m = model.clone();
        for (c, g) in cands.iter().zip(gains) {
            let mut c = *c;
            if !g.is_empty() {
                c.set_gains(g);
            }
            m = m.with_effect(c);
        }
        m
    };
    let e0 = errors(&with(&zero), rec, x0, h);
    let p: usize = zero.iter().map(Vec::len).sum();
    let mut cols = Vec::with_capacity(p);
    for (k, g) in zero.iter().enumerate() {
        for j in 0..g.len() {
            let mut gains = zero.clone();
            gains[k][j] = FD_STEP;
            let ej = errors(&with(&gains), rec, x0, h);
            cols.push(
                e0.iter()
                    .zip(&ej)
                    .map(|(a, b)| (a - b) / FD_STEP)
                    .collect::<Vec<f64>>(),
            );
        }
    }
    let mut q = Quad::zero(p);
    q.n = e0.len();
    for (t, e) in e0.iter().enumerate() {
        if !e.is_finite() {
            q.ee = f64::INFINITY;
            continue;
        }
        q.ee += e * e;
        for i in 0..p {
            q.se[i] += cols[i][t] * e;
            for j in 0..=i {
                q.ss[(i, j)] += cols[i][t] * cols[j][t];
            }
        }
    }
    for i in 0..p {
        for j in 0..i {
            q.ss[(j, i)] = q.ss[(i, j)];
        }
    }
    q
}

/// The candidates (grid) of one effect kind, with zero gains.
fn grid(kind: EffectKind, ts: f64, u_max: f64, du_max: f64) -> Vec<Effect> {
    match kind {
        EffectKind::DeadTime => {
            let dmax = ((8.0 / ts).ceil() as usize).clamp(1, 20);
            (1..=dmax)
                .map(|d| Effect::DeadTime { samples: d })
                .collect()
        }
        EffectKind::RateLimit => {
            // slew rates that bind on the recorded commands: from 0.5 °/s to the largest
            // command step, geometric
            let hi = (du_max / ts).max(1.0);
            let lo = 0.5_f64.min(hi / 2.0);
            geometric(lo, hi * 0.9, 12)
                .into_iter()
                .map(|rate| Effect::RateLimit { rate })
                .collect()
        }
        EffectKind::Saturation => geometric(0.2 * u_max, 0.95 * u_max, 12)
            .into_iter()
            .map(|limit| Effect::Saturation { limit })
            .collect(),
        EffectKind::DeadBand => band_widths(u_max)
            .into_iter()
            .map(|width| Effect::DeadBand { width })
            .collect(),
        EffectKind::NonlinearDamping => vec![
            Effect::NonlinearDamping {
                beta: 0.0,
                cubic: false,
            },
            Effect::NonlinearDamping {
                beta: 0.0,
                cubic: true,
            },
        ],
        // one structure each, the gains to be fitted
        EffectKind::Bias
        | EffectKind::GyroBias
        | EffectKind::Asymmetry
        | EffectKind::Wind
        | EffectKind::Current => vec![Effect::zero(kind, 0.0)],
    }
}

/// The dead-band widths searched, by diagnose and by augment alike: 12 geometric steps from
/// 0.2° to 6° (worn steering gears show 0.5–3°), or to 40 % of the largest command when that
/// is smaller. A wider "band" on large-amplitude records (zig-zags) only trades the command's
/// amplitude against the model's gain, so it is not searched.
///
/// ```
/// let w = yawcast::diagnose::band_widths(20.0);
/// assert_eq!(w.len(), 12);
/// assert!((w[0] - 0.2).abs() < 1e-12 && (w[11] - 6.0).abs() < 1e-9);
/// assert!((yawcast::diagnose::band_widths(5.0)[11] - 2.0).abs() < 1e-9);
/// ```
pub fn band_widths(u_max: f64) -> Vec<f64> {
    geometric(0.2, 6.0_f64.min(0.4 * u_max), 12)
}

fn geometric(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo) {
        return vec![hi.max(1e-6)];
    }
    let r = (hi / lo).powf(1.0 / (n - 1) as f64);
    (0..n).map(|i| lo * r.powi(i as i32)).collect()
}

/// A set of records with the base model's x̂(0) per record.
struct Set<'a> {
    recs: Vec<&'a Record>,
    x0: Vec<Vec<f64>>,
}

impl<'a> Set<'a> {
    fn new(model: &Model, recs: &'a [Record]) -> Set<'a> {
        Set {
            recs: recs.iter().collect(),
            x0: recs
                .iter()
                .map(|r| predict::estimate_x0(model, r))
                .collect(),
        }
    }

    fn from_owned(model: &Model, recs: &'a [Record]) -> Set<'a> {
        Set::new(model, recs)
    }

    /// Quads of every candidate, summed over records.
    fn family(&self, model: &Model, cands: &[Effect], h: usize, parallel: bool) -> Vec<Quad> {
        let one = |c: &Effect| {
            let mut q = Quad::zero(c.gains().len());
            for (r, x0) in self.recs.iter().zip(&self.x0) {
                q.add(&quad_of(model, c, r, x0, h));
            }
            q
        };
        crate::par::map(cands, parallel, one)
    }

    /// Quads of every pair of candidates (both added, their gains fitted jointly), summed
    /// over records.
    fn pairs(
        &self,
        model: &Model,
        pairs: &[(Effect, Effect)],
        h: usize,
        parallel: bool,
    ) -> Vec<Quad> {
        let one = |(a, b): &(Effect, Effect)| {
            let mut q = Quad::zero(a.gains().len() + b.gains().len());
            for (r, x0) in self.recs.iter().zip(&self.x0) {
                q.add(&quad_multi(model, &[*a, *b], r, x0, h));
            }
            q
        };
        crate::par::map(pairs, parallel, one)
    }

    /// SSE of the base model at horizon h.
    fn sse0(&self, model: &Model, h: usize) -> (f64, usize) {
        let mut s = 0.0;
        let mut n = 0;
        for (r, x0) in self.recs.iter().zip(&self.x0) {
            let e = errors(model, r, x0, h);
            s += e.iter().map(|v| v * v).sum::<f64>();
            n += e.len();
        }
        (s, n)
    }
}

/// The version of an effect a record set shows: `None` (the base model) or a candidate index
/// with its gains.
#[derive(Debug, Clone)]
struct Version {
    idx: Option<usize>,
    beta: DVector<f64>,
}

/// Best candidate of a family: (index, gains, SSE).
fn best_of(quads: &[Quad]) -> (usize, DVector<f64>, f64) {
    let mut best = (0, DVector::zeros(0), f64::INFINITY);
    for (i, q) in quads.iter().enumerate() {
        let (b, s) = q.best();
        if s < best.2 {
            best = (i, b, s);
        }
    }
    best
}

/// The version a set shows: the best candidate when it beats the base model.
fn version_of(quads: &[Quad], sse0: f64) -> Version {
    let (i, b, s) = best_of(quads);
    if s < sse0 {
        Version {
            idx: Some(i),
            beta: b,
        }
    } else {
        Version {
            idx: None,
            beta: DVector::zeros(0),
        }
    }
}

fn sse_at(quads: &[Quad], sse0: f64, v: &Version) -> f64 {
    match v.idx {
        None => sse0,
        Some(i) => quads[i].sse(&v.beta),
    }
}

/// `D = N·ln(SSE(reference version)/SSE(best))` on a trial set, with the best candidate.
fn trial_statistic(
    quads: &[Quad],
    sse0: f64,
    n: usize,
    reference: &Version,
) -> (f64, usize, DVector<f64>) {
    let base = sse_at(quads, sse0, reference);
    let (i, b, s) = best_of(quads);
    let s = s.min(base);
    let d = n as f64 * (base / s).ln();
    (d.max(0.0), i, b)
}

/// The candidate with its gains set.
fn effect_with(cand: &Effect, beta: &DVector<f64>) -> Effect {
    let mut e = *cand;
    if !beta.is_empty() {
        e.set_gains(beta.as_slice());
    }
    e
}

// ---------------------------------------------------------------------------------------
// parametric bootstrap

/// Simulates the innovations model on the commands of `like` with innovation std `sigma`
/// (heading integrated from the simulated rate, from the record's first heading).
fn simulate_innovations(model: &Model, like: &Record, sigma: f64, rng: &mut ChaCha8Rng) -> Record {
    let s = Stepper::new(model);
    let p0 = like.psi.as_ref().map(|p| p[0]).unwrap_or(0.0);
    let mut st = s.initial(&[], p0);
    let n = like.len();
    let mut y = Vec::with_capacity(n);
    let mut psi = Vec::with_capacity(n);
    let mut p = p0;
    for t in 0..n {
        let yt = s.output(&st) + sigma * gauss(rng);
        psi.push(p);
        s.step(&mut st, like.u[t], yt, Some(p));
        p += model.ts * (yt - s.d_y());
        y.push(yt);
    }
    let mut r = Record::from_uy(&like.name, like.ts, like.u.clone(), y);
    r.psi = Some(psi);
    r
}

/// A scaled χ² `c·χ²_ν` fitted to replicates by their mean and variance (Satterthwaite).
#[derive(Debug, Clone, Copy)]
struct Null {
    c: f64,
    nu: f64,
}

impl Null {
    fn fit(reps: &[f64]) -> Null {
        let n = reps.len().max(1) as f64;
        let mean = reps.iter().sum::<f64>() / n;
        let var = reps.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let mean = mean.max(1e-9);
        let var = var.max(1e-12 * mean * mean);
        Null {
            c: var / (2.0 * mean),
            nu: (2.0 * mean * mean / var).max(0.05),
        }
    }

    fn p(&self, d: f64) -> f64 {
        chi2_sf(d / self.c, self.nu).clamp(0.0, 1.0)
    }

    /// Likelihood gain above what noise alone gives (`D` minus the null's mean): comparable
    /// across effects judged on the same errors, where far-tail p-values are not.
    fn excess(&self, d: f64) -> f64 {
        d - self.c * self.nu
    }
}

// ---------------------------------------------------------------------------------------
// channel statistics

pub use crate::io::data::{heading_bias, HeadingBias};

/// Coefficients of (sin ψ, cos ψ, sin 2ψ, cos 2ψ) in speed over ground; nuisance: one
/// intercept per record and r² and δ² low-passed through each time constant of
/// [`sog_taus`] (speed lost in turns and to rudder/pod drag, whatever the ship's surge time
/// constant). `shift[i]` circularly shifts record i's heading against its speed (0: aligned).
fn sog_harmonics(recs: &[Record], shift: &[usize], taus: &[f64]) -> Option<DVector<f64>> {
    let nr = recs.len();
    let nt = taus.len();
    let p = nr + 4 + 2 * nt;
    let mut xtx = DMatrix::<f64>::zeros(p, p);
    let mut xty = DVector::<f64>::zeros(p);
    let mut x = DVector::<f64>::zeros(p);
    for (i, r) in recs.iter().enumerate() {
        let psi = r.psi.as_ref()?;
        let sp = r.speed.as_ref()?;
        let a: Vec<f64> = taus.iter().map(|tau| (r.ts / tau).min(1.0)).collect();
        let mut lr = vec![0.0; nt];
        let mut lu = vec![0.0; nt];
        let n = r.len();
        let sh = shift.get(i).copied().unwrap_or(0) % n.max(1);
        for t in 0..n {
            let ph = psi[(t + sh) % n].to_radians();
            let h = [ph.sin(), ph.cos(), (2.0 * ph).sin(), (2.0 * ph).cos()];
            x.fill(0.0);
            x[i] = 1.0;
            for (j, hj) in h.iter().enumerate() {
                x[nr + j] = *hj;
            }
            for k in 0..nt {
                lr[k] += a[k] * (r.y[t] * r.y[t] - lr[k]);
                lu[k] += a[k] * (r.u[t] * r.u[t] - lu[k]);
                x[nr + 4 + 2 * k] = lr[k];
                x[nr + 5 + 2 * k] = lu[k];
            }
            xtx.ger(1.0, &x, &x, 1.0);
            xty.axpy(sp[t], &x, 1.0);
        }
    }
    // the filter bank's columns are strongly correlated: a relative ridge keeps the solve
    // well posed without moving the (orthogonal) heading harmonics
    let ridge = 1e-9 * (xtx.trace() / p as f64).max(1e-300);
    for j in 0..p {
        xtx[(j, j)] += ridge;
    }
    let beta = xtx.cholesky()?.solve(&xty);
    Some(beta.rows(nr, 4).into_owned())
}

/// Time constants (s) of the low-pass nuisance regressors of speed over ground: a surge
/// equation `(m − X_u̇) u̇ = X(u) + X_rr r² + X_δδ δ² + …` makes the speed lost in turns a
/// first-order lag of r² and δ² with the surge time constant `T_u = (m − X_u̇)/(−∂X/∂u)`,
/// which is not known here and spans ≈ 10 s on a model ship to minutes on a large one. A
/// first-order lag anywhere in 10–270 s is matched closely by a combination of its two
/// neighbours in this bank (ratio 3); with one fixed time constant the unmatched part of the
/// speed loss follows the turning history, and with it the heading, and passes for a
/// current. Time constants longer than a quarter of the shortest record are dropped (the
/// per-record intercept already takes what they would).
fn sog_taus<'a>(recs: impl Iterator<Item = &'a Record>) -> Vec<f64> {
    let shortest = recs
        .map(|r| r.len() as f64 * r.ts)
        .fold(f64::INFINITY, f64::min);
    let mut out: Vec<f64> = SOG_TAUS_S
        .iter()
        .copied()
        .filter(|tau| *tau <= 0.25 * shortest)
        .collect();
    if out.is_empty() {
        out.push(SOG_TAUS_S[0]);
    }
    out
}

/// The bank of surge time constants (s) of [`sog_taus`].
const SOG_TAUS_S: [f64; 4] = [10.0, 30.0, 90.0, 270.0];
/// Circular shifts drawn for the null covariance of the speed harmonics.
const SOG_SHIFTS: usize = 60;

/// Covariance of the harmonics under "no heading dependence": heading circularly shifted
/// against speed by random amounts (10–90 % of each record), which keeps both series'
/// own structure.
fn sog_null_cov(recs: &[Record], taus: &[f64], rng: &mut ChaCha8Rng) -> Option<DMatrix<f64>> {
    let mut draws = Vec::with_capacity(SOG_SHIFTS);
    for _ in 0..SOG_SHIFTS {
        let sh: Vec<usize> = recs
            .iter()
            .map(|r| {
                let n = r.len();
                rng.random_range(n / 10..=(9 * n / 10).max(n / 10 + 1))
            })
            .collect();
        draws.push(sog_harmonics(recs, &sh, taus)?);
    }
    let m = draws.len() as f64;
    let mean = draws.iter().fold(DVector::zeros(4), |a, b| a + b) / m;
    let mut cov = DMatrix::<f64>::zeros(4, 4);
    for d in &draws {
        let c = d - &mean;
        cov += &c * c.transpose();
    }
    Some(cov / (m - 1.0))
}

/// Wald χ² of `d` (subset `idx`) with covariance `v`.
fn wald(d: &DVector<f64>, v: &DMatrix<f64>, idx: &[usize]) -> f64 {
    let k = idx.len();
    let dd = DVector::from_iterator(k, idx.iter().map(|&i| d[i]));
    let vv = DMatrix::from_fn(k, k, |a, b| v[(idx[a], idx[b])]);
    match vv.try_inverse() {
        Some(inv) => dd.dot(&(inv * &dd)).max(0.0),
        None => 0.0,
    }
}

/// SOG evidence: (χ² first harmonic, χ² second harmonic, first-harmonic amplitude m/s,
/// direction deg the speed gain points to).
#[derive(Debug, Clone, Copy)]
struct SogEvidence {
    chi1: f64,
    chi2: f64,
    amp1: f64,
    dir1: f64,
    amp2: f64,
}

fn sog_evidence(trial: &[Record], reference: &[Record], seed: u64) -> Option<SogEvidence> {
    sog_evidence_with(
        trial,
        reference,
        seed,
        &sog_taus(trial.iter().chain(reference)),
    )
}

/// [`sog_evidence`] with the nuisance time constants given.
fn sog_evidence_with(
    trial: &[Record],
    reference: &[Record],
    seed: u64,
    taus: &[f64],
) -> Option<SogEvidence> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5047_5f53_4f47);
    let t = sog_harmonics(trial, &[], taus)?;
    let vt = sog_null_cov(trial, taus, &mut rng)?;
    let (d, v) = if reference.is_empty() {
        (t, vt)
    } else {
        let r = sog_harmonics(reference, &[], taus)?;
        let vr = sog_null_cov(reference, taus, &mut rng)?;
        (t - r, vt + vr)
    };
    Some(SogEvidence {
        chi1: wald(&d, &v, &[0, 1]),
        chi2: wald(&d, &v, &[2, 3]),
        amp1: d[0].hypot(d[1]),
        dir1: d[0].atan2(d[1]).to_degrees().rem_euclid(360.0),
        amp2: d[2].hypot(d[3]),
    })
}

/// Number of effects tested (Bonferroni: each is judged at α / m).
fn cfg_m(_cfg: &DiagnoseConfig) -> f64 {
    EffectKind::ALL.len() as f64
}

// ---------------------------------------------------------------------------------------
// the diagnosis

/// Everything computed for one effect kind.
#[derive(Debug, Clone)]
struct Evidence {
    kind: EffectKind,
    h: usize,
    null: Null,
    best: Effect,
    p: f64,
    /// p-value of the yaw channel alone (before any other channel is combined in).
    p_yaw: f64,
    score: f64,
    statistic: f64,
    words: String,
    parameter: Option<f64>,
    channel_material: bool,
    /// The version of the effect the reference shows (θ frozen), if any.
    reference: Option<Effect>,
    /// Current or wind shown by speed over ground while the yaw channel shows no
    /// heading-dependent moment ([`current_or_wind`]).
    speed_only: bool,
}

/// Diagnoses which library effect `model` is missing on the trial records `est`.
///
/// `reference` holds the records the model was identified from (may be empty: the verdict is
/// then weaker, and the explanation says so); `val` holds held-out trial records for the
/// materiality check (empty: the last 30 % of each trial record are held out).
///
/// # Errors
/// [`DiagnoseError::Input`] for an invalid model, no trial records, records whose sample time
/// differs from the model's, ragged or non-finite channels, or records shorter than
/// [`MIN_SAMPLES`]; [`DiagnoseError::Mismatch`] when the records lack a channel some of the
/// others have in a way that makes the comparison meaningless.
///
/// ```
/// use yawcast::{io::data::Record, diagnose::{diagnose, DiagnoseConfig}, identify::model::Model};
/// let m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
/// let e = diagnose(&m, &[], &[], &[], &DiagnoseConfig::default()).unwrap_err();
/// assert_eq!(e.to_string(), "no trial records given");
/// ```
pub fn diagnose(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    val: &[Record],
    cfg: &DiagnoseConfig,
) -> Result<Diagnosis, DiagnoseError> {
    check_inputs(model, est, MIN_SAMPLES, "trial")?;
    if !reference.is_empty() {
        check_inputs(model, reference, MIN_SAMPLES, "reference")?;
    }
    if !val.is_empty() {
        check_inputs(model, val, 4 * model.n + 4, "validation")?;
    }
    if !(cfg.alpha > 0.0 && cfg.alpha < 1.0) {
        return Err(InputError::Config(format!("alpha {} is not in (0, 1)", cfg.alpha)).into());
    }
    let reps = cfg.null_reps.max(8);
    // long sets are diagnosed on blocks spread over them (see `WINDOW`)
    let windows = [window(est), window(reference), window(val)];
    let windowed = windows.iter().any(Option::is_some);
    let [est, reference, val] = [
        (est, &windows[0]),
        (reference, &windows[1]),
        (val, &windows[2]),
    ]
    .map(|(full, w)| w.as_deref().unwrap_or(full));
    let bar = progress_bar(cfg, reps);
    let has_ref = !reference.is_empty();
    // The reference's own actuator physics (module docs): the statistics are measured against
    // the reference model that carries it, `base`; `model` is what the user gave.
    bar.set_message("the reference's own steering gear");
    let gear = if has_ref {
        reference_actuator(model, reference, cfg)
    } else {
        None
    };
    bar.inc(1);
    bar.set_message("statistics on the records");
    let base = gear.as_ref().map_or(model, |g| &g.model);
    let trial = Set::new(model, est);
    let refset = Set::from_owned(model, reference);
    let all = est.iter().chain(reference);
    let u_max = all
        .clone()
        .flat_map(|r| r.u.iter())
        .fold(0.0_f64, |a, b| a.max(b.abs()));
    let du_max = all
        .flat_map(|r| r.u.windows(2).map(|w| (w[1] - w[0]).abs()))
        .fold(0.0_f64, f64::max);
    // innovation std under the null: the model's one-step errors on the reference (or trial)
    let sig_set = if has_ref { &refset } else { &trial };
    let (s1, n1) = sig_set.sse0(model, 1);
    let sigma = (s1 / n1.max(1) as f64).sqrt();
    // Is the model fitted to the trials rather than the reference? Then it has absorbed what
    // the trials show — a slew or angle limit above all — and the statistics against the
    // reference lose their power. Said when the model is significantly worse on the reference
    // than the same structure re-identified there (likelihood ratio; ≈ 0 for the reference's
    // own model) *and* predicts the trials better than that re-identified model does. On
    // blocks of a longer reference (`WINDOW`) the model was identified on more than the
    // blocks, whose own optimum beats it by their sampling spread alone: there the excess
    // must also reach 1 % of the one-step error.
    let min_pct = if windows[1].is_some() { 1.0 } else { 0.0 };
    let foreign_pct = if has_ref {
        let pc = PemConfig {
            order: model.n,
            max_iter: 50,
            parallel: false,
            ..PemConfig::default()
        };
        pem::identify_from(reference, model, &pc)
            .ok()
            .and_then(|r| {
                let v = s1 / n1.max(1) as f64;
                let lr = n1 as f64 * (v / r.cost).ln();
                let p = r.names.len() as f64;
                let (t_given, _) = trial.sse0(model, 1);
                let (t_ref, _) = Set::new(&r.model, est).sse0(&r.model, 1);
                let pct = 100.0 * (v / r.cost - 1.0);
                (lr.is_finite() && chi2_sf(lr, p) < cfg.alpha && t_given < t_ref && pct >= min_pct)
                    .then_some(pct)
            })
    } else {
        None
    };
    let (trial, refset) = if gear.is_some() {
        (Set::new(base, est), Set::new(base, reference))
    } else {
        (trial, refset)
    };
    let sigma = if gear.is_some() {
        let (s, n) = refset.sse0(base, 1);
        (s / n.max(1) as f64).sqrt()
    } else {
        sigma
    };

    let kinds: Vec<EffectKind> = EffectKind::ALL
        .iter()
        .copied()
        .filter(|k| model.effect(*k).is_none())
        .filter(|k| !(*k == EffectKind::Saturation && u_max <= 0.0))
        .collect();

    let heading_ok = est.iter().all(|r| r.psi.is_some())
        && (!has_ref || reference.iter().all(|r| r.psi.is_some()));
    let speed_ok = heading_ok
        && est.iter().all(|r| r.speed.is_some())
        && (!has_ref || reference.iter().all(|r| r.speed.is_some()));
    let hb = if heading_ok {
        let t = heading_bias(est);
        let r = if has_ref {
            heading_bias(reference)
        } else {
            None
        };
        t.map(|t| match r {
            Some(r) => (t.bias - r.bias, t.se.hypot(r.se)),
            None => (t.bias, t.se),
        })
    } else {
        None
    };
    let sog = if speed_ok {
        sog_evidence(est, if has_ref { reference } else { &[] }, cfg.seed)
    } else {
        None
    };

    let grids: Vec<(EffectKind, Vec<Effect>)> = kinds
        .iter()
        .map(|&k| (k, grid(k, model.ts, u_max, du_max)))
        .collect();
    let real = world(base, reference, est, &grids, cfg.parallel);
    bar.inc(1);
    bar.set_message("bootstrap replicates");
    let nulls = bootstrap(
        base,
        reference,
        est,
        &grids,
        sigma,
        reps,
        &bar,
        cfg.seed,
        cfg.parallel,
    );
    bar.set_message("encompassing test, materiality");
    let evidence: Vec<Evidence> = kinds
        .iter()
        .enumerate()
        .map(|(i, &kind)| {
            let mut e = effect_evidence(base, kind, &real[i], &nulls[i], has_ref, cfg, hb, sog);
            if let Some(own) = base.effect(kind).filter(|_| gear.is_some()) {
                e.words.push_str(&format!(
                    " (the reference's own: {})",
                    crate::diagnose::augment::describe(own, model.ts)
                ));
            }
            e
        })
        .collect();
    let mut ev = evidence;
    let level = cfg.alpha / cfg_m(cfg);
    ev.sort_by(|a, b| {
        let key = |e: &Evidence| ((e.p < level) as u8, e.channel_material as u8);
        key(b).cmp(&key(a)).then(
            b.score
                .partial_cmp(&a.score)
                .unwrap_or(std::cmp::Ordering::Equal),
        )
    });
    current_or_wind(&mut ev, level, cfg.alpha, sog.is_some());
    encompass(
        base,
        &trial,
        &mut ev,
        &grids,
        level,
        cfg.alpha,
        cfg.parallel,
        sog.is_some(),
    );

    // materiality: the effect's own held-out contribution (θ frozen, the effect's gains
    // refitted on the estimation part), best first; the verdict's effect is then refitted
    // with the model (augment) for the before/after fits
    let (est_part, held_out): (Vec<Record>, Vec<Record>) = if val.is_empty() {
        split(est)
    } else {
        (est.to_vec(), val.to_vec())
    };
    let before = mean_fit(model, &held_out, &Horizon::REPORT);
    let base_before = if gear.is_some() {
        mean_fit(base, &held_out, &Horizon::REPORT)
    } else {
        before.clone()
    };
    let est_set = Set::new(base, &est_part);
    let mut gains: Vec<Option<(f64, BTreeMap<String, f64>)>> = ev
        .iter()
        .map(|e| {
            (e.p < level)
                .then(|| frozen_gain(base, e, &est_set, &held_out, &base_before, cfg.parallel))
        })
        .collect();
    yaw_before_speed(&mut ev, &mut gains);
    bar.inc(1);
    bar.set_message("refit with the verdict's effect");
    let mut ranking = Vec::new();
    let mut verdict: Option<(usize, BTreeMap<String, f64>)> = None;
    for (i, (e, g)) in ev.iter().zip(&gains).enumerate() {
        let significant = e.p < level;
        let fit_gain = g.as_ref().map_or(0.0, |g| g.0);
        let material = significant && (e.channel_material || fit_gain > 0.0);
        if material && verdict.is_none() {
            verdict = g.as_ref().map(|g| (i, g.1.clone()));
        }
        ranking.push(Ranked {
            effect: e.kind.name().into(),
            statistic: e.statistic,
            p_value: e.p,
            above_noise: e.score,
            fit_gain_pp: fit_gain,
            significant,
            material,
            parameter: e.parameter,
            evidence: e.words.clone(),
        });
    }
    let verdict = verdict.map(|(i, frozen_fits)| {
        let report = if cfg.confirm {
            crate::diagnose::augment::augment(model, ev[i].kind, &est_part, &held_out, &cfg.augment)
                .ok()
        } else {
            None
        };
        let after = match &report {
            Some(r) => mean_fit(&r.candidate, &held_out, &Horizon::REPORT),
            None => frozen_fits,
        };
        (i, after, report)
    });
    bar.finish_and_clear();
    let (verdict_name, explanation, after, augment) = match verdict {
        Some((i, after, aug)) => {
            let e = &ev[i];
            let r = &ranking[i];
            let mut s = format!(
                "The trials show {} that the {} lacks: {} (p {}, held-out fit gain {:+.1} pp).",
                effect_phrase(e.kind),
                if has_ref { "reference" } else { "model" },
                e.words,
                fmt_p(r.p_value),
                r.fit_gain_pp
            );
            if let Some((_, second)) = ranking
                .iter()
                .enumerate()
                .find(|(j, x)| *j != i && x.significant)
            {
                s.push_str(&format!(
                    " Runner-up: {} (p {}, likelihood gain above noise {:.0} against {:.0}, \
                     held-out fit gain {:+.1} pp).",
                    second.effect,
                    fmt_p(second.p_value),
                    second.above_noise,
                    r.above_noise,
                    second.fit_gain_pp
                ));
                if second.p_value < r.p_value {
                    s.push_str(
                        " Effects are ranked by their likelihood gain above noise (the \
                         statistic less its null mean), not by p: p-values this far in the \
                         tail rest on the shape fitted to the null replicates and cannot be \
                         compared between effects.",
                    );
                }
            }
            if let Some(a) = &aug {
                s.push_str(&format!(" Refitted with the model: {}", a.explanation));
            }
            (e.kind.name().to_string(), s, after, aug)
        }
        None => {
            let sig: Vec<&Ranked> = ranking.iter().filter(|r| r.significant).collect();
            let s = if sig.is_empty() {
                format!(
                    "No effect of the library is significant at α = {} against its null \
                     distribution: the trials show nothing the {} lacks.",
                    cfg.alpha,
                    if has_ref { "reference" } else { "model" }
                )
            } else {
                format!(
                    "{} significant but not material: refitted, {} not improve held-out \
                     prediction, so the model is kept without it.",
                    sig.iter()
                        .map(|r| r.effect.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    if sig.len() == 1 { "it does" } else { "they do" }
                )
            };
            ("none".to_string(), s, before.clone(), None)
        }
    };
    let mut explanation = explanation;
    if let Some(g) = &gear {
        explanation.push_str(&g.words);
    }
    if windowed {
        let count = |w: &Option<Vec<Record>>| w.as_ref().map_or(0, Vec::len);
        explanation.push_str(&format!(
            " Records of more than {WINDOW} samples per set are diagnosed on blocks of up to \
             {WINDOW_BLOCK} samples spread evenly over them ({} of the trials, {} of the \
             reference, {} of the held-out records; 0: used whole).",
            count(&windows[0]),
            count(&windows[1]),
            count(&windows[2]),
        ));
    }
    if !has_ref {
        explanation.push_str(
            " No reference records were given, so every statistic is judged against the \
             model alone: hull nonlinearity the model never had shows up as an effect, and the \
             verdict is weaker.",
        );
    }
    if let Some(pct) = foreign_pct {
        explanation.push_str(&format!(
            " The model does not look identified from the reference records: its one-step \
             error there is {pct:.0} % above that of the same structure re-identified on them, \
             and it predicts the trials better than that model does. A model identified or \
             tuned on the trials has absorbed part of what they show (an actuator limit above \
             all), so the evidence is weaker; the strongest test uses the model identified on \
             the reference records."
        ));
    }
    if !heading_ok {
        explanation.push_str(
            " Heading is not logged in every record: a gyro bias cannot be told apart from a \
             constant yaw moment (bias), and wind and current are tested on the heading \
             integrated from the measured yaw rate, from an unknown start (0°) and drifting \
             with any rate offset.",
        );
    }
    if !speed_ok {
        explanation.push_str(
            " Speed over ground (or heading) is not logged in every record: current and wind \
             are judged from the yaw rate alone and are hard to tell apart from a bias.",
        );
    }
    Ok(Diagnosis {
        verdict: verdict_name,
        ranking,
        explanation,
        reference_used: has_ref,
        augment,
        before,
        after,
        reference_gear: gear.map(|g| g.model),
    })
}

/// The actuator effects that are gear *dynamics*: a slow or delayed gear changes when the
/// rudder/pod angle arrives, which a linear model absorbs into its poles (a lag), so with θ
/// frozen the reference shows neither. An angle limit is static: θ cannot absorb it (it
/// changes the gain at large angles, not the dynamics), so the frozen reference version
/// already holds it — and on a hull whose turning rate grows less than linearly with the
/// rudder angle a re-identified angle limit would stand for that hull physics instead.
const GEAR_DYNAMICS: [EffectKind; 2] = [EffectKind::DeadTime, EffectKind::RateLimit];

/// The actuator physics the reference records show of their own: the reference model with
/// it, θ re-identified on the reference, and the explanation's sentence.
#[derive(Debug, Clone)]
struct RefActuator {
    model: Model,
    words: String,
}

/// The reference's own steering-gear physics (module docs): forward selection over the
/// actuator effects the model lacks, on the reference records, by [`crate::diagnose::augment`]'s rule
/// (re-identified, kept only when the held-out part of the reference pays for it or the
/// reference supports it decisively). `None` when it keeps none.
fn reference_actuator(
    model: &Model,
    reference: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<RefActuator> {
    let kinds: Vec<EffectKind> = EffectKind::ALL
        .iter()
        .copied()
        .filter(|k| GEAR_DYNAMICS.contains(k) && model.effect(*k).is_none())
        .collect();
    if kinds.is_empty() {
        return None;
    }
    let f = crate::diagnose::augment::forward(model, reference, &[], &kinds, &cfg.augment).ok()?;
    if f.added.is_empty() || !f.model.is_stable() {
        return None;
    }
    let own: Vec<String> = f
        .added
        .iter()
        .filter_map(|k| f.model.effect(*k))
        .map(|e| crate::diagnose::augment::describe(e, model.ts))
        .collect();
    let words = format!(
        " The reference records show steering-gear physics of their own that the linear \
         model has absorbed into its poles: {} (re-identified on the reference, held-out \
         10-step fit there {:.1} → {:.1} %). A gear the model only approximates looks like \
         whatever actuator effect mimics it best on each record's commands, so every \
         statistic is measured against the reference model with it.",
        own.join(" and "),
        f.before.get("10").copied().unwrap_or(f64::NAN),
        f.after.get("10").copied().unwrap_or(f64::NAN),
    );
    Some(RefActuator {
        model: f.model,
        words,
    })
}

/// Hold-out split: the last 30 % of each record (kept long enough for the slow horizon).
fn split(est: &[Record]) -> (Vec<Record>, Vec<Record>) {
    let mut a = Vec::new();
    let mut b = Vec::new();
    for r in est {
        let n = r.len();
        let cut = (n * 7 / 10).max(n.saturating_sub(n / 3));
        a.push(r.slice(0, cut));
        b.push(r.slice(cut, n));
    }
    (a, b)
}

/// `= 3.1e-5`, or `< 1e-16` where the number is below what the tail computation resolves.
fn fmt_p(p: f64) -> String {
    if p < 1e-16 {
        "< 1e-16".into()
    } else {
        format!("= {p:.1e}")
    }
}

/// The effect in a few words ("a command dead time"), as the verdict, the demo and its report
/// name it.
///
/// ```
/// use yawcast_shared::model::EffectKind;
/// assert_eq!(yawcast::diagnose::effect_phrase(EffectKind::DeadBand), "a steering-gear dead band");
/// ```
pub fn effect_phrase(kind: EffectKind) -> &'static str {
    match kind {
        EffectKind::Bias => "a constant yaw moment",
        EffectKind::GyroBias => "a rate-gyro offset",
        EffectKind::DeadTime => "a command dead time",
        EffectKind::RateLimit => "a rudder/pod slew-rate limit",
        EffectKind::Saturation => "a rudder/pod angle limit",
        EffectKind::Asymmetry => "a port/starboard steering asymmetry",
        EffectKind::NonlinearDamping => "extra nonlinear yaw damping",
        EffectKind::Wind => "a heading-dependent wind moment",
        EffectKind::Current => "a current",
        EffectKind::DeadBand => "a steering-gear dead band",
    }
}

/// What one "world" (a model, its reference records, trial records) shows for one effect.
#[derive(Debug, Clone)]
struct WorldStat {
    d: f64,
    best: Effect,
    n: usize,
    /// The version of the effect the reference shows (its best candidate with its gains, when
    /// it beats the model there).
    reference: Option<Effect>,
}

/// The statistic `D` of every kind in one world: the reference version of each effect is
/// fitted on `reference` (none when empty), `D` measured on `trial`.
fn world(
    model: &Model,
    reference: &[Record],
    trial: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    parallel: bool,
) -> Vec<WorldStat> {
    let tset = Set::new(model, trial);
    let rset = Set::new(model, reference);
    let one = |(kind, cands): &(EffectKind, Vec<Effect>)| {
        let h = horizon_of(*kind);
        let (t0, tn) = tset.sse0(model, h);
        let tq = tset.family(model, cands, h, false);
        let version = if reference.is_empty() {
            Version {
                idx: None,
                beta: DVector::zeros(0),
            }
        } else {
            let (r0, _) = rset.sse0(model, h);
            let rq = rset.family(model, cands, h, false);
            version_of(&rq, r0)
        };
        let (d, bi, bb) = trial_statistic(&tq, t0, tn, &version);
        WorldStat {
            d,
            best: effect_with(&cands[bi], &bb),
            n: tn,
            reference: version.idx.map(|i| effect_with(&cands[i], &version.beta)),
        }
    };
    crate::par::map(grids, parallel, one)
}

/// Null replicates of `D` for every kind: parametric bootstrap of the whole procedure. The
/// innovations model is simulated with its innovation std on the recorded inputs of the
/// reference and trial records, the model is re-identified on the simulated reference (on the
/// simulated trials when there is no reference), and `D` is recomputed.
#[allow(clippy::too_many_arguments)]
fn bootstrap(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    sigma: f64,
    reps: usize,
    bar: &indicatif::ProgressBar,
    seed: u64,
    parallel: bool,
) -> Vec<Vec<f64>> {
    let one = |r: usize| -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                .wrapping_add(r as u64),
        );
        let rs: Vec<Record> = reference
            .iter()
            .map(|rec| simulate_innovations(model, rec, sigma, &mut rng))
            .collect();
        let ts: Vec<Record> = est
            .iter()
            .map(|rec| simulate_innovations(model, rec, sigma, &mut rng))
            .collect();
        let pc = PemConfig {
            order: model.n,
            max_iter: 30,
            parallel: false,
            ..PemConfig::default()
        };
        let fit_on = if rs.is_empty() { &ts } else { &rs };
        let m = pem::identify_from(fit_on, model, &pc)
            .map(|r| r.model)
            .unwrap_or_else(|_| model.clone());
        let d = world(&m, &rs, &ts, grids, false)
            .into_iter()
            .map(|w| w.d)
            .collect();
        bar.inc(1);
        d
    };
    let per: Vec<Vec<f64>> = crate::par::map_range(reps, parallel, one);
    (0..grids.len())
        .map(|k| per.iter().map(|v| v[k]).collect())
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn effect_evidence(
    model: &Model,
    kind: EffectKind,
    stat: &WorldStat,
    null_reps: &[f64],
    has_ref: bool,
    cfg: &DiagnoseConfig,
    hb: Option<(f64, f64)>,
    sog: Option<SogEvidence>,
) -> Evidence {
    let ts = model.ts;
    let h = horizon_of(kind);
    let d = stat.d;
    let tn = stat.n;
    let best = stat.best;
    let null = Null::fit(null_reps);
    let p_yaw = null.p(d);
    let mut ev = Evidence {
        kind,
        h,
        null,
        best,
        p: p_yaw,
        p_yaw,
        score: null.excess(d),
        statistic: d,
        words: String::new(),
        parameter: None,
        channel_material: false,
        reference: stat.reference,
        speed_only: false,
    };
    let pct = 100.0 * (1.0 - (-d / tn.max(1) as f64).exp());
    match best {
        Effect::DeadTime { samples } => {
            let s = samples as f64 * ts;
            ev.parameter = Some(s);
            ev.words = format!(
                "errors follow the steering commands late; a dead time of {s:.1} s removes {pct:.0} % of \
                 the one-step error energy the reference version leaves"
            );
        }
        Effect::RateLimit { rate } => {
            ev.parameter = Some(rate);
            ev.words = format!(
                "errors grow right after fast steering reversals; a slew limit of {rate:.1} °/s explains \
                 {pct:.0} % of the one-step error energy"
            );
        }
        Effect::Saturation { limit } => {
            ev.parameter = Some(limit);
            ev.words = format!(
                "large rudder/pod angles turn the ship less than the model expects; an angle limit of \
                 {limit:.1}° explains {pct:.0} % of the one-step error energy"
            );
        }
        Effect::DeadBand { width } => {
            ev.parameter = Some(width);
            ev.words = format!(
                "small steering corrections do not reach the ship and reversals arrive short; a \
                 dead band of {width:.2}° explains {pct:.0} % of the one-step error energy"
            );
        }
        Effect::Asymmetry { beta } => {
            ev.parameter = Some(beta);
            ev.words = format!(
                "starboard commands act {} than port ones (gain {beta:+.3} on max(δ,0)); explains \
                 {pct:.0} % of the one-step error energy",
                if beta > 0.0 { "harder" } else { "softer" }
            );
        }
        Effect::NonlinearDamping { beta, cubic } => {
            ev.parameter = Some(beta);
            ev.words = format!(
                "fast turns are damped {} than the model expects ({} gain {beta:+.4}); explains \
                 {pct:.0} % of the one-step error energy",
                if beta < 0.0 { "more" } else { "less" },
                if cubic { "r³" } else { "r|r|" }
            );
        }
        Effect::Bias { beta } => {
            ev.parameter = Some(beta);
            ev.words = format!(
                "a steady yaw moment worth {beta:+.2}° of rudder/pod angle; explains {pct:.0} % of the \
                 {SLOW_HORIZON}-step error energy"
            );
        }
        Effect::GyroBias { d_y } => {
            ev.parameter = Some(d_y);
            ev.words = format!(
                "the yaw rate reads {d_y:+.3} °/s off on the {SLOW_HORIZON}-step errors ({pct:.0} % of their energy)"
            );
        }
        Effect::Wind { .. } => {
            ev.words = format!(
                "a yaw moment with the heading's 1st and 2nd harmonics takes {pct:.0} % of the \
                 {SLOW_HORIZON}-step error energy (yaw channel: p {})",
                fmt_p(p_yaw)
            );
        }
        Effect::Current { .. } => {
            ev.words = format!(
                "a yaw moment with the heading's 1st harmonic takes {pct:.0} % of the \
                 {SLOW_HORIZON}-step error energy (yaw channel: p {})",
                fmt_p(p_yaw)
            );
        }
    }
    // channels
    match kind {
        EffectKind::GyroBias => {
            if let Some((b, se)) = hb {
                let z = b / se;
                ev.p = (2.0 * normal_sf(z.abs())).min(1.0);
                ev.statistic = z * z;
                ev.score = z * z - 1.0;
                ev.parameter = Some(b);
                ev.channel_material = true;
                ev.words = format!(
                    "the gyro reads {b:+.3} ± {se:.3} °/s more than the heading turns \
                     (mean r − mean dψ/dt{})",
                    if has_ref {
                        ", trial minus reference"
                    } else {
                        ""
                    }
                );
            }
        }
        EffectKind::Current | EffectKind::Wind => {
            if let Some(s) = sog {
                let (chi, df) = if kind == EffectKind::Current {
                    (s.chi1, 2.0)
                } else {
                    (s.chi1 + s.chi2, 4.0)
                };
                let p_sog = chi2_sf(chi, df);
                // either channel may show it (Bonferroni over the two)
                ev.p = (2.0 * p_yaw.min(p_sog)).min(1.0);
                ev.score = ev.score.max(chi - df);
                ev.channel_material = p_sog < cfg.alpha / cfg_m(cfg);
                if kind == EffectKind::Current {
                    ev.parameter = Some(s.amp1);
                    ev.words.push_str(&format!(
                        "; speed over ground varies by ±{:.3} m/s with heading, fastest heading \
                         {:.0}° (χ² = {chi:.1}, 2 df)",
                        s.amp1, s.dir1
                    ));
                } else {
                    ev.words.push_str(&format!(
                        "; speed over ground varies with heading by ±{:.3} m/s (1st harmonic) and \
                         ±{:.3} m/s (2nd) (χ² = {chi:.1}, 4 df)",
                        s.amp1, s.amp2
                    ));
                }
            }
        }
        // the channels carry nothing of the actuator and hull effects, nor of a moment
        EffectKind::Bias
        | EffectKind::DeadTime
        | EffectKind::RateLimit
        | EffectKind::Saturation
        | EffectKind::DeadBand
        | EffectKind::Asymmetry
        | EffectKind::NonlinearDamping => {}
    }
    ev
}

/// An effect named from speed over ground alone — current or wind while the yaw channel
/// shows no heading-dependent moment ([`Evidence::speed_only`]) — that buys no held-out
/// yaw-rate prediction is not named ahead of a significant effect that does: it explains
/// none of the yaw-rate departures the other one explains, and a yaw-rate predictor is what
/// the model is. The first such effect behind it moves ahead of it (`gains[i]`: held-out
/// gain and fits of the significant effects, in the order of `ev`).
fn yaw_before_speed(ev: &mut Vec<Evidence>, gains: &mut Vec<Option<(f64, BTreeMap<String, f64>)>>) {
    let gain = |g: &Option<(f64, BTreeMap<String, f64>)>| g.as_ref().map(|g| g.0);
    let material = |e: &Evidence, g: &Option<(f64, BTreeMap<String, f64>)>| {
        g.is_some() && (e.channel_material || gain(g).is_some_and(|v| v > 0.0))
    };
    let Some(i) = (0..ev.len()).find(|&i| material(&ev[i], &gains[i])) else {
        return;
    };
    let gi = gain(&gains[i]).unwrap_or(0.0);
    if !ev[i].speed_only || gi > 0.0 {
        return;
    }
    let Some(j) =
        (i + 1..ev.len()).find(|&j| !ev[j].speed_only && gain(&gains[j]).is_some_and(|v| v > 0.0))
    else {
        return;
    };
    let gj = gain(&gains[j]).unwrap_or(0.0);
    let words = format!(
        "; named behind {}: only speed over ground shows it (the yaw channel shows no \
         heading-dependent moment) and it buys no held-out yaw-rate prediction ({gi:+.1} pp), \
         where {} is significant in the yaw rate and buys {gj:+.1} pp",
        ev[j].kind.name(),
        ev[j].kind.name(),
    );
    ev[i].words.push_str(&words);
    let e = ev.remove(j);
    ev.insert(i, e);
    let g = gains.remove(j);
    gains.insert(i, g);
}

/// Current or wind, when speed over ground is logged (module docs): a uniform current carries
/// the ship without a heading-dependent yaw moment, wind turns it. "Wind" nests "current"
/// (the speed harmonics are free in both; wind adds the yaw-moment harmonics), so the
/// likelihood-ratio test between them is the yaw channel's heading-harmonic statistic against
/// its bootstrap null — first harmonic (current's regressors) or first and second (wind's),
/// Bonferroni over the two, one test at level α. When either effect is significant, the one
/// this test names is ranked ahead of the other; wind named this way is significant when
/// both the heading dependence (the better of the two effects' p-values) and the yaw moment
/// are (intersection–union: the larger p-value), and material when the speed channel shows
/// the heading dependence.
fn current_or_wind(ev: &mut Vec<Evidence>, level: f64, alpha: f64, speed: bool) {
    let pos = |ev: &[Evidence], k: EffectKind| ev.iter().position(|e| e.kind == k);
    let (Some(ic), Some(iw)) = (pos(ev, EffectKind::Current), pos(ev, EffectKind::Wind)) else {
        return;
    };
    if !speed || (ev[ic].p >= level && ev[iw].p >= level) {
        return;
    }
    let p_moment = (2.0 * ev[ic].p_yaw.min(ev[iw].p_yaw)).min(1.0);
    let wind = p_moment < alpha;
    let words = format!(
        "; yaw moment varying with heading: p {} ({}): {}",
        fmt_p(p_moment),
        if wind { "present" } else { "absent" },
        if wind {
            "the ship is turned by it, wind (a current carries the ship without turning it)"
        } else {
            "speed over ground alone depends on heading, the water carries the ship: a current"
        }
    );
    ev[ic].words.push_str(&words);
    ev[iw].words.push_str(&words);
    ev[ic].speed_only = !wind;
    ev[iw].speed_only = !wind;
    if wind {
        let heading_p = ev[ic].p.min(ev[iw].p);
        let cm = ev[ic].channel_material;
        let w = &mut ev[iw];
        w.p = w.p.min(heading_p.max(p_moment));
        w.channel_material |= cm;
    }
    let (win, lose) = if wind { (iw, ic) } else { (ic, iw) };
    if win > lose {
        let e = ev.remove(win);
        ev.insert(lose, e);
    }
}

/// Encompassing test between the top two significant effects: both fitted jointly, each
/// over its whole grid (a dead time and a slew limit that mimic each other alone settle on
/// other values together); what does each add, given the other, beyond the version the
/// reference shows? `adds_a = N·ln(SSE(a at its reference version, b free)/SSE(both free))`,
/// judged against a's own bootstrap null. The one that adds nothing significant given the
/// other is explained by it (and, when neither adds anything, the simpler one is kept). An
/// effect shown by its own channel is not displaced by one that is not.
#[allow(clippy::too_many_arguments)]
fn encompass(
    model: &Model,
    trial: &Set<'_>,
    ev: &mut [Evidence],
    grids: &[(EffectKind, Vec<Effect>)],
    level: f64,
    alpha: f64,
    par: bool,
    speed: bool,
) {
    if ev.len() < 2 || ev[1].p >= level {
        return;
    }
    // current vs wind with speed over ground logged: decided by `current_or_wind`
    let pair = [ev[0].kind, ev[1].kind];
    if speed && pair.contains(&EffectKind::Current) && pair.contains(&EffectKind::Wind) {
        return;
    }
    if ev[0].channel_material != ev[1].channel_material {
        return;
    }
    // on the slower horizon every effect is visible; the scale of the null comes from an
    // effect judged on that horizon
    let h = ev[0].h.max(ev[1].h);
    let cands = |x: &Evidence| -> Vec<Effect> {
        grids
            .iter()
            .find(|(k, _)| *k == x.kind)
            .map_or_else(|| vec![zero_gains(&x.best)], |(_, g)| g.clone())
    };
    let (a, b) = (&ev[0], &ev[1]);
    let (ca, cb) = (cands(a), cands(b));
    let best_sse = |q: &[Quad]| q.iter().map(|q| q.best().1).fold(f64::INFINITY, f64::min);
    // one effect held at the version the reference shows (the model itself when it shows
    // none), the other over its grid
    let held = |x: &Evidence, other: &[Effect]| {
        let m = match x.reference {
            Some(r) => model.clone().with_effect(r),
            None => model.clone(),
        };
        best_sse(&trial.family(&m, other, h, par))
    };
    let sa_ref = held(a, &cb);
    let sb_ref = held(b, &ca);
    let product: Vec<(Effect, Effect)> = ca
        .iter()
        .flat_map(|x| cb.iter().map(move |y| (*x, *y)))
        .collect();
    let sab = best_sse(&trial.pairs(model, &product, h, par))
        .min(sa_ref)
        .min(sb_ref);
    let n = trial.sse0(model, h).1 as f64;
    let adds_a = (n * (sa_ref / sab).ln()).max(0.0);
    let adds_b = (n * (sb_ref / sab).ln()).max(0.0);
    let scale = |x: &Evidence| {
        if x.h == h {
            x.null
        } else if a.h == h {
            a.null
        } else {
            b.null
        }
    };
    // degrees of freedom of what one adds given the other: wind nests current (its first
    // harmonics are current's regressors), so wind adds only its second harmonics
    let frac = |x: &Evidence, y: &Evidence| -> f64 {
        let (gx, gy) = (x.best.gains().len(), y.best.gains().len());
        let nested = x.kind == EffectKind::Wind && y.kind == EffectKind::Current;
        if nested && gx > gy {
            (gx - gy) as f64 / gx as f64
        } else {
            1.0
        }
    };
    let (mut na_, mut nb_) = (scale(a), scale(b));
    na_.nu *= frac(a, b);
    nb_.nu *= frac(b, a);
    // one test of one pair: level α
    let (pa, pb) = (na_.p(adds_a), nb_.p(adds_b));
    let sig_a = pa < alpha;
    let sig_b = pb < alpha;
    let simpler_b = b.best.gains().len() < a.best.gains().len();
    let (xa, xb) = (na_.excess(adds_a), nb_.excess(adds_b));
    let swap = match (sig_a, sig_b) {
        // b adds what a misses, a adds nothing given b
        (false, true) => true,
        // both add: the larger gain above noise wins
        (true, true) => xb > xa,
        // neither adds given the other: the simpler one
        (false, false) => simpler_b,
        (true, false) => false,
    };
    let adds = |x: &str, y: &str, p: f64| {
        if p < alpha {
            format!("given {y}, {x} still adds (p {})", fmt_p(p))
        } else {
            format!("given {y}, {x} adds nothing significant (p {})", fmt_p(p))
        }
    };
    let (na, nb) = (a.kind.name(), b.kind.name());
    let w = format!(
        "; encompassing test ({h}-step errors, both fitted together, each measured from the \
         version the reference shows): {}; {}",
        adds(na, nb, pa),
        adds(nb, na, pb),
    );
    ev[0].words.push_str(&w);
    ev[1].words.push_str(&w);
    if swap {
        ev.swap(0, 1);
    }
}

fn zero_gains(e: &Effect) -> Effect {
    let mut c = *e;
    let g = vec![0.0; e.gains().len()];
    c.set_gains(&g);
    c
}

/// The effect's own held-out contribution: θ frozen, the effect's structure as found, its
/// gains refitted on `est`; (gain pp at the effect's horizon — 10 steps for actuator and hull
/// effects, `sim` for slow ones —, held-out fits with the effect).
fn frozen_gain(
    model: &Model,
    e: &Evidence,
    est: &Set<'_>,
    held_out: &[Record],
    before: &BTreeMap<String, f64>,
    parallel: bool,
) -> (f64, BTreeMap<String, f64>) {
    let cand = zero_gains(&e.best);
    let q = est.family(model, &[cand], e.h, parallel);
    let (beta, _) = q[0].best();
    let m = model.clone().with_effect(effect_with(&cand, &beta));
    let fits = mean_fit(&m, held_out, &Horizon::REPORT);
    let key = if e.h == 1 { "10" } else { "sim" };
    let gain = match (fits.get(key), before.get(key)) {
        (Some(a), Some(b)) if (a - b).is_finite() => a - b,
        _ => f64::NEG_INFINITY,
    };
    (gain, fits)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{simulate, NoiseSpec, Scenario, Ship, SimEffect};
    use rayon::prelude::*;

    fn noise() -> NoiseSpec {
        NoiseSpec {
            gyro_std_degps: 0.03,
            heading_std_deg: 0.1,
            speed_std_mps: 0.01,
        }
    }

    fn records(kind: Option<(EffectKind, f64)>, seeds: &[u64]) -> Vec<Record> {
        ship_records(&Ship::default_lng(), kind, seeds)
    }

    /// Noisy records of `ship` with one hidden effect at a scale, or none.
    fn ship_records(ship: &Ship, kind: Option<(EffectKind, f64)>, seeds: &[u64]) -> Vec<Record> {
        let mut sc = match kind {
            Some((k, s)) => Scenario::with_effect(SimEffect::hidden(k, s)),
            None => Scenario::default(),
        };
        sc.noise = noise();
        seeds
            .par_iter()
            .map(|&s| simulate(ship, &sc, s).unwrap())
            .collect()
    }

    fn identify(recs: &[Record]) -> Model {
        pem::identify(recs, None, &PemConfig::default())
            .unwrap()
            .model
    }

    struct Fixture {
        refs: Vec<Vec<Record>>,
        models: Vec<Model>,
    }

    /// Three independent effect-free references (3 records each) and their models.
    fn fixture() -> Fixture {
        let refs: Vec<Vec<Record>> = (0..3u64)
            .map(|r| records(None, &[900 + 3 * r, 901 + 3 * r, 902 + 3 * r]))
            .collect();
        let models = refs.iter().map(|r| identify(r)).collect();
        Fixture { refs, models }
    }

    fn run_case(f: &Fixture, kind: Option<EffectKind>, strength: f64, seed: u64) -> Diagnosis {
        let est = records(
            kind.map(|k| (k, strength)),
            &[seed * 10, seed * 10 + 1, seed * 10 + 2],
        );
        let r = (seed % 3) as usize;
        let cfg = DiagnoseConfig {
            seed,
            ..DiagnoseConfig::default()
        };
        diagnose(&f.models[r], &f.refs[r], &est, &[], &cfg).unwrap()
    }

    fn name(k: Option<EffectKind>) -> &'static str {
        k.map_or("none", |k| k.name())
    }

    /// Runs `cases` (hidden kind, seed) and prints the confusion matrix; returns the number right.
    fn suite(
        f: &Fixture,
        cases: &[(Option<EffectKind>, u64)],
        strength: f64,
        title: &str,
    ) -> Vec<(Option<EffectKind>, Option<EffectKind>)> {
        let out: Vec<(Option<EffectKind>, Option<EffectKind>, String)> = cases
            .par_iter()
            .map(|&(k, seed)| {
                let d = run_case(f, k, strength, seed);
                let top: Vec<String> = d
                    .ranking
                    .iter()
                    .take(3)
                    .map(|r| {
                        format!(
                            "{}(p={:.1e},sig={},mat={})",
                            r.effect, r.p_value, r.significant as u8, r.material as u8
                        )
                    })
                    .collect();
                let why = d
                    .ranking
                    .first()
                    .map_or(String::new(), |r| r.evidence.clone());
                (k, d.verdict_kind(), format!("{} | {why}", top.join(" ")))
            })
            .collect();
        let mut labels: Vec<Option<EffectKind>> = vec![None];
        labels.extend(EffectKind::ALL.iter().map(|k| Some(*k)));
        println!("{title}: rows hidden, columns verdict");
        print!("{:>18}", "");
        for l in &labels {
            print!(" {:>5}", &name(*l)[..name(*l).len().min(5)]);
        }
        println!();
        for h in &labels {
            if !out.iter().any(|o| o.0 == *h) {
                continue;
            }
            print!("{:>18}", name(*h));
            for v in &labels {
                print!(
                    " {:>5}",
                    out.iter().filter(|o| o.0 == *h && o.1 == *v).count()
                );
            }
            println!();
        }
        for (k, v, top) in &out {
            if k != v {
                println!("  wrong: hidden {} → {}: {top}", name(*k), name(*v));
            }
        }
        out.into_iter().map(|o| (o.0, o.1)).collect()
    }

    fn right(out: &[(Option<EffectKind>, Option<EffectKind>)]) -> usize {
        out.iter().filter(|o| o.0 == o.1).count()
    }

    /// The acceptance suite of issue 4: every effect at full strength (three seeds each), twenty
    /// effect-free trials, and every effect at half strength.
    #[test]
    fn acceptance_suite() {
        let t = std::time::Instant::now();
        let f = fixture();
        let full: Vec<(Option<EffectKind>, u64)> = EffectKind::ALL
            .iter()
            .flat_map(|k| (0..3).map(move |s| (Some(*k), 11 + s)))
            .collect();
        let nulls: Vec<(Option<EffectKind>, u64)> = (0..20).map(|s| (None, 40 + s)).collect();
        let full_out = suite(&f, &full, 1.0, "full strength");
        let null_out = suite(&f, &nulls, 1.0, "no hidden effect");
        let half_out = suite(&f, &full, 0.5, "half strength");
        let (right_full, right_null, right_half) =
            (right(&full_out), right(&null_out), right(&half_out));
        println!(
            "full {right_full}/{}, null {right_null}/{}, half {right_half}/{} in {:.0} s",
            full.len(),
            nulls.len(),
            full.len(),
            t.elapsed().as_secs_f64()
        );
        // every effect named at full strength
        assert_eq!(
            right_full,
            full.len(),
            "full strength: {right_full} of {}",
            full.len()
        );
        assert!(right_null >= 19, "verdict none in {right_null} of 20");
        assert!(
            right_half * 4 >= full.len() * 3,
            "half strength right in {right_half} of {}",
            full.len()
        );
    }

    #[test]
    fn heading_statistic_recovers_a_gyro_bias() {
        let f = records(Some((EffectKind::GyroBias, 1.0)), &[5]);
        let hb = heading_bias(&f).unwrap();
        assert!(
            (hb.bias - crate::sim::HIDDEN_GYRO_BIAS_DEGPS).abs() < 5.0 * hb.se + 2e-3,
            "{hb:?}"
        );
        assert!(hb.se < 5e-3, "{hb:?}");
        // a yaw moment is not a sensor offset
        let m = records(Some((EffectKind::Bias, 1.0)), &[5]);
        let hm = heading_bias(&m).unwrap();
        assert!(hm.bias.abs() < 5.0 * hm.se + 2e-3, "{hm:?}");
        // no heading, no statistic
        let mut nh = m.clone();
        nh[0].psi = None;
        assert!(heading_bias(&nh).is_none());
    }

    #[test]
    fn speed_harmonics_see_a_current() {
        let ship_recs = records(Some((EffectKind::Current, 1.0)), &[7, 8]);
        let clean = records(None, &[9, 10]);
        let s = sog_evidence(&ship_recs, &clean, 3).unwrap();
        // current 0.3 m/s towards 090°: speed over ground gains ≈ 0.3 m/s heading east
        assert!(
            (s.amp1 - crate::sim::HIDDEN_CURRENT_MPS).abs() < 0.1,
            "{s:?}"
        );
        assert!((s.dir1 - 90.0).abs() < 10.0, "{s:?}");
        assert!(chi2_sf(s.chi1, 2.0) < 1e-6, "{s:?}");
        let n = sog_evidence(&records(None, &[11, 12]), &clean, 3).unwrap();
        assert!(n.amp1 < 0.05, "{n:?}");
    }

    #[test]
    fn speed_lost_in_turns_is_not_a_current() {
        // a slew limit changes the turning history, and with it the heading history, against
        // the reference's: with one 20 s lag the speed lost in turns that the nuisance
        // regressors leave aliases onto the heading harmonics and passes for a current
        // (p < 1e-3 at 2 df, significant at α/9); the bank of surge lags takes it out
        let reference = records(None, &[300, 301]);
        let trial = records(Some((EffectKind::RateLimit, 1.0)), &[302, 303]);
        let one = sog_evidence_with(&trial, &reference, 1, &[20.0]).unwrap();
        assert!(one.chi1 > 13.8 && one.amp1 > 0.02, "{one:?}");
        let bank = sog_evidence(&trial, &reference, 1).unwrap();
        assert!(bank.chi1 < 9.21 && bank.amp1 < 0.01, "{bank:?}");
        // no hidden effect at all: the same
        let none = records(None, &[302, 303]);
        let one = sog_evidence_with(&none, &reference, 1, &[20.0]).unwrap();
        assert!(one.chi1 > 13.8, "{one:?}");
        let bank = sog_evidence(&none, &reference, 1).unwrap();
        assert!(bank.chi1 < 9.21 && bank.amp1 < 0.01, "{bank:?}");
        assert_eq!(
            sog_taus(reference.iter().chain(&trial)),
            vec![10.0, 30.0, 90.0, 270.0]
        );
    }

    #[test]
    fn frozen_statistic_finds_a_known_dead_time() {
        // innovations data of a known model whose commands arrive 3 samples late
        let truth = crate::identify::pem::testdata::truth();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let u = crate::identify::pem::testdata::prbs(&mut rng, 1500, &[5.0, 10.0, 20.0]);
        let like = Record::from_uy("x", 1.0, u, vec![0.0; 1500]);
        let delayed = truth.clone().with_effect(Effect::DeadTime { samples: 3 });
        let rec = simulate_innovations(&delayed, &like, 0.02, &mut rng);
        let set = Set::new(&truth, std::slice::from_ref(&rec));
        let cands = grid(EffectKind::DeadTime, 1.0, 20.0, 40.0);
        let q = set.family(&truth, &cands, 1, false);
        let (s0, n) = set.sse0(&truth, 1);
        let none = Version {
            idx: None,
            beta: DVector::zeros(0),
        };
        let (d, i, _) = trial_statistic(&q, s0, n, &none);
        assert_eq!(cands[i], Effect::DeadTime { samples: 3 });
        assert!(d > 100.0, "{d}");
    }

    #[test]
    fn satterthwaite_null_matches_a_chi2() {
        // replicates of 2·χ²₃: mean 6, variance 24
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let reps: Vec<f64> = (0..4000)
            .map(|_| 2.0 * (0..3).map(|_| gauss(&mut rng).powi(2)).sum::<f64>())
            .collect();
        let n = Null::fit(&reps);
        assert!((n.c - 2.0).abs() < 0.2 && (n.nu - 3.0).abs() < 0.3, "{n:?}");
        assert!((n.p(2.0 * 11.345) - 0.01).abs() < 2e-3);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let f = records(None, &[3]);
        let m = identify(&f);
        let cfg = DiagnoseConfig {
            null_reps: 8,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let e = diagnose(&m, &[], &[], &[], &cfg).unwrap_err();
        assert!(e.to_string().contains("no trial records"), "{e}");
        let mut slow = f[0].clone();
        slow.ts = 2.0;
        let e = diagnose(&m, &[], &[slow], &[], &cfg).unwrap_err();
        assert!(e.to_string().contains("sample time"), "{e}");
        let short = f[0].slice(0, 100);
        let e = diagnose(&m, &[], &[short], &[], &cfg).unwrap_err();
        assert!(e.to_string().contains("at least 200"), "{e}");
        let mut ragged = f[0].clone();
        ragged.psi.as_mut().unwrap().pop();
        let e = diagnose(&m, &f, &[ragged], &[], &cfg).unwrap_err();
        assert!(e.to_string().contains("psi"), "{e}");
        let mut bad_order = m.clone();
        bad_order.n = 3;
        let e = diagnose(&bad_order, &[], &f, &[], &cfg).unwrap_err();
        // The model itself is refused, naming the vector, its length and the order claimed.
        assert!(
            matches!(
                &e,
                DiagnoseError::Input(InputError::Model(
                    crate::identify::model::ModelError::Length {
                        name: "a",
                        found: 4,
                        order: 3
                    }
                ))
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "the model is invalid: parameter vector `a` has 4 values, the order is 3"
        );
        let e = diagnose(
            &m,
            &[],
            &f,
            &[],
            &DiagnoseConfig {
                alpha: 1.5,
                ..cfg.clone()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("alpha"), "{e}");
    }

    #[test]
    fn without_reference_the_verdict_is_said_to_be_weaker() {
        let est = records(Some((EffectKind::GyroBias, 1.0)), &[31, 32]);
        let m = identify(&est);
        let cfg = DiagnoseConfig {
            null_reps: 8,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let d = diagnose(&m, &[], &est, &[], &cfg).unwrap();
        assert!(!d.reference_used);
        assert!(
            d.explanation.contains("verdict is weaker"),
            "{}",
            d.explanation
        );
        // the heading channel still sees the sensor offset
        assert_eq!(
            d.verdict_kind(),
            Some(EffectKind::GyroBias),
            "{}",
            d.explanation
        );
        let g = d.ranking.iter().find(|r| r.effect == "gyro-bias").unwrap();
        assert!((g.parameter.unwrap() - 0.25).abs() < 0.01, "{g:?}");
    }

    #[test]
    fn a_model_of_the_trials_given_with_a_reference_is_said_to_weaken_the_evidence() {
        let reference = records(None, &[61, 62]);
        let est = records(Some((EffectKind::RateLimit, 1.0)), &[63, 64]);
        let cfg = DiagnoseConfig {
            null_reps: 8,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let warning = "does not look identified from the reference records";
        // the documented use: the reference's model names the slew limit, no warning
        let d = diagnose(&identify(&reference), &reference, &est, &[], &cfg).unwrap();
        assert!(!d.explanation.contains(warning), "{}", d.explanation);
        assert_eq!(
            d.verdict_kind(),
            Some(EffectKind::RateLimit),
            "{}",
            d.explanation
        );
        // a model identified on the trials themselves: said
        let d = diagnose(&identify(&est), &reference, &est, &[], &cfg).unwrap();
        assert!(d.explanation.contains(warning), "{}", d.explanation);
    }

    #[test]
    fn missing_heading_and_speed_are_said() {
        let mut f = records(None, &[21]);
        let refs = records(None, &[22]);
        let m = identify(&refs);
        f[0].psi = None;
        f[0].speed = None;
        let cfg = DiagnoseConfig {
            null_reps: 8,
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let d = diagnose(&m, &refs, &f, &[], &cfg).unwrap();
        assert!(
            d.explanation.contains("gyro bias cannot be told apart"),
            "{}",
            d.explanation
        );
        assert!(
            d.explanation.contains("current and wind"),
            "{}",
            d.explanation
        );
        assert_eq!(d.ranking.len(), EffectKind::ALL.len());
        // an effect already in the model is not ranked again
        let with = m.clone().with_effect(Effect::DeadTime { samples: 1 });
        let d = diagnose(&with, &refs, &f, &[], &cfg).unwrap();
        assert!(d.ranking.iter().all(|r| r.effect != "dead-time"));
        assert!(d.reference_used);
    }

    fn evidence(kind: EffectKind, p: f64, p_yaw: f64, channel_material: bool) -> Evidence {
        Evidence {
            kind,
            h: SLOW_HORIZON,
            null: Null { c: 1.0, nu: 2.0 },
            best: Effect::zero(kind, 0.0),
            p,
            p_yaw,
            score: 0.0,
            statistic: 0.0,
            words: String::new(),
            parameter: None,
            channel_material,
            reference: None,
            speed_only: false,
        }
    }

    /// The built-in ship with a slow steering gear (4 °/s, servo lag 2.5 s, as on many large
    /// ships): records with one hidden effect, or none.
    fn slow_gear_records(kind: Option<EffectKind>, seeds: &[u64]) -> Vec<Record> {
        let mut ship = Ship::default_lng();
        ship.actuator.slew_degps = 4.0;
        ship.actuator.servo_tau_s = 2.5;
        ship_records(&ship, kind.map(|k| (k, 1.0)), seeds)
    }

    #[test]
    fn dead_time_on_a_rate_limited_reference_gear_is_named_dead_time() {
        // the linear reference model absorbs the gear's slew limit into its poles; with θ
        // frozen a slew limit then mimics the trials' extra 2 s delay as well as the delay
        // itself. Measured against the reference model with its own gear, the delay stands out.
        let reference = slow_gear_records(None, &[500, 501]);
        let model = identify(&reference);
        let cfg = DiagnoseConfig {
            confirm: false,
            ..DiagnoseConfig::default()
        };
        let est = slow_gear_records(Some(EffectKind::DeadTime), &[502, 503]);
        let d = diagnose(&model, &reference, &est, &[], &cfg).unwrap();
        assert_eq!(
            d.verdict_kind(),
            Some(EffectKind::DeadTime),
            "{}",
            d.explanation
        );
        let dt = &d.ranking[0];
        assert_eq!(dt.parameter, Some(2.0), "{dt:?}");
        assert!(dt.fit_gain_pp > 10.0, "{dt:?}");
        // the reference's own gear, found with θ re-identified (4 °/s and a 2.5 s lag)
        let own = d.explanation.find("slew limit of ").unwrap() + "slew limit of ".len();
        let rate: f64 = d.explanation[own..]
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!((3.5..6.0).contains(&rate), "{}", d.explanation);
        // the encompassing test in words that say what they mean
        assert!(
            dt.evidence
                .contains("given dead-time, rate-limit adds nothing significant"),
            "{}",
            dt.evidence
        );
        assert!(
            dt.evidence
                .contains("given rate-limit, dead-time still adds"),
            "{}",
            dt.evidence
        );
        let rl = d.ranking.iter().find(|r| r.effect == "rate-limit").unwrap();
        assert!(rl.above_noise < dt.above_noise, "{rl:?}");
        assert!(
            d.explanation.contains("likelihood gain above noise"),
            "{}",
            d.explanation
        );
        // no hidden effect on the same gear: nothing, in particular no slew limit
        let none = slow_gear_records(None, &[502, 503]);
        let d = diagnose(&model, &reference, &none, &[], &cfg).unwrap();
        assert_eq!(d.verdict, "none", "{}", d.explanation);
        assert!(d.ranking.iter().all(|r| !r.significant), "{:?}", d.ranking);
    }

    #[test]
    fn speed_over_ground_alone_is_not_named_ahead_of_a_yaw_effect() {
        let level = 0.01 / 9.0;
        let mut cur = evidence(EffectKind::Current, 9e-4, 1.0, true);
        cur.speed_only = true;
        let mut ev = vec![
            cur,
            evidence(EffectKind::Wind, 2e-4, 1.0, true),
            evidence(EffectKind::RateLimit, 0.0, 0.0, false),
        ];
        ev[1].speed_only = true;
        let fits = BTreeMap::new();
        let mut gains = vec![
            Some((-1.6, fits.clone())),
            Some((-1.7, fits.clone())),
            Some((23.7, fits.clone())),
        ];
        assert!(ev.iter().all(|e| e.p < level));
        yaw_before_speed(&mut ev, &mut gains);
        let kinds: Vec<EffectKind> = ev.iter().map(|e| e.kind).collect();
        assert_eq!(
            kinds,
            [EffectKind::RateLimit, EffectKind::Current, EffectKind::Wind]
        );
        assert_eq!(gains[0].as_ref().unwrap().0, 23.7);
        assert!(
            ev[1].words.contains("named behind rate-limit"),
            "{}",
            ev[1].words
        );
        // a current whose yaw moment is seen, or that buys yaw-rate prediction, stays first
        for (speed_only, gain) in [(false, -1.6), (true, 0.4)] {
            let mut ev = vec![
                evidence(EffectKind::Current, 9e-4, 1.0, true),
                evidence(EffectKind::RateLimit, 0.0, 0.0, false),
            ];
            ev[0].speed_only = speed_only;
            let mut gains = vec![Some((gain, fits.clone())), Some((23.7, fits.clone()))];
            yaw_before_speed(&mut ev, &mut gains);
            assert_eq!(ev[0].kind, EffectKind::Current);
        }
    }

    #[test]
    fn a_yaw_moment_names_wind_its_absence_a_current() {
        let (level, alpha) = (0.01 / 9.0, 0.01);
        let kinds = |ev: &[Evidence]| ev.iter().map(|e| e.kind).collect::<Vec<_>>();
        // speed over ground shows the heading dependence (current first), and the yaw
        // channel a moment: wind goes ahead, significant and material through the speed channel
        let mut ev = vec![
            evidence(EffectKind::Current, 1e-7, 8e-3, true),
            evidence(EffectKind::Bias, 1e-4, 1e-4, false),
            evidence(EffectKind::Wind, 2e-3, 4e-4, false),
        ];
        current_or_wind(&mut ev, level, alpha, true);
        assert_eq!(
            kinds(&ev),
            [EffectKind::Wind, EffectKind::Current, EffectKind::Bias]
        );
        assert!((ev[0].p - 8e-4).abs() < 1e-15, "{}", ev[0].p);
        assert!(ev[0].channel_material);
        assert!(ev[0].words.contains("present"), "{}", ev[0].words);
        // the same speed evidence without a yaw moment: a current, wind moved behind it
        let mut ev = vec![
            evidence(EffectKind::Wind, 1e-6, 0.3, true),
            evidence(EffectKind::Current, 1e-7, 0.05, true),
        ];
        current_or_wind(&mut ev, level, alpha, true);
        assert_eq!(kinds(&ev), [EffectKind::Current, EffectKind::Wind]);
        assert_eq!(ev[1].p, 1e-6);
        // without speed over ground, or with neither significant, nothing changes
        for (speed, p) in [(false, 1e-7), (true, 0.5)] {
            let mut ev = vec![
                evidence(EffectKind::Current, p, 1e-9, true),
                evidence(EffectKind::Wind, p, 1e-9, true),
            ];
            current_or_wind(&mut ev, level, alpha, speed);
            assert_eq!(kinds(&ev), [EffectKind::Current, EffectKind::Wind]);
            assert_eq!(ev[1].p, p);
        }
    }
}
