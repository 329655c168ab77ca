//! Records that each hold one course: a current read across their courses from the ground
//! velocity, which it carries whatever the hull does.
//!
//! Over one course a record's heading harmonics are its own offset plus a slope on how far
//! it has turned (`separation.rs`), so the ground velocity's harmonic regression
//! (`channels.rs`), which gives each record its own intercept, sees a current only through
//! the harmonics' curvature over a zig-zag's few tens of degrees: from 2–30 m/s on. But a
//! current is one vector on the earth for every record, and each record sees it along and
//! across its own heading. The ship's own speed through the water and its mean leeway are
//! the same on every course where the trials sail alike manoeuvres, so each record's mean
//! ground velocity in the ship's frame is `w + P(ψ)·c`: `w` common, `c` the current's
//! (north, east), `P(ψ)` its projection on the record's headings. A weighted least-squares
//! fit of `w` and `c` over the records, and a Wald χ² of `c` (2 df). Each record's mean is as
//! noisy as what the manoeuvre leaves of it: its covariance from the means of ten
//! consecutive batches of its residuals ([`record_mean`]). The reference records, which sail
//! no current of their own, calibrate it: their means' χ² against one another per degree of
//! freedom, where above 1, divides the trials' (an F test then), as the yaw channel's offsets
//! are calibrated (`course.rs`). So the reference must hold one course per record as well:
//! the records of a slow hull differ by more than what is left within each (KVLCC2's
//! effect-free zig-zags by 62 times), and only records sailed alike show by how much. The
//! trials' own means calibrate it too, where there are more of them than unknowns: their
//! misfit of the one current per degree of freedom, where larger. An effect that changes the
//! manoeuvre changes how far its records scatter, which the effect-free reference does not
//! show (the Seiun Maru's angle limit named a 0.012 m/s current second without it), and a
//! wind's set is no uniform current (Mariner's winds read `current` without it).

use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

use super::channels::{sog_taus, speed_towards, CROSS_TAUS_S};
use super::course::{set_apart, widest_span};
use super::separation::{heading_separation, MIN_HEADING_SEPARATION};
use crate::io::data::Record;
use crate::stats::{f_quantile, f_sf};

/// Batches each record's mean is judged on.
const BATCHES: usize = 10;
/// Speed over ground (m/s) below which a course over ground is not read (as `channels.rs`).
const MIN_SPEED: f64 = 0.1;

/// What the trial records' mean ground velocities on their own courses show of a current.
#[derive(Debug, Clone, Copy)]
pub(super) struct CarryEvidence {
    /// Wald χ² of the current (2 df), divided by `inflation`.
    pub(super) chi: f64,
    /// The reference records' own χ² per degree of freedom, or the trials' misfit of the one
    /// current per degree of freedom, the larger (≥ 1).
    pub(super) inflation: f64,
    /// Its degrees of freedom (∞ where the inflation is 1).
    pub(super) inflation_df: f64,
    /// Whether the inflation is the trials' own misfit (else the reference's).
    pub(super) own_misfit: bool,
    /// p-value: F on (2, `inflation_df`), which is χ² where the inflation is 1.
    pub(super) p: f64,
    /// The current's estimate (north, east), m/s.
    pub(super) current: [f64; 2],
    /// The estimate's covariance (times the inflation), (m/s)².
    pub(super) cov: [[f64; 2]; 2],
    /// The common speed through the water along the heading (m/s).
    pub(super) through: f64,
    /// The lanes read: 2 with course over ground (along and across the heading), else 1.
    pub(super) lanes: usize,
    /// The widest angle between two trial records' mean headings (deg, 0–180).
    pub(super) span_deg: f64,
    /// The trial records' mean (cos ψ, sin ψ), each record's own mean weighted alike.
    pub(super) courses_cs: [f64; 2],
}

impl CarryEvidence {
    /// The current's speed (m/s) and the direction it sets towards (deg from north, 0–360).
    pub(super) fn speed_dir(&self) -> (f64, f64) {
        speed_towards(self.current)
    }

