//! The 3-DOF MMG equations of motion, the force models (hull, pods, wind, effects), the
//! actuator chain and the RK4 integrator.
//!
//! State `[u, v, r, x_N, y_E, ψ]`: `u, v` are velocities over ground in body axes (m/s),
//! `r` the yaw rate (rad/s), `x_N, y_E` the position (m), `ψ` the heading (rad, unwrapped).
//! Hull and pod forces see the velocity through the water (`u − u_c`, `v − v_c`); the inertia
//! terms use the ground velocities, as MMG simulators usually do, so a current acts on a
//! turning ship with a heading-dependent force (first harmonic in ψ). Wind forces use the
//! velocity through the air.

use super::{Ship, SimEffect};
use crate::effects::SimKnobs;

/// Number of states.
pub(crate) const NX: usize = 6;

/// Everything the right-hand side needs, in SI units and radians.
#[derive(Debug, Clone)]
pub(crate) struct Model {
    lpp: f64,
    half_rho_ld: f64,
    half_rho_l2d: f64,
    half_rho_l4d: f64,
    h: super::ship::HullCoefficients,
    m: f64,
    mx: f64,
    my: f64,
    xg: f64,
    /// Inverse of the sway–yaw mass block.
    minv_vr: [[f64; 2]; 2],
    // pods
    n_pods: f64,
    rho: f64,
    rps: f64,
    d_prop: f64,
    kt: [f64; 3],
    wake: f64,
    tp: f64,
    pod_lift: f64,
    gamma_p: f64,
    l_p: f64,
    eps: f64,
    kappa: f64,
    eta: f64,
    a_h: f64,
    lever: f64,
    // wind
    wx: f64,
    wy: f64,
    wn1: f64,
    wn2: f64,
    // effects
    pub(crate) bias_nm: f64,
    pub(crate) asym: f64,
    pub(crate) n_rr: f64,
    pub(crate) cubic: bool,
    /// True wind towards (N, E) components (m/s).
    pub(crate) wind_ne: (f64, f64),
    /// Current (N, E) components (m/s).
    pub(crate) current_ne: (f64, f64),
}

/// Forces and derived quantities at one state.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Apparent {
    /// Apparent wind speed (m/s).
    pub speed: f64,
    /// Apparent wind angle from the bow, positive from starboard (rad).
    pub angle: f64,
}

impl Model {
    /// Derived constants of `ship` with the environment and hull effects of `effects`.
    pub(crate) fn new(ship: &Ship, effects: &[SimEffect]) -> Model {
        let mp = &ship.main;
        let l = mp.lpp_m;
        let d = mp.draft_m;
        let rho = mp.rho_water;
        let half_rho_ld = 0.5 * rho * l * d;
        let half_rho_l2d = half_rho_ld * l;
        let half_rho_l4d = half_rho_l2d * l * l;
        let h = ship.hull;
        let m = mp.mass_kg;
        let mx = h.m_x * half_rho_l2d;
        let my = h.m_y * half_rho_l2d;
        let jz = h.j_z * half_rho_l4d;
        let xg = mp.x_g_m;
        let izg = m * (mp.k_zz * l).powi(2);
        let a11 = m + my;
        let a12 = xg * m;
        let a22 = izg + xg * xg * m + jz;
        let det = a11 * a22 - a12 * a12;
        let minv_vr = [[a22 / det, -a12 / det], [-a12 / det, a11 / det]];
        let p = &ship.pods;
        let w = &ship.windage;
        let half_rho_air = 0.5 * mp.rho_air;
        let mut model = Model {
            lpp: l,
            half_rho_ld,
            half_rho_l2d,
            half_rho_l4d,
            h,
            m,
            mx,
            my,
            xg,
            minv_vr,
            n_pods: f64::from(p.count),
            rho,
            rps: p.rps,
            d_prop: p.diameter_m,
            kt: p.kt,
            wake: p.wake,
            tp: p.thrust_deduction,
            pod_lift: 0.5 * rho * p.lateral_area_m2 * p.lift_slope,
            gamma_p: p.flow_straightening,
            l_p: p.inflow_lever * l,
            eps: p.slipstream_epsilon,
            kappa: p.slipstream_kappa,
            eta: p.slipstream_eta,
            a_h: p.a_h,
            lever: p.x_m + p.a_h * p.x_h_m,
            wx: half_rho_air * w.frontal_area_m2 * w.c_x,
            wy: half_rho_air * w.lateral_area_m2 * w.c_y,
            wn1: half_rho_air * w.lateral_area_m2 * mp.loa_m * w.c_n1,
            wn2: half_rho_air * w.lateral_area_m2 * mp.loa_m * w.c_n2,
            bias_nm: 0.0,
            asym: 0.0,
            n_rr: 0.0,
            cubic: false,
            wind_ne: (0.0, 0.0),
            current_ne: (0.0, 0.0),
        };
        let k = SimKnobs::of(effects);
        model.bias_nm = k.yaw_moment_nm;
        model.asym = k.starboard_gain;
        model.n_rr = k.n_rr;
        model.cubic = k.cubic;
        model.wind_ne = k.wind_ne;
        model.current_ne = k.current_ne;
        model
    }

