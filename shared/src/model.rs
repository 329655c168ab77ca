//! The model schema: order, θ, sample time, units, actuator model and effects.
//!
//! This is the contract between the host (which identifies and exports models) and the
//! firmware (which evaluates them in `f32`). It holds data and validation only, no maths
//! beyond what validation needs.
//!
//! # The model
//!
//! Innovations form, order `n`, in the *difference form* of the observability canonical
//! parameterisation:
//!
//! ```text
//! z(t+1) = z(t) + A_δ z(t) + b (ũ(t) + Σ_j β_j φ_j(t)) + k e(t)
//! y(t)   = z_1(t) + d_y + e(t)
//! A_δ:  (A_δ z)_i = z_{i+1} for i < n,  (A_δ z)_n = Σ a_i z_i
//! ```
//!
//! `u` is the commanded pod/rudder angle (deg), `y` the yaw rate (deg/s). `ũ` is `u` after the
//! actuator model: dead time, then saturation of the delayed command, then the dead band
//! (backlash: the rudder/pod stays where it is until the target is more than the band's
//! width away), then the rate limit (the servo slews towards what the band lets through),
//! each optional. Every effect that
//! "enters through B" adds `β φ(t)` to the effective input; `gyro-bias` is the output offset `d_y`.
//!
//! The host identifies the model in the shift form of the same parameterisation, `x(t+1) =
//! A x(t) + …` with `A` the companion matrix of `z^n − a_n z^{n−1} − … − a_1`, `y = x_1 + …`.
//! The difference form is that model in the coordinates `z_i = Δ^{i−1} x_1` (`z_1 = x_1`,
//! `z_2 = x_2 − x_1`, `z_3 = x_3 − 2 x_2 + x_1`, …): `I + A_δ` is similar to `A`, and `a` here
//! holds the coefficients of the characteristic polynomial in `δ = z − 1`. A yaw model sampled
//! fast against the ship's time constants has poles close to 1, where the shift-form
//! coefficients cancel to many digits: rounded to `f32` they no longer hold the model (its
//! steady-state gain `A(1) = 1 − Σ a_i` can be smaller than their rounding error). The
//! difference-form coefficients measure the poles' distances from 1 directly and keep their
//! relative precision in `f32`, and the state update adds small increments to the state.

use heapless::Vec;
use serde::{Deserialize, Serialize};

/// Smallest model order accepted.
pub const MIN_ORDER: usize = 2;
/// Largest model order accepted.
pub const MAX_ORDER: usize = 8;
/// Largest number of effects one model may carry (one of each kind).
pub const MAX_EFFECTS: usize = 10;
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
///
/// Not `#[non_exhaustive]`: every match over the library is exhaustive, so a new effect makes
/// the compiler list each place that must learn it (the blob's format version guards the wire).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Effect<R = f32> {
    /// Constant yaw moment (current, steady wind, propeller asymmetry): `φ = 1` through B.
    Bias {
        /// Gain β (input units).
        beta: R,
    },
    /// Rate-sensor offset: `y = x_1 + d_y`.
    GyroBias {
        /// Output offset `d_y` (output units).
        d_y: R,
    },
    /// Actuator/command delay: `ũ(t) = u(t − d)`.
    DeadTime {
        /// Delay in whole samples, `1..=MAX_DEAD_TIME`.
        samples: u8,
    },
    /// Pod/rudder slew limit: `ũ` follows its target at no more than `ρ·Ts` per step.
    RateLimit {
        /// Slew rate ρ in input units per second, `> 0`.
        rate: R,
    },
    /// Angle limit: `ũ = clamp(ũ, −δ_max, δ_max)`.
    Saturation {
        /// Limit δ_max in input units, `> 0`.
        limit: R,
    },
    /// Port/starboard gain difference: `φ = max(ũ, 0)` through B.
    Asymmetry {
        /// Gain β.
        beta: R,
    },
    /// Hull damping beyond linear (Norrbin): `φ = ρ|ρ|` (or `ρ³`) through B, of the rate
    /// the hull turns at, `ρ = y − d_y` (the gyro's reading less its offset).
    NonlinearDamping {
        /// Gain β.
        beta: R,
        /// `true` for `φ = y³`, `false` for `φ = y|y|`.
        cubic: bool,
    },
    /// Heading-dependent yaw moment of a steady wind:
    /// `φ = (sin 2ψ, cos 2ψ, sin ψ, cos ψ)` through B.
    Wind {
        /// Gain of `sin 2ψ`.
        beta_s2: R,
        /// Gain of `cos 2ψ`.
        beta_c2: R,
        /// Gain of `sin ψ`.
        beta_s1: R,
        /// Gain of `cos ψ`.
        beta_c1: R,
    },
    /// Heading-dependent drift moment of a current: `φ = (sin ψ, cos ψ)` through B.
    Current {
        /// Gain of `sin ψ`.
        beta_s: R,
        /// Gain of `cos ψ`.
        beta_c: R,
    },
    /// Steering-gear dead band (backlash, a worn gear): the rudder/pod does not move until
    /// the (saturated) command differs from its position by more than `width`, then follows
    /// it `width` behind: `ũ = clamp(ũ_prev, τ − width, τ + width)`.
    ///
    /// Last in the enum so that the blob's variant indices of the other effects are those
    /// of format 2 blobs written before it existed.
    DeadBand {
        /// Width b in input units, `> 0`.
        width: R,
    },
}

