//! Residual analysis — where a model fails: whiteness of the one-step residuals (ACF with the
//! MATLAB `resid` band and a Ljung–Box p-value), input–residual cross-correlation with
//! MATLAB's band, the k-step error binned by regime (|δ|, |Δδ|, |r|, heading sector) and the
//! worst time windows with what was happening in them.
//!
//! The χ² distribution function behind the Ljung–Box p-value is [`crate::stats::chi2_sf`].

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::diagnose::compare::{check_inputs, InputError};
use crate::identify::model::Model;
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;
use crate::stats::chi2_sf;

/// The 99 % two-sided normal quantile used by MATLAB's `resid` bands.
pub const Z99: f64 = 2.58;

/// Auto- or cross-covariance sums pooled over records: `Σ_records Σ_t a(t+τ) b(t)` for
/// `τ = 0..=max_lag` (means removed per record), divided by the total sample count.
fn pooled_cov(a: &[Vec<f64>], b: &[Vec<f64>], max_lag: usize) -> Vec<f64> {
    let mut out = vec![0.0; max_lag + 1];
    let mut n_tot = 0usize;
    for (x, y) in a.iter().zip(b) {
        let n = x.len().min(y.len());
        if n == 0 {
            continue;
        }
        let mx = x.iter().sum::<f64>() / n as f64;
        let my = y.iter().sum::<f64>() / n as f64;
        for (tau, o) in out.iter_mut().enumerate() {
            let mut s = 0.0;
            for t in 0..n.saturating_sub(tau) {
                s += (x[t + tau] - mx) * (y[t] - my);
            }
            *o += s;
        }
        n_tot += n;
    }
    let nf = n_tot.max(1) as f64;
    out.iter().map(|v| v / nf).collect()
}

/// Normalised autocorrelation of `e` (pooled over records) at lags `0..=max_lag`.
///
/// ```
/// use yawcast::diagnose::resid::acf;
/// let e = vec![vec![1.0, -1.0, 1.0, -1.0, 1.0, -1.0]];
/// let r = acf(&e, 2);
/// assert_eq!(r[0], 1.0);
/// assert!(r[1] < -0.8);
/// ```
pub fn acf(e: &[Vec<f64>], max_lag: usize) -> Vec<f64> {
    let c = pooled_cov(e, e, max_lag);
    let c0 = c[0];
    if c0 <= 0.0 {
        let mut v = vec![0.0; max_lag + 1];
        v[0] = 1.0;
        return v;
    }
    c.iter().map(|v| v / c0).collect()
}

/// Ljung–Box portmanteau statistic over lags `1..=h` of a normalised ACF from `n` samples,
/// and its χ²(h) p-value.
///
/// ```
/// use yawcast::diagnose::resid::ljung_box;
/// let (q, p) = ljung_box(&[1.0, 0.0, 0.0], 100, 2);
/// assert_eq!(q, 0.0);
/// assert_eq!(p, 1.0);
/// ```
pub fn ljung_box(acf: &[f64], n: usize, h: usize) -> (f64, f64) {
    let h = h.min(acf.len().saturating_sub(1)).min(n.saturating_sub(1));
    let nf = n as f64;
    let mut q = 0.0;
    for k in 1..=h {
        q += acf[k] * acf[k] / (nf - k as f64);
    }
    q *= nf * (nf + 2.0);
    (q, if h == 0 { 1.0 } else { chi2_sf(q, h as f64) })
}

/// Settings of [`resid`].
#[derive(Debug, Clone, PartialEq)]
pub struct ResidConfig {
    /// Largest lag of the ACF and CCF (default 25).
    pub max_lag: usize,
    /// Horizon (steps) of the error binned by regime and of the worst windows (default 10).
    pub horizon: usize,
    /// Bins per regime variable (default 5, equal counts).
    pub bins: usize,
    /// Length of the worst-window search in seconds (default: 60 s, at least 3 horizons,
    /// at most a quarter of the record).
    pub window_s: Option<f64>,
    /// Worst windows to report (default 3).
    pub worst: usize,
}

impl Default for ResidConfig {
    fn default() -> Self {
        ResidConfig {
            max_lag: 25,
            horizon: 10,
            bins: 5,
            window_s: None,
            worst: 3,
        }
    }
}

/// A correlation function with its confidence band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Correlation {
    /// Lags (samples).
    pub lags: Vec<i64>,
    /// Normalised correlation per lag.
    pub values: Vec<f64>,
    /// ± band (99 %).
    pub band: f64,
    /// Lags (other than 0 for an ACF) outside the band.
    pub outside: Vec<i64>,
}

