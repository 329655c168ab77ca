//! Ship simulator: a 3-DOF (surge, sway, yaw) nonlinear MMG manoeuvring model of the paper's
//! training ship (1:24 LNG carrier, 11.33 m overall, two stern azimuth pods steered as one
//! input δ, constant revolutions), with the effect library's physics switchable one by one.
//!
//! - **Hull**: MMG cubic polynomials in `v' = v/U`, `r' = rL/U` (non-dimensional
//!   coefficients in the ship file), added masses, midship-origin equations of motion.
//! - **Pods**: thrust `T(J)` vectored at the pod angle δ, plus the lift of the pod housings
//!   in their local inflow (which gives the hull its course stability); hull–pod interaction
//!   `a_H` acting at `x_H`.
//! - **Actuator**: command dead time → angle limit (±35°) → largest pod rate → first-order servo lag.
//! - **Environment**: steady wind (`N = ½ρ_a V_r² A_L L_oa C_N(γ_r)`, Isherwood/Blendermann-type
//!   shapes), steady current (hull and pods see the velocity through the water; inertia terms
//!   use ground velocities, so a current acting on a turning ship gives a heading-dependent
//!   yaw moment, first harmonic in ψ), gyro noise and bias.
//! - **Integration**: RK4 with an internal step of at most [`Scenario::dt_max`] (0.1 s by
//!   default), commands held over each sample (zero-order hold).
//!
//! The sample time defaults to `Ts = 1 s`: Froude scaling by √24 puts the yaw time constants
//! of this 1:24 model at ~10–20 s (a few minutes at full scale), so 1 s gives 10–20 samples
//! per time constant, and 10-step predictions look ~10 s ahead — the MPC's horizon.
//!
//! Logged channels ([`Record`]): `u` the commanded δ (deg, held over `[t, t+Ts)`), `y` the
//! measured yaw rate (deg/s, with gyro noise and bias), `psi` the measured heading (deg,
//! **unwrapped**: continuous, starting in `[0, 360)` at `t = 0`), `speed` the speed over
//! ground (m/s). The apparent wind (speed m/s, angle from the bow deg, positive from
//! starboard, in `(-180, 180]`) only when [`Scenario::log_wind`] is set, since logging it
//! reveals wind. Directions: heading and wind *from*, current *towards*, degrees from north.
//!
//! ```
//! use yawcast::sim::{simulate, Scenario, Ship};
//! let rec = simulate(&Ship::default_lng(), &Scenario::default(), 1).unwrap();
//! assert_eq!(rec.len(), 1800);
//! assert_eq!(rec.ts, 1.0);
//! let peak = rec.y.iter().fold(0.0_f64, |a, &b| a.max(b.abs()));
//! assert!(peak > 0.3 && peak < 5.0, "{peak}");
//! ```

use std::path::PathBuf;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::io::data::Record;

mod dynamics;
mod inputs;
mod manoeuvres;
mod oracle;
mod ship;
mod worlds;

pub use crate::effects::{
    SimEffect, HIDDEN_ASYMMETRY, HIDDEN_BIAS_NM, HIDDEN_CURRENT_MPS, HIDDEN_DEAD_BAND_DEG,
    HIDDEN_DEAD_TIME_S, HIDDEN_GYRO_BIAS_DEGPS, HIDDEN_LIMIT_DEG, HIDDEN_N_RR, HIDDEN_RATE_DEGPS,
    HIDDEN_WIND_MPS,
};
pub use inputs::{Autopilot, InputSpec};
pub use manoeuvres::{turning_circle, zigzag, TurningResult, ZigzagResult};
pub use oracle::{simulate_with_oracle, Oracle};
pub use ship::{
    Actuator, HullCoefficients, MainParticulars, Pods, Ship, Windage, DEFAULT_SHIP_TOML,
};

pub use worlds::{World, WorldKind};

use dynamics::{Model, NX};

