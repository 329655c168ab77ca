//! The test worlds' own k-step predictor: the hull's simulator replayed from the true state
//! `k` samples back with the logged commands, its random processes decaying from their
//! values there towards their means.

use super::{dynamics, Integrator, State, Weather};

/// What a replay needs of one run: every sample's state, weather and steering gear, the
/// commands, and the random processes' time constants.
pub(super) struct Replay<'a> {
    pub(super) step: Integrator<'a>,
    pub(super) states: &'a [(State, Weather)],
    pub(super) gears: &'a [dynamics::Actuator],
    pub(super) cmds: &'a [f64],
    pub(super) tau_background_s: f64,
    pub(super) tau_gust_s: f64,
    /// The gyro's drift at every sample (deg/s).
    pub(super) drift: &'a [f64],
    pub(super) tau_drift_s: f64,
    pub(super) gyro_bias_degps: f64,
}

/// The weather `j` samples after `w0` as seen from there: a first-order process's
/// conditional mean decays by `exp(−j·Ts/τ)`.
fn expected(w0: Weather, j: usize, ts: f64, r: &Replay<'_>) -> Weather {
    let decay = |tau: f64| (-(j as f64) * ts / tau).exp();
    Weather {
        moment: w0.moment * decay(r.tau_background_s),
        gust: 1.0 + (w0.gust - 1.0) * decay(r.tau_gust_s),
    }
}

/// The predicted true yaw rate (rad/s) of every sample from the state `horizon` samples
/// back (from the first sample for the first `horizon`).
pub(super) fn rates(r: &Replay<'_>, horizon: usize) -> Vec<f64> {
    let ts = r.step.ts;
    (0..r.states.len())
        .map(|t| {
            let k0 = t.saturating_sub(horizon);
            let (mut s, w0) = r.states[k0];
            let mut gear = r.gears[k0].clone();
            for j in 0..t - k0 {
                let k = k0 + j;
                r.step
                    .sample(k, &mut s, &mut gear, &r.cmds[..=k], expected(w0, j, ts, r));
            }
            s[2]
        })
        .collect()
}

/// The predicted gyro reading (deg/s): the rate of [`rates`] plus the offset and the drift
/// decayed from its value `horizon` samples back.
pub(super) fn predict(r: &Replay<'_>, horizon: usize) -> Vec<f64> {
    let ts = r.step.ts;
    rates(r, horizon)
        .into_iter()
        .enumerate()
        .map(|(t, rate)| {
            let k0 = t.saturating_sub(horizon);
            let decay = (-((t - k0) as f64) * ts / r.tau_drift_s).exp();
            rate.to_degrees() + r.gyro_bias_degps + r.drift[k0] * decay
        })
        .collect()
}
