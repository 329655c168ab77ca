//! The frozen-θ likelihood statistics: prediction errors and their sensitivities to an
//! effect's gains, each effect's parameter grid, the version of an effect a record set
//! shows, and the statistic `D` of every kind in one world.

use nalgebra::{DMatrix, DVector};
use yawcast_shared::model::EffectKind;

use super::SLOW_HORIZON;
use crate::effects::{def, GridSpan};
use crate::identify::model::{Effect, Model};
use crate::identify::predict::{self, Stepper};
use crate::io::data::Record;

/// Every `SLOW_STRIDE`-th sample's 50-step error is used (they overlap heavily anyway).
const SLOW_STRIDE: usize = 10;

pub(super) fn horizon_of(kind: EffectKind) -> usize {
    if def(kind).slow {
        SLOW_HORIZON
    } else {
        1
    }
}

/// Prediction errors `y − ŷ` at horizon `h` (all samples for h = 1; every
/// [`SLOW_STRIDE`]-th sample from `h` on otherwise). Open-loop steps use the measured heading.
fn errors(model: &Model, rec: &Record, x0: &[f64], h: usize) -> Vec<f64> {
    let s = Stepper::new(model);
    let psi = |t: usize| rec.psi.as_ref().map(|p| p[t]);
    let p0 = psi(0).unwrap_or(0.0);
    let mut st = s.initial(x0, p0);
    let n = rec.len();
    if h <= 1 {
        return (0..n)
            .map(|t| rec.y[t] - s.step(&mut st, rec.u[t], rec.y[t], psi(t)).yhat)
            .collect();
    }
    // the open-loop pass predicting sample t starts from the filter's state at t + 1 − h: it
    // runs as the filter passes there, so no state sequence is kept
    let mut out = Vec::with_capacity(n / SLOW_STRIDE + 1);
    let mut w = st.clone();
    let mut t = h;
    for start in 0..n {
        if t < n && start == t + 1 - h {
            w.clone_from(&st);
            for j in start..t {
                s.step(&mut w, rec.u[j], f64::NAN, psi(j));
            }
            out.push(rec.y[t] - s.output(&w));
            t += SLOW_STRIDE;
        }
        s.step(&mut st, rec.u[start], rec.y[start], psi(start));
    }
    out
}

/// [`errors`] from the record's own x̂(0), with the sample each error predicts.
pub(super) fn errors_at(model: &Model, rec: &Record, h: usize) -> (Vec<f64>, Vec<usize>) {
    let x0 = predict::estimate_x0(model, rec);
    let e = errors(model, rec, &x0, h);
    let first = if h <= 1 { 0 } else { h };
    let at = (0..e.len()).map(|j| first + j * error_stride(h)).collect();
    (e, at)
}

/// The samples between two of [`errors`]' `h`-step errors.
pub(super) fn error_stride(h: usize) -> usize {
    if h <= 1 {
        1
    } else {
        SLOW_STRIDE
    }
}

/// Least-squares pieces of one candidate on a set of records: `e₀ᵀe₀`, `Sᵀe₀`, `SᵀS` with
/// `S` the sensitivities of ŷ to the effect's gains (so `SSE(β) = ‖e₀ − Sβ‖²`).
#[derive(Debug, Clone)]
pub(super) struct Quad {
    ee: f64,
    se: DVector<f64>,
    ss: DMatrix<f64>,
    n: usize,
}

impl Quad {
    fn zero(p: usize) -> Quad {
        Quad {
            ee: 0.0,
            se: DVector::zeros(p),
            ss: DMatrix::zeros(p, p),
            n: 0,
        }
    }

    fn add(&mut self, o: &Quad) {
        self.ee += o.ee;
        self.se += &o.se;
        self.ss += &o.ss;
        self.n += o.n;
    }

    fn sse(&self, beta: &DVector<f64>) -> f64 {
        if beta.is_empty() {
            return self.ee;
        }
        (self.ee - 2.0 * beta.dot(&self.se) + beta.dot(&(&self.ss * beta))).max(1e-300)
    }

    /// The smallest change of an effect's gains these errors show at the level a null's
    /// critical value `d_crit` sets: the change whose statistic
    /// `D = n·ln(1 + βᵀSᵀSβ/SSE)` reaches it, with the errors the best fit leaves as the
    /// noise — an effect that size reaches the level about half the time. Of one gain,
    /// `|β|` itself; of several, the length `|β|` of a change of the gains `within` alone
    /// (the others 0) in the direction the errors show least: the smallest eigenvalue of
    /// their block of `SᵀS`. `None` without errors, with `within` empty or out of range, or
    /// where some direction of those gains does not move the errors.
    pub(super) fn smallest_gain(&self, d_crit: f64, within: &[usize]) -> Option<f64> {
        let p = self.se.len();
        if self.n == 0 || within.is_empty() || within.iter().any(|&i| i >= p) {
            return None;
        }
        let m = within.len();
        let block = DMatrix::from_fn(m, m, |a, b| self.ss[(within[a], within[b])]);
        let least = block.clone().symmetric_eigenvalues().min();
        // (a NaN eigenvalue fails the comparison too)
        if least.partial_cmp(&(1e-12 * block.trace())) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let (_, sse) = self.best();
        let b2 = (d_crit / self.n as f64).exp_m1() * sse / least;
        b2.is_finite().then(|| b2.sqrt())
    }

