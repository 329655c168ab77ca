//! The environment shared by the test worlds: relative wind with Blendermann's (1994)
//! coefficient curves and first-order gusts, the sensors (rate gyro, compass) and the
//! first-order random processes behind gusts, the background yaw disturbance and the sensor
//! drifts.

use std::f64::consts::{FRAC_PI_2, PI};

use rand_chacha::ChaCha8Rng;

use crate::sim::inputs::gauss;

/// Density of air (kg/m³) in the wind loads.
pub(crate) const RHO_AIR: f64 = 1.225;

/// Above-water geometry and Blendermann's coefficients of one hull.
///
/// Blendermann, W. (1994), *Parameter identification of wind loads on ships*, J. Wind Eng.
/// Ind. Aerodyn. 51, 339–351 (the coefficients per ship type as tabulated in Fossen 2021,
/// *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., §10.1). With γ the
/// apparent wind angle from the bow (positive from starboard), `V` its speed, `q = ½ρ_a V²`,
/// `C_Dl = C_Dl,AF · A_F / A_L` and `D(γ) = 1 − ½δ(1 − C_Dl/C_Dt) sin² 2γ`:
///
/// - `X = q A_F · (−C_Dl,AF cos γ / D)`,
/// - `Y = q A_L · (−C_Dt sin γ / D)`,
/// - `N = q A_L L_oa · (−sgn γ) C_N(|γ|)`, `C_N(g) = (s_L/L_oa − 0.18 (g − π/2)) · C_Dt sin g / D`.
///
/// The moment's arm moves from forward of the lateral centroid in bow winds to aft of it in
/// stern winds, so the bow is pushed to leeward in bow winds and turns into stern-quarter
/// winds, with the change of sign at `γ = π/2 + s_L/(0.18 L_oa)`, not at 90° as in a pure
/// `sin 2γ` curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Windage {
    /// Length overall (m).
    pub loa: f64,
    /// Lateral projected area (m²).
    pub a_l: f64,
    /// Frontal projected area (m²).
    pub a_f: f64,
    /// Horizontal position of the lateral area's centroid from midships (m, + forward).
    pub s_l: f64,
    /// Transverse drag coefficient `C_Dt`.
    pub cd_t: f64,
    /// Longitudinal drag coefficient on `A_F` with the wind from ahead.
    pub cd_l_bow: f64,
    /// Longitudinal drag coefficient on `A_F` with the wind from astern.
    pub cd_l_stern: f64,
    /// Cross-force parameter δ.
    pub delta: f64,
}

impl Windage {
    /// The same geometry at `1/lambda` scale (lengths by `1/λ`, areas by `1/λ²`).
    pub(crate) fn scaled(self, lambda: f64) -> Windage {
        Windage {
            loa: self.loa / lambda,
            a_l: self.a_l / (lambda * lambda),
            a_f: self.a_f / (lambda * lambda),
            s_l: self.s_l / lambda,
            ..self
        }
    }

    /// Non-dimensional coefficients `(C_X, C_Y, C_N)` at the apparent wind angle `gamma`
    /// (rad, from the bow, positive from starboard), signed as forces and moment on the ship
    /// (`C_N < 0` turns the bow to port).
    pub(crate) fn coefficients(&self, gamma: f64) -> (f64, f64, f64) {
        let g = gamma.abs().min(PI);
        let cd_l_af = if g <= FRAC_PI_2 {
            self.cd_l_bow
        } else {
            self.cd_l_stern
        };
        let cd_l = cd_l_af * self.a_f / self.a_l;
        let s2 = (2.0 * g).sin();
        let den = 1.0 - 0.5 * self.delta * (1.0 - cd_l / self.cd_t) * s2 * s2;
        let sg = if gamma < 0.0 { -1.0 } else { 1.0 };
        let cy = self.cd_t * g.sin() / den;
        let cx = -cd_l_af * g.cos() / den;
        let cn = (self.s_l / self.loa - 0.18 * (g - FRAC_PI_2)) * cy;
        (cx, -sg * cy, -sg * cn)
    }

    /// Wind loads `(X, Y, N)` (N, N, N·m) for the air-relative body velocity `(ua, va)`
    /// of the ship (its velocity minus the wind's, m/s).
    pub(crate) fn loads(&self, ua: f64, va: f64) -> (f64, f64, f64) {
        let v2 = ua * ua + va * va;
        if v2 == 0.0 || self.a_l <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let (cx, cy, cn) = self.coefficients(va.atan2(ua));
        let q = 0.5 * RHO_AIR * v2;
        (
            q * self.a_f * cx,
            q * self.a_l * cy,
            q * self.a_l * self.loa * cn,
        )
    }
}

/// Samples of a stationary first-order (Gauss–Markov) process with standard deviation `std`
/// and time constant `tau` (s) at the sample time `ts`, `n` of them, from `rng`; zeros when
/// `std` is zero (and then `rng` is not drawn from).
pub(crate) fn gauss_markov(
    rng: &mut ChaCha8Rng,
    n: usize,
    ts: f64,
    tau: f64,
    std: f64,
) -> Vec<f64> {
    if std == 0.0 {
        return vec![0.0; n];
    }
    let a = (-ts / tau).exp();
    let b = (1.0 - a * a).sqrt();
    let mut x = std * gauss(rng);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(x);
        x = a * x + b * std * gauss(rng);
    }
    out
}

