//! The effect library on the host: one file per physical effect, and this registry.
//!
//! Each effect's file holds everything the host knows of it: its simulator physics (the
//! canonical hidden strength, validation, how it sets the simulator's knobs, how it carries
//! over to another hull), its place in the model (actuator, regressor or output offset, the
//! names of its gains), its parameter grids (diagnose's candidates and augment's search) and
//! its words (the short phrase, the parameter in words, the evidence sentence). This file
//! holds the two parameter enums — [`Effect`] (the model's f64 parameters, JSON tag
//! `effect`) and [`SimEffect`] (the simulator's physical parameters, TOML/JSON tag `kind`) —
//! the registry [`def`] and the dispatch from each enum variant to its file.
//!
//! The f32 semantics (what the firmware runs) are the shared crate's
//! `yawcast_shared::kernel`, used by the host's f64 predictor too.
//!
//! # Adding an effect
//! 1. a variant of `yawcast_shared::model::Effect`/`EffectKind` (last, so older blobs keep
//!    their indices) and its arm in `yawcast_shared::kernel` (the f32/f64 step);
//! 2. one file here with its [`Def`] and its functions, and one line in [`def`];
//! 3. the compiler then lists every arm of this file's enums that must learn it (no match
//!    over an effect enum has a catch-all arm).

use serde::{Deserialize, Serialize};
use yawcast_shared::model::{self as sm, EffectKind};

use crate::sim::SimError;

mod asymmetry;
mod bias;
mod current;
mod dead_band;
mod dead_time;
mod def;
mod gyro_bias;
mod nonlinear_damping;
mod rate_limit;
mod saturation;
mod wind;

pub use asymmetry::HIDDEN_ASYMMETRY;
pub use bias::HIDDEN_BIAS_NM;
pub use current::HIDDEN_CURRENT_MPS;
pub use dead_band::HIDDEN_DEAD_BAND_DEG;
pub use dead_time::HIDDEN_DEAD_TIME_S;
pub(crate) use def::geometric;
use def::{no_search, Field, Fields};
pub use def::{Channel, Def, GridSpan, HullScale, Regressor, Role, SimKnobs};
pub use gyro_bias::HIDDEN_GYRO_BIAS_DEGPS;
pub use nonlinear_damping::HIDDEN_N_RR;
pub use rate_limit::HIDDEN_RATE_DEGPS;
pub use saturation::HIDDEN_LIMIT_DEG;
pub use wind::HIDDEN_WIND_MPS;

/// The registry: the definition of each kind of the library.
///
/// ```
/// use yawcast::effects::{def, Role};
/// use yawcast_shared::model::EffectKind;
/// assert_eq!(def(EffectKind::DeadBand).phrase, "a steering-gear dead band");
/// assert_eq!(def(EffectKind::GyroBias).role, Role::Output);
/// for k in EffectKind::ALL {
///     assert_eq!(def(k).kind, k);
/// }
/// ```
pub fn def(kind: EffectKind) -> &'static Def {
    match kind {
        EffectKind::Bias => &bias::DEF,
        EffectKind::GyroBias => &gyro_bias::DEF,
        EffectKind::DeadTime => &dead_time::DEF,
        EffectKind::RateLimit => &rate_limit::DEF,
        EffectKind::Saturation => &saturation::DEF,
        EffectKind::Asymmetry => &asymmetry::DEF,
        EffectKind::NonlinearDamping => &nonlinear_damping::DEF,
        EffectKind::Wind => &wind::DEF,
        EffectKind::Current => &current::DEF,
        EffectKind::DeadBand => &dead_band::DEF,
    }
}

