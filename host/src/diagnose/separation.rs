//! How far a set of records' headings separate a heading harmonic from what each record's own
//! manoeuvre does: where they hardly do, the yaw channel cannot tell current or wind.

use nalgebra::DMatrix;

use super::caveat::Caveat;
use super::channels::turned;
use crate::io::data::Record;
use yawcast_shared::model::EffectKind;

/// The least share of the heading harmonics' variance over which the yaw channel's
/// heading-dependent moment counts ([`heading_separation`]): what three records keep that
/// each sweep their heading evenly through ±40° about their own course (a sine sweep:
/// ±20° keeps 0.05 %, ±45° 1.1 %, ±90° 13 %).
///
/// Measured on the suite's trial sets (`bench/worlds/run.sh`, three worlds, 189 sets each):
/// ±20° zig-zags 0.07–1.2 %, 185 of 189 under the level (the four above it a slow gear's
/// or a dead time's wider swings); PRBS trials 0.35–88 %, one of 189 under it (KVLCC2 with
/// nonlinear damping hidden, its turns held small); the autopilot's course changes under
/// 0.01 %. The level is a geometry — how far a record must turn for its curvature to show —
/// and no world's verdicts chose it.
pub(super) const MIN_HEADING_SEPARATION: f64 = 0.005;

/// How far a set of records' headings separate the heading harmonics (sin ψ, cos ψ) from
/// what each record's own manoeuvre does: the least share, over directions, of the
/// harmonics' variance (about their mean over the set) left once each record's own offset
/// and a slope on its heading turned through ([`turned`]) are taken out. `None` without
/// headings or samples.
///
/// Why: over a record that holds one course — a zig-zag about its first heading, an
/// autopilot's ±10° — a harmonic is that record's offset plus a slope on how far the ship
/// has turned, and so is the linear model's mismatch with the hull in every swing of the
/// manoeuvre, which no current or wind causes (the built-in ship's effect-free ±20°
/// zig-zags: a current on the yaw channel at p = 3.5·10⁻⁵ with the ground velocity at
/// χ² = 3.7 on 2 df and the anemometer showing no wind). Only what is left beyond those
/// tells a heading dependence; where that is almost nothing the yaw channel cannot tell
/// it, and the channels that carry current and wind themselves (the ground velocity, the
/// anemometer) must.
pub(super) fn heading_separation(recs: &[Record]) -> Option<f64> {
    let nr = recs.len();
    let p = 2 * nr;
    // per record: intercept, slope on the heading turned; the two harmonics as targets
    let mut xtx = DMatrix::<f64>::zeros(p, p);
    let mut xth = DMatrix::<f64>::zeros(p, 2);
    let mut hth = nalgebra::Matrix2::<f64>::zeros();
    let mut sum = nalgebra::Vector2::<f64>::zeros();
    let mut n = 0usize;
    for (i, r) in recs.iter().enumerate() {
        let psi = r.psi.as_ref()?;
        let turn = turned(psi);
        for (t, &ps) in psi.iter().enumerate() {
            if !ps.is_finite() {
                continue;
            }
            let ph = ps.to_radians();
            let h = nalgebra::Vector2::new(ph.sin(), ph.cos());
            let (a, b) = (i, nr + i);
            xtx[(a, a)] += 1.0;
            xtx[(a, b)] += turn[t];
            xtx[(b, a)] += turn[t];
            xtx[(b, b)] += turn[t] * turn[t];
            for k in 0..2 {
                xth[(a, k)] += h[k];
                xth[(b, k)] += turn[t] * h[k];
            }
            hth += h * h.transpose();
            sum += h;
            n += 1;
        }
    }
    if n < 2 * p {
        return None;
    }
    let mean = sum / n as f64;
    let total = hth - mean * mean.transpose() * n as f64;
    // what the nuisance explains: Hᵀ X (XᵀX)⁻¹ Xᵀ H (a relative ridge for records that
    // never turn)
    let ridge = 1e-12 * (xtx.trace() / p as f64).max(1e-300);
    for j in 0..p {
        xtx[(j, j)] += ridge;
    }
    let sol = xtx.cholesky()?.solve(&xth);
    let explained = xth.transpose() * sol;
    let left = hth - nalgebra::Matrix2::from_fn(|a, b| explained[(a, b)]);
    // least generalised eigenvalue of (left, total): through total's Cholesky factor
    let l = total.cholesky()?.l();
    let li = l.try_inverse()?;
    let m = li * left * li.transpose();
    let ev = m.symmetric_eigenvalues();
    let least = ev[0].min(ev[1]);
    least.is_finite().then_some(least.max(0.0))
}

