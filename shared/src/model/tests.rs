//! Unit tests of the schema: characteristic polynomials, Schur–Cohn, the difference form, validation.

use super::*;

fn poly_of(a: &[f32], k: &[f32]) -> Poly {
    companion_char_poly(a, k, a.len())
}

fn stable(c: &[f64]) -> bool {
    let mut p = [0.0; MAX_ORDER + 1];
    p[..c.len()].copy_from_slice(c);
    monic_schur_stable(&p, c.len() - 1)
}

#[test]
fn char_poly_of_companion() {
    // z^3 − a3 z^2 − a2 z − a1
    let p = poly_of(&[0.25, -0.5, 0.75], &[0.0; 3]);
    assert_eq!(&p[..4], &[1.0, -0.75, 0.5, -0.25]);
}

#[test]
fn char_poly_with_gain_matches_determinant() {
    // n = 2: A − K C = [[−k1, 1], [a1 − k2, a2]],
    // det(zI − M) = (z + k1)(z − a2) − (a1 − k2) = z² + (k1 − a2) z − k1 a2 − a1 + k2.
    let (a1, a2, k1, k2) = (0.5f32, 0.25f32, 0.75f32, 0.125f32);
    let p = poly_of(&[a1, a2], &[k1, k2]);
    let (a1, a2, k1, k2) = (a1 as f64, a2 as f64, k1 as f64, k2 as f64);
    assert_eq!(&p[..3], &[1.0, k1 - a2, -k1 * a2 - a1 + k2]);
}

#[test]
fn schur_cohn_on_known_roots() {
    // (z − 0.9)(z + 0.8) = z² − 0.1 z − 0.72: stable.
    assert!(stable(&[1.0, -0.1, -0.72]));
    // (z − 1.01)(z − 0.5) = z² − 1.51 z + 0.505: unstable.
    assert!(!stable(&[1.0, -1.51, 0.505]));
    // root exactly on the circle: z² − 1 is not strictly stable.
    assert!(!stable(&[1.0, 0.0, -1.0]));
    // complex pair 0.95 e^{±i 0.3}: z² − 1.9 cos(0.3) z + 0.9025.
    assert!(stable(&[1.0, -1.9 * 0.3f64.cos(), 0.9025]));
    // complex pair of modulus 1.05.
    assert!(!stable(&[1.0, -2.1 * 0.3f64.cos(), 1.1025]));
    // (z − 0.5)^4 = z⁴ − 2 z³ + 1.5 z² − 0.5 z + 0.0625.
    assert!(stable(&[1.0, -2.0, 1.5, -0.5, 0.0625]));
    assert!(!stable(&[1.0, f64::NAN, 0.0]));
}

#[test]
fn shift_by_one_moves_every_root_by_one() {
    // (δ + 0.5)(δ + 0.1) = δ² + 0.6 δ + 0.05 → (z − 0.5)(z − 0.9) = z² − 1.4 z + 0.45
    let mut p = [0.0; MAX_ORDER + 1];
    p[..3].copy_from_slice(&[1.0, 0.6, 0.05]);
    let q = shift_by_one(&p, 2);
    assert_eq!(&q[..3], &[1.0, -1.4, 0.45]);
    // δ⁴ → (z − 1)⁴ = z⁴ − 4 z³ + 6 z² − 4 z + 1
    let mut p = [0.0; MAX_ORDER + 1];
    p[0] = 1.0;
    assert_eq!(&shift_by_one(&p, 4)[..5], &[1.0, -4.0, 6.0, -4.0, 1.0]);
}

#[test]
fn difference_form_keeps_poles_near_one_apart() {
    // poles 1 − 1e-6 and 0.9: δ-coefficients 1e-6 scale, stable; the shift-form
    // coefficients of the same model are 1.9 and −0.9 to seven digits
    let m = ModelSpec::new(
        2,
        1.0,
        &[-9.99999e-8, -0.100001],
        &[1.0, 0.0],
        &[0.0, 0.0],
        Units::default(),
        &[],
    );
    assert!(m.is_ok(), "{m:?}");
    // a pole δ = +1e-7 (z = 1 + 1e-7): unstable
    let m = ModelSpec::new(
        2,
        1.0,
        &[1.0e-8, -0.0999999],
        &[1.0, 0.0],
        &[0.0, 0.0],
        Units::default(),
        &[],
    );
    assert_eq!(m, Err(ModelError::UnstableModel));
}

