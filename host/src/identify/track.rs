//! Heading and track prediction in f64: the host's twin of the firmware's track predictor
//! (`yawcast_firmware::track`, same steps in the same order), and its evaluation on records —
//! heading fit per horizon and track error (m) per horizon.
//!
//! The heading ψ is integrated from the yaw-rate prediction (less the gyro offset), the
//! position from the speed through water `U` along the heading plus the earth-frame current
//! `c`; `U` and `c` are corrected from the ground velocity (speed and course over ground) and
//! from position fixes by the fixed-gain observer of [`TrackSpec`]
//! (`docs/method.md`, heading and track). Firmware-exact f32 numbers come from the firmware
//! crate itself, never from here.

use crate::identify::model::Model;
use crate::identify::predict::{fit, Stepper};
use crate::io::data::Record;
use crate::io::nav::Nav;
use yawcast_shared::nav::TrackSpec;

/// What happened to one navigation correction (the firmware's `Correction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Correction {
    /// No measurement.
    Absent,
    /// Applied.
    Applied,
    /// Not finite: skipped.
    Rejected,
    /// Innovation beyond its gate (a jump): skipped.
    Gated,
}

/// The f64 tracker state (the firmware's `TrackState`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackState {
    /// Heading ψ̂ (deg) at the next sample.
    pub psi: f64,
    /// Heading vector as propagated.
    pub h: [f64; 2],
    /// Position (n, e) in metres at the next sample.
    pub pos: [f64; 2],
    /// Speed through water (m/s).
    pub speed: f64,
    /// Current (c_n, c_e) in m/s.
    pub current: [f64; 2],
}

/// The f64 heading/track predictor.
///
/// ```
/// use yawcast::identify::track::Tracker64;
/// use yawcast_shared::nav::TrackSpec;
/// let mut t = Tracker64::new(1.0, 0.0, &TrackSpec::new(1.0, 2.0, false).unwrap());
/// t.update(0.0, Some(90.0), None, None);
/// let out = t.predict(&[0.0, 0.0]);
/// assert!((out[2][2] - 6.0).abs() < 1e-12); // due east at 2 m/s
/// ```
#[derive(Debug, Clone)]
pub struct Tracker64 {
    spec: TrackSpec,
    ts: f64,
    kr: f64,
    kk: f64,
    kl: f64,
    d_y: f64,
    st: TrackState,
}

impl Tracker64 {
    /// A tracker for sample time `ts`, gyro offset `d_y` (0 without) and track part `spec`.
    pub fn new(ts: f64, d_y: f64, spec: &TrackSpec) -> Tracker64 {
        Tracker64 {
            spec: *spec,
            ts,
            kr: ts * std::f64::consts::PI / 180.0,
            kk: ts * f64::from(spec.sway),
            kl: ts * f64::from(spec.speed_loss),
            d_y,
            st: Self::start(spec),
        }
    }

    fn start(spec: &TrackSpec) -> TrackState {
        TrackState {
            psi: 0.0,
            h: [1.0, 0.0],
            pos: [0.0, 0.0],
            speed: f64::from(spec.speed),
            current: [0.0, 0.0],
        }
    }

    /// The state.
    pub fn state(&self) -> TrackState {
        self.st
    }