/// The caveat for a steady moment named (`named`: the verdict's effect and its second) on
/// trials whose [`heading_separation`] (`separation`) is under
/// [`MIN_HEADING_SEPARATION`], with no anemometer logged
/// ([`Caveat::BiasOrWind`]): the counterpart of [`Caveat::CurrentOrWind`] for the yaw
/// channel. Where the anemometer is logged it measures the wind itself.
pub(super) fn bias_or_wind(
    named: &[EffectKind],
    separation: Option<f64>,
    anemometer: bool,
    across: Option<[f64; 2]>,
) -> Option<Caveat> {
    let s = separation.filter(|&s| s < MIN_HEADING_SEPARATION)?;
    (!anemometer && named.contains(&EffectKind::Bias)).then_some(Caveat::BiasOrWind {
        separation: s,
        across,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_headings_beyond_each_records_offset_and_turn_separate_the_harmonics() {
        // three records of 1 000 samples sweeping their heading as a sine of ±`amp`° about
        // 0°, 120° and 240°
        let set = |amp: f64| -> Vec<Record> {
            (0..3)
                .map(|i| {
                    let mut r = Record::from_uy("h", 1.0, vec![0.0; 1000], vec![0.0; 1000]);
                    r.psi = Some(
                        (0..1000)
                            .map(|t| {
                                let psi = 120.0 * f64::from(i) + amp * (0.02 * f64::from(t)).sin();
                                psi.rem_euclid(360.0)
                            })
                            .collect(),
                    );
                    r
                })
                .collect()
        };
        let sep = |amp: f64| heading_separation(&set(amp)).unwrap();
        // ±20°, a zig-zag's or an autopilot's course: almost nothing beyond offset and turn
        let narrow = sep(20.0);
        assert!(narrow < 1e-3, "{narrow}");
        // ±180°: the harmonics separate
        let wide = sep(180.0);
        assert!(wide > 0.2, "{wide}");
        // the level lies between a ±30° and a ±45° sine sweep
        assert!(sep(30.0) < MIN_HEADING_SEPARATION && sep(45.0) > MIN_HEADING_SEPARATION);
        // growing with the sweep
        assert!(sep(30.0) > narrow && sep(90.0) > sep(45.0));
        // a record without heading: nothing to judge
        let mut none = set(20.0);
        none[1].psi = None;
        assert_eq!(heading_separation(&none), None);
    }

    #[test]
    fn a_steady_moment_on_one_course_without_an_anemometer_may_be_a_wind() {
        let bias = [EffectKind::RateLimit, EffectKind::Bias];
        // an autopilot's or a zig-zag's one course, no anemometer: the caveat
        let c = bias_or_wind(&bias, Some(0.0007), false, None).unwrap();
        assert_eq!(
            c,
            Caveat::BiasOrWind {
                separation: 0.0007,
                across: None
            }
        );
        assert!(
            c.explain().contains("keep 0.07 % of their variance"),
            "{}",
            c.explain()
        );
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["caveat"], "bias-or-wind");
        assert_eq!(json["separation"], 0.0007);
        assert!(json.get("across").is_none(), "{json}");
        // the records' courses compared: how far apart, and that no change showed
        let c = bias_or_wind(&bias, Some(0.0007), false, Some([46.0, 0.62])).unwrap();
        assert!(
            c.explain().contains("at most 46° apart") && c.explain().contains("(p = 6.2e-1)"),
            "{}",
            c.explain()
        );
        assert_eq!(serde_json::to_value(&c).unwrap()["across"][0], 46.0);
        // the anemometer logged: it measures the wind itself
        assert!(bias_or_wind(&bias, Some(0.0007), true, None).is_none());
        // several courses (at the level or above), or no heading to judge: none
        assert!(bias_or_wind(&bias, Some(0.005), false, None).is_none());
        assert!(bias_or_wind(&bias, None, false, None).is_none());
        // no steady moment named
        assert!(bias_or_wind(&[EffectKind::Asymmetry], Some(0.0007), false, None).is_none());
    }
}
