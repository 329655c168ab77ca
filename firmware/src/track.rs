//! The f32 heading and track predictor: heading ψ, position north/east, speed through water
//! and the earth-frame current, beside the yaw-rate [`Predictor`](crate::Predictor).
//!
//! # Exact semantics
//!
//! As for the yaw-rate predictor, every expression is evaluated as written, left to right,
//! one `f32` rounding per operation, no FMA. Sine and cosine of a heading come from
//! [`sin_cos_deg`], an `f32`-only polynomial (libm's `sincosf` reduces its argument in `f64`,
//! which the M4F emulates in software at about 2 000 instructions a call). `d_y` is the model's
//! `gyro-bias` offset, `+0` without one (`x − (+0)` is `x` for every `x`, so the one code path
//! equals skipping the subtraction). Constants computed
//! once when the tracker is built: `kr = ts · (π/180)` (the constant rounded to `f32`),
//! `kk = ts · κ`, `kl = ts · λ` (κ the sway, λ the speed loss of the [`TrackSpec`]).
//!
//! State ([`TrackState`]): heading `ψ̂` (deg), heading vector `h = (h_n, h_e)`, position
//! `p̂ = (n, e)` (m), speed through water `U` (m/s), current `c = (c_n, c_e)` (m/s). The
//! start (and reset) state is `ψ̂ = 0`, `h = (1, 0)`, `p̂ = 0`, `U = U₀`, `c = 0`.
//!
//! The rotation `rot(h, w)` turns `h` by the heading step of a yaw rate `w` (deg/s):
//! `Δ = kr · w`, `q = 1 − (Δ · Δ) · 0.5`, `h'_n = h_n · q − h_e · Δ`,
//! `h'_e = h_e · q + h_n · Δ` (cos to second order, sin to first: the angle is off by
//! `Δ³/6` per step, 1e-6 rad at 1 °/s and 1 s).
//!
//! The dead-reckoning step `dr(p, h, w, k_u)` over one sample at yaw rate `w`, with
//! `k_s = kk · w`, `k_w = k_u − kl · (w · w)`, `k_n = ts · c_n`, `k_e = ts · c_e`:
//! `n' = ((n + k_w · h_n) − k_s · h_e) + k_n`, `e' = ((e + k_w · h_e) + k_s · h_n) + k_e`
//! (speed `U − λw²` along the heading, `κw` to starboard, and the current).
//!
//! [`Tracker::update`]`(rate, psi, nav)` at sample t, with `w = rate − d_y`:
//! 1. heading: when `psi` is given and within ±[`MAX_HEADING`] (so finite), `ψ̂ = psi`,
//!    `(s, c) = sin_cos_deg(psi)`, `h = (c, s)`;
//! 2. ground velocity `v` (when given): not finite → [`Correction::Rejected`]; else with
//!    `s_w = κ · w` and `u_w = U − λ · (w · w)`,
//!    `ν_n = v_n − (((u_w · h_n) − (s_w · h_e)) + c_n)`,
//!    `ν_e = v_e − (((u_w · h_e) + (s_w · h_n)) + c_e)`; when `|ν_n|` or `|ν_e|` exceeds the
//!    gate → [`Correction::Gated`]; else `U = U + g_u · ((h_n · ν_n) + (h_e · ν_e))` and, with
//!    the current, `c_n = c_n + g_c · ν_n`, `c_e = c_e + g_c · ν_e`;
//! 3. position fix `m` (when given): not finite → `Rejected`; else `μ = m − p̂` per
//!    component; beyond the gate → `Gated`; else (when `α ≠ 0`) `n = n + α · μ_n`,
//!    `e = e + α · μ_e`,
//!    `U = U + k_u · ((h_n · μ_n) + (h_e · μ_e))`, with the current `c = c + k_c · μ` per
//!    component (step 2's `U` and `c` are the ones used here, `h` is step 1's);
//! 4. time update: `p̂ = dr(p̂, h, w, ts · U)` (with the `U`, `c` of step 3),
//!    `ψ̂ = ψ̂ + ts · w`, `h = rot(h, w)`;
//! 5. when `ψ̂ + h_n + h_e + n + e + U + c_n + c_e` (left to right) is not finite, the state
//!    is reset ([`TrackStatus::reset`]).
//!
//! `rate` is the yaw rate the yaw-rate predictor used at t: the measurement when finite,
//! else its prediction ([`Predictor::prediction`](crate::Predictor::prediction) before the
//! update).
//!
//! [`Tracker::predict_into`]`(out, rates)` works on a copy, with `k_u = ts · U` computed
//! once: `out[0] = (ψ̂, n, e)`; for `j = 1..H`: `w = rates[j−1] − d_y`,
//! `p̂ = dr(p̂, h, w, k_u)`, `ψ̂ = ψ̂ + ts · w`, `h = rot(h, w)`, `out[j] = (ψ̂, n, e)`. With
//! `rates` = ŷ(t+1|t) … from [`Predictor::predict_into`](crate::Predictor::predict_into),
//! `out[j]` is the heading and position at t + 1 + j.

