//! The heading and speed-over-ground channels: the gyro offset the heading shows, the
//! heading harmonics of speed over ground (speed lost in turns taken out through a bank of
//! surge lags) with their null covariance (what each adds to an effect's evidence:
//! `channel_evidence.rs`).

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::anemometer::{anemometer_evidence, AnemometerEvidence};
use super::carry::CarryEvidence;
use super::course::CourseEvidence;
use super::separation::{heading_separation, MIN_HEADING_SEPARATION};
use crate::io::data::Record;
use crate::io::data::{gyro_offset, GyroOffset};
use crate::stats::{f_quantile, f_sf};

/// What heading and speed over ground show on the trials against the reference: whether
/// every record logs them, the gyro offset the heading shows (trial minus reference when
/// there is a reference; offset and standard error, °/s) and the speed-over-ground evidence.
#[derive(Debug, Clone, Copy)]
pub(super) struct Channels {
    /// Heading is logged in every record.
    pub(super) heading_ok: bool,
    /// Heading and speed over ground are logged in every record.
    pub(super) speed_ok: bool,
    /// The gyro offset the heading shows (trial minus reference) and how sure it is.
    pub(super) hb: Option<GyroOffset>,
    /// The heading harmonics of speed over ground.
    pub(super) sog: Option<SogEvidence>,
    /// The true wind the anemometer shows, when every record logs it with heading, speed
    /// and course over ground.
    pub(super) anemometer: Option<AnemometerEvidence>,
    /// The speed through the water straight ahead of the trials and of the reference
    /// ([`straight_speed`]), when both log heading and speed.
    pub(super) speeds: Option<[f64; 2]>,
    /// The same over the ground on the courses sailed ([`course_speed`]): what records
    /// that each hold one course show.
    pub(super) course_speeds: Option<[f64; 2]>,
    /// The trials' [`heading_separation`], when every trial logs its heading.
    pub(super) separation: Option<f64>,
    /// On trials that each hold one course ([`Channels::yaw_tells_heading`] false): what
    /// their error offsets show of a moment that changes with the course (set
    /// by the caller, which has the model).
    pub(super) course: Option<CourseEvidence>,
    /// On such trials: what their ground velocities show of a current across their courses.
    pub(super) carry: Option<CarryEvidence>,
}

impl Channels {
    /// The channels of the trials `est` against `reference` (may be empty).
    pub(super) fn measure(est: &[Record], reference: &[Record], seed: u64) -> Channels {
        let has_ref = !reference.is_empty();
        let heading_ok = est.iter().all(|r| r.psi.is_some())
            && (!has_ref || reference.iter().all(|r| r.psi.is_some()));
        let speed_ok = heading_ok
            && est.iter().all(|r| r.speed.is_some())
            && (!has_ref || reference.iter().all(|r| r.speed.is_some()));
        let hb = if heading_ok {
            gyro_offset(est, if has_ref { reference } else { &[] })
        } else {
            None
        };
        let sog = if speed_ok {
            sog_evidence(est, if has_ref { reference } else { &[] }, seed)
        } else {
            None
        };
        let anemometer = if speed_ok {
            anemometer_evidence(est, reference)
        } else {
            None
        };
        let separation = if heading_ok {
            heading_separation(est)
        } else {
            None
        };
        let both = |f: fn(&[Record]) -> Option<f64>| {
            if speed_ok && has_ref {
                f(est).zip(f(reference)).map(|(t, r)| [t, r])
            } else {
                None
            }
        };
        let (speeds, course_speeds) = (both(straight_speed), both(course_speed));
        Channels {
            heading_ok,
            speed_ok,
            hb,
            sog,
            anemometer,
            speeds,
            course_speeds,
            separation,
            course: None,
            carry: None,
        }
    }

    /// Whether the yaw channel can tell current or wind from the trials' manoeuvre: their
    /// [`heading_separation`] at least [`MIN_HEADING_SEPARATION`] (or no heading logged).
    pub(super) fn yaw_tells_heading(&self) -> bool {
        !matches!(self.separation, Some(s) if s < MIN_HEADING_SEPARATION)
    }

    /// [`Channels::carry`] where it reads a current: trials that each hold one course.
    pub(super) fn across_carry(&self) -> Option<CarryEvidence> {
        self.carry.filter(|_| !self.yaw_tells_heading())
    }
}

/// Which component of the ground velocity is regressed on the heading harmonics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Lane {
    /// Speed over ground: the ship's speed through the water plus the current along the
    /// heading. Nuisance: the speed lost in turns and to rudder/pod drag, r² and δ² through
    /// the surge lags of [`sog_taus`].
    Along,
    /// Speed over ground times the sine of course over ground less heading: the sway
    /// velocity plus the current across the heading. Nuisance: the sway, linear in r and δ
    /// (as they are and through the lags of [`CROSS_TAUS_S`]). Samples whose course is
    /// missing, or whose speed is too low to give one, are skipped.
    Cross,
}

