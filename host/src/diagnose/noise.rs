//! The model's gain on measurement noise against the trials' own noise: where the trials'
//! yaw rate is noisier than the reference's, the reference is given the difference and the
//! model's Kalman gain re-fitted on it ([`matched_reference`], [`Caveat::NoisierTrials`]);
//! where the reference's is the noisier, the trials are given the difference
//! ([`quieted_trials`], [`Caveat::QuieterTrials`]); the caveat [`Caveat::NoiseGain`] where
//! the trials' noise, carried by a Kalman gain fitted to smoother records, is still what
//! their 10-step errors are.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::caveat::Caveat;
use super::evidence::Set;
use super::DiagnoseConfig;
use crate::diagnose::augment::sig;
use crate::identify::{model::Model, pem, predict};
use crate::io::data::Record;

/// The horizon whose noise gain is read: the 10 steps the ranking rule compares.
const HORIZON: usize = 10;

/// A 10-step prediction that carries white noise on the yaw rate this many times over
/// amplifies it ([`predict::NOISE_AMPLIFIES`]). A predictor that passes the latest
/// measurement on through the hull's dynamics carries it about once or less: the test
/// worlds' models 0.02–1.45, a model identified on MARIN's KVLCC2 records (resolved to 3
/// significant figures) 2.7; one identified on HSVA's records of the same hull (a yaw rate
/// smooth to 10⁻⁶ °/s) 1 661.
const AMPLIFIES: f64 = predict::NOISE_AMPLIFIES;

/// The trials' noise, for their yaw rate's spread, this many times the reference's or more:
/// noisier records than the gain was fitted to.
const NOISIER: f64 = 10.0;

/// The trials' white noise on the yaw rate this many times the reference's or more: the
/// reference is given the difference ([`matched_reference`]). Sensors alike read alike: the
/// test worlds' trials (a gyro of 0.03 °/s against the reference's 0.02) read 1.28–1.53
/// times the reference's, and nothing changes for them.
const MATCH_FROM: f64 = 2.0;

/// Iterations of the Kalman gain's re-fit (4 numbers, from the model's own).
const REFIT_ITER: usize = 50;

/// The reference records given white noise on their yaw rate to the trials' level, and the
/// model with its Kalman gain re-fitted on them ([`pem::refit_gain`]; A, B and the effects
/// kept), where the trials' noise is [`MATCH_FROM`] times the reference's or more.
pub(super) struct Matched {
    /// The model the method measures the trials against.
    pub model: Model,
    /// The reference records with the added noise.
    pub reference: Vec<Record>,
    /// [`Caveat::NoisierTrials`].
    pub caveat: Caveat,
}

