//! Command inputs: pseudo-random identification sequences (paper §2.2) and deterministic
//! manoeuvres (step, constant angle, zig-zag), plus the seeded random streams.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::SimError;

/// What the autopilot commands during a run (angles in degrees, δ > 0 to starboard).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum InputSpec {
    /// PRBS-like identification sequence: the sign alternates, each level is held for a
    /// random whole number of samples between `min_hold_s` and `max_hold_s`, and its
    /// amplitude is drawn from `amplitudes_deg`. Alternating signs keep the ship from
    /// entering a circle, as the paper asks of identification trials.
    Prbs {
        /// Amplitudes to draw from (deg, `> 0`).
        amplitudes_deg: Vec<f64>,
        /// Shortest hold (s).
        min_hold_s: f64,
        /// Longest hold (s).
        max_hold_s: f64,
    },
    /// Zero, then `delta_deg` from `at_s` on.
    Step {
        /// Step size (deg).
        delta_deg: f64,
        /// Time of the step (s).
        at_s: f64,
    },
    /// A constant command from the start (turning circle).
    Constant {
        /// Command (deg).
        delta_deg: f64,
    },
    /// Closed-loop zig-zag: `+delta_deg` until the heading has changed by `+psi_deg`, then
    /// `-delta_deg` until it has changed by `-psi_deg`, and so on (checked at each sample).
    ZigZag {
        /// Pod angle (deg, `> 0`).
        delta_deg: f64,
        /// Heading change that triggers the switch (deg, `> 0`).
        psi_deg: f64,
    },
    /// Closed-loop course keeping, as a ship's autopilot logs it: a PD law
    /// `δ = −kp·(ψ − ψ_set) − kd_s·r` on the heading and yaw rate, clipped to ±35°, with the
    /// set course stepping by `step_deg` to either side of the first heading (the side
    /// alternating) after holds drawn between `min_hold_s` and `max_hold_s`. The command then
    /// answers the ship's own disturbances (gusts, the background yaw moment), as on a ship
    /// in service, rather than being chosen beforehand.
    Autopilot(Autopilot),
    /// Given commands, one per sample (at least `n_samples` of them).
    Sequence {
        /// Commands (deg).
        delta_deg: Vec<f64>,
    },
}

impl Default for InputSpec {
    /// PRBS-like, amplitudes 5, 10, 15 and 20°, holds of 5–30 s.
    fn default() -> Self {
        InputSpec::Prbs {
            amplitudes_deg: vec![5.0, 10.0, 15.0, 20.0],
            min_hold_s: 5.0,
            max_hold_s: 30.0,
        }
    }
}

/// The course-keeping law and schedule of [`InputSpec::Autopilot`] (in a scenario file its
/// fields sit beside `kind = "autopilot"`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Autopilot {
    /// Heading gain (deg of command per deg of heading error, `> 0`).
    pub kp: f64,
    /// Rate gain (deg of command per deg/s of yaw rate, `≥ 0`).
    pub kd_s: f64,
    /// Course change (deg, `> 0`).
    pub step_deg: f64,
    /// Shortest hold of a set course (s).
    pub min_hold_s: f64,
    /// Longest hold of a set course (s).
    pub max_hold_s: f64,
}

impl Default for Autopilot {
    /// Tuned for the built-in ship: heading gain 1, rate gain 20 s, course changes of 10°
    /// held 60–180 s.
    fn default() -> Self {
        Autopilot {
            kp: 1.0,
            kd_s: 20.0,
            step_deg: 10.0,
            min_hold_s: 60.0,
            max_hold_s: 180.0,
        }
    }
}

impl Autopilot {
    /// Checks the gains and the schedule, naming the field (`input.kd_s`, …).
    fn validate(&self) -> Result<(), SimError> {
        use super::ship::{finite, pos};
        pos("input.kp", self.kp)?;
        finite("input.kd_s", self.kd_s)?;
        if self.kd_s < 0.0 {
            return Err(SimError::invalid("input.kd_s", self.kd_s, ">= 0"));
        }
        pos("input.step_deg", self.step_deg)?;
        holds(self.min_hold_s, self.max_hold_s)
    }
}

impl InputSpec {
    /// The autopilot of [`InputSpec::Autopilot`] tuned for the built-in ship
    /// ([`Autopilot::default`]).
    ///
    /// ```
    /// use yawcast::sim::InputSpec;
    /// let InputSpec::Autopilot(a) = InputSpec::autopilot() else { panic!() };
    /// assert_eq!((a.kp, a.kd_s, a.step_deg), (1.0, 20.0, 10.0));
    /// ```
    pub fn autopilot() -> InputSpec {
        InputSpec::Autopilot(Autopilot::default())
    }
}

