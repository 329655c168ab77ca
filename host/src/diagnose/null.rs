//! The nulls: the parametric bootstrap (the innovations model simulated on the recorded
//! commands, `D` recomputed on each replicate, a scaled χ² fitted to the replicates) and,
//! for the effects with no free gain, the reference's own spread of `D` between its parts.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use yawcast_shared::model::EffectKind;

use super::evidence::world;
use crate::identify::model::{Effect, Model};
use crate::identify::pem::{self, PemConfig};
use crate::identify::predict::Stepper;
use crate::io::data::Record;
use crate::stats::{chi2_sf, f_quantile, standard_normal as gauss};

/// Simulates the innovations model on the commands of `like` with innovation std `sigma`
/// (heading integrated from the simulated rate, from the record's first heading).
pub(super) fn simulate_innovations(
    model: &Model,
    like: &Record,
    sigma: f64,
    rng: &mut ChaCha8Rng,
) -> Record {
    let s = Stepper::new(model);
    let p0 = like.psi.as_ref().map(|p| p[0]).unwrap_or(0.0);
    let mut st = s.initial(&[], p0);
    let n = like.len();
    let mut y = Vec::with_capacity(n);
    let mut psi = Vec::with_capacity(n);
    let mut p = p0;
    for t in 0..n {
        let yt = s.output(&st) + sigma * gauss(rng);
        psi.push(p);
        s.step(&mut st, like.u[t], yt, Some(p));
        p += model.ts * (yt - s.d_y());
        y.push(yt);
    }
    let mut r = Record::from_uy(&like.name, like.ts, like.u.clone(), y);
    r.psi = Some(psi);
    r
}

/// A scaled χ² `c·χ²_ν` fitted to replicates by their mean and variance (Satterthwaite).
#[derive(Debug, Clone, Copy)]
pub(super) struct Null {
    pub(super) c: f64,
    pub(super) nu: f64,
}

impl Null {
    pub(super) fn fit(reps: &[f64]) -> Null {
        let n = reps.len().max(1) as f64;
        let mean = reps.iter().sum::<f64>() / n;
        let var = reps.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let mean = mean.max(1e-9);
        let var = var.max(1e-12 * mean * mean);
        Null {
            c: var / (2.0 * mean),
            nu: (2.0 * mean * mean / var).max(0.05),
        }
    }

    /// The p-value of `d`: the fitted scaled χ², and never below one parameter's
    /// likelihood ratio on white innovations (χ²₁, mean 1). Replicates that are (almost)
    /// all 0 — an effect with no free gain, which data from the linear model never favour,
    /// and a reference whose parts agree — fit a null of no width, by which any `D` > 0
    /// would be significant (KVLCC2 at 40 m, an asymmetry hidden: a slew limit at D = 0.5,
    /// p = 0); one grid value beside the reference's fits noise as one free parameter does.
    pub(super) fn p(&self, d: f64) -> f64 {
        chi2_sf(d / self.c, self.nu)
            .max(chi2_sf(d, 1.0))
            .clamp(0.0, 1.0)
    }

    /// The smallest `D` significant at `level` (the one whose [`Null::p`] is `level`): the
    /// fitted scaled χ²'s upper `level` point, and at least χ²₁'s, as [`Null::p`] floors it.
    pub(super) fn critical(&self, level: f64) -> f64 {
        let q = |nu: f64| nu * f_quantile(level, nu, f64::INFINITY);
        (self.c * q(self.nu)).max(q(1.0))
    }

    /// Likelihood gain above what noise alone gives (`D` minus the null's mean, at least
    /// the one of χ²₁ as in [`Null::p`]): comparable across effects judged on the same
    /// errors, where far-tail p-values are not.
    pub(super) fn excess(&self, d: f64) -> f64 {
        d - (self.c * self.nu).max(1.0)
    }
}

/// `sim` with the headings of `real` (record by record, where `real` logs one): the
/// replicates' heading-dependent regressors at the headings the ship sailed.
fn at_headings_sailed(sim: &[Record], real: &[Record]) -> Vec<Record> {
    sim.iter()
        .zip(real)
        .map(|(s, r)| {
            let mut s = s.clone();
            if r.psi.is_some() {
                s.psi.clone_from(&r.psi);
            }
            s
        })
        .collect()
}

