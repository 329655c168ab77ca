//! The ship description: main particulars, MMG hull coefficients, pods, actuator and
//! windage, read from a TOML ship file and validated field by field.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{SimEffect, SimError};

/// The built-in ship file (the paper's 1:24 LNG carrier), embedded at compile time.
pub const DEFAULT_SHIP_TOML: &str = include_str!("../../ships/lng_1to24.toml");

/// A ship for the simulator: what a TOML ship file holds.
///
/// Start from [`Ship::default_lng`] (or a copy of `host/ships/lng_1to24.toml`) and edit.
/// The fields are public for convenience; [`simulate`](super::simulate) validates them on
/// every call, so a bad edit gives an error, never a panic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ship {
    /// A name for reports.
    pub name: String,
    /// Main particulars and mass.
    pub main: MainParticulars,
    /// MMG hull coefficients (non-dimensional).
    pub hull: HullCoefficients,
    /// The azimuth pods.
    pub pods: Pods,
    /// The steering actuator (servo lag, limits, dead time).
    pub actuator: Actuator,
    /// Above-water areas and wind coefficients.
    pub windage: Windage,
    /// Effects carried by this ship (e.g. written back by an identification).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    effects: Vec<SimEffect>,
}

/// Main particulars (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MainParticulars {
    /// Length overall (m); the reference length of the wind moment.
    pub loa_m: f64,
    /// Length between perpendiculars (m); the reference length of the hull coefficients.
    pub lpp_m: f64,
    /// Beam (m).
    pub beam_m: f64,
    /// Draft (m).
    pub draft_m: f64,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Longitudinal centre of gravity from midships (m, positive forward).
    pub x_g_m: f64,
    /// Radius of gyration in yaw as a fraction of Lpp.
    pub k_zz: f64,
    /// Water density (kg/m³).
    pub rho_water: f64,
    /// Air density (kg/m³).
    pub rho_air: f64,
}

/// MMG hull coefficients, non-dimensional (Yasukawa & Yoshimura 2015 conventions).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)] // the names are the coefficients' own: x_vv is X'_vv, and so on
pub struct HullCoefficients {
    /// Surge added mass m'_x.
    pub m_x: f64,
    /// Sway added mass m'_y.
    pub m_y: f64,
    /// Yaw added moment of inertia J'_z.
    pub j_z: f64,
    /// Resistance coefficient R'_0.
    pub r0: f64,
    pub x_vv: f64,
    pub x_vr: f64,
    pub x_rr: f64,
    pub x_vvvv: f64,
    pub y_v: f64,
    pub y_r: f64,
    pub y_vvv: f64,
    pub y_vvr: f64,
    pub y_vrr: f64,
    pub y_rrr: f64,
    pub n_v: f64,
    pub n_r: f64,
    pub n_vvv: f64,
    pub n_vvr: f64,
    pub n_vrr: f64,
    pub n_rrr: f64,
}

impl HullCoefficients {
    /// The hull's non-dimensional forces `(X'_H, Y'_H, N'_H)` at `v' = v/U`, `r' = rL/U`:
    /// `X'_H = −R'_0 + X'_vv v'² + X'_vr v'r' + X'_rr r'² + X'_vvvv v'⁴`, `Y'_H` and `N'_H`
    /// cubic in `v'` and `r'` (MMG). Times `½ρLdU²` (and `L` for `N`) they are forces.
    ///
    /// ```
    /// let h = yawcast::sim::Ship::default_lng().hull;
    /// let [x, y, n] = h.forces(0.0, 0.0);
    /// assert_eq!((x, y, n), (-h.r0, 0.0, 0.0));
    /// ```
    #[inline]
    pub fn forces(&self, vp: f64, rp: f64) -> [f64; 3] {
        let h = self;
        let v2 = vp * vp;
        let r2 = rp * rp;
        [
            -h.r0 + h.x_vv * v2 + h.x_vr * vp * rp + h.x_rr * r2 + h.x_vvvv * v2 * v2,
            cubic([h.y_v, h.y_r, h.y_vvv, h.y_vvr, h.y_vrr, h.y_rrr], vp, rp),
            cubic([h.n_v, h.n_r, h.n_vvv, h.n_vvr, h.n_vrr, h.n_rrr], vp, rp),
        ]
    }
}

