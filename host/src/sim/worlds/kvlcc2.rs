//! KVLCC2 (the MOERI 320 m VLCC tanker) by the MMG standard method.
//!
//! Source: Yasukawa, H. & Yoshimura, Y. (2015), *Introduction of MMG standard method for ship
//! maneuvering predictions*, J. Mar. Sci. Technol. 20, 37–52 (doi 10.1007/s00773-014-0293-y),
//! Tables 1–4: principal particulars (full scale `L_pp` 320 m, `B` 58 m, `d` 20.8 m,
//! `∇` 312 600 m³, `x_G` 11.2 m, `D_P` 9.86 m, `H_R` 15.80 m, `A_R` 112.5 m²), the hull's
//! resistance and derivatives from captive tests of the 7 m model, and the propeller,
//! rudder and interaction coefficients. The approach speed is the paper's `Fn` = 0.142
//! (15.5 kn at full scale), with the propeller revolutions set for equilibrium at it.
//!
//! The equations are [`super::mmg`]'s, the wake's change with the inflow angle the MMG
//! standard method's own (`C_1`, `C_2`).
//!
//! - Steering gear: 2.34 °/s (the SIMMAN 2008 free-running tests' full-scale rate), ±35°,
//!   servo lag 2 s; times Froude-scaled with the hull.
//!
//! With `--scale L` the same hull is built at `L_pp = L` (Froude similarity: lengths by
//! `1/λ`, speeds and times by `1/√λ`, `λ = 320/L`); the non-dimensional coefficients are the
//! model's own, so the motion in `L_pp` and `L_pp/U` units does not change with the scale.

use super::env::Windage;
use super::mmg::{Coeffs, Wake};
use super::Gear;
use crate::sim::HullCoefficients;

/// Full-scale length between perpendiculars (m).
pub(crate) const LPP_FULL: f64 = 320.0;

/// KVLCC2 at full scale (Yasukawa & Yoshimura 2015, Tables 1–4).
pub(crate) const KVLCC2: Coeffs = Coeffs {
    name: "KVLCC2",
    lpp: LPP_FULL,
    froude: 0.142,
    rho: 1025.0,
    // Principal particulars at full scale (Table 1).
    d: 20.8,
    nabla: 312_600.0,
    x_g: 11.2,
    d_p: 9.86,
    h_r: 15.80,
    a_r: 112.5,
    hull: HullCoefficients {
        // Added masses (Table 2).
        m_x: 0.022,
        m_y: 0.223,
        j_z: 0.011,
        // Hull resistance and derivatives (Table 3).
        r0: 0.022,
        x_vv: -0.040,
        x_vr: 0.002,
        x_rr: 0.011,
        x_vvvv: 0.771,
        y_v: -0.315,
        y_r: 0.083,
        y_vvv: -1.607,
        y_vvr: 0.379,
        y_vrr: -0.391,
        y_rrr: 0.008,
        n_v: -0.137,
        n_r: -0.049,
        n_vvv: -0.030,
        n_vvr: -0.294,
        n_vrr: 0.055,
        n_rrr: -0.013,
    },
    k_zz: 0.25,
    // Propeller (Table 2).
    t_p: 0.220,
    w_p0: 0.40,
    wake: Wake::Mmg {
        c1: 2.0,
        c2_pos: 1.6,
        c2_neg: 1.1,
    },
    k: [0.2931, -0.2753, -0.1385],
    x_p: -0.48,
    // Rudder and interaction (Table 2).
    t_r: 0.387,
    a_h: 0.312,
    x_h: -0.464,
    x_r: -0.5,
    gamma_r_neg: 0.395,
    gamma_r_pos: 0.640,
    l_r: -0.710,
    eps: 1.09,
    kappa: 0.50,
    f_alpha: 2.747,
    gear: Gear {
        tau_s: 2.0,
        limit_deg: 35.0,
        rate_degps: 2.34,
    },
    // Estimated from the particulars (depth 30 m, so 9.2 m freeboard over 320 m) and a
    // VLCC's aft accommodation block; Blendermann's "tanker, loaded".
    windage: Windage {
        loa: 325.0,
        a_l: 3600.0,
        a_f: 1400.0,
        s_l: -25.0,
        cd_t: 0.70,
        cd_l_bow: 0.90,
        cd_l_stern: 0.55,
        delta: 0.40,
    },
};