    /// Total pod thrust (N) at surge speed through the water `ur`, and the inflow speed
    /// over the housings along the pod axis.
    #[inline]
    fn thrust(&self, ur: f64) -> (f64, f64) {
        let nd = self.rps * self.d_prop;
        let ua = (ur * (1.0 - self.wake)).max(0.0);
        let j = ua / nd;
        let kt = self.kt[0] + self.kt[1] * j + self.kt[2] * j * j;
        let t = self.n_pods * self.rho * self.rps * self.rps * self.d_prop.powi(4) * kt;
        // slipstream: u·√(1 + 8K_T/(πJ²)) written without dividing by J
        let slip = (ua * ua + 8.0 * kt.max(0.0) * nd * nd / std::f64::consts::PI).sqrt();
        let up_core = ua + self.kappa * (slip - ua);
        let up = self.eps * (self.eta * up_core * up_core + (1.0 - self.eta) * ua * ua).sqrt();
        (t, up)
    }

    /// Equilibrium surge speed on a straight course in still air and water at δ = 0, by
    /// bisection; `None` when none lies below 30 m/s.
    pub(crate) fn equilibrium_speed(&self) -> Option<f64> {
        let net = |u: f64| {
            let mut s = [0.0; NX];
            s[0] = u;
            self.forces(&s, 0.0, 1.0, Self::calm()).0
        };
        let (lo, hi) = (1e-3, 30.0);
        if net(lo) <= 0.0 || net(hi) >= 0.0 {
            return None;
        }
        // Past the equilibrium the thrust no longer exceeds the resistance.
        Some(super::bisect(lo, hi, 80, |u| net(u) <= 0.0))
    }

    fn calm() -> Env {
        Env {
            wind: (0.0, 0.0),
            current: (0.0, 0.0),
        }
    }

    /// The environment of this model.
    pub(crate) fn env(&self) -> Env {
        Env {
            wind: self.wind_ne,
            current: self.current_ne,
        }
    }

    /// Water-relative velocities in body axes.
    #[inline]
    fn relative(s: &[f64; NX], env: Env) -> (f64, f64) {
        if env.current == (0.0, 0.0) {
            return (s[0], s[1]);
        }
        let (sp, cp) = s[5].sin_cos();
        let (cn, ce) = env.current;
        let uc = cn * cp + ce * sp;
        let vc = -cn * sp + ce * cp;
        (s[0] - uc, s[1] - vc)
    }

    /// Air-relative velocities in body axes (the apparent wind comes from this direction).
    #[inline]
    pub(crate) fn air(s: &[f64; NX], env: Env) -> (f64, f64) {
        if env.wind == (0.0, 0.0) {
            return (s[0], s[1]);
        }
        let (sp, cp) = s[5].sin_cos();
        let (wn, we) = env.wind;
        let uw = wn * cp + we * sp;
        let vw = -wn * sp + we * cp;
        (s[0] - uw, s[1] - vw)
    }

    /// Apparent wind at a state.
    pub(crate) fn apparent(&self, s: &[f64; NX]) -> Apparent {
        let (ua, va) = Self::air(s, self.env());
        Apparent {
            speed: ua.hypot(va),
            angle: va.atan2(ua),
        }
    }

    /// External forces `(X, Y, N)` at state `s` with pod angle δ given as (sin δ, cos δ).
    #[inline]
    fn forces(&self, s: &[f64; NX], sd: f64, cd: f64, env: Env) -> (f64, f64, f64) {
        let r = s[2];
        let (ur, vr) = Self::relative(s, env);
        let h = &self.h;
        // hull (MMG, non-dimensional polynomials)
        let u2 = (ur * ur + vr * vr).max(1e-4);
        let uu = u2.sqrt();
        let vp = vr / uu;
        let rp = r * self.lpp / uu;
        let q = self.half_rho_ld * u2;
        let [xh, yh, nh] = h.forces(vp, rp);
        let (xh, yh, nh) = (q * xh, q * yh, q * self.lpp * nh);
        // pods: vectored thrust plus the housings' lift in the local inflow
        let (t, up) = self.thrust(ur);
        let vlat = self.gamma_p * (vr + self.l_p * r);
        let up2 = up * up + vlat * vlat;
        let upn = up2.sqrt().max(1e-9);
        // sin α with α = δ + atan2(vlat, up)
        let sin_in = vlat / upn;
        let cos_in = up / upn;
        let fn_of = |sd: f64, cd: f64| self.pod_lift * up2 * (sd * cos_in + cd * sin_in);
        let fnd = fn_of(sd, cd);
        let mut side = t * sd + fnd * cd;
        if self.asym != 0.0 && sd > 0.0 {
            let side0 = fn_of(0.0, 1.0);
            side = side0 + (1.0 + self.asym) * (side - side0);
        }
        let xp = (1.0 - self.tp) * t * cd - fnd * sd;
        let yp = -(1.0 + self.a_h) * side;
        let np = -self.lever * side;
        // wind (always: the ship's own motion through still air as well)
        let (ua, va) = Self::air(s, env);
        let vra = ua.hypot(va);
        let xa = -self.wx * vra * ua;
        let ya = -self.wy * vra * va;
        let na = self.wn1 * vra * va - 2.0 * self.wn2 * ua * va;
        // effects acting as moments
        let mut ne = self.bias_nm;
        if self.n_rr != 0.0 {
            ne -= if self.cubic {
                self.n_rr * self.half_rho_l2d * u2 * rp * rp * rp
            } else {
                self.n_rr * self.half_rho_l4d * r * r.abs()
            };
        }
        (xh + xp + xa, yh + yp + ya, nh + np + na + ne)
    }