/// `a_v v' + a_r r' + a_vvv v'²v' + a_vvr v'²r' + a_vrr v'r'² + a_rrr r'²r'`, the MMG sway
/// force's and yaw moment's polynomial, summed in that order.
#[inline]
fn cubic([a_v, a_r, a_vvv, a_vvr, a_vrr, a_rrr]: [f64; 6], vp: f64, rp: f64) -> f64 {
    let v2 = vp * vp;
    let r2 = rp * rp;
    a_v * vp + a_r * rp + a_vvv * v2 * vp + a_vvr * v2 * rp + a_vrr * vp * r2 + a_rrr * r2 * rp
}

/// The azimuth pods (all pods together; they steer as one).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pods {
    /// Number of pods.
    pub count: u32,
    /// Position from midships (m, negative aft).
    pub x_m: f64,
    /// Propeller diameter (m).
    pub diameter_m: f64,
    /// Constant propeller revolutions (rev/s).
    pub rps: f64,
    /// Open-water thrust coefficient `K_T(J) = kt[0] + kt[1]·J + kt[2]·J²`.
    pub kt: [f64; 3],
    /// Wake fraction at the propellers.
    pub wake: f64,
    /// Thrust deduction factor.
    pub thrust_deduction: f64,
    /// Lateral area of housings and struts, all pods (m²).
    pub lateral_area_m2: f64,
    /// Lift-curve slope of the housings (1/rad).
    pub lift_slope: f64,
    /// Flow-straightening factor γ of the inflow.
    pub flow_straightening: f64,
    /// Effective longitudinal position ℓ' of the inflow (fraction of Lpp, negative aft).
    pub inflow_lever: f64,
    /// Slipstream factor ε (MMG rudder-inflow form).
    pub slipstream_epsilon: f64,
    /// Slipstream factor κ.
    pub slipstream_kappa: f64,
    /// Propeller diameter over housing height η.
    pub slipstream_eta: f64,
    /// Hull–pod interaction factor a_H.
    pub a_h: f64,
    /// Point of action of the hull's interaction force (m from midships).
    pub x_h_m: f64,
}

/// The steering actuator of the reference ship.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Actuator {
    /// First-order servo time constant (s).
    pub servo_tau_s: f64,
    /// Angle limit (deg).
    pub max_angle_deg: f64,
    /// Largest rudder/pod rate (deg/s); the ship file's key is `slew_degps`.
    #[serde(rename = "slew_degps")]
    pub max_rate_degps: f64,
    /// Command dead time (s).
    pub dead_time_s: f64,
}

/// Above-water areas and wind-force coefficient shapes.
///
/// With γ the apparent wind angle from the bow (positive from starboard) and
/// `q = ½ρ_a V_r²`: `X = q A_F (−c_x cos γ)`, `Y = q A_L (−c_y sin γ)`,
/// `N = q A_L L_oa (c_n1 sin γ − c_n2 sin 2γ)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Windage {
    /// Lateral projected area (m²).
    pub lateral_area_m2: f64,
    /// Frontal projected area (m²).
    pub frontal_area_m2: f64,
    /// Longitudinal force coefficient amplitude.
    pub c_x: f64,
    /// Lateral force coefficient amplitude.
    pub c_y: f64,
    /// First-harmonic yaw moment coefficient (centre of lateral area aft of midships > 0).
    pub c_n1: f64,
    /// Second-harmonic yaw moment coefficient.
    pub c_n2: f64,
}

