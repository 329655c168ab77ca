//! Test worlds: ship simulators beside the built-in one, independent of it in hull and
//! equations, so a rule tuned on one world can be checked on another.
//!
//! - [`WorldKind::Lng`]: the built-in 1:24 LNG carrier ([`simulate`](super::simulate),
//!   unchanged).
//! - [`WorldKind::Kvlcc2`]: the KVLCC2 tanker by the MMG standard method (Yasukawa &
//!   Yoshimura 2015), full scale (`L_pp` 320 m) or Froude-scaled to any `L_pp`.
//! - [`WorldKind::Mariner`]: the Mariner-class cargo ship, an Abkowitz-type model
//!   (Chislett & Strøm-Tejsen 1965), full scale (`L_pp` 160.93 m).
//! - [`WorldKind::SeiunMaru`]: the Seiun Maru, a 105 m training ship with a fine hull, by
//!   the MMG standard method (Yoshimura & Masumoto 2012), full scale or Froude-scaled. It
//!   was added after the diagnosis's rules were set, to check them on a hull they never saw.
//! - [`WorldKind::Container`]: a high-speed container ship (`L_pp` 175 m) whose steering
//!   couples with its roll, by the four-degree-of-freedom model of Son & Nomoto (1981),
//!   full scale; added after the rules too, the one world whose equations hold a roll mode.
//! - [`WorldKind::EssoOsaka`]: the Esso Osaka, a 304.8 m tanker whose rudder works in the
//!   propeller's race, by the model of Van Berlekom & Goddard (1972), full scale or
//!   Froude-scaled (at 3.0 m the hull of the tank records in `tests/data/real`); added
//!   after the rules too.
//!
//! The new worlds share one environment and one integrator:
//!
//! - **State** `[u, v, r, x_N, y_E, ψ, p, φ]` with `u, v` the velocity *through the water*
//!   in body axes, and the roll rate and heel `p, φ` (0 but on a hull with a roll mode). A
//!   current is uniform and steady in the earth frame, so the water is an inertial frame
//!   and the hull's equations hold in it unchanged: the current carries the ship
//!   (`ẋ_N, ẏ_E` and the logged speed over ground include it) and exerts no yaw moment.
//! - **Wind**: relative wind (the ship's velocity over ground minus the true wind) with
//!   Blendermann's (1994) coefficient curves for the hull's ship type ([`env::Windage`]);
//!   the true wind's speed gusts as `V̄(1 + g(t))`, `g` first-order with a 10 % standard
//!   deviation and a 20 s time constant (Froude-scaled). The ship's own motion through still
//!   air is always felt.
//! - **Background yaw disturbance** in every record (reference and trials alike): a
//!   first-order random yaw moment whose standard deviation is what 0.5° of rudder gives at
//!   the approach speed, time constant `L_pp/U`.
//! - **Sensors**: the rate gyro's white noise ([`NoiseSpec`](super::NoiseSpec)) on top of a
//!   fibre-optic gyro's bias instability (0.002 °/s, 10 min) and resolution (0.001 °/s); the
//!   compass's white noise on top of a gyrocompass's slow error (0.1°, 2 min) and its 0.1°
//!   resolution.
//! - **Steering gear**: dead time → angle limit → largest rudder rate → first-order servo lag, as on
//!   the built-in ship, with each hull's own limits.
//! - **Effects** ([`SimEffect`]) act as on the built-in ship, in the world's own units:
//!   `bias` a steady yaw moment (N·m), `gyro-bias` an offset of the measured rate,
//!   the actuator effects the gear, `asymmetry` the rudder's
//!   starboard effectiveness, `nonlinear-damping` a Norrbin term `−n_rr ½ρL⁴d r|r|`, `wind`
//!   and `current` the environment. [`World::hidden`] gives the canonical strengths of the
//!   built-in ship carried over to the hull (below).
//!
//! The random streams of one seed are independent: input, heading and white noise as on
//! the built-in ship, the background disturbance, the gusts and the sensor drifts each on
//! their own, so switching an effect on changes nothing else in the record.
//!
//! ```
//! use yawcast::sim::{Scenario, World, WorldKind};
//! let w = World::new(WorldKind::Mariner, None).unwrap();
//! let rec = w.simulate(&Scenario { n_samples: 300, ..Scenario::default() }, 1).unwrap();
//! assert_eq!(rec.len(), 300);
//! let sog = rec.speed.as_ref().unwrap();
//! assert!(sog[0] > 7.0 && sog[0] < 8.0, "{}", sog[0]);
//! ```