/// Errors of the simulator.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SimError {
    /// A ship file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// A ship file is not valid TOML for a ship (syntax, unknown key, wrong type).
    #[error("ship file: {0}")]
    Parse(String),
    /// A value is out of range.
    #[error("{field}: {value} is not valid (expected {expected})")]
    Invalid {
        /// The field, as a path (`pods.rps`, `effects[1] (wind).speed_mps`, `scenario.ts`).
        field: String,
        /// The value found.
        value: f64,
        /// What the value must be.
        expected: String,
    },
    /// The ship has no forward equilibrium speed (thrust never balances resistance).
    #[error("the ship has no equilibrium speed below 30 m/s at δ = 0 (check pods.rps, pods.kt, hull.r0)")]
    NoEquilibrium,
    /// The motion became non-finite or absurd.
    #[error("simulation diverged at t = {t_s} s (check the ship's coefficients)")]
    Diverged {
        /// Time (s) of the first bad sample.
        t_s: f64,
    },
    /// A manoeuvre did not complete in its time limit.
    #[error("{manoeuvre}: {reason}")]
    Manoeuvre {
        /// Which manoeuvre.
        manoeuvre: &'static str,
        /// What did not happen.
        reason: String,
    },
}

impl SimError {
    pub(crate) fn invalid(field: impl Into<String>, value: f64, expected: &str) -> SimError {
        SimError::Invalid {
            field: field.into(),
            value,
            expected: expected.to_string(),
        }
    }
}

/// Measurement noise of the logged channels (standard deviations of white noise).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseSpec {
    /// Rate-gyro noise (deg/s); default 0.03.
    pub gyro_std_degps: f64,
    /// Heading noise (deg); default 0.
    pub heading_std_deg: f64,
    /// Speed-over-ground noise (m/s); default 0.
    pub speed_std_mps: f64,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        NoiseSpec {
            gyro_std_degps: 0.03,
            heading_std_deg: 0.0,
            speed_std_mps: 0.0,
        }
    }
}

impl NoiseSpec {
    /// No noise at all.
    ///
    /// ```
    /// assert_eq!(yawcast::sim::NoiseSpec::none().gyro_std_degps, 0.0);
    /// ```
    pub fn none() -> NoiseSpec {
        NoiseSpec {
            gyro_std_degps: 0.0,
            heading_std_deg: 0.0,
            speed_std_mps: 0.0,
        }
    }
}

/// One simulated trial: sample time, length, input, noise and effects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    /// Record name (default `"sim"`).
    pub name: String,
    /// Sample time (s); default 1.
    pub ts: f64,
    /// Number of samples; default 1800 (30 min at 1 s).
    pub n_samples: usize,
    /// The commanded pod angle.
    pub input: InputSpec,
    /// Measurement noise.
    pub noise: NoiseSpec,
    /// Effects switched on for this run, on top of the ship's own (an effect here replaces
    /// the ship's effect of the same kind; of several of one kind, the last counts).
    pub effects: Vec<SimEffect>,
    /// Log the apparent wind (anemometer) channels.
    pub log_wind: bool,
    /// Log the steering gear's angle at each sample in the command column instead of the
    /// command: a rig that logs the rudder's (pod's) own angle, its gear between.
    pub log_angle: bool,
    /// Heading at `t = 0` (deg); `None` draws it uniformly from `[0, 360)` with the seed.
    pub initial_heading_deg: Option<f64>,
    /// Straight run at δ = 0 before `t = 0`, so the record starts settled (s); default 120.
    pub warmup_s: f64,
    /// Largest internal integration step (s); default 0.1.
    pub dt_max: f64,
    /// The background yaw disturbance of the simulator worlds ([`World`]) times this
    /// (default 1: a standard deviation of what 0.5° of rudder gives; 2 a rougher day, 0
    /// none). The built-in ship has no background disturbance and refuses any other value
    /// than 1.
    pub disturbance: f64,
}

impl Default for Scenario {
    fn default() -> Self {
        Scenario {
            name: "sim".into(),
            ts: 1.0,
            n_samples: 1800,
            input: InputSpec::default(),
            noise: NoiseSpec::default(),
            effects: Vec::new(),
            log_wind: false,
            log_angle: false,
            initial_heading_deg: None,
            warmup_s: 120.0,
            dt_max: 0.1,
            disturbance: 1.0,
        }
    }
}

/// Upper bound on samples per run (a typo guard: 10⁷ samples).
pub const MAX_SAMPLES: usize = 10_000_000;

impl Scenario {
    /// The default scenario with one effect switched on.
    ///
    /// ```
    /// use yawcast::sim::{Scenario, SimEffect};
    /// let s = Scenario::with_effect(SimEffect::GyroBias { bias_degps: 0.2 });
    /// assert_eq!(s.effects.len(), 1);
    /// ```
    pub fn with_effect(effect: SimEffect) -> Scenario {
        Scenario {
            effects: vec![effect],
            ..Scenario::default()
        }
    }

