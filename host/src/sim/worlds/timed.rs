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
        self.timed(InputSpec::default())
    }

    /// The autopilot of [`InputSpec::autopilot`] for this hull: its rate gain and its holds
    /// stretched by the hull's time `L_pp/U` over the built-in ship's, as the PRBS holds
    /// are ([`World::default_input`]).
    ///
    /// ```
    /// use yawcast::sim::{InputSpec, World, WorldKind};
    /// let lng = World::new(WorldKind::Lng, None).unwrap();
    /// assert_eq!(lng.default_autopilot(), InputSpec::autopilot());
    /// let InputSpec::Autopilot(a) =
    ///     World::new(WorldKind::Kvlcc2, None).unwrap().default_autopilot() else { panic!() };
    /// assert!(a.kd_s > 20.0, "{}", a.kd_s);
    /// ```
    pub fn default_autopilot(&self) -> InputSpec {
        self.timed(InputSpec::autopilot())
    }

    /// `spec` for this hull: as given on the built-in ship, else stretched by the hull's time
    /// over the built-in ship's ([`InputSpec::stretched`]).
    fn timed(&self, spec: InputSpec) -> InputSpec {
        if self.kind == WorldKind::Lng {
            spec
        } else {
            spec.stretched(self.time_ratio())
        }
    }
}
