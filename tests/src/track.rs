//! The heading/track part of the bit-exactness tests: a reference model with a track part,
//! navigation inputs derived deterministically from the recorded trajectory (with missing,
//! non-finite and jumping values), and the native run of predictor and tracker.
//!
//! `golden/track.bin`: per step, four status bytes (yaw-rate update, velocity, fix, reset)
//! and TRACK_HORIZON rows of three little-endian f32 (ψ̂, n, e).

use yawcast_firmware::track::{sin_cos_deg, Correction, NavMeasurement, Tracker};
use yawcast_firmware::Predictor;
use yawcast_shared::model::{Effect, ModelSpec};
use yawcast_shared::nav::TrackSpec;

use crate::data::Trajectory;
use crate::{status_code, with_effects, HORIZON, STEPS};

/// Rows of heading and track predicted at every step (t+1 … t+TRACK_HORIZON).
pub const TRACK_HORIZON: usize = HORIZON;

/// The reference model of the track tests: the base model with a gyro offset (so `− d_y`
/// is exercised) and a track part with sway, speed loss, the current and non-default gains.
///
/// # Panics
/// Never (fixed valid parameters).
pub fn track_model() -> (ModelSpec, TrackSpec) {
    let m = with_effects(&[Effect::GyroBias { d_y: 0.12 }]);
    let mut t = TrackSpec::new(m.ts, 1.3, true).expect("valid track part");
    t.sway = -0.07;
    t.speed_loss = 0.009;
    t.gain_speed = 0.08;
    t.gain_current = 0.004;
    t.fix_current = 0.003;
    (m, t)
}

/// Navigation inputs for every sample: a ground velocity 1.3 m/s along the logged heading
/// (the last finite one where it is missing) plus a current (0.3, −0.2) m/s, missing at every
/// 97th sample, NaN at t = 150, a 20 m/s jump at t = 400; a fix every 10th sample from the
/// integrated velocity, 5 km off at t = 600, NaN at t = 700. Pure f32 arithmetic: the same
/// bits on every machine.
pub fn nav_inputs(traj: &Trajectory) -> Vec<NavMeasurement> {
    let mut psi = 0.0f32;
    let mut pos = [0.0f32; 2];
    let mut out = Vec::with_capacity(traj.u.len());
    for t in 0..traj.u.len() {
        if let Some(p) = traj.psi[t].filter(|p| p.is_finite()) {
            psi = p;
        }
        let (s, c) = sin_cos_deg(psi);
        let v = [1.3 * c + 0.3, 1.3 * s - 0.2];
        let velocity = match t {
            150 => Some([f32::NAN, 0.0]),
            400 => Some([20.0, 0.0]),
            _ if t % 97 == 3 => None,
            _ => Some(v),
        };
        let fix = match t {
            600 => Some([pos[0] + 5000.0, pos[1]]),
            700 => Some([f32::NAN, pos[1]]),
            _ if t % 10 == 0 => Some(pos),
            _ => None,
        };
        out.push(NavMeasurement { velocity, fix });
        pos = [pos[0] + traj.ts * v[0], pos[1] + traj.ts * v[1]];
    }
    out
}

/// One step of the track record: status codes and the predicted rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackStepOut {
    /// Yaw-rate update (0 corrected, 1 skipped, 2 reset), velocity and fix
    /// (0 absent, 1 applied, 2 rejected, 3 gated), track reset (0 or 1).
    pub status: [u8; 4],
    /// `[ψ̂, n, e]` at t+1 … t+TRACK_HORIZON.
    pub rows: [[f32; 3]; TRACK_HORIZON],
}

/// Status code of a navigation correction, as stored in the golden file.
pub fn correction_code(c: Correction) -> u8 {
    match c {
        Correction::Absent => 0,
        Correction::Applied => 1,
        Correction::Rejected => 2,
        Correction::Gated => 3,
    }
}

/// Runs predictor and tracker (this machine's build) over the trajectory: at each step the
/// yaw-rate update, the track update with the rate the predictor used, the yaw-rate
/// prediction and the track prediction from it.
///
/// # Panics
/// When a prediction fails (the reference model is stable).
pub fn run_track_native(
    model: &ModelSpec,
    track: &TrackSpec,
    traj: &Trajectory,
    nav: &[NavMeasurement],
) -> Vec<TrackStepOut> {
    let mut p = Predictor::<4>::new(model).expect("order-4 model");
    let mut tr = Tracker::new(model, track).expect("valid track part");
    (0..STEPS)
        .map(|t| {
            let before = p.prediction();
            let s = status_code(p.update_with_heading(traj.u[t], traj.y[t], traj.psi[t]));
            let rate = if traj.y[t].is_finite() {
                traj.y[t]
            } else {
                before
            };
            let ts = tr.update(rate, traj.psi[t], &nav[t]);
            let mut yhat = [0.0f32; TRACK_HORIZON];
            p.predict_into(&mut yhat, traj.future_u(t))
                .expect("prediction of a stable model");
            let mut rows = [[0.0f32; 3]; TRACK_HORIZON];
            tr.predict_into(&mut rows, &yhat)
                .expect("track prediction of a stable model");
            TrackStepOut {
                status: [
                    s,
                    correction_code(ts.velocity),
                    correction_code(ts.fix),
                    u8::from(ts.reset),
                ],
                rows,
            }
        })
        .collect()
}

/// Serialises a track record.
pub fn encode_track_golden(steps: &[TrackStepOut]) -> Vec<u8> {
    let mut out = Vec::with_capacity(steps.len() * (4 + 12 * TRACK_HORIZON));
    for s in steps {
        out.extend_from_slice(&s.status);
        for row in &s.rows {
            for v in row {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    out
}

/// Parses a track record.
///
/// # Errors
/// When the length is not a whole number of steps.
pub fn decode_track_golden(bytes: &[u8]) -> Result<Vec<TrackStepOut>, String> {
    let step = 4 + 12 * TRACK_HORIZON;
    if bytes.len() % step != 0 {
        return Err(format!(
            "track golden file of {} bytes is not whole steps",
            bytes.len()
        ));
    }
    Ok(bytes
        .chunks(step)
        .map(|c| {
            let mut rows = [[0.0f32; 3]; TRACK_HORIZON];
            for (k, row) in rows.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    let o = 4 + 12 * k + 4 * j;
                    *v = f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
                }
            }
            TrackStepOut {
                status: [c[0], c[1], c[2], c[3]],
                rows,
            }
        })
        .collect())
}