/// The k-step RMSE in one bin of a regime variable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bin {
    /// Label, e.g. `"5–10"`.
    pub label: String,
    /// Lower edge.
    pub lo: f64,
    /// Upper edge.
    pub hi: f64,
    /// Samples in the bin.
    pub count: usize,
    /// k-step RMSE in the bin (deg/s).
    pub rmse: f64,
    /// `rmse` relative to the overall k-step RMSE.
    pub ratio: f64,
}

/// The k-step error binned by one regime variable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Regime {
    /// Stable key: `abs_delta`, `abs_ddelta`, `abs_r`, `heading`.
    pub key: String,
    /// Human name with unit, e.g. `"|δ| (deg)"`.
    pub dimension: String,
    /// The bins.
    pub bins: Vec<Bin>,
}

/// One of the worst time windows and what happened in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// Record name.
    pub record: String,
    /// Start time (s).
    pub t_start: f64,
    /// End time (s).
    pub t_end: f64,
    /// k-step RMSE in the window (deg/s).
    pub rmse: f64,
    /// `rmse` relative to the record's k-step RMSE.
    pub ratio: f64,
    /// Mean k-step error in the window (deg/s).
    pub mean_error: f64,
    /// Largest |δ| (deg).
    pub max_abs_delta: f64,
    /// Largest one-step change |Δδ| (deg).
    pub max_abs_ddelta: f64,
    /// Whether the command changed sign with a large step.
    pub reversal: bool,
    /// Largest |r| (deg/s).
    pub max_abs_r: f64,
    /// What was happening, e.g. `"t = 412–470 s: fast pod reversal, |Δδ| = 18°"`.
    pub what: String,
}

/// Ljung–Box whiteness test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LjungBox {
    /// Statistic Q.
    pub q: f64,
    /// Degrees of freedom (lags tested).
    pub df: usize,
    /// χ² p-value.
    pub p_value: f64,
}

/// The result of [`resid`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidReport {
    /// One-step residual samples used (all records).
    pub samples: usize,
    /// One-step residual RMS (deg/s).
    pub rms: f64,
    /// ACF of the one-step residuals, lags 0..=max_lag, band ±2.58/√N.
    pub acf: Correlation,
    /// Residual–input cross-correlation, lags −max_lag..=max_lag (positive: input leads).
    pub ccf: Correlation,
    /// Ljung–Box test over lags 1..=max_lag.
    pub ljung_box: LjungBox,
    /// Whether the residuals pass both tests (LB p ≥ 0.01 and no CCF lag outside the band).
    pub white: bool,
    /// Horizon (steps) of the regime tables and worst windows.
    pub horizon: usize,
    /// Overall k-step RMSE (deg/s).
    pub k_rmse: f64,
    /// k-step error by regime.
    pub regimes: Vec<Regime>,
    /// The worst time windows, worst first.
    pub worst: Vec<Window>,
    /// One-line summary.
    pub summary: String,
}

