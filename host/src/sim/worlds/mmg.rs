//! One hull by the MMG standard method, its coefficients a table ([`Coeffs`]): the KVLCC2
//! tanker ([`super::kvlcc2`]) and the Seiun Maru training ship ([`super::seiun`]).
//!
//! Equations of Yasukawa, H. & Yoshimura, Y. (2015), *Introduction of MMG standard method
//! for ship maneuvering predictions*, J. Mar. Sci. Technol. 20, 37–52
//! (doi 10.1007/s00773-014-0293-y):
//!
//! - Hull: `X'_H = −R'_0 + X'_vv v'² + X'_vr v'r' + X'_rr r'² + X'_vvvv v'⁴`, `Y'_H`, `N'_H`
//!   cubic in `v' = v_m/U`, `r' = rL/U`.
//! - Propeller: `X_P = (1 − t_P) ρ n² D_P⁴ K_T(J_P)`, `K_T = k_0 + k_1 J + k_2 J²`, the wake
//!   at `β_P = β − x'_P r'` by [`Wake`].
//! - Rudder: normal force `F_N = ½ρ A_R U_R² f_α sin α_R` with the propeller slipstream in
//!   `u_R` (ε, κ, η) and the flow straightening `v_R = U γ_R (β − ℓ'_R r')`;
//!   `X_R = −(1 − t_R) F_N sin δ`, `Y_R = −(1 + a_H) F_N cos δ`,
//!   `N_R = −(x_R + a_H x_H) F_N cos δ`.
//!
//! The approach is the hull's own Froude number, with the propeller revolutions set for
//! equilibrium at it. Built at `L_pp = L` by Froude similarity (lengths by `1/λ`, speeds and
//! times by `1/√λ`, `λ = L_full/L`); the non-dimensional coefficients are the model's own,
//! so the motion in `L_pp` and `L_pp/U` units does not change with the scale.

use super::env::Windage;
use super::{Gear, Hull};
use crate::sim::HullCoefficients;

const G: f64 = 9.81;

/// How the propeller's wake fraction changes with the inflow angle `β_P`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Wake {
    /// The MMG standard method's `1 − w_P = (1 − w_P0)[1 + (1 − e^{−C_1|β_P|})(C_2 − 1)]`,
    /// `C_2` by the sign of `β_P`.
    Mmg { c1: f64, c2_pos: f64, c2_neg: f64 },
    /// Kijima et al. (1990): `w_P = w_P0 e^{−4 β_P²}`.
    Kijima,
}

/// One hull's particulars (full scale) and non-dimensional coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Coeffs {
    /// Name for reports.
    pub name: &'static str,
    /// Length between perpendiculars (m).
    pub lpp: f64,
    /// Froude number of the approach.
    pub froude: f64,
    /// Water density (kg/m³).
    pub rho: f64,
    /// Draft (m).
    pub d: f64,
    /// Displacement volume (m³).
    pub nabla: f64,
    /// Centre of gravity forward of midships (m).
    pub x_g: f64,
    /// Propeller diameter (m).
    pub d_p: f64,
    /// Rudder span (m).
    pub h_r: f64,
    /// Rudder area (m²).
    pub a_r: f64,
    /// Added masses, resistance and the hull's derivatives (non-dimensional).
    pub hull: HullCoefficients,
    /// Yaw radius of gyration over `L_pp`.
    pub k_zz: f64,
    /// Thrust deduction `t_P` and straight-ahead wake `w_P0`.
    pub t_p: f64,
    pub w_p0: f64,
    /// The wake's change with the inflow angle.
    pub wake: Wake,
    /// Open-water thrust `K_T = k[0] + k[1] J + k[2] J²`.
    pub k: [f64; 3],
    /// Propeller position `x'_P`.
    pub x_p: f64,
    /// Steering resistance deduction `t_R`, rudder force increase `a_H`, its point `x'_H`,
    /// the rudder's position `x'_R`.
    pub t_r: f64,
    pub a_h: f64,
    pub x_h: f64,
    pub x_r: f64,
    /// Flow straightening `γ_R` for `β_R < 0` and `≥ 0`, and `ℓ'_R`.
    pub gamma_r_neg: f64,
    pub gamma_r_pos: f64,
    pub l_r: f64,
    /// Slipstream: `ε`, `κ`, and the rudder's lift gradient `f_α`.
    pub eps: f64,
    pub kappa: f64,
    pub f_alpha: f64,
    /// Steering gear at full scale.
    pub gear: Gear,
    /// Windage at full scale.
    pub windage: Windage,
}

