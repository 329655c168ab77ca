//! yawcast-firmware: the on-board f32 yaw-rate predictor.
//!
//! [`Predictor`] runs the model of `yawcast_shared::model` in `f32`: a Kalman-gain
//! measurement update and time update per sample ([`Predictor::update`]) and a k-step
//! open-loop prediction ([`Predictor::predict_into`]). It never allocates and never panics;
//! numerical failure is reported as a status or an error value.
//!
//! # Exact semantics
//!
//! Bit-exactness between builds (x86_64 and Cortex-M4F) rests on every build executing the
//! same sequence of IEEE-754 `f32` operations. Rust never contracts `a * b + c` into a fused
//! multiply-add, this crate never calls `mul_add`, and transcendental functions come from
//! `libm` (portable software implementations). Each expression below is evaluated exactly as
//! written, left to right, one rounding per operation. `d_y` is the `gyro-bias` output offset;
//! where a formula says "`+ d_y`" or "`− d_y`", that operation is performed only when the
//! model has a `gyro-bias` effect (otherwise the value is used as is).
//!
//! State: `x̂ ∈ R^N`, a delay line of the last `d` commands (`d` = dead time, 0 without the
//! effect), the actuator position `ũ_prev`, the heading `ψ̂` (deg). All start at zero. Steps 2
//! and 7 and the `ψ̂` term of step 8 apply only to a model with a heading effect (wind or
//! current), the only readers of `ψ`; otherwise `ψ̂` keeps its value.
//!
//! [`Predictor::update_with_heading`]`(u, y, psi)`:
//! 1. actuator: `δ = u(t−d)` (pop the delay line, push `u`; `δ = u` when `d = 0`);
//!    `ũ = Step::actuator(δ, ũ_prev)` of `yawcast_shared::kernel` (the angle limit, the dead
//!    band and the largest move per step, each optional, in that order and evaluated as
//!    documented there; the move per step is computed once when the model is loaded); then
//!    `ũ_prev = ũ`.
//! 2. heading: `ψ = psi` when given and finite, else `ψ̂`.
//! 3. `ŷ = x̂_1 + d_y`; `y_used = y` if `y` is finite, else `ŷ`; the rate the hull turns at
//!    `ρ = y_used − d_y` (`ρ = y_used` without a gyro offset).
//! 4. `v = Step::effective_input(ũ, ρ, ψ)` of `yawcast_shared::kernel`: `v = ũ`, then
//!    for each effect present, in library order, `v = v + β·φ` (bias, asymmetry, nonlinear
//!    damping, then wind and current from `libm::sincosf` of `r = ψ·(π/180)` and of `r + r`),
//!    one term at a time as documented there.
//! 5. `e = y − ŷ` if `y` is finite; otherwise there is no correction
//!    ([`UpdateStatus::SkippedCorrection`]) and `e = 0`.
//! 6. with `s = (…((a_1·x̂_1 + a_2·x̂_2) + a_3·x̂_3) …) + a_N·x̂_N` (the model is in the
//!    difference form of `yawcast_shared::model`):
//!    `x̂'_i = ((x̂_i + x̂_{i+1}) + b_i·v) + k_i·e` for `i < N`;
//!    `x̂'_N = ((x̂_N + s) + b_N·v) + k_N·e`.
//! 7. `ψ̂ = ψ + ts·ρ` (heading effect only).
//! 8. when `x̂'_1 + … + x̂'_N (+ ψ̂)` (summed left to right) is not finite — a component is
//!    NaN or infinite, or the sum leaves the `f32` range — the whole state is reset to zero
//!    and [`UpdateStatus::NonFiniteReset`] is returned.
//!
//! [`Predictor::predict_into`]`(out, future_u)` works on a copy of the state:
//! `out[0] = x̂_1 + d_y`; for `j = 1..H`, one step as above with `u = future_u[j−1]`,
//! `y_used = out[j−1]`, `ψ = ψ̂` of the copy and no correction term at all
//! (`x̂'_i = (x̂_i + x̂_{i+1}) + b_i·v`, `x̂'_N = (x̂_N + s) + b_N·v`), then `out[j] = x̂_1 + d_y`.
//! If any step of the copy goes non-finite the call fails and `out` must not be used.
//!
//! A model without effects runs a specialised path (one dot product and the neighbour sums,
//! no effect dispatch) that performs exactly the operations above.
#![no_std]
#![deny(missing_docs)]
// `v = v + β·φ` is written out so the code reads exactly like the documented evaluation order.
#![allow(clippy::assign_op_pattern)]

