//! The simulator's effect library: physical parameters of each effect, their validation and
//! the canonical strengths of a *hidden* effect.

use serde::{Deserialize, Serialize};
use yawcast_shared::model::EffectKind;

use super::SimError;

/// One physical effect the simulator can switch on, with its physical parameters.
///
/// Serialised (TOML `[[effects]]` tables, JSON) with a `kind` key carrying the stable name
/// of [`EffectKind::name`]:
///
/// ```toml
/// [[effects]]
/// kind = "wind"
/// speed_mps = 2.0
/// from_deg = 45.0
/// ```
///
/// Heading, wind and current directions are in degrees from north, clockwise.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SimEffect {
    /// Constant yaw moment (pod misalignment, propeller asymmetry), positive to starboard.
    Bias {
        /// Yaw moment (N·m).
        yaw_moment_nm: f64,
    },
    /// Rate-gyro offset added to the measured yaw rate.
    GyroBias {
        /// Offset (deg/s).
        bias_degps: f64,
    },
    /// Extra command delay between the autopilot and the pods.
    DeadTime {
        /// Delay (s), `0..=60`.
        delay_s: f64,
    },
    /// Pod slew limit (replaces the ship's own slew rate when lower).
    RateLimit {
        /// Slew rate (deg/s), `> 0`.
        rate_degps: f64,
    },
    /// Pod angle limit below the ship's own limit.
    Saturation {
        /// Angle limit (deg), `> 0`.
        limit_deg: f64,
    },
    /// Port/starboard difference in pod effectiveness: the steering part of the pods' side
    /// force is multiplied by `1 + starboard_gain` when δ > 0.
    Asymmetry {
        /// Relative extra effectiveness to starboard, `> -1`.
        starboard_gain: f64,
    },
    /// Norrbin-type yaw damping beyond the hull's own:
    /// `N = -n_rr · ½ρ L⁴ d · r|r|` (or `-n_rr · ½ρ L²d U² · r'³` when `cubic`).
    NonlinearDamping {
        /// Non-dimensional coefficient, `>= 0`.
        n_rr: f64,
        /// Cubic `r'³` form instead of `r'|r'|`.
        #[serde(default)]
        cubic: bool,
    },
    /// Steady true wind.
    Wind {
        /// True wind speed (m/s), `>= 0`.
        speed_mps: f64,
        /// Direction the wind blows *from* (deg).
        from_deg: f64,
    },
    /// Steady uniform current.
    Current {
        /// Current speed (m/s), `>= 0`.
        speed_mps: f64,
        /// Direction the current sets *towards* (deg).
        towards_deg: f64,
    },
    /// Steering-gear dead band (backlash of a worn gear): the pods do not move until the
    /// command differs from their angle by more than the width, then follow it that far
    /// behind.
    DeadBand {
        /// Width (deg), `> 0`.
        width_deg: f64,
    },
}

/// Yaw moment of the default ship's pods at about 4.5° at its approach speed (N·m): the
/// hidden `bias` at full strength.
pub const HIDDEN_BIAS_NM: f64 = 60.0;
/// Hidden `gyro-bias` at full strength (deg/s).
pub const HIDDEN_GYRO_BIAS_DEGPS: f64 = 0.25;
/// Hidden `dead-time` at full strength (s).
pub const HIDDEN_DEAD_TIME_S: f64 = 2.0;
/// Hidden `rate-limit` at full strength (deg/s); strength `s` gives `rate / s`.
pub const HIDDEN_RATE_DEGPS: f64 = 3.0;
/// Hidden `saturation` at full strength (deg); strength `s` gives
/// `20° − s·(20° − limit)` (20° is the largest identification amplitude), at least 2°.
pub const HIDDEN_LIMIT_DEG: f64 = 8.0;
/// Hidden `asymmetry` at full strength (relative extra effectiveness to starboard).
pub const HIDDEN_ASYMMETRY: f64 = 0.4;
/// Hidden `nonlinear-damping` at full strength (non-dimensional `n_rr`).
pub const HIDDEN_N_RR: f64 = 0.15;
/// Hidden `wind` at full strength (m/s at model scale; 14.7 m/s, Beaufort 7, Froude-scaled by √24).
pub const HIDDEN_WIND_MPS: f64 = 3.0;
/// Hidden `current` at full strength (m/s at model scale).
pub const HIDDEN_CURRENT_MPS: f64 = 0.3;
/// Hidden `dead-band` at full strength (deg): the backlash of a worn steering gear.
pub const HIDDEN_DEAD_BAND_DEG: f64 = 2.0;

