//! The Seiun Maru (a 105 m training ship, single screw, `C_b` 0.508) by the MMG standard
//! method: a fine, fast hull, unlike KVLCC2's full one.
//!
//! Sources:
//! - Hull derivatives, flow straightening (`γ_R`, `ℓ'_R`), rudder interaction (`t_R`,
//!   `a_H`, `x'_H`) and slipstream (`ε`, `κ`, `f_α`): Yoshimura, Y. & Masumoto, Y. (2012),
//!   *Hydrodynamic database and manoeuvring prediction method with medium high-speed
//!   merchant ships and fishing vessels*, MARSIM 2012, as tabulated in the `mmgdynamics`
//!   package (N. Paulig, `calibrated_vessels.py`, `seiunmaru`), which also gives the
//!   particulars (`L_pp` 105 m, `B` 17.91 m, `d` 5.966 m, `x_G` −2.249 m, `D_P` 4.7 m,
//!   `A_R` 13.405 m²) and the propeller's 2.93 rev/s maximum.
//! - Added masses by the empirical formulas that package cites (`m'_x = 0.05 m'`, `m'_y`,
//!   `J'_z` after Zhou et al. 1983), the wake's change with the inflow angle by Kijima et
//!   al. (1990), and the open-water `K_T = 0.4 − 0.4 J` and `R'_0` = 0.016 as estimated
//!   there (no captive tests of this propeller are published).
//! - Assumed here: the approach at `Fn` 0.20 (12.5 kn, the revolutions 1.8 rev/s of the
//!   2.93 the engine gives), a faster steering gear than the big hulls' (3 °/s, ±35°, servo
//!   lag 1 s), and the windage of a ship with a large accommodation block, Blendermann's
//!   "research vessel" (`L_oa` 116 m, estimated areas).
//!
//! Nothing in `diagnose` was chosen on this world: it was added after the rules were set,
//! to check them on a hull they never saw.

use super::env::Windage;
use super::mmg::{Coeffs, Wake};
use super::Gear;
use crate::sim::HullCoefficients;

/// Full-scale length between perpendiculars (m).
pub(crate) const LPP_FULL: f64 = 105.0;

/// Displacement volume (m³): `C_b L B d`, 0.508 × 105 × 17.91 × 5.966.
const NABLA: f64 = 5_699.4;

/// `m' = m/(½ρL²d)`, for the empirical added masses.
const M_PRIME: f64 = NABLA / (0.5 * LPP_FULL * LPP_FULL * 5.966);

/// The Seiun Maru at full scale.
pub(crate) const SEIUN_MARU: Coeffs = Coeffs {
    name: "Seiun Maru",
    lpp: LPP_FULL,
    froude: 0.20,
    rho: 1025.0,
    d: 5.966,
    nabla: NABLA,
    x_g: -2.249,
    d_p: 4.7,
    h_r: 4.7 / 0.960,
    a_r: 13.405,
    hull: HullCoefficients {
        m_x: 0.05 * M_PRIME,
        m_y: 0.9089 * M_PRIME,
        j_z: 0.0537 * M_PRIME,
        r0: 0.016,
        x_vv: -0.0804,
        x_vr: 0.072,
        x_rr: 0.022,
        x_vvvv: 0.439,
        y_v: -0.317,
        y_r: 0.052,
        y_vvv: -1.604,
        y_vvr: -0.75,
        y_vrr: -0.8599,
        y_rrr: -0.051,
        n_v: -0.1136,
        n_r: -0.0795,
        n_vvv: -0.3095,
        n_vvr: -0.6257,
        n_vrr: -0.3143,
        n_rrr: -0.0502,
    },
    k_zz: 0.25,
    t_p: 0.21,
    w_p0: 0.204,
    wake: Wake::Kijima,
    k: [0.4, -0.4, 0.0],
    x_p: -0.5,
    t_r: 0.341,
    a_h: 0.236,
    x_h: -0.4,
    x_r: -0.5,
    gamma_r_neg: 0.312,
    gamma_r_pos: 0.394,
    l_r: -0.947,
    eps: 1.033,
    kappa: 0.676,
    f_alpha: 2.88,
    gear: Gear {
        tau_s: 1.0,
        limit_deg: 35.0,
        rate_degps: 3.0,
    },
    windage: Windage {
        loa: 116.0,
        a_l: 1200.0,
        a_f: 280.0,
        s_l: 2.0,
        cd_t: 0.85,
        cd_l_bow: 0.55,
        cd_l_stern: 0.65,
        delta: 0.60,
    },
};

#[cfg(test)]
mod tests {
    use super::super::mmg::Mmg;
    use super::super::{Hull, World, WorldKind};
    use super::*;

    #[test]
    fn approach_is_an_equilibrium_within_the_engines_revolutions() {
        let h = Mmg::new(&SEIUN_MARU, LPP_FULL);
        assert!((h.u0() - 6.419).abs() < 0.01, "{}", h.u0());
        let a = h.accel([h.u0(), 0.0, 0.0], 0.0, [0.0; 3]);
        assert!(a.iter().all(|x| x.abs() < 1e-9), "{a:?}");
        let n = h.revolutions();
        println!("Seiun Maru: n_P {n:.3} rps at {:.2} m/s", h.u0());
        assert!(n > 1.5 && n < 2.93, "{n}");
    }

    /// No free-running trials of this hull are published with the coefficients, so the
    /// checks are the physics a fine single-screw hull must show: a turning circle of a
    /// few lengths with the speed lost in the turn, a 10°/10° zig-zag that checks the
    /// swing with a small overshoot (a course-stable hull), and a turn to port unlike the
    /// turn to starboard (flow straightening differs to port and starboard).
    #[test]
    fn turning_circle_and_zigzag_are_a_fine_single_screw_hulls() {
        let w = World::new(WorldKind::SeiunMaru, None).unwrap();
        let l = LPP_FULL;
        let tc = w.turning_circle(35.0).unwrap();
        let port = w.turning_circle(-35.0).unwrap();
        let z = w.zigzag(10.0, 10.0).unwrap();
        println!(
            "Seiun Maru 35°: advance {:.2} L, tactical diameter {:.2} L, steady r {:.3} °/s, U {:.2} m/s; \
             −35°: tactical diameter {:.2} L; 10/10: {z:?}",
            tc.advance_m / l,
            tc.tactical_diameter_m / l,
            tc.steady_r_degps,
            tc.steady_speed_mps,
            port.tactical_diameter_m / l
        );
        assert!((2.0..5.0).contains(&(tc.tactical_diameter_m / l)), "{tc:?}");
        assert!((2.0..5.0).contains(&(tc.advance_m / l)), "{tc:?}");
        assert!(port.steady_r_degps < 0.0 && tc.steady_r_degps > 0.0);
        assert!(
            (tc.tactical_diameter_m - port.tactical_diameter_m).abs() > 0.01 * l,
            "{tc:?} {port:?}"
        );
        assert!(
            tc.steady_speed_mps < 0.8 * 6.419,
            "speed is lost in the turn"
        );
        assert!((1.0..10.0).contains(&z.first_overshoot_deg), "{z:?}");
    }
}
