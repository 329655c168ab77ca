//! Which physical effect is the model missing? Evidence for every library effect on the
//! trial records *and* on the reference records the model was identified from; the verdict
//! names what the trials have that the reference lacks, or `none`.
//!
//! The method (for users, in words: docs/method.md, "Diagnose and augment"):
//!
//! - **Frozen linear part.** θ stays at the model's values; each effect is added with its
//!   structural parameter on a grid (dead time d, gear rate ρ, clip level, `y|y|` or `y³`)
//!   and its linear gains fitted by least squares on the prediction errors (one-step errors
//!   for actuator and hull effects, ≈ 50-step errors for the slow effects bias, gyro bias,
//!   wind and current). The likelihood statistic is `N·ln(SSE₀/SSE₁)`, maximised over the grid.
//! - **Difference against the reference.** The same fit on the reference records gives the
//!   version of the effect the reference already shows (a linear model of a nonlinear hull
//!   shows "nonlinear damping" on any data). The trial statistic is measured from that
//!   version: `D = N·ln(SSE(reference version)/SSE(trial's best))`.
//! - **The reference's own steering gear.** A slow or delayed gear (a low rudder rate, a
//!   dead time) is dynamics: the linear model identified on the reference absorbs it into its
//!   poles, so with θ frozen the reference shows no version of it, and on the trials
//!   whichever gear effect mimics the gear's lag best on their commands stands out — a
//!   2 s dead time on a ship whose own gear turns at 4 °/s looked like a gear of
//!   5 °/s, and trials with no hidden effect showed a slow gear. So first the reference's
//!   own gear dynamics are looked for with θ re-identified ([`crate::diagnose::augment::forward`] over
//!   the gear dynamics effects on the reference records, its rule for keeping an effect,
//!   judged against the structure re-identified on the same part: the reference model saw
//!   the held-out third, so its fit there is in-sample and no yardstick);
//!   when the reference shows some, every statistic below is measured against the reference
//!   model with it (`base`), and a trial's departure from the reference's gear is tested as
//!   that effect's parameter moving. Angle limits are left to the frozen reference version:
//!   static, they cannot hide in the poles.
//! - **Null distribution by parametric bootstrap.** The innovations model (with the
//!   reference's own gear, when it shows one) is simulated with the reference's innovation
//!   variance on the reference and trial inputs; `D` is recomputed on each replicate and a
//!   scaled χ² is fitted to the replicates (Satterthwaite), which gives the p-value. No
//!   threshold is set by hand: an effect is *significant* at level α.
//! - **Trials sailed with other commands.** Where half or more of the trials' command
//!   magnitudes lie where the reference's do not (a zig-zag against a PRBS), the linear
//!   model meets the hull's own nonlinearity differently on the two, which data simulated
//!   from a linear model cannot show. The hull physics the reference records show of their
//!   own ([`crate::diagnose::augment::forward`] over the registry's `own` kinds on the
//!   reference, with its gear) is then what the bootstrap simulates, with its own
//!   innovation variance, on both sets' commands; the linear structure is still what each
//!   replicate re-identifies and measures `D` against.
//! - **The reference's own spread.** For an effect with no free gain (dead time, gear rate,
//!   angle limit, dead band) data from the linear model can only fit worse, so the
//!   bootstrap's replicates are (almost) all 0 and say nothing of how far two effect-free
//!   sets of a nonlinear hull differ. Each part of the reference (a record, or a piece of
//!   one) is therefore also measured as a trial against the others, `D` scaled to the
//!   trials; p is the larger of the two nulls' (`null::with_spread`). Where the parts agree
//!   too, neither null has width: no p-value is taken below one free parameter's
//!   likelihood ratio on white innovations, χ²₁ (`Null::p`).
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
//!   decides between look-alikes (dead time vs a slow gear, bias vs current vs wind), on the
//!   slower horizon of the two; where neither adds given the other there and the two are
//!   judged on different horizons (a steady moment on 50-step errors, an asymmetry on
//!   one-step ones), the faster horizon decides if it can.
//! - **Ranking.** Effects are ranked by their likelihood gain above noise (`D` less its null
//!   mean; a channel's χ² less its degrees of freedom): p-values far in the tail rest on the
//!   shape fitted to a few dozen null replicates and cannot be compared between effects.
//! - **Significant and material.** Each effect is judged at level α/m (m effects tested,
//!   Bonferroni), and reported only when it also improves held-out prediction (θ frozen, the
//!   effect's gains fitted on the estimation part, fit at 10 steps or in simulation) — or, for
//!   effects the yaw prediction cannot see well, when its own channel shows it (heading for
//!   a gyro bias, speed over ground for current and wind). An effect that speed over ground
//!   alone shows (no heading-dependent yaw moment) and that buys no held-out yaw-rate
//!   prediction is not named ahead of a significant effect that does; and, the one ranking
//!   rule above the statistics, no effect whose held-out gain is below 0.5 pp is named ahead
//!   of a significant one whose gain is 1 pp or more (a sensor offset with nothing to win
//!   back becomes a note behind it); nor is an effect that predicts the held-out records
//!   worse than another significant one both at 10 steps and in simulation (by 0.5 pp at
//!   one of them). The verdict's effect
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
//! next one — but for a steady offset (`bias`, `gyro-bias`) the model carries as the
//! reference's own (identification adds one where the reference needs it; the model is not
//! [foreign](Caveat::ForeignModel) to the reference): that one is tested for a *change* on
//! the trials, the reference's version (the model's own) against the trials' best.

