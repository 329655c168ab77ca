//! The host's f64 model: canonical innovations form of order n plus library effects.
//!
//! Mirrors `yawcast_shared::model::ModelSpec` (the f32 export) with f64 numbers. The
//! semantics of every effect are those of the firmware predictor; see [`crate::identify::predict`].

use serde::{Deserialize, Serialize};
use thiserror::Error;
use yawcast_shared::model::{self as sm, EffectKind, ModelSpec, Units};

pub use crate::effects::Effect;

/// Errors building or converting models.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// Order outside 2..=8.
    #[error("model order {0} is outside 2..=8")]
    Order(usize),
    /// a, b or k has the wrong length.
    #[error("parameter vector `{name}` has {found} values, the order is {order}")]
    Length {
        /// Which vector.
        name: &'static str,
        /// Its length.
        found: usize,
        /// The order.
        order: usize,
    },
    /// A number is NaN or infinite.
    #[error("parameter `{0}` is not finite")]
    NonFinite(String),
    /// The sample time is not positive.
    #[error("sample time {0} s is not positive")]
    SampleTime(f64),
    /// Two effects of the same kind.
    #[error("effect `{0}` appears twice")]
    DuplicateEffect(&'static str),
    /// The f32 export was refused by the shared schema.
    #[error("the model cannot be exported: {0}")]
    Export(String),
}

/// A linear canonical innovations model of order `n` with optional effects (f64).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// Order n.
    pub n: usize,
    /// Sample time (s).
    pub ts: f64,
    /// Last row of the companion matrix A: `x_n(t+1) = Σ a_i x_i(t) + …`.
    pub a: Vec<f64>,
    /// Input vector B.
    pub b: Vec<f64>,
    /// Kalman gain K.
    pub k: Vec<f64>,
    /// Library effects, at most one of each kind.
    #[serde(default)]
    pub effects: Vec<Effect>,
}

