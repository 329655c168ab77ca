//! The inputs of a test world timed to its hull: the identification PRBS and the autopilot.

use super::{World, WorldKind};
use crate::sim::InputSpec;

impl World {
    /// The identification input: the built-in ship's PRBS-like sequence (amplitudes 5–20°)
    /// with its holds (5–30 s) stretched by the hull's time `L_pp/U` over the built-in
    /// ship's, so the ship answers each hold alike.
    ///
    /// ```
    /// use yawcast::sim::{InputSpec, World, WorldKind};
    /// let lng = World::new(WorldKind::Lng, None).unwrap();
    /// assert_eq!(lng.default_input(), InputSpec::default());
    /// ```
    pub fn default_input(&self) -> InputSpec {
        let k = self.time_ratio();
        match InputSpec::default() {
            InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s,
                max_hold_s,
            } if self.kind != WorldKind::Lng => InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s: (min_hold_s * k).round(),
                max_hold_s: (max_hold_s * k).round(),
            },
            other => other,
        }
    }

    /// The autopilot of [`InputSpec::autopilot`] for this hull: its rate gain and its holds
    /// stretched by the hull's time `L_pp/U` over the built-in ship's, as the PRBS holds
    /// are ([`World::default_input`]).
    ///
    /// ```
    /// use yawcast::sim::{InputSpec, World, WorldKind};
    /// let lng = World::new(WorldKind::Lng, None).unwrap();
    /// assert_eq!(lng.default_autopilot(), InputSpec::autopilot());
    /// let InputSpec::Autopilot { kd_s, .. } =
    ///     World::new(WorldKind::Kvlcc2, None).unwrap().default_autopilot() else { panic!() };
    /// assert!(kd_s > 20.0, "{kd_s}");
    /// ```
    pub fn default_autopilot(&self) -> InputSpec {
        let k = self.time_ratio();
        match InputSpec::autopilot() {
            InputSpec::Autopilot {
                kp,
                kd_s,
                step_deg,
                min_hold_s,
                max_hold_s,
            } if self.kind != WorldKind::Lng => InputSpec::Autopilot {
                kp,
                kd_s: (kd_s * k).round(),
                step_deg,
                min_hold_s: (min_hold_s * k).round(),
                max_hold_s: (max_hold_s * k).round(),
            },
            other => other,
        }
    }
}
