//! The types of the effect registry: an effect's [`Def`] (role, channel, gains, grids), the
//! records' span its grids are laid over, and the knobs of the simulators' physics.

use yawcast_shared::model::EffectKind;

use super::{Effect, SimEffect};

/// Where an effect enters the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Transforms the command before it reaches the hull (`ũ`); a structural parameter is
    /// searched on a grid. `dynamics`: it changes *when* the rudder/pod angle arrives (a
    /// delay or a slow gear, which a linear model partly absorbs into its poles), rather
    /// than how far it goes.
    Actuator {
        /// A gear dynamics effect (see above).
        dynamics: bool,
    },
    /// Adds `β φ` to the effective input; the gains are estimated.
    Regressor,
    /// An offset on the measured output (`y = x₁ + d_y`).
    Output,
}

/// The channel besides the yaw rate that carries an effect's own evidence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Only the yaw rate.
    None,
    /// The heading: the rate gyro's reading against the turn of the compass heading.
    Heading,
    /// Speed over ground against heading (its harmonics).
    SpeedOverGround,
}

/// What one effect gain multiplies (the regressor `φ`, or the output offset).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regressor {
    /// `φ = 1`.
    One,
    /// The output offset `d_y` (not part of `v`).
    Offset,
    /// `φ = max(ũ, 0)`.
    Starboard,
    /// `φ = y|y|` or `y³`.
    Damping,
    /// `φ = sin 2ψ`.
    Sin2,
    /// `φ = cos 2ψ`.
    Cos2,
    /// `φ = sin ψ`.
    Sin1,
    /// `φ = cos ψ`.
    Cos1,
}

/// The records' range the grids are laid over.
#[derive(Debug, Clone, Default)]
pub struct GridSpan {
    /// Sample time (s).
    pub ts: f64,
    /// Largest |command| (deg).
    pub u_max: f64,
    /// Largest command step between samples (deg).
    pub du_max: f64,
    /// Length of the shortest record (samples).
    pub shortest: usize,
    /// Every |command|, sorted ascending (for quantiles).
    pub abs_u: Vec<f64>,
}

impl GridSpan {
    /// The span of the commands of `records` (`u` of each), sampled at `ts`.
    ///
    /// ```
    /// use yawcast::effects::GridSpan;
    /// let g = GridSpan::of(1.0, [&[0.0, 3.0, -1.0][..]]);
    /// assert_eq!((g.u_max, g.du_max, g.shortest), (3.0, 4.0, 3));
    /// ```
    pub fn of<'a>(ts: f64, records: impl IntoIterator<Item = &'a [f64]>) -> GridSpan {
        let mut g = GridSpan {
            ts,
            shortest: usize::MAX,
            ..GridSpan::default()
        };
        for u in records {
            g.shortest = g.shortest.min(u.len());
            for w in u.windows(2) {
                g.du_max = g.du_max.max((w[1] - w[0]).abs());
            }
            g.abs_u.extend(u.iter().map(|v| v.abs()));
        }
        if g.shortest == usize::MAX {
            g.shortest = 0;
        }
        g.abs_u.sort_by(f64::total_cmp);
        g.u_max = g.abs_u.last().copied().unwrap_or(0.0);
        g
    }
}

/// The definition of one kind: what every part of the host needs to know of it that is not
/// a parameter value.
#[derive(Debug)]
pub struct Def {
    /// The kind.
    pub kind: EffectKind,
    /// The effect in a few words ("a command dead time"), as verdicts and reports name it.
    pub phrase: &'static str,
    /// Where it enters the model.
    pub role: Role,
    /// Physics of the ship's own, present on every record it sails, that a linear model
    /// lacks and the reference records can show: `augment --effect auto` adds what they
    /// show ([`crate::diagnose::augment::own_base`]) — the hull's nonlinear damping, a
    /// rudder asymmetry, the gear's limits and dynamics (the dynamics from diagnose). Not
    /// the day's wind, current, steady moment or sensor offset. On a hull whose turn grows
    /// less than linearly with the angle an angle limit re-identified on the reference
    /// stands for that hull physics, and the words say so.
    pub own: bool,
    /// The channel besides the yaw rate that shows it.
    pub channel: Channel,
    /// Judged on the long-horizon errors (a slow, steady effect) rather than the one-step
    /// errors.
    pub slow: bool,
    /// The names and regressors of its estimated gains, in parameter order.
    pub gains: &'static [(&'static str, Regressor)],
    /// The canonical hidden effect at a strength (1 full, 0.5 half; > 0, finite).
    pub hidden: fn(f64) -> SimEffect,
    /// Diagnose's candidates: the versions searched, gains zero.
    pub candidates: fn(&GridSpan) -> Vec<Effect>,
    /// Augment's structural search values (empty when the effect has none).
    pub search: fn(&GridSpan) -> Vec<f64>,
}