impl Model {
    /// Builds and validates a model with no effects.
    ///
    /// # Errors
    /// [`ModelError`] for a bad order, wrong lengths, non-finite numbers or `ts ≤ 0`.
    ///
    /// ```
    /// use yawcast::identify::model::Model;
    /// let m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
    /// assert_eq!(m.n, 2);
    /// assert!(Model::new(1.0, vec![0.5], vec![0.1], vec![0.3]).is_err());
    /// ```
    pub fn new(ts: f64, a: Vec<f64>, b: Vec<f64>, k: Vec<f64>) -> Result<Model, ModelError> {
        let m = Model {
            n: a.len(),
            ts,
            a,
            b,
            k,
            effects: Vec::new(),
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks order, lengths, finiteness and effect uniqueness.
    ///
    /// # Errors
    /// See [`ModelError`].
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(2..=8).contains(&self.n) {
            return Err(ModelError::Order(self.n));
        }
        for (name, v) in [("a", &self.a), ("b", &self.b), ("k", &self.k)] {
            if v.len() != self.n {
                return Err(ModelError::Length {
                    name,
                    found: v.len(),
                    order: self.n,
                });
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(ModelError::NonFinite(format!("{name}{}", i + 1)));
            }
        }
        if !(self.ts > 0.0 && self.ts.is_finite()) {
            return Err(ModelError::SampleTime(self.ts));
        }
        for (i, e) in self.effects.iter().enumerate() {
            if self.effects[..i].iter().any(|f| f.kind() == e.kind()) {
                return Err(ModelError::DuplicateEffect(e.kind().name()));
            }
            if e.gains().iter().any(|g| !g.is_finite()) {
                return Err(ModelError::NonFinite(e.kind().name().into()));
            }
        }
        Ok(())
    }

    /// θ = (a1..an, b1..bn, k1..kn).
    ///
    /// ```
    /// use yawcast::identify::model::Model;
    /// let m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
    /// assert_eq!(m.theta(), vec![0.0, 0.5, 0.1, 0.2, 0.3, 0.1]);
    /// ```
    pub fn theta(&self) -> Vec<f64> {
        let mut t = Vec::with_capacity(3 * self.n);
        t.extend_from_slice(&self.a);
        t.extend_from_slice(&self.b);
        t.extend_from_slice(&self.k);
        t
    }

    /// Sets θ (length 3n).
    pub fn set_theta(&mut self, theta: &[f64]) {
        let n = self.n;
        self.a.copy_from_slice(&theta[..n]);
        self.b.copy_from_slice(&theta[n..2 * n]);
        self.k.copy_from_slice(&theta[2 * n..3 * n]);
    }

    /// Parameter names in θ order followed by effect gains: `a1.., b1.., k1.., <effect>.<gain>`.
    ///
    /// ```
    /// use yawcast::identify::model::{Effect, Model};
    /// let mut m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
    /// m.effects.push(Effect::Bias { beta: 0.0 });
    /// assert_eq!(m.param_names().last().unwrap(), "bias.beta");
    /// ```
    pub fn param_names(&self) -> Vec<String> {
        let mut v = Vec::new();
        for p in ["a", "b", "k"] {
            for i in 1..=self.n {
                v.push(format!("{p}{i}"));
            }
        }
        for e in &self.effects {
            let names = e.def().gains.iter().map(|(g, _)| g);
            for g in names {
                v.push(format!("{}.{g}", e.kind().name()));
            }
        }
        v
    }

    /// All linear effect gains, in effect order.
    pub fn effect_gains(&self) -> Vec<f64> {
        self.effects.iter().flat_map(|e| e.gains()).collect()
    }

    /// Sets all linear effect gains (length as [`Model::effect_gains`]).
    pub fn set_effect_gains(&mut self, g: &[f64]) {
        let mut at = 0;
        for e in &mut self.effects {
            let len = e.gains().len();
            e.set_gains(&g[at..at + len]);
            at += len;
        }
    }

    /// The effect of `kind`, if present.
    pub fn effect(&self, kind: EffectKind) -> Option<&Effect> {
        self.effects.iter().find(|e| e.kind() == kind)
    }

    /// Adds `e`, replacing an effect of the same kind.
    pub fn with_effect(mut self, e: Effect) -> Model {
        self.effects.retain(|f| f.kind() != e.kind());
        self.effects.push(e);
        self
    }

    /// Output offset `d_y` (gyro bias), 0 when absent.
    pub fn d_y(&self) -> f64 {
        match self.effect(EffectKind::GyroBias) {
            Some(Effect::GyroBias { d_y }) => *d_y,
            _ => 0.0,
        }
    }

    /// Spectral radius of A and of A − KC (the predictor), computed from the companion
    /// polynomials' eigenvalues.
    ///
    /// ```
    /// use yawcast::identify::model::Model;
    /// // x2' = 0.5 x1 ... companion with a = [0.25, 0]: eigenvalues ±0.5
    /// let m = Model::new(1.0, vec![0.25, 0.0], vec![0.0, 1.0], vec![0.0, 0.0]).unwrap();
    /// let (ra, rp) = m.spectral_radii();
    /// assert!((ra - 0.5).abs() < 1e-12 && (rp - 0.5).abs() < 1e-12);
    /// ```
    pub fn spectral_radii(&self) -> (f64, f64) {
        (
            spectral_radius(&self.a_matrix()),
            spectral_radius(&self.predictor_matrix()),
        )
    }

    /// Whether A and A − KC are both strictly stable (spectral radius < 1).
    pub fn is_stable(&self) -> bool {
        let (a, p) = self.spectral_radii();
        a < 1.0 && p < 1.0
    }

    /// The companion matrix A.
    pub fn a_matrix(&self) -> nalgebra::DMatrix<f64> {
        let n = self.n;
        let mut m = nalgebra::DMatrix::zeros(n, n);
        for i in 0..n - 1 {
            m[(i, i + 1)] = 1.0;
        }
        for j in 0..n {
            m[(n - 1, j)] = self.a[j];
        }
        m
    }

    /// The predictor matrix A − K C (C = e₁ᵀ).
    pub fn predictor_matrix(&self) -> nalgebra::DMatrix<f64> {
        let mut m = self.a_matrix();
        for i in 0..self.n {
            m[(i, 0)] -= self.k[i];
        }
        m
    }

    /// Converts to the f32 export schema, in its difference form ([`to_difference_form`]),
    /// rounded to `f32`.
    ///
    /// # Errors
    /// [`ModelError::Export`] when the model has more effects than the schema holds. The
    /// schema's own checks (stability after rounding) run when the spec is validated or
    /// encoded.
    ///
    /// ```
    /// use yawcast::identify::model::Model;
    /// // shift form z² − 0.5 z + 0.2 (a = (−0.2, 0.5)) is δ² + 1.5 δ + 0.7 in δ = z − 1
    /// let m = Model::new(1.0, vec![-0.2, 0.5], vec![0.1, 0.05], vec![0.3, 0.1]).unwrap();
    /// let s = m.to_spec().unwrap();
    /// assert_eq!(s.a.as_slice(), &[-0.7f32, -1.5]);
    /// assert_eq!(s.b.as_slice(), &[0.1f32, -0.05]);
    /// let back = Model::from_spec(&s).unwrap();
    /// assert!((back.a[0] + 0.2).abs() < 1e-7 && (back.a[1] - 0.5).abs() < 1e-7);
    /// ```
    pub fn to_spec(&self) -> Result<ModelSpec, ModelError> {
        let cvt = |v: &[f64]| -> heapless::Vec<f32, { sm::MAX_ORDER }> {
            v.iter().map(|x| *x as f32).collect()
        };
        let (a, b, k) = to_difference_form(&self.a, &self.b, &self.k);
        let mut effects = heapless::Vec::new();
        for e in &self.effects {
            effects
                .push(e.to_spec())
                .map_err(|_| ModelError::Export("too many effects".into()))?;
        }
        let spec = ModelSpec {
            order: self.n as u8,
            ts: self.ts as f32,
            a: cvt(&a),
            b: cvt(&b),
            k: cvt(&k),
            units: Units::default(),
            effects,
        };
        Ok(spec)
    }

    /// Converts from the f32 export schema (difference form) back to the shift form, in f64.
    ///
    /// # Errors
    /// [`ModelError`] when the converted model does not validate.
    pub fn from_spec(spec: &ModelSpec) -> Result<Model, ModelError> {
        let f = |v: &[f32]| v.iter().map(|x| f64::from(*x)).collect::<Vec<_>>();
        let (a, b, k) = from_difference_form(&f(&spec.a), &f(&spec.b), &f(&spec.k));
        let m = Model {
            n: spec.order as usize,
            ts: spec.ts.into(),
            a,
            b,
            k,
            effects: spec.effects.iter().map(Effect::from_spec).collect(),
        };
        m.validate()?;
        Ok(m)
    }
}

/// Binomial coefficient C(n, k) as f64 (exact for the orders used here).
fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
}