use rayon::prelude::*;
use yawcast_shared::model::EffectKind;

use super::dynamics::{self, Model};
use super::inputs::{self, ZigZagLogic};
use super::manoeuvres::{TurningTracker, ZigzagTracker};
use super::{NoiseSpec, Oracle, Scenario, Ship, SimEffect, SimError, TurningResult, ZigzagResult};
use crate::effects::HullScale;
use crate::io::data::Record;

mod container;
pub(crate) mod env;
mod kvlcc2;
mod mariner;
mod mmg;
mod oracle;
mod physics;
mod seiun;
mod tanker;
mod timed;

use env::{gauss_markov, quantise, Sensors, Windage};
use physics::{Physics, State, Weather, CALM};

/// Random stream of the background yaw disturbance.
const STREAM_BACKGROUND: u64 = 16;
/// Random stream of the gusts.
const STREAM_GUST: u64 = 17;
/// Random stream of the sensor drifts.
const STREAM_SENSORS: u64 = 18;
/// Random stream of the course-over-ground noise.
const STREAM_COURSE: u64 = 19;
/// Gust standard deviation (fraction of the mean wind speed).
const GUST_STD: f64 = 0.10;
/// Gust time constant at full scale (s).
const GUST_TAU_S: f64 = 20.0;
/// Background yaw disturbance: standard deviation in degrees of rudder.
const BACKGROUND_RUDDER_DEG: f64 = 0.5;
/// Scale of the built-in ship (its full-scale speeds are its own × √24).
const LNG_SCALE: f64 = 24.0;

/// Which ship simulator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum WorldKind {
    /// The built-in 1:24 LNG carrier (azimuth pods, MMG-style hull).
    Lng,
    /// KVLCC2 by the MMG standard method (Yasukawa & Yoshimura 2015).
    Kvlcc2,
    /// The Mariner-class cargo ship, Abkowitz-type (Chislett & Strøm-Tejsen 1965).
    Mariner,
    /// The Seiun Maru, a fine 105 m training ship, by the MMG standard method (Yoshimura &
    /// Masumoto 2012).
    SeiunMaru,
    /// A high-speed container ship whose steering couples with its roll (Son & Nomoto
    /// 1981).
    Container,
    /// The Esso Osaka tanker, its rudder in the propeller's race (Van Berlekom & Goddard
    /// 1972).
    EssoOsaka,
}

impl WorldKind {
    /// Every world, the built-in one first.
    pub const ALL: [WorldKind; 6] = [
        WorldKind::Lng,
        WorldKind::Kvlcc2,
        WorldKind::Mariner,
        WorldKind::SeiunMaru,
        WorldKind::Container,
        WorldKind::EssoOsaka,
    ];

    /// The stable name (`lng`, `kvlcc2`, `mariner`, `seiun-maru`, `container`, `esso-osaka`).
    ///
    /// ```
    /// use yawcast::sim::WorldKind;
    /// assert_eq!(WorldKind::from_name("kvlcc2"), Some(WorldKind::Kvlcc2));
    /// assert_eq!(WorldKind::Mariner.name(), "mariner");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            WorldKind::Lng => "lng",
            WorldKind::Kvlcc2 => "kvlcc2",
            WorldKind::Mariner => "mariner",
            WorldKind::SeiunMaru => "seiun-maru",
            WorldKind::Container => "container",
            WorldKind::EssoOsaka => "esso-osaka",
        }
    }

    /// The world of a stable name.
    pub fn from_name(name: &str) -> Option<WorldKind> {
        WorldKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// A steering gear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gear {
    /// First-order servo time constant (s).
    pub tau_s: f64,
    /// Angle limit (deg).
    pub limit_deg: f64,
    /// Largest rudder rate (deg/s).
    pub rate_degps: f64,
}

