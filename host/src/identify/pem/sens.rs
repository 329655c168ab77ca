//! The one-step predictor and its exact parameter sensitivities.
//!
//! The forward pass is [`crate::identify::predict::Stepper::step`] itself; alongside it runs the
//! derivative of every quantity of that step with respect to each estimated number (θ, the
//! effect gains and x̂(0)), so the Jacobian is the exact derivative of what the predictor
//! computes — including missing measurements (`y_used = ŷ`), effects that use `y` and an
//! integrated heading.

use crate::effects::Regressor;
use crate::identify::model::Model;
use crate::identify::predict::{Stepper, MAX_N};
use crate::io::data::Record;

/// Layout of the estimated vector: θ = (a, b, k) then the effect gains in
/// [`Model::effect_gains`] order; the x̂(0) columns follow in the Jacobian.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    /// Order.
    pub n: usize,
    /// Number of estimated parameters (3n + gains).
    pub p: usize,
    /// Kind of each gain column (index 3n + j).
    pub gains: Vec<Regressor>,
    /// Column of d_y, if estimated.
    pub dy: Option<usize>,
    /// Heading effects present (ψ̂ integrated when not measured).
    pub heading: bool,
    /// Damping is cubic.
    pub cubic: bool,
}

impl Layout {
    /// The layout of `model`'s structure.
    pub fn new(model: &Model) -> Layout {
        let n = model.n;
        let mut gains = Vec::new();
        let mut cubic = false;
        let mut heading = false;
        for e in &model.effects {
            gains.extend(e.def().gains.iter().map(|(_, r)| *r));
            cubic |= e.cubic();
            heading |= e.kind().needs_heading();
        }
        let dy = gains
            .iter()
            .position(|g| *g == Regressor::Offset)
            .map(|j| 3 * n + j);
        Layout {
            n,
            p: 3 * n + gains.len(),
            gains,
            dy,
            heading,
            cubic,
        }
    }

    /// Columns of the Jacobian: parameters then x̂(0).
    pub fn q(&self) -> usize {
        self.p + self.n
    }
}

/// The full estimated vector of `model` (θ then effect gains).
pub(crate) fn params_of(model: &Model) -> Vec<f64> {
    let mut v = model.theta();
    v.extend(model.effect_gains());
    v
}

/// `template` with its parameters replaced by `params` (θ then effect gains).
pub(crate) fn with_params(template: &Model, params: &[f64]) -> Model {
    let mut m = template.clone();
    let t = 3 * m.n;
    m.set_theta(&params[..t]);
    m.set_effect_gains(&params[t..]);
    m
}

/// Receives, for each sample with a measured y, the one-step error ε = y − ŷ and the row
/// ∂ŷ/∂(θ, x̂(0)); a row shorter than the layout's `q` has zeros in its missing entries.
pub(crate) trait Sink {
    /// One sample.
    fn sample(&mut self, e: f64, row: &[f64]);
}

/// Normal-equation accumulator: `H = Σ ψψᵀ`, `g = Σ ψ ε`, `Σ ε²`.
#[derive(Debug, Clone)]
pub(crate) struct Accum {
    /// Columns.
    pub q: usize,
    /// H, q×q row-major (upper triangle filled during accumulation, then mirrored).
    pub h: Vec<f64>,
    /// g.
    pub g: Vec<f64>,
    /// Σ ε².
    pub sse: f64,
    /// Samples used.
    pub count: usize,
}

impl Accum {
    /// A zero accumulator with `q` columns.
    pub fn new(q: usize) -> Accum {
        Accum {
            q,
            h: vec![0.0; q * q],
            g: vec![0.0; q],
            sse: 0.0,
            count: 0,
        }
    }

    /// Mirrors the upper triangle into the lower.
    pub fn finish(&mut self) {
        let q = self.q;
        for i in 0..q {
            for j in 0..i {
                self.h[i * q + j] = self.h[j * q + i];
            }
        }
    }
}

impl Sink for Accum {
    #[inline]
    fn sample(&mut self, e: f64, row: &[f64]) {
        let q = self.q;
        let len = row.len().min(q);
        self.sse += e * e;
        self.count += 1;
        for i in 0..len {
            let ri = row[i];
            if ri == 0.0 {
                continue;
            }
            self.g[i] += ri * e;
            // indexed, not zipped: the hottest loop of identification, and slices' `zip`
            // is not always inlined across codegen units (the `ci` profile's tests)
            let h = &mut self.h[i * q + i..i * q + len];
            let r = &row[i..i + h.len()];
            for k in 0..h.len() {
                h[k] += ri * r[k];
            }
        }
    }
}