    /// One sample: heading `psi` (deg) when logged, ground velocity `(v_n, v_e)` and fix
    /// `(n, e)` when measured, and the yaw rate used at this sample. Returns the two
    /// corrections, the corrected position (before the time update) and whether the state
    /// went non-finite and was reset.
    pub fn update(
        &mut self,
        rate: f64,
        psi: Option<f64>,
        velocity: Option<[f64; 2]>,
        fix: Option<[f64; 2]>,
    ) -> (Correction, Correction, [f64; 2], bool) {
        let sp = self.spec;
        let mut st = self.st;
        if let Some(p) = psi.filter(|p| p.is_finite()) {
            st.psi = p;
            let (s, c) = p.to_radians().sin_cos();
            st.h = [c, s];
        }
        let h = st.h;
        let w = rate - self.d_y;
        let sw = f64::from(self.spec.sway) * w;
        let ul = st.speed - f64::from(self.spec.speed_loss) * (w * w);
        let gate_v = f64::from(sp.gate_velocity);
        let gate_p = f64::from(sp.gate_position);
        let vel = match velocity {
            None => Correction::Absent,
            Some(v) if !(v[0].is_finite() && v[1].is_finite()) => Correction::Rejected,
            Some(v) => {
                let nu = [
                    v[0] - (ul * h[0] - sw * h[1] + st.current[0]),
                    v[1] - (ul * h[1] + sw * h[0] + st.current[1]),
                ];
                if !(nu[0].abs() <= gate_v && nu[1].abs() <= gate_v) {
                    Correction::Gated
                } else {
                    st.speed += f64::from(sp.gain_speed) * (h[0] * nu[0] + h[1] * nu[1]);
                    if sp.current {
                        let g = f64::from(sp.gain_current);
                        st.current = [st.current[0] + g * nu[0], st.current[1] + g * nu[1]];
                    }
                    Correction::Applied
                }
            }
        };
        let fx = match fix {
            None => Correction::Absent,
            Some(m) if !(m[0].is_finite() && m[1].is_finite()) => Correction::Rejected,
            Some(m) => {
                let mu = [m[0] - st.pos[0], m[1] - st.pos[1]];
                if !(mu[0].abs() <= gate_p && mu[1].abs() <= gate_p) {
                    Correction::Gated
                } else {
                    let a = f64::from(sp.gain_position);
                    st.pos = [st.pos[0] + a * mu[0], st.pos[1] + a * mu[1]];
                    st.speed += f64::from(sp.fix_speed) * (h[0] * mu[0] + h[1] * mu[1]);
                    if sp.current {
                        let k = f64::from(sp.fix_current);
                        st.current = [st.current[0] + k * mu[0], st.current[1] + k * mu[1]];
                    }
                    Correction::Applied
                }
            }
        };
        let corrected = st.pos;
        self.dead_reckon(&mut st, w);
        st.psi += self.ts * w;
        st.h = self.rot(st.h, w);
        let finite = [
            st.psi,
            st.h[0],
            st.h[1],
            st.pos[0],
            st.pos[1],
            st.speed,
            st.current[0],
            st.current[1],
        ]
        .iter()
        .all(|v| v.is_finite());
        self.st = if finite { st } else { Self::start(&sp) };
        (vel, fx, corrected, !finite)
    }

    fn dead_reckon(&self, st: &mut TrackState, w: f64) {
        let ku = self.ts * st.speed - self.kl * (w * w);
        let ks = self.kk * w;
        let kn = self.ts * st.current[0];
        let ke = self.ts * st.current[1];
        st.pos = [
            st.pos[0] + ku * st.h[0] - ks * st.h[1] + kn,
            st.pos[1] + ku * st.h[1] + ks * st.h[0] + ke,
        ];
    }

    fn rot(&self, h: [f64; 2], w: f64) -> [f64; 2] {
        let d = self.kr * w;
        let q = 1.0 - d * d * 0.5;
        [h[0] * q - h[1] * d, h[1] * q + h[0] * d]
    }

    /// Heading and position `[ψ̂, n, e]` at t+1 … t+1+len(rates) from the yaw rates
    /// ŷ(t+1|t) … (the firmware's `predict_into` with H = `rates.len() + 1`).
    pub fn predict(&self, rates: &[f64]) -> Vec<[f64; 3]> {
        let st = self.st;
        let ku = self.ts * st.speed;
        let kn = self.ts * st.current[0];
        let ke = self.ts * st.current[1];
        let (mut psi, mut h, mut n, mut e) = (st.psi, st.h, st.pos[0], st.pos[1]);
        let mut out = Vec::with_capacity(rates.len() + 1);
        out.push([psi, n, e]);
        for &r in rates {
            let w = r - self.d_y;
            let ks = self.kk * w;
            let kw = ku - self.kl * (w * w);
            n = n + kw * h[0] - ks * h[1] + kn;
            e = e + kw * h[1] + ks * h[0] + ke;
            psi += self.ts * w;
            h = self.rot(h, w);
            out.push([psi, n, e]);
        }
        out
    }
}

/// Heading fit and track error of a model with a track part on one record.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackEval {
    /// Horizons of the heading fit (steps) and the fit % of ψ̂(t+k|t).
    pub heading_fit: Vec<(usize, f64)>,
    /// The same from the yaw-rate prediction integrated alone (no gyro offset taken out).
    pub heading_fit_rate_only: Vec<(usize, f64)>,
    /// Track horizons (s) and the median distance (m) between predicted and measured
    /// displacement over that horizon; `None` when the record is too short.
    pub track_error_m: Vec<(f64, Option<f64>)>,
    /// Ground-velocity corrections applied, rejected (not finite) and gated (jumps).
    pub velocity_counts: [usize; 3],
    /// Position fixes applied, rejected and gated.
    pub fix_counts: [usize; 3],
    /// Times the tracker went non-finite and was reset.
    pub resets: usize,
}