/// A hull of a test world: its particulars and its equations of motion.
pub(crate) trait Hull: std::fmt::Debug + Send + Sync {
    /// A name for reports.
    fn name(&self) -> String;
    /// Length between perpendiculars (m).
    fn lpp(&self) -> f64;
    /// Draft (m).
    fn draft(&self) -> f64;
    /// Water density (kg/m³).
    fn rho(&self) -> f64;
    /// Approach speed through the water on a straight course at δ = 0 (m/s).
    fn u0(&self) -> f64;
    /// Froude time scale against full scale (`√(1/λ)`; 1 at full scale).
    fn froude_time(&self) -> f64;
    /// The steering gear.
    fn gear(&self) -> Gear;
    /// Above-water geometry and wind coefficients.
    fn windage(&self) -> Windage;
    /// Sets the `asymmetry` effect's extra rudder effectiveness to starboard.
    fn set_asymmetry(&mut self, gain: f64);
    /// Sails at approach speed `u` (m/s at this scale) instead: the propeller turns at the
    /// revolutions that hold it on a straight course. `false` where the equations are
    /// written about their design speed and cannot (the default).
    fn set_approach_speed(&mut self, _u: f64) -> bool {
        false
    }
    /// Accelerations `(u̇, v̇, ṙ)` at the water-relative body velocities `s = [u, v, r]`
    /// and rudder angle δ (rad, positive to starboard), with external loads `ext`
    /// (`X`, `Y` in N, `N` in N·m).
    fn accel(&self, s: [f64; 3], delta: f64, ext: [f64; 3]) -> [f64; 3];
    /// Accelerations `(u̇, v̇, ṙ, ṗ)` at `s = [u, v, r, p, φ]` (roll rate `p`, heel `φ`),
    /// as [`accel`](Hull::accel) otherwise. A hull without a roll mode (the default)
    /// ignores `p, φ`, and its roll stays 0.
    fn accel_roll(&self, s: [f64; 5], delta: f64, ext: [f64; 3]) -> [f64; 4] {
        let a = self.accel([s[0], s[1], s[2]], delta, ext);
        [a[0], a[1], a[2], 0.0]
    }
}

/// One test world: a simulator and its scale.
///
/// ```
/// use yawcast::sim::{World, WorldKind};
/// let w = World::new(WorldKind::Kvlcc2, Some(7.0)).unwrap();
/// assert!((w.default_ts() - (7.0f64 / 320.0).sqrt()).abs() < 1e-12);
/// assert!(World::new(WorldKind::Mariner, Some(7.0)).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct World {
    kind: WorldKind,
    lpp: Option<f64>,
    /// Approach speed set by the user (m/s at the world's scale).
    speed: Option<f64>,
}

impl World {
    /// The world `kind`, at `L_pp = scale_lpp` metres when given (KVLCC2, the Seiun Maru
    /// and the Esso Osaka only: the built-in ship is a model already, the Mariner and
    /// container models are full scale only).
    ///
    /// # Errors
    /// [`SimError::Invalid`] (`world.scale`) for a scale on another world or outside
    /// 1–1000 m.
    pub fn new(kind: WorldKind, scale_lpp: Option<f64>) -> Result<World, SimError> {
        if let Some(l) = scale_lpp {
            if !matches!(
                kind,
                WorldKind::Kvlcc2 | WorldKind::SeiunMaru | WorldKind::EssoOsaka
            ) {
                return Err(SimError::invalid(
                    "world.scale",
                    l,
                    "no scale: only kvlcc2, seiun-maru and esso-osaka take one",
                ));
            }
            super::ship::within("world.scale", l, 1.0, 1000.0)?;
        }
        Ok(World {
            kind,
            lpp: scale_lpp,
            speed: None,
        })
    }