/// Residual analysis of `model` on `data`.
///
/// # Errors
/// [`InputError`] when the model is invalid or a record does not match it, or is shorter than
/// `max(2·max_lag, 4·horizon)` samples.
///
/// ```
/// use yawcast::{io::data::Record, identify::model::Model, identify::predict, diagnose::resid::{resid, ResidConfig}};
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1]).unwrap();
/// let u: Vec<f64> = (0..400).map(|i| if (i * 37 / 11) % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let mut r = Record::from_uy("r", 1.0, u, vec![0.0; 400]);
/// r.y = predict::simulate(&m, &r, &[0.0, 0.0]);
/// let rep = resid(&m, &[r], &ResidConfig::default()).unwrap();
/// assert_eq!(rep.acf.values.len(), 26);
/// assert_eq!(rep.ccf.lags.len(), 51);
/// ```
///
/// Long: the residual tests one after another on the same residuals (whiteness,
/// cross-correlation, regimes, worst windows).
pub fn resid(model: &Model, data: &[Record], cfg: &ResidConfig) -> Result<ResidReport, InputError> {
    if cfg.max_lag == 0 || cfg.horizon == 0 || cfg.bins == 0 {
        return Err(InputError::Config(
            "max_lag, horizon and bins must be at least 1".into(),
        ));
    }
    check_inputs(model, data, (2 * cfg.max_lag).max(4 * cfg.horizon), "data")?;
    let k = cfg.horizon;
    let per: Vec<(Vec<f64>, Vec<f64>)> = data
        .par_iter()
        .map(|r| {
            let x0 = predict::estimate_x0(model, r);
            let e1: Vec<f64> = predict::one_step(model, r, &x0)
                .iter()
                .zip(&r.y)
                .map(|(p, y)| y - p)
                .collect();
            let ek: Vec<f64> = predict::predict(model, r, &x0, Horizon::Steps(k))
                .iter()
                .zip(&r.y)
                .map(|(p, y)| y - p)
                .collect();
            (e1, ek)
        })
        .collect();
    let e1: Vec<Vec<f64>> = per.iter().map(|p| p.0.clone()).collect();
    let ek: Vec<Vec<f64>> = per.iter().map(|p| p.1.clone()).collect();
    let us: Vec<Vec<f64>> = data.iter().map(|r| r.u.clone()).collect();
    let n: usize = e1.iter().map(Vec::len).sum();
    let nf = n as f64;
    let rms = (e1.iter().flatten().map(|v| v * v).sum::<f64>() / nf).sqrt();

    let l = cfg.max_lag;
    let ra = acf(&e1, l);
    let acf_band = Z99 / nf.sqrt();
    let acf_c = Correlation {
        lags: (0..=l as i64).collect(),
        outside: (1..=l)
            .filter(|&i| ra[i].abs() > acf_band)
            .map(|i| i as i64)
            .collect(),
        values: ra.clone(),
        band: acf_band,
    };
    let (q, p) = ljung_box(&ra, n, l);

    // CCF: R_eu(τ) = E[e(t+τ) u(t)], τ ≥ 0 from (e, u), τ < 0 from (u, e).
    let pos = pooled_cov(&e1, &us, l);
    let neg = pooled_cov(&us, &e1, l);
    let ce0 = pooled_cov(&e1, &e1, 0)[0];
    let ru = acf(&us, l);
    let cu0 = pooled_cov(&us, &us, 0)[0];
    let norm = (ce0 * cu0).sqrt();
    let mut lags = Vec::new();
    let mut vals = Vec::new();
    for tau in -(l as i64)..=(l as i64) {
        let v = if tau >= 0 {
            pos[tau as usize]
        } else {
            neg[(-tau) as usize]
        };
        lags.push(tau);
        vals.push(if norm > 0.0 { v / norm } else { 0.0 });
    }
    let mut s = 1.0;
    for kk in 1..=l {
        s += 2.0 * ra[kk] * ru[kk];
    }
    let ccf_band = Z99 * s.max(1e-3).sqrt() / nf.sqrt();
    let ccf_outside: Vec<i64> = lags
        .iter()
        .zip(&vals)
        .filter(|(_, v)| v.abs() > ccf_band)
        .map(|(t, _)| *t)
        .collect();
    let white = p >= 0.01 && ccf_outside.is_empty();

    // k-step error by regime (first k samples are pure simulation: left out).
    let mut rows: Vec<[f64; 5]> = Vec::new(); // |δ|, |Δδ|, |r|, ψ, e
    for (r, e) in data.iter().zip(&ek) {
        for t in k..r.len() {
            let lo = t + 1 - k;
            let mut mu = 0.0;
            let mut md = 0.0f64;
            for j in lo..=t {
                mu += r.u[j].abs();
                md = md.max((r.u[j] - r.u[j - 1]).abs());
            }
            let psi = r
                .psi
                .as_ref()
                .map(|p| p[t].rem_euclid(360.0))
                .unwrap_or(f64::NAN);
            rows.push([mu / k as f64, md, r.y[t].abs(), psi, e[t]]);
        }
    }
    let k_rmse = (rows.iter().map(|r| r[4] * r[4]).sum::<f64>() / rows.len().max(1) as f64).sqrt();
    let mut regimes = vec![
        quantile_regime(
            &rows,
            0,
            "abs_delta",
            "|δ| (deg, mean over the horizon)",
            cfg.bins,
            k_rmse,
        ),
        quantile_regime(
            &rows,
            1,
            "abs_ddelta",
            "|Δδ| (deg, largest step in the horizon)",
            cfg.bins,
            k_rmse,
        ),
        quantile_regime(&rows, 2, "abs_r", "|r| (deg/s)", cfg.bins, k_rmse),
    ];
    if data.iter().all(|r| r.psi.is_some()) {
        regimes.push(heading_regime(&rows, k_rmse));
    }

    let worst = worst_windows(data, &ek, k, cfg);
    let summary = format!(
        "one-step residual RMS {rms:.4} deg/s; Ljung–Box p = {p:.3} ({}); {} of {} input \
         cross-correlation lags outside the 99 % band; {k}-step RMSE {k_rmse:.4} deg/s",
        if p >= 0.01 { "white" } else { "not white" },
        ccf_outside.len(),
        lags.len()
    );
    Ok(ResidReport {
        samples: n,
        rms,
        acf: acf_c,
        ccf: Correlation {
            lags,
            values: vals,
            band: ccf_band,
            outside: ccf_outside,
        },
        ljung_box: LjungBox {
            q,
            df: l,
            p_value: p,
        },
        white,
        horizon: k,
        k_rmse,
        regimes,
        worst,
        summary,
    })
}

