//! A gyro offset measured on the heading: the candidate is the model re-identified on the yaw
//! rate less the offset the heading shows, with the offset held at that measurement.
//!
//! On the yaw rate alone a rate-gyro offset and a steady yaw moment give the same steady
//! output, so a model that carries a moment (a single-screw hull's reference) leaves the
//! offset unresolved (≈ 0 ± several °/s). The heading measures it directly — the gyro against
//! the compass's turn, which only a sensor offset moves — so where every record logs heading
//! the offset is taken from there. The shift is exact: with `y = x₁ + d_y` the innovations of
//! the model with `d_y` on `y` are those of the model without it on `y − d_y`, and a fit % is
//! the same on either — nonlinear damping included, which reads the rate the hull turns at,
//! `y − d_y` (`yawcast_shared::kernel::Step::effective_input`).

use yawcast_shared::model::EffectKind;

use crate::identify::model::{Effect, Model};
use crate::identify::pem::PemReport;
use crate::io::data::{gyro_offset, HeadingBias, Record};

/// The offset the heading measures on `est`, when `kind` is a gyro offset and every record
/// logs heading: the records' pooled offset, its standard error counting how far the
/// records' own offsets wander beside the noise within each
/// ([`gyro_offset`](crate::io::data::gyro_offset)), as diagnose judges it.
pub(super) fn measured_offset(kind: EffectKind, est: &[Record]) -> Option<HeadingBias> {
    if kind != EffectKind::GyroBias {
        return None;
    }
    let g = gyro_offset(est, &[])?;
    Some(HeadingBias {
        bias: g.offset,
        se: g.se,
        n: g.n,
    })
    .filter(|h| h.bias.is_finite() && h.se.is_finite())
}

/// The records with `bias` taken off the yaw rate.
pub(super) fn shifted(est: &[Record], bias: f64) -> Vec<Record> {
    est.iter()
        .map(|r| {
            let mut r = r.clone();
            r.y.iter_mut().for_each(|y| *y -= bias);
            r
        })
        .collect()
}

/// `model` without its gyro offset (the structure re-identified on shifted records).
pub(super) fn without_offset(model: &Model) -> Model {
    let mut m = model.clone();
    m.effects.retain(|e| e.kind() != EffectKind::GyroBias);
    m
}

/// The report of a re-identification on shifted records as the candidate's: the model with
/// the offset, which counts as one more parameter (its standard error the heading's, last,
/// as a gain would be). Its information criteria count the heading's evidence as well: the
/// offset is measured on the heading, a channel the yaw-rate likelihood does not see, and
/// there the offset at its estimate against none lowers −2 ln L by z² = (offset / se)²
/// ([`heading_evidence`]) — so an offset the heading measures well is worth its parameter
/// even where the yaw rate alone cannot tell it from a steady moment.
pub(super) fn with_measured_offset(mut rep: PemReport, hb: HeadingBias) -> PemReport {
    rep.model = rep.model.with_effect(Effect::GyroBias { d_y: hb.bias });
    rep.names.push("d_y".into());
    rep.std.push(hb.se);
    rep.std_pct.push(100.0 * hb.se / hb.bias.abs());
    let p = rep.cov.len();
    for row in &mut rep.cov {
        row.push(0.0);
    }
    let mut last = vec![0.0; p + 1];
    last[p] = hb.se * hb.se;
    rep.cov.push(last);
    let z2 = heading_evidence(hb);
    rep.aic += 2.0 - z2;
    rep.bic += (rep.samples.max(1) as f64).ln() - z2;
    rep
}

/// The heading's evidence for the offset `hb`: the drop in −2 ln L of its measurement,
/// z² = (offset / se)² (0 where the standard error is not positive and finite).
pub(super) fn heading_evidence(hb: HeadingBias) -> f64 {
    let z = hb.bias / hb.se;
    if hb.se > 0.0 && z.is_finite() {
        z * z
    } else {
        0.0
    }
}

