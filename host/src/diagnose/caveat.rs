//! Caveats: what the verdict rests on that weakens or qualifies it, and their words.

use serde::Serialize;
use yawcast_shared::model::EffectKind;

use super::channels::Channels;
use super::rule::{GAIN_PP, NO_GAIN_PP};
use super::set_shape::SetShape;
use super::verdict::{effect_phrase, fmt_p, Evidence, Moment};
use super::{MIN_SAMPLES, WINDOW, WINDOW_BLOCK};
use crate::diagnose::augment::sig;
use crate::io::data::Record;

/// What the verdict rests on that weakens or qualifies it; [`Caveat::explain`] says it in
/// words (the explanation appends them in this order).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "caveat", rename_all = "kebab-case")]
pub enum Caveat {
    /// The model given is a plain linear model, and its reference records show a steady
    /// offset (a yaw moment or a gyro offset) that `yawcast identify` would have added; the
    /// statistics were measured against the reference model identified with it.
    ReferenceOffset {
        /// The sentence naming the offset and the rule that found it.
        words: String,
    },
    /// The reference records show steering-gear dynamics of their own; the statistics were
    /// measured against the reference model with them.
    ReferenceGear {
        /// The sentence naming the gear and its held-out fits.
        words: String,
    },
    /// Long sets were diagnosed on blocks spread evenly over them (the heading, speed and
    /// anemometer channels on the records whole).
    Blocks {
        /// Blocks of the trials (0: used whole).
        trials: usize,
        /// Of the reference.
        reference: usize,
        /// Of the held-out records.
        held_out: usize,
        /// The sample time (s), a whole multiple of the records', at which every set would
        /// fit in [`WINDOW`] samples and so be read whole, with each record still
        /// [`MIN_SAMPLES`] long (`None` when none is): the slow effects (a steady moment, a
        /// gyro offset, wind, a current) show with the span of the records read, not with
        /// the number of samples.
        resample_s: Option<f64>,
    },
    /// No reference records: every statistic is judged against the model alone.
    NoReference,
    /// The model does not look identified from the reference records.
    ForeignModel {
        /// Its one-step error on the reference above the re-identified structure's (%).
        excess_pct: f64,
    },
    /// Heading is not logged in every record.
    NoHeading,
    /// Speed over ground (or heading) is not logged in every record.
    NoSpeedOverGround,
    /// Speed over ground cannot show a current weaker than `smallest_mps` on these records
    /// (heading range, speed lost in turns): a verdict other than current does not rule
    /// one out (not given when a current is named, first or second).
    CurrentResolution {
        /// The smallest current (m/s) the records show at the level applied, in any
        /// direction.
        smallest_mps: f64,
    },
    /// The trials' prediction errors cannot show a steady yaw moment smaller than
    /// `smallest_deg` (° of rudder/pod angle) at the level applied: a verdict other than a
    /// steady moment does not rule a smaller one out (not given when one is named, first
    /// or second).
    MomentResolution {
        /// The smallest steady moment (° of rudder/pod angle, either way) whose statistic
        /// reaches the level applied against its null: one that size does about half the
        /// time.
        smallest_deg: f64,
    },
    /// The trials' prediction errors cannot show a yaw moment varying with heading (a
    /// wind's) smaller than `smallest_deg` at the level applied, and no anemometer is logged
    /// to show the wind itself: a verdict other than wind does not rule a weaker one out (not
    /// given when wind is named, first or second, nor where the yaw channel is not counted).
    WindResolution {
        /// The smallest such moment (° of rudder/pod angle: the amplitude of a moment
        /// varying once per turn, as a wind's mostly does, at the direction the headings
        /// sailed show least) whose statistic reaches the level applied against its null.
        smallest_deg: f64,
    },
    /// A current named from speed over ground alone, with no anemometer: the wind's leeway
    /// sets the ship over ground as a current does, and the yaw channel, which decides
    /// between the two without an anemometer, shows no heading-dependent moment.
    CurrentOrLeeway {
        /// p-value of the yaw channel's heading-dependent moment (absent: ≥ α).
        p_moment: f64,
        /// Where course over ground is logged: the ground track's set across the heading as
        /// a ratio of its set along it, and that ratio's standard error — about 1 for a
        /// uniform current, well under for a wind's drag and leeway; it did not decide.
        #[serde(skip_serializing_if = "Option::is_none")]
        set_ratio: Option<[f64; 2]>,
    },
    /// A current named from speed over ground alone on trials that each hold one course,
    /// with no anemometer: the yaw channel cannot tell a heading-dependent moment from the
    /// manoeuvre's own (docs/method.md, "Records that each hold one course"), so nothing in
    /// the records tells a current from a wind.
    CurrentOrWind {
        /// The least share of the heading harmonics' variance the trials keep beyond each
        /// record's own offset and turn (under 0.005).
        separation: f64,
    },
    /// A steady moment named (first or second) on trials that each hold one course, with
    /// no anemometer: over one course a wind from one side turns the ship as a steady moment
    /// does, and the yaw channel, which tells a moment varying with heading, cannot
    /// (docs/method.md, "Records that each hold one course"). The records cannot tell a
    /// steady moment from a wind.
    BiasOrWind {
        /// The share of the heading harmonics' variance the trials keep beyond each record's
        /// own offset and turn (under 0.005).
        separation: f64,
        /// Where the trial records' courses were compared (`diagnose::course`): the widest
        /// angle between two of them (deg) and the p-value of a moment that changes across
        /// them (not significant: else wind would be named).
        #[serde(skip_serializing_if = "Option::is_none")]
        across: Option<[f64; 2]>,
    },
    /// An angle limit or a dead band named (first or second) on trials whose commands hold
    /// one magnitude — a zig-zag's ±20°: a limit below it and a dead band take the same off
    /// every command, and the records cannot tell them apart.
    ClipOrDeadBand {
        /// The one magnitude (deg).
        magnitude_deg: f64,
        /// Share of the commanded samples (|δ| > 0) within 5 % of it.
        share: f64,
        /// The held-out gains (pp, at 10 steps and in simulation) of the hull's nonlinear
        /// damping, where it is significant, improves prediction and is not named: on
        /// commands of one magnitude every swing turns about as fast, so a damping growing
        /// with the rate takes about as much off each as a limit or a band does.
        #[serde(skip_serializing_if = "Option::is_none")]
        damping_gains_pp: Option<[f64; 2]>,
    },
    /// A port/starboard asymmetry or a steady moment named (first or second) on trials whose
    /// commands hold one magnitude A: there an asymmetry is a steady moment and a changed
    /// rudder effectiveness, and only that change tells the two apart.
    AsymmetryOrBias {
        /// The one magnitude (deg).
        magnitude_deg: f64,
        /// Share of the commanded samples (|δ| > 0) within 5 % of it.
        share: f64,
    },
    /// A slew limit or a dead time named (first or second) on trials whose command changes
    /// hold one size — a zig-zag's 40° swings: a slew limit then delays every change by the
    /// same time, as a dead time does, and the two differ only in the ramp's shape.
    SlewOrDeadTime {
        /// The one size of change (deg).
        step_deg: f64,
        /// Share of the command's changes (those of a tenth of the largest or more) within
        /// 5 % of it.
        share: f64,
    },
    /// The trials were sailed with other commands than the reference: half or more of their
    /// command magnitudes lie where the reference's do not (a zig-zag's ±20° against a
    /// PRBS), and a linear model meets the hull's own nonlinearity differently there.
    OtherManoeuvre {
        /// Total-variation distance between the two sets' distributions of |δ| in 1° bins
        /// (0: alike, 1: disjoint).
        distance: f64,
        /// The hull physics of the ship's own the reference records show, which the
        /// bootstrap's nulls then simulate on the trials' commands and the reference's
        /// (each in words; empty when the reference shows none).
        hull: Vec<String>,
    },
    /// One set's commands step where the other's inputs never move so fast: its largest
    /// change over one sample is 3 times the other's or more (one set logs the rudder's
    /// angle, the other the command). The set that never steps
    /// cannot show how the ship answers a step, and a steering gear lies between the two:
    /// where the trials step, a slew limit is judged against the reference's own spread.
    CommandSteps {
        /// The trials' largest change of δ over one sample (deg).
        trial_step_deg: f64,
        /// The reference's (deg).
        reference_step_deg: f64,
        /// The smaller of the two over the sample time (deg/s): the fastest the slower
        /// set's inputs move.
        slew_degps: f64,
    },
    /// The model's 10-step prediction carries white noise on the yaw rate many times over,
    /// and the trials' noise (far above the reference's) so carried is what their 10-step
    /// errors are (`noise.rs`).
    NoiseGain {
        /// [`crate::identify::predict::noise_gain`] at 10 steps.
        gain_10: f64,
        /// The white noise on the trials' yaw rate, from its fourth differences (°/s).
        trials_noise_degps: f64,
        /// The trials' 10-step error (°/s).
        trials_ten_step_degps: f64,
        /// The white noise on the reference's yaw rate (°/s).
        reference_noise_degps: f64,
    },
    /// The trials' yaw rate is noisier than the reference's (twice or more): the reference
    /// records were given the difference as white noise and the model's Kalman gain
    /// re-fitted on them (`noise.rs`); the statistics are measured against those.
    NoisierTrials {
        /// The white noise on the trials' yaw rate, from its fourth differences (°/s).
        trials_noise_degps: f64,
        /// On the reference's as given (°/s).
        reference_noise_degps: f64,
        /// The white noise added to the reference's yaw rate (°/s).
        added_noise_degps: f64,
        /// The model given's noise gain at 10 steps ([`crate::identify::predict::noise_gain`]).
        gain_10_given: f64,
        /// The re-fitted model's.
        gain_10: f64,
    },
    /// The reference's yaw rate is noisier than the trials' (twice or more): the trials were
    /// given the difference as white noise for the statistics (`noise.rs`).
    QuieterTrials {
        /// The white noise on the trials' yaw rate as logged, from its fourth differences (°/s).
        trials_noise_degps: f64,
        /// On the reference's (°/s).
        reference_noise_degps: f64,
        /// The white noise added to the trials' yaw rate (°/s).
        added_noise_degps: f64,
    },
    /// The trials ran at another speed than the reference, by [`OTHER_SPEED`] or more of
    /// the reference's: a hull's rudder gain and time constants change with speed through
    /// the water, which the library's effects can only mimic. Either the difference exceeds
    /// the smallest current the ground track can show ([`Caveat::CurrentResolution`]), so it
    /// is the speed through the water; or it does not — records that each hold one course,
    /// on courses too alike to read a current across them, cannot tell a current along
    /// them from the speed — and the caveat says both. Given only
    /// for trials sailed with commands like the reference's (no
    /// [`Caveat::OtherManoeuvre`]): a zig-zag's straight speed is an extrapolation.
    OtherSpeed {
        /// The trials' speed straight ahead (m/s): through the water where
        /// `told_from_current` (speed over ground less the current the ground track shows —
        /// its heading harmonics, or on records that each hold one course the current read
        /// across their courses — and the speed lost in turns), else over the ground on
        /// their courses (less the speed lost in turns only).
        trials_mps: f64,
        /// The reference's (m/s), read the same way.
        reference_mps: f64,
        /// Whether the ground track tells the difference from a current: `false` where a
        /// current along the courses sailed as large as the difference could not be told.
        told_from_current: bool,
    },
    /// The trials ran at another speed over the ground ([`Caveat::OtherSpeed`]); the
    /// reference re-timed to theirs by similarity (time divided by `ratio`, yaw rate and
    /// speeds times it: a hull's manoeuvres at another speed are the same in distance
    /// sailed) and the model re-identified on it predict the trials 10 steps ahead by 1 pp
    /// or more better than the model given (`shows_speed`: the hull answers the helm as at
    /// the trials' speed, so the difference is the speed through the water), or not (more
    /// likely a current along the courses, which changes the speed over the ground only).
    SpeedSimilar {
        /// The trials' speed over the reference's.
        ratio: f64,
        /// The model given: 10-step fit (%) on the trials.
        fit_10_given_pct: f64,
        /// The model re-identified on the re-timed reference: 10-step fit (%) on the trials.
        fit_10_similar_pct: f64,
        /// Whether it predicts them 1 pp or more better: the speed through the water differs.
        shows_speed: bool,
    },
    /// The trials ran at another speed through the water ([`Caveat::SpeedSimilar`]'s
    /// `shows_speed`), so every statistic was measured against the reference re-timed to
    /// their speed and the model given's structure identified on it: against the reference
    /// as given, the hull's own change with speed reads as an effect.
    AtTrialsSpeed {
        /// The trials' speed over the reference's.
        ratio: f64,
        /// The verdict against the reference as given.
        verdict_as_given: String,
        /// Its second effect, where it had one.
        #[serde(skip_serializing_if = "Option::is_none")]
        then_as_given: Option<String>,
    },
    /// The reference records show more of a current or wind than the trials — their own
    /// heading harmonics of the ground velocity, or the anemometer's true wind, the larger —
    /// and the change between the two is significant: a current or wind the reference
    /// sailed in and the trials did not. That change is not counted towards a current or
    /// wind in the trials (a missing effect is one the trials show more of).
    ReferenceEnvironment {
        /// Each set's own heading harmonics of the ground velocity (m/s, root-sum-square):
        /// `[trials, reference]`, where the ground track's change is the reference's.
        #[serde(skip_serializing_if = "Option::is_none")]
        ground_mps: Option<[f64; 2]>,
        /// Each set's own mean true wind (m/s): `[trials, reference]`, where the
        /// anemometer's change is the reference's.
        #[serde(skip_serializing_if = "Option::is_none")]
        wind_mps: Option<[f64; 2]>,
    },
    /// A significant effect that does not improve held-out prediction was named behind
    /// the verdict by the ranking rule.
    PassedOver {
        /// Its name.
        effect: String,
    },
    /// An effect with the larger likelihood statistic was named behind one that predicts the
    /// held-out records better both at 10 steps and in simulation (the ranking rule's second
    /// clause).
    Outpredicted {
        /// Its name.
        effect: String,
        /// Its held-out gains (pp) at 10 steps and in simulation.
        gains_pp: [f64; 2],
        /// The effect named ahead of it.
        by: String,
        /// That effect's held-out gains (pp) at 10 steps and in simulation.
        by_gains_pp: [f64; 2],
    },
}

