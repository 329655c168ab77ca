//! Augment's estimate of an effect's parameter beside diagnose's, and whether the two agree
//! within what each states of its uncertainty ([`check_estimate`]).

use serde::Serialize;
use yawcast_shared::model::EffectKind;

use crate::effects::{def, Role};
use crate::identify::model::Effect;

/// Augment's estimate of the effect's parameter beside diagnose's (`yawcast augment --effect
/// auto`, JSON `estimate_check`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimateCheck {
    /// The effect's library name.
    pub effect: String,
    /// The parameter's unit ("s", "°/s", "°", "° of command", "fraction",
    /// "° of command per (°/s)²" or "… per (°/s)³").
    pub unit: String,
    /// Diagnose's estimate (the effect measured against the model held fixed, or read off its
    /// own channel).
    pub diagnose: f64,
    /// Diagnose's uncertainty ([`crate::diagnose::Ranked::parameter_uncertainty`]), or null.
    pub diagnose_uncertainty: Option<f64>,
    /// Augment's estimate (the effect re-identified with the model).
    pub augment: f64,
    /// Augment's standard error of a gain (from its STD%), or null for a grid value.
    pub augment_se: Option<f64>,
    /// The largest difference called agreement: for a grid value diagnose's grid gap, for a
    /// gain twice the standard error of the difference; null when neither states one.
    pub tolerance: Option<f64>,
    /// Whether `|augment − diagnose| ≤ tolerance`; null when there is no tolerance, or when
    /// a gain's tolerance is as large as diagnose's value (it could not tell it from zero).
    pub agree: Option<bool>,
    /// Why the two may differ, when they do (or cannot be judged); null when they agree.
    pub why: Option<String>,
}

impl EstimateCheck {
    /// The check in one line of words.
    ///
    /// ```
    /// use yawcast::diagnose::augment::EstimateCheck;
    /// let c = EstimateCheck {
    ///     effect: "dead-time".into(), unit: "s".into(), diagnose: 2.0,
    ///     diagnose_uncertainty: Some(1.0), augment: 3.0, augment_se: None,
    ///     tolerance: Some(1.0), agree: Some(true), why: None,
    /// };
    /// assert_eq!(c.line(), "dead-time: augment 3 s, diagnose 2 ± 1 s: they agree (within 1 s)");
    /// ```
    pub fn line(&self) -> String {
        let u = &self.unit;
        let pm = self
            .diagnose_uncertainty
            .map_or(String::new(), |d| format!(" ± {}", sig(d)));
        let se = self
            .augment_se
            .map_or(String::new(), |d| format!(" ± {}", sig(d)));
        let head = format!(
            "{}: augment {}{se} {u}, diagnose {}{pm} {u}",
            self.effect,
            sig(self.augment),
            sig(self.diagnose)
        );
        match (self.agree, self.tolerance) {
            (Some(true), Some(t)) => format!("{head}: they agree (within {} {u})", sig(t)),
            (Some(false), Some(t)) => format!(
                "{head}: they differ by more than {} {u}: {}",
                sig(t),
                self.why.as_deref().unwrap_or("")
            ),
            _ => format!("{head}: {}", self.why.as_deref().unwrap_or("")),
        }
    }
}

/// A number with three significant digits, without trailing zeros.
pub(crate) fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The unit of an effect's parameter as [`crate::identify::model::Effect::evidence`] gives it.
fn unit(kind: EffectKind, cubic: bool) -> &'static str {
    match kind {
        EffectKind::DeadTime => "s",
        EffectKind::RateLimit | EffectKind::GyroBias => "°/s",
        EffectKind::Saturation | EffectKind::DeadBand => "°",
        EffectKind::Bias => "° of command",
        EffectKind::Asymmetry => "fraction",
        EffectKind::NonlinearDamping if cubic => "° of command per (°/s)³",
        EffectKind::NonlinearDamping => "° of command per (°/s)²",
        EffectKind::Wind | EffectKind::Current => "",
    }
}

/// Why augment's estimate of `kind` may differ from diagnose's.
fn why_differ(kind: EffectKind) -> &'static str {
    match (kind, def(kind).role) {
        (EffectKind::GyroBias, _) => {
            "augment holds the offset at the heading's measurement only where every record \
             logs heading and the model has no nonlinear damping; otherwise it estimates it from \
             the yaw rate alone, where a steady yaw moment or an asymmetry of the gear looks much \
             the same, while diagnose reads it off the heading (the gyro against the compass's \
             turn), which only a sensor offset moves — diagnose's is the direct measurement"
        }
        (_, Role::Actuator { dynamics: true }) => {
            "augment re-identifies the hull's dynamics together with the effect, diagnose holds \
             them at the reference model's: a re-identified model takes part of a delay or of a \
             slow gear into its own poles"
        }
        _ => {
            "augment re-identifies the model with the effect, diagnose measures the effect \
             with the model's dynamics held at the reference's"
        }
    }
}