use yawcast_shared::kernel::Step;
use yawcast_shared::model::{ModelError, ModelSpec, MAX_DEAD_TIME, MAX_ORDER, MIN_ORDER};

/// Longest prediction horizon [`Predictor::predict_into`] accepts.
pub const MAX_HORIZON: usize = 64;

/// Length of the dead-time delay line (a power of two, so index masking cannot fail).
const DELAY_LEN: usize = MAX_DEAD_TIME as usize;
const _: () = assert!(DELAY_LEN.is_power_of_two());

/// What one [`Predictor::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum UpdateStatus {
    /// The measurement was used: innovation correction applied.
    Corrected,
    /// The measurement was missing or non-finite: time update only.
    SkippedCorrection,
    /// The new state was not finite; the predictor was reset to the zero state.
    NonFiniteReset,
}

/// Why a predictor call failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum PredictorError {
    /// The model's order is not the predictor's `N`.
    OrderMismatch {
        /// The predictor's order `N`.
        expected: usize,
        /// The model's order.
        found: u8,
    },
    /// The model does not validate.
    InvalidModel(ModelError),
    /// The horizon `out.len()` is not in `1..=MAX_HORIZON`.
    HorizonOutOfRange(usize),
    /// Fewer future commands than the horizon needs (`H − 1`).
    NotEnoughInputs {
        /// Commands needed.
        needed: usize,
        /// Commands given.
        got: usize,
    },
    /// The prediction went non-finite.
    NonFinite,
    /// A state given to [`Predictor::restore`] is not finite or not consistent with the model.
    InvalidState,
    /// The heading/track part of the model does not validate ([`track::Tracker::new`]).
    InvalidTrack(yawcast_shared::nav::TrackError),
}

impl core::fmt::Display for PredictorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            PredictorError::OrderMismatch { expected, found } => write!(
                f,
                "model order {found} does not match the predictor order {expected}"
            ),
            PredictorError::InvalidModel(e) => write!(f, "invalid model: {e}"),
            PredictorError::HorizonOutOfRange(h) => {
                write!(f, "horizon {h} is outside 1..={MAX_HORIZON}")
            }
            PredictorError::NotEnoughInputs { needed, got } => {
                write!(f, "prediction needs {needed} future commands, {got} given")
            }
            PredictorError::NonFinite => write!(f, "prediction became non-finite"),
            PredictorError::InvalidState => {
                write!(f, "state is non-finite or inconsistent with the model")
            }
            PredictorError::InvalidTrack(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for PredictorError {}

impl From<ModelError> for PredictorError {
    fn from(e: ModelError) -> Self {
        PredictorError::InvalidModel(e)
    }
}

/// The complete predictor state, for save and restore.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictorState<const N: usize> {
    /// State estimate x̂ after the last update (x̂(t+1|t)), in the model's difference
    /// coordinates: `x̂_1` is the prediction without `d_y`, `x̂_i` its `(i−1)`-th difference.
    pub x: [f32; N],
    /// Dead-time delay line, a ring of the last `d` commands; only `delay[..d]` is used.
    pub delay: [f32; MAX_DEAD_TIME as usize],
    /// Index of the oldest command in the ring (`< d`, 0 without dead time).
    pub delay_head: u8,
    /// Actuator position ũ_prev.
    pub u_prev: f32,
    /// Integrated heading ψ̂ in degrees.
    pub psi: f32,
}

impl<const N: usize> PredictorState<N> {
    /// The all-zero state.
    const ZERO: Self = Self {
        x: [0.0; N],
        delay: [0.0; DELAY_LEN],
        delay_head: 0,
        u_prev: 0.0,
        psi: 0.0,
    };
}

/// The f32 k-step yaw-rate predictor for a model of order `N` (4 by default).
///
/// See the [crate documentation](crate) for the exact arithmetic.
#[derive(Debug, Clone)]
pub struct Predictor<const N: usize = 4> {
    a: [f32; N],
    b: [f32; N],
    k: [f32; N],
    ts: f32,
    /// No effect at all: the specialised path.
    plain: bool,
    /// The effects, unpacked (`yawcast_shared::kernel`).
    fx: Step<f32>,
    /// Wind or current: the heading is tracked (steps 2 and 7).
    heading: bool,
    st: PredictorState<N>,
}