/// One library effect with f64 parameters (see `yawcast_shared::model::Effect` for physics).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "effect", rename_all = "kebab-case")]
pub enum Effect {
    /// Constant yaw moment: `φ = 1` through B.
    Bias {
        /// Gain β (deg of equivalent input).
        beta: f64,
    },
    /// Rate-sensor offset `d_y` (deg/s).
    GyroBias {
        /// Output offset.
        d_y: f64,
    },
    /// Command delay of `samples` whole samples.
    DeadTime {
        /// Delay (samples).
        samples: usize,
    },
    /// Largest rudder/pod rate ρ (deg/s).
    RateLimit {
        /// ρ (deg/s).
        rate: f64,
    },
    /// Angle limit δ_max (deg).
    Saturation {
        /// δ_max (deg).
        limit: f64,
    },
    /// Port/starboard gain difference: `φ = max(ũ, 0)` through B.
    Asymmetry {
        /// Gain β.
        beta: f64,
    },
    /// Nonlinear hull damping: `φ = y|y|` (or `y³`) through B.
    NonlinearDamping {
        /// Gain β.
        beta: f64,
        /// Cubic rather than `y|y|`.
        cubic: bool,
    },
    /// Wind: `φ = (sin 2ψ, cos 2ψ, sin ψ, cos ψ)` through B.
    Wind {
        /// Gain of sin 2ψ.
        beta_s2: f64,
        /// Gain of cos 2ψ.
        beta_c2: f64,
        /// Gain of sin ψ.
        beta_s1: f64,
        /// Gain of cos ψ.
        beta_c1: f64,
    },
    /// Current: `φ = (sin ψ, cos ψ)` through B.
    Current {
        /// Gain of sin ψ.
        beta_s: f64,
        /// Gain of cos ψ.
        beta_c: f64,
    },
    /// Steering-gear dead band b (deg): `ũ = clamp(ũ_prev, τ − b, τ + b)`.
    DeadBand {
        /// b (deg).
        width: f64,
    },
}

impl Effect {
    /// The effect's kind.
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// assert_eq!(Effect::Bias { beta: 1.0 }.kind().name(), "bias");
    /// ```
    pub fn kind(&self) -> EffectKind {
        match self {
            Effect::Bias { .. } => EffectKind::Bias,
            Effect::GyroBias { .. } => EffectKind::GyroBias,
            Effect::DeadTime { .. } => EffectKind::DeadTime,
            Effect::RateLimit { .. } => EffectKind::RateLimit,
            Effect::Saturation { .. } => EffectKind::Saturation,
            Effect::Asymmetry { .. } => EffectKind::Asymmetry,
            Effect::NonlinearDamping { .. } => EffectKind::NonlinearDamping,
            Effect::Wind { .. } => EffectKind::Wind,
            Effect::Current { .. } => EffectKind::Current,
            Effect::DeadBand { .. } => EffectKind::DeadBand,
        }
    }

