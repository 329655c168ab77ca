//! Tests of the test worlds: manoeuvres against published trials, every effect's physics,
//! the shared environment and seeding.
use super::*;
use crate::sim::InputSpec;

fn quiet(n: usize, effects: Vec<SimEffect>, w: &World) -> Scenario {
    Scenario {
        noise: NoiseSpec::none(),
        initial_heading_deg: Some(30.0),
        n_samples: n,
        input: w.default_input(),
        effects,
        ..Scenario::default()
    }
}

/// The 35° turning circle and the 10°/10° zig-zag of full-scale `kind`, printed in
/// lengths: `(advance / L, tactical diameter / L, the turn, the zig-zag)`.
pub(super) fn manoeuvres(kind: WorldKind) -> (f64, f64, TurningResult, ZigzagResult) {
    let w = World::new(kind, None).unwrap();
    let l = w.hull().unwrap().lpp();
    let tc = w.turning_circle(35.0).unwrap();
    let z = w.zigzag(10.0, 10.0).unwrap();
    let (adv, td) = (tc.advance_m / l, tc.tactical_diameter_m / l);
    println!(
        "{} 35°: advance {adv:.2} L, tactical diameter {td:.2} L, steady r {:.3} °/s, U {:.2} m/s; 10/10: {z:?}",
        kind.name(),
        tc.steady_r_degps,
        tc.steady_speed_mps
    );
    (adv, td, tc, z)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

const NEW: [WorldKind; 5] = [
    WorldKind::Kvlcc2,
    WorldKind::Mariner,
    WorldKind::SeiunMaru,
    WorldKind::Container,
    WorldKind::EssoOsaka,
];

#[test]
fn the_lng_world_is_the_built_in_simulator() {
    let w = World::new(WorldKind::Lng, None).unwrap();
    let sc = Scenario {
        n_samples: 300,
        effects: vec![SimEffect::hidden(EffectKind::Wind, 1.0)],
        log_wind: true,
        ..Scenario::default()
    };
    let a = w.simulate(&sc, 4).unwrap();
    assert_eq!(
        a,
        super::super::simulate(&Ship::default_lng(), &sc, 4).unwrap()
    );
    for k in EffectKind::ALL {
        assert_eq!(w.hidden(k, 0.7), SimEffect::hidden(k, 0.7));
    }
    assert_eq!(w.default_ts(), 1.0);
    assert_eq!(w.name(), Ship::default_lng().name);
}

#[test]
fn canonical_strengths_carry_over_by_the_hull_time() {
    let (l, _, _, u) = lng_reference();
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let t = w.time_ratio();
        let h = w.hull().unwrap();
        assert!((t - (h.lpp() / h.u0()) / (l / u)).abs() < 1e-12);
        println!(
            "{}: L/U = {:.1} s, {t:.2} × the built-in ship's",
            kind.name(),
            h.lpp() / h.u0()
        );
        assert_eq!(
            w.hidden(EffectKind::DeadTime, 1.0),
            SimEffect::DeadTime { delay_s: 2.0 * t }
        );
        assert_eq!(
            w.hidden(EffectKind::Saturation, 1.0),
            SimEffect::Saturation { limit_deg: 8.0 }
        );
        for k in EffectKind::ALL {
            w.hidden(k, 1.0).validate("x").unwrap();
        }
        let InputSpec::Prbs {
            min_hold_s,
            max_hold_s,
            ..
        } = w.default_input()
        else {
            panic!()
        };
        assert_eq!(
            (min_hold_s, max_hold_s),
            ((5.0 * t).round(), (30.0 * t).round())
        );
    }
    // a scaled KVLCC2 keeps full-scale wind in Froude proportion
    let m = World::new(WorldKind::Kvlcc2, Some(7.0)).unwrap();
    let SimEffect::Wind { speed_mps, .. } = m.hidden(EffectKind::Wind, 1.0) else {
        panic!()
    };
    assert!((speed_mps - 3.0 * 24f64.sqrt() * (7.0f64 / 320.0).sqrt()).abs() < 1e-12);
}