impl Caveat {
    /// The caveat in words, as the explanation appends it.
    ///
    /// ```
    /// use yawcast::diagnose::Caveat;
    /// assert!(Caveat::NoReference.explain().starts_with("No reference records were given"));
    /// // three 30-min records at 10 Hz a set: at 0.5 s they would be read whole
    /// let c = Caveat::Blocks { trials: 6, reference: 6, held_out: 0, resample_s: Some(0.5) };
    /// assert!(c.explain().contains("`--resample 0.5` on identify and on diagnose"));
    /// // a model-scale ship's resolution in mm/s, not rounded to 0.00
    /// let c = Caveat::CurrentResolution { smallest_mps: 0.00226 };
    /// assert!(c.explain().contains("only from about 0.00226 m/s on"), "{}", c.explain());
    /// ```
    pub fn explain(&self) -> String {
        match self {
            Caveat::ReferenceOffset { words } | Caveat::ReferenceGear { words } => {
                words.trim().to_string()
            }
            Caveat::Blocks {
                trials,
                reference,
                held_out,
                resample_s,
            } => {
                let mut w = format!(
                    "Records of more than {WINDOW} samples per set are diagnosed on blocks of \
                     up to {WINDOW_BLOCK} samples spread evenly over them ({trials} of the \
                     trials, {reference} of the reference, {held_out} of the held-out \
                     records; 0: used whole); the heading, speed-over-ground and anemometer \
                     channels read the records whole."
                );
                if let Some(step) = resample_s {
                    let step = sig(*step);
                    w.push_str(&format!(
                        " The slow effects (a steady moment, a gyro offset, wind, a current) \
                         show with the span of the records read, so on blocks a weak one can \
                         go unseen: resampled to {step} s (`--resample {step}` on identify and \
                         on diagnose) every set is read whole, while a dead time or a slew \
                         limit is best judged at the sample time logged."
                    ));
                }
                w
            }
            Caveat::OtherSpeed {
                trials_mps,
                reference_mps,
                told_from_current,
            } => {
                let pct = 100.0 * (trials_mps / reference_mps - 1.0);
                let (t, r) = (sig(*trials_mps), sig(*reference_mps));
                let speed = "a hull's rudder gain and time constants change with speed, and \
                    the library's effects can only mimic that, so an angle limit, a dead band, \
                    an asymmetry or damping named here may be the speed";
                let remedy = format!(
                    "Sail the reference at the trials' speed (in a ship file, the propeller \
                     revolutions; on a test world, `simulate --speed {t}`)"
                );
                if *told_from_current {
                    format!(
                        "The trials ran straight at {t} m/s through the water and the \
                         reference at {r} m/s ({pct:+.0} %; speed over ground less the \
                         current the ground track shows and the speed lost in turns): \
                         {speed}. {remedy}."
                    )
                } else {
                    format!(
                        "The trials ran straight at {t} m/s over the ground on their courses \
                         and the reference at {r} m/s ({pct:+.0} %; less the speed lost in \
                         turns). The ground track cannot tell which: another speed through \
                         the water, or a current of about {} m/s along the courses the \
                         trials held. If the speed, {speed}. {remedy}; if the trials sailed \
                         at the reference's speed through the water, the difference is a \
                         current.",
                        sig((trials_mps - reference_mps).abs())
                    )
                }
            }
            Caveat::SpeedSimilar {
                ratio,
                fit_10_given_pct,
                fit_10_similar_pct,
                shows_speed,
            } => {
                let what = format!(
                    "The reference re-timed to the trials' speed by similarity (×{}: a hull's \
                     manoeuvres at another speed are the same in distance sailed, so time is \
                     divided by that and yaw rate and speeds multiplied) and the model \
                     re-identified on it predict the trials 10 steps ahead at {:.1} % against \
                     {:.1} % for the model given",
                    sig(*ratio),
                    fit_10_similar_pct,
                    fit_10_given_pct
                );
                if *shows_speed {
                    format!(
                        "{what}: the hull answers the helm as at the trials' speed, which a \
                         current would not change, so the trials ran at another speed through \
                         the water."
                    )
                } else {
                    format!(
                        "{what}: no better by {GAIN_PP} pp, so the difference is more likely a \
                         current along the courses, which changes the speed over the ground \
                         and not how the hull answers the helm."
                    )
                }
            }
            Caveat::AtTrialsSpeed {
                ratio,
                verdict_as_given,
                then_as_given,
            } => {
                let given = match then_as_given {
                    Some(t) => format!("`{verdict_as_given}, then {t}`"),
                    None => format!("`{verdict_as_given}`"),
                };
                format!(
                    "So every statistic is measured against the reference re-timed to the \
                     trials' speed (×{}) and the model given's structure identified on it: \
                     against the reference as given, the hull's own change with speed reads as \
                     an effect (the verdict there: {given}). Similarity holds to first order, \
                     and the re-timed records scale the steering gear's slew rate and dead time \
                     with the hull, which a real gear keeps: a reference sailed at the trials' \
                     speed is the stronger test.",
                    sig(*ratio)
                )
            }
            Caveat::NoReference => "No reference records were given, so every statistic is \
                judged against the model alone: hull nonlinearity the model never had shows up \
                as an effect, and the verdict is weaker."
                .into(),
            Caveat::ForeignModel { excess_pct } => format!(
                "The model does not look identified from the reference records: its one-step \
                 error there is {excess_pct:.0} % above that of the same structure re-identified \
                 on them, and it predicts the trials better than that model does. A model \
                 identified or tuned on the trials has absorbed part of what they show (an \
                 actuator limit above all), so the evidence is weaker; the strongest test uses \
                 the model identified on the reference records."
            ),
            Caveat::NoHeading => "Heading is not logged in every record: a gyro bias cannot be \
                told apart from a constant yaw moment (bias), and wind and current are tested on \
                the heading integrated from the measured yaw rate, from an unknown start (0°) \
                and drifting with any rate offset."
                .into(),
            Caveat::NoSpeedOverGround => "Speed over ground (or heading) is not logged in every \
                record: current and wind are judged from the yaw rate alone and are hard to tell \
                apart from a bias."
                .into(),
            Caveat::CurrentResolution { smallest_mps } => format!(
                "Speed over ground on these records shows a current only from about {} m/s \
                 on (in any direction, at the level applied: the headings sailed and the speed \
                 lost in turns limit it); a weaker current cannot be told.",
                super::augment::sig(*smallest_mps)
            ),
            Caveat::MomentResolution { smallest_deg } => format!(
                "The trials' {h}-step prediction errors show a steady yaw moment only from \
                 about {}° of rudder/pod angle on, either way (at the level applied, against \
                 its null: a moment that size reaches it about half the time); a weaker one \
                 cannot be told from these records.",
                sig(*smallest_deg),
                h = super::SLOW_HORIZON
            ),
            Caveat::WindResolution { smallest_deg } => format!(
                "The trials' {h}-step prediction errors show a yaw moment varying once per \
                 turn of heading, as a wind's does, only from an amplitude of about {}° of \
                 rudder/pod angle on (from the direction these headings show least, at the \
                 level applied against its null); a weaker wind cannot be told from these \
                 records without an anemometer.",
                sig(*smallest_deg),
                h = super::SLOW_HORIZON
            ),
            Caveat::CurrentOrLeeway {
                p_moment,
                set_ratio,
            } => format!(
                "The current is seen on the ground track alone and no anemometer is logged: \
                 the wind's leeway sets a ship over ground as a current does, and the yaw \
                 channel shows no heading-dependent moment (p {}) that would tell a wind.{} The \
                 records cannot tell a current from the leeway of a wind too weak to turn the \
                 ship; the anemometer's columns (apparent wind speed and angle) would.",
                fmt_p(*p_moment),
                set_ratio.map_or(String::new(), |[ratio, se]| SetShape { ratio, se }
                    .lean_words())
            ),
            Caveat::CurrentOrWind { separation } => format!(
                "The current is seen on the ground track alone, no anemometer is logged, and \
                 the trials each hold one course (the heading harmonics keep {:.2} % of their \
                 variance beyond each record's own offset and turn): over them the yaw \
                 channel cannot tell a moment varying with heading from the manoeuvre's own. \
                 The records cannot tell a current from a wind; the anemometer's columns, or \
                 trials on several courses (a zig-zag or a PRBS on each of four headings), \
                 would.",
                100.0 * separation
            ),
            Caveat::BiasOrWind { separation, across } => match across {
                None => format!(
                    "The steady moment is named on trials that each hold one course (the \
                     heading harmonics keep {:.2} % of their variance beyond each record's own \
                     offset and turn) and no anemometer is logged: over one course a wind from \
                     one side turns the ship as a steady moment does, and only a change of \
                     course would change its moment. The records cannot tell a steady moment \
                     from a wind; the anemometer's columns, or trials on several courses (a \
                     zig-zag or a PRBS on each of four headings), would.",
                    100.0 * separation
                ),
                Some([span, p]) => format!(
                    "The steady moment is named on trials that each hold one course (the \
                     heading harmonics keep {:.2} % of their variance beyond each record's own \
                     offset and turn) and no anemometer is logged: over one course a wind from \
                     one side turns the ship as a steady moment does, and only a change of \
                     course changes its moment. Across the trials' courses, at most {span:.0}° \
                     apart, the moment does not change beyond the records' noise (p {}); a \
                     wind whose moment is alike on those courses is not ruled out. The \
                     anemometer's columns, or trials on courses further apart, would tell.",
                    100.0 * separation,
                    fmt_p(*p)
                ),
            },
            Caveat::ClipOrDeadBand {
                magnitude_deg,
                share,
                damping_gains_pp,
            } => {
                let damping = damping_gains_pp.map_or(String::new(), |[g10, gsim]| {
                    format!(
                        " The hull's nonlinear damping is significant too (held-out {g10:+.1} \
                         pp at 10 steps, {gsim:+.1} in simulation): every swing of one size \
                         turns about as fast, so a damping growing with the rate takes about \
                         as much off each; the records may not tell it from either."
                    )
                });
                format!(
                    "The trials' commands hold one magnitude (±{magnitude_deg:.1}° in {:.0} % \
                     of the commanded samples): an angle limit below it and a dead band take \
                     the same off every such command and differ only in how the gear moves \
                     between them, which the model approximates. The records cannot tell a \
                     saturation from a dead band; commands of several magnitudes would (a PRBS, \
                     or zig-zags of two amplitudes).{damping}",
                    100.0 * share
                )
            }
            Caveat::AsymmetryOrBias {
                magnitude_deg,
                share,
            } => format!(
                "The trials' commands hold one magnitude (±{magnitude_deg:.1}° in {:.0} % of \
                 the commanded samples): there a port/starboard asymmetry β (a gain on \
                 max(δ, 0)) is a steady moment of β·{magnitude_deg:.1}°/2 and a rudder \
                 effectiveness changed by β/2, and only that change, which the hull's own \
                 nonlinearity also makes, tells it from a steady moment. The records may not \
                 tell an asymmetry from a steady moment; commands of several magnitudes would.",
                100.0 * share
            ),
            Caveat::SlewOrDeadTime { step_deg, share } => format!(
                "The trials' command changes hold one size ({step_deg:.1}° in {:.0} % of the \
                 changes): a slew limit takes the same time over every such change, so it \
                 delays each swing by one time as a dead time does, and the two differ only in \
                 the shape of the gear's ramp, which a slow hull hardly shows. The records may \
                 not tell a slew limit from a dead time; changes of several sizes would (a \
                 PRBS, or zig-zags of two amplitudes).",
                100.0 * share
            ),
            Caveat::ReferenceEnvironment {
                ground_mps,
                wind_mps,
            } => {
                let mut shown = Vec::new();
                if let Some([t, r]) = ground_mps {
                    shown.push(format!(
                        "speed and course over ground vary with heading by ±{r:.3} m/s on the \
                         reference, ±{t:.3} m/s on the trials"
                    ));
                }
                if let Some([t, r]) = wind_mps {
                    shown.push(format!(
                        "the anemometer shows a true wind of {r:.2} m/s on the reference, \
                         {t:.2} m/s on the trials"
                    ));
                }
                format!(
                    "The reference records show more current or wind than the trials ({}): \
                     the difference is one the reference sailed in and the trials did not, \
                     and it is not counted towards a current or wind in the trials. A model \
                     identified on those records may carry the steady part of that wind as a \
                     steady moment; records sailed in the trials' conditions make a better \
                     reference.",
                    shown.join("; ")
                )
            }
            Caveat::CommandSteps {
                trial_step_deg,
                reference_step_deg,
                slew_degps,
            } => super::commands::steps_words(*trial_step_deg, *reference_step_deg, *slew_degps),
            Caveat::NoiseGain { .. } => super::noise::words(self),
            Caveat::NoisierTrials { .. } => super::noise::matched_words(self),
            Caveat::QuieterTrials { .. } => super::noise::quieted_words(self),
            Caveat::OtherManoeuvre { distance, hull } => {
                let nulls = if hull.is_empty() {
                    "The reference records show no hull physics of their own that the null \
                     distributions could simulate on the trials' commands, and the \
                     reference's own spread, which the statistics are also judged against, \
                     does not measure that."
                        .to_string()
                } else {
                    format!(
                        "So the null distributions simulate the hull physics the reference \
                         records show of their own ({}, re-identified on the reference) on the \
                         trials' commands as well as the reference's; what that physics does \
                         not capture of the hull at the trials' commands can still read as an \
                         effect.",
                        hull.join(", ")
                    )
                };
                format!(
                    "The trials were sailed with other commands than the reference ({:.0} % of \
                     their command magnitudes lie where the reference's do not, 1° bins): a \
                     linear model meets the hull's own nonlinearity differently on other \
                     commands. {nulls} An actuator or hull effect named may be the hull's own; \
                     sail the reference with the trials' manoeuvre.",
                    100.0 * distance
                )
            }
            Caveat::PassedOver { effect } => {
                let kind = EffectKind::from_name(effect);
                format!(
                    "Note: {} ({effect}) is significant but does not improve held-out \
                     prediction; by the ranking rule no effect that does not improve prediction \
                     (< {NO_GAIN_PP} pp at 10 steps and in simulation) is named ahead of one \
                     that does (≥ {GAIN_PP} pp at its own horizon; behind a sensor offset, at \
                     any).",
                    kind.map_or("an effect", effect_phrase)
                )
            }
            Caveat::Outpredicted {
                effect,
                gains_pp,
                by,
                by_gains_pp,
            } => {
                let kind = EffectKind::from_name(effect);
                format!(
                    "Note: {} ({effect}) has the larger likelihood statistic but predicts the \
                     held-out records worse than {by} at 10 steps ({:+.2} pp against {:+.2}) \
                     and in simulation ({:+.2} pp against {:+.2}); by the ranking rule an \
                     effect that predicts worse at both horizons (by {NO_GAIN_PP} pp or more \
                     at one) is not named ahead.",
                    kind.map_or("an effect", effect_phrase),
                    gains_pp[0],
                    by_gains_pp[0],
                    gains_pp[1],
                    by_gains_pp[1],
                )
            }
        }
    }
}