/// The kind of an effect, without parameters.
///
/// Not `#[non_exhaustive]`, like [`Effect`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
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
    /// See [`Effect::DeadBand`].
    DeadBand,
}

impl EffectKind {
    /// Every kind, in library order.
    pub const ALL: [EffectKind; 10] = [
        EffectKind::Bias,
        EffectKind::GyroBias,
        EffectKind::DeadTime,
        EffectKind::RateLimit,
        EffectKind::Saturation,
        EffectKind::Asymmetry,
        EffectKind::NonlinearDamping,
        EffectKind::Wind,
        EffectKind::Current,
        EffectKind::DeadBand,
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
            EffectKind::DeadBand => "dead-band",
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
        match self {
            EffectKind::DeadTime
            | EffectKind::RateLimit
            | EffectKind::Saturation
            | EffectKind::DeadBand => true,
            EffectKind::Bias
            | EffectKind::GyroBias
            | EffectKind::Asymmetry
            | EffectKind::NonlinearDamping
            | EffectKind::Wind
            | EffectKind::Current => false,
        }
    }

    /// Whether the effect needs the heading ψ (measured or integrated from `r`).
    ///
    /// ```
    /// use yawcast_shared::model::EffectKind;
    /// assert!(EffectKind::Current.needs_heading());
    /// ```
    pub const fn needs_heading(self) -> bool {
        match self {
            EffectKind::Wind | EffectKind::Current => true,
            EffectKind::Bias
            | EffectKind::GyroBias
            | EffectKind::DeadTime
            | EffectKind::RateLimit
            | EffectKind::Saturation
            | EffectKind::Asymmetry
            | EffectKind::NonlinearDamping
            | EffectKind::DeadBand => false,
        }
    }
}