/// Evaluates the model's heading and track prediction on `rec` with navigation data `nav`:
/// heading fit at `heading_steps` (needs a logged heading), track error at `track_secs`
/// (only with `nav`; without it the track errors are `None`).
///
/// # Errors
/// A message when the record has no heading (the heading is where the track starts from).
pub fn evaluate(
    model: &Model,
    track: &TrackSpec,
    rec: &Record,
    nav: Option<&Nav>,
    heading_steps: &[usize],
    track_secs: &[f64],
) -> Result<TrackEval, String> {
    let psi = rec
        .psi
        .as_ref()
        .ok_or_else(|| format!("{}: no heading logged: the track needs one", rec.name))?;
    let n = rec.len();
    let ts = rec.ts;
    let track_steps: Vec<usize> = track_secs
        .iter()
        .map(|s| (s / ts).round().max(1.0) as usize)
        .collect();
    let kmax = heading_steps
        .iter()
        .chain(&track_steps)
        .copied()
        .max()
        .unwrap_or(1);
    let stepper = Stepper::new(model);
    let x0 = crate::identify::predict::estimate_x0(model, rec);
    let mut st = stepper.initial(&x0, psi[0]);
    let mut tr = Tracker64::new(ts, model.d_y(), track);
    let mut w = st.clone();
    let mut psi_hat = vec![vec![f64::NAN; n]; heading_steps.len()];
    let mut psi_rate = vec![vec![f64::NAN; n]; heading_steps.len()];
    let mut errs: Vec<Vec<f64>> = vec![Vec::new(); track_steps.len()];
    let mut vc = [0usize; 3];
    let mut fc = [0usize; 3];
    let mut resets = 0;
    let count = |c: Correction, into: &mut [usize; 3]| match c {
        Correction::Applied => into[0] += 1,
        Correction::Rejected => into[1] += 1,
        Correction::Gated => into[2] += 1,
        Correction::Absent => {}
    };
    let mut rates = Vec::with_capacity(kmax);
    for t in 0..n {
        let yhat = stepper.output(&st);
        let y_used = if rec.y[t].is_finite() { rec.y[t] } else { yhat };
        let (v, f, origin, reset) = tr.update(
            y_used,
            Some(psi[t]),
            nav.and_then(|n| n.velocity(t)),
            nav.and_then(|n| n.fix(t)),
        );
        count(v, &mut vc);
        count(f, &mut fc);
        resets += usize::from(reset);
        stepper.step(&mut st, rec.u[t], rec.y[t], Some(psi[t]));
        let last = kmax.min(n - 1 - t);
        if last == 0 {
            continue;
        }
        // ŷ(t+1|t) … ŷ(t+last−1|t)
        w.clone_from(&st);
        rates.clear();
        for j in 1..last {
            rates.push(stepper.output(&w));
            stepper.step(&mut w, rec.u[t + j], f64::NAN, None);
        }
        let pred = tr.predict(&rates);
        for (i, &k) in heading_steps.iter().enumerate() {
            if k <= last {
                psi_hat[i][t + k] = pred[k - 1][0];
                let mut p = psi[t] + ts * y_used;
                for r in &rates[..k - 1] {
                    p += ts * r;
                }
                psi_rate[i][t + k] = p;
            }
        }
        if let Some(reference) = nav.and_then(Nav::reference) {
            for (i, &k) in track_steps.iter().enumerate() {
                if k <= last {
                    let dn = (pred[k - 1][1] - origin[0]) - (reference[t + k][0] - reference[t][0]);
                    let de = (pred[k - 1][2] - origin[1]) - (reference[t + k][1] - reference[t][1]);
                    let d = dn.hypot(de);
                    if d.is_finite() {
                        errs[i].push(d);
                    }
                }
            }
        }
    }
    let fits = |hat: &[Vec<f64>]| -> Vec<(usize, f64)> {
        heading_steps
            .iter()
            .zip(hat)
            .map(|(&k, p)| {
                let (y, yh): (Vec<f64>, Vec<f64>) = psi
                    .iter()
                    .zip(p)
                    .filter(|(_, h)| h.is_finite())
                    .map(|(a, b)| (*a, *b))
                    .unzip();
                (k, fit(&y, &yh))
            })
            .collect()
    };
    Ok(TrackEval {
        heading_fit: fits(&psi_hat),
        heading_fit_rate_only: fits(&psi_rate),
        track_error_m: track_secs
            .iter()
            .zip(errs)
            .map(|(&s, mut e)| (s, median(&mut e)))
            .collect(),
        velocity_counts: vc,
        fix_counts: fc,
        resets,
    })
}