/// Appends the words of `caveats` to `explanation`, in their order, each after a space.
pub(super) fn append_words(explanation: &mut String, caveats: &[Caveat]) {
    for c in caveats {
        explanation.push(' ');
        explanation.push_str(&c.explain());
    }
}

/// The caveats of a diagnosis, in the order the explanation gives them.
pub(super) fn caveats(
    offset_words: Option<&str>,
    gear_words: Option<&str>,
    records: [&[Record]; 3],
    windows: &[Option<Vec<Record>>; 3],
    has_ref: bool,
    foreign_pct: Option<f64>,
    ch: &Channels,
) -> Vec<Caveat> {
    let mut out = Vec::new();
    if let Some(w) = offset_words {
        out.push(Caveat::ReferenceOffset { words: w.into() });
    }
    if let Some(w) = gear_words {
        out.push(Caveat::ReferenceGear { words: w.into() });
    }
    if windows.iter().any(Option::is_some) {
        let count = |w: &Option<Vec<Record>>| w.as_ref().map_or(0, Vec::len);
        out.push(Caveat::Blocks {
            trials: count(&windows[0]),
            reference: count(&windows[1]),
            held_out: count(&windows[2]),
            resample_s: resample_step(records),
        });
    }
    if !has_ref {
        out.push(Caveat::NoReference);
    }
    if let Some(excess_pct) = foreign_pct {
        out.push(Caveat::ForeignModel { excess_pct });
    }
    if !ch.heading_ok {
        out.push(Caveat::NoHeading);
    }
    if !ch.speed_ok {
        out.push(Caveat::NoSpeedOverGround);
    }
    out
}