#[test]
fn the_seed_fixes_the_record_and_the_background_is_always_there() {
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let sc = quiet(400, Vec::new(), &w);
        let a = w.simulate(&sc, 11).unwrap();
        assert_eq!(a, w.simulate(&sc, 11).unwrap());
        let b = w.simulate(&sc, 12).unwrap();
        assert_ne!(a.u, b.u);
        // on a straight course (δ = 0) the background yaw disturbance and the sensors
        // still move the yaw rate
        let straight = Scenario {
            input: InputSpec::Constant { delta_deg: 0.0 },
            ..sc.clone()
        };
        let s = w.simulate(&straight, 11).unwrap();
        let sd = (s.y.iter().map(|x| x * x).sum::<f64>() / s.len() as f64).sqrt();
        println!(
            "{}: rms yaw rate on a straight course {sd:.4} °/s",
            kind.name()
        );
        assert!(sd > 1e-3 && sd < 0.2, "{sd}");
        // the default noise adds to it, on its own stream: the input is unchanged
        let noisy = w
            .simulate(
                &Scenario {
                    noise: NoiseSpec::default(),
                    ..sc.clone()
                },
                11,
            )
            .unwrap();
        assert_eq!(noisy.u, a.u);
        assert!(max_abs_diff(&noisy.y, &a.y) > 0.03);
    }
}

#[test]
fn the_background_disturbance_scales_with_the_scenario() {
    // the same commands (their own stream) with the background disturbance off, as it is,
    // and doubled: what it adds to the yaw rate doubles (the hull nearly linear at its
    // size), off it adds nothing, and the world's own scale is the default record
    let rms = |a: &[f64], b: &[f64]| {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let at = |k: f64| {
            let sc = Scenario {
                disturbance: k,
                ..quiet(1200, Vec::new(), &w)
            };
            w.simulate(&sc, 21).unwrap()
        };
        let (none, one, two) = (at(0.0), at(1.0), at(2.0));
        assert_eq!(one, w.simulate(&quiet(1200, Vec::new(), &w), 21).unwrap());
        assert_eq!(none.u, two.u);
        let (a, b) = (rms(&one.y, &none.y), rms(&two.y, &none.y));
        println!(
            "{}: the background adds {a:.4} °/s, doubled {b:.4}",
            kind.name()
        );
        assert!(a > 1e-3, "{a}");
        assert!((b / a - 2.0).abs() < 0.3, "{a} {b}");
    }
    let lng = Scenario {
        disturbance: 2.0,
        ..Scenario::default()
    };
    let err = crate::sim::simulate(&Ship::default_lng(), &lng, 1).unwrap_err();
    assert!(err.to_string().contains("disturbance"), "{err}");
}

#[test]
fn every_effect_changes_what_it_should() {
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let n = 900;
        let base = w.simulate(&quiet(n, Vec::new(), &w), 7).unwrap();
        for k in EffectKind::ALL {
            let e = w.hidden(k, 1.0);
            let rec = w.simulate(&quiet(n, vec![e], &w), 7).unwrap();
            assert_eq!(rec.u, base.u, "{}: same command", k.name());
            let dy = max_abs_diff(&rec.y, &base.y);
            let dpsi = max_abs_diff(rec.psi.as_ref().unwrap(), base.psi.as_ref().unwrap());
            let dv = max_abs_diff(rec.speed.as_ref().unwrap(), base.speed.as_ref().unwrap());
            println!(
                "{} {}: {e:?}: Δr {dy:.4} °/s, Δψ {dpsi:.2}°, ΔU {dv:.4} m/s",
                kind.name(),
                k.name()
            );
            match e {
                SimEffect::GyroBias { bias_degps } => {
                    // the rate shifts by the bias, heading and speed do not move
                    let shift = mean(&rec.y) - mean(&base.y);
                    assert!((shift - bias_degps).abs() < 1e-3, "{shift}");
                    assert_eq!(dpsi, 0.0);
                    assert_eq!(dv, 0.0);
                }
                SimEffect::Current { .. } => {
                    // the ship is carried: its speed over ground changes by metres per
                    // second, its turning hardly (only the air it feels changes)
                    assert!(dv > 0.5, "{dv}");
                }
                _ => {
                    assert!(dy > 0.005 || dpsi > 0.5, "{}: Δr {dy}, Δψ {dpsi}", k.name());
                }
            }
        }
    }
}