mod anemometer;
pub mod augment;
mod carry;
mod caveat;
mod channel_evidence;
mod channels;
mod commands;
pub mod compare;
mod course;
mod evidence;
mod noise;
mod null;
mod reference;
pub mod resid;
mod rule;
mod second;
mod separation;
mod set_shape;
mod similar;
#[cfg(test)]
pub(crate) mod tests;
mod verdict;
mod window;

use std::collections::BTreeMap;

use serde::Serialize;
use thiserror::Error;
use yawcast_shared::model::EffectKind;

use crate::diagnose::augment::{AugmentConfig, AugmentReport};
use crate::diagnose::compare::{check_command, check_inputs, mean_fit, InputError};
use crate::effects::GridSpan;
use crate::identify::model::{Effect, Model};
use crate::identify::pem::offset::OFFSET_KINDS;
use crate::identify::predict::Horizon;
use crate::io::data::Record;
use caveat::caveats;
use channels::Channels;
use evidence::{grid, reference_versions, trial_stats, Set};
use null::bootstrap;
use reference::{foreign, reference_actuator, reference_hull, reference_offset};
use rule::{gain_before_statistic, outpredicted, yaw_before_speed};
use verdict::{cfg_m, effect_evidence, frozen_gain, rank, ranked, split, verdict_words, Evidence};

pub use crate::io::data::{heading_bias, HeadingBias};
pub use caveat::{Caveat, OTHER_SPEED};
pub use verdict::effect_phrase;
pub use window::{channel_records, window, CHANNEL_WINDOW, WINDOW, WINDOW_BLOCK};

