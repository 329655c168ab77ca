//! The physics every hull of the test worlds shares: the effects' loads, the wind, the
//! current and the background weather on the hull's state, and the RK4 step.

use super::env::Windage;
use super::{dynamics, Hull};
use crate::effects::SimKnobs;
use crate::sim::SimEffect;

/// The horizontal part of the sway velocity, `v cos φ` (`v` itself upright).
#[inline]
fn sway(s: &State) -> f64 {
    s[1] * s[7].cos()
}

/// A hull's state: `[u, v, r, x_N, y_E, ψ, p, φ]`, with `u, v` the velocity through the
/// water in body axes (m/s), `r` the yaw rate (rad/s), `x_N, y_E` the position (m), `ψ` the
/// heading (rad), `p` the roll rate (rad/s) and `φ` the heel (rad). A hull without roll
/// keeps `p = φ = 0`, and its motion is the plane motion, bit for bit.
pub(super) type State = [f64; 8];

/// The effects' physics on a hull.
#[derive(Debug, Clone)]
pub(super) struct Physics {
    pub(super) windage: Windage,
    pub(super) bias_nm: f64,
    pub(super) n_rr: f64,
    pub(super) cubic: bool,
    pub(super) gyro_bias: f64,
    /// True wind velocity, towards (N, E), m/s.
    pub(super) wind_ne: (f64, f64),
    /// Current velocity, towards (N, E), m/s.
    pub(super) current_ne: (f64, f64),
    pub(super) half_rho_l2d: f64,
    pub(super) half_rho_l4d: f64,
    pub(super) lpp: f64,
}

/// One sample's random environment: background moment (N·m) and gust factor.
#[derive(Debug, Clone, Copy)]
pub(super) struct Weather {
    pub(super) moment: f64,
    pub(super) gust: f64,
}

pub(super) const CALM: Weather = Weather {
    moment: 0.0,
    gust: 1.0,
};

impl Physics {
    /// The physics of `effects` on `hull`, its gear with the gear effects, and the
    /// `asymmetry` effect's gain (for [`Hull::set_asymmetry`]).
    pub(super) fn new(
        hull: &dyn Hull,
        effects: &[SimEffect],
    ) -> (Physics, dynamics::Actuator, f64) {
        let gear = hull.gear();
        let k = SimKnobs::of(&merged(effects));
        let act =
            dynamics::Actuator::with_knobs(0.0, gear.limit_deg, gear.rate_degps, gear.tau_s, &k);
        let (l, d, rho) = (hull.lpp(), hull.draft(), hull.rho());
        let mut p = Physics {
            windage: hull.windage(),
            bias_nm: 0.0,
            n_rr: 0.0,
            cubic: false,
            gyro_bias: 0.0,
            wind_ne: (0.0, 0.0),
            current_ne: (0.0, 0.0),
            half_rho_l2d: 0.5 * rho * l * l * d,
            half_rho_l4d: 0.5 * rho * l.powi(4) * d,
            lpp: l,
        };
        p.bias_nm = k.yaw_moment_nm;
        p.gyro_bias = k.gyro_bias_degps;
        p.n_rr = k.n_rr;
        p.cubic = k.cubic;
        p.wind_ne = k.wind_ne;
        p.current_ne = k.current_ne;
        (p, act, k.starboard_gain)
    }

    /// Current and (gusting) true wind in body axes at heading ψ.
    #[inline]
    pub(super) fn body(&self, psi: f64, gust: f64) -> ((f64, f64), (f64, f64)) {
        let (sp, cp) = psi.sin_cos();
        let rot = |(n, e): (f64, f64)| (n * cp + e * sp, -n * sp + e * cp);
        let (wn, we) = self.wind_ne;
        (rot(self.current_ne), rot((wn * gust, we * gust)))
    }

    /// Air-relative body velocity (the apparent wind comes from its direction).
    #[inline]
    pub(super) fn air(&self, s: &State, w: Weather) -> (f64, f64) {
        let ((uc, vc), (uw, vw)) = self.body(s[5], w.gust);
        (s[0] + uc - uw, sway(s) + vc - vw)
    }

    /// Speed over ground.
    pub(super) fn sog(&self, s: &State) -> f64 {
        let ((uc, vc), _) = self.body(s[5], 1.0);
        (s[0] + uc).hypot(sway(s) + vc)
    }

    /// Velocity over ground (north, east; m/s): the hull's through the water plus the
    /// current.
    pub(super) fn ground_velocity(&self, s: &State) -> (f64, f64) {
        let (sp, cp) = s[5].sin_cos();
        let (cn, ce) = self.current_ne;
        let v = sway(s);
        (s[0] * cp - v * sp + cn, s[0] * sp + v * cp + ce)
    }

    /// The state's rate of change: the hull's accelerations under the effects' and the
    /// environment's loads, the ground velocity, the heading's rate `r cos φ` and the roll.
    #[inline]
    pub(super) fn deriv(&self, hull: &dyn Hull, s: &State, delta: f64, w: Weather) -> State {
        let (ua, va) = self.air(s, w);
        let (xa, ya, na) = self.windage.loads(ua, va);
        let mut n = na + self.bias_nm + w.moment;
        let r = s[2];
        if self.n_rr != 0.0 {
            n -= if self.cubic {
                let u2 = (s[0] * s[0] + s[1] * s[1]).max(1e-8);
                let rp = r * self.lpp / u2.sqrt();
                self.n_rr * self.half_rho_l2d * u2 * rp * rp * rp
            } else {
                self.n_rr * self.half_rho_l4d * r * r.abs()
            };
        }
        let a = hull.accel_roll([s[0], s[1], r, s[6], s[7]], delta, [xa, ya, n]);
        let (vn, ve) = self.ground_velocity(s);
        [a[0], a[1], a[2], vn, ve, r * s[7].cos(), a[3], s[6]]
    }

    pub(super) fn rk4(&self, hull: &dyn Hull, s: &mut State, delta: f64, dt: f64, w: Weather) {
        let k1 = self.deriv(hull, s, delta, w);
        let mut tmp = [0.0; 8];
        for i in 0..8 {
            tmp[i] = s[i] + 0.5 * dt * k1[i];
        }
        let k2 = self.deriv(hull, &tmp, delta, w);
        for i in 0..8 {
            tmp[i] = s[i] + 0.5 * dt * k2[i];
        }
        let k3 = self.deriv(hull, &tmp, delta, w);
        for i in 0..8 {
            tmp[i] = s[i] + dt * k3[i];
        }
        let k4 = self.deriv(hull, &tmp, delta, w);
        for i in 0..8 {
            s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

/// The effects in force: of several of one kind, the last.
pub(super) fn merged(effects: &[SimEffect]) -> Vec<SimEffect> {
    let mut out: Vec<SimEffect> = Vec::new();
    for e in effects {
        match out.iter_mut().find(|x| x.kind() == e.kind()) {
            Some(x) => *x = *e,
            None => out.push(*e),
        }
    }
    out
}