use crate::PredictorError;
use yawcast_shared::model::{Effect, ModelSpec};
use yawcast_shared::nav::TrackSpec;

/// Degrees to radians, rounded once to `f32`.
const DEG2RAD: f32 = core::f32::consts::PI / 180.0;

/// What happened to one navigation correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Correction {
    /// No measurement was given.
    Absent,
    /// The measurement was applied.
    Applied,
    /// The measurement was not finite: skipped.
    Rejected,
    /// The innovation exceeded its gate (a jump): skipped.
    Gated,
}

/// What one [`Tracker::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackStatus {
    /// The ground-velocity correction.
    pub velocity: Correction,
    /// The position-fix correction.
    pub fix: Correction,
    /// The new state was not finite and the tracker was reset.
    pub reset: bool,
}

/// Navigation measurements of one sample, in the earth frame (north, east).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NavMeasurement {
    /// Ground velocity `(v_n, v_e)` in m/s (from speed and course over ground).
    pub velocity: Option<[f32; 2]>,
    /// Position fix `(n, e)` in metres from the navigation origin.
    pub fix: Option<[f32; 2]>,
}

/// The tracker's complete state, for save and restore.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackState {
    /// Heading ψ̂ (deg) at the next sample.
    pub psi: f32,
    /// Heading vector `(cos ψ̂, sin ψ̂)` as propagated.
    pub h: [f32; 2],
    /// Position `(n, e)` (m) at the next sample.
    pub pos: [f32; 2],
    /// Speed through water `U` (m/s).
    pub speed: f32,
    /// Current `(c_n, c_e)` (m/s).
    pub current: [f32; 2],
}

/// The f32 heading/track predictor. See the [module documentation](self).
#[derive(Debug, Clone)]
pub struct Tracker {
    spec: TrackSpec,
    ts: f32,
    kr: f32,
    kk: f32,
    kl: f32,
    dy: f32,
    st: TrackState,
}

/// `|x|` without `f32::abs` (core-only builds have it, but `libm` keeps one spelling).
#[inline(always)]
fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}