impl<const N: usize> Predictor<N> {
    /// Compile-time check of `N`: instantiating a predictor of an unsupported order fails to build.
    const ORDER_OK: () = assert!(
        N >= MIN_ORDER && N <= MAX_ORDER,
        "Predictor order N must be in MIN_ORDER..=MAX_ORDER"
    );

    /// Builds a predictor for `spec`, in the zero state.
    ///
    /// # Errors
    /// [`PredictorError::OrderMismatch`] when `spec.order != N`,
    /// [`PredictorError::InvalidModel`] when the model does not validate.
    ///
    /// ```
    /// use yawcast_firmware::{Predictor, PredictorError};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
    ///                        Units::default(), &[]).unwrap();
    /// let p = Predictor::<2>::new(&m).unwrap();
    /// assert_eq!(p.prediction(), 0.0);
    /// assert_eq!(Predictor::<4>::new(&m).unwrap_err(),
    ///            PredictorError::OrderMismatch { expected: 4, found: 2 });
    /// ```
    pub fn new(spec: &ModelSpec) -> Result<Self, PredictorError> {
        let () = Self::ORDER_OK;
        if usize::from(spec.order) != N {
            return Err(PredictorError::OrderMismatch {
                expected: N,
                found: spec.order,
            });
        }
        spec.validate()?;
        let mut p = Predictor {
            a: [0.0; N],
            b: [0.0; N],
            k: [0.0; N],
            ts: spec.ts,
            plain: spec.effects.is_empty(),
            fx: Step::new(&spec.effects, spec.ts),
            heading: false,
            st: PredictorState::ZERO,
        };
        p.a.copy_from_slice(&spec.a[..N]);
        p.b.copy_from_slice(&spec.b[..N]);
        p.k.copy_from_slice(&spec.k[..N]);
        p.heading = p.fx.heading();
        Ok(p)
    }

    /// One measurement update with command `u` and measured output `y` (NaN when missing),
    /// without a measured heading. Same as `update_with_heading(u, y, None)`.
    ///
    /// # Errors
    /// None: numerical failure resets the state and is reported as
    /// [`UpdateStatus::NonFiniteReset`].
    ///
    /// ```
    /// use yawcast_firmware::{Predictor, UpdateStatus};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// assert_eq!(p.update(1.0, 2.0), UpdateStatus::Corrected);
    /// // x̂ = ((0 + 0) + 0.5·1 + 0.5·2, (0 + 0) − 0.25·1 − 0.375·2) = (1.5, −1)
    /// assert_eq!(p.state().x, [1.5, -1.0]);
    /// assert_eq!(p.update(0.0, f32::NAN), UpdateStatus::SkippedCorrection);
    /// assert_eq!(p.update(f32::INFINITY, 0.0), UpdateStatus::NonFiniteReset);
    /// assert_eq!(p.state().x, [0.0, 0.0]);
    /// ```
    #[inline(never)]
    pub fn update(&mut self, u: f32, y: f32) -> UpdateStatus {
        self.update_inner(u, y, None)
    }

    /// One measurement update with command `u`, measured output `y` (NaN when missing) and,
    /// when logged, the measured heading `psi` in degrees.
    ///
    /// # Errors
    /// None: numerical failure resets the state and is reported as
    /// [`UpdateStatus::NonFiniteReset`].
    ///
    /// ```
    /// use yawcast_firmware::{Predictor, UpdateStatus};
    /// use yawcast_shared::model::{Effect, ModelSpec, Units};
    /// let m = ModelSpec::new(2, 0.5, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(),
    ///                        &[Effect::Current { beta_s: 1.0, beta_c: 0.0 }]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// p.update_with_heading(0.0, 2.0, Some(90.0));
    /// // ψ̂ = 90 + 0.5·2; v = 0 + 1·sin(90°) = 1
    /// assert_eq!(p.state().psi, 91.0);
    /// assert_eq!(p.state().x, [0.5 + 0.5 * 2.0, -0.25 - 0.375 * 2.0]);
    /// ```
    #[inline(never)]
    pub fn update_with_heading(&mut self, u: f32, y: f32, psi: Option<f32>) -> UpdateStatus {
        self.update_inner(u, y, psi)
    }

