//! The actuator-parameter search of step 2: the grid of the effect's structural parameter
//! (dead time, gear rate, angle limit, dead band), each value ranked by frozen-θ cost and by a warm re-identification, the
//! golden-section refinement, and the candidate identified from the value chosen.

use yawcast_shared::model::EffectKind;

use super::refit::{reidentify, reidentify_final, reidentify_warm};
use super::words::describe;
use super::AugmentConfig;
use crate::effects::{def, GridSpan};
use crate::identify::model::{Effect, Model};
use crate::identify::pem::PemReport;
use crate::identify::predict;
use crate::io::data::Record;
/// Grid values re-identified fully after each ranking (frozen θ per model, warm re-fit).
const TOP_FROZEN: usize = 3;

/// Golden-section evaluations when refining a continuous actuator parameter.
const REFINE_STEPS: usize = 8;

/// One-step cost (mean squared error, x̂(0) estimated per record) of a fixed model.
fn frozen_cost(model: &Model, est: &[Record]) -> f64 {
    let mut sse = 0.0;
    let mut n = 0usize;
    for r in est {
        let x0 = predict::estimate_x0(model, r);
        let yhat = predict::one_step(model, r, &x0);
        sse +=
            r.y.iter()
                .zip(&yhat)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>();
        n += r.len();
    }
    if sse.is_finite() {
        sse / n.max(1) as f64
    } else {
        f64::INFINITY
    }
}

/// The structural-parameter grid of an actuator effect: the effect's own search
/// ([`crate::effects::Def::search`]) over the estimation records.
fn actuator_grid(kind: EffectKind, est: &[Record], ts: f64) -> Vec<f64> {
    (def(kind).search)(&GridSpan::of(ts, est.iter().map(|r| &r.u[..])))
}

/// The chosen actuator candidate: its re-identification and the grid/refinement trail.
struct ActuatorChoice {
    rep: PemReport,
    value: f64,
    scored: usize,
    reidentified: usize,
}

fn choose_actuator(
    kind: EffectKind,
    input: &Model,
    base: &Model,
    est: &[Record],
    cfg: &AugmentConfig,
) -> Option<ActuatorChoice> {
    let grid = actuator_grid(kind, est, input.ts);
    if grid.is_empty() {
        return None;
    }
    let score = |m: &Model| -> Vec<f64> {
        let f = |v: &f64| frozen_cost(&m.clone().with_effect(Effect::zero(kind, *v)), est);
        crate::par::map(&grid, cfg.parallel, f)
    };
    let mut pick: Vec<usize> = Vec::new();
    let add_best = |c: &[f64], pick: &mut Vec<usize>| {
        let mut idx: Vec<usize> = (0..grid.len()).filter(|i| c[*i].is_finite()).collect();
        idx.sort_by(|a, b| c[*a].total_cmp(&c[*b]));
        for i in idx.into_iter().take(TOP_FROZEN) {
            if !pick.contains(&i) {
                pick.push(i);
            }
        }
    };
    for m in [input, base] {
        add_best(&score(m), &mut pick);
    }
    // A model identified without the effect has adapted to its absence: with θ frozen, a
    // slow gear or an angle limit only makes it worse, so the frozen cost can fall monotonically
    // towards "no limit" and miss a sharp optimum that re-identification finds (a 3 °/s gear
    // limit on one 1 800 s record: frozen cost best at 20 °/s, re-identified cost 37 % lower
    // at 3 °/s). So every grid value is also re-identified once, warm-started from `base`.
    let warm_cost = |v: &f64| -> f64 {
        let m = base.clone().with_effect(Effect::zero(kind, *v));
        reidentify_warm(est, &m, cfg).map_or(f64::INFINITY, |r| r.cost)
    };
    let warm: Vec<f64> = crate::par::map(&grid, cfg.parallel, warm_cost);
    add_best(&warm, &mut pick);
    let warm_scanned = grid.len();
    let fit_at = |v: f64| -> Option<PemReport> {
        let t = input.clone().with_effect(Effect::zero(kind, v));
        let mut best = reidentify(est, &t, cfg).ok();
        let warm = base.clone().with_effect(Effect::zero(kind, v));
        if let Ok(w) = reidentify_warm(est, &warm, cfg) {
            if best.as_ref().map_or(true, |b| w.cost < b.cost) {
                best = Some(w);
            }
        }
        best
    };
    let tried: Vec<(usize, Option<PemReport>)> =
        crate::par::map(&pick, cfg.parallel, |&i| (i, fit_at(grid[i])));
    let reidentified = tried.len() + warm_scanned;
    let (bi, brep) = tried
        .into_iter()
        .filter_map(|(i, r)| r.map(|r| (i, r)))
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))?;
    let mut best = ActuatorChoice {
        value: grid[bi],
        rep: brep,
        scored: 2 * grid.len(),
        reidentified,
    };
    if kind == EffectKind::DeadTime {
        return Some(best);
    }
    // golden-section refinement between the neighbours of the best grid value
    let lo = if bi > 0 { grid[bi - 1] } else { grid[bi] * 0.8 };
    let hi = if bi + 1 < grid.len() {
        grid[bi + 1]
    } else {
        grid[bi] * 1.2
    };
    refine(kind, (lo, hi), &mut best, est, cfg);
    Some(best)
}