/// Horizon (samples) of the prediction errors the slow effects are fitted on.
pub const SLOW_HORIZON: usize = 50;
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
    /// Likelihood gain above what noise alone gives: the statistic less its null mean,
    /// taken as at least 1, χ²₁'s (for a channel statistic, its χ² less its degrees of
    /// freedom). Effects are ranked by it: far-tail p-values rest on the shape fitted to
    /// the null replicates and are not comparable between effects.
    pub above_noise: f64,
    /// Held-out fit gain (percentage points, at the effect's horizon: 10 steps for actuator and
    /// hull effects, `sim` for slow ones) of the model with the effect added (θ frozen, the
    /// effect's gains fitted on the estimation part); 0 for effects that are not significant.
    pub fit_gain_pp: f64,
    /// Held-out fit gain (pp) at 10 steps, as `fit_gain_pp` measures it; 0 for effects that
    /// are not significant. With `fit_gain_sim_pp`, what the ranking rule compares.
    pub fit_gain_10_pp: f64,
    /// Held-out fit gain (pp) in simulation; 0 for effects that are not significant.
    pub fit_gain_sim_pp: f64,
    /// p-value below α/m (m: the number of library effects, Bonferroni).
    pub significant: bool,
    /// Held-out improvement on refit, or measurable channel evidence.
    pub material: bool,
    /// The effect's estimated structural parameter in physical units, where it has one
    /// (dead time s, gear rate °/s, clip level °, gyro bias °/s, current m/s of speed over ground;
    /// wind, where an anemometer is logged, the speed in m/s of the true wind it shows, trials
    /// less reference).
    pub parameter: Option<f64>,
    /// How far off `parameter` may be, in its units: the standard error where a channel
    /// measures it (the gyro offset, from the heading), or for a value searched on a grid
    /// (dead time, gear rate, angle limit, dead band) the larger gap to its neighbouring grid
    /// values — null at the grid's largest value, beyond which the truth may lie; null
    /// otherwise.
    pub parameter_uncertainty: Option<f64>,
    /// The smallest change of `parameter` (from the version the reference shows, either
    /// way) these trials show at the level applied, against the null `p_value` is read from
    /// — one that size is significant about half the time: where the verdict is not this
    /// effect, a smaller one may be there unseen. Given for the effects of one gain judged
    /// on the yaw-rate errors (steady moment in ° of rudder/pod angle, asymmetry, nonlinear
    /// damping, in `parameter`'s units), for the gyro offset on its heading channel (°/s),
    /// for the current on its ground track (m/s, in its worst direction), for the wind on the
    /// anemometer where one is logged (the true wind in m/s, in its worst direction) and else
    /// as the amplitude (° of rudder/pod angle) of a yaw moment varying once per turn of
    /// heading; null for the grid-searched effects and where the records cannot give one.
    pub resolution: Option<f64>,
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
    /// The verdict in physical words, with numbers (the caveats' words at its end).
    pub explanation: String,
    /// What qualifies the verdict, typed (the explanation words them).
    pub caveats: Vec<Caveat>,
    /// Whether reference records were given.
    pub reference_used: bool,
    /// The confirming refit of the verdict's effect, when done.
    pub augment: Option<AugmentReport>,
    /// The second effect of a ranked verdict ("rate-limit, then nonlinear-damping"): the
    /// most significant other effect measured against the model with the verdict's effect
    /// added, or `None`.
    pub then: Option<String>,
    /// Held-out fit % of the model, keyed by horizon ("1","5","10","20","sim"); where
    /// [`Caveat::AtTrialsSpeed`] is given, of the model identified on the re-timed
    /// reference.
    pub before: BTreeMap<String, f64>,
    /// Held-out fit % of the model with the verdict's effect (same as `before` when `none`).
    pub after: BTreeMap<String, f64>,
    /// The reference model with the steering-gear dynamics the reference records show of
    /// their own (θ re-identified on them), when they show some: what the statistics were
    /// measured against (but where [`Caveat::AtTrialsSpeed`] is given: the reference as
    /// given, whose records augment reads), and the better start for augmenting.
    #[serde(skip)]
    pub reference_gear: Option<Model>,
    /// The verdict's effect as the diagnosis measured it (θ frozen, its gains fitted on the
    /// trials): its structure and form (nonlinear damping's `y|y|` or `y³`), which
    /// `augment --effect auto` fits.
    #[serde(skip)]
    pub verdict_effect: Option<Effect>,
}