/// Null replicates of `D` for every kind: parametric bootstrap of the whole procedure. The
/// innovations model is simulated with its innovation std on the recorded inputs of the
/// reference and trial records, the model is re-identified on the simulated reference (on the
/// simulated trials when there is no reference), and `D` is recomputed. With a `generator`
/// (a model and its innovation std: the hull physics the reference shows of its own, for
/// trials sailed with other commands) that model is simulated instead, and `model`'s
/// structure is still what each replicate re-identifies. The heading-dependent effects
/// (current, wind) are measured on each replicate at the headings the records sailed, so
/// their null is conditional on the headings as their statistic is: a replicate replays the
/// logged commands open loop, and its own heading wanders where an autopilot held the ship
/// within ±10° — over which a heading harmonic mimics a steady moment, as it does not over
/// the headings the replicate makes up.
#[allow(clippy::too_many_arguments)]
pub(super) fn bootstrap(
    model: &Model,
    generator: Option<(&Model, f64)>,
    reference: &[Record],
    est: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    sigma: f64,
    reps: usize,
    bar: &indicatif::ProgressBar,
    seed: u64,
    parallel: bool,
) -> Vec<Vec<f64>> {
    // the heading-dependent effects are measured at the headings sailed, the others on the
    // replicate's own: a replicate replays the logged commands open loop, so its heading,
    // integrated from its own rate, wanders where an autopilot held the ship's
    let (heading_at, plain_at): (Vec<usize>, Vec<usize>) =
        (0..grids.len()).partition(|&i| grids[i].0.needs_heading());
    let pick = |at: &[usize]| -> Vec<(EffectKind, Vec<Effect>)> {
        at.iter().map(|&i| grids[i].clone()).collect()
    };
    let (heading, plain) = (pick(&heading_at), pick(&plain_at));
    let one = |r: usize| -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                .wrapping_add(r as u64),
        );
        let (gen, sigma) = generator.unwrap_or((model, sigma));
        let rs: Vec<Record> = reference
            .iter()
            .map(|rec| simulate_innovations(gen, rec, sigma, &mut rng))
            .collect();
        let ts: Vec<Record> = est
            .iter()
            .map(|rec| simulate_innovations(gen, rec, sigma, &mut rng))
            .collect();
        let pc = PemConfig {
            order: model.n,
            max_iter: 30,
            parallel: false,
            ..PemConfig::default()
        };
        let fit_on = if rs.is_empty() { &ts } else { &rs };
        let m = pem::identify_from(fit_on, model, &pc)
            .map(|r| r.model)
            .unwrap_or_else(|_| model.clone());
        let mut d = vec![0.0; grids.len()];
        for (w, &i) in world(&m, &rs, &ts, &plain, false)
            .into_iter()
            .zip(&plain_at)
        {
            d[i] = w.d;
        }
        if !heading.is_empty() {
            let (rs, ts) = (
                at_headings_sailed(&rs, reference),
                at_headings_sailed(&ts, est),
            );
            for (w, &i) in world(&m, &rs, &ts, &heading, false)
                .into_iter()
                .zip(&heading_at)
            {
                d[i] = w.d;
            }
        }
        bar.inc(1);
        d
    };
    let per: Vec<Vec<f64>> = crate::par::map_range(reps, parallel, one);
    (0..grids.len())
        .map(|k| per.iter().map(|v| v[k]).collect())
        .collect()
}

/// Most parts the reference is cut into ([`reference_parts`]): each part is measured against
/// all the others, so the cost grows with the square of their number; as many as the blocks
/// of a long set ([`super::WINDOW`] / [`super::WINDOW_BLOCK`]).
const MAX_PARTS: usize = super::WINDOW / super::WINDOW_BLOCK;

/// Parts of the reference records, at least three and at most [`MAX_PARTS`]: the records
/// themselves (dealt in turn into [`MAX_PARTS`] groups when there are more), or each record
/// cut into equal pieces when there are fewer than three; empty when a piece would be
/// shorter than `min_len` samples.
pub(super) fn reference_parts(reference: &[Record], min_len: usize) -> Vec<Vec<Record>> {
    if reference.len() >= 3 {
        let k = reference.len().min(MAX_PARTS);
        let mut parts = vec![Vec::new(); k];
        for (i, r) in reference.iter().enumerate() {
            parts[i % k].push(r.clone());
        }
        return parts;
    }
    let k = 3usize.div_ceil(reference.len().max(1));
    let mut parts = Vec::new();
    for r in reference {
        let len = r.len() / k;
        if len < min_len {
            return Vec::new();
        }
        for i in 0..k {
            let mut p = r.slice(i * len, if i + 1 == k { r.len() } else { (i + 1) * len });
            p.name = format!("{} (part {} of {k})", r.name, i + 1);
            parts.push(vec![p]);
        }
    }
    parts
}