/// Golden-section search for `best`'s value on `(lo, hi)`, every point re-identified
/// warm-started from `best`'s model; `best` takes the better last point when its cost is lower.
fn refine(
    kind: EffectKind,
    (lo, hi): (f64, f64),
    best: &mut ActuatorChoice,
    est: &[Record],
    cfg: &AugmentConfig,
) {
    let mut reidentified = best.reidentified;
    let start = best.rep.model.clone();
    let eval = |v: f64| -> (f64, Option<PemReport>) {
        let m = start.clone().with_effect(Effect::zero(kind, v));
        match reidentify_warm(est, &m, cfg) {
            Ok(r) => (r.cost, Some(r)),
            Err(_) => (f64::INFINITY, None),
        }
    };
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut rc) = eval(c);
    let (mut fd, mut rd) = eval(d);
    reidentified += 2;
    for _ in 0..REFINE_STEPS {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            rd = rc.take();
            c = b - g * (b - a);
            (fc, rc) = eval(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            rc = rd.take();
            d = a + g * (b - a);
            (fd, rd) = eval(d);
        }
        reidentified += 1;
    }
    best.reidentified = reidentified;
    for (v, f, r) in [(c, fc, rc), (d, fd, rd)] {
        if let Some(r) = r {
            if f < best.rep.cost {
                best.rep = r;
                best.value = v;
            }
        }
    }
}

/// Step 2 for an actuator effect: the structural parameter chosen ([`choose_actuator`]) and
/// its structure identified as the baseline was; with the search in words.
pub(super) fn actuator_candidate(
    kind: EffectKind,
    model: &Model,
    base: &Model,
    est_part: &[Record],
    cfg: &AugmentConfig,
) -> (Option<PemReport>, String) {
    // the structural parameter is searched on blocks of records longer than the
    // diagnosis window (`crate::diagnose::window`); the chosen structure is then
    // identified on all of them
    let blocks = crate::diagnose::window(est_part);
    let search_on = blocks.as_deref().unwrap_or(est_part);
    match choose_actuator(kind, model, base, search_on, cfg) {
        Some(c) => {
            let mut note = format!(
                "{} grid values scored with θ frozen, {} re-identified, best {}",
                c.scored,
                c.reidentified,
                describe(&Effect::zero(kind, c.value), model.ts)
            );
            if let Some(b) = &blocks {
                note.push_str(&format!(
                    "; searched on {} blocks of up to {} samples spread over the records",
                    b.len(),
                    crate::diagnose::WINDOW_BLOCK
                ));
            }
            // the chosen value's structure identified as the baseline was
            let fin = reidentify_final(est_part, &c.rep.model, &[], cfg);
            // (the search's own fit only stands in when it was made on the same records)
            let fin = match (fin, blocks) {
                (Ok(f), _) => Some(f),
                (Err(_), None) => Some(c.rep),
                (Err(_), Some(_)) => None,
            };
            (fin, note)
        }
        None => (None, "no usable grid value".to_string()),
    }
}
