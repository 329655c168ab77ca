//! The model schema: order, θ, sample time, units, actuator model and effects.
//!
//! This is the contract between the host (which identifies and exports models) and the
//! firmware (which evaluates them in `f32`). It holds data and validation only, no maths
//! beyond what validation needs.
//!
//! # The model
//!
//! Innovations form in observability canonical parameterisation, order `n`:
//!
//! ```text
//! x(t+1) = A x(t) + B (ũ(t) + Σ_j β_j φ_j(t)) + K e(t)
//! y(t)   = x_1(t) + d_y + e(t)
//! A = companion: x_i(t+1) = x_{i+1}(t) for i < n,  x_n(t+1) = Σ a_i x_i(t)
//! ```
//!
//! `u` is the commanded pod/rudder angle (deg), `y` the yaw rate (deg/s). `ũ` is `u` after the
//! actuator model: dead time, then saturation of the delayed command, then the rate limit
//! (the servo slews towards the saturated target), each optional. Every effect that
//! "enters through B" adds `β φ(t)` to the effective input; `gyro-bias` is the output offset `d_y`.

use heapless::Vec;
use serde::{Deserialize, Serialize};

/// Smallest model order accepted.
pub const MIN_ORDER: usize = 2;
/// Largest model order accepted.
pub const MAX_ORDER: usize = 8;
/// Largest number of effects one model may carry (one of each kind).
pub const MAX_EFFECTS: usize = 9;
/// Largest dead time, in samples, the firmware keeps a delay line for.
pub const MAX_DEAD_TIME: u8 = 32;

/// Unit of the input (commanded angle) column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum AngleUnit {
    /// Degrees.
    Deg,
    /// Radians.
    Rad,
}

/// Unit of the output (yaw rate) column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum RateUnit {
    /// Degrees per second.
    DegPerS,
    /// Radians per second.
    RadPerS,
}

/// Units the model's input and output are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Units {
    /// Unit of `u` (and of headings used by effects).
    pub input: AngleUnit,
    /// Unit of `y`.
    pub output: RateUnit,
}

impl Default for Units {
    fn default() -> Self {
        Self {
            input: AngleUnit::Deg,
            output: RateUnit::DegPerS,
        }
    }
}

/// One effect of the library, with its parameters.
///
/// The names used on the command line and in JSON are given by [`EffectKind::name`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Effect {
    /// Constant yaw moment (current, steady wind, propeller asymmetry): `φ = 1` through B.
    Bias {
        /// Gain β (input units).
        beta: f32,
    },
    /// Rate-sensor offset: `y = x_1 + d_y`.
    GyroBias {
        /// Output offset `d_y` (output units).
        d_y: f32,
    },
    /// Actuator/command delay: `ũ(t) = u(t − d)`.
    DeadTime {
        /// Delay in whole samples, `1..=MAX_DEAD_TIME`.
        samples: u8,
    },
    /// Pod/rudder slew limit: `ũ` follows its target at no more than `ρ·Ts` per step.
    RateLimit {
        /// Slew rate ρ in input units per second, `> 0`.
        rate: f32,
    },
    /// Angle limit: `ũ = clamp(ũ, −δ_max, δ_max)`.
    Saturation {
        /// Limit δ_max in input units, `> 0`.
        limit: f32,
    },
    /// Port/starboard gain difference: `φ = max(ũ, 0)` through B.
    Asymmetry {
        /// Gain β.
        beta: f32,
    },
    /// Hull damping beyond linear (Norrbin): `φ = y|y|` (or `y³`) through B.
    NonlinearDamping {
        /// Gain β.
        beta: f32,
        /// `true` for `φ = y³`, `false` for `φ = y|y|`.
        cubic: bool,
    },
    /// Heading-dependent yaw moment of a steady wind:
    /// `φ = (sin 2ψ, cos 2ψ, sin ψ, cos ψ)` through B.
    Wind {
        /// Gain of `sin 2ψ`.
        beta_s2: f32,
        /// Gain of `cos 2ψ`.
        beta_c2: f32,
        /// Gain of `sin ψ`.
        beta_s1: f32,
        /// Gain of `cos ψ`.
        beta_c1: f32,
    },
    /// Heading-dependent drift moment of a current: `φ = (sin ψ, cos ψ)` through B.
    Current {
        /// Gain of `sin ψ`.
        beta_s: f32,
        /// Gain of `cos ψ`.
        beta_c: f32,
    },
}

