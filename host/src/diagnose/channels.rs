//! The heading and speed-over-ground channels: the gyro offset the heading shows, the
//! heading harmonics of speed over ground (speed lost in turns taken out through a bank of
//! surge lags) with their null covariance, and what each channel adds to an effect's evidence.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use yawcast_shared::model::EffectKind;

use super::verdict::{cfg_m, Evidence};
use super::{heading_bias, DiagnoseConfig};
use crate::effects::{def, Channel};
use crate::io::data::Record;
use crate::stats::{chi2_sf, normal_sf};

/// What heading and speed over ground show on the trials against the reference: whether
/// every record logs them, the gyro offset the heading shows (trial minus reference when
/// there is a reference; offset and standard error, °/s) and the speed-over-ground evidence.
#[derive(Debug, Clone, Copy)]
pub(super) struct Channels {
    /// Heading is logged in every record.
    pub(super) heading_ok: bool,
    /// Heading and speed over ground are logged in every record.
    pub(super) speed_ok: bool,
    /// The gyro offset the heading shows and its standard error.
    pub(super) hb: Option<(f64, f64)>,
    /// The heading harmonics of speed over ground.
    pub(super) sog: Option<SogEvidence>,
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
            let t = heading_bias(est);
            let r = if has_ref {
                heading_bias(reference)
            } else {
                None
            };
            t.map(|t| match r {
                Some(r) => (t.bias - r.bias, t.se.hypot(r.se)),
                None => (t.bias, t.se),
            })
        } else {
            None
        };
        let sog = if speed_ok {
            sog_evidence(est, if has_ref { reference } else { &[] }, seed)
        } else {
            None
        };
        Channels {
            heading_ok,
            speed_ok,
            hb,
            sog,
        }
    }
}

/// Coefficients of (sin ψ, cos ψ, sin 2ψ, cos 2ψ) in speed over ground; nuisance: one
/// intercept per record and r² and δ² low-passed through each time constant of
/// [`sog_taus`] (speed lost in turns and to rudder/pod drag, whatever the ship's surge time
/// constant). `shift[i]` circularly shifts record i's heading against its speed (0: aligned).
fn sog_harmonics(recs: &[Record], shift: &[usize], taus: &[f64]) -> Option<DVector<f64>> {
    let nr = recs.len();
    let nt = taus.len();
    let p = nr + 4 + 2 * nt;
    let mut xtx = DMatrix::<f64>::zeros(p, p);
    let mut xty = DVector::<f64>::zeros(p);
    let mut x = DVector::<f64>::zeros(p);
    for (i, r) in recs.iter().enumerate() {
        let psi = r.psi.as_ref()?;
        let sp = r.speed.as_ref()?;
        let a: Vec<f64> = taus.iter().map(|tau| (r.ts / tau).min(1.0)).collect();
        let mut lr = vec![0.0; nt];
        let mut lu = vec![0.0; nt];
        let n = r.len();
        let sh = shift.get(i).copied().unwrap_or(0) % n.max(1);
        for t in 0..n {
            let ph = psi[(t + sh) % n].to_radians();
            let h = [ph.sin(), ph.cos(), (2.0 * ph).sin(), (2.0 * ph).cos()];
            x.fill(0.0);
            x[i] = 1.0;
            for (j, hj) in h.iter().enumerate() {
                x[nr + j] = *hj;
            }
            for k in 0..nt {
                lr[k] += a[k] * (r.y[t] * r.y[t] - lr[k]);
                lu[k] += a[k] * (r.u[t] * r.u[t] - lu[k]);
                x[nr + 4 + 2 * k] = lr[k];
                x[nr + 5 + 2 * k] = lu[k];
            }
            xtx.ger(1.0, &x, &x, 1.0);
            xty.axpy(sp[t], &x, 1.0);
        }
    }
    // the filter bank's columns are strongly correlated: a relative ridge keeps the solve
    // well posed without moving the (orthogonal) heading harmonics
    let ridge = 1e-9 * (xtx.trace() / p as f64).max(1e-300);
    for j in 0..p {
        xtx[(j, j)] += ridge;
    }
    let beta = xtx.cholesky()?.solve(&xty);
    Some(beta.rows(nr, 4).into_owned())
}

/// Time constants (s) of the low-pass nuisance regressors of speed over ground: a surge
/// equation `(m − X_u̇) u̇ = X(u) + X_rr r² + X_δδ δ² + …` makes the speed lost in turns a
/// first-order lag of r² and δ² with the surge time constant `T_u = (m − X_u̇)/(−∂X/∂u)`,
/// which is not known here and spans ≈ 10 s on a model ship to minutes on a large one. A
/// first-order lag anywhere in 10–270 s is matched closely by a combination of its two
/// neighbours in this bank (ratio 3); with one fixed time constant the unmatched part of the
/// speed loss follows the turning history, and with it the heading, and passes for a
/// current. Time constants longer than a quarter of the shortest record are dropped (the
/// per-record intercept already takes what they would).
pub(super) fn sog_taus<'a>(recs: impl Iterator<Item = &'a Record>) -> Vec<f64> {
    let shortest = recs
        .map(|r| r.len() as f64 * r.ts)
        .fold(f64::INFINITY, f64::min);
    let mut out: Vec<f64> = SOG_TAUS_S
        .iter()
        .copied()
        .filter(|tau| *tau <= 0.25 * shortest)
        .collect();
    if out.is_empty() {
        out.push(SOG_TAUS_S[0]);
    }
    out
}