/// Time constants (s) of the sway nuisance of the cross-track lane: a hull's sway time
/// constant is about `L/U` (≈ 5 s on a model ship, ≈ 40 s on a full-scale tanker).
pub(super) const CROSS_TAUS_S: [f64; 4] = [3.0, 10.0, 30.0, 90.0];
/// Speed over ground (m/s) below which a course is not used.
const CROSS_MIN_SPEED: f64 = 0.1;

/// The coefficients of (sin ψ, cos ψ, sin 2ψ, cos 2ψ) out of a [`sog_fit`] of `records`
/// records.
fn sog_harmonics(beta: DVector<f64>, records: usize) -> DVector<f64> {
    beta.rows(2 * records, 4).into_owned()
}

/// The speed a set of records runs at straight ahead through the water (m/s): the mean of
/// the per-record intercepts of the [`sog_fit`] along the heading — speed over
/// ground less the current its heading harmonics take, less the speed lost in turns and to
/// the commands. `None` without heading or speed, or where the fit cannot be made.
pub(super) fn straight_speed(recs: &[Record]) -> Option<f64> {
    intercept_speed(recs, true)
}

/// The speed a set of records runs at straight ahead over the ground on the courses they
/// sailed (m/s): as [`straight_speed`] without the heading harmonics, so whatever a current
/// adds along those courses stays in it. On records that each hold one course the
/// harmonics are each record's own offset, and [`straight_speed`] splits the speed between
/// them as its ridge happens to; this figure is what such records show.
pub(super) fn course_speed(recs: &[Record]) -> Option<f64> {
    intercept_speed(recs, false)
}

/// The mean per-record intercept of the [`sog_fit`] along the heading, with or without the
/// heading harmonics (without: their columns are zero, and the fit's ridge holds their
/// coefficients at zero).
fn intercept_speed(recs: &[Record], harmonics: bool) -> Option<f64> {
    let refs: Vec<&Record> = recs.iter().collect();
    let mut heading = headings(&refs)?;
    if !harmonics {
        heading
            .iter_mut()
            .for_each(|h| h.harmonics.iter_mut().for_each(|x| *x = [0.0; 4]));
    }
    let taus = sog_taus(refs.iter().copied());
    let beta = sog_fit(Lane::Along, &refs, &heading, &[], &taus, None)?;
    let u = beta.rows(0, refs.len()).mean();
    u.is_finite().then_some(u)
}

/// The least-squares fit of the lane's component of the ground velocity on the coefficients
/// of (sin ψ, cos ψ, sin 2ψ, cos 2ψ) and the nuisance: one intercept and one slope on the
/// heading turned through ([`turned`]) per record, and the lane's own regressors (see
/// [`Lane`]); all coefficients, in the order intercepts, slopes, harmonics
/// ([`sog_harmonics`] takes them out), the lane's own.
/// `shift[i]` circularly shifts record i's heading against its speed (0: aligned);
/// `remove` is a heading dependence (harmonic coefficients) taken out of the target at the
/// true heading first, as the null draws do. `heading[i]` is record i's [`Heading`]
/// (computed once for the many shifted draws of one set).
fn sog_fit(
    lane: Lane,
    recs: &[&Record],
    heading: &[Heading],
    shift: &[usize],
    taus: &[f64],
    remove: Option<&DVector<f64>>,
) -> Option<DVector<f64>> {
    let nr = recs.len();
    let taus: &[f64] = match lane {
        Lane::Along => taus,
        Lane::Cross => &CROSS_TAUS_S,
    };
    let nt = taus.len();
    let own = match lane {
        Lane::Along => 2 * nt,
        Lane::Cross => 2 * nt + 2,
    };
    let p = 2 * nr + 4 + own;
    let mut xtx = DMatrix::<f64>::zeros(p, p);
    let mut xty = DVector::<f64>::zeros(p);
    let mut x = DVector::<f64>::zeros(p);
    let mut rows = 0usize;
    for ((i, r), hd) in recs.iter().enumerate().zip(heading) {
        let psi = r.psi.as_ref()?;
        let sp = r.speed.as_ref()?;
        let cog = match lane {
            Lane::Along => None,
            Lane::Cross => Some(r.cog.as_ref()?),
        };
        let a: Vec<f64> = taus.iter().map(|tau| (r.ts / tau).min(1.0)).collect();
        let mut lr = vec![0.0; nt];
        let mut lu = vec![0.0; nt];
        let n = r.len();
        let (hr, turn) = (&hd.harmonics, &hd.turned);
        let sh = shift.get(i).copied().unwrap_or(0) % n.max(1);
        for t in 0..n {
            let (fr, fu) = match lane {
                Lane::Along => (r.y[t] * r.y[t], r.u[t] * r.u[t]),
                Lane::Cross => (r.y[t], r.u[t]),
            };
            for k in 0..nt {
                lr[k] += a[k] * (fr - lr[k]);
                lu[k] += a[k] * (fu - lu[k]);
            }
            let mut target = match cog {
                None => sp[t],
                Some(c) => {
                    if !(c[t].is_finite() && sp[t] >= CROSS_MIN_SPEED) {
                        continue;
                    }
                    sp[t] * (c[t] - psi[t]).to_radians().sin()
                }
            };
            if let Some(b) = remove {
                let h0 = &hr[t];
                target -= (0..4).map(|j| h0[j] * b[j]).sum::<f64>();
            }
            let h = &hr[(t + sh) % n];
            x.fill(0.0);
            x[i] = 1.0;
            // shifted with the heading: the harmonics and the heading turned through keep
            // their common part in the null draws as in the records
            x[nr + i] = turn[(t + sh) % n];
            let o = 2 * nr;
            for (j, hj) in h.iter().enumerate() {
                x[o + j] = *hj;
            }
            for k in 0..nt {
                x[o + 4 + 2 * k] = lr[k];
                x[o + 5 + 2 * k] = lu[k];
            }
            if lane == Lane::Cross {
                x[o + 4 + 2 * nt] = fr;
                x[o + 5 + 2 * nt] = fu;
            }
            xtx.ger(1.0, &x, &x, 1.0);
            xty.axpy(target, &x, 1.0);
            rows += 1;
        }
    }
    if rows < 2 * p {
        return None;
    }
    // the filter bank's columns are strongly correlated: a relative ridge keeps the solve
    // well posed without moving the (orthogonal) heading harmonics
    let ridge = 1e-9 * (xtx.trace() / p as f64).max(1e-300);
    for j in 0..p {
        xtx[(j, j)] += ridge;
    }
    Some(xtx.cholesky()?.solve(&xty))
}

