//! From an identified effect to the simulator's physics ([`to_sim_effect`]): the
//! calibrations of bias, nonlinear damping, wind and current on runs of the ship.

use rayon::prelude::*;

use crate::effects::SimCounterpart;
use crate::identify::model::{Effect, Model};
use crate::identify::predict;
use crate::io::data::Record;
use crate::sim::{self, Scenario, Ship, SimEffect};
/// Converts an identified model effect into the simulator's physical parameters, for writing
/// it into a ship file (`--ship`). `None` when the effect has no physical counterpart in the
/// simulator (damping identified with the wrong sign) or a calibration run fails.
///
/// Conversions and their approximations:
/// - dead time: `samples·Ts` (the simulator's delay acts before its own servo lag);
/// - the gear's rate, angle limit, dead band, gyro offset: carried over unchanged (the model's ũ is the pod
///   angle before the simulator's servo lag);
/// - asymmetry β: starboard gain β (the model scales the effective input by `1 + β` for
///   δ > 0, the simulator the steering part of the pods' side force);
/// - bias β (degrees of equivalent pod angle): the yaw moment whose steady turn on the
///   simulator equals that of a constant pod angle δ = β (secant iterations from a test
///   moment; linear about straight running);
/// - nonlinear damping: the extra Norrbin `n_rr` whose steady turn rates at δ = 7.5°, 15°
///   and 25° best match the augmented model's (least squares; absolute rates, so only what
///   the simulator's hull lacks is attributed to `n_rr`);
/// - wind and current: speed and direction whose heading harmonics, as the model's θ sees
///   them on calibration runs of the simulator, match the model's gains (a speed grid with
///   golden-section refinement; the direction by rotating the harmonics). The calibration
///   uses noise-free runs of one identification input on eight headings, so it costs about
///   a second.
///
/// ```
/// use yawcast::{diagnose::augment::to_sim_effect, identify::model::{Effect, Model}, sim::{Ship, SimEffect}};
/// let m = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.0, 0.0]).unwrap();
/// let e = to_sim_effect(&Effect::DeadTime { samples: 2 }, &m, &Ship::default_lng());
/// assert_eq!(e, Some(SimEffect::DeadTime { delay_s: 2.0 }));
/// ```
pub fn to_sim_effect(effect: &Effect, model: &Model, ship: &Ship) -> Option<SimEffect> {
    let e = match effect.sim_counterpart(model.ts) {
        SimCounterpart::Direct(e) => e,
        SimCounterpart::Moment { beta } => bias_to_moment(beta, ship)?,
        SimCounterpart::Damping { beta, cubic } => damping_to_nrr(beta, cubic, model, ship)?,
        SimCounterpart::Heading => heading_effect(effect, model, ship)?,
    };
    e.validate("effect").ok()?;
    Some(e)
}

/// Steady yaw rate (deg/s) of `ship` at constant command `delta` with extra `effects`.
fn steady_rate(ship: &Ship, delta: f64, effects: Vec<SimEffect>) -> Option<f64> {
    let sc = Scenario {
        name: "calibration".into(),
        n_samples: 400,
        input: sim::InputSpec::Constant { delta_deg: delta },
        noise: sim::NoiseSpec::none(),
        effects,
        initial_heading_deg: Some(0.0),
        ..Scenario::default()
    };
    let r = sim::simulate(ship, &sc, 0).ok()?;
    let tail = &r.y[r.len() * 3 / 4..];
    Some(tail.iter().sum::<f64>() / tail.len() as f64)
}

/// Bias β (input-equivalent degrees) → yaw moment: the moment whose steady turn equals that of
/// δ = β (secant iterations from a test moment).
fn bias_to_moment(beta: f64, ship: &Ship) -> Option<SimEffect> {
    if beta == 0.0 {
        return Some(SimEffect::Bias { yaw_moment_nm: 0.0 });
    }
    let r0 = steady_rate(ship, 0.0, vec![])?;
    let target = steady_rate(ship, beta, vec![])? - r0;
    let mut m = sim::HIDDEN_BIAS_NM * beta.signum() * (beta.abs() / 4.5);
    for _ in 0..3 {
        let r = steady_rate(ship, 0.0, vec![SimEffect::Bias { yaw_moment_nm: m }])? - r0;
        if r.abs() < 1e-12 {
            return None;
        }
        m *= target / r;
    }
    Some(SimEffect::Bias { yaw_moment_nm: m })
}

