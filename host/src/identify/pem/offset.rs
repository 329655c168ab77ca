//! An operating point the linear model cannot hold: when the records carry a steady offset
//! (a yaw moment from a single screw, a current or wind, a rate-gyro offset), the plain
//! structure has no term for it and the search parks a pole on the unit circle instead —
//! an integrator that carries the offset through its state. Such a model predicts a few
//! steps ahead about as well, but it drifts in simulation and its slow mode is an artefact.
//!
//! The integrator shows in A, or in the predictor A − KC when the per-record initial state
//! x̂(0) carries the offset through a predictor that never forgets it. [`identify`]
//! identifies the plain structure first. When A or A − KC has a pole that does not decay to
//! 1 % within the mean record length L (`ρ^L > 0.01`, the rule PEM applies to the predictor:
//! the records cannot tell such a mode from a constant), it identifies the structure again
//! with each offset effect of the library
//! — `bias` (a steady moment through B) and `gyro-bias` (an offset on the measured rate) —
//! and takes the one with the lowest criterion (BIC, with the heading's term below) if it
//! beats the plain structure's and no longer needs the slow pole. A plain model that settles can still lack the offset: its
//! predictor then passes it into the one-step errors, whose mean is tested against their
//! block-sum standard error (two-sided 0.1 %); a mean beyond it asks for the same two
//! candidates. Otherwise the plain model stands.
//!
//! The two look alike on the yaw rate alone (a steady output offset either way), so the one
//! that reached the lower minimum hands it, converted through the steady gain, to the other
//! as a further start. The heading tells them apart when every record logs it
//! ([`gyro_offset`]: the gyro's mean reading less the heading's turn, b ± se, the error
//! counting how far the records' own offsets wander from one to the next as a real gyro's
//! do, beside the noise within each). That is a
//! measurement of the gyro offset the yaw-rate likelihood does not hold, so it enters the
//! criterion as one more Gaussian term: BIC + ((b − d)/s)², d the model's gyro offset (0
//! without `gyro-bias`) and s the heading's standard error combined with the identified
//! offset's. A moment then cannot stand in for an offset the heading shows, nor a gyro bias
//! for one it does not. A gyro offset the heading shows beyond its noise (the two-sided
//! 0.1 % normal quantile) has `gyro-bias` tried even when the plain model settles (the offset
//! then sits in x̂(0) and a slow mode, and simulation drifts).

use serde::Serialize;
use yawcast_shared::model::EffectKind;

use super::{identify_with, IdentError, PemConfig, PemReport};
use crate::identify::model::{Effect, Model};
use crate::identify::predict;
use crate::io::data::{block_mean, gyro_offset, Record};

/// Why an offset effect was added.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OffsetChoice {
    /// The effect added (`bias` or `gyro-bias`, as its name).
    pub effect: &'static str,
    /// Its estimated value (bias: degrees of command; gyro bias: deg/s).
    pub value: f64,
    /// Largest pole modulus of A and A − KC without the effect (with `reason`
    /// `"integrator"`, the pole that stood in for the offset).
    pub radius_without: f64,
    /// The same with it.
    pub radius_with: f64,
    /// What asked for the offset: `"integrator"` (the plain model's slow pole),
    /// `"residual-mean"` (the plain model settles but its one-step errors are not centred)
    /// or `"heading"` (only the heading shows an offset: a gyro offset).
    pub reason: &'static str,
    /// BIC with the effect minus BIC without it, the heading's term included when every
    /// record logs heading (module docs; negative).
    pub delta_bic: f64,
    /// The gyro's mean reading less the heading's turn (deg/s) and its standard error, when
    /// every record logs heading (module docs).
    pub heading_gyro_bias: Option<[f64; 2]>,
}