/// The heading a record has turned through (rad): unwrapped, less its mean over the record.
///
/// Why a slope on it is nuisance: over a record whose heading spans a sector only — a
/// zig-zag's few tens of degrees — the heading harmonics less the record's intercept are
/// (nearly) this one series, and so is whatever the manoeuvre itself moves in step with the
/// heading (the sway and speed of each swing), which no current causes. A current shows in
/// how the heading dependence changes *across* headings: through the harmonics' curvature
/// within a record and their directions between records. The slope is one per record: one
/// for all the records of a set, as the manoeuvre's own response would be, left a tanker's
/// slow fall of speed over its own turning history to the harmonics (KVLCC2: a wind read on
/// effect-free trials with the anemometer showing none). On records that turn through full
/// circles the turned heading is a slow trend the harmonics hardly see.
pub(super) fn turned(psi: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(psi.len());
    let mut acc = 0.0;
    let mut prev = psi.first().copied().unwrap_or(0.0);
    for &p in psi {
        if p.is_finite() {
            acc += (p - prev + 180.0).rem_euclid(360.0) - 180.0;
            prev = p;
        }
        out.push(acc.to_radians());
    }
    let mean = out.iter().sum::<f64>() / out.len().max(1) as f64;
    out.iter_mut().for_each(|v| *v -= mean);
    out
}

/// A record's heading as the ground track's regression reads it, per sample: its harmonics
/// (sin ψ, cos ψ, sin 2ψ, cos 2ψ) and the heading turned through ([`turned`]).
struct Heading {
    harmonics: Vec<[f64; 4]>,
    turned: Vec<f64>,
}

/// The [`Heading`] of every record; `None` when a record has no heading.
fn headings(recs: &[&Record]) -> Option<Vec<Heading>> {
    recs.iter()
        .map(|r| {
            let psi = r.psi.as_ref()?;
            Some(Heading {
                harmonics: psi
                    .iter()
                    .map(|p| {
                        let ph = p.to_radians();
                        [ph.sin(), ph.cos(), (2.0 * ph).sin(), (2.0 * ph).cos()]
                    })
                    .collect(),
                turned: turned(psi),
            })
        })
        .collect()
}

/// Time constants (s) of the low-pass nuisance regressors of speed over ground: a surge
/// equation `(m − X_u̇) u̇ = X(u) + X_rr r² + X_δδ δ² + …` makes the speed lost in turns a
/// first-order lag of r² and δ² with the surge time constant `T_u = (m − X_u̇)/(−∂X/∂u)`,
/// which is not known here and spans ≈ 10 s on a model ship to ≈ 15 minutes on a
/// full-scale tanker (KVLCC2 at 15.5 kn: `m ≈ 3.3·10⁵ t`, `−∂X/∂u ≈ 2R/U ≈ 4·10⁵ N·s/m`,
/// `T_u ≈ 850 s`). A first-order lag anywhere in 10–810 s is matched closely by a combination
/// of its two neighbours in this bank (ratio 3); with one fixed time constant, or a bank that
/// stops short of the hull's, the unmatched part of the speed loss — on a full-scale hull
/// the slow fall from the approach speed over the first turns — follows the turning history,
/// and with it the heading, and passes for a current. Time constants longer than half the
/// shortest record are dropped (over so short a record the per-record intercept and the
/// shorter lags take what they would).
pub(super) fn sog_taus<'a>(recs: impl Iterator<Item = &'a Record>) -> Vec<f64> {
    let shortest = recs
        .map(|r| r.len() as f64 * r.ts)
        .fold(f64::INFINITY, f64::min);
    let mut out: Vec<f64> = SOG_TAUS_S
        .iter()
        .copied()
        .filter(|tau| *tau <= 0.5 * shortest)
        .collect();
    if out.is_empty() {
        out.push(SOG_TAUS_S[0]);
    }
    out
}