impl Tracker {
    /// Builds a tracker for the yaw-rate model `model` (its sample time and gyro offset) and
    /// the track part `track`, in the start state.
    ///
    /// # Errors
    /// [`PredictorError::InvalidModel`] when `model` does not validate,
    /// [`PredictorError::InvalidTrack`] when `track` does not validate for its sample time.
    ///
    /// ```
    /// use yawcast_firmware::{track::Tracker, PredictorError};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::{TrackError, TrackField, TrackSpec};
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut track = TrackSpec::new(1.0, 2.0, true).unwrap();
    /// assert_eq!(Tracker::new(&m, &track).unwrap().state().speed, 2.0);
    /// track.gate_position = 0.0;
    /// assert_eq!(Tracker::new(&m, &track).unwrap_err(),
    ///            PredictorError::InvalidTrack(TrackError::OutOfRange(TrackField::GatePosition)));
    /// ```
    pub fn new(model: &ModelSpec, track: &TrackSpec) -> Result<Tracker, PredictorError> {
        model.validate()?;
        track
            .validate(model.ts)
            .map_err(PredictorError::InvalidTrack)?;
        let mut dy = 0.0;
        for e in &model.effects {
            if let Effect::GyroBias { d_y } = *e {
                dy = d_y;
            }
        }
        Ok(Tracker {
            spec: *track,
            ts: model.ts,
            kr: model.ts * DEG2RAD,
            kk: model.ts * track.sway,
            kl: model.ts * track.speed_loss,
            dy,
            st: Self::start(track),
        })
    }

    fn start(track: &TrackSpec) -> TrackState {
        TrackState {
            psi: 0.0,
            h: [1.0, 0.0],
            pos: [0.0, 0.0],
            speed: track.speed,
            current: [0.0, 0.0],
        }
    }

    /// `rate − d_y`.
    #[inline(always)]
    fn minus_dy(&self, rate: f32) -> f32 {
        rate - self.dy
    }

