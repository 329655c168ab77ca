//! The re-identifications every step makes: the PEM settings of a structure, and fresh,
//! final (as [`pem::identify`] chooses) and warm-started identifications.

use super::AugmentConfig;
use crate::identify::model::Model;
use crate::identify::pem::{self, IdentError, PemConfig, PemReport};
use crate::io::data::Record;
/// PEM settings for a structure with `p` estimated parameters.
fn pem_cfg(cfg: &AugmentConfig, n: usize, p: usize) -> PemConfig {
    let fit_len = |v: &Option<Vec<f64>>| {
        v.as_ref().map(|v| {
            let mut v = v.clone();
            v.resize(p, 0.0);
            v
        })
    };
    PemConfig {
        order: n,
        r: fit_len(&cfg.pem.r),
        nominal: fit_len(&cfg.pem.nominal),
        parallel: cfg.parallel && cfg.pem.parallel,
        // the grid, the golden-section search and ΔAIC/ΔBIC compare one-step costs: each
        // identification must end at its lowest minimum, not at the better multi-step one
        select_horizons: Vec::new(),
        ..cfg.pem.clone()
    }
}

fn n_params(m: &Model) -> usize {
    3 * m.n + m.effect_gains().len()
}

/// Identifies `template`'s structure on `est`: ARX, ARMAX, subspace and the template itself as
/// starts (the template only when it is stable), lowest cost wins.
pub(super) fn reidentify(
    est: &[Record],
    template: &Model,
    cfg: &AugmentConfig,
) -> Result<PemReport, IdentError> {
    let pc = pem_cfg(cfg, template.n, n_params(template));
    let fresh = pem::identify(est, Some(template), &pc);
    if template.is_stable() {
        if let Ok(warm) = pem::identify_from(est, template, &pc) {
            if fresh.as_ref().map_or(true, |f| warm.cost < f.cost) {
                return Ok(warm);
            }
        }
    }
    fresh
}

/// The final identification of a compared structure (the baseline, the candidate), as
/// [`pem::identify`] does it: ARX, ARMAX, subspace, `template` and `extra` as starts, and
/// among their minima the lowest cost unless another predicts one step as well and several
/// steps significantly better ([`pem::choose`]). Falls back to [`reidentify`].
pub(super) fn reidentify_final(
    est: &[Record],
    template: &Model,
    extra: &[Model],
    cfg: &AugmentConfig,
) -> Result<PemReport, IdentError> {
    let pc = PemConfig {
        select_horizons: cfg.pem.select_horizons.clone(),
        ..pem_cfg(cfg, template.n, n_params(template))
    };
    let extra: Vec<Model> = extra.iter().filter(|m| m.is_stable()).cloned().collect();
    pem::identify_with(est, Some(template), &extra, &pc).or_else(|_| reidentify(est, template, cfg))
}

/// A warm-started re-identification from `start` (falls back to a fresh one).
pub(super) fn reidentify_warm(
    est: &[Record],
    start: &Model,
    cfg: &AugmentConfig,
) -> Result<PemReport, IdentError> {
    let pc = pem_cfg(cfg, start.n, n_params(start));
    if start.is_stable() {
        if let Ok(r) = pem::identify_from(est, start, &pc) {
            return Ok(r);
        }
    }
    pem::identify(est, Some(start), &pc)
}