/// The kind of an effect, without parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum EffectKind {
    /// See [`Effect::Bias`].
    Bias,
    /// See [`Effect::GyroBias`].
    GyroBias,
    /// See [`Effect::DeadTime`].
    DeadTime,
    /// See [`Effect::RateLimit`].
    RateLimit,
    /// See [`Effect::Saturation`].
    Saturation,
    /// See [`Effect::Asymmetry`].
    Asymmetry,
    /// See [`Effect::NonlinearDamping`].
    NonlinearDamping,
    /// See [`Effect::Wind`].
    Wind,
    /// See [`Effect::Current`].
    Current,
}

impl EffectKind {
    /// Every kind, in library order.
    pub const ALL: [EffectKind; 9] = [
        EffectKind::Bias,
        EffectKind::GyroBias,
        EffectKind::DeadTime,
        EffectKind::RateLimit,
        EffectKind::Saturation,
        EffectKind::Asymmetry,
        EffectKind::NonlinearDamping,
        EffectKind::Wind,
        EffectKind::Current,
    ];

    /// The stable name used on the command line and in JSON.
    ///
    /// ```
    /// use yawcast_shared::model::EffectKind;
    /// assert_eq!(EffectKind::RateLimit.name(), "rate-limit");
    /// ```
    pub const fn name(self) -> &'static str {
        match self {
            EffectKind::Bias => "bias",
            EffectKind::GyroBias => "gyro-bias",
            EffectKind::DeadTime => "dead-time",
            EffectKind::RateLimit => "rate-limit",
            EffectKind::Saturation => "saturation",
            EffectKind::Asymmetry => "asymmetry",
            EffectKind::NonlinearDamping => "nonlinear-damping",
            EffectKind::Wind => "wind",
            EffectKind::Current => "current",
        }
    }

    /// Parses a stable name; `None` when the name is not in the library.
    ///
    /// ```
    /// use yawcast_shared::model::EffectKind;
    /// assert_eq!(EffectKind::from_name("gyro-bias"), Some(EffectKind::GyroBias));
    /// assert_eq!(EffectKind::from_name("waves"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<EffectKind> {
        EffectKind::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// Whether this effect is part of the actuator chain (changes `ũ`) rather than a regressor.
    ///
    /// ```
    /// use yawcast_shared::model::EffectKind;
    /// assert!(EffectKind::DeadTime.is_actuator());
    /// assert!(!EffectKind::Wind.is_actuator());
    /// ```
    pub const fn is_actuator(self) -> bool {
        matches!(
            self,
            EffectKind::DeadTime | EffectKind::RateLimit | EffectKind::Saturation
        )
    }

    /// Whether the effect needs the heading ψ (measured or integrated from `r`).
    ///
    /// ```
    /// use yawcast_shared::model::EffectKind;
    /// assert!(EffectKind::Current.needs_heading());
    /// ```
    pub const fn needs_heading(self) -> bool {
        matches!(self, EffectKind::Wind | EffectKind::Current)
    }
}

impl Effect {
    /// The kind of this effect.
    ///
    /// ```
    /// use yawcast_shared::model::{Effect, EffectKind};
    /// assert_eq!(Effect::Bias { beta: 0.1 }.kind(), EffectKind::Bias);
    /// ```
    pub const fn kind(&self) -> EffectKind {
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
        }
    }
}

/// A complete model as exported to the controller (all numbers `f32`).
///
/// `a`, `b`, `k` each hold exactly `order` values. Build one with [`ModelSpec::new`], which
/// validates it; the blob decoder validates again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// Model order n, `MIN_ORDER..=MAX_ORDER`.
    pub order: u8,
    /// Sample time in seconds, `> 0`.
    pub ts: f32,
    /// Last row of the companion matrix A: `a_1..a_n` (`x_n(t+1) = Σ a_i x_i(t) + …`).
    pub a: Vec<f32, MAX_ORDER>,
    /// Input vector B.
    pub b: Vec<f32, MAX_ORDER>,
    /// Kalman gain K.
    pub k: Vec<f32, MAX_ORDER>,
    /// Units of input and output.
    pub units: Units,
    /// Effects, at most one of each kind.
    pub effects: Vec<Effect, MAX_EFFECTS>,
}
