//! Standard manoeuvres for sanity checks: turning circle and zig-zag (IMO MSC.137(76) style),
//! run on the ship with its own effects and no noise.

use super::inputs::ZigZagLogic;
use super::{run, RunSpec, Ship, SimError};

/// Sample time of the manoeuvre runs (s).
const TS: f64 = 0.1;
/// Longest manoeuvre (s).
const T_MAX: f64 = 7200.0;

/// Turning-circle figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurningResult {
    /// Advance: distance along the approach course when the heading has changed by 90° (m).
    pub advance_m: f64,
    /// Transfer: distance across the approach course at 90° heading change (m).
    pub transfer_m: f64,
    /// Tactical diameter: distance across the approach course at 180° heading change (m).
    pub tactical_diameter_m: f64,
    /// Steady yaw rate, averaged over the heading change 360°–450° (deg/s, signed as δ).
    pub steady_r_degps: f64,
    /// Steady speed over ground over the same stretch (m/s).
    pub steady_speed_mps: f64,
}

/// Zig-zag figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZigzagResult {
    /// Heading overshoot beyond the switch angle after the first switch (deg).
    pub first_overshoot_deg: f64,
    /// Heading overshoot after the second switch (deg).
    pub second_overshoot_deg: f64,
    /// Time from the start to the first switch (s).
    pub time_to_switch_s: f64,
}

/// Bookkeeping of a turning circle, shared by every simulator: fed each sample's heading
/// change `dpsi` (deg, positive into the turn), position (x ahead, y into the turn, m), yaw
/// rate (deg/s) and speed (m/s).
#[derive(Debug)]
pub(crate) struct TurningTracker {
    prev: Option<(f64, f64, f64)>, // (Δψ deg, x, y)
    at90: Option<(f64, f64)>,
    at180: Option<(f64, f64)>,
    r_sum: f64,
    sp_sum: f64,
    cnt: usize,
    done: bool,
}

impl TurningTracker {
    pub(crate) fn new() -> TurningTracker {
        TurningTracker {
            prev: None,
            at90: None,
            at180: None,
            r_sum: 0.0,
            sp_sum: 0.0,
            cnt: 0,
            done: false,
        }
    }

    /// Observes one sample; `false` once the heading has turned 450° (the run may stop).
    pub(crate) fn observe(&mut self, dpsi: f64, x: f64, y: f64, r_degps: f64, speed: f64) -> bool {
        if let Some((p, px, py)) = self.prev {
            for (target, slot) in [(90.0, &mut self.at90), (180.0, &mut self.at180)] {
                if slot.is_none() && p < target && dpsi >= target {
                    let w = (target - p) / (dpsi - p);
                    *slot = Some((px + w * (x - px), py + w * (y - py)));
                }
            }
        }
        self.prev = Some((dpsi, x, y));
        if (360.0..450.0).contains(&dpsi) {
            self.r_sum += r_degps;
            self.sp_sum += speed;
            self.cnt += 1;
        }
        self.done = dpsi >= 450.0;
        !self.done
    }

    /// The figures, or why there are none (`within` says how long the run was allowed).
    pub(crate) fn result(&self, delta_deg: f64, within: &str) -> Result<TurningResult, SimError> {
        match (self.at90, self.at180, self.done && self.cnt > 0) {
            (Some((adv, tr)), Some((_, td)), true) => Ok(TurningResult {
                advance_m: adv,
                transfer_m: tr,
                tactical_diameter_m: td,
                steady_r_degps: self.r_sum / self.cnt as f64,
                steady_speed_mps: self.sp_sum / self.cnt as f64,
            }),
            _ => Err(SimError::Manoeuvre {
                manoeuvre: "turning circle",
                reason: format!("heading did not change by 450°{within} at δ = {delta_deg}°"),
            }),
        }
    }
}

/// Bookkeeping of a zig-zag's overshoots, shared by every simulator: fed each sample's
/// heading change (deg) before the command logic sees it.
#[derive(Debug)]
pub(crate) struct ZigzagTracker {
    psi_deg: f64,
    switches: usize,
    max1: f64,
    min2: f64,
    t_switch: f64,
}

impl ZigzagTracker {
    pub(crate) fn new(psi_deg: f64) -> ZigzagTracker {
        ZigzagTracker {
            psi_deg,
            switches: 0,
            max1: f64::NEG_INFINITY,
            min2: f64::INFINITY,
            t_switch: f64::NAN,
        }
    }