/// An MMG hull at one scale, with its derived constants.
#[derive(Debug, Clone)]
pub(crate) struct Mmg {
    c: &'static Coeffs,
    lpp: f64,
    d: f64,
    d_p: f64,
    a_r: f64,
    u0: f64,
    n_p: f64,
    eta: f64,
    m: f64,
    mx: f64,
    my: f64,
    xg: f64,
    minv_vr: [[f64; 2]; 2],
    lambda: f64,
    /// Extra rudder effectiveness to starboard (asymmetry effect).
    pub(crate) asym: f64,
}

impl Mmg {
    /// The hull `c` at `L_pp = lpp` metres (`c.lpp` full scale).
    pub(crate) fn new(c: &'static Coeffs, lpp: f64) -> Mmg {
        let lambda = c.lpp / lpp;
        let d = c.d / lambda;
        let d_p = c.d_p / lambda;
        let h_r = c.h_r / lambda;
        let half_rho_l2d = 0.5 * c.rho * lpp * lpp * d;
        let m = c.rho * c.nabla / lambda.powi(3);
        let mx = c.hull.m_x * half_rho_l2d;
        let my = c.hull.m_y * half_rho_l2d;
        let jz = c.hull.j_z * half_rho_l2d * lpp * lpp;
        let xg = c.x_g / lambda;
        let izg = m * (c.k_zz * lpp).powi(2);
        let a11 = m + my;
        let a12 = xg * m;
        let a22 = izg + xg * xg * m + jz;
        let det = a11 * a22 - a12 * a12;
        let u0 = c.froude * (G * lpp).sqrt();
        let mut hull = Mmg {
            c,
            lpp,
            d,
            d_p,
            a_r: c.a_r / (lambda * lambda),
            u0,
            n_p: 0.0,
            eta: d_p / h_r,
            m,
            mx,
            my,
            xg,
            minv_vr: [[a22 / det, -a12 / det], [-a12 / det, a11 / det]],
            lambda,
            asym: 0.0,
        };
        hull.n_p = hull.revolutions_for(u0);
        hull
    }

    /// `K_T(J)`.
    #[inline]
    fn thrust_coefficient(&self, j: f64) -> f64 {
        let [k0, k1, k2] = self.c.k;
        k0 + k1 * j + k2 * j * j
    }

    /// Propeller revolutions (rev/s) for which thrust balances the hull's resistance on a
    /// straight course at `u` (bisection).
    fn revolutions_for(&self, u: f64) -> f64 {
        let c = self.c;
        let resist = c.hull.r0 * 0.5 * c.rho * self.lpp * self.d * u * u;
        let net = |n: f64| {
            let j = u * (1.0 - c.w_p0) / (n * self.d_p);
            let kt = self.thrust_coefficient(j);
            (1.0 - c.t_p) * c.rho * n * n * self.d_p.powi(4) * kt - resist
        };
        // Past the revolutions sought the thrust exceeds the resistance.
        crate::sim::bisect(1e-3, 1e3, 200, |n| net(n) > 0.0)
    }

    /// Rudder forces `(X_R, Y_R, N_R)` at rudder angle δ (rad) given the inflow.
    #[inline]
    fn rudder(&self, delta: f64, u_r: f64, v_r: f64) -> (f64, f64, f64) {
        let c = self.c;
        let alpha = delta - v_r.atan2(u_r);
        let f_n = 0.5 * c.rho * self.a_r * (u_r * u_r + v_r * v_r) * c.f_alpha * alpha.sin();
        let (sd, cd) = delta.sin_cos();
        let lever = (c.x_r + c.a_h * c.x_h) * self.lpp;
        (
            -(1.0 - c.t_r) * f_n * sd,
            -(1.0 + c.a_h) * f_n * cd,
            -lever * f_n * cd,
        )
    }

    /// Propeller revolutions (rev/s) at this scale.
    #[cfg(test)]
    pub(crate) fn revolutions(&self) -> f64 {
        self.n_p
    }
}