/// One value per step of a geometric grid from `lo` to `hi` (`n` ≥ 2 values); `[hi]` (at
/// least 1e-6) when the range is empty.
pub(crate) fn geometric(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo) {
        return vec![hi.max(1e-6)];
    }
    let r = (hi / lo).powf(1.0 / (n - 1) as f64);
    (0..n).map(|i| lo * r.powi(i as i32)).collect()
}

pub(super) fn no_search(_: &GridSpan) -> Vec<f64> {
    Vec::new()
}

/// What the simulators' physics read from the effects switched on: each effect sets its
/// knobs ([`SimEffect::apply`]), each simulator reads them on top of its own hull and gear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimKnobs {
    /// Extra command delay (s).
    pub dead_time_s: f64,
    /// Angle limit (deg), the smallest of the effects' (infinite without one).
    pub limit_deg: f64,
    /// Largest pod rate (deg/s), the smallest of the effects' (infinite without one).
    pub max_rate_degps: f64,
    /// Dead band width (deg).
    pub band_deg: f64,
    /// Constant yaw moment (N·m).
    pub yaw_moment_nm: f64,
    /// Rate-gyro offset (deg/s).
    pub gyro_bias_degps: f64,
    /// Relative extra pod effectiveness to starboard.
    pub starboard_gain: f64,
    /// Extra Norrbin damping coefficient.
    pub n_rr: f64,
    /// The damping is cubic.
    pub cubic: bool,
    /// True wind velocity, north/east components (m/s; the direction it blows *to*).
    pub wind_ne: (f64, f64),
    /// Current velocity, north/east components (m/s).
    pub current_ne: (f64, f64),
}

impl Default for SimKnobs {
    fn default() -> SimKnobs {
        SimKnobs {
            dead_time_s: 0.0,
            limit_deg: f64::INFINITY,
            max_rate_degps: f64::INFINITY,
            band_deg: 0.0,
            yaw_moment_nm: 0.0,
            gyro_bias_degps: 0.0,
            starboard_gain: 0.0,
            n_rr: 0.0,
            cubic: false,
            wind_ne: (0.0, 0.0),
            current_ne: (0.0, 0.0),
        }
    }
}

impl SimKnobs {
    /// The knobs of `effects`, applied in order (moments, delays and bands add up; limits
    /// take the smallest; the others the last).
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// use yawcast::effects::SimKnobs;
    /// let k = SimKnobs::of(&[
    ///     SimEffect::DeadTime { delay_s: 1.0 },
    ///     SimEffect::DeadTime { delay_s: 0.5 },
    ///     SimEffect::Saturation { limit_deg: 10.0 },
    /// ]);
    /// assert_eq!((k.dead_time_s, k.limit_deg), (1.5, 10.0));
    /// ```
    pub fn of(effects: &[SimEffect]) -> SimKnobs {
        let mut k = SimKnobs::default();
        for e in effects {
            e.apply(&mut k);
        }
        k
    }
}

/// How a built-in effect's strength carries over to another hull (see
/// `yawcast::sim::World::hidden`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullScale {
    /// The hull's time `L/U` over the built-in ship's.
    pub time: f64,
    /// Speeds: the full-scale factor times Froude scaling to the hull.
    pub speed: f64,
    /// Yaw moments: the hull's `½ρL²dU²` over the built-in ship's.
    pub moment: f64,
}

/// One parameter's check: its field name, value, whether it is in range and what is
/// expected otherwise.
#[derive(Debug, Clone, Copy)]
pub(super) struct Field {
    pub(super) name: &'static str,
    pub(super) value: f64,
    pub(super) ok: bool,
    pub(super) expected: &'static str,
}

impl Field {
    pub(super) fn new(
        name: &'static str,
        value: f64,
        ok: bool,
        expected: &'static str,
    ) -> Option<Field> {
        Some(Field {
            name,
            value,
            ok,
            expected,
        })
    }
}

/// At most two checked fields per effect.
pub(super) type Fields = [Option<Field>; 2];