impl Diagnosis {
    /// The verdict as an effect kind (`None` for `"none"`).
    ///
    /// ```
    /// use yawcast::diagnose::Diagnosis;
    /// use yawcast_shared::model::EffectKind;
    /// let d = Diagnosis {
    ///     verdict: "dead-time".into(), ranking: vec![], explanation: String::new(), caveats: vec![],
    ///     reference_used: true, augment: None, then: None, before: Default::default(),
    ///     after: Default::default(), reference_gear: None, verdict_effect: None,
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
///
/// Where the trials ran at another speed than the reference ([`Caveat::OtherSpeed`]), the
/// reference re-timed to the trials' speed by similarity tells the speed through the water
/// from a current along the courses ([`Caveat::SpeedSimilar`]); where it is the speed, the
/// diagnosis is measured against the re-timed reference ([`Caveat::AtTrialsSpeed`]).
///
/// Long: the driver: the method's steps in the order the module docs give them, each a call to
/// its own module.
pub fn diagnose(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    val: &[Record],
    cfg: &DiagnoseConfig,
) -> Result<Diagnosis, DiagnoseError> {
    check(model, reference, est, val, cfg)?;
    // trials noisier than the reference: against it given their noise; quieter: given its
    let quiet = noise::quieted_trials(reference, est, cfg);
    let quiet = quiet.as_ref();
    if let Some(m) = noise::matched_reference(model, reference, est, cfg) {
        let mut d = run(&m.model, &m.reference, est, None, val, cfg, Against::Given)?;
        caveat::append_words(&mut d.explanation, std::slice::from_ref(&m.caveat));
        d.caveats.push(m.caveat);
        return Ok(d);
    }
    run(model, reference, est, quiet, val, cfg, Against::Given)
}

/// Which reference a run of the method measures the trials against.
#[derive(Clone, Copy, PartialEq)]
enum Against {
    /// The reference as given; where the trials ran at another speed through the water,
    /// the method runs again at theirs.
    Given,
    /// The reference re-timed to the trials' speed, the model given's structure identified
    /// on it ([`similar::at_trials_speed`]).
    TrialsSpeed,
}

/// The method against `reference` ([`diagnose`], its inputs checked).
fn run(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    quiet: Option<&noise::Quieted>,
    val: &[Record],
    cfg: &DiagnoseConfig,
    against: Against,
) -> Result<Diagnosis, DiagnoseError> {
    // Long: the steps in their order (the reference's own gear, the statistics on the
    // records, the bootstrap nulls, the ranking, materiality, the refit, the words), each a
    // call, with the intermediate results they share held here.
    let reps = cfg.null_reps.max(8);
    let given = [est, reference, val];
    // quieter trials given the reference's noise (`quiet`) for the statistics, not the channels
    let (logged, est) = (est, quiet.map_or(est, |q| &q.trials[..]));
    // long sets are diagnosed on blocks spread over them (see `WINDOW`)
    let windows = [window(est), window(reference), window(val)];
    // the heading, speed-over-ground and anemometer channels read the records whole (thinned
    // beyond `CHANNEL_WINDOW`): a channel's calibration compares each record with the others
    // of its set, and blocks of one record against each other span too few headings (a
    // current of 1.4 m/s missed at Ts 0.25 s, its resolution 3.1 m/s)
    let whole = [channel_records(logged), channel_records(reference)];
    let whole = (
        whole[0].as_deref().unwrap_or(logged),
        whole[1].as_deref().unwrap_or(reference),
    );
    let [est, reference, val] = [
        (est, &windows[0]),
        (reference, &windows[1]),
        (val, &windows[2]),
    ]
    .map(|(full, w)| w.as_deref().unwrap_or(full));
    let bar = progress_bar(cfg, reps);
    let has_ref = !reference.is_empty();
    // A plain model whose reference records show a steady offset (`reference_offset`): the
    // diagnosis reads the model `identify` writes for them, as if it had been given.
    let offset = if has_ref {
        reference_offset(model, reference, cfg)
    } else {
        None
    };
    let (given_model, model) = (model, offset.as_ref().map_or(model, |o| &o.model));
    // The reference's own actuator physics (module docs): the statistics are measured against
    // the reference model that carries it, `base`; `model` is what the user gave (a plain
    // model with the reference's own offset added, above).
    bar.set_message("the reference's own steering gear");
    let gear = if has_ref {
        reference_actuator(model, reference, cfg)
    } else {
        None
    };
    let at_trials_speed = against == Against::TrialsSpeed;
    bar.inc(1);
    bar.set_message("statistics on the records");
    let base = gear.as_ref().map_or(model, |g| &g.model);
    let trial = Set::new(model, est);
    let refset = Set::from_owned(model, reference);
    let span = GridSpan::of(model.ts, est.iter().chain(reference).map(|r| &r.u[..]));
    let u_max = span.u_max;
    // innovation std under the null: the model's one-step errors on the reference (or trial)
    let sig_set = if has_ref { &refset } else { &trial };
    let (s1, n1) = sig_set.sse0(model, 1);
    let sigma = (s1 / n1.max(1) as f64).sqrt();
    // Is the model fitted to the trials rather than the reference? (`foreign`)
    let min_pct = if windows[1].is_some() { 1.0 } else { 0.0 };
    let foreign_pct = if has_ref {
        foreign(model, reference, est, &trial, (s1, n1), min_pct, cfg.alpha)
    } else {
        None
    };
    let (trial, refset) = if gear.is_some() {
        (Set::new(base, est), Set::new(base, reference))
    } else {
        (trial, refset)
    };
    let sigma = if gear.is_some() {
        refset.innovation_std(base)
    } else {
        sigma
    };

    // an offset the model carries as the reference's own (identified on it) is tested for a
    // change on the trials; any other effect already in the model is skipped
    let own_offsets = has_ref && foreign_pct.is_none();
    let kinds: Vec<EffectKind> = EffectKind::ALL
        .iter()
        .copied()
        .filter(|k| model.effect(*k).is_none() || (own_offsets && OFFSET_KINDS.contains(k)))
        .filter(|k| !(*k == EffectKind::Saturation && u_max <= 0.0))
        .collect();

    let mut ch = Channels::measure(whole.0, whole.1, cfg.seed);
    if ch.heading_ok && !ch.yaw_tells_heading() {
        // one course per record: a moment that changes with the course, read across them
        ch.course = course::course_evidence(base, est, reference, SLOW_HORIZON);
        // and a current, which carries every record alike, from their ground velocities
        ch.carry = ch
            .speed_ok
            .then(|| carry::carry_evidence(whole.0, whole.1))
            .flatten();
    }

    let grids: Vec<(EffectKind, Vec<Effect>)> =
        kinds.iter().map(|&k| (k, grid(k, &span))).collect();
    let versions = reference_versions(base, reference, &grids, cfg.parallel);
    let real = trial_stats(base, est, &grids, &versions, cfg.parallel);
    bar.inc(1);
    bar.set_message("bootstrap replicates");
    // trials sailed with other commands than the reference: the nulls simulate the hull
    // physics the reference shows of its own, on both sets' commands (module docs)
    let mut other = commands::other_manoeuvre(est, reference);
    let steps = commands::command_steps(est, reference, model.ts);
    let hull = other
        .as_ref()
        .and_then(|_| reference_hull(base, reference, cfg))
        .map(|h| {
            let s = Set::new(&h, reference).innovation_std(&h);
            (h, s)
        });
    if let (Some(Caveat::OtherManoeuvre { hull: words, .. }), Some((h, _))) = (&mut other, &hull) {
        *words = h
            .effects
            .iter()
            .filter(|e| base.effect(e.kind()).is_none())
            .map(|e| crate::diagnose::augment::describe(e, model.ts))
            .collect();
    }
    let boot = bootstrap(
        base,
        hull.as_ref().map(|(h, s)| (h, *s)),
        reference,
        est,
        &grids,
        sigma,
        reps,
        &bar,
        cfg.seed,
        cfg.parallel,
    );
    let nulls = null::with_spread(boot, base, reference, &grids, &real, est, cfg.parallel);
    bar.set_message("encompassing test, materiality");
    let evidence: Vec<Evidence> = kinds
        .iter()
        .enumerate()
        .map(|(i, &kind)| {
            let mut e = effect_evidence(base, kind, &real[i], &nulls[i], has_ref, cfg, &ch);
            if kind == EffectKind::RateLimit && commands::trials_step(steps.as_ref()) {
                commands::slew_on_spread(&mut e, &nulls[i]);
            }
            // (a quicker estimate's own words name the reference's gear already)
            if let Some(own) = base
                .effect(kind)
                .filter(|own| gear.is_some() && !verdict::quicker_gear(&e.best, own))
            {
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
    let resolutions = resolutions(&kinds, &real, &nulls, level, &ch, &ev);
    for e in ev.iter_mut() {
        e.resolution = kinds
            .iter()
            .position(|&k| k == e.kind)
            .and_then(|i| resolutions[i]);
    }
    let of = |kind: EffectKind| {
        ev.iter()
            .find(|e| e.kind == kind)
            .and_then(|e| e.resolution)
    };
    let moment_resolution = of(EffectKind::Bias);
    let current_resolution = of(EffectKind::Current);
    let wind_resolution = of(EffectKind::Wind).filter(|_| ch.anemometer.is_none());
    rank(base, &trial, &mut ev, &grids, level, cfg, &ch);

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
    let passed_over = gain_before_statistic(&mut ev, &mut gains, &base_before);
    let outpredicted = outpredicted(&mut ev, &mut gains, &base_before, ch.anemometer.is_some());
    bar.inc(1);
    bar.set_message("refit with the verdict's effect");
    let (mut ranking, verdict) = ranked(&ev, &gains, level, &base_before);
    for (r, e) in ranking.iter_mut().zip(&ev) {
        if r.parameter_uncertainty.is_none() {
            let g = grids
                .iter()
                .find(|(k, _)| *k == e.kind)
                .map(|(_, g)| &g[..]);
            r.parameter_uncertainty = r
                .parameter
                .zip(g)
                .and_then(|(v, g)| verdict::grid_gap(v, g, model.ts));
        }
    }
    let verdict_effect = verdict.as_ref().map(|(i, _)| ev[*i].best);
    let verdict = verdict.map(|(i, frozen_fits)| {
        let report = if cfg.confirm {
            // the damping's form as measured: one parameter, one unit
            let acfg = augment::AugmentConfig {
                damping_form: ev[i].best.damping_form(),
                ..cfg.augment.clone()
            };
            augment::augment(model, ev[i].kind, &est_part, &held_out, &acfg).ok()
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
    let (verdict_name, mut explanation, after, augment) =
        verdict_words(&ev, &ranking, verdict, has_ref, cfg.alpha, &before);
    let mut caveats = caveats(
        offset.as_ref().map(|o| o.words.as_str()),
        gear.as_ref().map(|g| g.words.as_str()),
        given,
        &windows,
        has_ref,
        foreign_pct,
        &ch,
    );
    // speed through the water: told apart from a current only as far as the ground track
    // resolves one; on records that each hold one course, the speed on their courses less
    // the current read across them, which resolves it there
    let (speeds, resolution) = carry::through_water(
        ch.across_carry().as_ref(),
        ch.course_speeds,
        ch.speeds,
        current_resolution,
        level,
    );
    // only where both sets were sailed with alike commands: on a zig-zag the straight speed
    // is an extrapolation to a rudder held amidships, which the records never show
    // (effect-free zig-zags against a PRBS reference read 3.7 m/s against 7.7 on Mariner)
    let speed = (other.is_none() && !at_trials_speed)
        .then(|| caveat::other_speed(speeds, ch.course_speeds, resolution))
        .flatten();
    // speed or current: the reference re-timed to the trials' speed, on the records whole
    let (similar, at_speed) = match &speed {
        Some(Caveat::OtherSpeed {
            trials_mps,
            reference_mps,
            ..
        }) => similar::at_trials_speed(trials_mps / reference_mps, given_model, given[1], given[0])
            .map_or((None, None), |(c, at)| (Some(c), Some(at))),
        _ => (None, None),
    };
    let again = match &similar {
        Some(Caveat::SpeedSimilar {
            ratio,
            shows_speed: true,
            ..
        }) => at_speed.map(|at| (*ratio, at)),
        _ => None,
    };
    caveats.extend(speed.into_iter().chain(similar));
    caveats.extend(caveat::reference_environment(&ch, level));
    if let Some(x) = current_resolution.filter(|_| verdict_name != EffectKind::Current.name()) {
        caveats.push(Caveat::CurrentResolution { smallest_mps: x });
    }
    if let Some(x) = moment_resolution.filter(|_| verdict_name != EffectKind::Bias.name()) {
        caveats.push(Caveat::MomentResolution { smallest_deg: x });
    }
    if let Some(x) = wind_resolution.filter(|_| verdict_name != EffectKind::Wind.name()) {
        caveats.push(Caveat::WindResolution { smallest_deg: x });
    }
    if let Some(k) = passed_over.filter(|k| k.name() != verdict_name) {
        caveats.push(Caveat::PassedOver {
            effect: k.name().into(),
        });
    }
    if let Some(o) = outpredicted.filter(|o| o.by.name() == verdict_name) {
        caveats.push(Caveat::Outpredicted {
            effect: o.kind.name().into(),
            gains_pp: o.gains,
            by: o.by.name().into(),
            by_gains_pp: o.by_gains,
        });
    }
    // the second effect of a ranked verdict, against the model with the first added
    let then = EffectKind::from_name(&verdict_name).and_then(|k1| {
        let first = ev.iter().find(|e| e.kind == k1)?;
        second::second_effect(
            base,
            &first.best,
            &versions,
            est,
            &grids,
            &nulls,
            level,
            has_ref,
            cfg,
            &ch,
            (&est_part, &held_out),
        )
    });
    if let Some((e, why)) = &then {
        explanation.push_str(&format!(
            " Then, against the model with it: {} ({}; p {}; {why}).",
            effect_phrase(e.kind),
            e.kind.name(),
            verdict::fmt_p(e.p)
        ));
    }
    let verdict_ev = ev.iter().find(|e| e.kind.name() == verdict_name);
    let named_ev = verdict_ev.into_iter().chain(then.as_ref().map(|(e, _)| e));
    let (sep, shape) = (ch.separation, set_shape::SetShape::of_channels(&ch));
    caveats.extend(caveat::current_without_anemometer(named_ev, sep, shape));
    let named: Vec<EffectKind> = verdict_ev
        .map(|e| e.kind)
        .into_iter()
        .chain(then.as_ref().map(|(e, _)| e.kind))
        .collect();
    caveats.extend(separation::bias_or_wind(
        &named,
        ch.separation,
        ch.anemometer.is_some(),
        ch.course.map(|c| [c.span_deg, c.p]),
    ));
    // a significant damping that predicts better beside an angle limit or a dead band named
    // on one magnitude: the third look-alike there
    let damping = ranking
        .iter()
        .find(|r| {
            r.effect == EffectKind::NonlinearDamping.name()
                && r.significant
                && r.fit_gain_10_pp >= rule::NO_GAIN_PP
        })
        .map(|r| [r.fit_gain_10_pp, r.fit_gain_sim_pp]);
    caveats.extend(commands::clip_or_dead_band(&named, est, damping));
    caveats.extend(commands::asymmetry_or_bias(&named, est));
    caveats.extend(commands::slew_or_dead_time(&named, est));
    caveats.extend(steps.into_iter().chain(other));
    caveats.extend(noise::noise_gain(base, est, reference));
    caveats.extend(quiet.map(|q| q.caveat.clone()));
    let then = then.map(|(e, _)| e.kind.name().to_string());
    if then.as_deref() == Some(EffectKind::Current.name()) {
        // a current named second: what speed over ground cannot show does not qualify it
        caveats.retain(|c| !matches!(c, Caveat::CurrentResolution { .. }));
    }
    if then.as_deref() == Some(EffectKind::Bias.name()) {
        caveats.retain(|c| !matches!(c, Caveat::MomentResolution { .. }));
    }
    if then.as_deref() == Some(EffectKind::Wind.name()) {
        caveats.retain(|c| !matches!(c, Caveat::WindResolution { .. }));
    }
    // the trials ran at another speed through the water: the method again, against the
    // reference at theirs, the verdict against the reference as given said beside it
    if let Some((ratio, at)) = again {
        let against = Against::TrialsSpeed;
        // re-timed to a higher speed, a reference record is shorter: checked as the one given
        let (m, r) = (&at.model, &at.reference);
        let again = check(m, r, given[0], given[2], cfg)
            .and_then(|()| run(m, r, given[0], quiet, given[2], cfg, against));
        if let Ok(mut d) = again {
            let more: Vec<Caveat> = caveats
                .iter()
                .filter(|c| matches!(c, Caveat::OtherSpeed { .. } | Caveat::SpeedSimilar { .. }))
                .cloned()
                .chain([Caveat::AtTrialsSpeed {
                    ratio,
                    verdict_as_given: verdict_name,
                    then_as_given: then,
                }])
                .collect();
            caveat::append_words(&mut d.explanation, &more);
            d.caveats.extend(more);
            // `augment --effect auto` searches the ship's own physics on the reference as
            // given, from the gear found there
            d.reference_gear = gear.map(|g| g.model);
            return Ok(d);
        }
    }
    caveat::append_words(&mut explanation, &caveats);
    Ok(Diagnosis {
        verdict: verdict_name,
        ranking,
        explanation,
        caveats,
        reference_used: has_ref,
        augment,
        then,
        before,
        after,
        reference_gear: gear.map(|g| g.model),
        verdict_effect,
    })
}

/// The smallest change of each effect of `kinds` the trials show at `level`
/// ([`Ranked::resolution`]): for an effect with gains on the yaw-rate errors, the change
/// whose statistic reaches the critical value of the null its p-value is read from, on the
/// errors of the candidate the trials fit best, as `real[i]` measured its statistic
/// ([`evidence::Quad::smallest_gain`]; of the wind, the amplitude of a once-per-turn moment
/// in the direction the errors show least, [`resolved_gains`]); for the gyro offset and
/// the current, their channels' own. An effect whose p is the best of several channels
/// (Bonferroni over them, `channel_evidence`) shows on one of them at `level` over their
/// number; one whose yaw channel is not counted, or is read across the courses of records
/// that each hold one course, has no resolution there.
fn resolutions(
    kinds: &[EffectKind],
    real: &[evidence::WorldStat],
    nulls: &[null::Nulls],
    level: f64,
    ch: &Channels,
    ev: &[verdict::Evidence],
) -> Vec<Option<f64>> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            // each channel of an effect's p shows it at the level over their number
            let at = level / f64::from(ev[i].channels);
            match k {
                EffectKind::GyroBias => ch.hb.map(|g| g.smallest(level)),
                EffectKind::Current => match ch.across_carry() {
                    Some(c) => Some(c.smallest(at)),
                    None => ch.sog.as_ref().map(|s| s.smallest_current(at)),
                },
                // with an anemometer, the true wind it shows, as the wind's parameter is
                EffectKind::Wind if ch.anemometer.is_some() => {
                    ch.anemometer.map(|a| a.smallest(at))
                }
                // on records that each hold one course the harmonics' null is not what
                // decides (read across the courses, `course.rs`)
                _ if !ev[i].yaw_counted => None,
                k if k.needs_heading() && !ch.yaw_tells_heading() => None,
                k if !crate::effects::def(k).gains.is_empty() => {
                    let d_crit = nulls[i].at(real[i].d).0.critical(at);
                    real[i].quad.smallest_gain(d_crit, &resolved_gains(k))
                }
                _ => None,
            }
        })
        .collect()
}

/// The gains of `kind` its resolution is read along: all, but of the wind's the once-per-turn
/// harmonic alone, which a wind's moment mostly is (the rudder holding course against the
/// test worlds' winds varies once per turn by 0.6–1.9°, twice by 0.01–0.5°); the regressors
/// twice per turn, correlated with it over the headings sailed, would make the worst
/// direction a mix no wind has.
fn resolved_gains(kind: EffectKind) -> Vec<usize> {
    use crate::effects::Regressor::{Cos1, Sin1};
    let gains = crate::effects::def(kind).gains;
    let all = 0..gains.len();
    let first: Vec<usize> = all
        .clone()
        .filter(|&j| matches!(gains[j].1, Sin1 | Cos1))
        .collect();
    match kind == EffectKind::Wind && !first.is_empty() {
        true => first,
        false => all.collect(),
    }
}

/// The inputs [`diagnose`] refuses (its `# Errors`).
fn check(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    val: &[Record],
    cfg: &DiagnoseConfig,
) -> Result<(), DiagnoseError> {
    check_inputs(model, est, MIN_SAMPLES, "trial")?;
    check_command(model, est, "trial")?;
    if !reference.is_empty() {
        check_inputs(model, reference, MIN_SAMPLES, "reference")?;
        check_command(model, reference, "reference")?;
    }
    if !val.is_empty() {
        check_inputs(model, val, 4 * model.n + 4, "validation")?;
        check_command(model, val, "validation")?;
    }
    if !(cfg.alpha > 0.0 && cfg.alpha < 1.0) {
        return Err(InputError::Config(format!("alpha {} is not in (0, 1)", cfg.alpha)).into());
    }
    Ok(())
}
