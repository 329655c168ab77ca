//! The world's own k-step predictor: the true simulator, started from the true state at
//! `t − k` and driven by the logged commands, as the yardstick of how well a model of the
//! records could predict them at all.
//!
//! On the built-in ship nothing random acts on the motion (wind and current are steady; the
//! gyro's noise is white), so from the true state the simulator predicts the noise-free gyro
//! reading at every horizon. On the test worlds the background yaw moment, the gusts and the
//! gyro's drift are first-order processes: the predictor knows their values at `t − k` and
//! lets them decay towards their means (their conditional expectations), as the best
//! predictor of such a world does.

use crate::identify::predict;
use crate::io::data::Record;

use super::{simulate_full, Scenario, Ship, SimError, SimNav};

/// The true simulator's k-step predictions of a record's logged yaw rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Oracle {
    /// Steps ahead `k`.
    pub horizon: usize,
    /// `ŷ(t | t − k)` for every sample (deg/s); the first `k` from the record's start.
    pub yaw_rate_degps: Vec<f64>,
}

impl Oracle {
    /// Fit % of the predictions to `rec`'s logged yaw rate, as
    /// [`predict::fit`](crate::identify::predict::fit) scores a model's.
    ///
    /// ```
    /// use yawcast::sim::{simulate_with_oracle, NoiseSpec, Scenario, Ship};
    /// let quiet = Scenario {
    ///     noise: NoiseSpec { gyro_std_degps: 0.0, ..NoiseSpec::default() },
    ///     ..Scenario::default()
    /// };
    /// let (rec, _, o) = simulate_with_oracle(&Ship::default_lng(), &quiet, 1, 10).unwrap();
    /// assert_eq!(o.fit(&rec), 100.0);
    /// ```
    pub fn fit(&self, rec: &Record) -> f64 {
        predict::fit(&rec.y, &self.yaw_rate_degps)
    }
}

/// [`simulate_with_nav`](super::simulate_with_nav) with the simulator's own `horizon`-step
/// predictions of the logged yaw rate: on the built-in ship, whose motion nothing random
/// disturbs, the noise-free gyro reading.
///
/// # Errors
/// As [`simulate`](super::simulate).
///
/// ```
/// use yawcast::sim::{simulate_with_oracle, Scenario, Ship};
/// let (rec, _, o) = simulate_with_oracle(&Ship::default_lng(), &Scenario::default(), 1, 10)
///     .unwrap();
/// let fit = o.fit(&rec);
/// assert!(fit > 90.0 && fit < 100.0, "{fit}");
/// ```
pub fn simulate_with_oracle(
    ship: &Ship,
    scenario: &Scenario,
    seed: u64,
    horizon: usize,
) -> Result<(Record, SimNav, Oracle), SimError> {
    let (rec, nav, truth) = simulate_full(ship, scenario, seed)?;
    Ok((
        rec,
        nav,
        Oracle {
            horizon,
            yaw_rate_degps: truth,
        },
    ))
}
