//! The heading and track part of a model: what the firmware's track predictor needs besides
//! the yaw-rate model.
//!
//! The track predictor (`yawcast_firmware::track`, and the host's f64 twin) integrates the
//! heading ψ from the predicted yaw rate and the ship's position north/east from its speed
//! through water `U` along the heading plus an earth-frame current `c = (c_n, c_e)`. `U` and,
//! when [`TrackSpec::current`] is set, `c` are estimated by a fixed-gain observer from the
//! measured ground velocity (speed and course over ground) and from position fixes:
//!
//! ```text
//! velocity:  ν = v_meas − ((U − λ·r²)·h + κ·r·h⊥ + c)    h = (cos ψ, sin ψ), h⊥ = (−sin ψ, cos ψ)
//!            U ← U + g_u·(h·ν),   c ← c + g_c·ν
//! fix:       μ = p_meas − p̂
//!            p̂ ← p̂ + α·μ,  U ← U + k_u·(h·μ),  c ← c + k_c·μ
//! ```
//!
//! A correction whose innovation exceeds its gate in either component is skipped and
//! counted, never applied. The equations, the order of every operation and the choice of the
//! gains are in `docs/method.md` (heading and track).

use serde::{Deserialize, Serialize};

/// Largest nominal speed through water accepted, m/s.
pub const MAX_SPEED: f32 = 100.0;

/// The heading/track part of a model.
///
/// Build one with [`TrackSpec::new`] (or fill the fields and call [`TrackSpec::validate`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackSpec {
    /// Nominal speed through water `U₀` (m/s): the speed estimate's starting value.
    pub speed: f32,
    /// `κ`: sway (drift) velocity per yaw rate, (m/s)/(deg/s): the ship's velocity through
    /// the water is `U` along the heading and `κ·r` to starboard (a turning hull drifts
    /// outwards); `|κ| ≤ 100`.
    pub sway: f32,
    /// `λ`: speed lost in a turn per squared yaw rate, (m/s)/(deg/s)²: the speed along the
    /// heading is `U − λ·r²`; `|λ| ≤ 100`.
    pub speed_loss: f32,
    /// The current vector is estimated (the model has the track's current part); without it
    /// `c` stays zero and `g_c`, `k_c` must be zero.
    pub current: bool,
    /// `g_u`: speed gain of a ground-velocity innovation, in `[0, 1]`.
    pub gain_speed: f32,
    /// `g_c`: current gain of a ground-velocity innovation, in `[0, 1]`.
    pub gain_current: f32,
    /// `α`: position gain of a fix innovation, in `[0, 1]`.
    pub gain_position: f32,
    /// `k_u`: speed gain of a fix innovation (1/s), in `[0, 1/Ts]`.
    pub fix_speed: f32,
    /// `k_c`: current gain of a fix innovation (1/s), in `[0, 1/Ts]`.
    pub fix_current: f32,
    /// Largest ground-velocity innovation component applied (m/s), `> 0`.
    pub gate_velocity: f32,
    /// Largest fix innovation component applied (m), `> 0`.
    pub gate_position: f32,
}

/// A field of [`TrackSpec`], as named in errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackField {
    /// `speed`.
    Speed,
    /// `sway`.
    Sway,
    /// `speed_loss`.
    SpeedLoss,
    /// `gain_speed`.
    GainSpeed,
    /// `gain_current`.
    GainCurrent,
    /// `gain_position`.
    GainPosition,
    /// `fix_speed`.
    FixSpeed,
    /// `fix_current`.
    FixCurrent,
    /// `gate_velocity`.
    GateVelocity,
    /// `gate_position`.
    GatePosition,
}

impl TrackField {
    /// Every field, in declaration order.
    pub const ALL: [TrackField; 10] = [
        TrackField::Speed,
        TrackField::Sway,
        TrackField::SpeedLoss,
        TrackField::GainSpeed,
        TrackField::GainCurrent,
        TrackField::GainPosition,
        TrackField::FixSpeed,
        TrackField::FixCurrent,
        TrackField::GateVelocity,
        TrackField::GatePosition,
    ];

    /// The field's name in the model's JSON twin and in messages.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_shared::nav::TrackField;
    /// assert_eq!(TrackField::GatePosition.name(), "gate_position");
    /// ```
    pub const fn name(self) -> &'static str {
        match self {
            TrackField::Speed => "speed",
            TrackField::Sway => "sway",
            TrackField::SpeedLoss => "speed_loss",
            TrackField::GainSpeed => "gain_speed",
            TrackField::GainCurrent => "gain_current",
            TrackField::GainPosition => "gain_position",
            TrackField::FixSpeed => "fix_speed",
            TrackField::FixCurrent => "fix_current",
            TrackField::GateVelocity => "gate_velocity",
            TrackField::GatePosition => "gate_position",
        }
    }
}