/// Relative difference of the trials' and the reference's speed through the water from which
/// [`Caveat::OtherSpeed`] is given. On the cross-world suite's PRBS trials with hidden
/// currents (up to 1.4 m/s), winds or nothing hidden (45 sets, their own seeds and noise) the
/// two differ by at most 5.7 %; the built-in ship's trials sailed with the propeller turning
/// 8.0 instead of 10.5 rev/s, by 24 %.
pub const OTHER_SPEED: f64 = 0.15;

/// [`Caveat::OtherSpeed`] for the speeds `[trials, reference]` when they differ by
/// [`OTHER_SPEED`] or more: through the water (`speeds`, [`super::channels::straight_speed`])
/// where they differ by more than `resolution` (m/s), the smallest current the ground track
/// shows; else over the ground on the courses sailed (`course`,
/// [`super::channels::course_speed`]) where those differ by no more than it, saying that a
/// current along the courses could be the difference.
pub(super) fn other_speed(
    speeds: Option<[f64; 2]>,
    course: Option<[f64; 2]>,
    resolution: f64,
) -> Option<Caveat> {
    let differ = |s: &[f64; 2]| s[1] > 0.0 && (s[0] / s[1] - 1.0).abs() >= OTHER_SPEED;
    let told = |s: &[f64; 2]| (s[0] - s[1]).abs() > resolution;
    let caveat = |[t, r]: [f64; 2], told_from_current| Caveat::OtherSpeed {
        trials_mps: t,
        reference_mps: r,
        told_from_current,
    };
    match speeds.filter(|s| differ(s) && told(s)) {
        Some(s) => Some(caveat(s, true)),
        None => course
            .filter(|s| differ(s) && !told(s))
            .map(|s| caveat(s, false)),
    }
}