impl Ship {
    /// The built-in ship: the paper's 1:24 LNG carrier (`host/ships/lng_1to24.toml`).
    ///
    /// ```
    /// let s = yawcast::sim::Ship::default_lng();
    /// assert_eq!(s.main.loa_m, 11.33);
    /// assert_eq!(s.pods.count, 2);
    /// ```
    pub fn default_lng() -> Ship {
        match Ship::from_toml_str(DEFAULT_SHIP_TOML) {
            Ok(s) => s,
            // The embedded file is checked by the unit tests; this arm is unreachable.
            Err(e) => unreachable!("built-in ship file: {e}"),
        }
    }

    /// Parses and validates a ship file's text.
    ///
    /// # Errors
    /// [`SimError::Parse`] for TOML syntax errors, unknown keys or wrong types (the message
    /// names the key and line); [`SimError::Invalid`] naming the field for out-of-range
    /// values.
    ///
    /// ```
    /// use yawcast::sim::{Ship, DEFAULT_SHIP_TOML};
    /// let bad = DEFAULT_SHIP_TOML.replace("draft_m = 0.47", "draft_m = -0.47");
    /// let e = Ship::from_toml_str(&bad).unwrap_err();
    /// assert!(e.to_string().contains("main.draft_m"));
    /// ```
    pub fn from_toml_str(text: &str) -> Result<Ship, SimError> {
        let ship: Ship = toml::from_str(text).map_err(|e| SimError::Parse(e.to_string()))?;
        ship.validate()?;
        Ok(ship)
    }