/// Steady-state change of the model's yaw rate (deg/s) between command `delta` and 0.
fn model_steady(model: &Model, delta: f64) -> f64 {
    let n = 600;
    let run = |u: f64| {
        let r = Record::from_uy("steady", model.ts, vec![u; n], vec![0.0; n]);
        predict::simulate(model, &r, &vec![0.0; model.n])[n - 1]
    };
    run(delta) - run(0.0)
}

/// Test commands of the damping calibration (deg): the identification amplitudes' range.
const DAMPING_DELTAS: [f64; 3] = [7.5, 15.0, 25.0];

/// Nonlinear damping β → Norrbin `n_rr`: the extra simulator damping whose steady turn
/// rates at δ = 7.5°, 15° and 25° best match the augmented model's (least squares over
/// `n_rr`, golden-section search on 0..=2). Matching absolute turn rates (rather than the
/// ratio the effect makes in the model) attributes to `n_rr` only what the simulator's hull
/// lacks. `None` when the model turns faster than the simulator without any extra damping
/// (β of the wrong sign for a damping).
fn damping_to_nrr(beta: f64, cubic: bool, model: &Model, ship: &Ship) -> Option<SimEffect> {
    if beta >= 0.0 {
        return None;
    }
    let want: Vec<f64> = DAMPING_DELTAS
        .iter()
        .map(|d| model_steady(model, *d))
        .collect();
    if want.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let r0 = steady_rate(ship, 0.0, vec![])?;
    let cost = |nrr: f64| -> f64 {
        let e = vec![SimEffect::NonlinearDamping { n_rr: nrr, cubic }];
        DAMPING_DELTAS
            .iter()
            .zip(&want)
            .map(|(d, w)| match steady_rate(ship, *d, e.clone()) {
                Some(r) => (r - r0 - w).powi(2),
                None => f64::INFINITY,
            })
            .sum()
    };
    let nrr = golden_min(cost, 0.0, 2.0, 20);
    (nrr > 1e-4).then_some(SimEffect::NonlinearDamping { n_rr: nrr, cubic })
}

/// Golden-section minimum of `f` on `[a, b]` with `iters` narrowing steps.
fn golden_min(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, iters: usize) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iters {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        c
    } else {
        d
    }
}

/// Heading harmonics (β_s2, β_c2, β_s1, β_c1) that the model's θ (frozen) gives to simulator
/// records carrying `effect`: eight noise-free 900-sample runs of one identification input,
/// started on headings 0°, 45°, …, 315°, the gains fitted by linear least squares on the
/// one-step errors. One input for all eight headings makes any heading-independent misfit of
/// the model (hull nonlinearity, say) orthogonal to the harmonics, so only the effect's
/// heading dependence is measured.
pub(super) fn reference_harmonics(
    effect: SimEffect,
    model: &Model,
    ship: &Ship,
) -> Option<[f64; 4]> {
    let kind = effect.kind();
    let recs: Vec<Record> = (0..8)
        .into_par_iter()
        .map(|i| {
            let sc = Scenario {
                name: format!("calibration-{i}"),
                n_samples: 900,
                noise: sim::NoiseSpec::none(),
                effects: vec![effect],
                initial_heading_deg: Some(45.0 * i as f64),
                ..Scenario::default()
            };
            sim::simulate(ship, &sc, 7).ok()
        })
        .collect::<Option<Vec<_>>>()?;
    // θ frozen at the model's, the heading gains by linear least squares on the one-step
    // errors (the predictor is affine in them: measured y and ψ enter the regressors)
    let zero = model.clone().with_effect(Effect::zero(kind, 0.0));
    let q = zero.effect(kind)?.gains().len();
    let with_gain = |j: usize| {
        let mut m = zero.clone();
        let mut g = vec![0.0; q];
        g[j] = 1.0;
        if let Some(e) = m.effects.iter_mut().find(|e| e.kind() == kind) {
            e.set_gains(&g);
        }
        m
    };
    let models: Vec<Model> = (0..q).map(with_gain).collect();
    let mut ata = nalgebra::DMatrix::<f64>::zeros(q, q);
    let mut atb = nalgebra::DVector::<f64>::zeros(q);
    for r in &recs {
        let x0 = vec![0.0; model.n];
        let base = predict::one_step(&zero, r, &x0);
        let cols: Vec<Vec<f64>> = models
            .iter()
            .map(|m| {
                predict::one_step(m, r, &x0)
                    .iter()
                    .zip(&base)
                    .map(|(a, b)| a - b)
                    .collect()
            })
            .collect();
        // skip the start-up transient of x̂(0) = 0
        for t in (4 * model.n).min(r.len())..r.len() {
            let e = r.y[t] - base[t];
            for i in 0..q {
                atb[i] += cols[i][t] * e;
                for j in 0..q {
                    ata[(i, j)] += cols[i][t] * cols[j][t];
                }
            }
        }
    }
    let g = ata.cholesky()?.solve(&atb);
    let mut e = Effect::zero(kind, 0.0);
    e.set_gains(g.as_slice());
    e.harmonics()
}