impl OffsetChoice {
    /// One line for the user.
    ///
    /// ```
    /// use yawcast::identify::pem::offset::OffsetChoice;
    /// let c = OffsetChoice { effect: "bias", value: 2.1, radius_without: 0.9999999,
    ///                        radius_with: 0.97, reason: "integrator", delta_bic: -812.0,
    ///                        heading_gyro_bias: Some([0.001, 0.002]) };
    /// assert!(c.describe().contains("2.10"));
    /// assert!(c.describe().contains("+0.0010 ± 0.0020 °/s"));
    /// ```
    pub fn describe(&self) -> String {
        let what = match self.effect {
            "bias" => format!(
                "a steady yaw moment equal to {:.2}° of command (`bias`)",
                self.value
            ),
            _ => format!(
                "an offset of {:+.4} °/s on the measured rate (`gyro-bias`)",
                self.value
            ),
        };
        let heading = match self.heading_gyro_bias {
            Some([b, se]) => format!(
                " (the heading: the gyro reads {b:+.4} ± {se:.4} °/s more than the ship turns)"
            ),
            None => String::new(),
        };
        let without = if self.reason == "heading" {
            format!(
                "the heading shows a rate-gyro offset: without a term for it the model holds \
                 it in its initial state and a slow mode (largest pole {:.5})",
                self.radius_without
            )
        } else if self.reason == "residual-mean" {
            format!(
                "the records carry a steady offset: without a term for it the model's one-step \
                 errors are not centred (largest pole {:.5})",
                self.radius_without
            )
        } else {
            format!(
                "the records carry a steady offset: without a term for it the search held a \
                 pole at {:.7} (an integrator, slower than the records)",
                self.radius_without
            )
        };
        format!(
            "{without}; identified with {what} instead: largest pole {:.4}, ΔBIC {:+.1}{heading}",
            self.radius_with, self.delta_bic
        )
    }
}

/// Whether every pole of A and of A − KC decays to 1 % within the mean record length.
fn settles(model: &Model, recs: &[Record]) -> bool {
    let len = recs.iter().map(Record::len).sum::<usize>() as f64 / recs.len().max(1) as f64;
    let (ra, rp) = model.spectral_radii();
    len * ra.max(rp).ln() <= 0.01f64.ln()
}

/// The steady offsets identification fits to a record set by itself when its errors ask
/// for one: a steady yaw moment (`bias`) or a rate-gyro offset (`gyro-bias`). A model
/// identified on a reference may carry either as the reference's own.
pub const OFFSET_KINDS: [EffectKind; 2] = [EffectKind::Bias, EffectKind::GyroBias];

/// [`super::identify`] of the plain structure, with an offset effect added when the plain
/// model needs an integrator to carry one or the heading shows a gyro offset (module docs). The effect's gain is estimated
/// with θ; the returned choice is `None` when the plain model stands.
///
/// # Errors
/// As [`super::identify`] for the plain structure (a failed identification with an offset
/// effect only means the plain model stands).
///
/// ```
/// use yawcast::{io::data::Record, identify::model::Model, identify::pem, identify::predict};
/// // a 2nd-order ship without an offset: the plain model stands
/// let truth = Model::new(1.0, vec![-0.5, 1.4], vec![0.1, 0.05], vec![0.3, 0.1]).unwrap();
/// let u: Vec<f64> = (0..600).map(|i| if (i / 25) % 2 == 0 { 5.0 } else { -5.0 }).collect();
/// let mut rec = Record::from_uy("r", 1.0, u, vec![0.0; 600]);
/// rec.y = predict::simulate(&truth, &rec, &[0.0, 0.0]);
/// let cfg = pem::PemConfig { order: 2, ..Default::default() };
/// let (rep, choice) = pem::offset::identify(&[rec], &cfg).unwrap();
/// assert!(choice.is_none());
/// assert!((rep.model.a[1] - 1.4).abs() < 1e-6);
/// ```
pub fn identify(
    records: &[Record],
    cfg: &PemConfig,
) -> Result<(PemReport, Option<OffsetChoice>), IdentError> {
    let plain = super::identify(records, None, cfg)?;
    let hb = gyro_offset(records, &[]).map(|g| [g.offset, g.se]);
    let gyro_seen = hb.is_some_and(|[b, se]| (b / se).abs() > Z_BAR);
    // an integrator or a one-step error that is not centred asks for either offset; a gyro
    // offset the heading shows, for that one
    let integrator = !settles(&plain.model, records);
    let kinds: &[EffectKind] = if integrator || off_centre(&plain, records) {
        &OFFSET_KINDS
    } else if gyro_seen {
        &[EffectKind::GyroBias]
    } else {
        return Ok((plain, None));
    };
    let radius = |m: &Model| {
        let (a, p) = m.spectral_radii();
        a.max(p)
    };
    let radius_without = radius(&plain.model);
    let fit = |kind: EffectKind, warm: Option<Model>| {
        let template = plain.model.clone().with_effect(Effect::zero(kind, 0.0));
        let mut structure = template.clone();
        structure.a = vec![0.0; structure.n];
        structure.b = vec![0.0; structure.n];
        structure.k = vec![0.0; structure.n];
        // fresh starts for the structure, the plain optimum with the offset at zero, and the
        // other offset's optimum carried over
        let starts: Vec<Model> = std::iter::once(template).chain(warm).collect();
        identify_with(records, Some(&structure), &starts, cfg).ok()
    };
    let mut fits: Vec<(EffectKind, Option<PemReport>)> =
        kinds.iter().map(|&kind| (kind, fit(kind, None))).collect();
    // A steady moment and a rate offset give the same steady output offset: the one that
    // found the lower minimum hands it, converted, to the other (whose own starts can stay
    // on the integrator's minimum, where the offset is held by x̂(0)).
    let bic = |r: &Option<PemReport>| r.as_ref().map_or(f64::INFINITY, |r| r.bic);
    let (lo, hi) = if fits.len() < 2 || bic(&fits[0].1) <= bic(&fits[1].1) {
        (0, 1)
    } else {
        (1, 0)
    };
    if let Some(warm) = fits
        .get(hi)
        .and_then(|h| converted(&fits[lo].1.as_ref()?.model, h.0))
    {
        if let Some(r) = fit(fits[hi].0, Some(warm)) {
            if r.bic < bic(&fits[hi].1) {
                fits[hi].1 = Some(r);
            }
        }
    }
    let tried: Vec<(EffectKind, PemReport)> = fits
        .into_iter()
        .filter_map(|(kind, r)| r.map(|r| (kind, r)))
        .filter(|(_, r)| settles(&r.model, records))
        .collect();
    let plain_bic = plain.bic + heading_term(&plain, hb);
    let Some((kind, rep, total)) = tried
        .into_iter()
        .map(|(k, r)| {
            let total = r.bic + heading_term(&r, hb);
            (k, r, total)
        })
        .filter(|(_, _, total)| *total < plain_bic)
        .min_by(|a, b| a.2.total_cmp(&b.2))
    else {
        return Ok((plain, None));
    };
    let value = offset_value(&rep.model, kind);
    let choice = OffsetChoice {
        effect: kind.name(),
        value,
        radius_without,
        radius_with: radius(&rep.model),
        reason: if integrator {
            "integrator"
        } else if kinds.len() == 2 {
            "residual-mean"
        } else {
            "heading"
        },
        delta_bic: total - plain_bic,
        heading_gyro_bias: hb,
    };
    Ok((rep, Some(choice)))
}