    /// The same world sailing at approach speed `u_mps` (m/s at its scale, through the
    /// water, straight ahead) instead of its design speed: the propeller turns at the
    /// revolutions that hold it, and everything the world scales by the hull's speed (its
    /// time `L_pp/U`, the background disturbance's time constant, the hidden yaw moment)
    /// follows. For records of a ship that ran slower or faster than the source's design
    /// speed — tank tests often do. KVLCC2, the Seiun Maru, the container ship and the Esso
    /// Osaka only: the Mariner's equations are written about their design speed, and the
    /// built-in ship's speed is its pods' revolutions (`rps` in a ship file).
    ///
    /// ```
    /// use yawcast::sim::{World, WorldKind};
    /// let w = World::new(WorldKind::EssoOsaka, Some(3.0)).unwrap().at_speed(0.3).unwrap();
    /// assert_eq!(w.approach_speed(), 0.3);
    /// assert!(World::new(WorldKind::Mariner, None).unwrap().at_speed(5.0).is_err());
    /// ```
    ///
    /// # Errors
    /// [`SimError::Invalid`] (`world.speed`) on the Mariner or the built-in ship, for a
    /// speed outside 0.25–1.5 times the design speed (the range the sources' coefficients
    /// are fitted over, about), or where no revolutions hold it.
    pub fn at_speed(self, u_mps: f64) -> Result<World, SimError> {
        let Some(mut h) = self.design_hull() else {
            return Err(SimError::invalid(
                "world.speed",
                u_mps,
                "no approach speed on the built-in ship: its speed is its pods' revolutions, `rps` \
                 under `[pods]` in a ship file (--ship)",
            ));
        };
        let design = h.u0();
        if !u_mps.is_finite() || u_mps < 0.25 * design || u_mps > 1.5 * design {
            return Err(SimError::invalid(
                "world.speed",
                u_mps,
                &format!("0.25–1.5 times the world's design speed of {design:.3} m/s at its scale"),
            ));
        }
        if !h.set_approach_speed(u_mps) {
            return Err(SimError::invalid(
                "world.speed",
                u_mps,
                "no approach speed on this world: its equations are written about their \
                 design speed",
            ));
        }
        // the revolutions found must hold the speed: no surge acceleration straight ahead
        let ax = h.accel([u_mps, 0.0, 0.0], 0.0, [0.0; 3])[0];
        if ax.is_nan() || ax.abs() > 1e-6 * u_mps {
            return Err(SimError::invalid(
                "world.speed",
                u_mps,
                "a speed some propeller revolutions hold on this hull",
            ));
        }
        Ok(World {
            speed: Some(u_mps),
            ..self
        })
    }

    /// The approach speed through the water straight ahead (m/s): the design speed unless
    /// [`at_speed`](World::at_speed) set another.
    pub fn approach_speed(&self) -> f64 {
        match self.hull() {
            Some(h) => h.u0(),
            None => lng_reference().3,
        }
    }

    /// Which world.
    pub fn kind(&self) -> WorldKind {
        self.kind
    }

    fn hull(&self) -> Option<Box<dyn Hull>> {
        let mut h = self.design_hull()?;
        if let Some(u) = self.speed {
            // checked by `at_speed`, the only way to set it
            let _ = h.set_approach_speed(u);
        }
        Some(h)
    }

    /// The hull at its design speed.
    fn design_hull(&self) -> Option<Box<dyn Hull>> {
        match self.kind {
            WorldKind::Lng => None,
            WorldKind::Kvlcc2 => Some(Box::new(mmg::Mmg::new(
                &kvlcc2::KVLCC2,
                self.lpp.unwrap_or(kvlcc2::LPP_FULL),
            ))),
            WorldKind::Mariner => Some(Box::new(mariner::Mariner::new())),
            WorldKind::SeiunMaru => Some(Box::new(mmg::Mmg::new(
                &seiun::SEIUN_MARU,
                self.lpp.unwrap_or(seiun::LPP_FULL),
            ))),
            WorldKind::Container => Some(Box::new(container::Container::new())),
            WorldKind::EssoOsaka => Some(Box::new(tanker::Tanker::new(
                self.lpp.unwrap_or(tanker::LPP_FULL),
            ))),
        }
    }

    /// A name for reports.
    ///
    /// ```
    /// use yawcast::sim::{World, WorldKind};
    /// let w = World::new(WorldKind::Kvlcc2, None).unwrap();
    /// assert_eq!(w.name(), "KVLCC2 (MMG, Lpp 320 m)");
    /// ```
    pub fn name(&self) -> String {
        match (self.hull(), self.speed) {
            (Some(h), Some(u)) => format!("{} at {u} m/s", h.name()),
            (Some(h), None) => h.name(),
            (None, _) => Ship::default_lng().name,
        }
    }

    /// The default sample time (s): 1 s at full scale and on the built-in ship,
    /// Froude-scaled (`√(L_pp/320)` s) on a scaled KVLCC2.
    pub fn default_ts(&self) -> f64 {
        self.hull().map_or(1.0, |h| h.froude_time())
    }

    /// The hull's time `L_pp/U` over the built-in ship's.
    fn time_ratio(&self) -> f64 {
        match self.hull() {
            None => 1.0,
            Some(h) => {
                let (l, _, _, u) = lng_reference();
                (h.lpp() / h.u0()) / (l / u)
            }
        }
    }