/// The median of `v` (sorted in place), `None` when empty.
///
/// ```
/// use yawcast::identify::track::median;
/// assert_eq!(median(&mut [3.0, 1.0, 2.0, 10.0]), Some(2.5));
/// assert_eq!(median(&mut []), None);
/// ```
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// The track part fitted on reference records (heading and ground velocity logged, no
/// current): `U₀` and `λ` the least-squares line of the speed along the heading on the
/// squared yaw rate (`U₀ − λ·r²`), `κ` the least-squares slope of the
/// sideways ground velocity on the yaw rate (less `d_y`), the default observer gains of
/// [`TrackSpec::new`] for sample time `ts`, with the current part when `current`.
///
/// # Errors
/// A message when no record has both a heading and a ground velocity, or the fit is not a
/// valid track part.
///
/// ```
/// use yawcast::identify::track::fit_track;
/// use yawcast::io::{data::Record, nav::Nav};
/// let mut r = Record::from_uy("r", 1.0, vec![0.0; 4], vec![0.0, 1.0, -1.0, 2.0]);
/// r.psi = Some(vec![0.0; 4]);
/// // heading north, 2 m/s ahead and 0.1 m/s to starboard per deg/s of yaw rate
/// let v = r.y.iter().map(|y| [2.0, 0.1 * y]).collect();
/// let nav = Nav::new(1.0, Some(v), None, "t").unwrap();
/// let t = fit_track(1.0, 0.0, &[(&r, &nav)], false).unwrap();
/// assert_eq!((t.speed, t.sway, t.speed_loss), (2.0, 0.1, 0.0));
/// ```
pub fn fit_track(
    ts: f64,
    d_y: f64,
    data: &[(&Record, &Nav)],
    current: bool,
) -> Result<TrackSpec, String> {
    let (mut sum_u, mut n, mut srl, mut srr) = (0.0, 0usize, 0.0, 0.0);
    // along = U₀ − λ·r²: sums for the 2 × 2 normal equations in (U₀, λ)
    let (mut sq, mut sq2, mut suq) = (0.0, 0.0, 0.0);
    for (rec, nav) in data {
        let Some(psi) = rec.psi.as_ref() else {
            continue;
        };
        for t in 0..rec.len() {
            let Some(v) = nav.velocity(t) else { break };
            let r = rec.y[t] - d_y;
            if !(v[0].is_finite() && v[1].is_finite() && r.is_finite()) {
                continue;
            }
            let (s, c) = psi[t].to_radians().sin_cos();
            let along = v[0] * c + v[1] * s;
            sum_u += along;
            sq += r * r;
            sq2 += r * r * r * r;
            suq += along * r * r;
            let lat = -v[0] * s + v[1] * c;
            srl += r * lat;
            srr += r * r;
            n += 1;
        }
    }
    if n == 0 {
        return Err("no record with both a heading and a ground velocity".into());
    }
    let nf = n as f64;
    let det = nf * sq2 - sq * sq;
    let (u0, lambda) = if det > 1e-12 * nf * sq2 {
        // [n, −Σq; Σq, −Σq²]·(U₀, λ) = (Σa, Σa·q), q = r²
        let u0 = (sum_u * sq2 - sq * suq) / det;
        let lambda = (sum_u * sq - nf * suq) / det;
        (u0, lambda)
    } else {
        (sum_u / nf, 0.0)
    };
    let mut spec = TrackSpec::new(ts as f32, u0 as f32, current).map_err(|e| e.to_string())?;
    spec.speed_loss = lambda as f32;
    spec.sway = if srr > 0.0 { (srl / srr) as f32 } else { 0.0 };
    spec.validate(ts as f32).map_err(|e| e.to_string())?;
    Ok(spec)
}

#[cfg(test)]
#[path = "track_tests.rs"]
mod tests;