/// The two-sided 0.1 % normal quantile: the bar for a mean beyond its noise (module docs).
const Z_BAR: f64 = 3.29;

/// `model` (with a `bias` or a `gyro-bias`) with the other offset `to` giving the same steady
/// output offset: `d_y = G(1)·β`, G(1) = C(I − A)⁻¹B the steady gain. `None` when G(1) is
/// not finite and non-zero.
fn converted(model: &Model, to: EffectKind) -> Option<Model> {
    let n = model.n;
    let i_a = nalgebra::DMatrix::<f64>::identity(n, n) - model.a_matrix();
    let x = i_a
        .lu()
        .solve(&nalgebra::DVector::from_column_slice(&model.b))?;
    let gain = x[0];
    if !gain.is_finite() || gain == 0.0 {
        return None;
    }
    let value = match to {
        EffectKind::Bias => offset_value(model, EffectKind::GyroBias) / gain,
        _ => offset_value(model, EffectKind::Bias) * gain,
    };
    if !value.is_finite() {
        return None;
    }
    let mut m = model.clone();
    m.effects.clear();
    Some(m.with_effect(match to {
        EffectKind::Bias => Effect::Bias { beta: value },
        _ => Effect::GyroBias { d_y: value },
    }))
}

fn offset_value(model: &Model, kind: EffectKind) -> f64 {
    match model.effect(kind) {
        Some(Effect::Bias { beta }) => *beta,
        Some(Effect::GyroBias { d_y }) => *d_y,
        _ => f64::NAN,
    }
}

/// Whether the plain model's one-step errors have a mean beyond their noise (the block-sum
/// standard error at [`Z_BAR`]): a settling predictor passes a steady offset it has no
/// term for into its errors, scaled by its noise model's steady gain.
fn off_centre(plain: &PemReport, records: &[Record]) -> bool {
    let errors: Vec<Vec<f64>> = records
        .iter()
        .zip(&plain.x0)
        .map(|(r, x0)| {
            let yhat = predict::one_step(&plain.model, r, x0);
            r.y.iter().zip(&yhat).map(|(y, p)| y - p).collect()
        })
        .collect();
    block_mean(&errors).is_some_and(|(mean, se, _)| (mean / se).abs() > Z_BAR)
}

