//! Tests over the whole library: every kind's definition, parameters, knobs and scaling.

use super::*;

#[test]
fn hidden_covers_every_kind_and_validates() {
    for k in EffectKind::ALL {
        for s in [0.5, 1.0, 2.0] {
            let e = SimEffect::hidden(k, s);
            assert_eq!(e.kind(), k);
            e.validate("effects[0]").unwrap();
        }
        SimEffect::hidden(k, 0.0).validate("x").unwrap();
        SimEffect::hidden(k, -3.0).validate("x").unwrap();
    }
    assert!(SimEffect::hidden(EffectKind::Wind, f64::NAN)
        .validate("x")
        .is_err());
}

#[test]
fn serde_uses_stable_names() {
    #[derive(Serialize, Deserialize)]
    struct F {
        effects: Vec<SimEffect>,
    }
    let f = F {
        effects: EffectKind::ALL
            .iter()
            .map(|&k| SimEffect::hidden(k, 1.0))
            .collect(),
    };
    let txt = toml::to_string(&f).unwrap();
    for k in EffectKind::ALL {
        assert!(txt.contains(&format!("kind = \"{}\"", k.name())), "{txt}");
    }
    let back: F = toml::from_str(&txt).unwrap();
    assert_eq!(back.effects, f.effects);
    let bad = "[[effects]]\nkind = \"wind\"\nspeed_mps = 1.0\nfrom_deg = 0.0\nspeed = 3\n";
    let e = toml::from_str::<F>(bad).err().unwrap().to_string();
    assert!(e.contains("speed"), "{e}");
    let cubic = "[[effects]]\nkind = \"nonlinear-damping\"\nn_rr = 0.1\n";
    let f: F = toml::from_str(cubic).unwrap();
    assert_eq!(
        f.effects[0],
        SimEffect::NonlinearDamping {
            n_rr: 0.1,
            cubic: false
        }
    );
}

#[test]
fn every_kind_round_trips_through_the_schema_and_has_its_definition() {
    for k in EffectKind::ALL {
        let d = def(k);
        assert_eq!(d.kind, k);
        assert!(!d.phrase.is_empty());
        let mut e = Effect::zero(k, 2.0);
        assert_eq!(e.kind(), k);
        let g: Vec<f64> = (1..=d.gains.len()).map(|i| i as f64 * 0.25).collect();
        e.set_gains(&g);
        assert_eq!(e.gains(), g, "{k:?}");
        assert_eq!(Effect::from_spec(&e.to_spec()), e, "{k:?}");
        assert_eq!(e.to_spec().kind(), k);
        // actuators have a structural parameter and no gains, the others the opposite
        let actuator = matches!(d.role, Role::Actuator { .. });
        assert_eq!(actuator, k.is_actuator(), "{k:?}");
        assert_eq!(e.structural().is_some(), actuator, "{k:?}");
        assert_eq!(d.gains.is_empty(), actuator, "{k:?}");
        assert_eq!(e.harmonics().is_some(), k.needs_heading(), "{k:?}");
        // the grids of the actuator effects are non-empty and positive
        let span = GridSpan::of(1.0, [&[0.0, 20.0, -20.0, 5.0, 0.0][..]; 1]);
        let cands = (d.candidates)(&span);
        assert!(!cands.is_empty(), "{k:?}");
        assert!(cands.iter().all(|c| c.kind() == k));
        let search = (d.search)(&span);
        assert_eq!(search.is_empty(), !actuator, "{k:?}");
        assert!(search.iter().all(|v| *v > 0.0), "{k:?}");
        if let SimCounterpart::Direct(s) = e.sim_counterpart(1.0) {
            assert_eq!(s.kind(), k);
        }
    }
}

#[test]
fn knobs_read_the_effects() {
    let hidden: Vec<SimEffect> = EffectKind::ALL
        .iter()
        .map(|&k| SimEffect::hidden(k, 1.0))
        .collect();
    let k = SimKnobs::of(&hidden);
    assert_eq!(k.dead_time_s, HIDDEN_DEAD_TIME_S);
    assert_eq!(k.max_rate_degps, HIDDEN_RATE_DEGPS);
    assert_eq!(k.limit_deg, HIDDEN_LIMIT_DEG);
    assert_eq!(k.band_deg, HIDDEN_DEAD_BAND_DEG);
    assert_eq!(k.yaw_moment_nm, HIDDEN_BIAS_NM);
    assert_eq!(k.gyro_bias_degps, HIDDEN_GYRO_BIAS_DEGPS);
    assert_eq!(k.starboard_gain, HIDDEN_ASYMMETRY);
    assert_eq!((k.n_rr, k.cubic), (HIDDEN_N_RR, false));
    // wind from 045° blows towards 225°: both components negative
    assert!(k.wind_ne.0 < 0.0 && k.wind_ne.1 < 0.0);
    assert!((k.wind_ne.0.hypot(k.wind_ne.1) - HIDDEN_WIND_MPS).abs() < 1e-12);
    // current towards 090°: east
    assert!(k.current_ne.0.abs() < 1e-12 && (k.current_ne.1 - HIDDEN_CURRENT_MPS).abs() < 1e-12);
    assert_eq!(SimKnobs::of(&[]), SimKnobs::default());
}

#[test]
fn hull_scaling_follows_each_quantity() {
    let s = HullScale {
        time: 4.0,
        speed: 3.0,
        moment: 100.0,
    };
    for k in EffectKind::ALL {
        let e = SimEffect::hidden(k, 1.0);
        let on = e.on_hull(&s);
        assert_eq!(on.kind(), k);
        on.validate("x").unwrap();
    }
    assert_eq!(
        SimEffect::hidden(EffectKind::DeadTime, 1.0).on_hull(&s),
        SimEffect::DeadTime {
            delay_s: 4.0 * HIDDEN_DEAD_TIME_S
        }
    );
    assert_eq!(
        SimEffect::hidden(EffectKind::Bias, 1.0).on_hull(&s),
        SimEffect::Bias {
            yaw_moment_nm: 100.0 * HIDDEN_BIAS_NM
        }
    );
}
