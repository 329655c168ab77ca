//! The starts of a search, run in parallel, and the choice among the minima they reach.

use super::lm::{Point, Problem, Search};
use super::{choose, predict, report};
use super::{IdentError, PemConfig, PemReport, Start};
use crate::identify::model::Model;
use crate::io::data::Record;

/// The template's structure at order `n` (effects kept; θ zero when the order differs).
pub(super) fn structure_of(template: Option<&Model>, n: usize, records: &[Record]) -> Model {
    let ts = records.first().map(|r| r.ts).unwrap_or(1.0);
    match template {
        Some(t) if t.n == n => t.clone(),
        Some(t) => Model {
            n,
            ts: t.ts,
            a: vec![0.0; n],
            b: vec![0.0; n],
            k: vec![0.0; n],
            effects: t.effects.clone(),
        },
        None => Model {
            n,
            ts,
            a: vec![0.0; n],
            b: vec![0.0; n],
            k: vec![0.0; n],
            effects: Vec::new(),
        },
    }
}

pub(super) fn run_starts(
    prob: &Problem<'_>,
    starts: Vec<(Start, Vec<f64>)>,
    cfg: &PemConfig,
    mut failures: Vec<String>,
) -> Result<PemReport, IdentError> {
    let usable: Vec<(Start, Vec<f64>)> = starts
        .into_iter()
        .filter(|(s, params)| {
            let ok = prob.stable(params) && params.iter().all(|v| v.is_finite());
            if !ok {
                failures.push(format!("{s:?}: unstable"));
            }
            ok
        })
        .collect();
    // the searches are independent: in parallel when allowed (same result either way)
    let searched: Vec<(Start, Search)> = crate::par::map_owned(usable, cfg.parallel, |(s, p)| {
        (s, prob.search(p, cfg.max_iter, cfg.tol))
    });
    let mut found: Vec<(Start, Search)> = Vec::new();
    for (s, res) in searched {
        if res.pt.sse.is_finite() {
            found.push((s, res));
        } else {
            failures.push(format!("{s:?}: non-finite predictions"));
        }
    }
    // Only minima whose predictor forgets its initial state within the records compete
    // (see `forgets`), unless none does.
    let forgetting: Vec<bool> = found
        .iter()
        .map(|(_, r)| forgets(&prob.model(&r.pt.params), prob.recs))
        .collect();
    let any = forgetting.iter().any(|f| *f);
    let pool: Vec<(Start, Search)> = found
        .into_iter()
        .zip(forgetting)
        .filter(|(_, f)| *f || !any)
        .map(|(r, _)| r)
        .collect();
    let Some(lowest) = (0..pool.len()).reduce(|a, b| {
        if prob.total(&pool[b].1.pt) < prob.total(&pool[a].1.pt) {
            b
        } else {
            a
        }
    }) else {
        return Err(IdentError::AllStartsFailed(failures.join(", ")));
    };
    let (pick, choice) = choose_minimum(prob, &pool, lowest, &cfg.select_horizons);
    // AIC and BIC belong to the structure: its maximum likelihood is the lowest minimum
    let ml_sse = pool[lowest].1.pt.sse;
    let (start, search) = pool.into_iter().nth(pick).expect("index from the pool");
    let mut rep = report(prob, start, search, ml_sse)?;
    rep.choice = choice;
    Ok(rep)
}

