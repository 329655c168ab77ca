//! What the heading, ground-velocity and anemometer channels add to an effect's evidence: a
//! gyro offset judged on the heading, current and wind on the ground track and the
//! anemometer as well as on the yaw channel, and a change the reference shows more of than
//! the trials set aside as the reference's.

use yawcast_shared::model::EffectKind;

use super::channels::Channels;
use super::verdict::{cfg_m, Evidence};
use super::DiagnoseConfig;
use crate::effects::{def, Channel};

/// What the heading and speed-over-ground channels add to the evidence of `ev.kind`: a gyro
/// bias judged on the heading, current and wind on speed over ground as well as on the yaw
/// channel (either may show them; a current, which carries the ship, must show on the
/// ground track too where one is logged: [`super::verdict::carried`]).
pub(super) fn add_channels(ev: &mut Evidence, has_ref: bool, cfg: &DiagnoseConfig, ch: &Channels) {
    let (hb, sog) = (ch.hb, ch.sog);
    let kind = ev.kind;
    let p_yaw = ev.p_yaw;
    match def(kind).channel {
        Channel::Heading => {
            if let Some(g) = hb {
                let (b, se) = (g.offset, g.se);
                let z = b / se;
                ev.p = g.p();
                ev.statistic = z * z;
                ev.score = z * z - 1.0;
                ev.parameter = Some(b);
                ev.parameter_se = Some(se);
                ev.channel_material = true;
                ev.words = format!(
                    "the gyro reads {b:+.3} ± {se:.3} °/s more than the heading turns \
                     (mean r − mean dψ/dt{}{})",
                    if has_ref {
                        ", trial minus reference"
                    } else {
                        ""
                    },
                    match g.dof.filter(|&d| d < 30.0) {
                        Some(d) => format!(
                            "; the gyro's offset wanders from record to record beyond its \
                             noise, and the error counts that wander: a t on {d:.0} df"
                        ),
                        None => String::new(),
                    }
                );
            }
        }
        Channel::SpeedOverGround => {
            let mut p_speed = None;
            // on records that each hold one course, read across their courses
            // (`course.rs`), the speed lost in each turn varies with the heading as a wind's
            // drag does: the ground track is not counted towards a wind there
            let across = ch.course.is_some() && !ch.yaw_tells_heading();
            let sog_counts = !(kind == EffectKind::Wind && across);
            // and a current, which carries the ship, is read from the ground track alone
            // there, as on one course without them: the moment read across the courses
            // tells it from a wind (`verdict::current_or_wind`)
            let yaw_counts = ev.yaw_counted && !(kind == EffectKind::Current && across);
            if let (Some(s), false) = (sog, sog_counts) {
                let (chi, df, _) = s.test(false);
                ev.words.push_str(&format!(
                    "; speed over ground varies with heading by ±{:.3} m/s (1st harmonic) and \
                     ±{:.3} m/s (2nd) (χ² = {chi:.1}, {df:.0} df): not counted towards a wind on \
                     records that each hold one course, where the speed lost in each turn \
                     varies with the heading as a wind's drag does",
                    s.amp1, s.amp2
                ));
            }
            if let (Some(s), true) = (sog, sog_counts) {
                let current = kind == EffectKind::Current;
                // on records that each hold one course a current is read across their
                // courses (`carry.rs`): the harmonics see it within each from 2–30 m/s on
                let carry = ch.across_carry().filter(|_| current);
                let (chi, df, p_sog) = match carry {
                    Some(c) => (c.chi, 2.0, c.p),
                    None => s.test(current),
                };
                // a change the reference shows more of than the trials is not the trials'
                let theirs = carry.is_none() && s.the_references();
                let p_sog = if theirs { 1.0 } else { p_sog };
                p_speed = Some(p_sog);
                let calibration = s.calibration_words(current);
                // either channel may show it (Bonferroni over the two); only speed over
                // ground where the yaw channel is not counted
                ev.channels = if yaw_counts { 2 } else { 1 };
                ev.p = if yaw_counts {
                    (2.0 * p_yaw.min(p_sog)).min(1.0)
                } else {
                    p_sog
                };
                if current {
                    ev.p_ground = Some(p_sog);
                }
                if ev.yaw_counted && !yaw_counts {
                    ev.words.push_str(
                        "; a current carries the ship, so on records that each hold one \
                         course its p is the ground track's alone, and the moment read across \
                         the courses only tells it from a wind",
                    );
                }
                if !theirs {
                    ev.score = ev.score.max(chi - df);
                }
                ev.channel_material = p_sog < cfg.alpha / cfg_m(cfg);
                if let Some(c) = carry {
                    let (speed, dir) = c.speed_dir();
                    ev.parameter = Some(speed);
                    ev.parameter_se = Some(c.speed_se());
                    ev.words.push_str(&format!(
                        "; read across the courses (each record's mean speed over ground \
                         {}, projected on its own headings; courses {:.0}° apart), the ground \
                         velocity shows a current of {speed:.3} m/s setting towards {dir:.0}° \
                         beside {:.3} m/s through the water (χ² = {chi:.1}, 2 df{}, p {})",
                        if c.lanes == 2 {
                            "along and across the heading"
                        } else {
                            "along the heading"
                        },
                        c.span_deg,
                        c.through,
                        if c.inflation > 1.0 {
                            format!(
                                ", divided by {:.1}, what {} (an F test on {:.0} df)",
                                c.inflation,
                                if c.own_misfit {
                                    "the trials' means leave beyond one current"
                                } else {
                                    "the reference records show against each other"
                                },
                                c.inflation_df
                            )
                        } else {
                            String::new()
                        },
                        super::verdict::fmt_p(c.p)
                    ));
                } else if let (EffectKind::Current, Some(c)) = (kind, s.cross) {
                    let (speed, dir) = c.speed_dir();
                    ev.parameter = Some(speed);
                    ev.words.push_str(&format!(
                        "; the ground velocity shows a current of {speed:.3} m/s setting towards \
                         {dir:.0}° (speed over ground along the heading, course over ground \
                         across it; χ² = {chi:.1}, 2 df, across alone {:.1}{}{})",
                        c.cross_chi,
                        if c.cross_inflation > 1.0 || s.inflation[0] > 1.0 {
                            format!(
                                "; each lane's χ² divided by what the records show against each \
                                 other without a current: {:.1} along, {:.1} across",
                                s.inflation[0], c.cross_inflation
                            )
                        } else {
                            String::new()
                        },
                        if c.agree > 13.8 {
                            format!(
                                "; the two lanes disagree (χ² = {:.1}, 2 df): not all of it \
                                 is a uniform current",
                                c.agree
                            )
                        } else {
                            String::new()
                        }
                    ));
                } else if kind == EffectKind::Current {
                    ev.parameter = Some(s.amp1);
                    ev.words.push_str(&format!(
                        "; speed over ground varies by ±{:.3} m/s with heading, fastest heading \
                         {:.0}° (χ² = {chi:.1}, 2 df{calibration})",
                        s.amp1, s.dir1
                    ));
                } else {
                    ev.words.push_str(&format!(
                        "; speed over ground varies with heading by ±{:.3} m/s (1st harmonic) and \
                         ±{:.3} m/s (2nd) (χ² = {chi:.1}, 4 df{calibration})",
                        s.amp1, s.amp2
                    ));
                }
                if theirs {
                    ev.words.push_str(&format!(
                        "; not counted: the change is the reference's, whose own heading \
                         harmonics of the ground velocity (±{:.3} m/s) are larger than the \
                         trials' (±{:.3} m/s): a current or wind it sailed in and the trials \
                         did not",
                        s.own[1], s.own[0]
                    ));
                }
            }
            if let (EffectKind::Wind, Some(a)) = (kind, ch.anemometer) {
                // the direct channel: three tests now, Bonferroni over them
                let (speed, from) = a.speed_from();
                let p_sog = p_speed.unwrap_or(p_yaw);
                let counted = if sog_counts { 3 } else { 2 };
                // a wind the reference's anemometer shows more of is not the trials'
                let theirs = a.the_references();
                let p_air = a.p_trials();
                ev.channels = if ev.yaw_counted { counted } else { 2 };
                ev.p = if ev.yaw_counted {
                    (counted as f64 * p_yaw.min(p_air).min(p_sog)).min(1.0)
                } else {
                    (2.0 * p_air.min(p_sog)).min(1.0)
                };
                if !theirs {
                    ev.score = ev.score.max(a.chi - 2.0);
                }
                ev.channel_material |= p_air < cfg.alpha / cfg_m(cfg);
                ev.parameter = Some(speed);
                ev.parameter_se = Some(a.speed_se());
                ev.words.push_str(&format!(
                    "; the anemometer shows a true wind of {speed:.2} m/s from {from:.0}° \
                     (ground velocity less the apparent wind{}; beyond the instrument's \
                     {:.2} m/s: χ² = {:.1}, 2 df, p {})",
                    if has_ref {
                        ", trial minus reference"
                    } else {
                        ""
                    },
                    a.floor,
                    a.chi,
                    super::verdict::fmt_p(a.p)
                ));
                if theirs {
                    ev.words.push_str(&format!(
                        "; not counted: the change is the reference's, whose own true wind \
                         ({:.2} m/s) is stronger than the trials' ({:.2} m/s)",
                        a.own[1], a.own[0]
                    ));
                }
            }
        }
        // the channels carry nothing of the actuator and hull effects, nor of a moment
        Channel::None => {}
    }
}