/// The bank of surge time constants (s) of [`sog_taus`].
const SOG_TAUS_S: [f64; 5] = [10.0, 30.0, 90.0, 270.0, 810.0];
/// Circular shifts drawn for the null covariance of the speed harmonics.
const SOG_SHIFTS: usize = 60;

/// Covariance of the harmonics under "no heading dependence": heading circularly shifted
/// against speed by random amounts (10–90 % of each record), which keeps both series'
/// own structure. The heading dependence the records show (`own`, their harmonics as
/// [`sog_harmonics`] gives them unshifted) is taken out first: a strong
/// one (a current of a knot) is itself a slow series, and shifted against the heading it
/// would pass for noise and hide itself.
fn sog_null_cov(
    lane: Lane,
    recs: &[&Record],
    heading: &[Heading],
    taus: &[f64],
    own: &DVector<f64>,
    rng: &mut ChaCha8Rng,
) -> Option<DMatrix<f64>> {
    let mut draws = Vec::with_capacity(SOG_SHIFTS);
    for _ in 0..SOG_SHIFTS {
        let sh: Vec<usize> = recs
            .iter()
            .map(|r| {
                let n = r.len();
                rng.random_range(n / 10..=(9 * n / 10).max(n / 10 + 1))
            })
            .collect();
        draws.push(sog_harmonics(
            sog_fit(lane, recs, heading, &sh, taus, Some(own))?,
            recs.len(),
        ));
    }
    let m = draws.len() as f64;
    let mean = draws.iter().fold(DVector::zeros(4), |a, b| a + b) / m;
    let mut cov = DMatrix::<f64>::zeros(4, 4);
    for d in &draws {
        let c = d - &mean;
        cov += &c * c.transpose();
    }
    Some(cov / (m - 1.0))
}

/// Wald χ² of `d` (subset `idx`) with covariance `v`.
fn wald(d: &DVector<f64>, v: &DMatrix<f64>, idx: &[usize]) -> f64 {
    let k = idx.len();
    let dd = DVector::from_iterator(k, idx.iter().map(|&i| d[i]));
    let vv = DMatrix::from_fn(k, k, |a, b| v[(idx[a], idx[b])]);
    match vv.try_inverse() {
        Some(inv) => dd.dot(&(inv * &dd)).max(0.0),
        None => 0.0,
    }
}

/// SOG evidence: the Wald χ² of the first and second harmonics (trial minus reference),
/// calibrated for the aliasing the records show without any current, the first-harmonic
/// amplitude (m/s) and the direction (deg) the speed gain points to.
///
/// The circular-shift null knows the noise of each series but not the speed lost in turns
/// that the surge lags leave: on a full-scale hull turning through part of a circle that
/// remainder follows the heading, and passes for a current. How much it does is measured on
/// the records themselves: each record against the others of its own set (reference, and
/// trials — a current common to the trials cancels there), the same statistic. `inflation`
/// is their mean χ² per degree of freedom (at least 1) and divides the χ²; the p-value is
/// then an F with the splits' degrees of freedom.
#[derive(Debug, Clone, Copy)]
pub(super) struct SogEvidence {
    /// χ² of the first harmonic (2 df), divided by `inflation[0]`.
    pub(super) chi1: f64,
    /// χ² of the second harmonic (2 df), divided by `inflation[1]`.
    pub(super) chi2: f64,
    /// The χ² before calibration (first, second harmonic).
    pub(super) raw: [f64; 2],
    /// Aliasing inflation of each harmonic's χ² (≥ 1).
    pub(super) inflation: [f64; 2],
    /// Degrees of freedom of the inflation estimate per harmonic (2 per split; ∞ when the
    /// inflation is 1: the χ² is then used as it is).
    pub(super) inflation_df: [f64; 2],
    pub(super) amp1: f64,
    pub(super) dir1: f64,
    pub(super) amp2: f64,
    /// Largest variance (m/s)² of the first harmonic in any direction (the circular-shift
    /// null's, times the inflation): what the records can resolve.
    pub(super) var1: f64,
    /// The current seen across the track as well, when every record logs course over
    /// ground.
    pub(super) cross: Option<CrossEvidence>,
    /// Each set's own heading harmonics of the ground velocity, root-sum-square over both
    /// harmonics and both lanes (m/s): `[trials, reference]`, the reference's 0 without one.
    pub(super) own: [f64; 2],
}