/// `v ↦ T v` with `(T v)_i = Σ_{m ≤ i} (−1)^{i−m} C(i, m) v_m`: the `i`-th forward difference
/// of a sequence `v_0, v_1, …` at its start. Maps a shift-form state, input vector or gain
/// to the difference form.
///
/// ```
/// assert_eq!(yawcast::identify::model::differences(&[1.0, 3.0, 7.0, 13.0]), vec![1.0, 2.0, 2.0, 0.0]);
/// ```
pub fn differences(v: &[f64]) -> Vec<f64> {
    (0..v.len())
        .map(|i| {
            (0..=i)
                .map(|m| {
                    let sign = if (i - m) % 2 == 0 { 1.0 } else { -1.0 };
                    sign * binomial(i, m) * v[m]
                })
                .sum()
        })
        .collect()
}

/// The inverse of [`differences`]: `v_i = Σ_{m ≤ i} C(i, m) d_m`.
fn sums(d: &[f64]) -> Vec<f64> {
    (0..d.len())
        .map(|i| (0..=i).map(|m| binomial(i, m) * d[m]).sum())
        .collect()
}

/// Ascending coefficients of `p(x + s)` from those of `p(x)`.
fn shift_poly(p: &[f64], s: f64) -> Vec<f64> {
    (0..p.len())
        .map(|i| {
            (i..p.len())
                .map(|j| p[j] * binomial(j, i) * s.powi((j - i) as i32))
                .sum()
        })
        .collect()
}

/// The difference form of a shift-form model `(a, b, k)` (the model schema's docs): the
/// coefficients `g` of its characteristic polynomial in `δ = z − 1`, written as the last
/// row of `A_δ` (`p(1 + δ) = δ^n − g_n δ^{n−1} − … − g_1`), and `b`, `k` in the coordinates
/// `z_i = Δ^{i−1} x_1` ([`differences`]). Exact up to f64 rounding; the firmware runs this
/// form in `f32`, where it keeps poles close to 1 that the shift form's coefficients lose.
///
/// ```
/// use yawcast::identify::model::to_difference_form;
/// // poles 0.9 and 0.5: z² − 1.4 z + 0.45 → δ² + 0.6 δ + 0.05
/// let (g, b, k) = to_difference_form(&[-0.45, 1.4], &[1.0, 2.0], &[0.5, 0.25]);
/// assert!((g[0] + 0.05).abs() < 1e-15 && (g[1] + 0.6).abs() < 1e-15);
/// assert_eq!((b, k), (vec![1.0, 1.0], vec![0.5, -0.25]));
/// ```
pub fn to_difference_form(a: &[f64], b: &[f64], k: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    // p(z) = z^n − Σ a_i z^{i−1}, ascending
    let mut p: Vec<f64> = a.iter().map(|v| -v).collect();
    p.push(1.0);
    let g = shift_poly(&p, 1.0)[..a.len()].iter().map(|v| -v).collect();
    (g, differences(b), differences(k))
}

