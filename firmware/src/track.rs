//! The f32 heading and track predictor: heading ψ, position north/east, speed through water
//! and the earth-frame current, beside the yaw-rate [`Predictor`](crate::Predictor).
//!
//! # Exact semantics
//!
//! As for the yaw-rate predictor, every expression is evaluated as written, left to right,
//! one `f32` rounding per operation, no FMA. Sine and cosine of a heading come from
//! [`sin_cos_deg`], an `f32`-only polynomial (libm's `sincosf` reduces its argument in `f64`,
//! which the M4F emulates in software at about 2 000 instructions a call). `d_y` is the model's
//! `gyro-bias` offset: "`− d_y`" is performed only when the model has one. Constants computed
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
//!    component; beyond the gate → `Gated`; else `n = n + α · μ_n`, `e = e + α · μ_e`,
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
    dy: Option<f32>,
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
    /// use yawcast_shared::nav::{TrackError, TrackSpec};
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let mut track = TrackSpec::new(1.0, 2.0, true).unwrap();
    /// assert_eq!(Tracker::new(&m, &track).unwrap().state().speed, 2.0);
    /// track.gate_position = 0.0;
    /// assert_eq!(Tracker::new(&m, &track).unwrap_err(),
    ///            PredictorError::InvalidTrack(TrackError::OutOfRange("gate_position")));
    /// ```
    pub fn new(model: &ModelSpec, track: &TrackSpec) -> Result<Tracker, PredictorError> {
        model.validate()?;
        track
            .validate(model.ts)
            .map_err(PredictorError::InvalidTrack)?;
        let mut dy = None;
        for e in &model.effects {
            if let Effect::GyroBias { d_y } = *e {
                dy = Some(d_y);
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
        match self.dy {
            Some(d) => rate - d,
            None => rate,
        }
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
        let velocity = match nav.velocity {
            None => Correction::Absent,
            Some(v) if !(v[0].is_finite() && v[1].is_finite()) => Correction::Rejected,
            Some(v) => {
                let sw = sp.sway * w;
                let uw = st.speed - sp.speed_loss * (w * w);
                let nu_n = v[0] - (uw * h[0] - sw * h[1] + st.current[0]);
                let nu_e = v[1] - (uw * h[1] + sw * h[0] + st.current[1]);
                if !(abs(nu_n) <= sp.gate_velocity && abs(nu_e) <= sp.gate_velocity) {
                    Correction::Gated
                } else {
                    st.speed = st.speed + sp.gain_speed * (h[0] * nu_n + h[1] * nu_e);
                    if sp.current {
                        st.current[0] = st.current[0] + sp.gain_current * nu_n;
                        st.current[1] = st.current[1] + sp.gain_current * nu_e;
                    }
                    Correction::Applied
                }
            }
        };
        let fix = match nav.fix {
            None => Correction::Absent,
            Some(m) if !(m[0].is_finite() && m[1].is_finite()) => Correction::Rejected,
            Some(m) => {
                let mu_n = m[0] - st.pos[0];
                let mu_e = m[1] - st.pos[1];
                if !(abs(mu_n) <= sp.gate_position && abs(mu_e) <= sp.gate_position) {
                    Correction::Gated
                } else {
                    st.pos[0] = st.pos[0] + sp.gain_position * mu_n;
                    st.pos[1] = st.pos[1] + sp.gain_position * mu_e;
                    st.speed = st.speed + sp.fix_speed * (h[0] * mu_n + h[1] * mu_e);
                    if sp.current {
                        st.current[0] = st.current[0] + sp.fix_current * mu_n;
                        st.current[1] = st.current[1] + sp.fix_current * mu_e;
                    }
                    Correction::Applied
                }
            }
        };
        let ku = self.ts * st.speed;
        let (n, e) = self.dr(&st, st.pos[0], st.pos[1], st.h, w, ku);
        st.pos = [n, e];
        st.psi = st.psi + self.ts * w;
        st.h = self.rot(st.h, w);
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
        }
        if psi.is_finite() && n.is_finite() && e.is_finite() {
            Ok(())
        } else {
            Err(PredictorError::NonFinite)
        }
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

/// `(sin x, cos x)` of an angle `x` in degrees, in `f32` only: `k = roundf(x / 90)` (as
/// `x · (1/90)`, the constant rounded to `f32`), `r = (x − k·90) · (π/180)` in [−π/4, π/4]
/// (`x − k·90` is exact for |x| ≤ [`MAX_HEADING`]), then with `r2 = r · r` the Taylor
/// polynomials `s = r + r·(r2·(−1/6 + r2·(1/120 + r2·(−1/5040))))` and
/// `c = 1 + r2·(−1/2 + r2·(1/24 + r2·(−1/720 + r2·(1/40320))))` (each constant rounded to
/// `f32`; errors below 4e-7), and the quadrant `k mod 4` picks `(s, c)`, `(c, −s)`,
/// `(−s, −c)` or `(−c, s)`. Beyond ±[`MAX_HEADING`], and for NaN, the result is
/// `(NaN, NaN)`.
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
    let k = libm::roundf(x * (1.0 / 90.0));
    let r = (x - k * 90.0) * DEG2RAD;
    let r2 = r * r;
    let s = r + r * (r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0))));
    let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0))));
    // `as` saturates (NaN gives 0): never panics
    match (k as i32) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
#[path = "track_tests.rs"]
mod tests;