    /// The standard error of the current's speed (m/s): its spread along the direction it
    /// sets (the larger of the two where it is nil).
    pub(super) fn speed_se(&self) -> f64 {
        let [[a, b], [_, d]] = self.cov;
        let (speed, _) = self.speed_dir();
        if speed > 0.0 {
            let [n, e] = self.current.map(|x| x / speed);
            (n * n * a + 2.0 * n * e * b + e * e * d).max(0.0).sqrt()
        } else {
            a.max(d).sqrt()
        }
    }

    /// The current's mean component (m/s) along the trials' courses, each record weighted
    /// alike: what it adds to their mean speed over ground along the heading.
    pub(super) fn along_courses(&self) -> f64 {
        let [n, e] = self.current;
        n * self.courses_cs[0] + e * self.courses_cs[1]
    }

    /// The smallest current (m/s) the test shows at `level`, in the direction the records
    /// show least.
    pub(super) fn smallest(&self, level: f64) -> f64 {
        // F on (2, ∞) is χ²(2)/2, so this holds for an inflation of 1 too
        let crit = 2.0 * f_quantile(level, 2.0, self.inflation_df);
        let [[a, b], [_, d]] = self.cov;
        let worst = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + b * b).sqrt();
        (crit * worst).sqrt()
    }
}

/// One record's mean ground velocity in the ship's frame (along; across with `lanes` 2),
/// its covariance and the mean (cos ψ, sin ψ) of the samples read.
struct Mean {
    g: DVector<f64>,
    cov: DMatrix<f64>,
    cs: [f64; 2],
}

/// [`Mean`] of `rec` in `lanes` lanes; `None` without heading or speed (or course over
/// ground for 2 lanes), or with too few samples for the batches. `taus`: the surge lags of
/// the speed lost in turns ([`sog_taus`]).
///
/// The mean's noise is what is left of each lane beyond the manoeuvre's own part, the
/// same on every course: a line in the heading turned through (a current's projection over
/// each swing) and in time (the speed a slow hull loses over the record), the yaw rate and
/// command and their squares as they are and through the lags of the speed lost in turns
/// and of the sway (`channels.rs`). Its covariance is that of the residuals' means over ten
/// consecutive batches, divided by their number.
fn record_mean(rec: &Record, lanes: usize, taus: &[f64]) -> Option<Mean> {
    let (psi, sog) = (rec.psi.as_ref()?, rec.speed.as_ref()?);
    let cog = if lanes == 2 { rec.cog.as_ref() } else { None };
    let (nl, ns) = (taus.len(), CROSS_TAUS_S.len());
    // [1, turned, time, r, δ, r², δ², r² and δ² lagged at `taus`, r and δ at the sway's]
    let p = 7 + 2 * nl + 2 * ns;
    let gain = |tau: &f64| (rec.ts / tau).min(1.0);
    let (al, as_): (Vec<f64>, Vec<f64>) = (
        taus.iter().map(gain).collect(),
        CROSS_TAUS_S.iter().map(gain).collect(),
    );
    let (mut l2, mut l1) = (vec![[0.0; 2]; nl], vec![[0.0; 2]; ns]);
    let mut rows: Vec<([f64; 2], [f64; 2], Vec<f64>)> = Vec::with_capacity(rec.len());
    let mut turned = 0.0;
    let mut last: Option<f64> = None;
    for t in 0..rec.len() {
        let (r, d) = (rec.y[t], rec.u[t]);
        for (k, a) in al.iter().enumerate() {
            l2[k][0] += a * (r * r - l2[k][0]);
            l2[k][1] += a * (d * d - l2[k][1]);
        }
        for (k, a) in as_.iter().enumerate() {
            l1[k][0] += a * (r - l1[k][0]);
            l1[k][1] += a * (d - l1[k][1]);
        }
        let (h, s) = (psi[t], sog[t]);
        if !(h.is_finite() && s.is_finite()) {
            continue;
        }
        if let Some(h0) = last {
            turned += ((h - h0 + 180.0).rem_euclid(360.0) - 180.0).to_radians();
        }
        last = Some(h);
        let (sp, cp) = h.to_radians().sin_cos();
        let v = match cog {
            Some(c) if c[t].is_finite() && s >= MIN_SPEED => {
                let (sd, cd) = (c[t] - h).to_radians().sin_cos();
                [s * cd, s * sd]
            }
            Some(_) => continue,
            None => [s, 0.0],
        };
        let mut x = Vec::with_capacity(p);
        x.extend([1.0, turned, t as f64 / rec.len() as f64, r, d, r * r, d * d]);
        x.extend(l2.iter().flatten());
        x.extend(l1.iter().flatten());
        rows.push((v, [cp, sp], x));
    }
    let per = rows.len() / BATCHES;
    if per < 10 || per * BATCHES < 4 * p {
        return None;
    }
    let used = &rows[..per * BATCHES];
    let k = used.len() as f64;
    let (mut v, mut cs) = ([0.0; 2], [0.0; 2]);
    for (a, c, _) in used {
        for j in 0..2 {
            v[j] += a[j] / k;
            cs[j] += c[j] / k;
        }
    }
    let mut xtx = DMatrix::<f64>::zeros(p, p);
    let mut xty = DMatrix::<f64>::zeros(p, lanes);
    for (a, _, x) in used {
        let x = DVector::from_column_slice(x);
        xtx.ger(1.0, &x, &x, 1.0);
        for j in 0..lanes {
            xty.column_mut(j).axpy(a[j], &x, 1.0);
        }
    }
    // the lags are strongly correlated: a relative ridge keeps the solve well posed
    let ridge = 1e-9 * (xtx.trace() / p as f64).max(1e-300);
    for j in 0..p {
        xtx[(j, j)] += ridge;
    }
    let beta = xtx.cholesky()?.solve(&xty);
    let mut cov = DMatrix::<f64>::zeros(lanes, lanes);
    for batch in used.chunks(per) {
        let mut d = DVector::<f64>::zeros(lanes);
        for (a, _, x) in batch {
            for j in 0..lanes {
                let fit: f64 = x
                    .iter()
                    .zip(beta.column(j).iter())
                    .map(|(xi, bi)| xi * bi)
                    .sum();
                d[j] += (a[j] - fit) / per as f64;
            }
        }
        cov.ger(1.0 / (BATCHES * (BATCHES - 1)) as f64, &d, &d, 1.0);
    }
    Some(Mean {
        g: DVector::from_iterator(lanes, v.iter().copied().take(lanes)),
        cov,
        cs,
    })
}