/// A uniform current seen by both components of the ground velocity: along the heading
/// (speed over ground's first harmonic, `(c_N, c_E) = (b_cos, b_sin)`) and across it (speed
/// over ground times the sine of course less heading, `(c_N, c_E) = (−b_sin, b_cos)`). Each
/// lane is calibrated on its own splits; the two estimates are combined by their inverse
/// calibrated covariances. A current moves both lanes alike; what else varies with heading
/// (speed lost in turns, wind drag and leeway) moves them differently, which `agree` tests.
#[derive(Debug, Clone, Copy)]
pub(super) struct CrossEvidence {
    /// Combined current (north, east; m/s), trial minus reference.
    pub(super) current: [f64; 2],
    /// Wald χ² (2 df) of the combined current against its calibrated covariance.
    pub(super) chi: f64,
    /// Denominator degrees of freedom of its F test (∞: none calibrated).
    pub(super) df: f64,
    /// Largest variance (m/s)² of the combined current in any direction.
    pub(super) var: f64,
    /// The cross-track lane alone: calibrated χ² (2 df) and its inflation.
    pub(super) cross_chi: f64,
    /// Inflation of the cross-track lane's χ² (≥ 1).
    pub(super) cross_inflation: f64,
    /// χ² (2 df) of the two lanes' currents' difference: large where the set is no uniform one.
    pub(super) agree: f64,
    /// How large the set is across the heading against along it.
    pub(super) shape: Option<super::set_shape::SetShape>,
}

impl CrossEvidence {
    /// Speed (m/s) and the direction it sets towards (deg).
    pub(super) fn speed_dir(&self) -> (f64, f64) {
        speed_towards(self.current)
    }
}

/// The speed (m/s) of a current `(north, east)` and the direction it sets towards (deg from
/// north, 0–360).
pub(super) fn speed_towards([n, e]: [f64; 2]) -> (f64, f64) {
    (n.hypot(e), e.atan2(n).to_degrees().rem_euclid(360.0))
}

impl SogEvidence {
    /// `(χ², df, p)` of what speed over ground shows: the first harmonic for a current, both
    /// for wind.
    pub(super) fn test(&self, current: bool) -> (f64, f64, f64) {
        if let (true, Some(c)) = (current, self.cross) {
            return (c.chi, 2.0, f_sf(c.chi / 2.0, 2.0, c.df));
        }
        if current {
            let p = f_sf(self.chi1 / 2.0, 2.0, self.inflation_df[0]);
            (self.chi1, 2.0, p)
        } else {
            let chi = self.chi1 + self.chi2;
            let d2 = self.inflation_df[0].min(self.inflation_df[1]) * 2.0;
            (chi, 4.0, f_sf(chi / 4.0, 4.0, d2))
        }
    }

    /// Whether the change the ground track shows is the reference's: its own heading
    /// harmonics at least as large as the trials' (a current or wind the reference sailed in
    /// and the trials did not). A missing effect is one the trials show more of.
    pub(super) fn the_references(&self) -> bool {
        self.own[1] > 0.0 && self.own[1] >= self.own[0]
    }

    /// The smallest current (m/s) speed over ground shows at the level `level` whatever its
    /// direction: the amplitude whose χ² (along the direction the records resolve worst)
    /// reaches the level's critical value.
    pub(super) fn smallest_current(&self, level: f64) -> f64 {
        if let Some(c) = self.cross {
            return (2.0 * f_quantile(level, 2.0, c.df) * c.var).sqrt();
        }
        let f = f_quantile(level, 2.0, self.inflation_df[0]);
        // χ²/inflation = a²/var1 = 2·F
        (2.0 * f * self.var1).sqrt()
    }

    /// The calibration in words, empty when the records show no aliasing.
    pub(super) fn calibration_words(&self, current: bool) -> String {
        let (phi, raw) = if current {
            (self.inflation[0], self.raw[0])
        } else {
            (
                0.5 * (self.inflation[0] + self.inflation[1]),
                self.raw[0] + self.raw[1],
            )
        };
        if phi <= 1.0 {
            return String::new();
        }
        format!(
            "; χ² {raw:.1} divided by {phi:.1}: the records vary with heading by as much \
             against each other without a current (speed lost in turns), so speed over ground \
             tells a current only beyond that"
        )
    }
}

pub(super) fn sog_evidence(
    trial: &[Record],
    reference: &[Record],
    seed: u64,
) -> Option<SogEvidence> {
    sog_evidence_with(
        trial,
        reference,
        seed,
        &sog_taus(trial.iter().chain(reference)),
    )
}