    /// Checks every value; the error names the field (`scenario.ts`, `input.min_hold_s`).
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SimError> {
        ship::within("scenario.ts", self.ts, 1e-4, 3600.0)?;
        if self.n_samples < 2 || self.n_samples > MAX_SAMPLES {
            return Err(SimError::invalid(
                "scenario.n_samples",
                self.n_samples as f64,
                &format!("in 2..={MAX_SAMPLES}"),
            ));
        }
        self.input.validate(self.n_samples)?;
        ship::non_neg("noise.gyro_std_degps", self.noise.gyro_std_degps)?;
        ship::non_neg("noise.heading_std_deg", self.noise.heading_std_deg)?;
        ship::non_neg("noise.speed_std_mps", self.noise.speed_std_mps)?;
        for (i, e) in self.effects.iter().enumerate() {
            e.validate(&format!("scenario.effects[{i}]"))?;
        }
        if let Some(h) = self.initial_heading_deg {
            ship::finite("scenario.initial_heading_deg", h)?;
        }
        ship::within("scenario.warmup_s", self.warmup_s, 0.0, 36_000.0)?;
        ship::within("scenario.dt_max", self.dt_max, 1e-4, 1.0)?;
        ship::within("scenario.disturbance", self.disturbance, 0.0, 100.0)?;
        Ok(())
    }
}

/// The effects in force: the ship's, then the scenario's (replacing same-kind ones).
fn merged_effects(ship: &Ship, scenario: &[SimEffect]) -> Vec<SimEffect> {
    let mut out: Vec<SimEffect> = Vec::new();
    for e in ship.effects().iter().chain(scenario) {
        match out.iter_mut().find(|x| x.kind() == e.kind()) {
            Some(x) => *x = *e,
            None => out.push(*e),
        }
    }
    out
}

/// Settings of one integration run (internal).
pub(crate) struct RunSpec<'a> {
    pub ship: &'a Ship,
    pub effects: &'a [SimEffect],
    pub ts: f64,
    pub n: usize,
    pub dt_max: f64,
    pub warmup_s: f64,
    pub psi0_deg: f64,
}

/// What an observer sees at each sample.
pub(crate) struct Sample<'a> {
    pub k: usize,
    pub state: &'a [f64; NX],
    pub model: &'a Model,
    /// The gear's angle (rad).
    pub delta: f64,
}

/// Integrates the ship over `spec.n` samples. At each sample `observe` sees the state (and
/// may stop the run by returning `false`), then `command` gives the command (deg) held until
/// the next sample.
pub(crate) fn run(
    spec: &RunSpec<'_>,
    mut command: impl FnMut(usize, &[f64; NX]) -> f64,
    mut observe: impl FnMut(&Sample<'_>) -> bool,
) -> Result<(), SimError> {
    let model = Model::new(spec.ship, spec.effects);
    let mut act = dynamics::Actuator::new(spec.ship, spec.effects);
    let env = model.env();
    let u0 = model.equilibrium_speed().ok_or(SimError::NoEquilibrium)?;
    let mut s = [u0, 0.0, 0.0, 0.0, 0.0, spec.psi0_deg.to_radians()];
    let nsub = (spec.ts / spec.dt_max).ceil().max(1.0) as usize;
    let dt = spec.ts / nsub as f64;
    let nwarm = (spec.warmup_s / dt).ceil() as usize;
    let delayed_cmd = |hist: &[f64], t: f64, dead: f64| -> f64 {
        let tk = (t - dead) / spec.ts + 1e-9;
        if tk < 0.0 {
            0.0
        } else {
            hist[(tk.floor() as usize).min(hist.len() - 1)]
        }
    };
    // warm-up at δ = 0 (in the wind and current of the run), heading held fixed at the end
    for _ in 0..nwarm {
        act.step(0.0, dt);
        model.rk4(&mut s, act.delta, dt, env);
    }
    if nwarm > 0 {
        // start the record on the asked heading and at the origin
        s[3] = 0.0;
        s[4] = 0.0;
        s[5] = spec.psi0_deg.to_radians();
    }
    let mut hist = Vec::with_capacity(spec.n);
    for k in 0..spec.n {
        let t = k as f64 * spec.ts;
        if !s.iter().all(|x| x.is_finite()) || s[0].abs() > 100.0 || s[1].abs() > 100.0 {
            return Err(SimError::Diverged { t_s: t });
        }
        let go = observe(&Sample {
            k,
            state: &s,
            model: &model,
            delta: act.delta,
        });
        if !go || k + 1 == spec.n {
            break;
        }
        hist.push(command(k, &s));
        for j in 0..nsub {
            let tj = t + j as f64 * dt;
            let c = delayed_cmd(&hist, tj, act.dead_time);
            act.step(c.to_radians(), dt);
            model.rk4(&mut s, act.delta, dt, env);
        }
    }
    Ok(())
}

/// Simulates one trial of `ship` under `scenario`; `seed` drives the input sequence, the
/// initial heading and the noise (independent streams, ChaCha8).
///
/// # Errors
/// [`SimError::Invalid`] naming the field for a bad ship or scenario value,
/// [`SimError::NoEquilibrium`] when the ship cannot make way, [`SimError::Diverged`] when the
/// motion becomes non-finite.
///
/// ```
/// use yawcast::sim::{simulate, Scenario, Ship, SimEffect};
/// let ship = Ship::default_lng();
/// let base = simulate(&ship, &Scenario::default(), 3).unwrap();
/// let biased = Scenario::with_effect(SimEffect::GyroBias { bias_degps: 0.25 });
/// let rec = simulate(&ship, &biased, 3).unwrap();
/// let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
/// assert!((mean(&rec.y) - mean(&base.y) - 0.25).abs() < 1e-9);
/// ```
pub fn simulate(ship: &Ship, scenario: &Scenario, seed: u64) -> Result<Record, SimError> {
    simulate_with_nav(ship, scenario, seed).map(|(rec, _)| rec)
}

/// The navigation channels of a simulated record, one value per sample: course over ground
/// (deg, in `[0, 360)`) and position north/east of the record's start (m), without noise.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimNav {
    /// Course over ground (deg).
    pub cog_deg: Vec<f64>,
    /// Position north of the start (m).
    pub north_m: Vec<f64>,
    /// Position east of the start (m).
    pub east_m: Vec<f64>,
}