/// Why a [`TrackSpec`] is not valid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum TrackError {
    /// A field is not finite or outside its range.
    OutOfRange(TrackField),
    /// A current gain is non-zero although the current is not estimated.
    CurrentGainWithoutCurrent,
}

impl core::fmt::Display for TrackError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            TrackError::OutOfRange(field) => write!(
                f,
                "track part: {} is not finite or out of range",
                field.name()
            ),
            TrackError::CurrentGainWithoutCurrent => write!(
                f,
                "track part: current gains must be zero when the current is not estimated"
            ),
        }
    }
}

impl core::error::Error for TrackError {}

impl TrackSpec {
    /// The default observer for a model of sample time `ts` and nominal speed `speed`, no
    /// sway and no speed loss (`κ = λ = 0`): `g_u = 0.05`, `g_c = 0.002` with the current (else 0), `α = 0.5`, `k_u = 0.01/Ts`,
    /// `k_c = 0.002/Ts` with the current (else 0), gates 3 m/s and 200 m.
    ///
    /// # Errors
    /// [`TrackError::OutOfRange`] when `speed` (or `ts`, reported as the speed) is not finite
    /// or out of range.
    ///
    /// ```
    /// use yawcast_shared::nav::TrackSpec;
    /// let t = TrackSpec::new(1.0, 1.5, true).unwrap();
    /// assert_eq!(t.gain_current, 0.002);
    /// assert_eq!(TrackSpec::new(1.0, 1.5, false).unwrap().gain_current, 0.0);
    /// assert!(TrackSpec::new(1.0, -1.0, false).is_err());
    /// ```
    pub fn new(ts: f32, speed: f32, current: bool) -> Result<TrackSpec, TrackError> {
        if !(ts.is_finite() && ts > 0.0) {
            return Err(TrackError::OutOfRange(TrackField::Speed));
        }
        let c = if current { 1.0 } else { 0.0 };
        let spec = TrackSpec {
            speed,
            sway: 0.0,
            speed_loss: 0.0,
            current,
            gain_speed: 0.05,
            gain_current: 0.002 * c,
            gain_position: 0.5,
            fix_speed: 0.01 / ts,
            fix_current: 0.002 / ts * c,
            gate_velocity: 3.0,
            gate_position: 200.0,
        };
        spec.validate(ts)?;
        Ok(spec)
    }

    /// Checks every field for a model of sample time `ts`.
    ///
    /// # Errors
    /// [`TrackError::OutOfRange`] naming the first bad field,
    /// [`TrackError::CurrentGainWithoutCurrent`].
    ///
    /// ```
    /// use yawcast_shared::nav::{TrackError, TrackField, TrackSpec};
    /// let mut t = TrackSpec::new(0.5, 2.0, false).unwrap();
    /// t.gain_speed = 1.5;
    /// assert_eq!(t.validate(0.5), Err(TrackError::OutOfRange(TrackField::GainSpeed)));
    /// assert_eq!(t.validate(0.5).unwrap_err().to_string(),
    ///            "track part: gain_speed is not finite or out of range");
    /// ```
    pub fn validate(&self, ts: f32) -> Result<(), TrackError> {
        // one table, one loop: the controller carries this check, and it is small this way
        let inv_ts = 1.0 / ts;
        let value = [
            self.speed,
            self.sway,
            self.speed_loss,
            self.gain_speed,
            self.gain_current,
            self.gain_position,
            self.fix_speed,
            self.fix_current,
            self.gate_velocity,
            self.gate_position,
        ];
        let tiny = f32::MIN_POSITIVE;
        let lo = [0.0, -100.0, -100.0, 0.0, 0.0, 0.0, 0.0, 0.0, tiny, tiny];
        let hi = [
            MAX_SPEED, 100.0, 100.0, 1.0, 1.0, 1.0, inv_ts, inv_ts, 1.0e3, 1.0e7,
        ];
        for i in 0..TrackField::ALL.len() {
            // NaN fails both comparisons
            if !(value[i] >= lo[i] && value[i] <= hi[i]) {
                return Err(TrackError::OutOfRange(TrackField::ALL[i]));
            }
        }
        if !self.current && (self.gain_current != 0.0 || self.fix_current != 0.0) {
            return Err(TrackError::CurrentGainWithoutCurrent);
        }
        Ok(())
    }
}