/// The records' means in `lanes` lanes, each with its precision (inverse covariance).
fn means(recs: &[Record], lanes: usize) -> Option<Vec<(Mean, DMatrix<f64>)>> {
    let taus = sog_taus(recs.iter());
    recs.iter()
        .map(|r| {
            let m = record_mean(r, lanes, &taus)?;
            let w = m.cov.clone().try_inverse()?;
            Some((m, w))
        })
        .collect()
}

/// Weighted least squares of the means on `[w, c]` (`current`) or `w` alone: the
/// parameters, their covariance and the weighted residual sum of squares.
fn gls(ms: &[(Mean, DMatrix<f64>)], current: bool) -> Option<(DVector<f64>, DMatrix<f64>, f64)> {
    let lanes = ms.first()?.0.g.len();
    let p = lanes + if current { 2 } else { 0 };
    let design = |m: &Mean| {
        let [c, s] = m.cs;
        let mut x = DMatrix::<f64>::zeros(lanes, p);
        for j in 0..lanes {
            x[(j, j)] = 1.0;
        }
        if current {
            // the current (north, east) along the heading, and across it to starboard
            x[(0, lanes)] = c;
            x[(0, lanes + 1)] = s;
            if lanes == 2 {
                x[(1, lanes)] = -s;
                x[(1, lanes + 1)] = c;
            }
        }
        x
    };
    let mut info = DMatrix::<f64>::zeros(p, p);
    let mut rhs = DVector::<f64>::zeros(p);
    for (m, w) in ms {
        let x = design(m);
        let xtw = x.transpose() * w;
        info += &xtw * &x;
        rhs += &xtw * &m.g;
    }
    // courses too alike to part a current from the speed through the water
    let eig = info.clone().symmetric_eigen().eigenvalues;
    let (lo, hi) = (eig.min(), eig.max());
    if lo.is_nan() || lo <= 1e-12 * hi {
        return None;
    }
    let cov = info.try_inverse()?;
    let theta = &cov * rhs;
    let sse = ms
        .iter()
        .map(|(m, w)| {
            let r = &m.g - design(m) * &theta;
            r.dot(&(w * &r))
        })
        .sum();
    Some((theta, cov, sse))
}