    /// The canonical hidden effect of `kind` at `strength` on this world: the built-in
    /// ship's ([`SimEffect::hidden`]) carried over to the hull. Angles, gains and `n_rr`
    /// stay; times (dead time) scale with the hull's time `L_pp/U` over the built-in ship's
    /// and rates (gyro bias, the gear's largest rate) with its inverse; the yaw moment keeps its
    /// non-dimensional value `N/(½ρL²dU²)`; wind and current keep their full-scale speeds
    /// (the built-in ship's × √24: 14.7 m/s and 1.47 m/s at full strength), Froude-scaled
    /// to the hull.
    ///
    /// ```
    /// use yawcast::sim::{SimEffect, World, WorldKind};
    /// use yawcast_shared::model::EffectKind;
    /// let w = World::new(WorldKind::Mariner, None).unwrap();
    /// let SimEffect::Wind { speed_mps, .. } = w.hidden(EffectKind::Wind, 1.0) else { panic!() };
    /// assert!((speed_mps - 3.0 * 24f64.sqrt()).abs() < 1e-12);
    /// ```
    pub fn hidden(&self, kind: EffectKind, strength: f64) -> SimEffect {
        let base = SimEffect::hidden(kind, strength);
        let Some(h) = self.hull() else {
            return base;
        };
        let t = self.time_ratio();
        let (l, d, rho, u) = lng_reference();
        let u0 = h.u0();
        base.on_hull(&HullScale {
            time: t,
            speed: LNG_SCALE.sqrt() * h.froude_time(),
            moment: (0.5 * h.rho() * h.lpp().powi(2) * h.draft() * u0 * u0)
                / (0.5 * rho * l * l * d * u * u),
        })
    }

    /// Simulates one trial under `scenario` with `seed`, as [`simulate`](super::simulate)
    /// does for the built-in ship (same channels, same meaning; the speed is over ground);
    /// on the built-in world it *is* that function, byte for byte.
    ///
    /// # Errors
    /// As [`simulate`](super::simulate).
    pub fn simulate(&self, scenario: &Scenario, seed: u64) -> Result<Record, SimError> {
        match self.hull() {
            None => super::simulate(&Ship::default_lng(), scenario, seed),
            Some(h) => simulate_hull(h, scenario, seed, 0).map(|(rec, _)| rec),
        }
    }

    /// [`World::simulate`] with the world's own `horizon`-step predictions of the logged yaw
    /// rate ([`Oracle`]): the true simulator from the true state `horizon` samples back,
    /// driven by the logged commands, the background moment, gusts and gyro drift decaying
    /// from their values there towards their means. The record is the same.
    ///
    /// # Errors
    /// As [`World::simulate`].
    ///
    /// ```
    /// use yawcast::sim::{Scenario, World, WorldKind};
    /// let w = World::new(WorldKind::Mariner, None).unwrap();
    /// let sc = Scenario { n_samples: 600, ..Scenario::default() };
    /// let (rec, o10) = w.simulate_with_oracle(&sc, 1, 10).unwrap();
    /// let (_, o1) = w.simulate_with_oracle(&sc, 1, 1).unwrap();
    /// assert!(o1.fit(&rec) > o10.fit(&rec) && o10.fit(&rec) > 80.0);
    /// ```
    pub fn simulate_with_oracle(
        &self,
        scenario: &Scenario,
        seed: u64,
        horizon: usize,
    ) -> Result<(Record, Oracle), SimError> {
        match self.hull() {
            None => super::simulate_with_oracle(&Ship::default_lng(), scenario, seed, horizon)
                .map(|(rec, _, o)| (rec, o)),
            Some(h) => simulate_hull(h, scenario, seed, horizon),
        }
    }

    /// One record per seed, in parallel, named `{scenario.name}-{seed}`.
    ///
    /// # Errors
    /// The first error of [`World::simulate`], in seed order.
    pub fn simulate_many(
        &self,
        scenario: &Scenario,
        seeds: &[u64],
    ) -> Result<Vec<Record>, SimError> {
        seeds
            .par_iter()
            .map(|&seed| {
                let mut r = self.simulate(scenario, seed)?;
                r.name = format!("{}-{seed}", scenario.name);
                Ok(r)
            })
            .collect()
    }

    /// Turning circle at a constant rudder `delta_deg` from a steady straight approach, in
    /// calm water and air without disturbances.
    ///
    /// # Errors
    /// As [`turning_circle`](super::turning_circle).
    pub fn turning_circle(&self, delta_deg: f64) -> Result<TurningResult, SimError> {
        match self.hull() {
            None => super::turning_circle(&Ship::default_lng(), delta_deg),
            Some(h) => turning_hull(h.as_ref(), delta_deg),
        }
    }