impl<R> Effect<R> {
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
            Effect::DeadBand { .. } => EffectKind::DeadBand,
        }
    }

    /// The same effect with every real parameter passed through `f` (the dead time's
    /// samples and the damping's form unchanged): `f32` for the wire, `f64` for the host.
    ///
    /// ```
    /// use yawcast_shared::model::Effect;
    /// let e: Effect<f64> = Effect::Saturation { limit: 2.5f32 }.map(f64::from);
    /// assert_eq!(e, Effect::Saturation { limit: 2.5 });
    /// ```
    pub fn map<S>(self, f: impl Fn(R) -> S) -> Effect<S> {
        match self {
            Effect::Bias { beta } => Effect::Bias { beta: f(beta) },
            Effect::GyroBias { d_y } => Effect::GyroBias { d_y: f(d_y) },
            Effect::DeadTime { samples } => Effect::DeadTime { samples },
            Effect::RateLimit { rate } => Effect::RateLimit { rate: f(rate) },
            Effect::Saturation { limit } => Effect::Saturation { limit: f(limit) },
            Effect::Asymmetry { beta } => Effect::Asymmetry { beta: f(beta) },
            Effect::NonlinearDamping { beta, cubic } => Effect::NonlinearDamping {
                beta: f(beta),
                cubic,
            },
            Effect::Wind {
                beta_s2,
                beta_c2,
                beta_s1,
                beta_c1,
            } => Effect::Wind {
                beta_s2: f(beta_s2),
                beta_c2: f(beta_c2),
                beta_s1: f(beta_s1),
                beta_c1: f(beta_c1),
            },
            Effect::Current { beta_s, beta_c } => Effect::Current {
                beta_s: f(beta_s),
                beta_c: f(beta_c),
            },
            Effect::DeadBand { width } => Effect::DeadBand { width: f(width) },
        }
    }
}

/// One effect of every kind with typical parameters, in library order
/// ([`EffectKind::ALL`]): for examples and tests that must cover the whole library.
///
/// ```
/// use yawcast_shared::model::{EffectKind, EVERY_EFFECT};
/// assert!(EVERY_EFFECT.iter().map(|e| e.kind()).eq(EffectKind::ALL));
/// ```
pub const EVERY_EFFECT: [Effect; EffectKind::ALL.len()] = [
    Effect::Bias { beta: 0.2 },
    Effect::GyroBias { d_y: -0.3 },
    Effect::DeadTime { samples: 3 },
    Effect::RateLimit { rate: 4.0 },
    Effect::Saturation { limit: 6.0 },
    Effect::Asymmetry { beta: 0.1 },
    Effect::NonlinearDamping {
        beta: -0.05,
        cubic: false,
    },
    Effect::Wind {
        beta_s2: 0.3,
        beta_c2: -0.2,
        beta_s1: 0.1,
        beta_c1: 0.05,
    },
    Effect::Current {
        beta_s: -0.2,
        beta_c: 0.1,
    },
    Effect::DeadBand { width: 0.75 },
];

/// A complete model as exported to the controller (all numbers `f32`), in the difference
/// form (module docs).
///
/// `a`, `b`, `k` each hold exactly `order` values. Build one with [`ModelSpec::new`], which
/// validates it; the blob decoder validates again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// Model order n, `MIN_ORDER..=MAX_ORDER`.
    pub order: u8,
    /// Sample time in seconds, `> 0`.
    pub ts: f32,
    /// Last row of `A_δ`: `a_1..a_n` (`z_n(t+1) = z_n(t) + Σ a_i z_i(t) + …`).
    pub a: Vec<f32, MAX_ORDER>,
    /// Input vector (difference coordinates).
    pub b: Vec<f32, MAX_ORDER>,
    /// Kalman gain (difference coordinates).
    pub k: Vec<f32, MAX_ORDER>,
    /// Units of input and output.
    pub units: Units,
    /// Effects, at most one of each kind.
    pub effects: Vec<Effect, MAX_EFFECTS>,
}

/// Largest absolute value accepted for any model coefficient or effect parameter.
pub const MAX_MAGNITUDE: f32 = 1.0e6;
/// Largest sample time accepted, in seconds.
pub const MAX_SAMPLE_TIME: f32 = 3600.0;

/// Which coefficient vector of the model an error refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Field {
    /// The companion row `a`.
    A,
    /// The input vector `b`.
    B,
    /// The Kalman gain `k`.
    K,
}