fn fmt_num(v: f64) -> String {
    if v.abs() >= 10.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// Equal-count bins of column `col` (edges at quantiles, duplicates merged).
fn quantile_regime(
    rows: &[[f64; 5]],
    col: usize,
    key: &str,
    dimension: &str,
    bins: usize,
    overall: f64,
) -> Regime {
    let mut v: Vec<f64> = rows.iter().map(|r| r[col]).collect();
    v.sort_by(f64::total_cmp);
    let mut edges: Vec<f64> = Vec::new();
    if let (Some(first), Some(last)) = (v.first(), v.last()) {
        edges.push(*first);
        for i in 1..bins {
            let q = v[(i * v.len() / bins).min(v.len() - 1)];
            if q > *edges.last().unwrap_or(&f64::NEG_INFINITY) {
                edges.push(q);
            }
        }
        if *last > *edges.last().unwrap_or(&f64::NEG_INFINITY) || edges.len() == 1 {
            edges.push(*last);
        }
    }
    let nb = edges.len().saturating_sub(1);
    let mut sse = vec![0.0; nb];
    let mut cnt = vec![0usize; nb];
    for r in rows {
        let x = r[col];
        // bin i holds [edges[i], edges[i+1]), the last one is closed
        let mut i = edges.partition_point(|e| *e <= x).saturating_sub(1);
        if i >= nb {
            i = nb.saturating_sub(1);
        }
        if nb > 0 {
            sse[i] += r[4] * r[4];
            cnt[i] += 1;
        }
    }
    let out = (0..nb)
        .map(|i| {
            let rm = if cnt[i] > 0 {
                (sse[i] / cnt[i] as f64).sqrt()
            } else {
                f64::NAN
            };
            Bin {
                label: format!("{}–{}", fmt_num(edges[i]), fmt_num(edges[i + 1])),
                lo: edges[i],
                hi: edges[i + 1],
                count: cnt[i],
                rmse: rm,
                ratio: rm / overall,
            }
        })
        .collect();
    Regime {
        key: key.into(),
        dimension: dimension.into(),
        bins: out,
    }
}

/// Eight 45° heading sectors centred on N, NE, E, …
fn heading_regime(rows: &[[f64; 5]], overall: f64) -> Regime {
    const NAMES: [&str; 8] = ["N", "NE", "E", "SE", "S", "SW", "W", "NW"];
    let mut sse = [0.0; 8];
    let mut cnt = [0usize; 8];
    for r in rows {
        if r[3].is_finite() {
            let i = (((r[3] + 22.5) / 45.0).floor() as usize) % 8;
            sse[i] += r[4] * r[4];
            cnt[i] += 1;
        }
    }
    let bins = (0..8)
        .map(|i| {
            let rm = if cnt[i] > 0 {
                (sse[i] / cnt[i] as f64).sqrt()
            } else {
                f64::NAN
            };
            let c = 45.0 * i as f64;
            Bin {
                label: NAMES[i].into(),
                lo: (c - 22.5).rem_euclid(360.0),
                hi: c + 22.5,
                count: cnt[i],
                rmse: rm,
                ratio: rm / overall,
            }
        })
        .collect();
    Regime {
        key: "heading".into(),
        dimension: "heading sector".into(),
        bins,
    }
}

/// The `cfg.worst` worst non-overlapping windows over all records.
fn worst_windows(data: &[Record], ek: &[Vec<f64>], k: usize, cfg: &ResidConfig) -> Vec<Window> {
    // record-wide thresholds for the words
    let mut steps: Vec<f64> = Vec::new();
    let mut mags: Vec<f64> = Vec::new();
    let mut rates: Vec<f64> = Vec::new();
    for r in data {
        for t in 1..r.len() {
            let d = (r.u[t] - r.u[t - 1]).abs();
            if d > 0.0 {
                steps.push(d);
            }
            mags.push(r.u[t].abs());
            rates.push(r.y[t].abs());
        }
    }
    let q90 = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() * 9 / 10).copied().unwrap_or(f64::INFINITY)
    };
    let (step90, mag90, rate90) = (q90(&mut steps), q90(&mut mags), q90(&mut rates));

    let mut cands: Vec<(f64, usize, usize, usize)> = Vec::new(); // (mse, rec, start, end)
    for (ri, (r, e)) in data.iter().zip(ek).enumerate() {
        let n = r.len();
        let w_default = (60.0 / r.ts).round() as usize;
        let w = cfg
            .window_s
            .map(|s| (s / r.ts).round() as usize)
            .unwrap_or(w_default)
            .max(3 * k)
            .min(n / 4)
            .max(2);
        if n <= k + w {
            continue;
        }
        let sq: Vec<f64> = e.iter().map(|v| v * v).collect();
        let mut s: f64 = sq[k..k + w].iter().sum();
        let mut best: Vec<(f64, usize)> = vec![(s, k)];
        for st in k + 1..=n - w {
            s += sq[st + w - 1] - sq[st - 1];
            best.push((s, st));
        }
        best.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut taken: Vec<usize> = Vec::new();
        for (v, st) in best {
            if taken.iter().all(|&o| st + w <= o || o + w <= st) {
                taken.push(st);
                cands.push((v / w as f64, ri, st, st + w));
                if taken.len() >= cfg.worst {
                    break;
                }
            }
        }
    }
    cands.sort_by(|a, b| b.0.total_cmp(&a.0));
    cands
        .into_iter()
        .take(cfg.worst)
        .map(|(mse, ri, a, b)| {
            let r = &data[ri];
            let e = &ek[ri];
            let rec_rmse =
                (e[k..].iter().map(|v| v * v).sum::<f64>() / (e.len() - k).max(1) as f64).sqrt();
            describe_window(r, e, a, b, mse.sqrt(), rec_rmse, (step90, mag90, rate90))
        })
        .collect()
}