    /// Reads and validates a ship file.
    ///
    /// # Errors
    /// [`SimError::Io`] when the file cannot be read, otherwise as [`Ship::from_toml_str`]
    /// (parse errors are prefixed with the path).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Ship, SimError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| SimError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ship::from_toml_str(&text).map_err(|e| match e {
            SimError::Parse(m) => SimError::Parse(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    /// The ship as TOML text (what [`Ship::from_toml_str`] reads back).
    ///
    /// # Errors
    /// [`SimError::Parse`] if serialisation fails (it does not for a validated ship).
    ///
    /// ```
    /// use yawcast::sim::Ship;
    /// let s = Ship::default_lng();
    /// let back = Ship::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
    /// assert_eq!(back, s);
    /// ```
    pub fn to_toml_string(&self) -> Result<String, SimError> {
        toml::to_string_pretty(self).map_err(|e| SimError::Parse(e.to_string()))
    }

    /// The effects this ship carries.
    ///
    /// ```
    /// assert!(yawcast::sim::Ship::default_lng().effects().is_empty());
    /// ```
    pub fn effects(&self) -> &[SimEffect] {
        &self.effects
    }

    /// The ship with `effect` added, replacing any effect of the same kind.
    ///
    /// ```
    /// use yawcast::sim::{Ship, SimEffect};
    /// let s = Ship::default_lng()
    ///     .with_effect(SimEffect::DeadTime { delay_s: 1.0 })
    ///     .with_effect(SimEffect::DeadTime { delay_s: 2.0 });
    /// assert_eq!(s.effects(), &[SimEffect::DeadTime { delay_s: 2.0 }]);
    /// ```
    pub fn with_effect(mut self, effect: SimEffect) -> Ship {
        match self.effects.iter_mut().find(|e| e.kind() == effect.kind()) {
            Some(e) => *e = effect,
            None => self.effects.push(effect),
        }
        self
    }

    /// The ship without any effect of the given kind.
    ///
    /// ```
    /// use yawcast::sim::{Ship, SimEffect};
    /// use yawcast_shared::model::EffectKind;
    /// let s = Ship::default_lng().with_effect(SimEffect::hidden(EffectKind::Wind, 1.0));
    /// assert!(s.without_effect(EffectKind::Wind).effects().is_empty());
    /// ```
    pub fn without_effect(mut self, kind: yawcast_shared::model::EffectKind) -> Ship {
        self.effects.retain(|e| e.kind() != kind);
        self
    }

    /// Checks every value; the error names the first bad field (`pods.rps`).
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the field, its value and the range it must lie in.
    pub fn validate(&self) -> Result<(), SimError> {
        let m = &self.main;
        pos("main.loa_m", m.loa_m)?;
        pos("main.lpp_m", m.lpp_m)?;
        pos("main.beam_m", m.beam_m)?;
        pos("main.draft_m", m.draft_m)?;
        pos("main.mass_kg", m.mass_kg)?;
        within("main.x_g_m", m.x_g_m, -0.5 * m.lpp_m, 0.5 * m.lpp_m)?;
        within("main.k_zz", m.k_zz, 1e-3, 1.0)?;
        pos("main.rho_water", m.rho_water)?;
        non_neg("main.rho_air", m.rho_air)?;
        let h = &self.hull;
        non_neg("hull.m_x", h.m_x)?;
        non_neg("hull.m_y", h.m_y)?;
        non_neg("hull.j_z", h.j_z)?;
        non_neg("hull.r0", h.r0)?;
        for (name, v) in [
            ("hull.x_vv", h.x_vv),
            ("hull.x_vr", h.x_vr),
            ("hull.x_rr", h.x_rr),
            ("hull.x_vvvv", h.x_vvvv),
            ("hull.y_v", h.y_v),
            ("hull.y_r", h.y_r),
            ("hull.y_vvv", h.y_vvv),
            ("hull.y_vvr", h.y_vvr),
            ("hull.y_vrr", h.y_vrr),
            ("hull.y_rrr", h.y_rrr),
            ("hull.n_v", h.n_v),
            ("hull.n_r", h.n_r),
            ("hull.n_vvv", h.n_vvv),
            ("hull.n_vvr", h.n_vvr),
            ("hull.n_vrr", h.n_vrr),
            ("hull.n_rrr", h.n_rrr),
        ] {
            finite(name, v)?;
        }
        let p = &self.pods;
        if p.count == 0 {
            return Err(SimError::invalid("pods.count", 0.0, ">= 1"));
        }
        within("pods.x_m", p.x_m, -m.lpp_m, -1e-3)?;
        pos("pods.diameter_m", p.diameter_m)?;
        pos("pods.rps", p.rps)?;
        pos("pods.kt[0]", p.kt[0])?;
        finite("pods.kt[1]", p.kt[1])?;
        finite("pods.kt[2]", p.kt[2])?;
        within("pods.wake", p.wake, 0.0, 0.95)?;
        within("pods.thrust_deduction", p.thrust_deduction, 0.0, 0.95)?;
        non_neg("pods.lateral_area_m2", p.lateral_area_m2)?;
        non_neg("pods.lift_slope", p.lift_slope)?;
        within("pods.flow_straightening", p.flow_straightening, 0.0, 2.0)?;
        within("pods.inflow_lever", p.inflow_lever, -2.0, 2.0)?;
        within("pods.slipstream_epsilon", p.slipstream_epsilon, 0.1, 3.0)?;
        within("pods.slipstream_kappa", p.slipstream_kappa, 0.0, 2.0)?;
        within("pods.slipstream_eta", p.slipstream_eta, 0.0, 1.0)?;
        within("pods.a_h", p.a_h, 0.0, 2.0)?;
        within("pods.x_h_m", p.x_h_m, -m.lpp_m, m.lpp_m)?;
        let a = &self.actuator;
        within("actuator.servo_tau_s", a.servo_tau_s, 0.0, 10.0)?;
        within("actuator.max_angle_deg", a.max_angle_deg, 1e-3, 180.0)?;
        pos("actuator.slew_degps", a.max_rate_degps)?;
        within("actuator.dead_time_s", a.dead_time_s, 0.0, 60.0)?;
        let w = &self.windage;
        non_neg("windage.lateral_area_m2", w.lateral_area_m2)?;
        non_neg("windage.frontal_area_m2", w.frontal_area_m2)?;
        finite("windage.c_x", w.c_x)?;
        finite("windage.c_y", w.c_y)?;
        finite("windage.c_n1", w.c_n1)?;
        finite("windage.c_n2", w.c_n2)?;
        for (i, e) in self.effects.iter().enumerate() {
            e.validate(&format!("effects[{i}]"))?;
        }
        Ok(())
    }
}

pub(crate) fn finite(field: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SimError::invalid(field, v, "a finite number"))
    }
}