/// Among the minima whose one-step cost is not significantly above the lowest's
/// ([`choose::dm_z`] below [`choose::Z_EQUAL`]) and whose k-step errors over `horizons` are
/// significantly below the lowest's, the one with the lowest mean relative k-step error;
/// `(lowest, None)` when there is none.
fn choose_minimum(
    prob: &Problem<'_>,
    pool: &[(Start, Search)],
    lowest: usize,
    horizons: &[usize],
) -> (usize, Option<choose::StartChoice>) {
    if pool.len() < 2 || horizons.is_empty() {
        return (lowest, None);
    }
    let mut hs: Vec<usize> = horizons.iter().map(|h| (*h).max(1)).collect();
    hs.sort_unstable();
    hs.dedup();
    // prediction errors per record: one step, or per horizon of `hs`
    let errors_of = |pt: &Point, one: bool| -> Vec<Vec<Vec<f64>>> {
        let m = prob.model(&pt.params);
        let mut out = vec![Vec::with_capacity(prob.recs.len()); if one { 1 } else { hs.len() }];
        for (r, x) in prob.recs.iter().zip(&pt.x0) {
            let preds = if one {
                vec![predict::one_step(&m, r, x)]
            } else {
                predict::k_steps(&m, r, x, &hs)
            };
            for (slot, p) in out.iter_mut().zip(preds) {
                slot.push(r.y.iter().zip(p).map(|(y, p)| y - p).collect());
            }
        }
        out
    };
    let base_pt = &pool[lowest].1.pt;
    let base_total = prob.total(base_pt);
    let base_one = errors_of(base_pt, true).remove(0);
    // the minima as good one step ahead (the cheap test first: k-step errors only for them)
    let equal: Vec<(usize, f64)> = pool
        .iter()
        .enumerate()
        .filter(|(i, (_, s))| {
            // a start that ended in the lowest minimum itself (to well within the sampling
            // spread): its tiny differences may test significant but mean nothing
            *i != lowest && prob.total(&s.pt) - base_total > 1e-6 * base_total
        })
        .filter_map(|(i, (_, s))| {
            let count = s.pt.count.max(1) as f64;
            // the penalty's share of the cost difference (0 for plain PEM)
            let extra = (prob.pen.value(&s.pt.params) - prob.pen.value(&base_pt.params)) / count;
            let z = choose::dm_z(&errors_of(&s.pt, true)[0], &base_one, extra);
            // NaN (no usable samples) never qualifies
            (z < choose::Z_EQUAL).then_some((i, z))
        })
        .collect();
    if equal.is_empty() {
        return (lowest, None);
    }
    let base_multi = errors_of(base_pt, false);
    let base_mse: Vec<f64> = base_multi.iter().map(|e| choose::mse(e)).collect();
    let mut best: Option<choose::StartChoice> = None;
    let mut pick = lowest;
    for (i, z) in equal {
        let pt = &pool[i].1.pt;
        let multi = errors_of(pt, false);
        let ratio = multi
            .iter()
            .zip(&base_mse)
            .map(|(e, b)| choose::mse(e) / b)
            .sum::<f64>()
            / hs.len() as f64;
        let zm = choose::dm_z_of(
            &choose::scaled_differences(&multi, &base_multi),
            0.0,
            hs.last().copied().unwrap_or(1),
        );
        if zm < -choose::Z_EQUAL && best.as_ref().map_or(true, |b| ratio < b.multi_step_ratio) {
            best = Some(choose::StartChoice {
                lowest: pool[lowest].0,
                cost_ratio: prob.total(pt) / base_total,
                z,
                horizons: hs.clone(),
                multi_step_ratio: ratio,
                multi_step_z: zm,
            });
            pick = i;
        }
    }
    (pick, best)
}

/// Whether the one-step predictor A − KC forgets its initial state within the records: its
/// spectral radius ρ satisfies ρ^L ≤ 1 % over the mean record length L.
///
/// x̂(0) is estimated per record, so a predictor pole a hair inside the unit circle lets x̂(0)
/// carry an unmodelled offset through the whole record and wins on the one-step cost. The
/// controller starts from a state it does not know that well and would carry its initial
/// error as long; such a minimum (typically reached from the subspace start when the records
/// hold an offset the structure has no effect for) is taken only when no start gives another.
fn forgets(model: &Model, recs: &[Record]) -> bool {
    let len = recs.iter().map(Record::len).sum::<usize>() as f64 / recs.len().max(1) as f64;
    let (_, rho) = model.spectral_radii();
    len * rho.ln() <= 0.01f64.ln()
}
