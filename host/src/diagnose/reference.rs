//! What the reference records show of their own: a steady offset the model given lacks, the
//! steering-gear dynamics the linear reference model has absorbed into its poles, and
//! whether the model given looks identified from the reference records at all.

use yawcast_shared::model::EffectKind;

use super::evidence::Set;
use super::DiagnoseConfig;
use crate::diagnose::augment::{describe, forward, own_search, AugmentConfig};
use crate::effects::{def, Role};
use crate::identify::model::Model;
use crate::identify::pem::{self, PemConfig};
use crate::io::data::Record;
use crate::stats::chi2_sf;

/// What the reference records show of their own and the model given lacks (a steady offset,
/// steering-gear dynamics): the reference model with it, θ re-identified on the reference,
/// and the explanation's sentence.
#[derive(Debug, Clone)]
pub(super) struct RefOwn {
    pub(super) model: Model,
    pub(super) words: String,
}

/// The reference's own steady offset. A model without any effect (a plain linear model, as
/// `pem::identify` gives) is identified again on the reference records by
/// [`pem::offset::identify`], the rule `yawcast identify` applies; when that rule adds a
/// steady yaw moment or a gyro offset, the reference carries one that the model given does
/// not, and the trials' errors against that model hold it too. Measured against the model
/// without it, a constant moment reads as whatever heading-dependent moment the trials'
/// headings make of it (the Seiun Maru's effect-free trials: `wind` at p = 1.7·10⁻⁷, `none`
/// against the model with the offset). So the statistics are measured against the model
/// `identify` would have written. `None` when the model carries any effect (it is not a
/// plain model, and re-identifying it would drop what it carries) or the rule adds none.
pub(super) fn reference_offset(
    model: &Model,
    reference: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<RefOwn> {
    if !model.effects.is_empty() || reference.is_empty() {
        return None;
    }
    let pc = PemConfig {
        order: model.a.len(),
        ..cfg.augment.pem.clone()
    };
    let (rep, choice) = pem::offset::identify(reference, &pc).ok()?;
    let choice = choice?;
    if !rep.model.is_stable() {
        return None;
    }
    let words = format!(
        " The model given is a plain linear model, and `yawcast identify` would have added a \
         steady offset for its reference records: {}. Every statistic is measured against the \
         model identified with it.",
        choice.describe()
    );
    Some(RefOwn {
        model: rep.model,
        words,
    })
}

/// The reference's own steering-gear physics (module docs): forward selection over the
/// actuator effects the model lacks, on the reference records, by
/// [`crate::diagnose::augment`]'s rule (re-identified, kept only when the held-out part of
/// the reference pays for it or the reference supports it decisively). `None` when it keeps
/// none.
pub(super) fn reference_actuator(
    model: &Model,
    reference: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<RefOwn> {
    let kinds: Vec<EffectKind> = EffectKind::ALL
        .iter()
        .copied()
        // the gear *dynamics* ([`Role::Actuator`]): a slow or delayed gear changes when the
        // rudder/pod angle arrives, which a linear model absorbs into its poles (a lag), so
        // with θ frozen the reference shows neither. A static limit or band θ cannot absorb,
        // so the frozen reference version already holds it — and on a hull whose turning
        // rate grows less than linearly with the rudder angle a re-identified angle limit
        // would stand for that hull physics instead.
        .filter(|k| def(*k).role == Role::Actuator { dynamics: true })
        .filter(|k| model.effect(*k).is_none())
        .collect();
    if kinds.is_empty() {
        return None;
    }
    // the reference model was identified on the whole reference, the held-out third
    // included: its fit there is in-sample and no yardstick, so the gear is judged against
    // the structure re-identified on the first two thirds alone
    let acfg = AugmentConfig {
        input_in_sample: true,
        ..cfg.augment.clone()
    };
    let f = forward(model, reference, &[], &kinds, &acfg).ok()?;
    if f.added.is_empty() || !f.model.is_stable() {
        return None;
    }
    let (without, with) = f.fit10_without_and_with()?;
    let own: Vec<String> = f
        .added
        .iter()
        .filter_map(|k| f.model.effect(*k))
        .map(|e| describe(e, model.ts))
        .collect();
    let words = format!(
        " The reference records show steering-gear physics of their own that the linear \
         model has absorbed into its poles: {} (re-identified on the reference, held-out \
         10-step fit there {:.1} % without it, {:.1} % with it). A gear the model only \
         approximates looks like whatever actuator effect mimics it best on each record's \
         commands, so every statistic is measured against the reference model with it.",
        own.join(" and "),
        without,
        with,
    );
    Some(RefOwn {
        model: f.model,
        words,
    })
}

/// The hull physics of the ship's own the reference records show, for a null that holds
/// how the hull meets a linear model on the trials' manoeuvre: `augment --effect auto`'s
/// search ([`crate::diagnose::augment::own_search`]) on the reference records, from `base`
/// (the reference model with its own gear). `None` when it keeps none.
pub(super) fn reference_hull(
    base: &Model,
    reference: &[Record],
    cfg: &DiagnoseConfig,
) -> Option<Model> {
    own_search(base, reference, None, &cfg.augment).map(|f| f.model)
}

/// The settings `model`'s structure is identified again with on other records (the
/// reference as it is, or re-timed): its order, at most 50 iterations, one thread.
pub(super) fn refit_config(model: &Model) -> PemConfig {
    PemConfig {
        order: model.n,
        max_iter: 50,
        parallel: false,
        ..PemConfig::default()
    }
}

/// Is the model fitted to the trials rather than the reference? Then it has absorbed what
/// the trials show — a slow gear or an angle limit above all — and the statistics against the
/// reference lose their power. Said when the model is significantly worse on the reference
/// than the same structure re-identified there (likelihood ratio; ≈ 0 for the reference's
/// own model) *and* predicts the trials better than that re-identified model does. On
/// blocks of a longer reference (`WINDOW`) the model was identified on more than the
/// blocks, whose own optimum beats it by their sampling spread alone: there the excess
/// must also reach 1 % of the one-step error.
///
/// `Some(pct)` when said, `pct` being how much larger (%) the model's one-step error on the
/// reference is than that of the re-identified structure; `(s1, n1)` are the model's
/// one-step SSE and error count on the reference, `trial` the trial records with the
/// model's x̂(0), `min_pct` the excess required (1 on blocks of a longer reference, else 0).
pub(super) fn foreign(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    trial: &Set<'_>,
    (s1, n1): (f64, usize),
    min_pct: f64,
    alpha: f64,
) -> Option<f64> {
    pem::identify_from(reference, model, &refit_config(model))
        .ok()
        .and_then(|r| {
            let v = s1 / n1.max(1) as f64;
            let lr = n1 as f64 * (v / r.cost).ln();
            let p = r.names.len() as f64;
            let (t_given, _) = trial.sse0(model, 1);
            let (t_ref, _) = Set::new(&r.model, est).sse0(&r.model, 1);
            let pct = 100.0 * (v / r.cost - 1.0);
            (lr.is_finite() && chi2_sf(lr, p) < alpha && t_given < t_ref && pct >= min_pct)
                .then_some(pct)
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::tests::{identify, records};
    use crate::identify::model::Effect;

    #[test]
    fn the_reference_gear_is_judged_against_the_structure_re_identified() {
        // the built-in ship's gear slews at 20 °/s; on one of the acceptance suite's
        // references a slew limit predicts the held-out third better than the structure
        // re-identified without it, but not better than the reference model, which was
        // identified on that third too
        let reference = records(None, &[903, 904, 905]);
        let model = identify(&reference);
        let g = reference_actuator(&model, &reference, &DiagnoseConfig::default()).unwrap();
        let Some(Effect::RateLimit { rate }) = g.model.effect(EffectKind::RateLimit) else {
            panic!("{:?}", g.model.effects)
        };
        assert!((16.0..26.0).contains(rate), "{rate} °/s");
        assert!(g.words.contains("% without it,"), "{}", g.words);
        // against the in-sample yardstick it is declined
        let kinds = [EffectKind::DeadTime, EffectKind::RateLimit];
        let cfg = AugmentConfig::default();
        let f = forward(&model, &reference, &[], &kinds, &cfg).unwrap();
        assert!(f.added.is_empty(), "{:?}", f.added);
        let tried = &f.rounds[0].tried;
        let rl = tried
            .iter()
            .find(|t| t.effect == EffectKind::RateLimit)
            .unwrap();
        assert!(rl.fit_gain_pp > 0.0 && !rl.kept, "{rl:?}");
    }
}