/// Parts of the reference the size of the trial set, when the trials' records are at most
/// half as long as the reference's: each reference record cut into pieces of the trials'
/// mean record length (at least `min_len`), dealt record by record in turn, and grouped as
/// many to a part as there are trial records — at least three parts and at most
/// [`MAX_PARTS`], else `None` ([`reference_parts`] then serves).
///
/// Why: `D` of a structure with no free gain fluctuates far more between short sets than
/// between long ones, and the reference's own records measured against each other show
/// only the long sets' spread. The built-in ship's effect-free trials cut to their first
/// 400 s read as a 24 °/s slew limit at D = 25 (its gear slews at 20 °/s; at 900 and
/// 1 800 s, D = 0), where the records' spread and the bootstrap both gave 0.
pub(super) fn trial_sized_parts(
    reference: &[Record],
    trial: &[Record],
    min_len: usize,
) -> Option<Vec<Vec<Record>>> {
    if trial.is_empty() || reference.is_empty() {
        return None;
    }
    let mean = |s: &[Record]| s.iter().map(Record::len).sum::<usize>() / s.len();
    let len = mean(trial).max(min_len);
    if 2 * len > mean(reference) {
        return None;
    }
    let mut per: Vec<std::collections::VecDeque<Record>> = reference
        .iter()
        .map(|r| {
            (0..r.len() / len)
                .map(|i| {
                    let mut p = r.slice(i * len, (i + 1) * len);
                    p.name = format!("{}@{}", r.name, i * len);
                    p
                })
                .collect()
        })
        .collect();
    let mut pieces = Vec::new();
    while per.iter().any(|v| !v.is_empty()) {
        pieces.extend(per.iter_mut().filter_map(|v| v.pop_front()));
    }
    let k = trial.len();
    let groups = (pieces.len() / k).min(MAX_PARTS);
    (groups >= 3).then(|| {
        pieces
            .chunks(k)
            .take(groups)
            .map(<[Record]>::to_vec)
            .collect()
    })
}

/// The replicates one effect's statistic is judged against: the bootstrap's, and for an
/// effect with no free gain the reference's own spread ([`with_spread`]).
#[derive(Debug, Clone)]
pub(super) struct Nulls {
    /// Bootstrap replicates of `D`.
    pub(super) boot: Vec<f64>,
    /// `D` of each part of the reference measured against the others, scaled to the trials.
    pub(super) spread: Option<Vec<f64>>,
}

impl Nulls {
    /// The null `d` is judged against: the bootstrap's, or the reference's own spread where
    /// that gives the larger p-value (the more conservative of the two); with the largest
    /// `D` of the spread when it is the spread's.
    pub(super) fn at(&self, d: f64) -> (Null, Option<f64>) {
        let boot = Null::fit(&self.boot);
        match &self.spread {
            Some(s) => {
                let spread = Null::fit(s);
                if spread.p(d) > boot.p(d) {
                    (spread, Some(s.iter().copied().fold(0.0, f64::max)))
                } else {
                    (boot, None)
                }
            }
            None => (boot, None),
        }
    }
}