    /// The definition of the effect's kind ([`def`]).
    pub fn def(&self) -> &'static Def {
        def(self.kind())
    }

    /// The effect of `kind` with zero gains (linear parameters to be estimated) and the
    /// given structural parameter where one is needed (dead time samples, rate, limit).
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// use yawcast_shared::model::EffectKind;
    /// assert_eq!(Effect::zero(EffectKind::Current, 0.0), Effect::Current { beta_s: 0.0, beta_c: 0.0 });
    /// assert_eq!(Effect::zero(EffectKind::DeadTime, 2.0), Effect::DeadTime { samples: 2 });
    /// ```
    pub fn zero(kind: EffectKind, structural: f64) -> Effect {
        let mut e = match kind {
            EffectKind::Bias => Effect::Bias { beta: 0.0 },
            EffectKind::GyroBias => Effect::GyroBias { d_y: 0.0 },
            EffectKind::DeadTime => Effect::DeadTime { samples: 0 },
            EffectKind::RateLimit => Effect::RateLimit { rate: 0.0 },
            EffectKind::Saturation => Effect::Saturation { limit: 0.0 },
            EffectKind::DeadBand => Effect::DeadBand { width: 0.0 },
            EffectKind::Asymmetry => Effect::Asymmetry { beta: 0.0 },
            EffectKind::NonlinearDamping => Effect::NonlinearDamping {
                beta: 0.0,
                cubic: false,
            },
            EffectKind::Wind => Effect::Wind {
                beta_s2: 0.0,
                beta_c2: 0.0,
                beta_s1: 0.0,
                beta_c1: 0.0,
            },
            EffectKind::Current => Effect::Current {
                beta_s: 0.0,
                beta_c: 0.0,
            },
        };
        e.set_structural(structural);
        e
    }

    /// The structural (grid-searched) parameter of an actuator effect, in its CLI units
    /// (samples, deg/s, deg); `None` for the others.
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// assert_eq!(Effect::DeadTime { samples: 3 }.structural(), Some(3.0));
    /// assert_eq!(Effect::Bias { beta: 1.0 }.structural(), None);
    /// ```
    pub fn structural(&self) -> Option<f64> {
        match *self {
            Effect::DeadTime { samples } => Some(samples as f64),
            Effect::RateLimit { rate } => Some(rate),
            Effect::Saturation { limit } => Some(limit),
            Effect::DeadBand { width } => Some(width),
            Effect::Bias { .. }
            | Effect::GyroBias { .. }
            | Effect::Asymmetry { .. }
            | Effect::NonlinearDamping { .. }
            | Effect::Wind { .. }
            | Effect::Current { .. } => None,
        }
    }

    /// Sets the structural parameter (ignored by effects without one; a dead time is
    /// rounded to whole samples, at least 0).
    pub fn set_structural(&mut self, v: f64) {
        match self {
            Effect::DeadTime { samples } => *samples = v.round().max(0.0) as usize,
            Effect::RateLimit { rate } => *rate = v,
            Effect::Saturation { limit } => *limit = v,
            Effect::DeadBand { width } => *width = v,
            Effect::Bias { .. }
            | Effect::GyroBias { .. }
            | Effect::Asymmetry { .. }
            | Effect::NonlinearDamping { .. }
            | Effect::Wind { .. }
            | Effect::Current { .. } => {}
        }
    }

    /// The linear gains this effect adds to the parameter vector (empty for actuator effects).
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// assert_eq!(Effect::Current { beta_s: 1.0, beta_c: 2.0 }.gains(), vec![1.0, 2.0]);
    /// ```
    pub fn gains(&self) -> Vec<f64> {
        match *self {
            Effect::Bias { beta } | Effect::Asymmetry { beta } => vec![beta],
            Effect::NonlinearDamping { beta, .. } => vec![beta],
            Effect::GyroBias { d_y } => vec![d_y],
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => vec![beta_s2, beta_c2, beta_s1, beta_c1],
            Effect::Current { beta_s, beta_c } => vec![beta_s, beta_c],
            Effect::DeadTime { .. }
            | Effect::RateLimit { .. }
            | Effect::Saturation { .. }
            | Effect::DeadBand { .. } => vec![],
        }
    }

    /// Sets the linear gains from `g` (length as returned by [`Effect::gains`]).
    pub fn set_gains(&mut self, g: &[f64]) {
        match self {
            Effect::Bias { beta } | Effect::Asymmetry { beta } => *beta = g[0],
            Effect::NonlinearDamping { beta, .. } => *beta = g[0],
            Effect::GyroBias { d_y } => *d_y = g[0],
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => {
                *beta_s2 = g[0];
                *beta_c2 = g[1];
                *beta_s1 = g[2];
                *beta_c1 = g[3];
            }
            Effect::Current { beta_s, beta_c } => {
                *beta_s = g[0];
                *beta_c = g[1];
            }
            Effect::DeadTime { .. }
            | Effect::RateLimit { .. }
            | Effect::Saturation { .. }
            | Effect::DeadBand { .. } => {}
        }
    }

    /// Whether the nonlinear damping is cubic (`false` for every other effect).
    pub fn cubic(&self) -> bool {
        matches!(self, Effect::NonlinearDamping { cubic: true, .. })
    }

    /// The form of a nonlinear damping (`Some(true)` for `y³`), `None` for every other
    /// effect: what [`crate::diagnose::augment::AugmentConfig::damping_form`] takes.
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// assert_eq!(Effect::NonlinearDamping { beta: -1.0, cubic: true }.damping_form(), Some(true));
    /// assert_eq!(Effect::Bias { beta: 1.0 }.damping_form(), None);
    /// ```
    pub fn damping_form(&self) -> Option<bool> {
        match self {
            Effect::NonlinearDamping { cubic, .. } => Some(*cubic),
            _ => None,
        }
    }

    /// The f32 schema's effect (parameters rounded to f32; a dead time capped at 255).
    pub fn to_spec(self) -> sm::Effect {
        self.to_kernel().map(|x| x as f32)
    }

    /// The schema's effect with f64 parameters, as the shared kernel's `f64` instance runs
    /// it (a dead time capped at 255 samples).
    pub fn to_kernel(self) -> sm::Effect<f64> {
        match self {
            Effect::Bias { beta } => sm::Effect::Bias { beta },
            Effect::GyroBias { d_y } => sm::Effect::GyroBias { d_y },
            Effect::DeadTime { samples } => sm::Effect::DeadTime {
                samples: samples.min(255) as u8,
            },
            Effect::RateLimit { rate } => sm::Effect::RateLimit { rate },
            Effect::DeadBand { width } => sm::Effect::DeadBand { width },
            Effect::Saturation { limit } => sm::Effect::Saturation { limit },
            Effect::Asymmetry { beta } => sm::Effect::Asymmetry { beta },
            Effect::NonlinearDamping { beta, cubic } => {
                sm::Effect::NonlinearDamping { beta, cubic }
            }
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => sm::Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            },
            Effect::Current { beta_s, beta_c } => sm::Effect::Current { beta_s, beta_c },
        }
    }

    /// The f64 effect of an f32 schema effect (exact).
    pub fn from_spec(e: &sm::Effect) -> Effect {
        match e.map(f64::from) {
            sm::Effect::Bias { beta } => Effect::Bias { beta },
            sm::Effect::GyroBias { d_y } => Effect::GyroBias { d_y },
            sm::Effect::DeadTime { samples } => Effect::DeadTime {
                samples: samples.into(),
            },
            sm::Effect::RateLimit { rate } => Effect::RateLimit { rate },
            sm::Effect::DeadBand { width } => Effect::DeadBand { width },
            sm::Effect::Saturation { limit } => Effect::Saturation { limit },
            sm::Effect::Asymmetry { beta } => Effect::Asymmetry { beta },
            sm::Effect::NonlinearDamping { beta, cubic } => {
                Effect::NonlinearDamping { beta, cubic }
            }
            sm::Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            },
            sm::Effect::Current { beta_s, beta_c } => Effect::Current { beta_s, beta_c },
        }
    }

    /// The effect in physical words (`ts`: the model's sample time, s).
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// assert_eq!(
    ///     Effect::DeadTime { samples: 4 }.describe(0.5),
    ///     "a command dead time of 4 samples (2.0 s)"
    /// );
    /// ```
    pub fn describe(&self, ts: f64) -> String {
        match *self {
            Effect::Bias { beta } => bias::describe(beta),
            Effect::GyroBias { d_y } => gyro_bias::describe(d_y),
            Effect::DeadTime { samples } => dead_time::describe(samples, ts),
            Effect::RateLimit { rate } => rate_limit::describe(rate),
            Effect::Saturation { limit } => saturation::describe(limit),
            Effect::DeadBand { width } => dead_band::describe(width),
            Effect::Asymmetry { beta } => asymmetry::describe(beta),
            Effect::NonlinearDamping { beta, cubic } => nonlinear_damping::describe(beta, cubic),
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => wind::describe([beta_s2, beta_c2, beta_s1, beta_c1]),
            Effect::Current { beta_s, beta_c } => current::describe(beta_s, beta_c),
        }
    }

    /// What the yaw channel's evidence of this version of the effect says: its parameter in
    /// physical units (when it has one) and the sentence, given the share `pct` of the error
    /// energy it removes, the horizon `slow_h` of the slow effects and the yaw channel's
    /// p-value (printed by the heading effects).
    pub fn evidence(&self, ts: f64, pct: f64, slow_h: usize, p_yaw: &str) -> (Option<f64>, String) {
        match *self {
            Effect::Bias { beta } => bias::evidence(beta, pct, slow_h),
            Effect::GyroBias { d_y } => gyro_bias::evidence(d_y, pct, slow_h),
            Effect::DeadTime { samples } => dead_time::evidence(samples, ts, pct),
            Effect::RateLimit { rate } => rate_limit::evidence(rate, pct),
            Effect::Saturation { limit } => saturation::evidence(limit, pct),
            Effect::DeadBand { width } => dead_band::evidence(width, pct),
            Effect::Asymmetry { beta } => asymmetry::evidence(beta, pct),
            Effect::NonlinearDamping { beta, cubic } => {
                nonlinear_damping::evidence(beta, cubic, pct)
            }
            Effect::Wind { .. } => wind::evidence(pct, slow_h, p_yaw),
            Effect::Current { .. } => current::evidence(pct, slow_h, p_yaw),
        }
    }

    /// The heading harmonics `(sin 2ψ, cos 2ψ, sin ψ, cos ψ)` of a heading effect's gains.
    ///
    /// ```
    /// use yawcast::identify::model::Effect;
    /// let c = Effect::Current { beta_s: 1.0, beta_c: 2.0 };
    /// assert_eq!(c.harmonics(), Some([0.0, 0.0, 1.0, 2.0]));
    /// assert_eq!(Effect::Bias { beta: 1.0 }.harmonics(), None);
    /// ```
    pub fn harmonics(&self) -> Option<[f64; 4]> {
        match *self {
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => Some([beta_s2, beta_c2, beta_s1, beta_c1]),
            Effect::Current { beta_s, beta_c } => Some([0.0, 0.0, beta_s, beta_c]),
            Effect::Bias { .. }
            | Effect::GyroBias { .. }
            | Effect::DeadTime { .. }
            | Effect::RateLimit { .. }
            | Effect::Saturation { .. }
            | Effect::DeadBand { .. }
            | Effect::Asymmetry { .. }
            | Effect::NonlinearDamping { .. } => None,
        }
    }

    /// How the effect maps onto the simulator's physics: directly (the actuator effects,
    /// the gyro offset, the asymmetry's relative gain), or through a calibration on a
    /// simulated hull (the moments: bias, damping, wind and current).
    ///
    /// ```
    /// use yawcast::{effects::SimCounterpart, identify::model::Effect, sim::SimEffect};
    /// assert_eq!(
    ///     Effect::DeadTime { samples: 2 }.sim_counterpart(0.5),
    ///     SimCounterpart::Direct(SimEffect::DeadTime { delay_s: 1.0 })
    /// );
    /// assert_eq!(Effect::Bias { beta: 1.5 }.sim_counterpart(1.0), SimCounterpart::Moment { beta: 1.5 });
    /// ```
    pub fn sim_counterpart(&self, ts: f64) -> SimCounterpart {
        match *self {
            Effect::DeadTime { samples } => SimCounterpart::Direct(dead_time::to_sim(samples, ts)),
            Effect::RateLimit { rate } => SimCounterpart::Direct(rate_limit::to_sim(rate)),
            Effect::Saturation { limit } => SimCounterpart::Direct(saturation::to_sim(limit)),
            Effect::DeadBand { width } => SimCounterpart::Direct(dead_band::to_sim(width)),
            Effect::GyroBias { d_y } => SimCounterpart::Direct(gyro_bias::to_sim(d_y)),
            Effect::Asymmetry { beta } => SimCounterpart::Direct(asymmetry::to_sim(beta)),
            Effect::Bias { beta } => SimCounterpart::Moment { beta },
            Effect::NonlinearDamping { beta, cubic } => SimCounterpart::Damping { beta, cubic },
            Effect::Wind { .. } | Effect::Current { .. } => SimCounterpart::Heading,
        }
    }
}