/// The bank of surge time constants (s) of [`sog_taus`].
const SOG_TAUS_S: [f64; 4] = [10.0, 30.0, 90.0, 270.0];
/// Circular shifts drawn for the null covariance of the speed harmonics.
const SOG_SHIFTS: usize = 60;

/// Covariance of the harmonics under "no heading dependence": heading circularly shifted
/// against speed by random amounts (10–90 % of each record), which keeps both series'
/// own structure.
fn sog_null_cov(recs: &[Record], taus: &[f64], rng: &mut ChaCha8Rng) -> Option<DMatrix<f64>> {
    let mut draws = Vec::with_capacity(SOG_SHIFTS);
    for _ in 0..SOG_SHIFTS {
        let sh: Vec<usize> = recs
            .iter()
            .map(|r| {
                let n = r.len();
                rng.random_range(n / 10..=(9 * n / 10).max(n / 10 + 1))
            })
            .collect();
        draws.push(sog_harmonics(recs, &sh, taus)?);
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

/// SOG evidence: (χ² first harmonic, χ² second harmonic, first-harmonic amplitude m/s,
/// direction deg the speed gain points to).
#[derive(Debug, Clone, Copy)]
pub(super) struct SogEvidence {
    pub(super) chi1: f64,
    pub(super) chi2: f64,
    pub(super) amp1: f64,
    pub(super) dir1: f64,
    pub(super) amp2: f64,
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

/// [`sog_evidence`] with the nuisance time constants given.
pub(super) fn sog_evidence_with(
    trial: &[Record],
    reference: &[Record],
    seed: u64,
    taus: &[f64],
) -> Option<SogEvidence> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5047_5f53_4f47);
    let t = sog_harmonics(trial, &[], taus)?;
    let vt = sog_null_cov(trial, taus, &mut rng)?;
    let (d, v) = if reference.is_empty() {
        (t, vt)
    } else {
        let r = sog_harmonics(reference, &[], taus)?;
        let vr = sog_null_cov(reference, taus, &mut rng)?;
        (t - r, vt + vr)
    };
    Some(SogEvidence {
        chi1: wald(&d, &v, &[0, 1]),
        chi2: wald(&d, &v, &[2, 3]),
        amp1: d[0].hypot(d[1]),
        dir1: d[0].atan2(d[1]).to_degrees().rem_euclid(360.0),
        amp2: d[2].hypot(d[3]),
    })
}

/// What the heading and speed-over-ground channels add to the evidence of `ev.kind`: a gyro
/// bias judged on the heading, current and wind on speed over ground as well as on the yaw
/// channel (either may show them).
pub(super) fn add_channels(
    ev: &mut Evidence,
    has_ref: bool,
    cfg: &DiagnoseConfig,
    hb: Option<(f64, f64)>,
    sog: Option<SogEvidence>,
) {
    let kind = ev.kind;
    let p_yaw = ev.p_yaw;
    match def(kind).channel {
        Channel::Heading => {
            if let Some((b, se)) = hb {
                let z = b / se;
                ev.p = (2.0 * normal_sf(z.abs())).min(1.0);
                ev.statistic = z * z;
                ev.score = z * z - 1.0;
                ev.parameter = Some(b);
                ev.channel_material = true;
                ev.words = format!(
                    "the gyro reads {b:+.3} ± {se:.3} °/s more than the heading turns \
                     (mean r − mean dψ/dt{})",
                    if has_ref {
                        ", trial minus reference"
                    } else {
                        ""
                    }
                );
            }
        }
        Channel::SpeedOverGround => {
            if let Some(s) = sog {
                let (chi, df) = if kind == EffectKind::Current {
                    (s.chi1, 2.0)
                } else {
                    (s.chi1 + s.chi2, 4.0)
                };
                let p_sog = chi2_sf(chi, df);
                // either channel may show it (Bonferroni over the two)
                ev.p = (2.0 * p_yaw.min(p_sog)).min(1.0);
                ev.score = ev.score.max(chi - df);
                ev.channel_material = p_sog < cfg.alpha / cfg_m(cfg);
                if kind == EffectKind::Current {
                    ev.parameter = Some(s.amp1);
                    ev.words.push_str(&format!(
                        "; speed over ground varies by ±{:.3} m/s with heading, fastest heading \
                         {:.0}° (χ² = {chi:.1}, 2 df)",
                        s.amp1, s.dir1
                    ));
                } else {
                    ev.words.push_str(&format!(
                        "; speed over ground varies with heading by ±{:.3} m/s (1st harmonic) and \
                         ±{:.3} m/s (2nd) (χ² = {chi:.1}, 4 df)",
                        s.amp1, s.amp2
                    ));
                }
            }
        }
        // the channels carry nothing of the actuator and hull effects, nor of a moment
        Channel::None => {}
    }
}