    /// Observes sample `k` (time `t` s) with heading change `dpsi`; `false` once the third
    /// switch has come (the run may stop).
    pub(crate) fn observe(&mut self, k: usize, t: f64, dpsi: f64) -> bool {
        // the logic switches in `command`, called right after this observation
        match self.switches {
            1 => self.max1 = self.max1.max(dpsi),
            2 => self.min2 = self.min2.min(dpsi),
            _ => {}
        }
        let will_switch = match self.switches % 2 {
            0 => dpsi >= self.psi_deg,
            _ => dpsi <= -self.psi_deg,
        };
        if will_switch && k > 0 {
            self.switches += 1;
            if self.switches == 1 {
                self.t_switch = t;
                self.max1 = dpsi;
            }
            if self.switches == 2 {
                self.min2 = dpsi;
            }
        }
        self.switches < 3
    }

    /// The figures, or why there are none (`within` says how long the run was allowed).
    pub(crate) fn result(&self, within: &str) -> Result<ZigzagResult, SimError> {
        if self.switches < 3 {
            return Err(SimError::Manoeuvre {
                manoeuvre: "zig-zag",
                reason: format!("only {} of 3 switches{within}", self.switches),
            });
        }
        Ok(ZigzagResult {
            first_overshoot_deg: self.max1 - self.psi_deg,
            second_overshoot_deg: -self.min2 - self.psi_deg,
            time_to_switch_s: self.t_switch,
        })
    }
}

fn settled(ship: &Ship) -> RunSpec<'_> {
    RunSpec {
        ship,
        effects: ship.effects(),
        ts: TS,
        n: (T_MAX / TS) as usize,
        dt_max: 0.05,
        warmup_s: 60.0,
        psi0_deg: 0.0,
    }
}

/// Turning circle from a steady straight approach (at the ship's own speed) with a constant
/// command `delta_deg` from `t = 0`.
///
/// # Errors
/// [`SimError::Invalid`] for a bad ship or a non-finite or zero `delta_deg`;
/// [`SimError::Manoeuvre`] when the heading does not change by 450° within two hours.
///
/// ```
/// use yawcast::sim::{turning_circle, Ship};
/// let ship = Ship::default_lng();
/// let tc = turning_circle(&ship, 35.0).unwrap();
/// let l = ship.main.lpp_m;
/// assert!(tc.tactical_diameter_m > 2.0 * l && tc.tactical_diameter_m < 6.0 * l);
/// ```
pub fn turning_circle(ship: &Ship, delta_deg: f64) -> Result<TurningResult, SimError> {
    ship.validate()?;
    if !delta_deg.is_finite() || delta_deg == 0.0 {
        return Err(SimError::invalid(
            "delta_deg",
            delta_deg,
            "finite and non-zero",
        ));
    }
    let sg = delta_deg.signum();
    let spec = settled(ship);
    let mut track = TurningTracker::new();
    run(
        &spec,
        |_, _| delta_deg,
        |smp| {
            let s = smp.state;
            track.observe(
                sg * s[5].to_degrees(),
                s[3],
                sg * s[4],
                s[2].to_degrees(),
                s[0].hypot(s[1]),
            )
        },
    )?;
    track.result(delta_deg, &format!(" within {T_MAX} s"))
}

/// Zig-zag `delta_deg`/`psi_deg` (10/10, 20/20, …) from a steady straight approach,
/// starting to starboard.
///
/// # Errors
/// [`SimError::Invalid`] for a bad ship or non-positive angles; [`SimError::Manoeuvre`]
/// when the third switch does not come within two hours.
///
/// ```
/// use yawcast::sim::{zigzag, Ship};
/// let z = zigzag(&Ship::default_lng(), 10.0, 10.0).unwrap();
/// assert!(z.first_overshoot_deg > 2.0 && z.first_overshoot_deg < 20.0);
/// ```
pub fn zigzag(ship: &Ship, delta_deg: f64, psi_deg: f64) -> Result<ZigzagResult, SimError> {
    ship.validate()?;
    super::ship::within("delta_deg", delta_deg, 1e-3, 90.0)?;
    super::ship::within("psi_deg", psi_deg, 1e-3, 180.0)?;
    let spec = settled(ship);
    let mut logic = ZigZagLogic::new(delta_deg, psi_deg);
    let mut track = ZigzagTracker::new(psi_deg);
    run(
        &spec,
        |_, s| logic.command(s[5].to_degrees()),
        |smp| track.observe(smp.k, smp.k as f64 * TS, smp.state[5].to_degrees()),
    )?;
    track.result(&format!(" within {T_MAX} s"))
}