    /// Time derivative of the state.
    #[inline]
    fn deriv(&self, s: &[f64; NX], sd: f64, cd: f64, env: Env) -> [f64; NX] {
        let (u, v, r, psi) = (s[0], s[1], s[2], s[5]);
        let (x, y, n) = self.forces(s, sd, cd, env);
        let m = self.m;
        let fu = x + (m + self.my) * v * r + self.xg * m * r * r;
        let fv = y - (m + self.mx) * u * r;
        let fr = n - self.xg * m * u * r;
        let udot = fu / (m + self.mx);
        let vdot = self.minv_vr[0][0] * fv + self.minv_vr[0][1] * fr;
        let rdot = self.minv_vr[1][0] * fv + self.minv_vr[1][1] * fr;
        let (sp, cp) = psi.sin_cos();
        [udot, vdot, rdot, u * cp - v * sp, u * sp + v * cp, r]
    }

    /// One RK4 step of length `dt` with the pod angle held at `delta` (rad).
    #[inline]
    pub(crate) fn rk4(&self, s: &mut [f64; NX], delta: f64, dt: f64, env: Env) {
        let (sd, cd) = delta.sin_cos();
        let k1 = self.deriv(s, sd, cd, env);
        let mut tmp = [0.0; NX];
        for i in 0..NX {
            tmp[i] = s[i] + 0.5 * dt * k1[i];
        }
        let k2 = self.deriv(&tmp, sd, cd, env);
        for i in 0..NX {
            tmp[i] = s[i] + 0.5 * dt * k2[i];
        }
        let k3 = self.deriv(&tmp, sd, cd, env);
        for i in 0..NX {
            tmp[i] = s[i] + dt * k3[i];
        }
        let k4 = self.deriv(&tmp, sd, cd, env);
        for i in 0..NX {
            s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

/// Steady environment: true wind velocity (towards, N/E) and current (N/E), m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Env {
    pub wind: (f64, f64),
    pub current: (f64, f64),
}

/// The pod actuator chain: dead time, angle limit, dead band, largest rate and first-order
/// servo lag.
#[derive(Debug, Clone)]
pub(crate) struct Actuator {
    /// Dead time (s).
    pub dead_time: f64,
    /// Angle limit (rad).
    pub limit: f64,
    /// Largest pod rate (rad/s).
    pub max_rate: f64,
    /// Servo time constant (s).
    pub tau: f64,
    /// Dead band (backlash) width (rad), 0 without one.
    pub band: f64,
    /// Actual pod angle (rad).
    pub delta: f64,
}

impl Actuator {
    /// A gear of dead time `dead_time_s`, angle limit `limit_deg`, largest rate
    /// `max_rate_degps` and servo time constant `tau_s`, with the gear effects of `k` on
    /// top: their dead time added, the smaller limit and rate, their dead band.
    pub(crate) fn with_knobs(
        dead_time_s: f64,
        limit_deg: f64,
        max_rate_degps: f64,
        tau_s: f64,
        k: &SimKnobs,
    ) -> Actuator {
        Actuator {
            dead_time: dead_time_s + k.dead_time_s,
            limit: limit_deg.min(k.limit_deg).to_radians(),
            max_rate: max_rate_degps.min(k.max_rate_degps).to_radians(),
            tau: tau_s,
            band: k.band_deg.to_radians(),
            delta: 0.0,
        }
    }

    /// The ship's actuator with the actuator effects of `effects` applied.
    pub(crate) fn new(ship: &Ship, effects: &[SimEffect]) -> Actuator {
        let a = &ship.actuator;
        Actuator::with_knobs(
            a.dead_time_s,
            a.max_angle_deg,
            a.max_rate_degps,
            a.servo_tau_s,
            &SimKnobs::of(effects),
        )
    }

    /// Moves the pod angle over `dt` towards the (delayed) command `cmd` (rad): the limit
    /// clips the target, a dead band leaves the pods where they are while the target is
    /// within the band and otherwise aims them the band's width short of it, the servo lag
    /// is integrated exactly, the largest rate clips the move.
    #[inline]
    pub(crate) fn step(&mut self, cmd: f64, dt: f64) {
        let target = cmd.clamp(-self.limit, self.limit);
        let target = if self.band > 0.0 {
            self.delta.clamp(target - self.band, target + self.band)
        } else {
            target
        };
        let lag = if self.tau > 0.0 {
            1.0 - (-dt / self.tau).exp()
        } else {
            1.0
        };
        let max = self.max_rate * dt;
        self.delta += ((target - self.delta) * lag).clamp(-max, max);
    }
}