impl SimEffect {
    /// The library kind of this effect.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// use yawcast_shared::model::EffectKind;
    /// let e = SimEffect::GyroBias { bias_degps: 0.2 };
    /// assert_eq!(e.kind(), EffectKind::GyroBias);
    /// ```
    pub fn kind(&self) -> EffectKind {
        match self {
            SimEffect::Bias { .. } => EffectKind::Bias,
            SimEffect::GyroBias { .. } => EffectKind::GyroBias,
            SimEffect::DeadTime { .. } => EffectKind::DeadTime,
            SimEffect::RateLimit { .. } => EffectKind::RateLimit,
            SimEffect::Saturation { .. } => EffectKind::Saturation,
            SimEffect::Asymmetry { .. } => EffectKind::Asymmetry,
            SimEffect::NonlinearDamping { .. } => EffectKind::NonlinearDamping,
            SimEffect::Wind { .. } => EffectKind::Wind,
            SimEffect::Current { .. } => EffectKind::Current,
            SimEffect::DeadBand { .. } => EffectKind::DeadBand,
        }
    }

    /// The canonical hidden effect of `kind` at `strength` (1.0 full, 0.5 half).
    ///
    /// At full strength each effect visibly degrades a linear model's long-horizon yaw-rate
    /// prediction on trial-like records of the default ship while staying physically
    /// plausible: bias 60 N·m (≈ the pods' moment at 4.5°), gyro bias 0.25 °/s, dead time
    /// 2 s, slew limit 3 °/s, angle limit 8°, asymmetry +40 % to starboard, extra Norrbin
    /// damping `n_rr` = 0.15, wind 3 m/s from 045° (Beaufort 7 Froude-scaled), current
    /// 0.3 m/s setting towards 090°, a steering-gear dead band of 2°. Additive effects and
    /// the dead band scale linearly with `strength`; the
    /// slew limit is divided by it; the angle limit moves from 20° (the largest
    /// identification amplitude) towards 8°. A `strength` at or below zero is taken as
    /// 1e-6 (practically no effect); a non-finite one gives parameters that
    /// [`simulate`](super::simulate) rejects.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// use yawcast_shared::model::EffectKind;
    /// assert_eq!(
    ///     SimEffect::hidden(EffectKind::DeadTime, 0.5),
    ///     SimEffect::DeadTime { delay_s: 1.0 }
    /// );
    /// assert_eq!(
    ///     SimEffect::hidden(EffectKind::RateLimit, 1.0),
    ///     SimEffect::RateLimit { rate_degps: 3.0 }
    /// );
    /// ```
    pub fn hidden(kind: EffectKind, strength: f64) -> SimEffect {
        let s = if strength > 0.0 || strength.is_nan() {
            strength
        } else {
            1e-6
        };
        match kind {
            EffectKind::Bias => SimEffect::Bias {
                yaw_moment_nm: HIDDEN_BIAS_NM * s,
            },
            EffectKind::GyroBias => SimEffect::GyroBias {
                bias_degps: HIDDEN_GYRO_BIAS_DEGPS * s,
            },
            EffectKind::DeadTime => SimEffect::DeadTime {
                delay_s: HIDDEN_DEAD_TIME_S * s,
            },
            EffectKind::RateLimit => SimEffect::RateLimit {
                rate_degps: HIDDEN_RATE_DEGPS / s,
            },
            EffectKind::Saturation => SimEffect::Saturation {
                limit_deg: (20.0 - s * (20.0 - HIDDEN_LIMIT_DEG)).max(2.0),
            },
            EffectKind::Asymmetry => SimEffect::Asymmetry {
                starboard_gain: HIDDEN_ASYMMETRY * s,
            },
            EffectKind::NonlinearDamping => SimEffect::NonlinearDamping {
                n_rr: HIDDEN_N_RR * s,
                cubic: false,
            },
            EffectKind::Wind => SimEffect::Wind {
                speed_mps: HIDDEN_WIND_MPS * s,
                from_deg: 45.0,
            },
            EffectKind::Current => SimEffect::Current {
                speed_mps: HIDDEN_CURRENT_MPS * s,
                towards_deg: 90.0,
            },
            EffectKind::DeadBand => SimEffect::DeadBand {
                width_deg: HIDDEN_DEAD_BAND_DEG * s,
            },
        }
    }

    /// The effect's physical parameters in words, as the demo and `augment --save-ship` print
    /// them.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// assert_eq!(SimEffect::RateLimit { rate_degps: 3.0 }.describe(), "a pod slew limit of 3.00 °/s");
    /// assert_eq!(SimEffect::DeadBand { width_deg: 2.0 }.describe(), "a steering-gear dead band of 2.00°");
    /// ```
    pub fn describe(&self) -> String {
        match *self {
            SimEffect::Bias { yaw_moment_nm } => {
                format!("a constant yaw moment of {yaw_moment_nm:.1} N·m")
            }
            SimEffect::GyroBias { bias_degps } => {
                format!("a rate-gyro offset of {bias_degps:.3} °/s")
            }
            SimEffect::DeadTime { delay_s } => format!("a command dead time of {delay_s:.1} s"),
            SimEffect::RateLimit { rate_degps } => {
                format!("a pod slew limit of {rate_degps:.2} °/s")
            }
            SimEffect::Saturation { limit_deg } => {
                format!("a pod angle limit of ±{limit_deg:.1}°")
            }
            SimEffect::Asymmetry { starboard_gain } => format!(
                "pods {:+.0} % more effective to starboard",
                100.0 * starboard_gain
            ),
            SimEffect::NonlinearDamping { n_rr, cubic } => format!(
                "extra Norrbin yaw damping n_rr = {n_rr:.3}{}",
                if cubic { " (cubic)" } else { "" }
            ),
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => format!("a steady wind of {speed_mps:.2} m/s from {from_deg:03.0}°"),
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => format!("a current of {speed_mps:.3} m/s setting towards {towards_deg:03.0}°"),
            SimEffect::DeadBand { width_deg } => {
                format!("a steering-gear dead band of {width_deg:.2}°")
            }
        }
    }