/// The sample time [`Caveat::Blocks`] suggests for `sets` (trials, reference, held-out):
/// the smallest whole multiple `k·Ts` of the records' at which every set holds at most
/// [`WINDOW`] samples, or `None` when a record would then hold fewer than [`MIN_SAMPLES`] (or
/// no set needs blocks).
fn resample_step(sets: [&[Record]; 3]) -> Option<f64> {
    let ts = sets.iter().flat_map(|s| s.iter()).next()?.ts;
    let most = sets
        .iter()
        .map(|s| s.iter().map(Record::len).sum::<usize>())
        .max()?;
    let k = most.div_ceil(WINDOW);
    let long = sets
        .iter()
        .flat_map(|s| s.iter())
        .all(|r| r.len() / k >= MIN_SAMPLES);
    (k > 1 && long).then_some(k as f64 * ts)
}

/// The caveat for a current named from the ground track alone without an anemometer
/// ([`Caveat::CurrentOrLeeway`], or [`Caveat::CurrentOrWind`] where the yaw channel is not
/// counted): of the effects `named` (the verdict's evidence, then its second effect's), a
/// current that the yaw channel's heading-dependent moment set apart from wind
/// ([`super::verdict::current_or_wind`]) and found absent, or could not (`separation`: the
/// trials' [`super::separation::heading_separation`]); with the ground track's `shape`,
/// where it was read and did not decide ([`SetShape::of_channels`]).
pub(super) fn current_without_anemometer<'a>(
    named: impl IntoIterator<Item = &'a Evidence>,
    separation: Option<f64>,
    shape: Option<SetShape>,
) -> Option<Caveat> {
    named
        .into_iter()
        .filter(|e| e.kind == EffectKind::Current && e.speed_only)
        .find_map(|e| e.moment)
        .map(|m| match m {
            Moment::Tested(p_moment) => Caveat::CurrentOrLeeway {
                p_moment,
                set_ratio: shape.map(|s| [s.ratio, s.se]),
            },
            Moment::NotCounted => Caveat::CurrentOrWind {
                separation: separation.unwrap_or(0.0),
            },
        })
}