/// [`Matched`] for `trials` against `reference`, or `None` where the trials are not
/// [`MATCH_FROM`] times noisier (or there is no reference, or the re-fit fails: the method
/// then runs against the reference as given, and [`noise_gain`] says what that means).
///
/// Why: a Kalman gain fitted to quiet records trusts each measurement; on noisier trials
/// it carries their noise into every prediction, and the nulls, simulated with the
/// reference's innovations, are narrower than the trials' own scatter. A gyro on board
/// noisier than a simulator's or a tank's is the rule, not the exception. The noise is
/// drawn from `cfg.seed`, so the same records give the same diagnosis.
pub(super) fn matched_reference(
    model: &Model,
    reference: &[Record],
    trials: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<Matched> {
    let (noise, r_noise, added) = noisier(trials, reference)?;
    let noisy = with_noise(reference, added, cfg.seed ^ 0x4e4f_4953_4552);
    let pcfg = pem::PemConfig {
        max_iter: REFIT_ITER,
        parallel: cfg.parallel,
        ..Default::default()
    };
    let refit = pem::refit_gain(&noisy, model, &pcfg).ok()?;
    let caveat = Caveat::NoisierTrials {
        trials_noise_degps: noise,
        reference_noise_degps: r_noise,
        added_noise_degps: added,
        gain_10_given: predict::noise_gain(model, HORIZON),
        gain_10: predict::noise_gain(&refit, HORIZON),
    };
    Some(Matched {
        model: refit,
        reference: noisy,
        caveat,
    })
}

/// The trials given white noise on their yaw rate to the reference's level, where the
/// reference's noise is [`MATCH_FROM`] times the trials' or more ([`quieted_trials`]).
pub(super) struct Quieted {
    /// The trials with the added noise: the records the yaw rate's statistics and nulls are
    /// measured on (the heading, ground-track and anemometer channels read them as logged).
    pub trials: Vec<Record>,
    /// [`Caveat::QuieterTrials`].
    pub caveat: Caveat,
}

/// [`Quieted`] for `trials` against `reference`, or `None` where the reference is not
/// [`MATCH_FROM`] times noisier than the trials (or either set is empty).
///
/// Why: the nulls are simulated with the reference's innovations and judged against the
/// reference's own spread, so they measure what differs beyond the reference's noise. On
/// trials far quieter than that, what the noise hides in the reference shows: the hull's own
/// nonlinearity, which a linear model of it misses alike in both sets, reads as a missing
/// effect (Mariner's and the container ship's effect-free trials at a tenth of the suite's
/// sensor noise read `nonlinear-damping`, 2 of 6 sets). So the trials are given the
/// difference, drawn from `cfg.seed` (the same records give the same diagnosis). The
/// held-out records are scored as logged, and the channels read the trials as logged: their
/// tests are calibrated on the records' own scatter, and on MARIN's records against a
/// simulator the added noise moved the gyro's offset by its own standard error. The
/// counterpart of [`matched_reference`], which cannot run this way round: noise taken off
/// the reference is not there to take.
pub(super) fn quieted_trials(
    reference: &[Record],
    trials: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<Quieted> {
    let (r_noise, noise, added) = noisier(reference, trials)?;
    Some(Quieted {
        trials: with_noise(trials, added, cfg.seed ^ 0x5155_4945_5445),
        caveat: Caveat::QuieterTrials {
            trials_noise_degps: noise,
            reference_noise_degps: r_noise,
            added_noise_degps: added,
        },
    })
}

/// The white noise on the yaw rate of `noisy` and of `quiet` ([`noise_and_spread`]) and the
/// white noise that brings the second to the first, `√(σ_n² − σ_q²)`, where the first is
/// [`MATCH_FROM`] times the second or more (`None` where not, or where either set is empty).
fn noisier(noisy: &[Record], quiet: &[Record]) -> Option<(f64, f64, f64)> {
    if noisy.is_empty() || quiet.is_empty() {
        return None;
    }
    let (n, _) = noise_and_spread(noisy);
    let (q, _) = noise_and_spread(quiet);
    (n.is_finite() && n >= MATCH_FROM * q).then(|| (n, q, (n * n - q * q).sqrt()))
}

/// `recs` with white noise of std `sigma` added to every finite yaw-rate sample, drawn from
/// `seed`.
fn with_noise(recs: &[Record], sigma: f64, seed: u64) -> Vec<Record> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    recs.iter()
        .map(|r| {
            let mut r = r.clone();
            for v in r.y.iter_mut().filter(|v| v.is_finite()) {
                *v += sigma * crate::stats::standard_normal(&mut rng);
            }
            r
        })
        .collect()
}

/// The share of the largest fourth differences [`noise_and_spread`] leaves out: a gyro's
/// isolated spikes (a glitch of the logger, a bit flipped on the line) each make five of
/// them, and a few spikes of 5 °/s in 1 800 samples would otherwise read as noise many
/// times the gyro's and send the method down the noisier-trials path.
const TRIM: f64 = 0.02;

/// `E[z² | |z| < z₀]` of a standard normal `z` cut at its two-sided `1 − TRIM` point
/// (`z₀ = 2.3263`): what the mean square of the differences kept is of white noise's.
const TRIMMED_SHARE: f64 = 0.873_465;

/// The white noise on records' yaw rate, from its fourth differences (`Var Δ⁴y = 70σ²` for
/// white noise; a ship's yaw rate is too smooth between samples to add to them: HSVA's
/// KVLCC2 records, smooth to 10⁻⁶ °/s, read 7·10⁻⁷ °/s, where their second differences read
/// the zig-zags' curvature, 6·10⁻⁵), the largest [`TRIM`] of them left out and the rest's
/// mean square scaled by [`TRIMMED_SHARE`], and the yaw rate's spread (°/s).
fn noise_and_spread(recs: &[Record]) -> (f64, f64) {
    let mut d2: Vec<f64> = recs
        .iter()
        .flat_map(|r| r.y.windows(5))
        .map(|w| w[4] - 4.0 * w[3] + 6.0 * w[2] - 4.0 * w[1] + w[0])
        .filter(|d| d.is_finite())
        .map(|d| d * d)
        .collect();
    d2.sort_by(f64::total_cmp);
    let kept = d2.len() - (TRIM * d2.len() as f64).floor() as usize;
    let d4 = d2[..kept].iter().sum::<f64>();
    let y: Vec<f64> = recs
        .iter()
        .flat_map(|r| r.y.iter().copied())
        .filter(|v| v.is_finite())
        .collect();
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let var = y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / y.len().max(1) as f64;
    let noise = (d4 / (70.0 * TRIMMED_SHARE * kept.max(1) as f64)).sqrt();
    (noise, var.sqrt())
}

/// [`Caveat::NoiseGain`] where the model's 10-step prediction amplifies white noise on the
/// measured yaw rate ([`predict::noise_gain`] ≥ [`AMPLIFIES`]), the trials' own noise
/// ([`noise_and_spread`]), so carried, is at least half their 10-step error, and the trials
/// are [`NOISIER`] than the reference: the statistics then measure the trials' noise through
/// a gain fitted to smoother records more than any missing effect. Without reference records
/// nothing tells noise the gain was fitted to from noise it was not, and none is given.
pub(super) fn noise_gain(model: &Model, trials: &[Record], reference: &[Record]) -> Option<Caveat> {
    let gain = predict::noise_gain(model, HORIZON);
    if !(gain.is_finite() && gain >= AMPLIFIES) || trials.is_empty() || reference.is_empty() {
        return None;
    }
    let (noise, spread) = noise_and_spread(trials);
    let set = Set::new(model, trials);
    let (s, n) = set.sse0(model, HORIZON);
    let ten = (s / n.max(1) as f64).sqrt();
    let (r_noise, r_spread) = noise_and_spread(reference);
    let carried = gain * noise >= 0.5 * ten;
    let noisier = noise * r_spread >= NOISIER * r_noise * spread;
    (carried && noisier).then_some(Caveat::NoiseGain {
        gain_10: gain,
        trials_noise_degps: noise,
        trials_ten_step_degps: ten,
        reference_noise_degps: r_noise,
    })
}

/// [`Caveat::NoisierTrials`]'s words (empty for another caveat).
pub(super) fn matched_words(c: &Caveat) -> String {
    let &Caveat::NoisierTrials {
        trials_noise_degps: noise,
        reference_noise_degps: reference,
        added_noise_degps: added,
        gain_10_given: given,
        gain_10: gain,
    } = c
    else {
        return String::new();
    };
    format!(
        "The trials' yaw rate carries white noise of about {noise:.2e} °/s (from its fourth \
         differences), {:.1} times the reference's {reference:.2e} °/s: a Kalman gain fitted \
         to the quieter records trusts each measurement more than the trials deserve. So the \
         reference records were given white noise of {added:.2e} °/s more (seeded) and the \
         model's Kalman gain re-fitted on them, A and B kept (its {HORIZON}-step prediction \
         carries white noise on the yaw rate {} times over as given, {} times re-fitted); \
         every statistic and null is measured against that model and those records.",
        noise / reference.max(f64::MIN_POSITIVE),
        sig(given),
        sig(gain)
    )
}

/// [`Caveat::QuieterTrials`]'s words (empty for another caveat).
pub(super) fn quieted_words(c: &Caveat) -> String {
    let &Caveat::QuieterTrials {
        trials_noise_degps: noise,
        reference_noise_degps: reference,
        added_noise_degps: added,
    } = c
    else {
        return String::new();
    };
    format!(
        "The reference's yaw rate carries white noise of about {reference:.2e} °/s (from its \
         fourth differences), {:.1} times the trials' {noise:.2e} °/s: the nulls, drawn from \
         the reference, tell only what differs beyond its noise, and what that noise hides \
         of the hull in the reference would show in the trials as a missing effect. So the \
         trials were given white noise of {added:.2e} °/s more (seeded) for the yaw rate's \
         statistics; the held-out records are scored, and the heading, ground-track and \
         anemometer channels read, as logged. A reference logged as quietly as the \
         trials (a simulated one: `simulate --gyro-noise {noise:.2e}`) would let them show \
         more.",
        reference / noise.max(f64::MIN_POSITIVE),
    )
}

/// [`Caveat::NoiseGain`]'s words (empty for another caveat).
pub(super) fn words(c: &Caveat) -> String {
    let &Caveat::NoiseGain {
        gain_10: gain,
        trials_noise_degps: noise,
        trials_ten_step_degps: ten,
        reference_noise_degps: reference,
    } = c
    else {
        return String::new();
    };
    format!(
        "The model's {HORIZON}-step prediction carries white noise on the measured yaw rate \
         {gain:.0} times over: its Kalman gain extrapolates the shape of the last few \
         measurements, as a model identified on records smoother than a rate gyro's output \
         learns to (a filtered or differentiated yaw rate, or one logged at a finer \
         resolution). The trials' yaw rate carries noise of about {noise:.2e} °/s (from its \
         fourth differences; the reference's {reference:.2e} °/s); so carried, that is \
         {:.2e} °/s, against the trials' {HORIZON}-step error of {ten:.2e} °/s: the \
         statistics measure the trials' noise through that gain as much as any missing \
         effect. Identify the reference on records logged as the trials are (the same gyro, \
         sample time and resolution; the reference's yaw rate rounded to the trials' \
         resolution will do).",
        gain * noise
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of the second-order model `m` (without its Kalman gain) driven by a
    /// PRBS-like command, with white noise of `noise` °/s on the measured yaw rate.
    fn record(m: &Model, noise: f64, seed: u64) -> Record {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = 1500;
        let mut u = Vec::with_capacity(n);
        let mut level = 5.0;
        for t in 0..n {
            if t % 37 == 0 {
                level = if rng.random_bool(0.5) { 10.0 } else { -10.0 };
            }
            u.push(level);
        }
        let clean = Model {
            k: vec![0.0; m.n],
            ..m.clone()
        };
        let rec = Record::from_uy("clean", 1.0, u.clone(), vec![0.0; n]);
        let y = predict::simulate(&clean, &rec, &vec![0.0; m.n])
            .into_iter()
            .map(|v| v + noise * (rng.random::<f64>() - 0.5) * 12f64.sqrt())
            .collect();
        Record::from_uy("noisy", 1.0, u, y)
    }

    #[test]
    fn a_gain_fitted_to_smooth_records_is_named_where_it_carries_the_trials_noise() {
        // a slow hull (poles 0.99 and 0.999); the smooth records' gain places the
        // predictor's poles at 0 (deadbeat: it extrapolates the last two measurements)
        let a = vec![-0.99 * 0.999, 0.99 + 0.999];
        let b = vec![0.0, 0.0001];
        let k = vec![a[1], a[0] + a[1] * a[1]];
        let smooth = Model::new(1.0, a.clone(), b.clone(), k).unwrap();
        let plain = Model::new(1.0, a, b, vec![0.1, 0.1]).unwrap();
        let g = predict::noise_gain(&smooth, HORIZON);
        assert!(g >= AMPLIFIES, "{g}");
        assert!(predict::noise_gain(&plain, HORIZON) < 2.0);
        let trials: Vec<Record> = (0..2).map(|s| record(&smooth, 0.03, s)).collect();
        let reference: Vec<Record> = (2..4).map(|s| record(&smooth, 1e-5, s)).collect();
        let c = noise_gain(&smooth, &trials, &reference).expect("the caveat");
        let Caveat::NoiseGain {
            gain_10,
            trials_noise_degps: noise,
            trials_ten_step_degps: ten,
            reference_noise_degps: r,
        } = c
        else {
            panic!("{c:?}");
        };
        assert_eq!(gain_10, g);
        // the fourth differences find the noise added (uniform, std 0.03 °/s) within 5 %;
        // on the reference (10⁻⁵ °/s) the command's steps add a little, 4·10⁻⁵
        assert!((noise - 0.03).abs() < 1.5e-3 && r < 1e-4, "{noise} {r}");
        assert!(gain_10 * noise >= 0.5 * ten, "{noise} {ten}");
        assert!(c.explain().contains("14 times over"), "{}", c.explain());
        // the JSON fields (docs/cli.md)
        let v = serde_json::to_value(&c).unwrap();
        assert_eq!(v["caveat"], "noise-gain");
        for key in [
            "gain_10",
            "trials_noise_degps",
            "trials_ten_step_degps",
            "reference_noise_degps",
        ] {
            assert!(v[key].as_f64().is_some_and(f64::is_finite), "{key}: {v}");
        }
        // the same trials through a gain that passes the measurement on: no caveat
        assert_eq!(noise_gain(&plain, &trials, &reference), None);
        // nor on trials as noisy as the reference (the gain meets the noise it was fitted
        // to), nor without a reference
        assert_eq!(noise_gain(&smooth, &trials, &trials[..1]), None);
        assert_eq!(noise_gain(&smooth, &trials, &[]), None);
    }

    /// A slow hull: poles 0.99 and 0.999, the command's gain small.
    fn slow_hull() -> Model {
        Model::new(
            1.0,
            vec![-0.99 * 0.999, 0.99 + 0.999],
            vec![0.0, 0.0001],
            vec![0.5, 0.5],
        )
        .unwrap()
    }

    #[test]
    fn a_gyros_spikes_are_not_read_as_its_noise() {
        // five spikes of 5 °/s in 1 500 samples of 0.02 °/s noise: the noise read within 5 %
        // of the record's without them, where all fourth differences would read 0.19 °/s
        let clean = record(&slow_hull(), 0.02, 3);
        let mut spiked = clean.clone();
        for i in [100, 400, 700, 1000, 1300] {
            spiked.y[i] += 5.0;
        }
        let (a, _) = noise_and_spread(std::slice::from_ref(&clean));
        let (b, _) = noise_and_spread(std::slice::from_ref(&spiked));
        assert!((a - 0.02).abs() < 0.001, "{a}");
        assert!((b / a - 1.0).abs() < 0.05, "{a} {b}");
        let d4: f64 = spiked
            .y
            .windows(5)
            .map(|w| (w[4] - 4.0 * w[3] + 6.0 * w[2] - 4.0 * w[1] + w[0]).powi(2))
            .sum();
        assert!((d4 / (70.0 * 1496.0)).sqrt() > 0.18);
    }

    #[test]
    fn trials_noisier_than_the_reference_are_measured_against_a_reference_as_noisy() {
        // the reference's yaw rate carries 0.005 °/s of white noise, the
        // trials' 0.03 °/s (a simulator's records against a ship's gyro)
        let m = slow_hull();
        let trials: Vec<Record> = (0..2).map(|s| record(&m, 0.03, s)).collect();
        let reference: Vec<Record> = (2..4).map(|s| record(&m, 0.005, s)).collect();
        let cfg = DiagnoseConfig {
            parallel: false,
            ..DiagnoseConfig::default()
        };
        let got = matched_reference(&m, &reference, &trials, &cfg).expect("matched");
        let Caveat::NoisierTrials {
            trials_noise_degps: noise,
            reference_noise_degps: r,
            added_noise_degps: added,
            gain_10_given,
            gain_10,
        } = got.caveat
        else {
            panic!("{:?}", got.caveat);
        };
        assert!(
            (noise - 0.03).abs() < 1.5e-3 && (r - 0.005).abs() < 5e-4,
            "{noise} {r}"
        );
        assert!((added * added + r * r - noise * noise).abs() < 1e-12);
        // the reference now reads the trials' noise, and only its yaw rate changed
        let (now, _) = noise_and_spread(&got.reference);
        assert!((now - noise).abs() < 0.05 * noise, "{now} {noise}");
        for (a, b) in got.reference.iter().zip(&reference) {
            assert_eq!(a.u, b.u);
            assert_ne!(a.y, b.y);
        }
        // A and B kept, the gain re-fitted: it trusts each measurement less
        assert_eq!((&got.model.a, &got.model.b), (&m.a, &m.b));
        assert_ne!(got.model.k, m.k);
        assert!(gain_10 < gain_10_given, "{gain_10} {gain_10_given}");
        assert_eq!(gain_10_given, predict::noise_gain(&m, HORIZON));
        let words = got.caveat.explain();
        assert!(words.contains("6.1 times the reference's"), "{words}");
        let v = serde_json::to_value(&got.caveat).unwrap();
        assert_eq!(v["caveat"], "noisier-trials");
        for key in [
            "trials_noise_degps",
            "reference_noise_degps",
            "added_noise_degps",
            "gain_10_given",
            "gain_10",
        ] {
            assert!(v[key].as_f64().is_some_and(f64::is_finite), "{key}: {v}");
        }
        // the same seed, the same noise; trials as noisy as the reference (or 1.5 times,
        // the test worlds' gyros), or no reference: nothing changes
        let again = matched_reference(&m, &reference, &trials, &cfg).unwrap();
        assert_eq!(again.reference[0].y, got.reference[0].y);
        let alike: Vec<Record> = (4..6).map(|s| record(&m, 0.0075, s)).collect();
        assert!(matched_reference(&m, &reference, &alike, &cfg).is_none());
        assert!(matched_reference(&m, &reference, &reference, &cfg).is_none());
        assert!(matched_reference(&m, &[], &trials, &cfg).is_none());
    }

    #[test]
    fn trials_quieter_than_the_reference_are_given_its_noise() {
        // the reference's yaw rate carries 0.03 °/s of white noise, the trials' 0.005 °/s (a
        // simulator's noisy gyro against a tank's clean one)
        let m = slow_hull();
        let reference: Vec<Record> = (0..2).map(|s| record(&m, 0.03, s)).collect();
        let trials: Vec<Record> = (2..4).map(|s| record(&m, 0.005, s)).collect();
        let cfg = DiagnoseConfig::default();
        // the other way round is not matched: noise cannot be taken off the reference
        assert!(matched_reference(&m, &reference, &trials, &cfg).is_none());
        let got = quieted_trials(&reference, &trials, &cfg).expect("quieted");
        let Caveat::QuieterTrials {
            trials_noise_degps: noise,
            reference_noise_degps: r,
            added_noise_degps: added,
        } = got.caveat
        else {
            panic!("{:?}", got.caveat);
        };
        assert!(
            (r - 0.03).abs() < 1.5e-3 && (noise - 0.005).abs() < 5e-4,
            "{noise} {r}"
        );
        assert!((added * added + noise * noise - r * r).abs() < 1e-12);
        // the trials now read the reference's noise, and only their yaw rate changed
        let (now, _) = noise_and_spread(&got.trials);
        assert!((now - r).abs() < 0.05 * r, "{now} {r}");
        for (a, b) in got.trials.iter().zip(&trials) {
            assert_eq!((&a.u, &a.psi, a.ts), (&b.u, &b.psi, b.ts));
            assert_ne!(a.y, b.y);
        }
        let words = got.caveat.explain();
        assert!(
            words.contains(&format!("{:.1} times the trials'", r / noise))
                && words.contains(&format!("`simulate --gyro-noise {noise:.2e}`")),
            "{words}"
        );
        let v = serde_json::to_value(&got.caveat).unwrap();
        assert_eq!(v["caveat"], "quieter-trials");
        assert_eq!(v["added_noise_degps"], added);
        for key in ["trials_noise_degps", "reference_noise_degps"] {
            assert!(v[key].as_f64().is_some_and(f64::is_finite), "{key}: {v}");
        }
        // the same seed, the same noise; another seed, another draw
        let again = quieted_trials(&reference, &trials, &cfg).unwrap();
        assert_eq!(again.trials[1].y, got.trials[1].y);
        let other = DiagnoseConfig {
            seed: cfg.seed + 1,
            ..cfg.clone()
        };
        assert_ne!(
            quieted_trials(&reference, &trials, &other).unwrap().trials[1].y,
            got.trials[1].y
        );
        // trials 1.5 times quieter (sensors alike), the same records, or no reference: none
        let alike: Vec<Record> = (4..6).map(|s| record(&m, 0.02, s)).collect();
        assert!(quieted_trials(&reference, &alike, &cfg).is_none());
        assert!(quieted_trials(&reference, &reference, &cfg).is_none());
        assert!(quieted_trials(&[], &trials, &cfg).is_none());
        assert!(quieted_trials(&reference, &[], &cfg).is_none());
    }
}