/// Harmonics of `trial` minus those of `reference` (none when empty) with the circular-shift
/// covariance of the difference, and each set's own harmonics' root-sum-square (m/s;
/// `[trial, reference]`, the reference's 0 when there is none).
fn sog_difference(
    lane: Lane,
    trial: &[&Record],
    reference: &[&Record],
    taus: &[f64],
    rng: &mut ChaCha8Rng,
) -> Option<(DVector<f64>, DMatrix<f64>, [f64; 2])> {
    let ht = headings(trial)?;
    let t = sog_harmonics(sog_fit(lane, trial, &ht, &[], taus, None)?, trial.len());
    let vt = sog_null_cov(lane, trial, &ht, taus, &t, rng)?;
    if reference.is_empty() {
        let own = [t.norm(), 0.0];
        return Some((t, vt, own));
    }
    let hr = headings(reference)?;
    let r = sog_harmonics(
        sog_fit(lane, reference, &hr, &[], taus, None)?,
        reference.len(),
    );
    let vr = sog_null_cov(lane, reference, &hr, taus, &r, rng)?;
    let own = [t.norm(), r.norm()];
    Some((t - r, vt + vr, own))
}

/// One lane's harmonics (trial minus reference), their covariance, the χ² of the first
/// and second harmonic before calibration, and the calibration: inflation and its degrees
/// of freedom per harmonic, from each record against the others of its own set.
struct LaneStat {
    d: DVector<f64>,
    own: [f64; 2],
    v: DMatrix<f64>,
    raw: [f64; 2],
    inflation: [f64; 2],
    inflation_df: [f64; 2],
}

fn lane_stat(
    lane: Lane,
    trial: &[&Record],
    reference: &[&Record],
    taus: &[f64],
    rng: &mut ChaCha8Rng,
) -> Option<LaneStat> {
    let (d, v, own) = sog_difference(lane, trial, reference, taus, rng)?;
    // each record against the others of its set: the aliasing without a current
    let mut sums = [0.0; 2];
    let mut splits = 0usize;
    for set in [reference, trial] {
        if set.len() < 2 {
            continue;
        }
        for j in 0..set.len() {
            let rest: Vec<&Record> = (0..set.len()).filter(|&i| i != j).map(|i| set[i]).collect();
            if let Some((dj, vj, _)) = sog_difference(lane, &set[j..=j], &rest, taus, rng) {
                sums[0] += wald(&dj, &vj, &[0, 1]);
                sums[1] += wald(&dj, &vj, &[2, 3]);
                splits += 1;
            }
        }
    }
    let raw = [wald(&d, &v, &[0, 1]), wald(&d, &v, &[2, 3])];
    let mut inflation = [1.0; 2];
    let mut inflation_df = [f64::INFINITY; 2];
    for k in 0..2 {
        if splits > 0 {
            let phi = sums[k] / (2.0 * splits as f64);
            if phi > 1.0 {
                inflation[k] = phi;
                inflation_df[k] = 2.0 * splits as f64;
            }
        }
    }
    Some(LaneStat {
        d,
        own,
        v,
        raw,
        inflation,
        inflation_df,
    })
}

/// [`sog_evidence`] with the nuisance time constants given.
pub(super) fn sog_evidence_with(
    trial: &[Record],
    reference: &[Record],
    seed: u64,
    taus: &[f64],
) -> Option<SogEvidence> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5047_5f53_4f47);
    let trial: Vec<&Record> = trial.iter().collect();
    let reference: Vec<&Record> = reference.iter().collect();
    let a = lane_stat(Lane::Along, &trial, &reference, taus, &mut rng)?;
    let with_course = trial.iter().chain(&reference).all(|r| r.cog.is_some());
    let x = if with_course {
        lane_stat(Lane::Cross, &trial, &reference, taus, &mut rng)
    } else {
        None
    };
    let cross = x.as_ref().and_then(|x| combine_current(&a, x));
    let own = x.as_ref().map_or(a.own, |x| {
        [a.own[0].hypot(x.own[0]), a.own[1].hypot(x.own[1])]
    });
    let (d, v, inflation) = (&a.d, &a.v, a.inflation);
    Some(SogEvidence {
        chi1: a.raw[0] / inflation[0],
        chi2: a.raw[1] / inflation[1],
        raw: a.raw,
        inflation,
        inflation_df: a.inflation_df,
        amp1: d[0].hypot(d[1]),
        dir1: d[0].atan2(d[1]).to_degrees().rem_euclid(360.0),
        amp2: d[2].hypot(d[3]),
        var1: inflation[0] * largest_eigenvalue(v[(0, 0)], v[(0, 1)], v[(1, 1)]),
        cross,
        own,
    })
}

