//! The step semantics of every effect, written once: the actuator chain and the effect
//! regressors, generic over the real type — `f32` in the firmware, `f64` on the host.
//!
//! [`Step::new`] is the one place an effect's parameters become the predictor's (one match
//! arm per effect); [`Step::actuator`] and [`Step::effective_input`] are the step's effect
//! parts, in the firmware's documented evaluation order (each operation rounded once, no
//! fused multiply-add, sines from `libm`). The firmware's bit-exactness is the `f32`
//! instance of these functions; the host's f64 predictor is the `f64` instance, so the two
//! cannot drift apart.

use core::ops::{Add, Mul, Neg, Sub};

use crate::model::{Effect, MAX_DEAD_TIME};

/// The arithmetic the kernel needs: IEEE-754 `f32` or `f64`, one rounding per operation.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// π/180, rounded once to the type.
    const DEG2RAD: Self;
    /// `|x|` (`libm`).
    fn abs(self) -> Self;
    /// `(sin x, cos x)` (`libm`).
    fn sin_cos(self) -> (Self, Self);
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    const DEG2RAD: f32 = core::f32::consts::PI / 180.0;
    #[inline(always)]
    fn abs(self) -> f32 {
        libm::fabsf(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (f32, f32) {
        libm::sincosf(self)
    }
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    const DEG2RAD: f64 = core::f64::consts::PI / 180.0;
    #[inline(always)]
    fn abs(self) -> f64 {
        libm::fabs(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (f64, f64) {
        libm::sincos(self)
    }
}

/// `lo` if `x < lo`, `hi` if `x > hi`, else `x` (NaN passes through). Never panics.
#[inline(always)]
pub fn clamp<R: Real>(x: R, lo: R, hi: R) -> R {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// A model's effects unpacked for stepping: `None` (or 0) where the model has no such
/// effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step<R> {
    /// Dead time (samples), `0..=MAX_DEAD_TIME`.
    pub dead: u8,
    /// Angle limit.
    pub limit: Option<R>,
    /// Dead band width.
    pub band: Option<R>,
    /// Largest actuator move per step (rate · ts).
    pub rate_step: Option<R>,
    /// Output offset `d_y`.
    pub dy: Option<R>,
    /// Constant regressor gain.
    pub bias: Option<R>,
    /// Gain on `max(ũ, 0)`.
    pub asym: Option<R>,
    /// Damping gain, cubic.
    pub damp: Option<(R, bool)>,
    /// Wind gains of `sin 2ψ, cos 2ψ, sin ψ, cos ψ`.
    pub wind: Option<[R; 4]>,
    /// Current gains of `sin ψ, cos ψ`.
    pub current: Option<[R; 2]>,
}

impl<R: Real> Step<R> {
    /// The step of `effects` at sample time `ts` (a later effect of a kind replaces an
    /// earlier one; a dead time above [`MAX_DEAD_TIME`] is capped).
    ///
    /// ```
    /// use yawcast_shared::{kernel::Step, model::Effect};
    /// let s = Step::new(&[Effect::Saturation { limit: 5.0f64 }, Effect::DeadTime { samples: 2 }], 0.5);
    /// assert_eq!((s.limit, s.dead, s.rate_step), (Some(5.0), 2, None));
    /// assert!(!s.heading());
    /// ```
    pub fn new(effects: &[Effect<R>], ts: R) -> Step<R> {
        let mut s = Step {
            dead: 0,
            limit: None,
            band: None,
            rate_step: None,
            dy: None,
            bias: None,
            asym: None,
            damp: None,
            wind: None,
            current: None,
        };
        for e in effects {
            match *e {
                Effect::Bias { beta } => s.bias = Some(beta),
                Effect::GyroBias { d_y } => s.dy = Some(d_y),
                Effect::DeadTime { samples } => s.dead = samples.min(MAX_DEAD_TIME),
                Effect::RateLimit { rate } => s.rate_step = Some(rate * ts),
                Effect::Saturation { limit } => s.limit = Some(limit),
                Effect::Asymmetry { beta } => s.asym = Some(beta),
                Effect::NonlinearDamping { beta, cubic } => s.damp = Some((beta, cubic)),
                Effect::Wind {
                    beta_s2,
                    beta_c2,
                    beta_s1,
                    beta_c1,
                } => s.wind = Some([beta_s2, beta_c2, beta_s1, beta_c1]),
                Effect::Current { beta_s, beta_c } => s.current = Some([beta_s, beta_c]),
                Effect::DeadBand { width } => s.band = Some(width),
            }
        }
        s
    }

    /// A heading effect (wind or current) is present: `ψ` is read and tracked.
    #[inline(always)]
    pub fn heading(&self) -> bool {
        self.wind.is_some() || self.current.is_some()
    }

    /// The actuator after the dead time: the delayed command `delayed` through saturation,
    /// dead band and rate limit, from the actuator position `u_prev`; returns `ũ`.
    ///
    /// `τ = clamp(δ, −limit, limit)`; `τ = clamp(ũ_prev, τ − b, τ + b)` (`τ − b`, `τ + b`
    /// each rounded first); `ũ = ũ_prev + clamp(τ − ũ_prev, −s, s)`.
    ///
    /// ```
    /// use yawcast_shared::{kernel::Step, model::Effect};
    /// let s = Step::new(&[Effect::Saturation { limit: 5.0f32 }, Effect::DeadBand { width: 1.0 }], 1.0);
    /// assert_eq!(s.actuator(9.0, 0.0), 4.0);
    /// assert_eq!(s.actuator(0.5, 0.0), 0.0);
    /// ```
    #[inline(always)]
    pub fn actuator(&self, delayed: R, u_prev: R) -> R {
        let target = match self.limit {
            Some(l) => clamp(delayed, -l, l),
            None => delayed,
        };
        let target = match self.band {
            Some(b) => clamp(u_prev, target - b, target + b),
            None => target,
        };
        match self.rate_step {
            Some(s) => u_prev + clamp(target - u_prev, -s, s),
            None => target,
        }
    }

    /// `v = ũ + Σ β φ`, accumulated one term at a time in library order: bias, asymmetry
    /// (`φ = ũ` if `ũ > 0` else `+0`), damping (`ρ|ρ|` or `(ρ·ρ)·ρ` of `rate` = ρ, the
    /// rate the hull turns at: the measured yaw rate less the gyro's offset `d_y`, so that
    /// an offset gyro does not move the hull's damping), then with
    /// `r = ψ·(π/180)`, `(sin r, cos r)` and `(sin 2r, cos 2r) = sin_cos(r + r)` the wind's
    /// four terms and the current's two.
    ///
    /// ```
    /// use yawcast_shared::{kernel::Step, model::Effect};
    /// let s = Step::new(&[Effect::Bias { beta: 0.5f64 }, Effect::Asymmetry { beta: 0.25 }], 1.0);
    /// assert_eq!(s.effective_input(2.0, 0.0, 0.0), 3.0);
    /// assert_eq!(s.effective_input(-2.0, 0.0, 0.0), -1.5);
    /// ```
    #[inline(always)]
    pub fn effective_input(&self, ut: R, rate: R, psi: R) -> R {
        let mut v = ut;
        if let Some(beta) = self.bias {
            v = v + beta;
        }
        if let Some(beta) = self.asym {
            let phi = if ut > R::ZERO { ut } else { R::ZERO };
            v = v + beta * phi;
        }
        if let Some((beta, cubic)) = self.damp {
            let phi = if cubic {
                rate * rate * rate
            } else {
                rate * rate.abs()
            };
            v = v + beta * phi;
        }
        if self.heading() {
            let r = psi * R::DEG2RAD;
            let (s1, c1) = r.sin_cos();
            if let Some(w) = self.wind {
                let (s2, c2) = (r + r).sin_cos();
                v = v + w[0] * s2;
                v = v + w[1] * c2;
                v = v + w[2] * s1;
                v = v + w[3] * c1;
            }
            if let Some(c) = self.current {
                v = v + c[0] * s1;
                v = v + c[1] * c1;
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::EffectKind;

    /// One effect of every kind, as the f32 and f64 instances see it.
    fn every<R: Real + From<f32>>() -> [Effect<R>; EffectKind::ALL.len()] {
        let r = |x: f32| R::from(x);
        [
            Effect::Bias { beta: r(0.5) },
            Effect::GyroBias { d_y: r(0.1) },
            Effect::DeadTime { samples: 3 },
            Effect::RateLimit { rate: r(2.0) },
            Effect::Saturation { limit: r(5.0) },
            Effect::Asymmetry { beta: r(0.25) },
            Effect::NonlinearDamping {
                beta: r(-0.125),
                cubic: false,
            },
            Effect::Wind {
                beta_s2: r(0.1),
                beta_c2: r(0.2),
                beta_s1: r(0.3),
                beta_c1: r(0.4),
            },
            Effect::Current {
                beta_s: r(0.5),
                beta_c: r(0.6),
            },
            Effect::DeadBand { width: r(1.0) },
        ]
    }

    #[test]
    fn every_kind_is_unpacked_in_library_order() {
        let e = every::<f32>();
        for (k, e) in EffectKind::ALL.iter().zip(&e) {
            assert_eq!(e.kind(), *k);
        }
        let s = Step::new(&e, 0.5f32);
        assert_eq!(s.dead, 3);
        assert_eq!(s.rate_step, Some(1.0));
        assert_eq!((s.limit, s.band, s.dy), (Some(5.0), Some(1.0), Some(0.1)));
        assert_eq!(
            (s.bias, s.asym, s.damp),
            (Some(0.5), Some(0.25), Some((-0.125, false)))
        );
        assert_eq!(s.wind, Some([0.1, 0.2, 0.3, 0.4]));
        assert_eq!(s.current, Some([0.5, 0.6]));
        assert!(s.heading());
        let capped = Step::<f32>::new(&[Effect::DeadTime { samples: 200 }], 1.0);
        assert_eq!(capped.dead, MAX_DEAD_TIME);
    }

    /// The actuator chain step by step: saturation at 5, a dead band of 1, 1 per step.
    #[test]
    fn actuator_chain() {
        let s = Step::new(&every::<f64>(), 0.5);
        let mut u = 0.0;
        let mut seen = [0.0; 7];
        for x in seen.iter_mut() {
            u = s.actuator(9.0, u);
            *x = u;
        }
        assert_eq!(seen, [1.0, 2.0, 3.0, 4.0, 4.0, 4.0, 4.0]);
        // within the band: no move; NaN passes through a limit
        assert_eq!(s.actuator(4.5, 4.0), 4.0);
        let sat = Step::new(&[Effect::Saturation { limit: 5.0f64 }], 1.0);
        assert!(sat.actuator(f64::NAN, 0.0).is_nan());
    }

    /// The firmware's sequences at ts = 0.5: a gear of 2/s (1 per step) after a limit of
    /// 2.5; a dead band of 1.5 before the same gear.
    #[test]
    fn gear_sequences() {
        let run = |effects: &[Effect<f32>], us: &[f32]| -> std::vec::Vec<f32> {
            let s = Step::new(effects, 0.5);
            let mut u = 0.0;
            us.iter()
                .map(|&c| {
                    u = s.actuator(c, u);
                    u
                })
                .collect()
        };
        let gear = Effect::RateLimit { rate: 2.0 };
        assert_eq!(
            run(
                &[gear, Effect::Saturation { limit: 2.5 }],
                &[10.0, 10.0, 10.0, 10.0, -0.5, -10.0]
            ),
            [1.0, 2.0, 2.5, 2.5, 1.5, 0.5]
        );
        assert_eq!(
            run(
                &[Effect::DeadBand { width: 1.5 }, gear],
                &[5.0, 5.0, 5.0, 5.0, 0.0]
            ),
            [1.0, 2.0, 3.0, 3.5, 2.5]
        );
    }

    /// f32 and f64 compute the same terms; the heading terms by hand.
    #[test]
    fn effective_input_by_hand() {
        let s = Step::new(&every::<f64>(), 1.0);
        let (ut, y, psi) = (2.0, 1.5, 30.0);
        let r = psi * core::f64::consts::PI / 180.0;
        let mut v = ut + 0.5 + 0.25 * 2.0 - 0.125 * 1.5 * 1.5;
        let w = [0.1f32, 0.2, 0.3, 0.4].map(f64::from);
        let c = [0.5f32, 0.6].map(f64::from);
        v += w[0] * libm::sin(2.0 * r) + w[1] * libm::cos(2.0 * r);
        v += w[2] * libm::sin(r) + w[3] * libm::cos(r);
        v += c[0] * libm::sin(r) + c[1] * libm::cos(r);
        let got = s.effective_input(ut, y, psi);
        assert!((got - v).abs() < 1e-12, "{got} {v}");
        let s32 = Step::new(&every::<f32>(), 1.0);
        let got32 = s32.effective_input(2.0f32, 1.5, 30.0);
        assert!((f64::from(got32) - v).abs() < 1e-5, "{got32} {v}");
        // asymmetry reads only a positive ũ, as +0
        let a = Step::new(&[Effect::Asymmetry { beta: 2.0f32 }], 1.0);
        assert_eq!(
            a.effective_input(-1.0, 0.0, 0.0).to_bits(),
            (-1.0f32).to_bits()
        );
    }
}