    /// One sample: heading, navigation corrections, time update (module docs, steps 1–5).
    ///
    /// # Errors
    /// None: skipped corrections and a reset are reported in the [`TrackStatus`].
    ///
    /// ```
    /// use yawcast_firmware::track::{Correction, NavMeasurement, Tracker};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::TrackSpec;
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 2.0, true).unwrap()).unwrap();
    /// let nav = NavMeasurement { velocity: Some([2.0, 0.5]), fix: None };
    /// let s = t.update(0.0, Some(0.0), &nav);
    /// assert_eq!(s.velocity, Correction::Applied);
    /// // ν = (0, 0.5): U unchanged, c_e = 0.002·0.5; n = 0 + 1·2·1 + 0, e = 0 + 0 + 0.001
    /// assert_eq!(t.state().current, [0.0, 0.001]);
    /// assert_eq!(t.state().pos, [2.0, 0.001]);
    /// let jump = NavMeasurement { velocity: None, fix: Some([5000.0, 0.0]) };
    /// assert_eq!(t.update(0.0, None, &jump).fix, Correction::Gated);
    /// ```
    #[inline(never)]
    pub fn update(&mut self, rate: f32, psi: Option<f32>, nav: &NavMeasurement) -> TrackStatus {
        let sp = self.spec;
        let mut st = self.st;
        if let Some(p) = psi {
            if abs(p) <= MAX_HEADING {
                st.psi = p;
                let (s, c) = sin_cos_deg(p);
                st.h = [c, s];
            }
        }
        let h = st.h;
        let w = self.minus_dy(rate);
        let sw = sp.sway * w;
        let uw = st.speed - sp.speed_loss * (w * w);
        let v_hat = [
            uw * h[0] - sw * h[1] + st.current[0],
            uw * h[1] + sw * h[0] + st.current[1],
        ];
        let gains = [0.0, sp.gain_speed, sp.gain_current];
        let velocity = self.correct(&mut st, nav.velocity, v_hat, sp.gate_velocity, gains, h);
        let gains = [sp.gain_position, sp.fix_speed, sp.fix_current];
        let p_hat = st.pos;
        let fix = self.correct(&mut st, nav.fix, p_hat, sp.gate_position, gains, h);
        let ku = self.ts * st.speed;
        let mut k = [st.psi, st.h[0], st.h[1], st.pos[0], st.pos[1]];
        self.advance(&st, &mut k, rate, ku);
        st.psi = k[0];
        st.h = [k[1], k[2]];
        st.pos = [k[3], k[4]];
        let sum = st.psi + st.h[0] + st.h[1] + st.pos[0] + st.pos[1] + st.speed;
        let sum = sum + st.current[0] + st.current[1];
        let reset = !sum.is_finite();
        self.st = if reset { Self::start(&sp) } else { st };
        TrackStatus {
            velocity,
            fix,
            reset,
        }
    }

    /// Steps 2 and 3 (module docs): the innovation `ν = m − m̂` of a measurement `m`, gated,
    /// then `p̂ = p̂ + g_p·ν` (only when `g_p ≠ 0`: the velocity has none),
    /// `U = U + g_u·((h_n·ν_n) + (h_e·ν_e))`, and with the current `c = c + g_c·ν`;
    /// `gains = [g_p, g_u, g_c]`. Out of line: both corrections share one copy.
    #[inline(never)]
    fn correct(
        &self,
        st: &mut TrackState,
        m: Option<[f32; 2]>,
        m_hat: [f32; 2],
        gate: f32,
        gains: [f32; 3],
        h: [f32; 2],
    ) -> Correction {
        let Some(m) = m else {
            return Correction::Absent;
        };
        if !(m[0].is_finite() && m[1].is_finite()) {
            return Correction::Rejected;
        }
        let nu = [m[0] - m_hat[0], m[1] - m_hat[1]];
        if !(abs(nu[0]) <= gate && abs(nu[1]) <= gate) {
            return Correction::Gated;
        }
        if gains[0] != 0.0 {
            st.pos = [st.pos[0] + gains[0] * nu[0], st.pos[1] + gains[0] * nu[1]];
        }
        st.speed = st.speed + gains[1] * (h[0] * nu[0] + h[1] * nu[1]);
        if self.spec.current {
            st.current = [
                st.current[0] + gains[2] * nu[0],
                st.current[1] + gains[2] * nu[1],
            ];
        }
        Correction::Applied
    }

    /// `dr(p, h, w, k_u)` (module docs) with the current of `st`.
    #[inline(always)]
    fn dr(&self, st: &TrackState, n: f32, e: f32, h: [f32; 2], w: f32, ku: f32) -> (f32, f32) {
        let ks = self.kk * w;
        let kw = ku - self.kl * (w * w);
        let kn = self.ts * st.current[0];
        let ke = self.ts * st.current[1];
        (
            n + kw * h[0] - ks * h[1] + kn,
            e + kw * h[1] + ks * h[0] + ke,
        )
    }

    /// `rot(h, w)` (module docs).
    #[inline(always)]
    fn rot(&self, h: [f32; 2], w: f32) -> [f32; 2] {
        let d = self.kr * w;
        let q = 1.0 - d * d * 0.5;
        [h[0] * q - h[1] * d, h[1] * q + h[0] * d]
    }

    /// Predicts heading and position at t+1 … t+H into `out` (H = `out.len()`, rows
    /// `[ψ̂ (deg), n (m), e (m)]`) from the yaw rates `rates` = ŷ(t+1|t) … ŷ(t+H−1|t) (extra
    /// values are ignored). The tracker's state is not changed.
    ///
    /// # Errors
    /// [`PredictorError::HorizonOutOfRange`] when H is 0 or above
    /// [`MAX_HORIZON`](crate::MAX_HORIZON), [`PredictorError::NotEnoughInputs`] when `rates`
    /// has fewer than H − 1 values, [`PredictorError::NonFinite`] when the prediction goes
    /// non-finite (`out` must then not be used).
    ///
    /// ```
    /// use yawcast_firmware::track::{NavMeasurement, Tracker};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::TrackSpec;
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 2.0, false).unwrap()).unwrap();
    /// t.update(0.0, Some(90.0), &NavMeasurement::default());
    /// let mut out = [[0.0f32; 3]; 3];
    /// t.predict_into(&mut out, &[0.0, 0.0])?;
    /// // due east at 2 m/s: e grows by 2 m per step
    /// assert_eq!(out[0][0], 90.0);
    /// assert_eq!([out[1][2], out[2][2]], [4.0, 6.0]);
    /// # Ok::<(), yawcast_firmware::PredictorError>(())
    /// ```
    #[inline(never)]
    pub fn predict_into(&self, out: &mut [[f32; 3]], rates: &[f32]) -> Result<(), PredictorError> {
        let hzn = out.len();
        if hzn == 0 || hzn > crate::MAX_HORIZON {
            return Err(PredictorError::HorizonOutOfRange(hzn));
        }
        if rates.len() < hzn - 1 {
            return Err(PredictorError::NotEnoughInputs {
                needed: hzn - 1,
                got: rates.len(),
            });
        }
        let st = self.st;
        let ku = self.ts * st.speed;
        let (mut psi, mut h, mut n, mut e) = (st.psi, st.h, st.pos[0], st.pos[1]);
        let (first, rest) = match out.split_first_mut() {
            Some(s) => s,
            None => return Err(PredictorError::HorizonOutOfRange(0)),
        };
        *first = [psi, n, e];
        for (o, &r) in rest.iter_mut().zip(rates) {
            let w = self.minus_dy(r);
            (n, e) = self.dr(&st, n, e, h, w, ku);
            psi = psi + self.ts * w;
            h = self.rot(h, w);
            *o = [psi, n, e];
            // a second exit keeps the loop one copy in flash (runtime unrolling needs one)
            if !e.is_finite() {
                return Err(PredictorError::NonFinite);
            }
        }
        if psi.is_finite() && n.is_finite() {
            Ok(())
        } else {
            Err(PredictorError::NonFinite)
        }
    }

    /// The time update of [`Tracker::update`] on `k = [ψ̂, h_n, h_e, n, e]` with yaw rate `r`
    /// (before `− d_y`): the same steps as one step of the prediction.
    #[inline(always)]
    fn advance(&self, st: &TrackState, k: &mut [f32; 5], r: f32, ku: f32) {
        let w = self.minus_dy(r);
        let h = [k[1], k[2]];
        let (n, e) = self.dr(st, k[3], k[4], h, w, ku);
        let psi = k[0] + self.ts * w;
        let h = self.rot(h, w);
        *k = [psi, h[0], h[1], n, e];
    }

    /// A copy of the state.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_firmware::track::Tracker;
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::TrackSpec;
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, false).unwrap()).unwrap();
    /// assert_eq!(t.state().h, [1.0, 0.0]);
    /// ```
    pub fn state(&self) -> TrackState {
        self.st
    }

    /// Replaces the state with a saved one.
    ///
    /// # Errors
    /// [`PredictorError::InvalidState`] when a value is not finite (state unchanged).
    ///
    /// ```
    /// use yawcast_firmware::{track::Tracker, PredictorError};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::TrackSpec;
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, false).unwrap()).unwrap();
    /// let mut s = t.state();
    /// s.pos = [10.0, -3.0];
    /// t.restore(s)?;
    /// assert_eq!(t.state().pos, [10.0, -3.0]);
    /// s.speed = f32::NAN;
    /// assert_eq!(t.restore(s), Err(PredictorError::InvalidState));
    /// # Ok::<(), PredictorError>(())
    /// ```
    pub fn restore(&mut self, state: TrackState) -> Result<(), PredictorError> {
        let v = [
            state.psi,
            state.h[0],
            state.h[1],
            state.pos[0],
            state.pos[1],
            state.speed,
            state.current[0],
            state.current[1],
        ];
        if v.iter().all(|x| x.is_finite()) {
            self.st = state;
            Ok(())
        } else {
            Err(PredictorError::InvalidState)
        }
    }

    /// Back to the start state (ψ̂ = 0, p̂ = 0, `U = U₀`, no current).
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_firmware::track::{NavMeasurement, Tracker};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// use yawcast_shared::nav::TrackSpec;
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut t = Tracker::new(&m, &TrackSpec::new(1.0, 1.5, false).unwrap()).unwrap();
    /// t.update(1.0, Some(45.0), &NavMeasurement::default());
    /// t.reset();
    /// assert_eq!(t.state().psi, 0.0);
    /// ```
    pub fn reset(&mut self) {
        self.st = Self::start(&self.spec);
    }
}