    /// Checks the parameters; `at` names the effect in errors (e.g. `effects[2]`).
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the field (`effects[2] (wind).speed_mps`) when a value
    /// is not finite or out of its range.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// let e = SimEffect::DeadTime { delay_s: -1.0 }.validate("effects[0]").unwrap_err();
    /// assert!(e.to_string().contains("effects[0] (dead-time).delay_s"));
    /// ```
    pub fn validate(&self, at: &str) -> Result<(), SimError> {
        let name = self.kind().name();
        let field = |f: &str| format!("{at} ({name}).{f}");
        let check = |f: &str, v: f64, ok: bool, reason: &str| -> Result<(), SimError> {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(SimError::invalid(field(f), v, reason))
            }
        };
        match *self {
            SimEffect::Bias { yaw_moment_nm: v } => check("yaw_moment_nm", v, true, "finite"),
            SimEffect::GyroBias { bias_degps: v } => check("bias_degps", v, true, "finite"),
            SimEffect::DeadTime { delay_s: v } => {
                check("delay_s", v, (0.0..=60.0).contains(&v), "in 0..=60 s")
            }
            SimEffect::RateLimit { rate_degps: v } => check("rate_degps", v, v > 0.0, "> 0"),
            SimEffect::Saturation { limit_deg: v } => check("limit_deg", v, v > 0.0, "> 0"),
            SimEffect::Asymmetry { starboard_gain: v } => {
                check("starboard_gain", v, v > -1.0, "> -1")
            }
            SimEffect::NonlinearDamping { n_rr: v, .. } => check("n_rr", v, v >= 0.0, ">= 0"),
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => {
                check("speed_mps", speed_mps, speed_mps >= 0.0, ">= 0")?;
                check("from_deg", from_deg, true, "finite")
            }
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => {
                check("speed_mps", speed_mps, speed_mps >= 0.0, ">= 0")?;
                check("towards_deg", towards_deg, true, "finite")
            }
            SimEffect::DeadBand { width_deg: v } => {
                check("width_deg", v, v > 0.0 && v <= 45.0, "in (0, 45] deg")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_covers_every_kind_and_validates() {
        for k in EffectKind::ALL {
            for s in [0.5, 1.0, 2.0] {
                let e = SimEffect::hidden(k, s);
                assert_eq!(e.kind(), k);
                e.validate("effects[0]").unwrap();
            }
            SimEffect::hidden(k, 0.0).validate("x").unwrap();
            SimEffect::hidden(k, -3.0).validate("x").unwrap();
        }
        assert!(SimEffect::hidden(EffectKind::Wind, f64::NAN)
            .validate("x")
            .is_err());
        assert_eq!(
            SimEffect::hidden(EffectKind::Saturation, 0.5),
            SimEffect::Saturation { limit_deg: 14.0 }
        );
    }

    #[test]
    fn serde_uses_stable_names() {
        #[derive(Serialize, Deserialize)]
        struct F {
            effects: Vec<SimEffect>,
        }
        let f = F {
            effects: EffectKind::ALL
                .iter()
                .map(|&k| SimEffect::hidden(k, 1.0))
                .collect(),
        };
        let txt = toml::to_string(&f).unwrap();
        for k in EffectKind::ALL {
            assert!(txt.contains(&format!("kind = \"{}\"", k.name())), "{txt}");
        }
        let back: F = toml::from_str(&txt).unwrap();
        assert_eq!(back.effects, f.effects);
        let bad = "[[effects]]\nkind = \"wind\"\nspeed_mps = 1.0\nfrom_deg = 0.0\nspeed = 3\n";
        let e = toml::from_str::<F>(bad).err().unwrap().to_string();
        assert!(e.contains("speed"), "{e}");
        let cubic = "[[effects]]\nkind = \"nonlinear-damping\"\nn_rr = 0.1\n";
        let f: F = toml::from_str(cubic).unwrap();
        assert_eq!(
            f.effects[0],
            SimEffect::NonlinearDamping {
                n_rr: 0.1,
                cubic: false
            }
        );
    }
}