    /// Zig-zag `delta_deg`/`psi_deg` from a steady straight approach, starting to
    /// starboard, in calm water and air without disturbances.
    ///
    /// # Errors
    /// As [`zigzag`](super::zigzag).
    pub fn zigzag(&self, delta_deg: f64, psi_deg: f64) -> Result<ZigzagResult, SimError> {
        match self.hull() {
            None => super::zigzag(&Ship::default_lng(), delta_deg, psi_deg),
            Some(h) => zigzag_hull(h.as_ref(), delta_deg, psi_deg),
        }
    }
}

/// The built-in ship's `(L_pp, d, ρ, U)` (U its equilibrium speed).
fn lng_reference() -> (f64, f64, f64, f64) {
    let ship = Ship::default_lng();
    let u = Model::new(&ship, &[]).equilibrium_speed().unwrap_or(1.0);
    (ship.main.lpp_m, ship.main.draft_m, ship.main.rho_water, u)
}

/// Settings of one run on a hull.
struct HullRun<'a> {
    hull: &'a dyn Hull,
    phys: &'a Physics,
    act: dynamics::Actuator,
    ts: f64,
    n: usize,
    dt_max: f64,
    warmup_s: f64,
    psi0_deg: f64,
    /// The weather of each sample (empty: calm).
    weather: &'a [Weather],
}

/// One sample's integration on a hull: the command history (the current sample's last)
/// through the gear's dead time, `nsub` RK4 steps in the sample's weather.
struct Integrator<'a> {
    hull: &'a dyn Hull,
    phys: &'a Physics,
    ts: f64,
    nsub: usize,
    dt: f64,
}

impl<'a> Integrator<'a> {
    fn new(hull: &'a dyn Hull, phys: &'a Physics, ts: f64, dt_max: f64) -> Integrator<'a> {
        let nsub = (ts / dt_max).ceil().max(1.0) as usize;
        Integrator {
            hull,
            phys,
            ts,
            nsub,
            dt: ts / nsub as f64,
        }
    }

    /// Advances `s` and `act` from sample `k` to `k + 1`; `hist` holds the commands of
    /// samples `0..=k`.
    fn sample(
        &self,
        k: usize,
        s: &mut State,
        act: &mut dynamics::Actuator,
        hist: &[f64],
        w: Weather,
    ) {
        let t = k as f64 * self.ts;
        for j in 0..self.nsub {
            let tj = t + j as f64 * self.dt;
            let tk = (tj - act.dead_time) / self.ts + 1e-9;
            let c = if tk < 0.0 {
                0.0
            } else {
                hist[(tk.floor() as usize).min(hist.len() - 1)]
            };
            act.step(c.to_radians(), self.dt);
            self.phys.rk4(self.hull, s, act.delta, self.dt, w);
        }
    }
}

/// Integrates over `spec.n` samples: at each sample `observe` sees the state, the weather
/// and the steering gear (and may stop the run), then `command` gives the command (deg)
/// held until the next sample.
fn run_hull(
    mut spec: HullRun<'_>,
    mut command: impl FnMut(usize, &State) -> f64,
    mut observe: impl FnMut(usize, &State, Weather, &dynamics::Actuator) -> bool,
) -> Result<(), SimError> {
    let (hull, phys) = (spec.hull, spec.phys);
    let u0 = hull.u0();
    let mut s = [u0, 0.0, 0.0, 0.0, 0.0, spec.psi0_deg.to_radians(), 0.0, 0.0];
    let step = Integrator::new(hull, phys, spec.ts, spec.dt_max);
    let dt = step.dt;
    let nwarm = (spec.warmup_s / dt).ceil() as usize;
    let act = &mut spec.act;
    for _ in 0..nwarm {
        act.step(0.0, dt);
        phys.rk4(hull, &mut s, act.delta, dt, CALM);
    }
    if nwarm > 0 {
        s[3] = 0.0;
        s[4] = 0.0;
        s[5] = spec.psi0_deg.to_radians();
    }
    let mut hist: Vec<f64> = Vec::with_capacity(spec.n);
    let vmax = 10.0 * u0;
    for k in 0..spec.n {
        let t = k as f64 * spec.ts;
        if !s.iter().all(|x| x.is_finite()) || s[0].abs() > vmax || s[1].abs() > vmax {
            return Err(SimError::Diverged { t_s: t });
        }
        let w = spec.weather.get(k).copied().unwrap_or(CALM);
        if !observe(k, &s, w, act) || k + 1 == spec.n {
            break;
        }
        hist.push(command(k, &s));
        step.sample(k, &mut s, act, &hist, w);
    }
    Ok(())
}