/// The inverse of [`to_difference_form`]: the shift-form `(a, b, k)` of a difference-form
/// model.
pub fn from_difference_form(g: &[f64], b: &[f64], k: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut p: Vec<f64> = g.iter().map(|v| -v).collect();
    p.push(1.0);
    let a = shift_poly(&p, -1.0)[..g.len()].iter().map(|v| -v).collect();
    (a, sums(b), sums(k))
}

/// Largest eigenvalue modulus of a square matrix; +∞ when an entry is not finite or the
/// (bounded) Schur iteration does not converge, so such a matrix never counts as stable.
///
/// ```
/// use nalgebra::DMatrix;
/// use yawcast::identify::model::spectral_radius;
/// let m = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -0.25, 0.0]);
/// assert!((spectral_radius(&m) - 0.5).abs() < 1e-12);
/// let bad = DMatrix::from_row_slice(2, 2, &[f64::NAN, 1.0, 3.4e200, 0.0]);
/// assert_eq!(spectral_radius(&bad), f64::INFINITY);
/// ```
pub fn spectral_radius(m: &nalgebra::DMatrix<f64>) -> f64 {
    if !m.iter().all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    match m.clone().try_schur(f64::EPSILON, 10_000) {
        Some(s) => s
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max),
        None => f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn theta_round_trip_and_names() {
        let mut m = Model::new(
            1.0,
            vec![0.1, 0.2, 0.3, 0.4],
            vec![1.0, 2.0, 3.0, 4.0],
            vec![0.5, 0.6, 0.7, 0.8],
        )
        .unwrap();
        let th: Vec<f64> = (0..12).map(|i| i as f64).collect();
        m.set_theta(&th);
        assert_eq!(m.theta(), th);
        assert_eq!(m.param_names()[4], "b1");
        assert_eq!(m.param_names()[11], "k4");
    }

    #[test]
    fn effect_gains_round_trip() {
        let mut m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1]).unwrap();
        m = m
            .with_effect(Effect::zero(EffectKind::Wind, 0.0))
            .with_effect(Effect::DeadTime { samples: 2 })
            .with_effect(Effect::Bias { beta: 0.0 });
        m.set_effect_gains(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(m.effect_gains(), vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(
            m.effect(EffectKind::Bias),
            Some(&Effect::Bias { beta: 5.0 })
        );
        m.effects.push(Effect::Bias { beta: 1.0 });
        assert_eq!(m.validate(), Err(ModelError::DuplicateEffect("bias")));
    }

    #[test]
    fn spectral_radius_of_predictor() {
        // A − KC for n = 2: [[-k1, 1], [a1 - k2, a2]]
        let m = Model::new(1.0, vec![-0.5, 1.0], vec![0.0, 1.0], vec![0.5, 0.0]).unwrap();
        let (ra, rp) = m.spectral_radii();
        // A: z² − z + 0.5 → |z| = √0.5
        assert!((ra - 0.5f64.sqrt()).abs() < 1e-12);
        // A−KC: [[-0.5, 1], [-0.5, 1]] → z² − 0.5 z + 0 → {0, 0.5}
        assert!((rp - 0.5).abs() < 1e-12);
        assert!(m.is_stable());
    }

    #[test]
    fn json_twin_uses_stable_effect_names() {
        for k in EffectKind::ALL {
            let m = Model::new(1.0, vec![0.0, 0.5], vec![0.1, 0.2], vec![0.3, 0.1])
                .unwrap()
                .with_effect(Effect::zero(k, 3.0));
            let s = serde_json::to_string(&m).unwrap();
            assert!(s.contains(&format!("\"effect\":\"{}\"", k.name())), "{s}");
            let back: Model = serde_json::from_str(&s).unwrap();
            assert_eq!(back, m);
        }
    }
}