#[cfg(test)]
mod tests {
    use super::super::mmg::Mmg;
    use super::super::Hull;
    use super::super::{World, WorldKind};
    use super::*;

    #[test]
    fn approach_is_an_equilibrium_at_fn_0142() {
        let h = Mmg::new(&KVLCC2, LPP_FULL);
        assert!((h.u0() - 7.956).abs() < 0.01, "{}", h.u0());
        let a = h.accel([h.u0(), 0.0, 0.0], 0.0, [0.0; 3]);
        assert!(a.iter().all(|x| x.abs() < 1e-9), "{a:?}");
        // Froude similarity: the 7 m model turns at the full scale's revolutions × √λ
        let m = Mmg::new(&KVLCC2, 7.0);
        let ratio = m.revolutions() / h.revolutions() / (320.0f64 / 7.0).sqrt();
        assert!((ratio - 1.0).abs() < 1e-6, "{ratio}");
        println!(
            "n_P full scale {:.3} rps, 7 m model {:.2} rps",
            h.revolutions(),
            m.revolutions()
        );
    }

    /// Free-running model tests of KVLCC2 (SIMMAN 2008, MARIN, `Fn` 0.142), against which
    /// Yasukawa & Yoshimura (2015, §5, Figs. 10–11) check this model: 35° turning to
    /// starboard with an advance of about 3.1 `L_pp` and a tactical diameter of about
    /// 3.3 `L_pp`; 10°/10° zig-zag with a first overshoot of about 8°. The ranges below are
    /// those figures with the spread of the paper's simulation and the repeated tests.
    #[test]
    fn turning_circle_and_zigzag_match_the_published_trials() {
        let w = World::new(WorldKind::Kvlcc2, None).unwrap();
        let l = LPP_FULL;
        let tc = w.turning_circle(35.0).unwrap();
        println!(
            "KVLCC2 35°: advance {:.2} L, tactical diameter {:.2} L, transfer {:.2} L, steady r {:.3} °/s, U {:.2} m/s",
            tc.advance_m / l,
            tc.tactical_diameter_m / l,
            tc.transfer_m / l,
            tc.steady_r_degps,
            tc.steady_speed_mps
        );
        assert!((2.8..3.5).contains(&(tc.advance_m / l)), "{tc:?}");
        assert!((2.9..3.8).contains(&(tc.tactical_diameter_m / l)), "{tc:?}");
        let port = w.turning_circle(-35.0).unwrap();
        println!(
            "KVLCC2 −35°: advance {:.2} L, tactical diameter {:.2} L",
            port.advance_m / l,
            port.tactical_diameter_m / l
        );
        assert!(port.steady_r_degps < 0.0);
        assert!(
            tc.steady_speed_mps < 0.6 * 7.956,
            "a full hull loses speed in the turn"
        );
        let z = w.zigzag(10.0, 10.0).unwrap();
        println!("KVLCC2 10/10: {z:?}");
        assert!((4.0..12.0).contains(&z.first_overshoot_deg), "{z:?}");
        assert!(z.second_overshoot_deg > z.first_overshoot_deg);
        // the model-scale hull turns the same circle in L_pp units
        let small = World::new(WorldKind::Kvlcc2, Some(7.0)).unwrap();
        let ts = small.turning_circle(35.0).unwrap();
        assert!(
            (ts.tactical_diameter_m / 7.0 - tc.tactical_diameter_m / l).abs() < 0.02,
            "{ts:?}"
        );
    }
}
