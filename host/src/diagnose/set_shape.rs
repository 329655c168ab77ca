//! The shape of what sets a ship over ground with heading: a uniform current sets it alike
//! along and across its heading, a wind's drag and leeway mostly along it. Without an
//! anemometer, and with no yaw moment that turns the ship, it tells the two apart
//! ([`super::verdict::current_or_wind`]).

use nalgebra::{Matrix2, Vector2};

/// The shape of what sets the ship over ground with heading: the across-heading lane's
/// current projected on the along-heading lane's direction, as a ratio of the latter's
/// length, with its standard error (delta method over the two lanes' calibrated
/// covariances). A uniform current is one vector on the earth: it sets the ship alike along
/// and across its heading, `ratio` ≈ 1. A wind pushes the hull, and the hull answers its
/// drag with its surge resistance and its side force with its sway resistance, several
/// times larger: its set lies mostly along the heading, `ratio` well under 1 (the test
/// worlds' winds 0.2–0.7, their currents 0.8–1.35: docs/method.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SetShape {
    /// Across-heading set over along-heading set.
    pub(super) ratio: f64,
    /// Its standard error.
    pub(super) se: f64,
}

/// A uniform current's set across the heading is its set along it; a set whose across part
/// is under this share of its along part is not a current's. Between a current's 1 (0.8 on
/// an MMG hull whose inertia sees the ground velocity, turning in the current) and a wind's
/// 0.2–0.7, where a hull's sway resistance, several times its surge resistance, puts it.
pub(super) const UNIFORM_SET_MIN: f64 = 0.75;

impl SetShape {
    /// The one-sided p of "this is a uniform current's set" (`ratio` ≥ [`UNIFORM_SET_MIN`]),
    /// normal on `ratio`'s standard error; 1 where it has none.
    pub(super) fn p_uniform(&self) -> f64 {
        if self.se.is_nan() || self.se <= 0.0 || !self.ratio.is_finite() {
            return 1.0;
        }
        crate::stats::normal_sf((UNIFORM_SET_MIN - self.ratio) / self.se)
    }

    /// The words of a wind told from a current by this shape, the yaw channel's `witness`
    /// absent at `p_moment`.
    pub(super) fn words(&self, witness: &str, p_moment: &str) -> String {
        format!(
            "; {witness}: p {p_moment} (absent), but the ground track's set is not a uniform \
             current's: across the heading it is {:.2} ± {:.2} of its set along it (p {} \
             against {UNIFORM_SET_MIN:.2} or more): a uniform current sets the ship alike along \
             and across its heading, a wind's drag and leeway, answered by the hull's surge and \
             several times stiffer sway resistance, mostly along it: wind, too weak to turn \
             the ship",
            self.ratio,
            self.se,
            super::verdict::fmt_p(self.p_uniform())
        )
    }

    /// The shape the trials' ground track shows against the reference's, where it is read:
    /// where the trials' headings part the harmonics from each record's own offset. On
    /// records that each hold one course (zig-zags) the lanes' harmonics are their offsets
    /// (a hidden current read −0.17 ± 0.32 across its set along it on the container ship's
    /// ±20° zig-zags, seed 3).
    pub(super) fn of_channels(ch: &super::channels::Channels) -> Option<SetShape> {
        ch.sog
            .and_then(|s| s.cross)
            .and_then(|c| c.shape)
            .filter(|_| ch.yaw_tells_heading())
    }

    /// What this shape says where it does not decide (a current named, its caveat
    /// `current-or-leeway`): which of the two it leans to, and how far from deciding.
    pub(super) fn lean_words(&self) -> String {
        let how = if self.ratio < UNIFORM_SET_MIN {
            format!(
                "under a uniform current's {UNIFORM_SET_MIN:.2} or more, as a wind's drag and \
                 leeway (mostly along the heading) would make it, but not far enough to tell \
                 (p {} against a uniform current's set, short of the α that names a wind from it)",
                super::verdict::fmt_p(self.p_uniform())
            )
        } else {
            format!("as a uniform current's (about 1; {UNIFORM_SET_MIN:.2} or more)")
        };
        format!(
            " The ground track's set across the heading is {:.2} ± {:.2} of its set along it: \
             {how}.",
            self.ratio, self.se
        )
    }