    #[inline(always)]
    fn update_inner(&mut self, u: f32, y: f32, psi: Option<f32>) -> UpdateStatus {
        if self.plain {
            self.update_plain(u, y)
        } else {
            self.update_general(u, y, psi)
        }
    }

    /// The effect-free update: one dot product and the neighbour sums (no heading: no effect
    /// reads it). A missing measurement takes the out-of-line path (same arithmetic with
    /// `e = 0`).
    #[inline(always)]
    fn update_plain(&mut self, u: f32, y: f32) -> UpdateStatus {
        if y.is_finite() {
            let e = y - self.st.x[0];
            self.plain_step(u, e, UpdateStatus::Corrected)
        } else {
            self.plain_skip(u)
        }
    }

    #[cold]
    #[inline(never)]
    fn plain_skip(&mut self, u: f32) -> UpdateStatus {
        self.plain_step(u, 0.0, UpdateStatus::SkippedCorrection)
    }

    #[inline(always)]
    fn plain_step(&mut self, u: f32, e: f32, ok: UpdateStatus) -> UpdateStatus {
        let x = self.st.x;
        let s = self.row_dot(&x);
        let mut nx = [0.0f32; N];
        for i in 0..N - 1 {
            nx[i] = x[i] + x[i + 1] + self.b[i] * u + self.k[i] * e;
        }
        nx[N - 1] = x[N - 1] + s + self.b[N - 1] * u + self.k[N - 1] * e;
        self.st.x = nx;
        self.st.u_prev = u;
        self.finish(&nx, None, ok)
    }

    #[inline(never)]
    fn update_general(&mut self, u: f32, y: f32, psi: Option<f32>) -> UpdateStatus {
        let finite = y.is_finite();
        let mut st = self.st;
        let yhat = self.output(&st);
        let (y_used, e) = if finite { (y, y - yhat) } else { (yhat, 0.0) };
        let heading = match psi {
            Some(p) if p.is_finite() && self.heading => p,
            _ => st.psi,
        };
        let ut = self.actuator(&mut st, u);
        let rate = self.minus_dy(y_used);
        let v = self.effective_input(ut, rate, heading);
        let x = st.x;
        let s = self.row_dot(&x);
        for i in 0..N - 1 {
            st.x[i] = x[i] + x[i + 1] + self.b[i] * v + self.k[i] * e;
        }
        st.x[N - 1] = x[N - 1] + s + self.b[N - 1] * v + self.k[N - 1] * e;
        let psi_new = if self.heading {
            st.psi = heading + self.ts * rate;
            Some(st.psi)
        } else {
            None
        };
        self.st = st;
        let ok = if finite {
            UpdateStatus::Corrected
        } else {
            UpdateStatus::SkippedCorrection
        };
        self.finish(&st.x, psi_new, ok)
    }

    /// `s = (…(a_1·x_1 + a_2·x_2) …) + a_N·x_N`, left to right (step 6).
    #[inline(always)]
    fn row_dot(&self, x: &[f32; N]) -> f32 {
        let mut s = self.a[0] * x[0];
        for i in 1..N {
            s = s + self.a[i] * x[i];
        }
        s
    }

    /// Step 8: the finiteness check of the new state (`psi`: the new ψ̂ of a model with a
    /// heading effect); `ok` is the status when it passes.
    #[inline(always)]
    fn finish(&mut self, x: &[f32; N], psi: Option<f32>, ok: UpdateStatus) -> UpdateStatus {
        let mut sum = x[0];
        for xi in &x[1..] {
            sum = sum + *xi;
        }
        if let Some(p) = psi {
            sum = sum + p;
        }
        if sum.is_finite() {
            ok
        } else {
            self.reset_non_finite()
        }
    }

    #[cold]
    #[inline(never)]
    fn reset_non_finite(&mut self) -> UpdateStatus {
        self.st = PredictorState::ZERO;
        UpdateStatus::NonFiniteReset
    }

    /// `x̂_1 + d_y` of a state (`x̂_1` without gyro bias).
    #[inline(always)]
    fn output(&self, st: &PredictorState<N>) -> f32 {
        match self.fx.dy {
            Some(dy) => st.x[0] + dy,
            None => st.x[0],
        }
    }