/// What the sensors add to the true yaw rate and heading, beyond the white noise of
/// [`NoiseSpec`](crate::sim::NoiseSpec).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sensors {
    /// Rate-gyro bias instability: a first-order drift of this standard deviation (deg/s)…
    pub gyro_drift_degps: f64,
    /// …and this time constant (s).
    pub gyro_drift_tau_s: f64,
    /// Rate-gyro resolution (deg/s).
    pub gyro_lsb_degps: f64,
    /// Compass (gyrocompass) error: a first-order error of this standard deviation (deg)…
    pub compass_err_deg: f64,
    /// …and this time constant (s).
    pub compass_tau_s: f64,
    /// Compass resolution (deg).
    pub compass_lsb_deg: f64,
}

impl Sensors {
    /// A fibre-optic rate gyro (bias instability 0.002 °/s over 10 min, resolution
    /// 0.001 °/s) and a gyrocompass (settle error 0.1° with a 2-min time constant, display
    /// resolution 0.1°) at full scale; time constants Froude-scaled by `time_scale`, rates
    /// by its inverse.
    pub(crate) fn marine(time_scale: f64) -> Sensors {
        Sensors {
            gyro_drift_degps: 0.002 / time_scale,
            gyro_drift_tau_s: 600.0 * time_scale,
            gyro_lsb_degps: 0.001 / time_scale,
            compass_err_deg: 0.1,
            compass_tau_s: 120.0 * time_scale,
            compass_lsb_deg: 0.1,
        }
    }
}

/// Rounds `x` to a multiple of `lsb` (no rounding when `lsb` is zero).
pub(crate) fn quantise(x: f64, lsb: f64) -> f64 {
    if lsb > 0.0 {
        (x / lsb).round() * lsb
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::inputs::rng;

    /// KVLCC2's full-scale windage.
    fn tanker() -> Windage {
        super::super::kvlcc2::KVLCC2.windage
    }

    #[test]
    fn blendermann_moment_has_its_published_shape() {
        let w = tanker();
        let cn = |deg: f64| w.coefficients(f64::to_radians(deg)).2;
        // wind from the starboard bow pushes the bow to port (leeward), from the starboard
        // quarter it turns the bow to starboard (into the wind); mirrored from port
        assert!(
            cn(30.0) < 0.0 && cn(150.0) > 0.0,
            "{} {}",
            cn(30.0),
            cn(150.0)
        );
        assert!(cn(-30.0) > 0.0 && cn(-150.0) < 0.0);
        assert!((cn(40.0) + cn(-40.0)).abs() < 1e-12);
        assert_eq!(cn(0.0), 0.0);
        assert!(cn(180.0).abs() < 1e-12);
        // the sign changes at π/2 + s_L/(0.18 L_oa) = 65.5°, not at 90° as sin 2γ would
        let cross = 90.0 + (w.s_l / w.loa / 0.18).to_degrees();
        assert!((cross - 65.52).abs() < 0.01, "{cross}");
        assert!(cn(cross - 1.0) < 0.0 && cn(cross + 1.0) > 0.0);
        assert!(cn(90.0) > 0.0);
        // head wind pushes astern, beam wind from starboard pushes to port
        let (cx0, cy0, _) = w.coefficients(0.0);
        assert!((cx0 + 0.90).abs() < 1e-12 && cy0 == 0.0);
        let (_, cy90, _) = w.coefficients(FRAC_PI_2);
        assert!((cy90 + 0.70).abs() < 1e-12, "{cy90}");
        // loads: ship making 8 m/s into still air = head wind, X = −½ρ V² A_F C_Dl,AF
        let (x, y, n) = w.loads(8.0, 0.0);
        assert!((x + 0.5 * RHO_AIR * 64.0 * 1400.0 * 0.9).abs() < 1e-6);
        assert!(y.abs() < 1e-9 && n.abs() < 1e-9);
        // scaling keeps the coefficients and divides the loads at Froude-scaled speed by λ³
        let m = w.scaled(45.7);
        let v = 8.0 / 45.7_f64.sqrt();
        let (_, _, n1) = w.loads(8.0, 4.0);
        let (_, _, n2) = m.loads(v, 0.5 * v);
        assert!(
            (n1 / n2 / 45.7_f64.powi(4) - 1.0).abs() < 1e-9,
            "{}",
            n1 / n2
        );
    }

    #[test]
    fn gauss_markov_is_stationary_with_its_std() {
        let mut r = rng(5, 99);
        let x = gauss_markov(&mut r, 40_000, 1.0, 10.0, 0.5);
        let m = x.iter().sum::<f64>() / x.len() as f64;
        let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / x.len() as f64;
        assert!(m.abs() < 0.03 && (v.sqrt() - 0.5).abs() < 0.03, "{m} {v}");
        // lag-10 autocorrelation e^{-1}
        let c = x.windows(11).map(|w| w[0] * w[10]).sum::<f64>() / (x.len() - 10) as f64;
        assert!((c / v - (-1.0f64).exp()).abs() < 0.05, "{}", c / v);
        assert_eq!(gauss_markov(&mut r, 3, 1.0, 10.0, 0.0), vec![0.0; 3]);
        assert_eq!(quantise(0.123_4, 0.1), 0.1);
        assert_eq!(quantise(0.123_4, 0.0), 0.123_4);
    }
}