/// The shift-form model with companion row (−0.1, 0.2, −0.3, 0.6) in difference form
/// (spectral radius 0.57).
fn base() -> ModelSpec {
    ModelSpec::new(
        4,
        0.5,
        &[-0.6, -2.6, -4.5, -3.4],
        &[0.01, 0.01, 0.005, 0.002],
        &[0.1, 0.01, 0.0, 0.0],
        Units::default(),
        &[],
    )
    .unwrap()
}

#[test]
fn validate_rejects_each_kind_of_error() {
    let mut m = base();
    m.order = 9;
    assert_eq!(m.validate(), Err(ModelError::Order(9)));
    let mut m = base();
    m.b.pop();
    assert_eq!(
        m.validate(),
        Err(ModelError::Length {
            field: Field::B,
            len: 3
        })
    );
    let mut m = base();
    m.k[2] = f32::NAN;
    assert_eq!(
        m.validate(),
        Err(ModelError::Coefficient {
            field: Field::K,
            index: 2
        })
    );
    let mut m = base();
    m.a[0] = 2.0e6;
    assert!(matches!(m.validate(), Err(ModelError::Coefficient { .. })));
    for ts in [0.0, -1.0, 3601.0, f32::INFINITY, f32::NAN] {
        let mut m = base();
        m.ts = ts;
        assert_eq!(m.validate(), Err(ModelError::SampleTime), "ts = {ts}");
    }
    for e in [
        Effect::DeadTime { samples: 0 },
        Effect::DeadTime { samples: 33 },
        Effect::Saturation { limit: -1.0 },
        Effect::Bias { beta: f32::NAN },
        Effect::Wind {
            beta_s2: 0.0,
            beta_c2: f32::INFINITY,
            beta_s1: 0.0,
            beta_c1: 0.0,
        },
    ] {
        let mut m = base();
        m.effects.push(e).unwrap();
        assert_eq!(m.validate(), Err(ModelError::EffectParameter(e.kind())));
    }
    let mut m = base();
    m.effects.push(Effect::Bias { beta: 0.1 }).unwrap();
    m.effects.push(Effect::Bias { beta: 0.2 }).unwrap();
    assert_eq!(
        m.validate(),
        Err(ModelError::DuplicateEffect(EffectKind::Bias))
    );
    let mut m = base();
    m.a[0] = 0.1;
    assert_eq!(m.validate(), Err(ModelError::UnstableModel));
    let mut m = base();
    m.k[0] = 2.5;
    assert_eq!(m.validate(), Err(ModelError::UnstablePredictor));
    assert_eq!(base().validate(), Ok(()));
}

#[test]
fn new_rejects_overlong_inputs() {
    let nine = [0.0f32; 9];
    assert_eq!(
        ModelSpec::new(4, 1.0, &nine, &nine, &nine, Units::default(), &[]),
        Err(ModelError::Length {
            field: Field::A,
            len: 9
        })
    );
    let ten = [Effect::Bias { beta: 0.0 }; 10];
    let z = [0.0f32; 4];
    assert_eq!(
        ModelSpec::new(4, 1.0, &z, &z, &z, Units::default(), &ten),
        Err(ModelError::DuplicateEffect(EffectKind::Bias))
    );
}

#[test]
fn display_is_specific() {
    use std::string::ToString;
    assert_eq!(
        ModelError::Order(1).to_string(),
        "model order 1 is outside 2..=8"
    );
    assert_eq!(
        ModelError::DuplicateEffect(EffectKind::Wind).to_string(),
        "effect wind appears more than once"
    );
    assert_eq!(
        ModelError::Coefficient {
            field: Field::A,
            index: 3
        }
        .to_string(),
        "a[3] is not finite or exceeds 1e6 in magnitude"
    );
}
