//! The anemometer channel: the true wind it shows, trials against the reference.

use crate::io::data::{block_mean, Record};
use crate::stats::chi2_sf;

/// The true wind an anemometer shows: the ship's velocity over ground (speed and course
/// over ground) less its velocity through the air (the apparent wind, turned from the bow
/// to north by the heading). A current carries ship and anemometer alike and cancels; the
/// ship's own motion through still air cancels; what is left is the wind. Its mean over the
/// trials less its mean over the reference, with block-mean (batch) standard errors per
/// component (gusts and slow sensor errors are correlated in time), gives a Wald χ² at 2 df
/// of what lies beyond the instrument's floor ([`ANEMOMETER_FLOOR`] of the ship's speed):
/// an anemometer's own alignment and calibration errors make a true wind of their own out
/// of the ship's motion, and a statistic that counted them would find "wind" in any calm.
#[derive(Debug, Clone, Copy)]
pub(super) struct AnemometerEvidence {
    /// Mean true wind, trial minus reference (north, east; m/s, the way it blows).
    pub(super) wind: [f64; 2],
    /// The standard errors of `wind`'s components (m/s, block means).
    pub(super) se: [f64; 2],
    /// Wald χ² (2 df).
    pub(super) chi: f64,
    /// Its p-value.
    pub(super) p: f64,
    /// The instrument's floor (m/s): a wind up to this is not told from a calm.
    pub(super) floor: f64,
    /// Each set's own mean true wind speed (m/s): `[trials, reference]`, the reference's 0
    /// without one.
    pub(super) own: [f64; 2],
}

/// The share of the ship's speed an anemometer cannot tell from a calm: a vane 1° off the
/// bow line (1.7 %) and a cup reading 2 % off, together.
const ANEMOMETER_FLOOR: f64 = 0.027;

impl AnemometerEvidence {
    /// Whether the change is the reference's: its own true wind beyond the instrument's
    /// floor and at least as strong as the trials' (a wind it sailed in and the trials did
    /// not; two calm sets are not that).
    pub(super) fn the_references(&self) -> bool {
        self.own[1] > self.floor && self.own[1] >= self.own[0]
    }

    /// The p-value counted towards a wind in the trials: 1 where the change is the
    /// reference's ([`Self::the_references`]), else the test's.
    pub(super) fn p_trials(&self) -> f64 {
        if self.the_references() {
            1.0
        } else {
            self.p
        }
    }

    /// The standard error (m/s) of the true wind's speed: its components' along their mean
    /// direction (the larger of the two where the mean is 0).
    pub(super) fn speed_se(&self) -> f64 {
        let ([n, e], [sn, se]) = (self.wind, self.se);
        let norm = n.hypot(e);
        if norm > 0.0 {
            (n * sn).hypot(e * se) / norm
        } else {
            sn.max(se)
        }
    }

    /// The smallest true wind (m/s, trials less reference) this test shows at `level`, in
    /// the direction its mean is least certain: the instrument's floor plus that
    /// component's standard error times the critical value of its χ² (2 df:
    /// `√(−2 ln level)`). One that strong reaches the level about half the time.
    pub(super) fn smallest(&self, level: f64) -> f64 {
        self.floor + self.se[0].max(self.se[1]) * (-2.0 * level.ln()).max(0.0).sqrt()
    }

    /// Speed (m/s) and the direction it blows *from* (deg).
    pub(super) fn speed_from(&self) -> (f64, f64) {
        let [n, e] = self.wind;
        (
            n.hypot(e),
            (e.atan2(n).to_degrees() + 180.0).rem_euclid(360.0),
        )
    }
}

/// Per-sample true wind (north, east) of a record, `NaN` where the course is missing;
/// `None` when a channel is not logged.
fn true_wind(r: &Record) -> Option<[Vec<f64>; 2]> {
    let (psi, sog, cog) = (r.psi.as_ref()?, r.speed.as_ref()?, r.cog.as_ref()?);
    let (va, ga) = (r.wind_speed.as_ref()?, r.wind_angle.as_ref()?);
    let mut out = [Vec::with_capacity(r.len()), Vec::with_capacity(r.len())];
    for t in 0..r.len() {
        let (sc, cc) = cog[t].to_radians().sin_cos();
        let (sg, cg) = ga[t].to_radians().sin_cos();
        let (sp, cp) = psi[t].to_radians().sin_cos();
        // the ship's velocity through the air, body axes, then north/east
        let (ua, wa) = (va[t] * cg, va[t] * sg);
        let (an, ae) = (ua * cp - wa * sp, ua * sp + wa * cp);
        out[0].push(sog[t] * cc - an);
        out[1].push(sog[t] * sc - ae);
    }
    Some(out)
}