    pub(super) fn best(&self) -> (DVector<f64>, f64) {
        let p = self.se.len();
        if p == 0 {
            return (DVector::zeros(0), self.ee.max(1e-300));
        }
        let mut a = self.ss.clone();
        let ridge = 1e-10 * (a.trace() / p as f64).max(1e-300);
        for i in 0..p {
            a[(i, i)] += ridge;
        }
        let beta = a
            .cholesky()
            .map(|c| c.solve(&self.se))
            .unwrap_or_else(|| DVector::zeros(p));
        let s = self.sse(&beta);
        (beta, s)
    }
}

/// Step of the finite-difference sensitivities (effects are affine in their gains apart from
/// the integrated heading, which is not used here).
const FD_STEP: f64 = 1e-3;

fn quad_of(model: &Model, cand: &Effect, rec: &Record, x0: &[f64], h: usize) -> Quad {
    quad_multi(model, std::slice::from_ref(cand), rec, x0, h)
}

/// [`quad_of`] for several effects added together, their gains fitted jointly (in the order
/// of `cands`, each effect's gains in [`Effect::gains`] order).
fn quad_multi(model: &Model, cands: &[Effect], rec: &Record, x0: &[f64], h: usize) -> Quad {
    let zero: Vec<Vec<f64>> = cands.iter().map(|c| vec![0.0; c.gains().len()]).collect();
    let with = |gains: &[Vec<f64>]| {
        let mut m = model.clone();
        for (c, g) in cands.iter().zip(gains) {
            let mut c = *c;
            if !g.is_empty() {
                c.set_gains(g);
            }
            m = m.with_effect(c);
        }
        m
    };
    let e0 = errors(&with(&zero), rec, x0, h);
    let p: usize = zero.iter().map(Vec::len).sum();
    let mut cols = Vec::with_capacity(p);
    for (k, g) in zero.iter().enumerate() {
        for j in 0..g.len() {
            let mut gains = zero.clone();
            gains[k][j] = FD_STEP;
            let ej = errors(&with(&gains), rec, x0, h);
            cols.push(
                e0.iter()
                    .zip(&ej)
                    .map(|(a, b)| (a - b) / FD_STEP)
                    .collect::<Vec<f64>>(),
            );
        }
    }
    let mut q = Quad::zero(p);
    q.n = e0.len();
    for (t, e) in e0.iter().enumerate() {
        if !e.is_finite() {
            q.ee = f64::INFINITY;
            continue;
        }
        q.ee += e * e;
        for i in 0..p {
            q.se[i] += cols[i][t] * e;
            for j in 0..=i {
                q.ss[(i, j)] += cols[i][t] * cols[j][t];
            }
        }
    }
    for i in 0..p {
        for j in 0..i {
            q.ss[(j, i)] = q.ss[(i, j)];
        }
    }
    q
}

/// The candidates (grid) of one effect kind, with zero gains: the effect's own
/// ([`crate::effects::Def::candidates`]) over the records' span.
pub(super) fn grid(kind: EffectKind, span: &GridSpan) -> Vec<Effect> {
    (def(kind).candidates)(span)
}

/// A set of records with the base model's x̂(0) per record.
pub(super) struct Set<'a> {
    recs: Vec<&'a Record>,
    x0: Vec<Vec<f64>>,
}