/// Cross-track error (m) of the position `(n, e)` from the line through `(n0, e0)` with
/// course `chi_deg`: positive to starboard of the line, `(−(n − n0)·sin χ) + ((e − e0)·cos χ)`.
///
/// # Errors
/// None (non-finite inputs give a non-finite result).
///
/// ```
/// use yawcast_firmware::track::cross_track;
/// // a line due north through the origin: a point 5 m east is 5 m to starboard
/// assert_eq!(cross_track([0.0, 0.0], 0.0, [12.0, 5.0]), 5.0);
/// ```
pub fn cross_track(origin: [f32; 2], chi_deg: f32, pos: [f32; 2]) -> f32 {
    let (s, c) = sin_cos_deg(chi_deg);
    -((pos[0] - origin[0]) * s) + (pos[1] - origin[1]) * c
}

/// Ground velocity `(v_n, v_e)` (m/s) from speed `sog` (m/s) and course `cog_deg` over ground.
///
/// # Errors
/// None (non-finite inputs give non-finite components, which [`Tracker::update`] rejects).
///
/// ```
/// use yawcast_firmware::track::ground_velocity;
/// assert_eq!(ground_velocity(2.0, 0.0), [2.0, 0.0]);
/// ```
pub fn ground_velocity(sog: f32, cog_deg: f32) -> [f32; 2] {
    let (s, c) = sin_cos_deg(cog_deg);
    [sog * c, sog * s]
}