/// The words of the search note.
pub(super) fn note(hb: HeadingBias) -> String {
    format!(
        "the offset held at what the heading measures, {:+.4} ± {:.4} °/s (the gyro against \
         the compass's turn, the error counting how far the records' own offsets wander; \
         on the yaw rate alone a steady yaw moment looks the same), the \
         model re-identified on the yaw rate less it; the heading's evidence for it, \
         z² = {:.1}, counts in ΔAIC and ΔBIC",
        hb.bias,
        hb.se,
        heading_evidence(hb)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::predict;

    #[test]
    fn the_shift_is_exact() {
        // the model with an offset on y predicts as the model without it on y − offset,
        // shifted back — with nonlinear damping too: it reads the rate the hull turns at,
        // y − d_y, so an offset gyro does not move the damping (before, it read y itself)
        let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1]).unwrap();
        let u: Vec<f64> = (0..200)
            .map(|i| ((i / 13) % 2) as f64 * 4.0 - 2.0)
            .collect();
        let y: Vec<f64> = (0..200).map(|i| (i as f64 * 0.1).sin() + 0.25).collect();
        let rec = Record::from_uy("r", 1.0, u, y);
        let less = shifted(std::slice::from_ref(&rec), 0.25).remove(0);
        let h = predict::Horizon::Steps(10);
        let damping = |cubic| Effect::NonlinearDamping { beta: -0.1, cubic };
        let models = [
            m.clone(),
            m.clone().with_effect(damping(false)),
            m.with_effect(damping(true)),
        ];
        for without in models {
            let with = without.clone().with_effect(Effect::GyroBias { d_y: 0.25 });
            assert_eq!(without_offset(&with), without);
            let a = predict::predict(&with, &rec, &[0.0, 0.0], h);
            let b = predict::predict(&without, &less, &[0.0, 0.0], h);
            for (p, q) in a.iter().zip(&b) {
                assert!(
                    (p - (q + 0.25)).abs() < 1e-12,
                    "{:?}: {p} {q}",
                    without.effects
                );
            }
        }
    }

    #[test]
    fn only_a_gyro_offset_on_records_with_heading() {
        let mut r = Record::from_uy("x", 1.0, vec![0.0; 400], vec![1.2; 400]);
        assert!(measured_offset(EffectKind::GyroBias, &[r.clone()]).is_none());
        r.psi = Some((0..400).map(|i| i as f64).collect());
        let hb = measured_offset(EffectKind::GyroBias, &[r.clone()]).unwrap();
        assert!((hb.bias - 0.2).abs() < 1e-12);
        assert!(measured_offset(EffectKind::Bias, &[r]).is_none());
    }

    #[test]
    fn the_offset_measured_counts_how_far_the_records_wander() {
        // three records whose offsets lie 0.01 °/s apart, each with ±0.03 °/s of noise: the
        // block sums alone give 0.0001 °/s, the records' spread 0.0058, and the heading's
        // evidence for the offset is judged on that (z² 3, not 10⁴)
        let recs: Vec<Record> = [0.0, 0.01, 0.02]
            .iter()
            .map(|&o| {
                let y = (0..900)
                    .map(|i| o + if i % 2 == 0 { 0.03 } else { -0.03 })
                    .collect();
                let mut r = Record::from_uy("r", 1.0, vec![0.0; 900], y);
                r.psi = Some(vec![90.0; 900]);
                r
            })
            .collect();
        let within = crate::io::data::heading_bias(&recs).unwrap();
        let hb = measured_offset(EffectKind::GyroBias, &recs).unwrap();
        assert_eq!((hb.bias, hb.n), (within.bias, within.n));
        assert!(
            within.se < 1e-3 && (hb.se - 0.01 / 3f64.sqrt()).abs() < 2e-4,
            "{hb:?}"
        );
        assert!(
            (heading_evidence(hb) - 3.0).abs() < 0.2,
            "{}",
            heading_evidence(hb)
        );
    }
}