/// [`AnemometerEvidence`] of the trials against the reference (against still air when
/// there is none).
pub(super) fn anemometer_evidence(
    trial: &[Record],
    reference: &[Record],
) -> Option<AnemometerEvidence> {
    let stat = |recs: &[Record]| -> Option<[(f64, f64); 2]> {
        let (mut north, mut east) = (Vec::new(), Vec::new());
        for r in recs {
            let [n, e] = true_wind(r)?;
            north.push(n);
            east.push(e);
        }
        let (mn, sn, _) = block_mean(&north)?;
        let (me, se, _) = block_mean(&east)?;
        Some([(mn, sn), (me, se)])
    };
    let t = stat(trial)?;
    let r = if reference.is_empty() {
        [(0.0, 0.0); 2]
    } else {
        stat(reference)?
    };
    let wind = [t[0].0 - r[0].0, t[1].0 - r[1].0];
    let own = [t[0].0.hypot(t[1].0), r[0].0.hypot(r[1].0)];
    // what the instrument cannot tell from a calm: the share of the ship's speed that a
    // vane 1° off the bow line, or a cup reading 2 % off, makes of its own motion
    let speed = trial
        .iter()
        .filter_map(|r| r.speed.as_ref())
        .flatten()
        .sum::<f64>()
        / trial.iter().map(Record::len).sum::<usize>().max(1) as f64;
    let floor = ANEMOMETER_FLOOR * speed.abs();
    let norm = wind[0].hypot(wind[1]);
    let shrink = if norm > floor {
        1.0 - floor / norm
    } else {
        0.0
    };
    let se = [0, 1].map(|k| t[k].1.hypot(r[k].1).max(1e-9));
    let chi = (0..2).map(|k| (shrink * wind[k] / se[k]).powi(2)).sum();
    Some(AnemometerEvidence {
        wind,
        se,
        chi,
        p: chi2_sf(chi, 2.0),
        floor,
        own,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evidence of a mean true wind `wind` with component errors `se` over a floor.
    fn evidence(wind: [f64; 2], se: [f64; 2], floor: f64) -> AnemometerEvidence {
        let norm = wind[0].hypot(wind[1]);
        let shrink = if norm > floor {
            1.0 - floor / norm
        } else {
            0.0
        };
        let chi = (0..2).map(|k| (shrink * wind[k] / se[k]).powi(2)).sum();
        AnemometerEvidence {
            wind,
            se,
            chi,
            p: chi2_sf(chi, 2.0),
            floor,
            own: [norm, 0.0],
        }
    }

    #[test]
    fn the_smallest_wind_shown_reaches_the_level_in_its_worst_direction() {
        let (se, floor, level) = ([0.05, 0.2], 0.01, 1e-3);
        let w = evidence([0.0; 2], se, floor).smallest(level);
        // √(−2 ln 0.001) = 3.717: 0.01 + 0.2 × 3.717
        assert!((w - 0.7534).abs() < 1e-4, "{w}");
        // that wind along the worse component is just significant; along the better one,
        // far more so; a little weaker along the worse, not
        let p = |wind| evidence(wind, se, floor).p;
        assert!(
            (p([0.0, w]) - level).abs() < 1e-9 * level.max(1.0),
            "{}",
            p([0.0, w])
        );
        assert!(p([w, 0.0]) < 1e-12);
        assert!(p([0.0, 0.9 * w]) > level);
        // the speed's error: the components' along the mean direction
        let e = evidence([0.3, 0.4], se, floor);
        assert!((e.speed_se() - (0.3f64 * 0.05).hypot(0.4 * 0.2) / 0.5).abs() < 1e-12);
        assert_eq!(e.speed_from().0, 0.5);
    }
}