/// Largest |heading| (deg) [`sin_cos_deg`] reduces exactly; a measured heading beyond it is
/// ignored like a missing one.
pub const MAX_HEADING: f32 = 1.0e6;

/// `(sin x, cos x)` of an angle `x` in degrees, in `f32` only: with `q = x · (1/90)` (the
/// constant rounded to `f32`), the quadrant `k = (q + 0.5) as i32` for `q ≥ 0`, else
/// `(q − 0.5) as i32` (truncating), `r = (x − k·90) · (π/180)` in [−π/4, π/4] up to a
/// rounding (`x − k·90` is exact for |x| ≤ [`MAX_HEADING`]), then with `r2 = r · r` the
/// Taylor polynomials `s = r + r·(r2·(−1/6 + r2·(1/120 + r2·(−1/5040))))` and
/// `c = 1 + r2·(−1/2 + r2·(1/24 + r2·(−1/720 + r2·(1/40320))))` (each constant rounded to
/// `f32`; errors below 4e-7), and `k mod 4` picks `(s, c)`, `(c, −s)`, `(−s, −c)` or
/// `(−c, s)`. Beyond ±[`MAX_HEADING`], and for NaN, the result is `(NaN, NaN)`.
///
/// # Errors
/// None.
///
/// ```
/// use yawcast_firmware::track::sin_cos_deg;
/// assert_eq!(sin_cos_deg(90.0), (1.0, 0.0));
/// assert_eq!(sin_cos_deg(-180.0), (0.0, -1.0));
/// let (s, c) = sin_cos_deg(30.0);
/// assert!((s - 0.5).abs() < 1e-7 && (c - 0.866_025_4).abs() < 1e-7);
/// assert!(sin_cos_deg(2.0e6).0.is_nan());
/// ```
#[inline(never)]
pub fn sin_cos_deg(x: f32) -> (f32, f32) {
    if x.is_nan() || abs(x) > MAX_HEADING {
        return (f32::NAN, f32::NAN);
    }
    let q = x * (1.0 / 90.0);
    // |q| ≤ 11 112: the conversion neither saturates nor loses the integer
    let ki = if q < 0.0 {
        (q - 0.5) as i32
    } else {
        (q + 0.5) as i32
    };
    let r = (x - ki as f32 * 90.0) * DEG2RAD;
    let r2 = r * r;
    let s = r + r * (r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0))));
    let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0))));
    match ki & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
#[path = "track_tests.rs"]
mod tests;