/// [`simulate`], also returning the navigation channels (course over ground and position);
/// the record is the same.
///
/// # Errors
/// As [`simulate`].
///
/// ```
/// use yawcast::sim::{simulate_with_nav, Scenario, Ship, SimEffect};
/// let sc = Scenario::with_effect(SimEffect::Current { speed_mps: 0.5, towards_deg: 90.0 });
/// let (rec, nav) = simulate_with_nav(&Ship::default_lng(), &sc, 2).unwrap();
/// assert_eq!(nav.north_m.len(), rec.len());
/// assert_eq!((nav.north_m[0], nav.east_m[0]), (0.0, 0.0));
/// ```
pub fn simulate_with_nav(
    ship: &Ship,
    scenario: &Scenario,
    seed: u64,
) -> Result<(Record, SimNav), SimError> {
    simulate_full(ship, scenario, seed).map(|(rec, nav, _)| (rec, nav))
}

/// [`simulate_with_nav`], also returning the noise-free gyro reading of each sample (the
/// true yaw rate plus the gyro offset, deg/s).
fn simulate_full(
    ship: &Ship,
    scenario: &Scenario,
    seed: u64,
) -> Result<(Record, SimNav, Vec<f64>), SimError> {
    ship.validate()?;
    scenario.validate()?;
    if scenario.disturbance != 1.0 {
        return Err(SimError::invalid(
            "scenario.disturbance",
            scenario.disturbance,
            "1: the built-in ship has no background yaw disturbance to scale",
        ));
    }
    let effects = merged_effects(ship, &scenario.effects);
    let n = scenario.n_samples;
    let ts = scenario.ts;
    let psi0 = match scenario.initial_heading_deg {
        Some(h) => h,
        None => {
            use rand::Rng;
            360.0 * inputs::rng(seed, inputs::STREAM_HEADING).random::<f64>()
        }
    };
    let gyro_bias = crate::effects::SimKnobs::of(&effects).gyro_bias_degps;
    let open = scenario.input.open_loop(n, ts, seed);
    let mut closed = inputs::Closed::of(&scenario.input, n, ts, seed);
    let mut rec = Record {
        name: scenario.name.clone(),
        ts,
        t: (0..n).map(|k| k as f64 * ts).collect(),
        u: Vec::with_capacity(n),
        y: Vec::with_capacity(n),
        psi: Some(Vec::with_capacity(n)),
        speed: Some(Vec::with_capacity(n)),
        wind_speed: scenario.log_wind.then(|| Vec::with_capacity(n)),
        wind_angle: scenario.log_wind.then(|| Vec::with_capacity(n)),
        // the course is the navigation part's (`SimNav`), written beside the record
        cog: None,
    };
    let mut cmds = Vec::with_capacity(n);
    let spec = RunSpec {
        ship,
        effects: &effects,
        ts,
        n,
        dt_max: scenario.dt_max,
        warmup_s: scenario.warmup_s,
        psi0_deg: psi0,
    };
    let mut decide = |k: usize, s: &[f64; NX]| match (&open, closed.as_mut()) {
        (Some(u), _) => u[k],
        (None, Some(c)) => c.command(k, s[5].to_degrees(), s[2].to_degrees()),
        (None, None) => 0.0,
    };
    let mut states: Vec<([f64; NX], dynamics::Apparent)> = Vec::with_capacity(n);
    let mut angles = Vec::with_capacity(n);
    run(
        &spec,
        |k, s| {
            let c = decide(k, s);
            cmds.push(c);
            c
        },
        |smp| {
            let app = if scenario.log_wind {
                smp.model.apparent(smp.state)
            } else {
                dynamics::Apparent::default()
            };
            states.push((*smp.state, app));
            angles.push(smp.delta.to_degrees());
            true
        },
    )?;
    // the last sample's command is logged but never acts within the record
    if let Some((s, _)) = states.last() {
        if cmds.len() < states.len() {
            cmds.push(decide(states.len() - 1, s));
        }
    }
    let mut nr = inputs::rng(seed, inputs::STREAM_NOISE);
    let ns = scenario.noise;
    let mut nav = SimNav::default();
    let mut truth = Vec::with_capacity(n);
    for (s, _) in &states {
        nav.cog_deg
            .push((s[5] + s[1].atan2(s[0])).to_degrees().rem_euclid(360.0));
        nav.north_m.push(s[3]);
        nav.east_m.push(s[4]);
    }
    for (k, (s, app)) in states.iter().enumerate() {
        rec.u.push(if scenario.log_angle {
            angles[k]
        } else {
            cmds[k]
        });
        let g = if ns.gyro_std_degps > 0.0 {
            ns.gyro_std_degps * inputs::gauss(&mut nr)
        } else {
            0.0
        };
        truth.push(s[2].to_degrees() + gyro_bias);
        rec.y.push(s[2].to_degrees() + gyro_bias + g);
        let hn = if ns.heading_std_deg > 0.0 {
            ns.heading_std_deg * inputs::gauss(&mut nr)
        } else {
            0.0
        };
        push(&mut rec.psi, s[5].to_degrees() + hn);
        let sn = if ns.speed_std_mps > 0.0 {
            ns.speed_std_mps * inputs::gauss(&mut nr)
        } else {
            0.0
        };
        push(&mut rec.speed, s[0].hypot(s[1]) + sn);
        push(&mut rec.wind_speed, app.speed);
        push(&mut rec.wind_angle, app.angle.to_degrees());
    }
    Ok((rec, nav, truth))
}