/// [`Caveat::ReferenceEnvironment`] where the ground track or the anemometer shows a change
/// significant at `level` (as a current's test or a wind's) whose larger part is the
/// reference's own (none without a reference: its own harmonics and wind are then 0).
pub(super) fn reference_environment(ch: &Channels, level: f64) -> Option<Caveat> {
    let ground_mps = ch
        .sog
        .filter(|s| s.the_references())
        .filter(|s| s.test(true).2 < level || s.test(false).2 < level)
        .map(|s| s.own);
    let wind_mps = ch
        .anemometer
        .filter(|a| a.the_references() && a.p < level)
        .map(|a| a.own);
    (ground_mps.is_some() || wind_mps.is_some()).then_some(Caveat::ReferenceEnvironment {
        ground_mps,
        wind_mps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recs(ts: f64, n: usize, k: usize) -> Vec<Record> {
        (0..k)
            .map(|i| Record::from_uy(&format!("r{i}"), ts, vec![0.0; n], vec![0.0; n]))
            .collect()
    }

    #[test]
    fn blocks_say_at_what_sample_time_the_sets_would_be_read_whole() {
        // three 30-min records a set at 10 Hz: 54 000 samples, whole at 0.5 s (10 800)
        let (trials, reference) = (recs(0.1, 18_000, 3), recs(0.1, 18_000, 3));
        let step = resample_step([&trials, &reference, &[]]).expect("a step");
        assert_eq!(step.to_bits(), 0.5f64.to_bits());
        let c = Caveat::Blocks {
            trials: 6,
            reference: 6,
            held_out: 0,
            resample_s: Some(step),
        };
        assert!(
            c.explain().contains("resampled to 0.5 s (`--resample 0.5`"),
            "{}",
            c.explain()
        );
        // at 4 Hz, 21 600 samples a set: 0.5 s
        let four = recs(0.25, 7_200, 3);
        assert_eq!(resample_step([&four, &four, &[]]), Some(0.5));
        // a set that fits is read whole: nothing to suggest
        assert_eq!(resample_step([&recs(1.0, 1_800, 3), &[], &[]]), None);
        // ten 1-h records at 1 Hz (36 000) would be whole at 3 s, each record 1 200 long
        assert_eq!(resample_step([&recs(1.0, 3_600, 10), &[], &[]]), Some(3.0));
        // one short record among long ones: resampled it would fall under MIN_SAMPLES
        let mut mixed = recs(0.25, 7_200, 3);
        mixed.push(recs(0.25, 300, 1).remove(0));
        assert_eq!(resample_step([&mixed, &[], &[]]), None);
        // without blocks the caveat has no such sentence
        let plain = Caveat::Blocks {
            trials: 6,
            reference: 0,
            held_out: 0,
            resample_s: None,
        };
        assert!(!plain.explain().contains("resample"), "{}", plain.explain());
    }
}