/// The heading's term of the criterion (module docs): `((b − d)/s)²`, d the gyro offset of
/// `rep`'s model (0 without one), s the heading's standard error combined with the
/// identification's for d. 0 without heading.
fn heading_term(rep: &PemReport, hb: Option<[f64; 2]>) -> f64 {
    let Some([b, se]) = hb else {
        return 0.0;
    };
    let Some(Effect::GyroBias { d_y: d }) = rep.model.effect(EffectKind::GyroBias) else {
        return (b / se).powi(2);
    };
    let sd = rep
        .names
        .iter()
        .position(|n| n.ends_with("d_y"))
        .and_then(|i| rep.std.get(i).copied())
        .filter(|v| v.is_finite())
        .unwrap_or(0.0);
    ((b - *d) / se.hypot(sd)).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::predict;

    fn record(truth: &Model, seed: usize) -> Record {
        // commands held 10–60 s at ±5, ±10, ±20°, deterministic per seed
        let mut u = Vec::with_capacity(1800);
        let mut s = 0x9e37_79b9_7f4a_7c15u64 ^ seed as u64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        while u.len() < 1800 {
            let level = [5.0, -10.0, 20.0, -5.0, 10.0, -20.0][(next() % 6) as usize];
            let hold = 10 + (next() % 51) as usize;
            u.extend(std::iter::repeat_n(level, hold));
        }
        u.truncate(1800);
        let mut rec = Record::from_uy("r", 1.0, u, vec![0.0; 1800]);
        let x0 = vec![0.0; truth.n];
        // white measurement noise, σ ≈ 0.05 °/s (sum of four uniforms)
        let mut noise = move || {
            (0..4)
                .map(|_| (next() >> 11) as f64 / (1u64 << 53) as f64)
                .sum::<f64>()
                - 2.0
        };
        rec.y = predict::simulate(truth, &rec, &x0)
            .iter()
            .map(|v| v + 0.085 * noise())
            .collect();
        rec
    }

    /// A slow 4th-order ship (poles 0.985, 0.9, 0.6 ± 0.2i).
    fn ship() -> Model {
        let (a, b, k) = crate::identify::model::from_difference_form(
            &[-0.0003, -0.0242, -0.2935, -0.915],
            &[1.6e-4, 8e-5, 4e-5, 1.6e-5],
            &[0.0; 4],
        );
        Model::new(1.0, a, b, k).unwrap()
    }

    #[test]
    fn a_steady_moment_is_a_bias_not_an_integrator() {
        let truth = ship().with_effect(Effect::Bias { beta: 2.0 });
        let recs = [record(&truth, 1), record(&truth, 2)];
        let cfg = PemConfig::default();
        let plain = super::super::identify(&recs, None, &cfg).unwrap();
        let (rep, choice) = identify(&recs, &cfg).unwrap();
        let c = choice.expect("offset found");
        // without the effect the search held a pole at the circle
        assert!(c.radius_without > 0.9999, "{c:?}");
        assert!(!settles(&plain.model, &recs));
        // a steady moment and a rate offset look alike in steady state (the heading tells
        // them apart, in `diagnose`): either holds the offset, the steady output offset of
        // 2° of command through the ship's gain
        let steady = |m: &Model| {
            let r = Record::from_uy("still", 1.0, vec![0.0; 4000], vec![0.0; 4000]);
            *predict::simulate(m, &r, &vec![0.0; m.n]).last().unwrap()
        };
        let want = steady(&truth);
        assert!(
            (steady(&rep.model) - want).abs() < 0.05 * want.abs(),
            "{} vs {want}: {c:?}",
            steady(&rep.model)
        );
        assert!(c.effect == "bias" || c.effect == "gyro-bias", "{c:?}");
        assert!(c.radius_with < 0.995 && settles(&rep.model, &recs), "{c:?}");
        assert!(c.delta_bic < 0.0);
        // and it simulates a fresh record at least as well as the integrator does
        let fresh = record(&truth, 3);
        let sim = |m: &Model| {
            let x0 = predict::estimate_x0(m, &fresh);
            predict::fit(&fresh.y, &predict::simulate(m, &fresh, &x0))
        };
        assert!(
            sim(&rep.model) > 95.0 && sim(&rep.model) >= sim(&plain.model) - 0.05,
            "{} vs {}",
            sim(&rep.model),
            sim(&plain.model)
        );
    }

    /// `record` with a heading: the integral of the ship's true rate (`rate_model`, without
    /// any gyro offset) plus 0.05° of white noise.
    fn with_heading(truth: &Model, rate_model: &Model, seed: usize) -> Record {
        let mut rec = record(truth, seed);
        let r = predict::simulate(rate_model, &rec, &vec![0.0; rate_model.n]);
        let mut psi = Vec::with_capacity(r.len());
        let mut h = 30.0;
        let mut s = 0x2545_f491_4f6c_dd1du64 ^ seed as u64;
        for i in 0..r.len() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            psi.push(h + 0.1 * ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5));
            if i + 1 < r.len() {
                h += 0.5 * (r[i] + r[i + 1]) * rec.ts;
            }
        }
        rec.psi = Some(psi);
        rec
    }

    #[test]
    fn the_heading_tells_a_moment_from_a_gyro_offset() {
        let moment = ship().with_effect(Effect::Bias { beta: 2.0 });
        let still = Record::from_uy("still", 1.0, vec![0.0; 4000], vec![0.0; 4000]);
        let steady = *predict::simulate(&moment, &still, &[0.0; 4])
            .last()
            .unwrap();
        // a gyro offset that gives the same steady rate offset
        let gyro = ship().with_effect(Effect::GyroBias { d_y: steady });
        let cfg = PemConfig::default();
        for (truth, rate, want) in [(&moment, &moment, "bias"), (&gyro, &ship(), "gyro-bias")] {
            let recs = [with_heading(truth, rate, 1), with_heading(truth, rate, 2)];
            let (rep, choice) = identify(&recs, &cfg).unwrap();
            let c = choice.unwrap_or_else(|| panic!("{want}: {:?}", rep.model.spectral_radii()));
            assert_eq!(c.effect, want, "{c:?}");
            let [b, se] = c.heading_gyro_bias.unwrap();
            let true_gyro = if want == "bias" { 0.0 } else { steady };
            assert!((b - true_gyro).abs() < 4.0 * se, "{c:?}");
            assert!(c.describe().contains("more than the ship turns"));
        }
    }

    #[test]
    fn a_moment_a_settling_model_leaves_in_its_errors_is_found_by_their_mean() {
        use crate::sim::{simulate, Scenario, Ship, SimEffect};
        let ship = Ship::default_lng();
        let cfg = PemConfig::default();
        let moment = Scenario::with_effect(SimEffect::hidden(EffectKind::Bias, 1.0));
        let mut by_mean = 0;
        for seed in 1..=6u64 {
            let recs = [simulate(&ship, &moment, seed).unwrap()];
            let plain = super::super::identify(&recs, None, &cfg).unwrap();
            let (rep, choice) = identify(&recs, &cfg).unwrap();
            let c = choice.unwrap_or_else(|| panic!("seed {seed}: no offset"));
            assert_eq!(c.effect, "bias", "seed {seed}: {c:?}");
            if settles(&plain.model, &recs) {
                // the settling plain model left the moment in its errors' mean
                assert!(off_centre(&plain, &recs), "seed {seed}");
                assert_eq!(c.reason, "residual-mean", "seed {seed}: {c:?}");
                by_mean += 1;
                // and the model with it simulates a fresh record better
                let fresh = simulate(&ship, &moment, 100 + seed).unwrap();
                let sim = |m: &Model| {
                    let x0 = predict::estimate_x0(m, &fresh);
                    predict::fit(&fresh.y, &predict::simulate(m, &fresh, &x0))
                };
                assert!(
                    sim(&rep.model) > sim(&plain.model) + 1.0,
                    "seed {seed}: {} vs {}",
                    sim(&rep.model),
                    sim(&plain.model)
                );
            }
        }
        assert!(by_mean >= 3, "{by_mean}");
        // the clean ship's errors are centred
        for seed in 1..=6u64 {
            let clean = [simulate(&ship, &Scenario::default(), seed).unwrap()];
            let p = super::super::identify(&clean, None, &cfg).unwrap();
            assert!(!off_centre(&p, &clean), "seed {seed}");
        }
    }

    #[test]
    fn records_without_an_offset_keep_the_plain_model() {
        let recs = [record(&ship(), 1), record(&ship(), 2)];
        let cfg = PemConfig::default();
        let (rep, choice) = identify(&recs, &cfg).unwrap();
        assert!(choice.is_none(), "{choice:?}");
        assert_eq!(rep, super::super::identify(&recs, None, &cfg).unwrap());
        assert!(rep.model.effects.is_empty());
    }
}