    /// `y − d_y` (`y` without gyro bias).
    #[inline(always)]
    fn minus_dy(&self, y: f32) -> f32 {
        match self.fx.dy {
            Some(dy) => y - dy,
            None => y,
        }
    }

    /// The actuator chain: the dead time here, the rest in the kernel. Advances its state.
    #[inline(always)]
    fn actuator(&self, st: &mut PredictorState<N>, u: f32) -> f32 {
        let delayed = if self.fx.dead > 0 {
            let h = usize::from(st.delay_head) % DELAY_LEN;
            let out = st.delay[h];
            st.delay[h] = u;
            let next = st.delay_head + 1;
            st.delay_head = if next >= self.fx.dead { 0 } else { next };
            out
        } else {
            u
        };
        let ut = self.fx.actuator(delayed, st.u_prev);
        st.u_prev = ut;
        ut
    }

    /// `v = ũ + Σ β φ`, accumulated one term at a time in library order; `rate` is the
    /// rate the hull turns at (the gyro's less its offset).
    #[inline(always)]
    fn effective_input(&self, ut: f32, rate: f32, psi: f32) -> f32 {
        self.fx.effective_input(ut, rate, psi)
    }

    /// Predicts `out.len()` = H outputs ŷ(t+1|t) … ŷ(t+H|t) from the current state, with
    /// future commands `future_u` = u(t+1) … u(t+H−1) (extra values are ignored).
    /// The predictor state is not changed.
    ///
    /// # Errors
    /// [`PredictorError::HorizonOutOfRange`] when H is 0 or above [`MAX_HORIZON`],
    /// [`PredictorError::NotEnoughInputs`] when `future_u` has fewer than H − 1 values,
    /// [`PredictorError::NonFinite`] when the prediction overflows or a command is not finite.
    ///
    /// ```
    /// use yawcast_firmware::{Predictor, PredictorError};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// p.update(1.0, 2.0); // x̂ = (1.5, −1)
    /// let mut out = [0.0f32; 3];
    /// p.predict_into(&mut out, &[2.0, 0.0])?;
    /// // s = −0.75·1.5 − 1.5·(−1) = 0.375; x̂' = ((1.5 − 1) + 0.5·2, (−1 + 0.375) − 0.25·2)
    /// // = (1.5, −1.125); then x̂'_1 = 1.5 − 1.125 = 0.375
    /// assert_eq!(out, [1.5, 1.5, 0.375]);
    /// assert_eq!(p.predict_into(&mut out, &[2.0]),
    ///            Err(PredictorError::NotEnoughInputs { needed: 2, got: 1 }));
    /// # Ok::<(), PredictorError>(())
    /// ```
    #[inline(never)]
    pub fn predict_into(&self, out: &mut [f32], future_u: &[f32]) -> Result<(), PredictorError> {
        let h = out.len();
        if h == 0 || h > MAX_HORIZON {
            return Err(PredictorError::HorizonOutOfRange(h));
        }
        if future_u.len() < h - 1 {
            return Err(PredictorError::NotEnoughInputs {
                needed: h - 1,
                got: future_u.len(),
            });
        }
        let ok = if self.plain {
            self.predict_plain(out, future_u)
        } else {
            self.predict_general(out, future_u)
        };
        if ok {
            Ok(())
        } else {
            Err(PredictorError::NonFinite)
        }
    }

    /// Effect-free prediction. A non-finite value, once in x̂, stays in x̂_N for every later
    /// step (x̂_N itself, every `a_i·x̂_i` and `b_N·v` enter it, and `0·∞` is NaN), so checking
    /// x̂_N at the end covers every step.
    #[inline(always)]
    fn predict_plain(&self, out: &mut [f32], future_u: &[f32]) -> bool {
        let mut x = self.st.x;
        let (first, rest) = match out.split_first_mut() {
            Some(s) => s,
            None => return false,
        };
        *first = x[0];
        for (o, &u) in rest.iter_mut().zip(future_u) {
            let s = self.row_dot(&x);
            for i in 0..N - 1 {
                x[i] = x[i] + x[i + 1] + self.b[i] * u;
            }
            x[N - 1] = x[N - 1] + s + self.b[N - 1] * u;
            *o = x[0];
        }
        x[N - 1].is_finite()
    }