impl InputSpec {
    /// This input with its times — the holds, the autopilot's rate gain — multiplied by `k`
    /// and rounded to whole seconds: the same manoeuvre for a hull whose time `L_pp/U` is `k`
    /// times the built-in ship's. Inputs without such times come back unchanged.
    ///
    /// ```
    /// use yawcast::sim::InputSpec;
    /// let InputSpec::Prbs { min_hold_s, max_hold_s, .. } = InputSpec::default().stretched(2.04)
    /// else { panic!() };
    /// assert_eq!((min_hold_s, max_hold_s), (10.0, 61.0));
    /// ```
    pub fn stretched(self, k: f64) -> InputSpec {
        let t = |s: f64| (s * k).round();
        match self {
            InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s,
                max_hold_s,
            } => InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s: t(min_hold_s),
                max_hold_s: t(max_hold_s),
            },
            InputSpec::Autopilot(a) => InputSpec::Autopilot(Autopilot {
                kd_s: t(a.kd_s),
                min_hold_s: t(a.min_hold_s),
                max_hold_s: t(a.max_hold_s),
                ..a
            }),
            other => other,
        }
    }
}

/// Largest command the autopilot of [`InputSpec::Autopilot`] gives (deg).
pub(crate) const AUTOPILOT_MAX_DEG: f64 = 35.0;

/// Random streams of one seed: independent, so changing the noise settings leaves the
/// input sequence and the initial heading unchanged.
pub(crate) const STREAM_INPUT: u64 = 0;
/// Stream of the measurement noise.
pub(crate) const STREAM_NOISE: u64 = 1;
/// Stream of the initial heading.
pub(crate) const STREAM_HEADING: u64 = 2;

/// A ChaCha8 generator for `seed` on `stream`.
pub(crate) fn rng(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

pub(crate) use crate::stats::standard_normal as gauss;

/// Checks a pair of holds (s): both positive, the longest no shorter than the shortest.
fn holds(min_hold_s: f64, max_hold_s: f64) -> Result<(), SimError> {
    use super::ship::pos;
    pos("input.min_hold_s", min_hold_s)?;
    pos("input.max_hold_s", max_hold_s)?;
    if max_hold_s < min_hold_s {
        return Err(SimError::invalid(
            "input.max_hold_s",
            max_hold_s,
            ">= input.min_hold_s",
        ));
    }
    Ok(())
}

impl InputSpec {
    /// Checks the parameters against the run length `n` and sample time `ts`.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the field (`input.max_hold_s`).
    pub fn validate(&self, n: usize) -> Result<(), SimError> {
        use super::ship::{finite, pos};
        match self {
            InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s,
                max_hold_s,
            } => {
                if amplitudes_deg.is_empty() {
                    return Err(SimError::invalid(
                        "input.amplitudes_deg",
                        f64::NAN,
                        "at least one amplitude",
                    ));
                }
                for (i, &a) in amplitudes_deg.iter().enumerate() {
                    pos(&format!("input.amplitudes_deg[{i}]"), a)?;
                }
                holds(*min_hold_s, *max_hold_s)
            }
            InputSpec::Step { delta_deg, at_s } => {
                finite("input.delta_deg", *delta_deg)?;
                finite("input.at_s", *at_s)
            }
            InputSpec::Constant { delta_deg } => finite("input.delta_deg", *delta_deg),
            InputSpec::ZigZag { delta_deg, psi_deg } => {
                pos("input.delta_deg", *delta_deg)?;
                pos("input.psi_deg", *psi_deg)
            }
            InputSpec::Autopilot(a) => a.validate(),
            InputSpec::Sequence { delta_deg } => {
                if delta_deg.len() < n {
                    return Err(SimError::invalid(
                        "input.delta_deg",
                        delta_deg.len() as f64,
                        &format!("at least n_samples = {n} commands"),
                    ));
                }
                for (i, &d) in delta_deg.iter().take(n).enumerate() {
                    finite(&format!("input.delta_deg[{i}]"), d)?;
                }
                Ok(())
            }
        }
    }

    /// The open-loop command sequence (`None` for the closed-loop zig-zag and autopilot).
    pub(crate) fn open_loop(&self, n: usize, ts: f64, seed: u64) -> Option<Vec<f64>> {
        match self {
            InputSpec::Prbs {
                amplitudes_deg,
                min_hold_s,
                max_hold_s,
            } => Some(prbs(n, ts, amplitudes_deg, *min_hold_s, *max_hold_s, seed)),
            InputSpec::Step { delta_deg, at_s } => Some(
                (0..n)
                    .map(|k| {
                        if k as f64 * ts >= at_s - 1e-9 {
                            *delta_deg
                        } else {
                            0.0
                        }
                    })
                    .collect(),
            ),
            InputSpec::Constant { delta_deg } => Some(vec![*delta_deg; n]),
            InputSpec::ZigZag { .. } | InputSpec::Autopilot(_) => None,
            InputSpec::Sequence { delta_deg } => Some(delta_deg[..n].to_vec()),
        }
    }
}