/// The moment (N·m) that turns the hull as `deg` degrees of rudder do at the approach.
fn rudder_moment(hull: &dyn Hull, deg: f64) -> f64 {
    let s = [hull.u0(), 0.0, 0.0];
    let r0 = hull.accel(s, 0.0, [0.0; 3])[2];
    let rd = hull.accel(s, deg.to_radians(), [0.0; 3])[2];
    let per_nm = hull.accel(s, 0.0, [0.0, 0.0, 1.0])[2] - r0;
    (rd - r0) / per_nm
}

/// Long: one integration loop with the weather, sensors and manoeuvre logic of each sample;
/// splitting would pass the loop state around.
fn simulate_hull(
    mut hull: Box<dyn Hull>,
    scenario: &Scenario,
    seed: u64,
    horizon: usize,
) -> Result<(Record, Oracle), SimError> {
    use rand::Rng;
    scenario.validate()?;
    let (phys, act, asym) = Physics::new(hull.as_ref(), &scenario.effects);
    hull.set_asymmetry(asym);
    let hull: &dyn Hull = hull.as_ref();
    let n = scenario.n_samples;
    let ts = scenario.ts;
    let ft = hull.froude_time();
    let psi0 = match scenario.initial_heading_deg {
        Some(h) => h,
        None => 360.0 * inputs::rng(seed, inputs::STREAM_HEADING).random::<f64>(),
    };
    // the world's random processes, one stream each
    let tau_bg = hull.lpp() / hull.u0();
    let bg = gauss_markov(
        &mut inputs::rng(seed, STREAM_BACKGROUND),
        n,
        ts,
        tau_bg,
        scenario.disturbance * BACKGROUND_RUDDER_DEG.abs() * rudder_moment(hull, 1.0).abs(),
    );
    let gust_std = if phys.wind_ne == (0.0, 0.0) {
        0.0
    } else {
        GUST_STD
    };
    let gust = gauss_markov(
        &mut inputs::rng(seed, STREAM_GUST),
        n,
        ts,
        GUST_TAU_S * ft,
        gust_std,
    );
    let weather: Vec<Weather> = bg
        .iter()
        .zip(&gust)
        .map(|(&m, &g)| Weather {
            moment: m,
            gust: 1.0 + g,
        })
        .collect();
    let sensors = Sensors::marine(ft);
    let mut sr = inputs::rng(seed, STREAM_SENSORS);
    let drift = gauss_markov(
        &mut sr,
        n,
        ts,
        sensors.gyro_drift_tau_s,
        sensors.gyro_drift_degps,
    );
    let compass = gauss_markov(
        &mut sr,
        n,
        ts,
        sensors.compass_tau_s,
        sensors.compass_err_deg,
    );

    let open = scenario.input.open_loop(n, ts, seed);
    let mut closed = inputs::Closed::of(&scenario.input, n, ts, seed);
    let mut decide = |k: usize, s: &State| match (&open, closed.as_mut()) {
        (Some(u), _) => u[k],
        (None, Some(c)) => c.command(k, s[5].to_degrees(), s[2].to_degrees()),
        (None, None) => 0.0,
    };
    let mut cmds = Vec::with_capacity(n);
    let mut states: Vec<(State, Weather)> = Vec::with_capacity(n);
    let mut gears: Vec<dynamics::Actuator> = Vec::with_capacity(n);
    run_hull(
        HullRun {
            hull,
            phys: &phys,
            act,
            ts,
            n,
            dt_max: scenario.dt_max,
            warmup_s: scenario.warmup_s,
            psi0_deg: psi0,
            weather: &weather,
        },
        |k, s| {
            let c = decide(k, s);
            cmds.push(c);
            c
        },
        |_, s, w, act| {
            states.push((*s, w));
            gears.push(act.clone());
            true
        },
    )?;
    if let Some((s, _)) = states.last() {
        if cmds.len() < states.len() {
            cmds.push(decide(states.len() - 1, s));
        }
    }
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
        cog: Some(Vec::with_capacity(n)),
    };
    // a GPS's velocity noise is isotropic: the speed's `speed_std_mps` across the track
    // too, so the course errs by that over the speed (own stream: nothing else changes)
    let mut cr = inputs::rng(seed, STREAM_COURSE);
    let mut nr = inputs::rng(seed, inputs::STREAM_NOISE);
    let ns: NoiseSpec = scenario.noise;
    let mut white = |std: f64| {
        if std > 0.0 {
            std * inputs::gauss(&mut nr)
        } else {
            0.0
        }
    };
    for (k, (s, w)) in states.iter().enumerate() {
        rec.u.push(if scenario.log_angle {
            gears[k].delta.to_degrees()
        } else {
            cmds[k]
        });
        let g = white(ns.gyro_std_degps);
        let gyro = s[2].to_degrees() + phys.gyro_bias + drift[k] + g;
        rec.y.push(quantise(gyro, sensors.gyro_lsb_degps));
        let h = white(ns.heading_std_deg);
        let heading = s[5].to_degrees() + compass[k] + h;
        push(&mut rec.psi, quantise(heading, sensors.compass_lsb_deg));
        let sn = white(ns.speed_std_mps);
        push(&mut rec.speed, phys.sog(s) + sn);
        let (vn, ve) = phys.ground_velocity(s);
        let cross = if ns.speed_std_mps > 0.0 {
            ns.speed_std_mps * inputs::gauss(&mut cr)
        } else {
            0.0
        };
        let cog = ve.atan2(vn) + cross / vn.hypot(ve).max(0.1);
        push(&mut rec.cog, cog.to_degrees().rem_euclid(360.0));
        if scenario.log_wind {
            let (ua, va) = phys.air(s, *w);
            push(&mut rec.wind_speed, ua.hypot(va));
            push(&mut rec.wind_angle, va.atan2(ua).to_degrees());
        }
    }
    let oracle = Oracle {
        horizon,
        yaw_rate_degps: oracle::predict(
            &oracle::Replay {
                step: Integrator::new(hull, &phys, ts, scenario.dt_max),
                states: &states,
                gears: &gears,
                cmds: &cmds,
                tau_background_s: tau_bg,
                tau_gust_s: GUST_TAU_S * ft,
                drift: &drift,
                tau_drift_s: sensors.gyro_drift_tau_s,
                gyro_bias_degps: phys.gyro_bias,
            },
            horizon,
        ),
    };
    Ok((rec, oracle))
}