/// [`CarryEvidence`] of the trials `est` against `reference`: both lanes where every record
/// logs course over ground, else speed over ground alone. `None` with fewer than two trial
/// records, a record without heading or speed or too short, courses too alike to tell a
/// current or not [`set_apart`], or a reference that cannot calibrate it: fewer than two
/// records, or records that do not each hold one course ([`heading_separation`] at least
/// [`MIN_HEADING_SEPARATION`]). A record's mean speed depends on its manoeuvre: PRBS
/// records of KVLCC2, each with its own sequence, differ by 56 000 times the noise their
/// alike zig-zags show.
pub(super) fn carry_evidence(est: &[Record], reference: &[Record]) -> Option<CarryEvidence> {
    let one_course =
        |recs: &[Record]| matches!(heading_separation(recs), Some(s) if s < MIN_HEADING_SEPARATION);
    if est.len() < 2 || reference.len() < 2 || !one_course(reference) {
        return None;
    }
    let lanes = if est.iter().chain(reference).all(|r| r.cog.is_some()) {
        2
    } else {
        1
    };
    let trial = means(est, lanes)?;
    let (theta, cov, sse_t) = gls(&trial, true)?;
    let v = Vector2::new(theta[lanes], theta[lanes + 1]);
    let cv: Matrix2<f64> = cov.fixed_view::<2, 2>(lanes, lanes).into_owned();
    let raw = v.dot(&(cv.try_inverse()? * v));
    // the noise: the reference's records against each other, on their own courses
    let refs = means(reference, lanes)?;
    let df = (lanes * (refs.len() - 1)) as f64;
    let (_, _, sse) = gls(&refs, false)?;
    let (mut inflation, mut inflation_df) = if sse / df > 1.0 {
        (sse / df, df)
    } else {
        (1.0, f64::INFINITY)
    };
    // and the trials' own misfit of the one current, where more means than unknowns
    let df_t = (lanes * trial.len()) as f64 - (lanes + 2) as f64;
    let own_misfit = df_t >= 1.0 && sse_t / df_t > inflation;
    if own_misfit {
        (inflation, inflation_df) = (sse_t / df_t, df_t);
    }
    let chi = raw / inflation;
    let p = f_sf(chi / 2.0, 2.0, inflation_df);
    let courses: Vec<f64> = trial
        .iter()
        .map(|(m, _)| m.cs[1].atan2(m.cs[0]).to_degrees())
        .collect();
    let span_deg = widest_span(&courses);
    if !set_apart(span_deg, est) {
        return None;
    }
    let k = trial.len() as f64;
    let courses_cs = trial.iter().fold([0.0; 2], |[a, b], (m, _)| {
        [a + m.cs[0] / k, b + m.cs[1] / k]
    });
    let c = cv * inflation;
    Some(CarryEvidence {
        chi,
        inflation,
        inflation_df,
        own_misfit,
        p,
        current: [v[0], v[1]],
        cov: [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]],
        through: theta[0],
        lanes,
        span_deg,
        courses_cs,
    })
}