#[test]
fn current_carries_the_ship_and_exerts_no_moment() {
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let h = w.hull().unwrap();
        let cur = SimEffect::Current {
            speed_mps: 1.5,
            towards_deg: 90.0,
        };
        let (mut calm, _, _) = Physics::new(h.as_ref(), &[]);
        let (mut carried, _, _) = Physics::new(h.as_ref(), &[cur]);
        // without air, the current changes no acceleration and moves the ship by itself
        calm.windage.a_l = 0.0;
        calm.windage.a_f = 0.0;
        carried.windage = calm.windage;
        let s = [h.u0(), -0.3, 0.004, 0.0, 0.0, 30f64.to_radians(), 0.0, 0.0];
        let a = calm.deriv(h.as_ref(), &s, 0.1, CALM);
        let b = carried.deriv(h.as_ref(), &s, 0.1, CALM);
        assert_eq!(a[..3], b[..3]);
        assert!((b[3] - a[3]).abs() < 1e-12 && (b[4] - a[4] - 1.5).abs() < 1e-12);
        // speed over ground: the water velocity plus the current
        let sog = carried.sog(&s);
        let (sp, cp) = s[5].sin_cos();
        let (vn, ve) = (s[0] * cp - s[1] * sp, s[0] * sp + s[1] * cp + 1.5);
        assert!((sog - vn.hypot(ve)).abs() < 1e-12);
        // in a record at δ = 0 from 030°, the speed over ground is the speed through the
        // water along the heading plus the current (1.5·cos 60° = 0.75 m/s along at
        // first); the heading hardly changes with the current
        let straight = Scenario {
            input: InputSpec::Constant { delta_deg: 0.0 },
            ..quiet(300, Vec::new(), &w)
        };
        let base = w.simulate(&straight, 3).unwrap();
        let with = w
            .simulate(
                &Scenario {
                    effects: vec![cur],
                    ..straight.clone()
                },
                3,
            )
            .unwrap();
        let (psi, stw) = (base.psi.as_ref().unwrap(), base.speed.as_ref().unwrap());
        let sog = with.speed.as_ref().unwrap();
        let err = (0..base.len())
            .map(|k| {
                let (sp, cp) = psi[k].to_radians().sin_cos();
                let expect = (stw[k] * cp).hypot(stw[k] * sp + 1.5);
                (sog[k] - expect).abs()
            })
            .fold(0.0, f64::max);
        let gain = mean(sog) - mean(stw);
        println!(
            "{}: SOG − STW {gain:.3} m/s, worst error {err:.4}",
            kind.name()
        );
        // (the error is the drift angle, left out of `expect`)
        assert!(err < 0.08 && gain > 0.5, "{err} {gain}");
        assert!(max_abs_diff(with.psi.as_ref().unwrap(), psi) < 2.0);
    }
}

#[test]
fn course_over_ground_is_the_ground_velocity_with_gps_noise() {
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let cur = SimEffect::Current {
            speed_mps: 1.5,
            towards_deg: 90.0,
        };
        let straight = Scenario {
            input: InputSpec::Constant { delta_deg: 0.0 },
            effects: vec![cur],
            ..quiet(300, Vec::new(), &w)
        };
        let rec = w.simulate(&straight, 3).unwrap();
        let (psi, cog) = (rec.psi.as_ref().unwrap(), rec.cog.as_ref().unwrap());
        // across the heading the ground velocity is the sway plus the current's
        // 1.5·cos ψ m/s: against the same record without the current, the current's part
        let calm = w
            .simulate(
                &Scenario {
                    effects: Vec::new(),
                    ..straight.clone()
                },
                3,
            )
            .unwrap();
        let across = |r: &Record, k: usize| {
            let (s, c, p) = (&r.speed, &r.cog, &r.psi);
            let (s, c, p) = (
                s.as_ref().unwrap(),
                c.as_ref().unwrap(),
                p.as_ref().unwrap(),
            );
            s[k] * (c[k] - p[k]).to_radians().sin()
        };
        let worst = (0..rec.len())
            .map(|k| {
                let d = across(&rec, k) - across(&calm, k);
                (d - 1.5 * psi[k].to_radians().cos()).abs()
            })
            .fold(0.0, f64::max);
        println!("{}: worst across error {worst:.3} m/s", kind.name());
        assert!(worst < 0.1, "{worst}");
        assert!(cog.iter().all(|c| (0.0..360.0).contains(c)));
        // the GPS's velocity noise has its own stream: the other channels are unchanged
        let noisy = Scenario {
            noise: NoiseSpec {
                speed_std_mps: 0.05,
                ..NoiseSpec::none()
            },
            ..straight.clone()
        };
        let a = w.simulate(&noisy, 3).unwrap();
        assert_eq!(a.psi, rec.psi);
        assert_eq!(a.y, rec.y);
        let dc: Vec<f64> = (0..a.len())
            .map(|k| (a.cog.as_ref().unwrap()[k] - cog[k] + 180.0).rem_euclid(360.0) - 180.0)
            .collect();
        // 0.05 m/s across at ≈ 8 m/s: ≈ 0.36° of course
        let sd = (dc.iter().map(|d| d * d).sum::<f64>() / dc.len() as f64).sqrt();
        assert!(sd > 0.2 && sd < 0.6, "{sd}");
    }
}