fn describe_window(
    r: &Record,
    e: &[f64],
    a: usize,
    b: usize,
    rmse: f64,
    rec_rmse: f64,
    (step90, mag90, rate90): (f64, f64, f64),
) -> Window {
    let mut max_d = 0.0f64;
    let mut max_dd = 0.0f64;
    let mut max_r = 0.0f64;
    let mut reversal = false;
    for t in a..b {
        max_d = max_d.max(r.u[t].abs());
        max_r = max_r.max(r.y[t].abs());
        if t > 0 {
            let dd = (r.u[t] - r.u[t - 1]).abs();
            max_dd = max_dd.max(dd);
            if r.u[t] * r.u[t - 1] < 0.0 && dd >= step90 {
                reversal = true;
            }
        }
    }
    let mean_e = e[a..b].iter().sum::<f64>() / (b - a) as f64;
    let mut what = Vec::new();
    if reversal {
        what.push(format!("fast pod reversal, |Δδ| = {max_dd:.0}°"));
    } else if max_dd >= step90 {
        what.push(format!("large pod step, |Δδ| = {max_dd:.0}°"));
    }
    if max_d >= mag90 {
        what.push(format!("hard over, |δ| up to {max_d:.0}°"));
    }
    if max_r >= rate90 {
        what.push(format!("fast turn, |r| up to {max_r:.2} °/s"));
    }
    if mean_e.abs() > 0.5 * rmse {
        what.push(format!("steady offset, mean error {mean_e:+.3} °/s"));
    }
    if what.is_empty() {
        what.push("no distinctive manoeuvre".into());
    }
    if let Some(p) = &r.psi {
        let lo = p[a..b].iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p[a..b].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        what.push(format!("heading {lo:.0}–{hi:.0}°"));
    }
    let ratio = rmse / rec_rmse.max(f64::MIN_POSITIVE);
    let t0 = r.t.get(a).copied().unwrap_or(a as f64 * r.ts);
    let t1 = r.t.get(b - 1).copied().unwrap_or((b - 1) as f64 * r.ts);
    Window {
        record: r.name.clone(),
        t_start: t0,
        t_end: t1,
        rmse,
        ratio,
        mean_error: mean_e,
        max_abs_delta: max_d,
        max_abs_ddelta: max_dd,
        reversal,
        max_abs_r: max_r,
        what: format!(
            "t = {t0:.0}–{t1:.0} s ({}): {}; error RMS {rmse:.3} °/s, {ratio:.1}× the record's",
            r.name,
            what.join(", ")
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::model::Effect;
    use rand::{Rng, SeedableRng};

    fn noisy(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n).map(|_| rng.random::<f64>() - 0.5).collect()
    }

    #[test]
    fn white_noise_passes_and_coloured_noise_fails() {
        let e = noisy(4000, 1);
        let r = acf(std::slice::from_ref(&e), 25);
        let (_, p) = ljung_box(&r, 4000, 25);
        assert!(p > 0.01, "{p}");
        let c: Vec<f64> = (1..e.len()).map(|i| e[i] + 0.5 * e[i - 1]).collect();
        let r = acf(&[c], 25);
        let (_, p) = ljung_box(&r, 3999, 25);
        assert!(p < 1e-10, "{p}");
    }

    fn model() -> Model {
        Model::new(
            1.0,
            vec![-0.2, 0.3, -0.1, 0.6],
            vec![0.01, 0.03, 0.05, 0.02],
            vec![0.8, 0.5, 0.3, 0.2],
        )
        .unwrap()
    }

    fn record(truth: &Model, n: usize, seed: u64) -> Record {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut u = Vec::new();
        let mut cur = 0.0;
        for i in 0..n {
            if i % 17 == 0 {
                cur = [-20.0, -8.0, 8.0, 20.0][rng.random_range(0..4)];
            }
            u.push(cur);
        }
        let mut r = Record::from_uy("trial", 1.0, u, vec![0.0; n]);
        r.psi = Some((0..n).map(|i| (i as f64 * 0.7) % 360.0).collect());
        let clean = predict::simulate(truth, &r, &[0.0; 4]);
        let e = noisy(n, seed + 100);
        r.y = clean.iter().zip(&e).map(|(c, e)| c + 0.02 * e).collect();
        r
    }

    #[test]
    fn missing_dead_time_shows_in_the_ccf_and_worst_windows() {
        let m = model();
        let truth = m.clone().with_effect(Effect::DeadTime { samples: 2 });
        let r = record(&truth, 1500, 3);
        let rep = resid(&m, &[r], &ResidConfig::default()).unwrap();
        assert!(!rep.white);
        assert!(!rep.ccf.outside.is_empty());
        assert_eq!(rep.worst.len(), 3);
        assert!(rep.worst[0].ratio > 1.0);
        assert!(
            rep.worst[0].what.contains("|Δδ|") || rep.worst[0].what.contains("|δ|"),
            "{}",
            rep.worst[0].what
        );
        // errors are larger right after large steps
        let dd = &rep.regimes[1];
        assert_eq!(dd.key, "abs_ddelta");
        let last = dd.bins.last().unwrap();
        assert!(last.rmse > dd.bins[0].rmse, "{dd:?}");
        assert_eq!(rep.regimes.len(), 4);
        let json = serde_json::to_value(&rep).unwrap();
        assert!(json["ljung_box"]["p_value"].is_number());
    }

    #[test]
    fn own_data_is_white() {
        let m = model();
        // innovations-form data: y = model one-step prediction + white e
        let n = 3000;
        let mut r = record(&m, n, 5);
        let e = noisy(n, 9);
        let s = predict::Stepper::new(&m);
        let mut st = s.initial(&[0.0; 4], 0.0);
        for t in 0..n {
            let yhat = s.output(&st);
            r.y[t] = yhat + 0.05 * e[t];
            s.step(&mut st, r.u[t], r.y[t], None);
        }
        let rep = resid(&m, &[r], &ResidConfig::default()).unwrap();
        assert!(rep.ljung_box.p_value > 0.01, "{}", rep.summary);
        assert!(rep.ccf.outside.len() <= 2, "{:?}", rep.ccf.outside);
    }

    #[test]
    fn too_short_is_an_error() {
        let m = model();
        let r = Record::from_uy("x", 1.0, vec![0.0; 30], vec![0.0; 30]);
        let e = resid(&m, &[r], &ResidConfig::default()).unwrap_err();
        assert!(matches!(e, InputError::TooShort { needed: 50, .. }), "{e}");
    }
}