    #[inline(never)]
    fn predict_general(&self, out: &mut [f32], future_u: &[f32]) -> bool {
        let mut st = self.st;
        let mut prev = self.output(&st);
        let mut finite = prev.is_finite();
        let (first, rest) = match out.split_first_mut() {
            Some(s) => s,
            None => return false,
        };
        *first = prev;
        for (o, &u) in rest.iter_mut().zip(future_u) {
            let y_used = prev;
            let heading = st.psi;
            let ut = self.actuator(&mut st, u);
            let rate = self.minus_dy(y_used);
            let v = self.effective_input(ut, rate, heading);
            let x = st.x;
            let s = self.row_dot(&x);
            for i in 0..N - 1 {
                st.x[i] = x[i] + x[i + 1] + self.b[i] * v;
            }
            st.x[N - 1] = x[N - 1] + s + self.b[N - 1] * v;
            if self.heading {
                st.psi = heading + self.ts * rate;
            }
            prev = self.output(&st);
            *o = prev;
            // outputs can overflow through d_y alone, so each one is checked here
            finite &= prev.is_finite();
        }
        finite && st.x[N - 1].is_finite() && st.psi.is_finite()
    }

    /// The one-step prediction ŷ(t+1|t) = x̂_1 + d_y of the current state.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_firmware::Predictor;
    /// use yawcast_shared::model::{Effect, ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[Effect::GyroBias { d_y: 0.25 }]).unwrap();
    /// let p = Predictor::<2>::new(&m).unwrap();
    /// assert_eq!(p.prediction(), 0.25);
    /// ```
    pub fn prediction(&self) -> f32 {
        self.output(&self.st)
    }

    /// A copy of the full state: x̂, delay line, actuator position, heading.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_firmware::Predictor;
    /// use yawcast_shared::model::{Effect, ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[Effect::DeadTime { samples: 2 }]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// p.update(3.0, 0.0);
    /// let s = p.state();
    /// assert_eq!(s.delay[0], 3.0);
    /// assert_eq!(s.delay_head, 1);
    /// assert_eq!(s.u_prev, 0.0); // u(t−2) = 0
    /// ```
    pub fn state(&self) -> PredictorState<N> {
        self.st
    }

    /// Replaces the state with a saved one (from [`Predictor::state`]).
    ///
    /// # Errors
    /// [`PredictorError::InvalidState`] when a value used by this model is not finite or
    /// `delay_head` is not below the dead time (0 without dead time); the state is then
    /// left unchanged.
    ///
    /// ```
    /// use yawcast_firmware::{Predictor, PredictorError};
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// p.update(1.0, 2.0);
    /// let saved = p.state();
    /// p.update(5.0, -1.0);
    /// p.restore(saved)?;
    /// assert_eq!(p.state().x, [1.5, -1.0]);
    /// let mut bad = saved;
    /// bad.x[1] = f32::NAN;
    /// assert_eq!(p.restore(bad), Err(PredictorError::InvalidState));
    /// # Ok::<(), PredictorError>(())
    /// ```
    pub fn restore(&mut self, state: PredictorState<N>) -> Result<(), PredictorError> {
        let d = usize::from(self.fx.dead);
        let head_ok = if d == 0 {
            state.delay_head == 0
        } else {
            state.delay_head < self.fx.dead
        };
        let finite = state.x.iter().all(|v| v.is_finite())
            && state.delay.iter().take(d).all(|v| v.is_finite())
            && state.u_prev.is_finite()
            && state.psi.is_finite();
        if head_ok && finite {
            self.st = state;
            Ok(())
        } else {
            Err(PredictorError::InvalidState)
        }
    }

    /// Resets the state to zero (x̂, delay line, actuator position, heading).
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_firmware::Predictor;
    /// use yawcast_shared::model::{ModelSpec, Units};
    /// let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
    ///                        Units::default(), &[]).unwrap();
    /// let mut p = Predictor::<2>::new(&m).unwrap();
    /// p.update(1.0, 2.0);
    /// p.reset();
    /// assert_eq!(p.state().x, [0.0, 0.0]);
    /// assert_eq!(p.state().psi, 0.0);
    /// ```
    pub fn reset(&mut self) {
        self.st = PredictorState::ZERO;
    }
}

pub mod track;

#[cfg(test)]
mod tests;