fn push(v: &mut Option<Vec<f64>>, x: f64) {
    if let Some(v) = v.as_mut() {
        v.push(x);
    }
}

/// A calm, disturbance-free manoeuvre run on `hull` (its own gear, no effects).
fn calm_run<'a>(hull: &'a dyn Hull, phys: &'a Physics, act: dynamics::Actuator) -> HullRun<'a> {
    let ft = hull.froude_time();
    HullRun {
        hull,
        phys,
        act,
        ts: 0.25 * ft,
        n: (7200.0 / 0.25) as usize,
        dt_max: 0.125 * ft,
        warmup_s: 60.0 * ft,
        psi0_deg: 0.0,
        weather: &[],
    }
}

fn turning_hull(hull: &dyn Hull, delta_deg: f64) -> Result<TurningResult, SimError> {
    if !delta_deg.is_finite() || delta_deg == 0.0 {
        return Err(SimError::invalid(
            "delta_deg",
            delta_deg,
            "finite and non-zero",
        ));
    }
    let (p, act, _) = Physics::new(hull, &[]);
    let sg = delta_deg.signum();
    let mut track = TurningTracker::new();
    run_hull(
        calm_run(hull, &p, act),
        |_, _| delta_deg,
        |_, s, _, _| {
            track.observe(
                sg * s[5].to_degrees(),
                s[3],
                sg * s[4],
                s[2].to_degrees(),
                p.sog(s),
            )
        },
    )?;
    track.result(delta_deg, "")
}

fn zigzag_hull(hull: &dyn Hull, delta_deg: f64, psi_deg: f64) -> Result<ZigzagResult, SimError> {
    super::ship::within("delta_deg", delta_deg, 1e-3, 90.0)?;
    super::ship::within("psi_deg", psi_deg, 1e-3, 180.0)?;
    let (p, act, _) = Physics::new(hull, &[]);
    let spec = calm_run(hull, &p, act);
    let ts = spec.ts;
    let mut logic = ZigZagLogic::new(delta_deg, psi_deg);
    let mut track = ZigzagTracker::new(psi_deg);
    run_hull(
        spec,
        |_, s| logic.command(s[5].to_degrees()),
        |k, s, _, _| track.observe(k, k as f64 * ts, s[5].to_degrees()),
    )?;
    track.result("")
}

#[cfg(test)]
mod tests;