impl Field {
    /// The field's name as written in the model (`"a"`, `"b"`, `"k"`).
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_shared::model::Field;
    /// assert_eq!(Field::K.name(), "k");
    /// ```
    pub const fn name(self) -> &'static str {
        match self {
            Field::A => "a",
            Field::B => "b",
            Field::K => "k",
        }
    }
}

/// Why a [`ModelSpec`] was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ModelError {
    /// The order is outside `MIN_ORDER..=MAX_ORDER`.
    Order(u8),
    /// A coefficient vector does not hold exactly `order` values.
    Length {
        /// The vector.
        field: Field,
        /// Its length.
        len: usize,
    },
    /// A coefficient is NaN, infinite or larger than [`MAX_MAGNITUDE`] in magnitude.
    Coefficient {
        /// The vector.
        field: Field,
        /// Zero-based index of the offending value.
        index: usize,
    },
    /// The sample time is not in `(0, MAX_SAMPLE_TIME]`.
    SampleTime,
    /// An effect parameter is out of its range (non-finite, too large, or violating the
    /// effect's own constraint such as a positive rate).
    EffectParameter(EffectKind),
    /// The same effect kind appears twice.
    DuplicateEffect(EffectKind),
    /// The state matrix `I + A_δ` has an eigenvalue on or outside the unit circle.
    UnstableModel,
    /// The predictor matrix A − K C has an eigenvalue on or outside the unit circle.
    UnstablePredictor,
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::Order(n) => {
                write!(f, "model order {n} is outside {MIN_ORDER}..={MAX_ORDER}")
            }
            ModelError::Length { field, len } => write!(
                f,
                "vector {} holds {len} values, not one per state",
                field.name()
            ),
            ModelError::Coefficient { field, index } => write!(
                f,
                "{}[{index}] is not finite or exceeds {MAX_MAGNITUDE:e} in magnitude",
                field.name()
            ),
            ModelError::SampleTime => {
                write!(f, "sample time must be in (0, {MAX_SAMPLE_TIME}] seconds")
            }
            ModelError::EffectParameter(kind) => {
                write!(f, "effect {} has a parameter out of range", kind.name())
            }
            ModelError::DuplicateEffect(kind) => {
                write!(f, "effect {} appears more than once", kind.name())
            }
            ModelError::UnstableModel => {
                write!(
                    f,
                    "the state matrix has an eigenvalue on or outside the unit circle"
                )
            }
            ModelError::UnstablePredictor => write!(
                f,
                "the predictor A - K C has an eigenvalue on or outside the unit circle"
            ),
        }
    }
}

impl core::error::Error for ModelError {}