/// The PRBS-like sequence of [`InputSpec::Prbs`].
fn prbs(n: usize, ts: f64, amps: &[f64], min_hold: f64, max_hold: f64, seed: u64) -> Vec<f64> {
    let mut r = rng(seed, STREAM_INPUT);
    let lo = ((min_hold / ts).round() as usize).max(1);
    let hi = ((max_hold / ts).round() as usize).max(lo);
    let mut sign = if r.random::<bool>() { 1.0 } else { -1.0 };
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let hold = r.random_range(lo..=hi);
        let amp = amps[r.random_range(0..amps.len())];
        for _ in 0..hold.min(n - out.len()) {
            out.push(sign * amp);
        }
        sign = -sign;
    }
    out
}

/// The command of a closed-loop input, decided at each sample from the ship's state.
#[derive(Debug, Clone)]
pub(crate) enum Closed {
    /// [`InputSpec::ZigZag`].
    ZigZag(ZigZagLogic),
    /// [`InputSpec::Autopilot`]: the gains and the set course of every sample (relative to
    /// the first heading, deg).
    Autopilot {
        kp: f64,
        kd_s: f64,
        set: Vec<f64>,
        psi0: Option<f64>,
    },
}

impl Closed {
    /// The closed loop of `spec` over `n` samples of `ts` (`None` for an open-loop input).
    pub(crate) fn of(spec: &InputSpec, n: usize, ts: f64, seed: u64) -> Option<Closed> {
        match *spec {
            InputSpec::ZigZag { delta_deg, psi_deg } => {
                Some(Closed::ZigZag(ZigZagLogic::new(delta_deg, psi_deg)))
            }
            InputSpec::Autopilot(a) => {
                // the set course: ±step about the first heading, alternating, PRBS-like holds
                let side = prbs(n, ts, &[a.step_deg], a.min_hold_s, a.max_hold_s, seed);
                Some(Closed::Autopilot {
                    kp: a.kp,
                    kd_s: a.kd_s,
                    set: side,
                    psi0: None,
                })
            }
            _ => None,
        }
    }

    /// The command at sample `k` for heading `psi_deg` (unwrapped) and yaw rate `r_degps`.
    pub(crate) fn command(&mut self, k: usize, psi_deg: f64, r_degps: f64) -> f64 {
        match self {
            Closed::ZigZag(z) => z.command(psi_deg),
            Closed::Autopilot {
                kp,
                kd_s,
                set,
                psi0,
            } => {
                let psi0 = *psi0.get_or_insert(psi_deg);
                let target = psi0 + set.get(k).or(set.last()).copied().unwrap_or(0.0);
                let e = psi_deg - target;
                let d = -*kp * e - *kd_s * r_degps;
                d.clamp(-AUTOPILOT_MAX_DEG, AUTOPILOT_MAX_DEG)
            }
        }
    }
}

/// The zig-zag switching logic on heading change (deg).
#[derive(Debug, Clone)]
pub(crate) struct ZigZagLogic {
    delta: f64,
    psi_sw: f64,
    psi0: Option<f64>,
    sign: f64,
    /// Switches so far.
    pub switches: usize,
}

impl ZigZagLogic {
    pub(crate) fn new(delta_deg: f64, psi_deg: f64) -> Self {
        ZigZagLogic {
            delta: delta_deg,
            psi_sw: psi_deg,
            psi0: None,
            sign: 1.0,
            switches: 0,
        }
    }