impl Hull for Mmg {
    fn name(&self) -> String {
        format!("{} (MMG, Lpp {} m)", self.c.name, self.lpp)
    }

    fn lpp(&self) -> f64 {
        self.lpp
    }

    fn draft(&self) -> f64 {
        self.d
    }

    fn rho(&self) -> f64 {
        self.c.rho
    }

    fn u0(&self) -> f64 {
        self.u0
    }

    fn froude_time(&self) -> f64 {
        self.lambda.sqrt().recip()
    }

    fn gear(&self) -> Gear {
        let t = self.froude_time();
        let g = self.c.gear;
        Gear {
            tau_s: g.tau_s * t,
            limit_deg: g.limit_deg,
            rate_degps: g.rate_degps / t,
        }
    }

    fn windage(&self) -> Windage {
        self.c.windage.scaled(self.lambda)
    }

    fn set_asymmetry(&mut self, gain: f64) {
        self.asym = gain;
    }

    fn set_approach_speed(&mut self, u: f64) -> bool {
        self.u0 = u;
        self.n_p = self.revolutions_for(u);
        true
    }

    fn accel(&self, s: [f64; 3], delta: f64, ext: [f64; 3]) -> [f64; 3] {
        let c = self.c;
        let [u, v, r] = s;
        let l = self.lpp;
        let u2 = (u * u + v * v).max(1e-8);
        let uu = u2.sqrt();
        let vp = v / uu;
        let rp = r * l / uu;
        let q = 0.5 * c.rho * l * self.d * u2;
        let [xh, yh, nh] = c.hull.forces(vp, rp);
        let (xh, yh, nh) = (q * xh, q * yh, q * l * nh);
        // propeller
        let beta = (-v).atan2(u);
        let beta_p = beta - c.x_p * rp;
        let one_w = match c.wake {
            Wake::Mmg { c1, c2_pos, c2_neg } => {
                let c2 = if beta_p > 0.0 { c2_pos } else { c2_neg };
                (1.0 - c.w_p0) * (1.0 + (1.0 - (-c1 * beta_p.abs()).exp()) * (c2 - 1.0))
            }
            Wake::Kijima => 1.0 - c.w_p0 * (-4.0 * beta_p * beta_p).exp(),
        };
        let nd = self.n_p * self.d_p;
        let u_p = (u * one_w).max(0.0);
        let j = u_p / nd;
        let kt = self.thrust_coefficient(j);
        let xp = (1.0 - c.t_p) * c.rho * self.n_p * self.n_p * self.d_p.powi(4) * kt;
        // rudder inflow: slipstream u_P·√(1 + 8K_T/(πJ²)) written without dividing by J
        let slip = (u_p * u_p + 8.0 * kt.max(0.0) * nd * nd / std::f64::consts::PI).sqrt();
        let core = u_p + c.kappa * (slip - u_p);
        let u_r = c.eps * (self.eta * core * core + (1.0 - self.eta) * u_p * u_p).sqrt();
        let beta_r = beta - c.l_r * rp;
        let gamma_r = if beta_r < 0.0 {
            c.gamma_r_neg
        } else {
            c.gamma_r_pos
        };
        let v_r = uu * gamma_r * beta_r;
        let (mut xr, mut yr, mut nr) = self.rudder(delta, u_r, v_r);
        if self.asym != 0.0 && delta > 0.0 {
            let (x0, y0, n0) = self.rudder(0.0, u_r, v_r);
            let g = 1.0 + self.asym;
            xr = x0 + g * (xr - x0);
            yr = y0 + g * (yr - y0);
            nr = n0 + g * (nr - n0);
        }
        let (x, y, n) = (xh + xp + xr + ext[0], yh + yr + ext[1], nh + nr + ext[2]);
        let m = self.m;
        let fu = x + (m + self.my) * v * r + self.xg * m * r * r;
        let fv = y - (m + self.mx) * u * r;
        let fr = n - self.xg * m * u * r;
        [
            fu / (m + self.mx),
            self.minv_vr[0][0] * fv + self.minv_vr[0][1] * fr,
            self.minv_vr[1][0] * fv + self.minv_vr[1][1] * fr,
        ]
    }
}