/// The nulls of every kind of `grids` (`boot[i]`, the bootstrap replicates of `grids[i]`),
/// with the reference's own spread for the effects with no free gain (dead time, gear rate,
/// angle limit, dead band: their structure is searched on a grid, nothing fitted).
///
/// Why: data simulated from the linear model never favour such an effect — it can only
/// worsen a linear model's fit — so their bootstrap replicates are (almost) all 0 and say
/// nothing about how large `D` gets without the effect, and any `D` > 0 would read as
/// significant. Yet a linear model meets a nonlinear hull differently on different inputs:
/// on the built-in ship, one reference record against the other two shows an angle limit
/// just under the largest command (a few per cent less gain) at D ≈ 29 scaled to the
/// trials, and effect-free trials show the same. So each part of the reference (a record or
/// a group of them, or a piece of one when there are fewer than three: [`reference_parts`];
/// pieces the size of the trials' records when those are short: [`trial_sized_parts`])
/// is measured as a trial against the version the other parts show, `D` scaled to the
/// trials' error count (`real[i].n`), and p is the larger of the two nulls'. Where the
/// reference is empty or too short to cut into three parts of `MIN_SAMPLES`, the bootstrap's
/// null stands alone.
pub(super) fn with_spread(
    boot: Vec<Vec<f64>>,
    model: &Model,
    reference: &[Record],
    grids: &[(EffectKind, Vec<Effect>)],
    real: &[super::evidence::WorldStat],
    trial: &[Record],
    parallel: bool,
) -> Vec<Nulls> {
    let gainless: Vec<usize> = (0..grids.len())
        .filter(|&i| crate::effects::def(grids[i].0).gains.is_empty())
        .collect();
    let parts = trial_sized_parts(reference, trial, super::MIN_SAMPLES)
        .unwrap_or_else(|| reference_parts(reference, super::MIN_SAMPLES));
    let mut spread: Vec<Option<Vec<f64>>> = vec![None; grids.len()];
    if parts.len() >= 3 && !gainless.is_empty() {
        let sub: Vec<(EffectKind, Vec<Effect>)> =
            gainless.iter().map(|&i| grids[i].clone()).collect();
        let per: Vec<Vec<f64>> = crate::par::map_range(parts.len(), parallel, |j| {
            let others: Vec<Record> = parts
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != j)
                .flat_map(|(_, p)| p.iter().cloned())
                .collect();
            world(model, &others, &parts[j], &sub, false)
                .into_iter()
                .zip(&gainless)
                .map(|(w, &i)| w.d * real[i].n as f64 / w.n.max(1) as f64)
                .collect()
        });
        for (k, &i) in gainless.iter().enumerate() {
            spread[i] = Some(per.iter().map(|v| v[k]).collect());
        }
    }
    boot.into_iter()
        .zip(spread)
        .map(|(boot, spread)| Nulls { boot, spread })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_critical_value_is_where_p_reaches_the_level() {
        let level = 0.001;
        // a null ten times χ²₁ (50-step errors overlapping): ten times χ²₁'s 10.83
        let wide = Null { c: 10.0, nu: 1.0 };
        let d = wide.critical(level);
        assert!((d - 108.28).abs() < 0.01, "{d}");
        assert!((wide.p(d) - level).abs() < 1e-9, "{}", wide.p(d));
        // a null of no width: χ²₁'s floor, as `p` reads it
        let narrow = Null { c: 1e-3, nu: 0.5 };
        assert!((narrow.critical(level) - 10.828).abs() < 1e-3);
        assert!((narrow.p(narrow.critical(level)) - level).abs() < 1e-9);
    }

    #[test]
    fn the_reference_is_cut_into_three_parts_at_least() {
        let rec = |n: usize| Record::from_uy("r", 1.0, vec![0.0; n], vec![0.0; n]);
        let lens = |p: &[Vec<Record>]| -> Vec<Vec<usize>> {
            p.iter()
                .map(|g| g.iter().map(Record::len).collect())
                .collect()
        };
        // three records or more: the records themselves
        let p = reference_parts(&[rec(500), rec(600), rec(700)], 100);
        assert_eq!(lens(&p), [[500], [600], [700]]);
        // more records than parts: dealt in turn into MAX_PARTS groups
        let many: Vec<Record> = (0..8).map(|i| rec(200 + i)).collect();
        let p = reference_parts(&many, 100);
        assert_eq!(MAX_PARTS, 6);
        assert_eq!(lens(&p)[0], [200, 206]);
        assert_eq!(lens(&p)[1], [201, 207]);
        assert_eq!(lens(&p)[5], [205]);
        // one record: three pieces, the last taking the remainder
        let p = reference_parts(&[rec(1801)], 100);
        assert_eq!(lens(&p), [[600], [600], [601]]);
        assert_eq!(p[2][0].name, "r (part 3 of 3)");
        // two records: two pieces each
        let p = reference_parts(&[rec(400), rec(300)], 100);
        assert_eq!(lens(&p), [[200], [200], [150], [150]]);
        // pieces too short: none
        assert!(reference_parts(&[rec(250)], 100).is_empty());
        assert!(reference_parts(&[], 100).is_empty());
    }

    #[test]
    fn short_trials_are_matched_by_reference_pieces_of_their_size() {
        let rec = |name: &str, n: usize| {
            let mut r = Record::from_uy(name, 1.0, vec![0.0; n], vec![0.0; n]);
            r.name = name.into();
            r
        };
        let reference = [rec("a", 1800), rec("b", 1800), rec("c", 1800)];
        // three trials of 400 s: 4 pieces of 400 from each reference record, dealt in
        // turn, three to a part — four parts, each a piece of every record
        let short = [rec("t1", 400), rec("t2", 400), rec("t3", 400)];
        let parts = trial_sized_parts(&reference, &short, 200).unwrap();
        assert_eq!(parts.len(), 4);
        assert!(parts
            .iter()
            .all(|p| p.len() == 3 && p.iter().all(|r| r.len() == 400)));
        let names: Vec<&str> = parts[1].iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["a@400", "b@400", "c@400"]);
        // many short trials: the parts stop at MAX_PARTS
        let tiny = [rec("t", 250)];
        assert_eq!(
            trial_sized_parts(&reference, &tiny, 200).unwrap().len(),
            MAX_PARTS
        );
        // trials as long as the reference's records, or more than half as long: the
        // records' own parts serve
        assert!(trial_sized_parts(&reference, &reference, 200).is_none());
        assert!(trial_sized_parts(&reference, &[rec("t", 1000)], 200).is_none());
        // a short reference that cannot give three parts
        let one = [rec("r", 1000)];
        assert!(trial_sized_parts(&one, &short, 200).is_none());
        assert!(trial_sized_parts(&[], &short, 200).is_none());
    }

    #[test]
    fn a_degenerate_bootstrap_yields_to_the_references_spread() {
        // the built-in ship's angle limit on effect-free trials: every bootstrap replicate 0
        // (a clip only worsens data from the linear model), one reference record against
        // the other two 28.6, the trials 42.6
        let n = Nulls {
            boot: vec![0.0; 24],
            spread: Some(vec![0.0, 28.6, 0.0]),
        };
        let level = 0.01 / 9.0;
        let (alone, _) = Nulls {
            spread: None,
            ..n.clone()
        }
        .at(42.6);
        // alone, the bootstrap's null has no width: only the floor of one parameter's
        // likelihood ratio (χ²₁) is left, by which 42.6 is far in the tail
        assert_eq!(alone.p(42.6), chi2_sf(42.6, 1.0));
        assert!(alone.p(42.6) < 1e-10, "{}", alone.p(42.6));
        assert!(alone.p(0.5) > 0.4, "{}", alone.p(0.5));
        let (null, max) = n.at(42.6);
        assert_eq!(max, Some(28.6));
        let p = null.p(42.6);
        assert!(p > level && p < 0.2, "{p}");
        // a real angle limit (half strength: D of several hundred) stays significant
        let (null, _) = n.at(253.5);
        assert!(null.p(253.5) < 1e-4, "{}", null.p(253.5));
        // where the bootstrap has the larger p it governs
        let wide = Nulls {
            boot: (0..24).map(|i| 30.0 * f64::from(i) / 23.0).collect(),
            spread: Some(vec![0.0, 1.0, 0.5]),
        };
        assert_eq!(wide.at(20.0).1, None);
    }

    #[test]
    fn an_angle_limit_within_the_references_own_spread_is_no_effect() {
        // the acceptance suite's effect-free case 43 on its reference 1, whose own gear
        // (a slew limit) the statistics are measured against: the trials show an angle
        // limit just under the largest command at D ≈ 43, where every bootstrap replicate
        // is 0 and one reference record against the other two gives D ≈ 29
        use crate::diagnose::tests::{identify, records};
        use crate::diagnose::{diagnose, DiagnoseConfig};
        let reference = records(None, &[903, 904, 905]);
        let model = identify(&reference);
        let est = records(None, &[430, 431, 432]);
        let cfg = DiagnoseConfig {
            seed: 43,
            ..DiagnoseConfig::default()
        };
        let d = diagnose(&model, &reference, &est, &[], &cfg).unwrap();
        let sat = d.ranking.iter().find(|r| r.effect == "saturation").unwrap();
        assert_eq!(d.verdict, "none", "{}", d.explanation);
        assert!(d.reference_gear.is_some());
        assert!(sat.statistic > 20.0 && !sat.significant, "{sat:?}");
        assert!(sat.p_value > 0.01 / 9.0, "{sat:?}");
        assert!(
            sat.evidence.contains("the reference's own spread"),
            "{}",
            sat.evidence
        );
    }
}