    /// The shape of the lanes' currents `along` and `across` (north, east; m/s) with their
    /// covariances; `None` where the along lane shows no set.
    pub(super) fn of(
        along: Vector2<f64>,
        va: &Matrix2<f64>,
        across: Vector2<f64>,
        vx: &Matrix2<f64>,
    ) -> Option<SetShape> {
        let aa = along.dot(&along);
        if aa.is_nan() || aa <= 0.0 {
            return None;
        }
        let ratio = across.dot(&along) / aa;
        // ∂ratio/∂across = along/|along|², ∂ratio/∂along = across/|along|² − 2·ratio·along/|along|²
        let gx = along / aa;
        let ga = across / aa - along * (2.0 * ratio / aa);
        let var = gx.dot(&(vx * gx)) + ga.dot(&(va * ga));
        Some(SetShape {
            ratio,
            se: var.max(0.0).sqrt(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::caveat::current_without_anemometer;
    use crate::diagnose::tests::evidence;
    use crate::diagnose::verdict::{current_or_wind, Evidence};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use yawcast_shared::model::EffectKind;

    #[test]
    fn a_sets_shape_is_its_across_lane_on_its_along_lane_with_the_delta_methods_error() {
        // a wind's set: 0.30 m/s along the heading towards 060°, 0.12 m/s across
        let dir = Vector2::new(60f64.to_radians().cos(), 60f64.to_radians().sin());
        let (along, across) = (dir * 0.30, dir * 0.12);
        let va = Matrix2::new(4e-4, 1e-4, 1e-4, 3e-4);
        let vx = Matrix2::new(9e-4, -2e-4, -2e-4, 6e-4);
        let sh = SetShape::of(along, &va, across, &vx).unwrap();
        assert!((sh.ratio - 0.4).abs() < 1e-12, "{sh:?}");
        // the delta method's error against the spread of 20 000 draws of both lanes
        let (la, lx) = (va.cholesky().unwrap().l(), vx.cholesky().unwrap().l());
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut z = || {
            use crate::stats::standard_normal;
            Vector2::new(standard_normal(&mut rng), standard_normal(&mut rng))
        };
        let draws: Vec<f64> = (0..20_000)
            .map(|_| {
                let (a, x) = (along + la * z(), across + lx * z());
                x.dot(&a) / a.dot(&a)
            })
            .collect();
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        let sd = (draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (draws.len() - 1) as f64)
            .sqrt();
        assert!((sh.se / sd - 1.0).abs() < 0.05, "{} {sd}", sh.se);
        // under a uniform current's 0.75 or more: p at z = (0.75 − 0.4)/se
        let want = crate::stats::normal_sf((UNIFORM_SET_MIN - sh.ratio) / sh.se);
        assert_eq!(sh.p_uniform(), want);
        assert!(want < 1e-3, "{want}");
        // a uniform current's set, alike along and across: p near 1; no set along: none;
        // no error: nothing shown
        let cur = SetShape::of(along, &va, along, &vx).unwrap();
        assert!(
            (cur.ratio - 1.0).abs() < 1e-12 && cur.p_uniform() > 0.99,
            "{cur:?}"
        );
        assert!(SetShape::of(Vector2::zeros(), &va, across, &vx).is_none());
        let exact = SetShape::of(along, &Matrix2::zeros(), across, &Matrix2::zeros()).unwrap();
        assert_eq!((exact.se, exact.p_uniform()), (0.0, 1.0));
    }

    #[test]
    fn a_set_mostly_along_the_heading_names_wind_and_a_uniform_one_a_current() {
        let (level, alpha) = (0.01 / 10.0, 0.01);
        let kinds = |ev: &[Evidence]| ev.iter().map(|e| e.kind).collect::<Vec<_>>();
        // the ground track shows a set (its p at 1e-9), the yaw channel no moment (p 0.3 / 0.6)
        let fresh = || {
            vec![
                Evidence {
                    p_ground: Some(1e-9),
                    ..evidence(EffectKind::Current, 1e-9, 0.3, true)
                },
                evidence(EffectKind::Wind, 1e-8, 0.6, true),
            ]
        };
        // the built-in ship's half-strength wind, seed 3: across the heading 0.51 ± 0.07 of
        // its set along it. Against a uniform current's 0.75 or more, z = 3.2: wind, named
        // from the ground track alone (its p the heading dependence's, no better than the
        // shape's), and no current-or-leeway caveat
        let wind_like = SetShape {
            ratio: 0.513,
            se: 0.074,
        };
        let p_shape = crate::stats::normal_sf((UNIFORM_SET_MIN - 0.513) / 0.074);
        assert!(p_shape < 1e-3 && p_shape > 1e-4, "{p_shape}");
        assert_eq!(wind_like.p_uniform(), p_shape);
        let mut ev = fresh();
        current_or_wind(&mut ev, level, alpha, true, None, Some(wind_like));
        assert_eq!(kinds(&ev), [EffectKind::Wind, EffectKind::Current]);
        assert_eq!(ev[0].p, 1e-8_f64.min(1e-9_f64.max(p_shape)));
        assert!(ev[0].speed_only && ev[0].channel_material);
        assert!(
            ev[0].words.contains("0.51 ± 0.07 of its set along it"),
            "{}",
            ev[0].words
        );
        assert!(current_without_anemometer(&ev, None, None).is_none());
        // a uniform current's set (the container ship's: 1.03 ± 0.06), one whose shape the
        // records cannot tell (0.5 ± 0.3: z = 0.8), or the built-in ship's current, whose
        // inertia sees the ground velocity (0.81 ± 0.02): a current, as before, with its caveat
        for shape in [
            SetShape {
                ratio: 1.03,
                se: 0.06,
            },
            SetShape {
                ratio: 0.5,
                se: 0.3,
            },
            SetShape {
                ratio: 0.81,
                se: 0.02,
            },
        ] {
            let mut ev = fresh();
            current_or_wind(&mut ev, level, alpha, true, None, Some(shape));
            assert_eq!(
                kinds(&ev),
                [EffectKind::Current, EffectKind::Wind],
                "{shape:?}"
            );
            assert_eq!(ev[0].p, 1e-9);
            assert!(
                current_without_anemometer(&ev, None, None).is_some(),
                "{shape:?}"
            );
        }
        // the shape is not read where an anemometer decides, where the yaw channel's moment
        // already says wind, or where the ground track itself shows no set at the level (the
        // current then significant from its yaw channel only)
        let mut ev = fresh();
        current_or_wind(&mut ev, level, alpha, true, Some(0.5), Some(wind_like));
        assert_eq!(kinds(&ev), [EffectKind::Current, EffectKind::Wind]);
        let mut ev = fresh();
        ev[0].p_ground = Some(0.2);
        current_or_wind(&mut ev, level, alpha, true, None, Some(wind_like));
        assert_eq!(kinds(&ev), [EffectKind::Current, EffectKind::Wind]);
        let mut ev = fresh();
        ev[1].p_yaw = 1e-5;
        current_or_wind(&mut ev, level, alpha, true, None, Some(wind_like));
        assert_eq!(kinds(&ev), [EffectKind::Wind, EffectKind::Current]);
        assert!(ev[0].words.contains("present"), "{}", ev[0].words);
        assert!(!ev[0].speed_only);
    }

    #[test]
    fn a_shape_that_does_not_decide_is_given_in_the_current_or_leeway_caveat() {
        use crate::diagnose::caveat::Caveat;
        let (level, alpha) = (0.01 / 10.0, 0.01);
        // the container ship's half-strength wind, seed 2: a set 0.34 ± 0.23 across the
        // heading of its set along it, z = 1.8 under a uniform current's 0.75, short of α:
        // a current is named, and its caveat says which way the shape leans and how far
        let lean = SetShape {
            ratio: 0.34,
            se: 0.23,
        };
        let p = crate::stats::normal_sf((UNIFORM_SET_MIN - 0.34) / 0.23);
        assert!(p > alpha && p < 0.05, "{p}");
        let mut ev = vec![
            Evidence {
                p_ground: Some(1e-9),
                ..evidence(EffectKind::Current, 1e-9, 0.3, true)
            },
            evidence(EffectKind::Wind, 1e-8, 0.6, true),
        ];
        current_or_wind(&mut ev, level, alpha, true, None, Some(lean));
        assert_eq!(ev[0].kind, EffectKind::Current);
        let c = current_without_anemometer(&ev, None, Some(lean)).unwrap();
        assert_eq!(
            c,
            Caveat::CurrentOrLeeway {
                p_moment: 0.6,
                set_ratio: Some([0.34, 0.23])
            }
        );
        let json = serde_json::to_value(&c).unwrap();
        assert_eq!(json["set_ratio"], serde_json::json!([0.34, 0.23]));
        let words = c.explain();
        for part in [
            "0.34 ± 0.23 of its set along it",
            "under a uniform current's 0.75 or more",
            &format!("(p {} against", crate::diagnose::verdict::fmt_p(p)),
            "The records cannot tell a current from the leeway",
        ] {
            assert!(words.contains(part), "{part}: {words}");
        }
        // a uniform current's shape (1.03 ± 0.06) says so; without course over ground the
        // caveat has no shape, and its JSON no field for one
        let uniform = SetShape {
            ratio: 1.03,
            se: 0.06,
        };
        let c = current_without_anemometer(&ev, None, Some(uniform)).unwrap();
        assert!(
            c.explain()
                .contains("1.03 ± 0.06 of its set along it: as a uniform current's"),
            "{}",
            c.explain()
        );
        let c = current_without_anemometer(&ev, None, None).unwrap();
        assert!(
            !c.explain().contains("of its set along it"),
            "{}",
            c.explain()
        );
        let json = serde_json::to_value(&c).unwrap();
        assert!(json.get("set_ratio").is_none(), "{json}");
    }
}