/// Only Σ ε² and the count.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SseOnly {
    /// Σ ε².
    pub sse: f64,
    /// Samples used.
    pub count: usize,
}

fn psi_at(rec: &Record, t: usize) -> Option<f64> {
    rec.psi.as_ref().map(|p| p[t])
}

/// Σ ε² of the one-step predictor of `model` on `rec` from x̂(0) = `x0` (samples with a
/// measured y). Non-finite predictions give an infinite sum.
pub(crate) fn sse(model: &Model, rec: &Record, x0: &[f64]) -> SseOnly {
    let s = Stepper::new(model);
    let mut st = s.initial(x0, psi_at(rec, 0).unwrap_or(0.0));
    let mut out = SseOnly::default();
    for t in 0..rec.len() {
        let o = s.step(&mut st, rec.u[t], rec.y[t], psi_at(rec, t));
        if rec.y[t].is_finite() {
            let e = rec.y[t] - o.yhat;
            out.sse += e * e;
            out.count += 1;
        }
    }
    if !out.sse.is_finite() {
        out.sse = f64::INFINITY;
    }
    out
}

/// Size below which the x̂(0) sensitivities (which start at 1) are dropped.
const X0_CUTOFF: f64 = 1e-30;

/// Runs the one-step predictor of `model` (structure `lay`) on `rec` from x̂(0) = `x0` and
/// feeds every measured sample's error and sensitivity row to `sink`.
pub(crate) fn pass<S: Sink>(model: &Model, lay: &Layout, rec: &Record, x0: &[f64], sink: &mut S) {
    // One copy per order, so that the loops over the state have constant length.
    match lay.n {
        2 => pass_n::<2, S>(model, lay, rec, x0, sink),
        3 => pass_n::<3, S>(model, lay, rec, x0, sink),
        4 => pass_n::<4, S>(model, lay, rec, x0, sink),
        5 => pass_n::<5, S>(model, lay, rec, x0, sink),
        6 => pass_n::<6, S>(model, lay, rec, x0, sink),
        7 => pass_n::<7, S>(model, lay, rec, x0, sink),
        _ => pass_n::<MAX_N, S>(model, lay, rec, x0, sink),
    }
}