    /// The command for heading `psi_deg` (unwrapped); the first call fixes the base course.
    pub(crate) fn command(&mut self, psi_deg: f64) -> f64 {
        let psi0 = *self.psi0.get_or_insert(psi_deg);
        let dpsi = psi_deg - psi0;
        if (self.sign > 0.0 && dpsi >= self.psi_sw) || (self.sign < 0.0 && dpsi <= -self.psi_sw) {
            self.sign = -self.sign;
            self.switches += 1;
        }
        self.sign * self.delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prbs_alternates_holds_and_is_seeded() {
        let u = prbs(1800, 1.0, &[5.0, 10.0, 15.0, 20.0], 5.0, 30.0, 7);
        assert_eq!(u.len(), 1800);
        assert_eq!(u, prbs(1800, 1.0, &[5.0, 10.0, 15.0, 20.0], 5.0, 30.0, 7));
        assert_ne!(u, prbs(1800, 1.0, &[5.0, 10.0, 15.0, 20.0], 5.0, 30.0, 8));
        // segment lengths within 5..=30 samples (last one may be cut), signs alternate
        let mut seg = 1;
        let mut segs = Vec::new();
        for k in 1..u.len() {
            if u[k] == u[k - 1] {
                seg += 1;
            } else {
                assert!(u[k].signum() != u[k - 1].signum());
                segs.push(seg);
                seg = 1;
            }
        }
        assert!(segs.iter().all(|&s| (5..=30).contains(&s)), "{segs:?}");
        assert!(segs.len() > 1800 / 30);
        let levels: std::collections::BTreeSet<i64> = u.iter().map(|&x| x as i64).collect();
        assert_eq!(levels.len(), 8, "{levels:?}");
    }

    #[test]
    fn zigzag_logic_switches_on_heading() {
        let mut z = ZigZagLogic::new(10.0, 10.0);
        assert_eq!(z.command(100.0), 10.0);
        assert_eq!(z.command(109.9), 10.0);
        assert_eq!(z.command(110.0), -10.0);
        assert_eq!(z.command(95.0), -10.0);
        assert_eq!(z.command(90.0), 10.0);
        assert_eq!(z.switches, 2);
    }

    #[test]
    fn gauss_has_unit_variance() {
        let mut r = rng(1, STREAM_NOISE);
        let x: Vec<f64> = (0..20000).map(|_| gauss(&mut r)).collect();
        let m = x.iter().sum::<f64>() / x.len() as f64;
        let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / x.len() as f64;
        assert!(m.abs() < 0.03 && (v - 1.0).abs() < 0.05, "{m} {v}");
    }

    #[test]
    fn an_autopilot_reads_from_a_scenario_file_with_its_fields_beside_the_kind() {
        let spec: InputSpec = toml::from_str(
            "kind = \"autopilot\"\nkp = 2.0\nkd_s = 10.0\nstep_deg = 5.0\n\
             min_hold_s = 30.0\nmax_hold_s = 90.0\n",
        )
        .unwrap();
        let want = Autopilot {
            kp: 2.0,
            kd_s: 10.0,
            step_deg: 5.0,
            min_hold_s: 30.0,
            max_hold_s: 90.0,
        };
        assert_eq!(spec, InputSpec::Autopilot(want));
        assert_eq!(
            toml::to_string(&spec).unwrap().lines().next(),
            Some("kind = \"autopilot\"")
        );
        let typo = "kind = \"autopilot\"\nkp = 1.0\nkd = 1.0\nkd_s = 1.0\nstep_deg = 5.0\n\
                    min_hold_s = 30.0\nmax_hold_s = 90.0\n";
        let e = toml::from_str::<InputSpec>(typo).unwrap_err().to_string();
        assert!(e.contains("unknown field `kd`"), "{e}");
    }

    #[test]
    fn the_autopilot_steers_back_to_its_set_course() {
        let spec = InputSpec::Autopilot(Autopilot {
            kp: 2.0,
            kd_s: 10.0,
            step_deg: 10.0,
            min_hold_s: 5.0,
            max_hold_s: 5.0,
        });
        assert!(spec.validate(100).is_ok());
        assert_eq!(spec.open_loop(100, 1.0, 1), None);
        let mut c = Closed::of(&spec, 100, 1.0, 1).unwrap();
        let Closed::Autopilot { set, .. } = &c else {
            panic!()
        };
        // the set course alternates ±10° every 5 s
        let first = set[0];
        assert_eq!(first.abs(), 10.0);
        assert_eq!(set[4], first);
        assert_eq!(set[5], -first);
        // the first heading is the base course: δ = −2·(ψ − ψ₀ − set) − 10·r
        let d0 = c.command(0, 100.0, 0.0);
        assert_eq!(d0, 2.0 * first);
        assert_eq!(c.command(1, 100.0 + first, 0.5), -5.0);
        // clipped to ±35°
        assert_eq!(c.command(2, 100.0 + first + 30.0, 0.0), -AUTOPILOT_MAX_DEG);
        // a negative rate gain is refused, named
        let bad = InputSpec::Autopilot(Autopilot {
            kd_s: -1.0,
            ..Autopilot::default()
        });
        assert!(bad
            .validate(100)
            .unwrap_err()
            .to_string()
            .contains("input.kd_s"));
    }
}