/// The root of a function that changes sign once in `[lo, hi]`, by `iterations` halvings:
/// `past(x)` says whether `x` lies beyond the root (above it). The midpoint of the last
/// bracket is returned. The hulls use it for an equilibrium speed and for the propeller
/// revolutions of a speed.
pub(crate) fn bisect(
    mut lo: f64,
    mut hi: f64,
    iterations: usize,
    past: impl Fn(f64) -> bool,
) -> f64 {
    for _ in 0..iterations {
        let mid = 0.5 * (lo + hi);
        if past(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

fn push(v: &mut Option<Vec<f64>>, x: f64) {
    if let Some(v) = v.as_mut() {
        v.push(x);
    }
}

/// Simulates one record per seed, in parallel (rayon); records are named
/// `{scenario.name}-{seed}`.
///
/// # Errors
/// The first error of [`simulate`], in seed order.
///
/// ```
/// use yawcast::sim::{simulate_many, Scenario, Ship};
/// let recs = simulate_many(&Ship::default_lng(), &Scenario::default(), &[1, 2]).unwrap();
/// assert_eq!(recs[1].name, "sim-2");
/// ```
pub fn simulate_many(
    ship: &Ship,
    scenario: &Scenario,
    seeds: &[u64],
) -> Result<Vec<Record>, SimError> {
    seeds
        .par_iter()
        .map(|&seed| {
            let mut r = simulate(ship, scenario, seed)?;
            r.name = format!("{}-{seed}", scenario.name);
            Ok(r)
        })
        .collect()
}

#[cfg(test)]
mod tests;