/// Long: the forward pass and its exact sensitivities must mirror the predictor step line by
/// line; one body keeps the two in view together.
fn pass_n<const N: usize, S: Sink>(
    model: &Model,
    lay: &Layout,
    rec: &Record,
    x0: &[f64],
    sink: &mut S,
) {
    let n = N;
    let p = lay.p;
    let q = lay.q();
    let nt = 3 * n;
    let stepper = Stepper::new(model);
    let arr = |v: &[f64]| {
        let mut o = [0.0f64; N];
        o.copy_from_slice(&v[..N]);
        o
    };
    let (a, b, k) = (arr(&model.a), arr(&model.b), arr(&model.k));
    let ts = model.ts;
    let gains = model.effect_gains();
    // β of damping and of the heading regressors, for the y and ψ partials of v.
    let mut damp = 0.0;
    let mut hb = [0.0f64; 4]; // of sin 2ψ, cos 2ψ, sin ψ, cos ψ (wind and current summed)
    for (j, g) in lay.gains.iter().enumerate() {
        match g {
            Regressor::Damping => damp = gains[j],
            Regressor::Sin2 => hb[0] += gains[j],
            Regressor::Cos2 => hb[1] += gains[j],
            Regressor::Sin1 => hb[2] += gains[j],
            Regressor::Cos1 => hb[3] += gains[j],
            Regressor::One | Regressor::Offset | Regressor::Starboard => {}
        }
    }
    let dy_col = lay.dy.unwrap_or(usize::MAX);
    let mut st = stepper.initial(x0, psi_at(rec, 0).unwrap_or(0.0));
    // Sensitivities of x̂ (and of ψ̂) to each column.
    let mut sx = vec![[0.0f64; N]; q];
    for i in 0..n {
        sx[p + i][i] = 1.0;
    }
    let mut spsi = vec![0.0f64; q];
    let mut row = vec![0.0f64; q];
    let mut active = q;
    let mut phi = vec![0.0f64; lay.gains.len()];
    for t in 0..rec.len() {
        let x = st.x;
        let psi_prev = st.psi;
        let y = rec.y[t];
        let psi_m = psi_at(rec, t);
        let o = stepper.step(&mut st, rec.u[t], y, psi_m);
        let yfin = y.is_finite();
        let (psi_meas, psi) = match psi_m {
            Some(v) if v.is_finite() => (true, v),
            _ => (false, psi_prev),
        };
        let (y_used, e) = if yfin { (y, y - o.yhat) } else { (o.yhat, 0.0) };
        // the hull turns at the rate the gyro reads less its offset
        let z = y_used - stepper.d_y();
        // Regressors and partials of v = ũ + Σβφ.
        let (mut s1, mut c1, mut s2, mut c2) = (0.0, 0.0, 0.0, 0.0);
        if lay.heading {
            let r = psi.to_radians();
            (s1, c1) = r.sin_cos();
            (s2, c2) = (2.0 * r).sin_cos();
        }
        for (j, g) in lay.gains.iter().enumerate() {
            phi[j] = match g {
                Regressor::One => 1.0,
                Regressor::Offset => 0.0,
                Regressor::Starboard => o.u_eff.max(0.0),
                Regressor::Damping => {
                    if lay.cubic {
                        z * z * z
                    } else {
                        z * z.abs()
                    }
                }
                Regressor::Sin2 => s2,
                Regressor::Cos2 => c2,
                Regressor::Sin1 => s1,
                Regressor::Cos1 => c1,
            };
        }
        let dv_dz = if damp == 0.0 {
            0.0
        } else if lay.cubic {
            3.0 * damp * z * z
        } else {
            2.0 * damp * z.abs()
        };
        let dv_dpsi = if lay.heading && !psi_meas {
            let d = std::f64::consts::PI / 180.0;
            d * (2.0 * hb[0] * c2 - 2.0 * hb[1] * s2 + hb[2] * c1 - hb[3] * s1)
        } else {
            0.0
        };
        for j in 0..active {
            let sj = sx[j];
            let ddy = if j == dy_col { 1.0 } else { 0.0 };
            let dyhat = sj[0] + ddy;
            row[j] = dyhat;
            let (dyu, de) = if yfin { (0.0, -dyhat) } else { (dyhat, 0.0) };
            let dpsi = if lay.heading && !psi_meas {
                spsi[j]
            } else {
                0.0
            };
            let mut dv = dv_dz * (dyu - ddy) + dv_dpsi * dpsi;
            if j >= nt && j < p {
                dv += phi[j - nt];
            }
            let mut last = 0.0;
            for i in 0..n {
                last += a[i] * sj[i];
            }
            let out = &mut sx[j];
            for i in 0..n - 1 {
                out[i] = sj[i + 1] + b[i] * dv + k[i] * de;
            }
            out[n - 1] = last + b[n - 1] * dv + k[n - 1] * de;
            if j < n {
                out[n - 1] += x[j];
            } else if j < 2 * n {
                out[j - n] += o.v;
            } else if j < nt {
                out[j - 2 * n] += e;
            }
            if lay.heading {
                spsi[j] = dpsi + ts * (dyu - ddy);
            }
        }
        if yfin {
            sink.sample(e, &row[..active]);
        }
        // The x̂(0) sensitivities decay with A − KC; once negligible they are exactly zero
        // from then on and need no more work.
        if active == q && t % 8 == 7 {
            let mut m = 0.0f64;
            for j in p..q {
                m = sx[j][..n].iter().fold(m, |m, v| m.max(v.abs()));
                m = m.max(spsi[j].abs());
            }
            if m < X0_CUTOFF {
                active = p;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::identify::model::Effect;
    use crate::identify::predict;

    /// Collects rows for Jacobian checks.
    #[derive(Default)]
    pub(crate) struct Rows {
        pub e: Vec<f64>,
        pub rows: Vec<Vec<f64>>,
    }
    impl Sink for Rows {
        fn sample(&mut self, e: f64, row: &[f64]) {
            self.e.push(e);
            self.rows.push(row.to_vec());
        }
    }

    pub(crate) fn base() -> Model {
        Model::new(
            1.0,
            vec![-0.2, 0.3, -0.1, 0.6],
            vec![0.01, 0.03, 0.05, 0.02],
            vec![0.8, 0.5, 0.3, 0.2],
        )
        .unwrap()
    }

    pub(crate) fn record(n: usize, heading: bool) -> Record {
        let mut s = 11u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut u = Vec::with_capacity(n);
        let mut level = 10.0;
        for i in 0..n {
            if i % 7 == 0 && rnd() > 0.0 {
                level = -level;
            }
            u.push(level + rnd());
        }
        let y: Vec<f64> = (0..n)
            .map(|i| 0.8 * (i as f64 * 0.07).sin() + 0.3 * rnd())
            .collect();
        let mut r = Record::from_uy("t", 1.0, u, y);
        if heading {
            r.psi = Some((0..n).map(|i| 40.0 + 2.5 * i as f64).collect());
        }
        r
    }

    /// Max relative difference between the analytic Jacobian and central differences of
    /// `predict::one_step` (the reference predictor).
    pub(crate) fn jacobian_error(model: &Model, rec: &Record, x0: &[f64]) -> f64 {
        let lay = Layout::new(model);
        let mut rows = Rows::default();
        pass(model, &lay, rec, x0, &mut rows);
        // the forward values are those of the reference predictor
        let yhat = predict::one_step(model, rec, x0);
        let idx: Vec<usize> = (0..rec.len()).filter(|t| rec.y[*t].is_finite()).collect();
        for (r, t) in idx.iter().enumerate() {
            assert_eq!(rows.e[r], rec.y[*t] - yhat[*t]);
        }
        let params = params_of(model);
        let mut worst: f64 = 0.0;
        for j in 0..lay.q() {
            let eval = |d: f64| {
                let mut pp = params.clone();
                let mut xx = x0.to_vec();
                let (m, x) = if j < lay.p {
                    pp[j] += d;
                    (with_params(model, &pp), xx)
                } else {
                    xx[j - lay.p] += d;
                    (model.clone(), xx)
                };
                predict::one_step(&m, rec, &x)
            };
            let base = if j < lay.p { params[j] } else { x0[j - lay.p] };
            let h = 1e-5 * base.abs().max(1e-2);
            let (yp, ym) = (eval(h), eval(-h));
            let at = |r: usize| rows.rows[r].get(j).copied().unwrap_or(0.0);
            let scale = (0..rows.rows.len())
                .map(|r| at(r).abs())
                .fold(1e-3, f64::max);
            for (r, t) in idx.iter().enumerate() {
                let fd = (yp[*t] - ym[*t]) / (2.0 * h);
                let err = (fd - at(r)).abs() / scale;
                worst = worst.max(err);
            }
        }
        worst
    }

    #[test]
    fn jacobian_equals_central_differences_plain() {
        let m = base();
        let r = record(300, false);
        let err = jacobian_error(&m, &r, &[0.3, -0.1, 0.2, 0.05]);
        assert!(err < 1e-6, "relative error {err}");
    }

    #[test]
    fn jacobian_equals_central_differences_with_effects() {
        let m = base()
            .with_effect(Effect::Bias { beta: 0.4 })
            .with_effect(Effect::NonlinearDamping {
                beta: -0.05,
                cubic: false,
            })
            .with_effect(Effect::Current {
                beta_s: 0.3,
                beta_c: -0.2,
            })
            .with_effect(Effect::GyroBias { d_y: 0.1 })
            .with_effect(Effect::Asymmetry { beta: 0.05 })
            .with_effect(Effect::DeadTime { samples: 1 });
        let r = record(300, true);
        let err = jacobian_error(&m, &r, &[0.3, -0.1, 0.2, 0.05]);
        assert!(err < 1e-6, "relative error {err}");
    }

    #[test]
    fn jacobian_with_missing_samples_and_integrated_heading() {
        let m = base()
            .with_effect(Effect::NonlinearDamping {
                beta: -0.05,
                cubic: true,
            })
            .with_effect(Effect::Wind {
                beta_s2: 0.2,
                beta_c2: 0.1,
                beta_s1: -0.1,
                beta_c1: 0.05,
            })
            .with_effect(Effect::GyroBias { d_y: 0.1 });
        let mut r = record(300, false);
        for t in (5..300).step_by(17) {
            r.y[t] = f64::NAN;
        }
        let err = jacobian_error(&m, &r, &[0.3, -0.1, 0.2, 0.05]);
        assert!(err < 1e-6, "relative error {err}");
    }
}