pub(crate) fn pos(field: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SimError::invalid(field, v, "> 0"))
    }
}

pub(crate) fn non_neg(field: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SimError::invalid(field, v, ">= 0"))
    }
}

pub(crate) fn within(field: &str, v: f64, lo: f64, hi: f64) -> Result<(), SimError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(SimError::invalid(field, v, &format!("in {lo}..={hi}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use yawcast_shared::model::EffectKind;

    #[test]
    fn built_in_file_parses_and_round_trips() {
        let s = Ship::from_toml_str(DEFAULT_SHIP_TOML).unwrap();
        assert_eq!(s.main.lpp_m, 10.85);
        let s2 = s
            .clone()
            .with_effect(SimEffect::hidden(EffectKind::Wind, 1.0))
            .with_effect(SimEffect::hidden(EffectKind::Bias, 1.0));
        let txt = s2.to_toml_string().unwrap();
        assert!(txt.contains("[[effects]]"), "{txt}");
        assert_eq!(Ship::from_toml_str(&txt).unwrap(), s2);
    }

    #[test]
    fn bad_values_name_the_field() {
        let cases = [
            ("rps = 10.5", "rps = 0.0", "pods.rps"),
            ("rps = 10.5", "rps = nan", "pods.rps"),
            ("mass_kg = 6999.0", "mass_kg = -1.0", "main.mass_kg"),
            ("k_zz = 0.25", "k_zz = 3.0", "main.k_zz"),
            ("wake = 0.25", "wake = 1.5", "pods.wake"),
            (
                "max_angle_deg = 35.0",
                "max_angle_deg = 0.0",
                "actuator.max_angle_deg",
            ),
            ("n_r = -0.0393", "n_r = inf", "hull.n_r"),
            ("count = 2", "count = 0", "pods.count"),
            // wrong type, unknown key: the TOML layer names the key
            ("beam_m = 1.83", "beam_m = \"wide\"", "beam_m"),
            ("beam_m = 1.83", "beam_m = 1.83\nbeem_m = 1.0", "beem_m"),
            ("x_m = -5.2", "x_m = 5.2", "pods.x_m"),
        ];
        for (from, to, field) in cases {
            assert!(DEFAULT_SHIP_TOML.contains(from), "{from}");
            let txt = DEFAULT_SHIP_TOML.replace(from, to);
            let e = Ship::from_toml_str(&txt).unwrap_err().to_string();
            assert!(e.contains(field), "{to}: {e}");
        }
        let txt =
            format!("{DEFAULT_SHIP_TOML}\n[[effects]]\nkind = \"rate-limit\"\nrate_degps = -2.0\n");
        let e = Ship::from_toml_str(&txt).unwrap_err().to_string();
        assert!(e.contains("effects[0] (rate-limit).rate_degps"), "{e}");
        let txt = format!("{DEFAULT_SHIP_TOML}\n[[effects]]\nkind = \"waves\"\n");
        let e = Ship::from_toml_str(&txt).unwrap_err().to_string();
        assert!(e.contains("waves"), "{e}");
    }

    #[test]
    fn from_file_reports_path() {
        let e = Ship::from_file("/nonexistent/ship.toml").unwrap_err();
        assert!(e.to_string().contains("/nonexistent/ship.toml"), "{e}");
    }
}