/// The speeds straight ahead `[trials, reference]` that [`super::caveat::other_speed`] compares
/// as through the water, and the smallest current (m/s) the ground track shows, which tells
/// their difference from a current. On records that each hold one course with a current read
/// across their courses (`carry`, [`super::channels::Channels::across_carry`]): each set's
/// speed on its courses (`course`) less that current's component along the trials' courses (the
/// reference's own current is [`super::Caveat::ReferenceEnvironment`]'s), and the current's
/// resolution at `level`. Else the heading harmonics' straight speeds (`speeds`) and their
/// `resolution` (none given: no current can be told).
pub(super) fn through_water(
    carry: Option<&CarryEvidence>,
    course: Option<[f64; 2]>,
    speeds: Option<[f64; 2]>,
    resolution: Option<f64>,
    level: f64,
) -> (Option<[f64; 2]>, f64) {
    match carry {
        Some(c) => (
            course.map(|[t, r]| [t - c.along_courses(), r]),
            c.smallest(level),
        ),
        None => (speeds, resolution.unwrap_or(f64::INFINITY)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of `n` samples at `ts` 1 s swinging ±20° about `course` (deg) at 1.0 m/s
    /// through the water with a leeway of 0.02 m/s to starboard, carried by `current`
    /// (north, east, m/s), with a deterministic noise of ±0.02 m/s.
    fn record(course: f64, current: [f64; 2], seed: u64) -> Record {
        record_at(1.0, course, current, seed)
    }

    /// [`record`] at `speed` (m/s) through the water.
    fn record_at(speed: f64, course: f64, current: [f64; 2], seed: u64) -> Record {
        let mut s = seed;
        let mut noise = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.04
        };
        let n = 1200;
        let (mut psi, mut sog, mut cog) = (vec![], vec![], vec![]);
        for t in 0..n {
            let h = course + 20.0 * (t as f64 / 40.0).sin();
            let (sh, ch) = h.to_radians().sin_cos();
            // through the water: `speed` along the heading, 0.02 across it to starboard
            let north = speed * ch - 0.02 * sh + current[0] + noise();
            let east = speed * sh + 0.02 * ch + current[1] + noise();
            psi.push(h);
            sog.push(north.hypot(east));
            cog.push(east.atan2(north).to_degrees());
        }
        let mut r = Record::from_uy("t", 1.0, vec![0.0; n], vec![0.0; n]);
        r.psi = Some(psi);
        r.speed = Some(sog);
        r.cog = Some(cog);
        r
    }

    /// Three calm [`record`]s on courses 0°, 40° and 80°.
    fn calm_reference() -> Vec<Record> {
        (0..3)
            .map(|i| record(40.0 * i as f64, [0.0; 2], i))
            .collect()
    }

    #[test]
    fn a_current_is_read_across_the_courses_and_alike_courses_show_none() {
        let reference = calm_reference();
        let courses = [120.0, 95.0, 145.0];
        // no current: the means agree once each is projected on its own heading
        let calm: Vec<Record> = courses
            .iter()
            .enumerate()
            .map(|(i, &c)| record(c, [0.0; 2], 10 + i as u64))
            .collect();
        let e = carry_evidence(&calm, &reference).unwrap();
        assert_eq!(e.lanes, 2);
        assert!(e.p > 0.01, "{e:?}");
        assert!((e.through - 1.0).abs() < 0.01, "{e:?}");
        assert!((e.span_deg - 50.0).abs() < 1.0, "{e:?}");
        // 0.3 m/s setting east: recovered to a hundredth
        let carried: Vec<Record> = courses
            .iter()
            .enumerate()
            .map(|(i, &c)| record(c, [0.0, 0.3], 10 + i as u64))
            .collect();
        let e = carry_evidence(&carried, &reference).unwrap();
        let (speed, dir) = e.speed_dir();
        assert!(e.p < 1e-6, "{e:?}");
        assert!((speed - 0.3).abs() < 0.01, "{e:?}");
        assert!((dir - 90.0).abs() < 3.0, "{e:?}");
        assert!(
            e.speed_se() > 0.0 && e.speed_se() < 0.01,
            "{}",
            e.speed_se()
        );
        assert!(e.smallest(0.01) < 0.1, "{}", e.smallest(0.01));
        // one course for all: the current cannot be told from the speed through the water
        let one: Vec<Record> = (0..3).map(|i| record(120.0, [0.0, 0.3], i)).collect();
        assert!(carry_evidence(&one, &reference).is_none());
        // along the heading alone (no course over ground): still shown, its size less
        // sure (three means for three unknowns; the speed over ground stands for its
        // component along the heading, which a current across the heading lengthens)
        let mut along = carried.clone();
        along.iter_mut().for_each(|r| r.cog = None);
        let e = carry_evidence(&along, &reference).unwrap();
        assert_eq!(e.lanes, 1);
        assert!(e.p < 1e-3, "{e:?}");
        assert!((e.speed_dir().0 - 0.3).abs() < 0.06, "{e:?}");
        // a reference that turns through every heading cannot calibrate it, nor no reference
        let mut circling = reference.clone();
        for r in circling.iter_mut() {
            r.psi = Some((0..r.len()).map(|t| 0.5 * t as f64).collect());
        }
        assert!(carry_evidence(&carried, &circling).is_none());
        assert!(carry_evidence(&carried, &[]).is_none());
    }

    /// The mean over `recs` of each record's mean speed over ground along its heading.
    fn along(recs: &[Record]) -> f64 {
        let one = |r: &Record| {
            let (psi, sog, cog) = (r.psi.as_ref(), r.speed.as_ref(), r.cog.as_ref());
            let (psi, sog, cog) = (psi.unwrap(), sog.unwrap(), cog.unwrap());
            let n = psi.len() as f64;
            (0..psi.len())
                .map(|t| sog[t] * (cog[t] - psi[t]).to_radians().cos())
                .sum::<f64>()
                / n
        };
        recs.iter().map(one).sum::<f64>() / recs.len() as f64
    }

    #[test]
    fn another_speed_is_told_from_a_current_along_the_courses_read_across_them() {
        use crate::diagnose::caveat::{other_speed, Caveat};
        let reference = calm_reference();
        let courses = [60.0, 85.0, 110.0];
        let trials = |speed: f64, current: [f64; 2]| -> Vec<Record> {
            courses
                .iter()
                .enumerate()
                .map(|(i, &c)| record_at(speed, c, current, 10 + i as u64))
                .collect()
        };
        let read = |t: &[Record]| {
            let c = carry_evidence(t, &reference).unwrap();
            let course = [along(t), along(&reference)];
            // the heading harmonics of one-course records resolve no current
            let (speeds, resolution) = through_water(Some(&c), Some(course), None, None, 0.01);
            (c, course, speeds.unwrap(), resolution)
        };
        // at the reference's speed, carried 0.3 m/s east along the courses: 27 % faster
        // over the ground on them, and the same speed through the water
        let (c, course, speeds, resolution) = read(&trials(1.0, [0.0, 0.3]));
        assert!((course[0] / course[1] - 1.27).abs() < 0.01, "{course:?}");
        // (about 0.27 m/s: the current's mean component along headings 40–130°)
        let a = c.along_courses();
        assert!(
            a > 0.25 && (a - (course[0] - 1.0)).abs() < 0.01,
            "{a} {course:?}"
        );
        assert!((speeds[0] - 1.0).abs() < 0.01, "{speeds:?}");
        assert!(resolution < 0.1, "{resolution}");
        assert_eq!(other_speed(Some(speeds), Some(course), resolution), None);
        // the harmonics alone could not tell, and said both readings
        assert!(matches!(
            other_speed(None, Some(course), f64::INFINITY),
            Some(Caveat::OtherSpeed {
                told_from_current: false,
                ..
            })
        ));
        // 20 % slower through the water in calm: told from a current
        let (c, course, speeds, resolution) = read(&trials(0.8, [0.0; 2]));
        assert!(c.along_courses().abs() < 0.01, "{c:?}");
        match other_speed(Some(speeds), Some(course), resolution) {
            Some(Caveat::OtherSpeed {
                trials_mps,
                reference_mps,
                told_from_current: true,
            }) => {
                assert!((trials_mps - 0.8).abs() < 0.01, "{trials_mps}");
                assert!((reference_mps - 1.0).abs() < 0.01, "{reference_mps}");
            }
            other => panic!("{other:?}"),
        }
    }
}