impl<'a> Set<'a> {
    pub(super) fn new(model: &Model, recs: &'a [Record]) -> Set<'a> {
        Set {
            recs: recs.iter().collect(),
            x0: recs
                .iter()
                .map(|r| predict::estimate_x0(model, r))
                .collect(),
        }
    }

    pub(super) fn from_owned(model: &Model, recs: &'a [Record]) -> Set<'a> {
        Set::new(model, recs)
    }

    /// Quads of every candidate, summed over records.
    pub(super) fn family(
        &self,
        model: &Model,
        cands: &[Effect],
        h: usize,
        parallel: bool,
    ) -> Vec<Quad> {
        let one = |c: &Effect| {
            let mut q = Quad::zero(c.gains().len());
            for (r, x0) in self.recs.iter().zip(&self.x0) {
                q.add(&quad_of(model, c, r, x0, h));
            }
            q
        };
        crate::par::map(cands, parallel, one)
    }

    /// Quads of every pair of candidates (both added, their gains fitted jointly), summed
    /// over records.
    pub(super) fn pairs(
        &self,
        model: &Model,
        pairs: &[(Effect, Effect)],
        h: usize,
        parallel: bool,
    ) -> Vec<Quad> {
        let one = |(a, b): &(Effect, Effect)| {
            let mut q = Quad::zero(a.gains().len() + b.gains().len());
            for (r, x0) in self.recs.iter().zip(&self.x0) {
                q.add(&quad_multi(model, &[*a, *b], r, x0, h));
            }
            q
        };
        crate::par::map(pairs, parallel, one)
    }

    /// The model's one-step error std on the set: the innovation std the bootstrap
    /// simulates it with.
    pub(super) fn innovation_std(&self, model: &Model) -> f64 {
        let (s, n) = self.sse0(model, 1);
        (s / n.max(1) as f64).sqrt()
    }

    /// SSE of the base model at horizon h.
    pub(super) fn sse0(&self, model: &Model, h: usize) -> (f64, usize) {
        let mut s = 0.0;
        let mut n = 0;
        for (r, x0) in self.recs.iter().zip(&self.x0) {
            let e = errors(model, r, x0, h);
            s += e.iter().map(|v| v * v).sum::<f64>();
            n += e.len();
        }
        (s, n)
    }
}

/// The version of an effect a record set shows: `None` (the base model) or a candidate index
/// with its gains.
#[derive(Debug, Clone)]
pub(super) struct Version {
    pub(super) idx: Option<usize>,
    pub(super) beta: DVector<f64>,
}

/// Best candidate of a family: (index, gains, SSE).
fn best_of(quads: &[Quad]) -> (usize, DVector<f64>, f64) {
    let mut best = (0, DVector::zeros(0), f64::INFINITY);
    for (i, q) in quads.iter().enumerate() {
        let (b, s) = q.best();
        if s < best.2 {
            best = (i, b, s);
        }
    }
    best
}

/// The version a set shows: the best candidate when it beats the base model.
fn version_of(quads: &[Quad], sse0: f64) -> Version {
    let (i, b, s) = best_of(quads);
    if s < sse0 {
        Version {
            idx: Some(i),
            beta: b,
        }
    } else {
        Version {
            idx: None,
            beta: DVector::zeros(0),
        }
    }
}

fn sse_at(quads: &[Quad], sse0: f64, v: &Version) -> f64 {
    match v.idx {
        None => sse0,
        Some(i) => quads[i].sse(&v.beta),
    }
}

/// `D = N·ln(SSE(reference version)/SSE(best))` on a trial set, with the best candidate.
pub(super) fn trial_statistic(
    quads: &[Quad],
    sse0: f64,
    n: usize,
    reference: &Version,
) -> (f64, usize, DVector<f64>) {
    let base = sse_at(quads, sse0, reference);
    let (i, b, s) = best_of(quads);
    let s = s.min(base);
    let d = n as f64 * (base / s).ln();
    (d.max(0.0), i, b)
}

/// The candidate with its gains set.
pub(super) fn effect_with(cand: &Effect, beta: &DVector<f64>) -> Effect {
    let mut e = *cand;
    if !beta.is_empty() {
        e.set_gains(beta.as_slice());
    }
    e
}

/// What one "world" (a model, its reference records, trial records) shows for one effect.
#[derive(Debug, Clone)]
pub(super) struct WorldStat {
    pub(super) d: f64,
    pub(super) best: Effect,
    pub(super) n: usize,
    /// The version of the effect the reference shows (its best candidate with its gains, when
    /// it beats the model there).
    pub(super) reference: Option<Effect>,
    /// The least-squares pieces of the best candidate on the trials, from which `d` was
    /// measured ([`Quad::smallest_gain`] reads the resolution from them).
    pub(super) quad: Quad,
}

/// The statistic `D` of every kind in one world: the reference version of each effect is
/// fitted on `reference` (none when empty), `D` measured on `trial`.
pub(super) fn world(
    model: &Model,
    reference: &[Record],
    trial: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    parallel: bool,
) -> Vec<WorldStat> {
    let versions = reference_versions(model, reference, grids, parallel);
    trial_stats(model, trial, grids, &versions, parallel)
}

/// The version of each effect of `grids` the `reference` records show against `model` (the
/// model itself for every effect when there are none).
pub(super) fn reference_versions(
    model: &Model,
    reference: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    parallel: bool,
) -> Vec<Version> {
    if reference.is_empty() {
        let none = Version {
            idx: None,
            beta: DVector::zeros(0),
        };
        return vec![none; grids.len()];
    }
    let rset = Set::new(model, reference);
    crate::par::map(
        grids,
        parallel,
        |(kind, cands): &(EffectKind, Vec<Effect>)| {
            let h = horizon_of(*kind);
            let (r0, _) = rset.sse0(model, h);
            let rq = rset.family(model, cands, h, false);
            version_of(&rq, r0)
        },
    )
}

/// The statistic `D` of every kind of `grids` on `trial` against `on_trial` (the model, or
/// the model with an effect the trials show added), measured from `versions[i]`, the version
/// of `grids[i]` the reference shows ([`reference_versions`]).
pub(super) fn trial_stats(
    on_trial: &Model,
    trial: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    versions: &[Version],
    parallel: bool,
) -> Vec<WorldStat> {
    let tset = Set::new(on_trial, trial);
    let items: Vec<_> = grids.iter().zip(versions).collect();
    crate::par::map(&items, parallel, |&((kind, cands), version)| {
        let h = horizon_of(*kind);
        let (t0, tn) = tset.sse0(on_trial, h);
        let tq = tset.family(on_trial, cands, h, false);
        let (d, bi, bb) = trial_statistic(&tq, t0, tn, version);
        WorldStat {
            d,
            best: effect_with(&cands[bi], &bb),
            n: tn,
            reference: version.idx.map(|i| effect_with(&cands[i], &version.beta)),
            quad: tq[bi].clone(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_gain_reaches_the_critical_value() {
        // 400 errors, SSE 100 before the gain, its regressor's SᵀS 50 and Sᵀe 10: the best
        // gain 0.2 leaves 98
        let q = Quad {
            ee: 100.0,
            se: DVector::from_element(1, 10.0),
            ss: DMatrix::from_element(1, 1, 50.0),
            n: 400,
        };
        let (b, sse) = q.best();
        assert!(
            (b[0] - 0.2).abs() < 1e-9 && (sse - 98.0).abs() < 1e-6,
            "{b} {sse}"
        );
        let d_crit = 10.83;
        let x = q.smallest_gain(d_crit, &[0]).unwrap();
        // a gain of x on those errors: D = n·ln((SSE + x²·SᵀS)/SSE) is the critical value
        let d = 400.0 * ((98.0 + x * x * 50.0) / 98.0).ln();
        assert!((d - d_crit).abs() < 1e-6, "{x} {d}");
        assert!((x - 0.2319).abs() < 1e-4, "{x}");
        // the larger the critical value, the larger the smallest gain shown
        assert!(q.smallest_gain(4.0 * d_crit, &[0]).unwrap() > 1.9 * x);
        // not without errors, nor without a gain, nor where the regressor does not move
        assert_eq!(Quad::zero(2).smallest_gain(d_crit, &[0, 1]), None);
        assert_eq!(q.smallest_gain(d_crit, &[]), None);
        assert_eq!(q.smallest_gain(d_crit, &[1]), None);
        let flat = Quad {
            ss: DMatrix::zeros(1, 1),
            ..q
        };
        assert_eq!(flat.smallest_gain(d_crit, &[0]), None);
    }

    /// Of several gains, the direction the errors show least decides: the length of a
    /// change along the eigenvector of the smallest eigenvalue of their block of SᵀS whose
    /// D is the critical value; a change of some gains alone reads their block only.
    #[test]
    fn of_several_gains_the_worst_direction_decides() {
        // the first two gains' block has eigenvalues 70 and 20 (eigenvectors (1, 1)/√2 and
        // (1, −1)/√2); the third is correlated with them
        let q = Quad {
            ee: 100.0,
            se: DVector::zeros(3),
            ss: DMatrix::from_row_slice(
                3,
                3,
                &[45.0, 25.0, 10.0, 25.0, 45.0, 0.0, 10.0, 0.0, 30.0],
            ),
            n: 400,
        };
        let d_crit = 13.8;
        let x = q.smallest_gain(d_crit, &[0, 1]).unwrap();
        let d_of = |b: &[f64]| {
            let b = DVector::from_column_slice(b);
            400.0 * ((100.0 + b.dot(&(&q.ss * &b))) / 100.0).ln()
        };
        let h = x / 2f64.sqrt();
        assert!((d_of(&[h, -h, 0.0]) - d_crit).abs() < 1e-6, "{x}");
        // along the other eigenvector the same length shows more
        assert!(d_of(&[h, h, 0.0]) > 3.0 * d_crit);
        // all three gains: a direction shown still less, so a longer change
        assert!(q.smallest_gain(d_crit, &[0, 1, 2]).unwrap() > x);
        // a direction the gains do not move: none
        let singular = Quad {
            ss: DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]),
            se: DVector::zeros(2),
            ..q
        };
        assert_eq!(singular.smallest_gain(d_crit, &[0, 1]), None);
    }
}