#[test]
fn wind_moment_follows_the_blendermann_curve() {
    let w = World::new(WorldKind::Kvlcc2, None).unwrap();
    let h = w.hull().unwrap();
    let s = [h.u0(), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let (calm, _, _) = Physics::new(h.as_ref(), &[]);
    let rdot = |from_deg: f64| {
        let wind = SimEffect::Wind {
            speed_mps: 20.0,
            from_deg,
        };
        let (p, _, _) = Physics::new(h.as_ref(), &[wind]);
        let (ua, va) = p.air(&s, CALM);
        let gamma = va.atan2(ua).to_degrees();
        let dr = p.deriv(h.as_ref(), &s, 0.0, CALM)[2] - calm.deriv(h.as_ref(), &s, 0.0, CALM)[2];
        (gamma, dr)
    };
    // starboard bow: the bow falls off to port; starboard quarter: it turns into the
    // wind; mirrored from port
    let (g, d) = rdot(30.0);
    assert!(g > 0.0 && g < 60.0 && d < 0.0, "{g} {d}");
    let (g, d) = rdot(150.0);
    assert!(g > 100.0 && d > 0.0, "{g} {d}");
    let (g, d) = rdot(-30.0);
    assert!(g < 0.0 && d > 0.0, "{g} {d}");
    // in a record the gusts make the apparent wind speed vary by about their 10 %
    let sc = Scenario {
        log_wind: true,
        input: InputSpec::Constant { delta_deg: 0.0 },
        ..quiet(1200, vec![w.hidden(EffectKind::Wind, 1.0)], &w)
    };
    let rec = w.simulate(&sc, 5).unwrap();
    let ws = rec.wind_speed.as_ref().unwrap();
    let m = mean(ws);
    let sd = (ws.iter().map(|x| (x - m).powi(2)).sum::<f64>() / ws.len() as f64).sqrt();
    println!("apparent wind {m:.2} m/s ± {sd:.2}");
    assert!(sd / m > 0.03 && sd / m < 0.2, "{m} {sd}");
}

#[test]
fn one_step_replays_are_the_run_itself_and_longer_ones_lose_the_disturbance() {
    let hull = mariner::Mariner::new();
    let n = 400;
    let (phys, gear, _) = Physics::new(&hull, &[SimEffect::DeadTime { delay_s: 3.0 }]);
    // a yaw moment worth ±2° of rudder, slowly varying
    let m = rudder_moment(&hull, 2.0);
    let weather: Vec<Weather> = (0..n)
        .map(|k| Weather {
            moment: m * (k as f64 * 0.05).sin(),
            gust: 1.0,
        })
        .collect();
    let cmds: Vec<f64> = (0..n)
        .map(|k| if (k / 60) % 2 == 0 { 15.0 } else { -10.0 })
        .collect();
    let mut states = Vec::new();
    let mut gears = Vec::new();
    run_hull(
        HullRun {
            hull: &hull,
            phys: &phys,
            act: gear,
            ts: 1.0,
            n,
            dt_max: 0.25,
            warmup_s: 20.0,
            psi0_deg: 0.0,
            weather: &weather,
        },
        |k, _| cmds[k],
        |_, s, w, g| {
            states.push((*s, w));
            gears.push(g.clone());
            true
        },
    )
    .unwrap();
    let replay = oracle::Replay {
        step: Integrator::new(&hull, &phys, 1.0, 0.25),
        states: &states,
        gears: &gears,
        cmds: &cmds,
        tau_background_s: 100.0,
        tau_gust_s: 20.0,
        drift: &vec![0.0; n],
        tau_drift_s: 600.0,
        gyro_bias_degps: 0.0,
    };
    let truth: Vec<f64> = states.iter().map(|(s, _)| s[2]).collect();
    // one step from the true state in the sample's own weather is the run, bit for bit
    let one = oracle::rates(&replay, 1);
    assert!(one
        .iter()
        .zip(&truth)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    // ten steps ahead the moment is only expected to decay: close, not exact
    let ten = oracle::rates(&replay, 10);
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let err: Vec<f64> = ten.iter().zip(&truth).map(|(a, b)| a - b).collect();
    let (e, r) = (rms(&err), rms(&truth));
    assert!(e > 1e-6 * r && e < 0.1 * r, "{e} vs {r}");
    // the gyro reading adds the offset and the decayed drift
    let drift: Vec<f64> = (0..n).map(|k| 0.01 * (k as f64 * 0.01).cos()).collect();
    let read = oracle::predict(
        &oracle::Replay {
            drift: &drift,
            gyro_bias_degps: 0.2,
            ..replay
        },
        10,
    );
    let want = ten[100].to_degrees() + 0.2 + drift[90] * (-10.0f64 / 600.0).exp();
    assert_eq!(read[100], want);
}

#[test]
fn the_worlds_own_predictor_beats_a_linear_model_of_the_hull() {
    use crate::identify::{pem, predict};
    let w = World::new(WorldKind::Mariner, None).unwrap();
    let sc = Scenario {
        n_samples: 900,
        input: w.default_input(),
        ..Scenario::default()
    };
    let fit_on = w.simulate(&sc, 5).unwrap();
    let (val, o10) = w.simulate_with_oracle(&sc, 6, 10).unwrap();
    assert_eq!(val, w.simulate(&sc, 6).unwrap());
    let m = pem::identify(&[fit_on], None, &pem::PemConfig::default())
        .unwrap()
        .model;
    let linear = predict::fit_at(&m, &val, predict::Horizon::Steps(10));
    let oracle = o10.fit(&val);
    assert!(oracle > linear + 1.0, "{oracle} vs {linear}");
    assert!(oracle < 100.0);
}

#[test]
fn the_autopilot_keeps_every_hull_on_its_set_course() {
    for kind in WorldKind::ALL {
        let w = World::new(kind, None).unwrap();
        let sc = Scenario {
            input: w.default_autopilot(),
            ..quiet(1800, Vec::new(), &w)
        };
        let r = w.simulate(&sc, 5).unwrap();
        let psi = r.psi.as_ref().unwrap();
        // the set course steps ±10° about the first heading: the heading follows it with a
        // small overshoot, the command moves mostly within a few degrees
        let dev = psi.iter().map(|p| (p - psi[0]).abs()).fold(0.0, f64::max);
        let rms = (r.u.iter().map(|u| u * u).sum::<f64>() / r.len() as f64).sqrt();
        let peak = r.u.iter().fold(0.0f64, |m, u| m.max(u.abs()));
        println!(
            "{}: heading within ±{dev:.1}°, command rms {rms:.2}°, peak {peak:.1}°",
            kind.name()
        );
        assert!(dev > 9.0 && dev < 13.0, "{dev}");
        assert!(rms > 1.0 && rms < 5.0, "{rms}");
        assert!(peak > 10.0 && peak <= 35.0, "{peak}");
        // the same seed gives the same record
        assert_eq!(r, w.simulate(&sc, 5).unwrap());
    }
}

/// The rudder that holds course (r = 0, p = 0; u, v and the heel steady) at heading `psi`
/// under `p`'s environment (deg).
fn holding_rudder(h: &dyn Hull, p: &Physics, psi: f64) -> f64 {
    // unknowns (u, v, δ, φ), equations (u̇, v̇, ṙ, ṗ); a hull without a roll mode keeps
    // φ = 0
    let rolls = {
        let s = [h.u0(), 0.0, 0.0, 0.0, 0.0, psi, 0.0, 0.01];
        p.deriv(h, &s, 0.0, CALM)[6] != 0.0
    };
    let f = |x: [f64; 4]| {
        let s = [x[0], x[1], 0.0, 0.0, 0.0, psi, 0.0, x[3]];
        let d = p.deriv(h, &s, x[2], CALM);
        nalgebra::Vector4::new(d[0], d[1], d[2], if rolls { d[6] } else { x[3] })
    };
    // Newton's method with a finite-difference Jacobian
    let mut x = [h.u0(), 0.0, 0.0, 0.0];
    for _ in 0..40 {
        let f0 = f(x);
        let mut j = nalgebra::Matrix4::zeros();
        for k in 0..4 {
            let mut y = x;
            let e = [1e-6, 1e-6, 1e-7, 1e-7][k];
            y[k] += e;
            j.set_column(k, &((f(y) - f0) / e));
        }
        let dx = j.lu().solve(&(-f0)).unwrap();
        for k in 0..4 {
            x[k] += dx[k];
        }
    }
    assert!(f(x).norm() < 1e-9, "{x:?}");
    x[2].to_degrees()
}

/// A wind's yaw moment, as the rudder that holds course against it, varies with heading
/// mostly once per turn: the ship's own speed makes the apparent wind's angle swing once
/// per turn. So `diagnose` reads the wind's resolution along its once-per-turn gains.
/// Measured (full strength, once / twice per turn): KVLCC2 0.59° / 0.01°, Mariner 1.07° /
/// 0.29°, the Seiun Maru 1.86° / 0.53°, the container ship 1.93° / 0.31° (heeled), the Esso
/// Osaka 0.71° / 0.03°; once per turn at half strength 0.15–0.42°.
#[test]
fn a_winds_moment_varies_with_heading_mostly_once_per_turn() {
    for kind in NEW {
        let w = World::new(kind, None).unwrap();
        let h = w.hull().unwrap();
        for strength in [1.0, 0.5] {
            let (calm, _, _) = Physics::new(h.as_ref(), &[]);
            let (windy, _, _) = Physics::new(h.as_ref(), &[w.hidden(EffectKind::Wind, strength)]);
            let n = 72;
            let mut a = [[0.0f64; 2]; 2];
            for i in 0..n {
                let psi = (i as f64 * 5.0).to_radians();
                let d = holding_rudder(h.as_ref(), &windy, psi)
                    - holding_rudder(h.as_ref(), &calm, psi);
                for (k, m) in [(0, 1.0), (1, 2.0)] {
                    a[k][0] += 2.0 * d * (m * psi).cos() / n as f64;
                    a[k][1] += 2.0 * d * (m * psi).sin() / n as f64;
                }
            }
            let (a1, a2) = (a[0][0].hypot(a[0][1]), a[1][0].hypot(a[1][1]));
            println!(
                "{} at {strength}: the holding rudder varies by {a1:.2}° once per turn, {a2:.2}° twice",
                kind.name()
            );
            assert!(a1 > 2.0 * a2 && (0.1..5.0).contains(&a1), "{a1} {a2}");
        }
    }
}

#[test]
fn a_world_sails_at_the_approach_speed_asked_on_the_revolutions_that_hold_it() {
    for (kind, scale, u) in [
        (WorldKind::EssoOsaka, Some(3.0), 0.3),
        (WorldKind::Kvlcc2, None, 4.0),
        (WorldKind::SeiunMaru, Some(4.0), 0.5),
        (WorldKind::Container, None, 11.0),
    ] {
        let w = World::new(kind, scale).unwrap();
        let s = w.at_speed(u).unwrap();
        assert_eq!(s.approach_speed(), u);
        assert!(s.name().ends_with(&format!(" at {u} m/s")), "{}", s.name());
        // the same hull and sampling; its time L/U and the moment ½ρL²dU² follow the speed
        assert_eq!(s.default_ts(), w.default_ts());
        let ratio = w.approach_speed() / u;
        assert!((s.time_ratio() / w.time_ratio() - ratio).abs() < 1e-12);
        let moment = |w: &World| match w.hidden(EffectKind::Bias, 1.0) {
            SimEffect::Bias { yaw_moment_nm } => yaw_moment_nm,
            e => panic!("{e:?}"),
        };
        assert!((moment(&s) / moment(&w) * ratio * ratio - 1.0).abs() < 1e-9);
        // straight ahead the propeller's thrust balances the resistance at the speed asked,
        // and the balance is stable: slower, the ship gains speed; faster, it loses it
        let h = s.hull().unwrap();
        let surge = |x: f64| h.accel([x, 0.0, 0.0], 0.0, [0.0; 3])[0];
        assert!(surge(u).abs() < 1e-9, "{}: {}", kind.name(), surge(u));
        assert!(surge(0.95 * u) > 0.0 && surge(1.05 * u) < 0.0);
    }
    // what cannot be asked
    let esso = World::new(WorldKind::EssoOsaka, None).unwrap();
    for (w, u, says) in [
        (
            World::new(WorldKind::Mariner, None).unwrap(),
            5.0,
            "design speed",
        ),
        (World::new(WorldKind::Lng, None).unwrap(), 1.0, "ship file"),
        (
            esso,
            1.0,
            "0.25–1.5 times the world's design speed of 8.230 m/s",
        ),
        (esso, 13.0, "8.230 m/s"),
        (esso, f64::NAN, "8.230 m/s"),
    ] {
        let e = w.at_speed(u).unwrap_err().to_string();
        assert!(e.contains("world.speed") && e.contains(says), "{e}");
    }
}