/// How a model effect maps onto the simulator ([`Effect::sim_counterpart`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimCounterpart {
    /// The same physics, parameters converted.
    Direct(SimEffect),
    /// A constant moment worth `beta` degrees of rudder/pod angle.
    Moment {
        /// β (deg).
        beta: f64,
    },
    /// Damping beyond linear with gain `beta` (deg of rudder per (°/s)² or (°/s)³).
    Damping {
        /// β.
        beta: f64,
        /// Cubic rather than `r|r|`.
        cubic: bool,
    },
    /// A heading-dependent moment ([`Effect::harmonics`]).
    Heading,
}

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
    /// Largest pod rate (replaces the ship's own when lower).
    RateLimit {
        /// Rate (deg/s), `> 0`.
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
    /// plausible; each effect's file gives its value and how it scales. A `strength` at or
    /// below zero is taken as 1e-6 (practically no effect); a non-finite one gives
    /// parameters that [`simulate`](crate::sim::simulate) rejects.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// use yawcast_shared::model::EffectKind;
    /// assert_eq!(
    ///     SimEffect::hidden(EffectKind::DeadTime, 0.5),
    ///     SimEffect::DeadTime { delay_s: 1.0 }
    /// );
    /// assert_eq!(
    ///     SimEffect::hidden(EffectKind::Saturation, 0.5),
    ///     SimEffect::Saturation { limit_deg: 14.0 }
    /// );
    /// ```
    pub fn hidden(kind: EffectKind, strength: f64) -> SimEffect {
        let s = if strength > 0.0 || strength.is_nan() {
            strength
        } else {
            1e-6
        };
        (def(kind).hidden)(s)
    }

    /// The effect's physical parameters in words, as the demo and `augment --save-ship` print
    /// them.
    ///
    /// ```
    /// use yawcast::sim::SimEffect;
    /// assert_eq!(SimEffect::DeadBand { width_deg: 2.0 }.describe(), "a steering-gear dead band of 2.00°");
    /// ```
    pub fn describe(&self) -> String {
        match *self {
            SimEffect::Bias { yaw_moment_nm } => bias::describe_sim(yaw_moment_nm),
            SimEffect::GyroBias { bias_degps } => gyro_bias::describe_sim(bias_degps),
            SimEffect::DeadTime { delay_s } => dead_time::describe_sim(delay_s),
            SimEffect::RateLimit { rate_degps } => rate_limit::describe_sim(rate_degps),
            SimEffect::Saturation { limit_deg } => saturation::describe_sim(limit_deg),
            SimEffect::Asymmetry { starboard_gain } => asymmetry::describe_sim(starboard_gain),
            SimEffect::NonlinearDamping { n_rr, cubic } => {
                nonlinear_damping::describe_sim(n_rr, cubic)
            }
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => wind::describe_sim(speed_mps, from_deg),
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => current::describe_sim(speed_mps, towards_deg),
            SimEffect::DeadBand { width_deg } => dead_band::describe_sim(width_deg),
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
        let check = |f: &str, v: f64, ok: bool, reason: &str| -> Result<(), SimError> {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(SimError::invalid(format!("{at} ({name}).{f}"), v, reason))
            }
        };
        let fields = match *self {
            SimEffect::Bias { yaw_moment_nm } => bias::fields(yaw_moment_nm),
            SimEffect::GyroBias { bias_degps } => gyro_bias::fields(bias_degps),
            SimEffect::DeadTime { delay_s } => dead_time::fields(delay_s),
            SimEffect::RateLimit { rate_degps } => rate_limit::fields(rate_degps),
            SimEffect::Saturation { limit_deg } => saturation::fields(limit_deg),
            SimEffect::Asymmetry { starboard_gain } => asymmetry::fields(starboard_gain),
            SimEffect::NonlinearDamping { n_rr, .. } => nonlinear_damping::fields(n_rr),
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => wind::fields(speed_mps, from_deg),
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => current::fields(speed_mps, towards_deg),
            SimEffect::DeadBand { width_deg } => dead_band::fields(width_deg),
        };
        for f in fields.iter().flatten() {
            check(f.name, f.value, f.ok, f.expected)?;
        }
        Ok(())
    }

    /// Sets this effect's knobs of the simulators' physics.
    pub fn apply(&self, k: &mut SimKnobs) {
        match *self {
            SimEffect::Bias { yaw_moment_nm } => bias::apply(yaw_moment_nm, k),
            SimEffect::GyroBias { bias_degps } => gyro_bias::apply(bias_degps, k),
            SimEffect::DeadTime { delay_s } => dead_time::apply(delay_s, k),
            SimEffect::RateLimit { rate_degps } => rate_limit::apply(rate_degps, k),
            SimEffect::Saturation { limit_deg } => saturation::apply(limit_deg, k),
            SimEffect::Asymmetry { starboard_gain } => asymmetry::apply(starboard_gain, k),
            SimEffect::NonlinearDamping { n_rr, cubic } => nonlinear_damping::apply(n_rr, cubic, k),
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => wind::apply(speed_mps, from_deg, k),
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => current::apply(speed_mps, towards_deg, k),
            SimEffect::DeadBand { width_deg } => dead_band::apply(width_deg, k),
        }
    }

    /// The effect carried over to another hull: times scale with `s.time`, rates with its
    /// inverse, speeds with `s.speed`, moments with `s.moment`; angles and
    /// non-dimensional gains stay.
    pub fn on_hull(&self, s: &HullScale) -> SimEffect {
        match *self {
            SimEffect::Bias { yaw_moment_nm } => bias::on_hull(yaw_moment_nm, s),
            SimEffect::GyroBias { bias_degps } => gyro_bias::on_hull(bias_degps, s),
            SimEffect::DeadTime { delay_s } => dead_time::on_hull(delay_s, s),
            SimEffect::RateLimit { rate_degps } => rate_limit::on_hull(rate_degps, s),
            SimEffect::Wind {
                speed_mps,
                from_deg,
            } => wind::on_hull(speed_mps, from_deg, s),
            SimEffect::Current {
                speed_mps,
                towards_deg,
            } => current::on_hull(speed_mps, towards_deg, s),
            SimEffect::Saturation { .. }
            | SimEffect::DeadBand { .. }
            | SimEffect::Asymmetry { .. }
            | SimEffect::NonlinearDamping { .. } => *self,
        }
    }
}

#[cfg(test)]
mod tests;