/// Augment's estimate of an effect's parameter beside diagnose's: `augmented` is the effect
/// augment identified (with `std_pct`, the STD% of its last estimated parameter — the
/// effect's gain — when it has one), `diagnosed` diagnose's parameter and its uncertainty
/// ([`crate::diagnose::Ranked::parameter`], [`crate::diagnose::Ranked::parameter_uncertainty`]).
/// `None` when the effect has no parameter in physical units to compare (wind, current:
/// diagnose's is a speed, augment's a yaw moment).
///
/// The tolerance is diagnose's grid gap for a grid-searched value (dead time, gear rate,
/// angle limit, dead band) and twice the standard error of the difference for a gain
/// (diagnose's channel error, augment's from its STD%).
///
/// ```
/// use yawcast::diagnose::augment::check_estimate;
/// use yawcast::identify::model::Effect;
/// // a dead time of 3 samples at 0.5 s against diagnose's 2.0 s on a 0.5-s grid
/// let c = check_estimate(&Effect::DeadTime { samples: 3 }, None, (2.0, Some(0.5)), 0.5).unwrap();
/// assert_eq!((c.augment, c.tolerance, c.agree), (1.5, Some(0.5), Some(true)));
/// // a gyro offset of 0.10 ± 0.01 °/s against diagnose's 0.25 ± 0.02 °/s
/// let c = check_estimate(&Effect::GyroBias { d_y: 0.1 }, Some(10.0), (0.25, Some(0.02)), 0.5)
///     .unwrap();
/// assert_eq!(c.agree, Some(false));
/// assert!(c.why.unwrap().contains("heading"));
/// // an offset augment cannot resolve (0.0 ± 5 °/s): not judged
/// let c = check_estimate(&Effect::GyroBias { d_y: 1e-3 }, Some(5e5), (0.05, Some(0.005)), 1.0)
///     .unwrap();
/// assert_eq!(c.agree, None);
/// assert!(c.why.unwrap().starts_with("the uncertainty"));
/// ```
pub fn check_estimate(
    augmented: &Effect,
    std_pct: Option<f64>,
    diagnosed: (f64, Option<f64>),
    ts: f64,
) -> Option<EstimateCheck> {
    let kind = augmented.kind();
    // wind and current have no parameter here (`Effect::evidence` gives none)
    let augment = augmented.evidence(ts, 0.0, 1, "").0?;
    let unit = unit(kind, augmented.cubic());
    let (diagnose, diag_u) = diagnosed;
    let structural = augmented.structural().is_some();
    let augment_se = (!structural && def(kind).gains.len() == 1)
        .then(|| std_pct.map(|p| p / 100.0 * augment.abs()))
        .flatten()
        .filter(|v| v.is_finite());
    let diag_u = diag_u.filter(|v| v.is_finite());
    let tolerance = if structural {
        diag_u
    } else if diag_u.is_some() || augment_se.is_some() {
        Some(2.0 * diag_u.unwrap_or(0.0).hypot(augment_se.unwrap_or(0.0)))
    } else {
        None
    };
    // a tolerance as large as the value itself cannot tell it from zero: not judged
    let resolved = tolerance.filter(|t| structural || *t < diagnose.abs());
    let agree = resolved.map(|t| (augment - diagnose).abs() <= t * (1.0 + 1e-9));
    let why = match (agree, tolerance) {
        (Some(true), _) => None,
        (Some(false), _) => Some(why_differ(kind).to_string()),
        (None, Some(t)) => Some(format!(
            "the uncertainty (± {} {unit}) is as large as the value: not judged; {}",
            sig(t / 2.0),
            why_differ(kind)
        )),
        (None, None) if structural => Some(
            "diagnose's value is the largest of the grid it searched, so the true value may \
             lie beyond it: not judged"
                .to_string(),
        ),
        (None, None) => Some("neither states an uncertainty: not judged".to_string()),
    };
    Some(EstimateCheck {
        effect: kind.name().to_string(),
        unit: unit.to_string(),
        diagnose,
        diagnose_uncertainty: diag_u,
        augment,
        augment_se,
        tolerance,
        agree,
        why,
    })
}