/// The harmonics of `h(ψ − Δ)` given those of `h(ψ)` (Δ in degrees): a moment that depends
/// on the wind's or current's direction relative to the heading turns with the direction.
fn rotate(g: &[f64; 4], delta_deg: f64) -> [f64; 4] {
    let mut out = [0.0; 4];
    for (m, i) in [(2.0, 0), (1.0, 2)] {
        let (sn, cs) = (m * delta_deg.to_radians()).sin_cos();
        let (s, c) = (g[i], g[i + 1]);
        out[i] = s * cs + c * sn;
        out[i + 1] = c * cs - s * sn;
    }
    out
}

/// The rotation Δ (1° grid, then refined) minimising ‖target − rotate(reference, Δ)‖²;
/// returns (Δ, residual).
fn match_rotation(target: &[f64; 4], reference: &[f64; 4]) -> (f64, f64) {
    let res = |d: f64| -> f64 {
        rotate(reference, d)
            .iter()
            .zip(target)
            .map(|(a, b)| (b - a).powi(2))
            .sum()
    };
    let coarse = (0..360)
        .map(|d| d as f64)
        .min_by(|a, b| res(*a).total_cmp(&res(*b)))
        .unwrap_or(0.0);
    let d = golden_min(res, coarse - 1.0, coarse + 1.0, 20);
    (d.rem_euclid(360.0), res(d))
}

/// Wind or current gains → speed and direction. The moment depends on the direction only
/// relative to the heading, so the harmonics of a wind from Δ are those from 000° rotated by
/// Δ; their size, though, is far from a simple power of the speed (the ship's own speed
/// enters the apparent wind). So: for each speed of a geometric grid (wind 0.3–10 m/s,
/// current 0.02–1.5 m/s), the harmonics the model's θ gives to simulator records with that
/// wind from 000° (or current towards 000°) are computed ([`reference_harmonics`]) and
/// rotated to match the model's best; the speed with the smallest mismatch is refined by
/// golden-section search (in log speed) and its rotation is the direction.
fn heading_effect(effect: &Effect, model: &Model, ship: &Ship) -> Option<SimEffect> {
    let target = effect.harmonics()?;
    let wind = matches!(effect, Effect::Wind { .. });
    let make = |speed: f64, dir: f64| {
        if wind {
            SimEffect::Wind {
                speed_mps: speed,
                from_deg: dir.rem_euclid(360.0),
            }
        } else {
            SimEffect::Current {
                speed_mps: speed,
                towards_deg: dir.rem_euclid(360.0),
            }
        }
    };
    let (lo, hi): (f64, f64) = if wind { (0.3, 10.0) } else { (0.02, 1.5) };
    let at = |ln_v: f64| -> (f64, f64) {
        match reference_harmonics(make(ln_v.exp(), 0.0), model, ship) {
            Some(r) => {
                let (d, res) = match_rotation(&target, &r);
                (res, d)
            }
            None => (f64::INFINITY, 0.0),
        }
    };
    let k = 12;
    let grid: Vec<f64> = (0..k)
        .map(|i| lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (k - 1) as f64)
        .collect();
    let res: Vec<f64> = grid.iter().map(|g| at(*g).0).collect();
    let bi = (0..k).min_by(|a, b| res[*a].total_cmp(&res[*b]))?;
    if !res[bi].is_finite() {
        return None;
    }
    let a = grid[bi.saturating_sub(1)];
    let b = grid[(bi + 1).min(k - 1)];
    let best = golden_min(|x| at(x).0, a, b, 8);
    let (_, dir) = at(best);
    Some(make(best.exp(), dir))
}