/// The current of each lane as (north, east) with its calibrated covariance, combined.
fn combine_current(a: &LaneStat, x: &LaneStat) -> Option<CrossEvidence> {
    // along: (c_N, c_E) = (b_cos, b_sin); across: (c_N, c_E) = (−b_sin, b_cos)
    let ca = nalgebra::Vector2::new(a.d[1], a.d[0]);
    let va =
        nalgebra::Matrix2::new(a.v[(1, 1)], a.v[(1, 0)], a.v[(0, 1)], a.v[(0, 0)]) * a.inflation[0];
    let cx = nalgebra::Vector2::new(-x.d[0], x.d[1]);
    let vx = nalgebra::Matrix2::new(x.v[(0, 0)], -x.v[(0, 1)], -x.v[(1, 0)], x.v[(1, 1)])
        * x.inflation[0];
    let (ia, ix) = (va.try_inverse()?, vx.try_inverse()?);
    let info = ia + ix;
    let cov = info.try_inverse()?;
    let c = cov * (ia * ca + ix * cx);
    let chi = c.dot(&(info * c)).max(0.0);
    let diff = ca - cx;
    let agree = (va + vx)
        .try_inverse()
        .map_or(0.0, |i| diff.dot(&(i * diff)).max(0.0));
    Some(CrossEvidence {
        current: [c[0], c[1]],
        chi,
        df: a.inflation_df[0].min(x.inflation_df[0]),
        var: largest_eigenvalue(cov[(0, 0)], cov[(0, 1)], cov[(1, 1)]),
        cross_chi: x.raw[0] / x.inflation[0],
        cross_inflation: x.inflation[0],
        agree,
        shape: super::set_shape::SetShape::of(ca, &va, cx, &vx),
    })
}