impl ModelSpec {
    /// Builds a model and validates it (see [`ModelSpec::validate`]).
    ///
    /// # Errors
    /// [`ModelError::Length`] when a slice is longer than [`MAX_ORDER`] or does not match
    /// `order`, [`ModelError::DuplicateEffect`] when more than one effect of a kind is given,
    /// and every error of [`ModelSpec::validate`].
    ///
    /// ```
    /// use yawcast_shared::model::{Effect, ModelError, ModelSpec, Units};
    /// // δ² + 1.5 δ + 0.7: poles z = 1 + δ = 0.25 ± 0.37i
    /// let m = ModelSpec::new(
    ///     2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2], Units::default(),
    ///     &[Effect::Bias { beta: 0.01 }],
    /// )?;
    /// assert_eq!(m.order, 2);
    /// assert_eq!(m.effects.len(), 1);
    /// // a = (0, 0.5): δ² − 0.5 δ has the root δ = 0.5, the pole z = 1.5.
    /// let bad = ModelSpec::new(2, 1.0, &[0.0, 0.5], &[0.1, 0.0], &[0.0, 0.0],
    ///                          Units::default(), &[]);
    /// assert_eq!(bad, Err(ModelError::UnstableModel));
    /// # Ok::<(), ModelError>(())
    /// ```
    pub fn new(
        order: u8,
        ts: f32,
        a: &[f32],
        b: &[f32],
        k: &[f32],
        units: Units,
        effects: &[Effect],
    ) -> Result<Self, ModelError> {
        let vec = |field: Field, v: &[f32]| -> Result<Vec<f32, MAX_ORDER>, ModelError> {
            Vec::from_slice(v).map_err(|_| ModelError::Length {
                field,
                len: v.len(),
            })
        };
        let mut list = Vec::new();
        for e in effects {
            if list.push(*e).is_err() {
                return Err(ModelError::DuplicateEffect(e.kind()));
            }
        }
        let spec = ModelSpec {
            order,
            ts,
            a: vec(Field::A, a)?,
            b: vec(Field::B, b)?,
            k: vec(Field::K, k)?,
            units,
            effects: list,
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Checks everything the firmware relies on.
    ///
    /// The order is in `MIN_ORDER..=MAX_ORDER`; `a`, `b`, `k` hold `order` finite values of
    /// magnitude at most [`MAX_MAGNITUDE`]; `0 < ts ≤ MAX_SAMPLE_TIME`; every effect's
    /// parameters are finite and at most [`MAX_MAGNITUDE`] in magnitude, dead time is in
    /// `1..=MAX_DEAD_TIME`, rate and limit are positive; no effect kind appears twice; and
    /// both the state matrix `I + A_δ` and the predictor matrix `I + A_δ − k e₁ᵀ` have all
    /// eigenvalues strictly inside the unit circle (Schur–Cohn test on their characteristic
    /// polynomials in `z`, in `f64`).
    ///
    /// # Errors
    /// The first [`ModelError`] found, in the order listed above.
    ///
    /// ```
    /// use yawcast_shared::model::{ModelError, ModelSpec, Units};
    /// let mut m = ModelSpec::new(2, 0.5, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                            Units::default(), &[])?;
    /// assert_eq!(m.validate(), Ok(()));
    /// // A large gain makes the predictor unstable although the model is stable.
    /// m.k[0] = 3.0;
    /// assert_eq!(m.validate(), Err(ModelError::UnstablePredictor));
    /// # Ok::<(), ModelError>(())
    /// ```
    pub fn validate(&self) -> Result<(), ModelError> {
        let n = usize::from(self.order);
        if !(MIN_ORDER..=MAX_ORDER).contains(&n) {
            return Err(ModelError::Order(self.order));
        }
        for (field, v) in [
            (Field::A, &self.a),
            (Field::B, &self.b),
            (Field::K, &self.k),
        ] {
            if v.len() != n {
                return Err(ModelError::Length {
                    field,
                    len: v.len(),
                });
            }
            if let Some(index) = v.iter().position(|x| !sane(*x)) {
                return Err(ModelError::Coefficient { field, index });
            }
        }
        if !(self.ts > 0.0 && self.ts <= MAX_SAMPLE_TIME) {
            return Err(ModelError::SampleTime);
        }
        let mut seen = [false; EffectKind::ALL.len()];
        for e in &self.effects {
            let kind = e.kind();
            let slot = kind as usize;
            if seen[slot] {
                return Err(ModelError::DuplicateEffect(kind));
            }
            seen[slot] = true;
            if !effect_ok(e) {
                return Err(ModelError::EffectParameter(kind));
            }
        }
        if !monic_schur_stable(&shift_by_one(&companion_char_poly(&self.a, &[], n), n), n) {
            return Err(ModelError::UnstableModel);
        }
        if !monic_schur_stable(
            &shift_by_one(&companion_char_poly(&self.a, &self.k, n), n),
            n,
        ) {
            return Err(ModelError::UnstablePredictor);
        }
        Ok(())
    }

    /// The effect of the given kind, if the model carries one.
    ///
    /// # Errors
    /// None: `None` means the model has no such effect.
    ///
    /// ```
    /// use yawcast_shared::model::{Effect, EffectKind, ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[Effect::DeadTime { samples: 2 }]).unwrap();
    /// assert_eq!(m.effect(EffectKind::DeadTime), Some(Effect::DeadTime { samples: 2 }));
    /// assert_eq!(m.effect(EffectKind::Wind), None);
    /// ```
    pub fn effect(&self, kind: EffectKind) -> Option<Effect> {
        self.effects.iter().copied().find(|e| e.kind() == kind)
    }
}

/// Finite and at most [`MAX_MAGNITUDE`] in magnitude.
fn sane(x: f32) -> bool {
    x.is_finite() && (-MAX_MAGNITUDE..=MAX_MAGNITUDE).contains(&x)
}

fn effect_ok(e: &Effect) -> bool {
    match *e {
        Effect::Bias { beta } | Effect::Asymmetry { beta } => sane(beta),
        Effect::NonlinearDamping { beta, .. } => sane(beta),
        Effect::GyroBias { d_y } => sane(d_y),
        Effect::DeadTime { samples } => (1..=MAX_DEAD_TIME).contains(&samples),
        Effect::RateLimit { rate } => sane(rate) && rate > 0.0,
        Effect::Saturation { limit } => sane(limit) && limit > 0.0,
        Effect::Wind {
            beta_s2,
            beta_c2,
            beta_s1,
            beta_c1,
        } => sane(beta_s2) && sane(beta_c2) && sane(beta_s1) && sane(beta_c1),
        Effect::Current { beta_s, beta_c } => sane(beta_s) && sane(beta_c),
        Effect::DeadBand { width } => sane(width) && width > 0.0,
    }
}

/// A polynomial, monic, in descending powers: `[1, c_1, …, c_n, 0, …]` for
/// `z^n + c_1 z^{n−1} + … + c_n`.
type Poly = [f64; MAX_ORDER + 1];

/// Characteristic polynomial of `A − k e₁ᵀ` for the order-`n` companion matrix with last row
/// `a` (missing entries of `a` and `k` count as 0; `n` outside `1..=MAX_ORDER` gives NaNs).
///
/// From `z x_i = x_{i+1} − k_i x_1` (i < n): `x_i = p_i(z) x_1` with `p_1 = 1`,
/// `p_{i+1} = z p_i + k_i`; the last row gives `z p_n + k_n − Σ a_j p_j = 0`.
/// With `k = 0` this is `z^n − a_n z^{n−1} − … − a_1`. Fixed-size arrays throughout, so no
/// index can fail.
// Element loops over fixed arrays: every index is provably in bounds, no panic path.
#[allow(clippy::manual_memcpy)]
fn companion_char_poly(a: &[f32], k: &[f32], n: usize) -> Poly {
    if n == 0 || n > MAX_ORDER {
        // not a valid order: a polynomial that fails the stability test
        return [f64::NAN; MAX_ORDER + 1];
    }
    let mut av = [0.0f64; MAX_ORDER];
    let mut kv = [0.0f64; MAX_ORDER];
    for (d, v) in av.iter_mut().zip(a).take(n) {
        *d = f64::from(*v);
    }
    for (d, v) in kv.iter_mut().zip(k).take(n) {
        *d = f64::from(*v);
    }
    // p[i] holds p_{i+1} in ascending powers (p[i][j] = coefficient of z^j).
    let mut p = [[0.0f64; MAX_ORDER + 1]; MAX_ORDER];
    p[0][0] = 1.0;
    for i in 1..n {
        let prev = p[i - 1];
        for j in 1..=i {
            p[i][j] = prev[j - 1];
        }
        p[i][0] = kv[i - 1];
    }
    // q(z) = z p_n + k_n − Σ a_j p_j, ascending powers, degree n.
    let mut q = [0.0f64; MAX_ORDER + 1];
    for j in 0..n {
        q[j + 1] = p[n - 1][j];
    }
    q[0] += kv[n - 1];
    for j in 0..n {
        for m in 0..n {
            q[m] -= av[j] * p[j][m];
        }
    }
    let mut out = [0.0f64; MAX_ORDER + 1];
    for (o, v) in out.iter_mut().zip(q.iter().take(n + 1).rev()) {
        *o = *v;
    }
    out
}

/// `p(z − 1)` for the monic polynomial `p` of degree `n` (descending powers, as [`Poly`]):
/// the characteristic polynomial in `z` of `I + M` from that of `M` in `δ`.
// Element loops over fixed arrays: every index is provably in bounds, no panic path.
#[allow(clippy::needless_range_loop)]
fn shift_by_one(p: &Poly, n: usize) -> Poly {
    let n = n.min(MAX_ORDER);
    // ascending coefficients of p(δ), then Horner in (z − 1): q ← q·(z − 1) + c
    let mut q = [0.0f64; MAX_ORDER + 1];
    for i in 0..=n {
        let c = p[i];
        // q·(z − 1): shift up, subtract
        let mut next = [0.0f64; MAX_ORDER + 1];
        for j in 0..n {
            next[j + 1] += q[j];
            next[j] -= q[j];
        }
        next[0] += c;
        q = next;
    }
    // back to descending powers
    let mut out = [0.0f64; MAX_ORDER + 1];
    for i in 0..=n {
        out[i] = q[n - i];
    }
    out
}

/// Schur–Cohn (Levinson step-down) test: `true` when every root of the polynomial
/// `p[0] z^n + p[1] z^{n−1} + … + p[n]` (descending powers, `n = p.len() − 1 ≤ MAX_ORDER`)
/// lies strictly inside the unit circle. `false` for a zero or non-finite leading coefficient,
/// any non-finite coefficient, an empty slice or a degree above [`MAX_ORDER`].
///
/// This is the test [`ModelSpec::validate`] applies to `A` and `A − KC`; the host's
/// identification uses the same function.
///
/// # Errors
/// None: an argument it cannot judge is reported as not stable.
///
/// ```
/// use yawcast_shared::model::schur_stable;
/// // (z − 0.9)(z + 0.8) = z² − 0.1 z − 0.72: stable; a root at 1.05 is not.
/// assert!(schur_stable(&[1.0, -0.1, -0.72]));
/// assert!(schur_stable(&[2.0, -0.2, -1.44]));
/// assert!(!schur_stable(&[1.0, -1.05]));
/// assert!(!schur_stable(&[0.0, 1.0]));
/// ```
pub fn schur_stable(p: &[f64]) -> bool {
    let n = match p.len().checked_sub(1) {
        Some(n) if n <= MAX_ORDER => n,
        _ => return false,
    };
    let lead = p[0];
    if lead == 0.0 || !p.iter().all(|c| c.is_finite()) {
        return false;
    }
    let mut c: Poly = [0.0; MAX_ORDER + 1];
    for (d, v) in c.iter_mut().zip(p) {
        *d = *v / lead;
    }
    monic_schur_stable(&c, n)
}

/// [`schur_stable`] for a monic polynomial of degree `n` held in a [`Poly`].
fn monic_schur_stable(poly: &Poly, n: usize) -> bool {
    let n = n.min(MAX_ORDER);
    let mut c = *poly;
    for m in (1..=n).rev() {
        let r = c[m];
        if !(r.is_finite() && r < 1.0 && r > -1.0) {
            return false;
        }
        let den = 1.0 - r * r;
        let mut next = [0.0f64; MAX_ORDER + 1];
        next[0] = 1.0;
        for i in 1..m {
            next[i] = (c[i] - r * c[m - i]) / den;
        }
        c = next;
    }
    true
}

#[cfg(test)]
mod tests;

/// The rate of a slow gear must be positive (the other parameters' checks are in the tests
/// module).
#[cfg(test)]
#[test]
fn gear_rate_must_be_positive() {
    let ok = |rate: f32| effect_ok(&Effect::RateLimit { rate });
    assert!(ok(2.0));
    assert!(!ok(0.0) && !ok(-1.0) && !ok(f32::NAN) && !ok(2.0e6));
}