/// Largest eigenvalue of the symmetric 2×2 matrix `[[a, b], [b, c]]`.
fn largest_eigenvalue(a: f64, b: f64, c: f64) -> f64 {
    0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::augment::sig;
    use crate::diagnose::caveat::Caveat;
    use crate::sim::{simulate_with_nav, InputSpec, NoiseSpec, Scenario, Ship};

    #[test]
    fn the_heading_turned_through_is_unwrapped_and_centred() {
        // through north and back: 350 → 10 → 350°, sampled every 10°
        let psi = [350.0, 0.0, 10.0, 0.0, 350.0];
        let t: Vec<f64> = turned(&psi).iter().map(|v| v.to_degrees()).collect();
        let want = [-8.0, 2.0, 12.0, 2.0, -8.0];
        for (a, b) in t.iter().zip(want) {
            assert!((a - b).abs() < 1e-9, "{t:?}");
        }
        // two full turns at 90° a sample span 720°, centred on their mean
        let psi: Vec<f64> = (0..9).map(|i| f64::from(i * 90 % 360)).collect();
        let t = turned(&psi);
        assert!((t[8] - t[0] - 4.0 * std::f64::consts::PI).abs() < 1e-12);
        assert!(t.iter().sum::<f64>().abs() < 1e-9);
        // a missing heading holds the last turn
        let t = turned(&[0.0, f64::NAN, 20.0]);
        assert!((t[1] - t[0]).abs() < 1e-12 && (t[2] - t[1] - 20f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn the_speed_straight_ahead_is_speed_over_ground_less_current_and_turns() {
        // a ship circling slowly at 5 m/s through the water, a 0.8 m/s current from the
        // north-east carrying it, 0.02 (m/s)/(°/s)² lost to the turn rate (lagged 30 s)
        let rec = |seed: u64, u0: f64| {
            let n = 1_800;
            let mut r = Record::from_uy(
                &format!("c{seed}"),
                1.0,
                (0..n).map(|t| 10.0 * (0.01 * t as f64).sin()).collect(),
                (0..n)
                    .map(|t| 0.6 + 0.4 * (0.013 * t as f64 + seed as f64).sin())
                    .collect(),
            );
            let mut psi = 0.0f64;
            let (mut lag, mut psis, mut sog) = (0.0f64, Vec::new(), Vec::new());
            for t in 0..n {
                psis.push(psi.rem_euclid(360.0));
                lag += (r.y[t] * r.y[t] - lag) / 30.0;
                let c = 0.8 * (psi - 225.0).to_radians().cos();
                sog.push(u0 + c - 0.02 * lag);
                psi += r.y[t];
            }
            r.psi = Some(psis);
            r.speed = Some(sog);
            r
        };
        let set = |u0: f64| (1..=3).map(|s| rec(s, u0)).collect::<Vec<_>>();
        let u = straight_speed(&set(5.0)).unwrap();
        assert!((u - 5.0).abs() < 0.05, "{u}");
        let slow = straight_speed(&set(4.0)).unwrap();
        assert!((slow - 4.0).abs() < 0.05, "{slow}");
        // 20 % slower is told (the ground track resolves 0.1 m/s), 5 % is not, nor 20 %
        // where a current as large could not be told apart
        let c = crate::diagnose::caveat::other_speed(Some([slow, u]), None, 0.1).unwrap();
        assert!(c.explain().contains("(-20 %"), "{}", c.explain());
        assert!(
            c.explain().contains("`simulate --speed 3.99`"),
            "{}",
            c.explain()
        );
        assert_eq!(
            crate::diagnose::caveat::other_speed(Some([4.8, 5.0]), None, 0.1),
            None
        );
        assert_eq!(
            crate::diagnose::caveat::other_speed(Some([slow, u]), None, 1.5),
            None
        );
        // no heading, no speed
        let mut bare = set(5.0);
        bare[1].psi = None;
        assert_eq!(straight_speed(&bare), None);
    }

    /// Zig-zag 20°/20° records of the built-in ship, as `bench/worlds/run.sh
    /// --trial-input zigzag:20/20 --ref-input zigzag:20/20` sails them (with `trial` the
    /// trials' noise, else the reference's).
    fn zigzags(seeds: &[u64], trial: bool) -> Vec<Record> {
        zigzags_of(&Ship::default_lng(), seeds, trial)
    }

    /// [`zigzags`] of `ship`.
    fn zigzags_of(ship: &Ship, seeds: &[u64], trial: bool) -> Vec<Record> {
        let sc = Scenario {
            input: InputSpec::ZigZag {
                delta_deg: 20.0,
                psi_deg: 20.0,
            },
            noise: NoiseSpec {
                gyro_std_degps: if trial { 0.03 } else { 0.02 },
                heading_std_deg: if trial { 0.2 } else { 0.1 },
                speed_std_mps: if trial { 0.02 } else { 0.0 },
            },
            log_wind: true,
            ..Scenario::default()
        };
        // the built-in ship logs its course beside the record, as `simulate` writes it
        seeds
            .iter()
            .map(|&s| {
                let (mut r, nav) = simulate_with_nav(ship, &sc, s).unwrap();
                r.cog = Some(nav.cog_deg);
                r
            })
            .collect()
    }

    #[test]
    fn a_zig_zags_own_sway_and_speed_are_no_current() {
        // effect-free zig-zags against a zig-zag reference sailed from other headings: each
        // record's heading spans some 60°, so within a record the harmonics are (nearly)
        // the heading turned through, and the sway and speed of each swing move with it.
        // Without the slope on the heading turned through, the ground track read a current
        // of 0.31 m/s here (χ² 39 on 2 df, p < 10⁻³; the ship sails at 1.1 m/s), and
        // `diagnose` named it on the effect-free trials of `bench/worlds/run.sh`
        let level = 0.01 / 10.0;
        let reference = zigzags(&[900, 901, 902], false);
        let trial = zigzags(&[100, 101, 102], true);
        let s = sog_evidence(&trial, &reference, 1).unwrap();
        let (chi, _, p) = s.test(true);
        println!(
            "{:?}: χ² {chi:.1}, p {p:.3}",
            s.cross.map(|c| c.speed_dir())
        );
        assert!(p > 0.05, "{s:?}");
        // nor wind's harmonics
        assert!(s.test(false).2 > level, "{s:?}");
    }

    #[test]
    fn zig_zags_at_another_speed_show_it_over_the_ground_on_their_courses() {
        // one-course zig-zags of the built-in ship, its pods at 10.5 rev/s (the reference,
        // and trials with other noise and headings) and at 8.0 (slower trials)
        let reference = zigzags(&[900, 901, 902], false);
        let same = zigzags(&[100, 101, 102], true);
        let mut ship = Ship::default_lng();
        ship.pods.rps = 8.0;
        let slow = zigzags_of(&ship, &[100, 101, 102], true);
        let [r, t, s] = [&reference, &same, &slow].map(|x| course_speed(x).unwrap());
        println!("course speed: reference {r:.3}, trials {t:.3}, slower trials {s:.3} m/s");
        assert!((t / r - 1.0).abs() < 0.03, "{t} {r}");
        assert!((s / r - 1.0) < -0.2, "{s} {r}");
        // their ground track cannot resolve a current as large (here: from 1 m/s on), so
        // the caveat says both readings; the same speed gives none
        let c = crate::diagnose::caveat::other_speed(None, Some([s, r]), 1.0).unwrap();
        let words = c.explain();
        assert!(
            matches!(
                c,
                Caveat::OtherSpeed {
                    told_from_current: false,
                    ..
                }
            ),
            "{c:?}"
        );
        assert!(
            words.contains("over the ground on their courses"),
            "{words}"
        );
        assert!(
            words.contains(&format!("a current of about {} m/s", sig(r - s))),
            "{words}"
        );
        assert!(
            words.contains(&format!("`simulate --speed {}`", sig(s))),
            "{words}"
        );
        assert_eq!(
            crate::diagnose::caveat::other_speed(None, Some([t, r]), 1.0),
            None
        );
        // a difference the ground track does resolve is left to the speed through the
        // water: none here, as none was given
        assert_eq!(
            crate::diagnose::caveat::other_speed(None, Some([s, r]), 0.1),
            None
        );
    }
}
