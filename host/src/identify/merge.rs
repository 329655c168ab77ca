//! Several trials → one model: the paper's plain parameter average, the covariance-weighted
//! merge with a χ² consistency test (MATLAB `merge`), and multi-experiment PEM, compared on
//! validation records.

use std::collections::BTreeMap;

use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::identify::model::Model;
use crate::identify::pem::{self, IdentError, PemConfig, PemReport};
use crate::identify::predict::{self, Horizon};
use crate::io::data::Record;
use crate::stats::chi2_sf;

/// Errors combining models.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum MergeError {
    /// Nothing to combine.
    #[error("no models to combine")]
    Empty,
    /// Models of different structure.
    #[error("model {index} has a different structure ({what}) from model 0; only models of the same order, sample time and effects can be combined")]
    Structure {
        /// 0-based index of the offending model.
        index: usize,
        /// What differs.
        what: String,
    },
    /// A covariance is missing or not usable.
    #[error("model {index}: covariance is not usable ({what})")]
    Covariance {
        /// 0-based index.
        index: usize,
        /// What is wrong.
        what: String,
    },
    /// An identification failed.
    #[error("identification failed on `{record}`: {source}")]
    Identification {
        /// The record (or `all records`).
        record: String,
        /// The cause.
        source: IdentError,
    },
    /// No validation records.
    #[error("no validation records")]
    NoValidation,
    /// A record's command (or yaw rate) is signed the other way round from the others'.
    #[error(
        "{set} record `{record}` is signed the other way round from the others: {flipped} of \
         the {of} models identified on the other records simulate it 50 pp or more better \
         with its command negated; negate its command column (--command-scale -1 negates every \
         record read; or its yaw-rate column, if that is the one), so that every record uses one sign convention"
    )]
    CommandSign {
        /// "estimation" or "validation".
        set: &'static str,
        /// The record.
        record: String,
        /// Models that find it flipped.
        flipped: usize,
        /// Models asked.
        of: usize,
    },
    /// A record's command is in another unit than the others'.
    #[error(
        "{set} record `{record}` has its command in another unit than the others: {found} of \
         the {of} models identified on the other records simulate it far better with its \
         command multiplied by about {scale:.4} (radians against degrees give 57.3, degrees \
         against radians 0.0175); give --angle-unit rad for a command in radians, or rescale \
         its command column, so that every record uses one unit"
    )]
    CommandUnit {
        /// "estimation" or "validation".
        set: &'static str,
        /// The record.
        record: String,
        /// The median factor of the models that find it in another unit.
        scale: f64,
        /// Models that find it in another unit.
        found: usize,
        /// Models asked.
        of: usize,
    },
}

fn same_structure(models: &[&Model]) -> Result<(), MergeError> {
    let m0 = models.first().ok_or(MergeError::Empty)?;
    for (i, m) in models.iter().enumerate().skip(1) {
        let what = if m.n != m0.n {
            Some(format!("order {} vs {}", m.n, m0.n))
        } else if (m.ts - m0.ts).abs() > 1e-9 * m0.ts {
            Some(format!("sample time {} vs {}", m.ts, m0.ts))
        } else if m.effects.len() != m0.effects.len()
            || m.effects
                .iter()
                .zip(&m0.effects)
                .any(|(a, b)| a.kind() != b.kind() || a.gains().len() != b.gains().len())
        {
            Some("effects differ".to_string())
        } else if m
            .effects
            .iter()
            .zip(&m0.effects)
            .any(|(a, b)| a.gains().is_empty() && a != b)
        {
            Some("actuator effects differ".to_string())
        } else {
            None
        };
        if let Some(what) = what {
            return Err(MergeError::Structure { index: i, what });
        }
    }
    Ok(())
}

/// The paper's plain average: parameter-wise mean of θ and the effect gains.
///
/// # Errors
/// [`MergeError::Empty`] or [`MergeError::Structure`] when the models differ in order,
/// sample time or effects.
///
/// ```
/// use yawcast::{identify::merge, identify::model::Model};
/// let a = Model::new(1.0, vec![0.1, 0.5], vec![1.0, 2.0], vec![0.2, 0.1]).unwrap();
/// let b = Model::new(1.0, vec![0.3, 0.3], vec![3.0, 2.0], vec![0.4, 0.1]).unwrap();
/// let m = merge::average(&[a, b]).unwrap();
/// assert_eq!(m.b, vec![2.0, 2.0]);
/// assert!((m.a[0] - 0.2).abs() < 1e-15);
/// ```
pub fn average(models: &[Model]) -> Result<Model, MergeError> {
    let refs: Vec<&Model> = models.iter().collect();
    same_structure(&refs)?;
    let count = models.len() as f64;
    let mut m = models[0].clone();
    let mut th = vec![0.0; m.theta().len()];
    let mut gains = vec![0.0; m.effect_gains().len()];
    for x in models {
        for (t, v) in th.iter_mut().zip(x.theta()) {
            *t += v;
        }
        for (t, v) in gains.iter_mut().zip(x.effect_gains()) {
            *t += v;
        }
    }
    th.iter_mut().for_each(|v| *v /= count);
    gains.iter_mut().for_each(|v| *v /= count);
    m.set_theta(&th);
    m.set_effect_gains(&gains);
    Ok(m)
}

/// STD of the plain average of independent estimates: `√(Σ σ²_i)/R` per parameter.
///
/// # Errors
/// [`MergeError::Empty`] or [`MergeError::Structure`] as [`average`].
pub fn average_std(reports: &[PemReport]) -> Result<Vec<f64>, MergeError> {
    let refs: Vec<&Model> = reports.iter().map(|r| &r.model).collect();
    same_structure(&refs)?;
    let count = reports.len() as f64;
    let p = reports[0].std.len();
    Ok((0..p)
        .map(|j| {
            reports
                .iter()
                .map(|r| r.std[j] * r.std[j])
                .sum::<f64>()
                .sqrt()
                / count
        })
        .collect())
}

/// The covariance-weighted merge of several estimates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Merged {
    /// The merged model.
    pub model: Model,
    /// Its covariance `(Σ P_i⁻¹)⁻¹`.
    pub cov: Vec<Vec<f64>>,
    /// STD per parameter.
    pub std: Vec<f64>,
    /// `χ² = Σ (θ_i − θ)ᵀ P_i⁻¹ (θ_i − θ)`.
    pub chi2: f64,
    /// Degrees of freedom `(R − 1)·p`.
    pub dof: usize,
    /// `P(χ²_dof ≥ chi2)`: small values say the estimates are not of one model.
    pub p_value: f64,
}

/// Symmetric (pseudo-)inverse by eigen-decomposition; eigenvalues below `1e-12·max` are
/// treated as zero. Returns the inverse and the rank.
fn sym_pinv(m: &DMatrix<f64>) -> (DMatrix<f64>, usize) {
    let n = m.nrows();
    // Jacobi scaling keeps parameters of different magnitudes from hiding each other.
    let d = crate::identify::pem::jacobi_scale(m);
    let s = DMatrix::from_fn(n, n, |i, j| m[(i, j)] * d[i] * d[j]);
    // bounded iterations: a matrix the eigen-solver cannot take has rank 0 here (no
    // information), not a hang
    let Some(e) = s
        .iter()
        .all(|v| v.is_finite())
        .then(|| s.try_symmetric_eigen(f64::EPSILON, 10_000))
        .flatten()
    else {
        return (DMatrix::zeros(n, n), 0);
    };
    let max = e.eigenvalues.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut inv = DMatrix::zeros(n, n);
    let mut rank = 0;
    for k in 0..n {
        let l = e.eigenvalues[k];
        if l > 1e-12 * max {
            rank += 1;
            let v = e.eigenvectors.column(k);
            inv += (v * v.transpose()) / l;
        }
    }
    (
        DMatrix::from_fn(n, n, |i, j| inv[(i, j)] * d[i] * d[j]),
        rank,
    )
}

/// MATLAB-style `merge`: `θ = (Σ P_i⁻¹)⁻¹ Σ P_i⁻¹ θ_i` with the χ² consistency statistic.
///
/// # Errors
/// [`MergeError::Empty`], [`MergeError::Structure`], or [`MergeError::Covariance`] when a
/// covariance has the wrong size, is not finite, or the information sum is singular.
pub fn merge(reports: &[PemReport]) -> Result<Merged, MergeError> {
    let refs: Vec<&Model> = reports.iter().map(|r| &r.model).collect();
    same_structure(&refs)?;
    let p = pem::params_of(&reports[0].model).len();
    let mut info_sum = DMatrix::<f64>::zeros(p, p);
    let mut rhs = nalgebra::DVector::<f64>::zeros(p);
    let mut infos = Vec::with_capacity(reports.len());
    for (i, r) in reports.iter().enumerate() {
        if r.cov.len() != p || r.cov.iter().any(|row| row.len() != p) {
            return Err(MergeError::Covariance {
                index: i,
                what: format!("expected {p}×{p}"),
            });
        }
        let c = DMatrix::from_fn(p, p, |a, b| r.cov[a][b]);
        if c.iter().any(|v| !v.is_finite()) {
            return Err(MergeError::Covariance {
                index: i,
                what: "not finite".into(),
            });
        }
        let (inf, _) = sym_pinv(&c);
        let th = nalgebra::DVector::from_vec(pem::params_of(&r.model));
        rhs += &inf * &th;
        info_sum += &inf;
        infos.push((inf, th));
    }
    let (cov, rank) = sym_pinv(&info_sum);
    if rank < p {
        return Err(MergeError::Covariance {
            index: 0,
            what: format!("the summed information has rank {rank} < {p}"),
        });
    }
    let theta = &cov * rhs;
    let mut chi2 = 0.0;
    for (inf, th) in &infos {
        let d = th - &theta;
        chi2 += d.dot(&(inf * &d));
    }
    let dof = (reports.len() - 1) * p;
    let mut model = reports[0].model.clone();
    let t: Vec<f64> = theta.iter().copied().collect();
    let nt = 3 * model.n;
    model.set_theta(&t[..nt]);
    model.set_effect_gains(&t[nt..]);
    Ok(Merged {
        std: (0..p).map(|i| cov[(i, i)].max(0.0).sqrt()).collect(),
        cov: (0..p)
            .map(|i| (0..p).map(|j| cov[(i, j)]).collect())
            .collect(),
        p_value: if dof == 0 {
            1.0
        } else {
            chi2_sf(chi2, dof as f64)
        },
        chi2,
        dof,
        model,
    })
}

/// One way of combining, and how it validates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Combination {
    /// `average`, `merge` or `multi`.
    pub name: String,
    /// The combined model.
    pub model: Model,
    /// Mean fit % over the validation records per horizon (`"1"`, `"5"`, `"10"`, `"20"`, `"sim"`).
    pub fits: BTreeMap<String, f64>,
    /// A and A − KC stable.
    pub stable: bool,
    /// STD per parameter, when known.
    pub std: Vec<f64>,
    /// One line: how it was made (χ² test for `merge`).
    pub note: String,
}

/// The comparison of the three combinations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CombineReport {
    /// Per-record identifications (the inputs of `average` and `merge`).
    pub per_record: Vec<PemReport>,
    /// `average`, `merge` (when the covariances allow it), `multi`.
    pub combinations: Vec<Combination>,
    /// Name of the combination with the best mean k-step fit (1, 5, 10, 20) among the stable.
    pub best: Option<String>,
    /// Why `merge` is missing, when it is.
    pub merge_error: Option<String>,
}

/// Mean fit per report horizon over `records`.
///
/// ```
/// use yawcast::{io::data::Record, identify::merge, identify::model::Model, identify::predict};
/// let m = Model::new(1.0, vec![0.0, 0.5], vec![1.0, 0.5], vec![0.0, 0.0]).unwrap();
/// let u: Vec<f64> = (0..50).map(|i| if i % 7 < 3 { 1.0 } else { -1.0 }).collect();
/// let mut r = Record::from_uy("x", 1.0, u, vec![0.0; 50]);
/// r.y = predict::simulate(&m, &r, &[0.0, 0.0]);
/// let fits = merge::validation_fits(&m, &[r]);
/// assert!(fits["5"] > 99.99 && fits["sim"] > 99.99);
/// ```
pub fn validation_fits(model: &Model, records: &[Record]) -> BTreeMap<String, f64> {
    let x0s: Vec<Vec<f64>> = records
        .iter()
        .map(|r| predict::estimate_x0(model, r))
        .collect();
    Horizon::REPORT
        .iter()
        .map(|h| {
            let f = records
                .iter()
                .zip(&x0s)
                .map(|(r, x)| predict::fit(&r.y, &predict::predict(model, r, x, *h)))
                .sum::<f64>()
                / records.len().max(1) as f64;
            (h.key(), f)
        })
        .collect()
}

fn combination(
    name: &str,
    model: Model,
    std: Vec<f64>,
    note: String,
    val: &[Record],
) -> Combination {
    Combination {
        name: name.into(),
        stable: model.is_stable(),
        fits: validation_fits(&model, val),
        model,
        std,
        note,
    }
}

/// Refuses a record signed the other way round from the rest ([`MergeError::CommandSign`])
/// or with its command in another unit ([`MergeError::CommandUnit`]): an estimation record
/// that more than half of the other records' models find flipped
/// ([`predict::command_flipped`]) or in another unit ([`predict::command_other_unit`]), or a
/// validation record that more than half of all of them do. Two estimation records that each
/// find the other flipped are both flagged, the first named.
fn check_commands(models: &[Model], records: &[Record], val: &[Record]) -> Result<(), MergeError> {
    let sets = records
        .iter()
        .enumerate()
        .map(|(i, r)| ("estimation", r, Some(i)))
        .chain(val.iter().map(|r| ("validation", r, None)));
    for (set, rec, skip) in sets {
        let others: Vec<&Model> = (0..models.len())
            .filter(|j| Some(*j) != skip)
            .map(|j| &models[j])
            .collect();
        let of = others.len();
        let flipped = others
            .iter()
            .filter(|m| predict::command_flipped(m, rec).is_some())
            .count();
        if of > 0 && 2 * flipped > of {
            return Err(MergeError::CommandSign {
                set,
                record: rec.name.clone(),
                flipped,
                of,
            });
        }
        let mut scales: Vec<f64> = others
            .iter()
            .filter_map(|m| predict::command_other_unit(m, rec).map(|s| s.scale))
            .collect();
        if of > 0 && 2 * scales.len() > of {
            scales.sort_by(f64::total_cmp);
            return Err(MergeError::CommandUnit {
                set,
                record: rec.name.clone(),
                scale: scales[scales.len() / 2],
                found: scales.len(),
                of,
            });
        }
    }
    Ok(())
}

/// Identifies each of `records` alone, combines them by `average` and `merge`, identifies on
/// all of them at once (`multi`), and validates the three on `validation`.
///
/// # Errors
/// [`MergeError::NoValidation`] without validation records; [`MergeError::Identification`]
/// when a per-record or the multi-record identification fails; [`MergeError::CommandSign`]
/// when a record is signed the other way round from the others, [`MergeError::CommandUnit`]
/// when its command is in another unit. A failed `merge` (singular
/// covariances) is reported in [`CombineReport::merge_error`].
pub fn compare(
    records: &[Record],
    validation: &[Record],
    template: Option<&Model>,
    cfg: &PemConfig,
) -> Result<CombineReport, MergeError> {
    if validation.is_empty() {
        return Err(MergeError::NoValidation);
    }
    if records.is_empty() {
        return Err(MergeError::Empty);
    }
    let per_record: Vec<PemReport> = records
        .par_iter()
        .map(|r| {
            pem::identify(std::slice::from_ref(r), template, cfg).map_err(|source| {
                MergeError::Identification {
                    record: r.name.clone(),
                    source,
                }
            })
        })
        .collect::<Result<_, _>>()?;
    let models: Vec<Model> = per_record.iter().map(|r| r.model.clone()).collect();
    check_commands(&models, records, validation)?;
    let mut combinations = Vec::new();
    let avg = average(&models)?;
    combinations.push(combination(
        "average",
        avg,
        average_std(&per_record)?,
        format!("parameter mean of {} per-record models", models.len()),
        validation,
    ));
    let mut merge_error = None;
    match merge(&per_record) {
        Ok(m) => combinations.push(combination(
            "merge",
            m.model,
            m.std,
            format!(
                "covariance-weighted; χ² = {:.1} on {} dof, p = {:.3}{}",
                m.chi2,
                m.dof,
                m.p_value,
                if m.p_value < 0.05 {
                    " (the per-record models disagree beyond their uncertainty)"
                } else {
                    ""
                }
            ),
            validation,
        )),
        Err(e) => merge_error = Some(e.to_string()),
    }
    let multi =
        pem::identify(records, template, cfg).map_err(|source| MergeError::Identification {
            record: "all records".into(),
            source,
        })?;
    combinations.push(combination(
        "multi",
        multi.model,
        multi.std,
        format!("one identification over {} records", records.len()),
        validation,
    ));
    let score = |c: &Combination| {
        ["1", "5", "10", "20"]
            .iter()
            .map(|k| c.fits[*k])
            .sum::<f64>()
            / 4.0
    };
    let best = combinations
        .iter()
        .filter(|c| c.stable && score(c).is_finite())
        .max_by(|a, b| score(a).total_cmp(&score(b)))
        .map(|c| c.name.clone());
    Ok(CombineReport {
        per_record,
        combinations,
        best,
        merge_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::model::Effect;
    use crate::identify::pem::testdata;

    #[test]
    fn merge_of_two_scalar_like_estimates_is_inverse_variance_weighted() {
        let rep = |b0: f64, var: f64| {
            let recs = [testdata::record(1, 300)];
            let mut r = pem::identify(&recs, None, &PemConfig::default()).unwrap();
            let mut th = pem::params_of(&r.model);
            th[4] = b0;
            r.model.set_theta(&th[..12]);
            r.cov = (0..12)
                .map(|i| (0..12).map(|j| if i == j { var } else { 0.0 }).collect())
                .collect();
            r
        };
        let a = rep(1.0, 1.0);
        let b = rep(4.0, 2.0);
        let m = merge(&[a, b]).unwrap();
        // (1/1·1 + 1/2·4)/(1 + 1/2) = 2
        assert!((m.model.b[0] - 2.0).abs() < 1e-12);
        assert!((m.std[4] - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
        // χ² = (1−2)²/1 + (4−2)²/2 = 3 on 12 dof
        assert!((m.chi2 - 3.0).abs() < 1e-9);
        assert_eq!(m.dof, 12);
        assert!(m.p_value > 0.99);
    }

    #[test]
    fn different_structures_are_refused() {
        let a = testdata::truth();
        let b = a.clone().with_effect(Effect::Bias { beta: 0.1 });
        let e = average(&[a, b]).unwrap_err();
        assert!(matches!(e, MergeError::Structure { index: 1, .. }), "{e}");
        assert_eq!(average(&[]).unwrap_err(), MergeError::Empty);
    }

    #[test]
    fn three_combinations_are_validated_and_consistent_data_passes_chi2() {
        let recs: Vec<Record> = (0..4).map(|s| testdata::record(20 + s, 800)).collect();
        let val = vec![testdata::record(77, 1000)];
        let rep = compare(&recs, &val, None, &PemConfig::default()).unwrap();
        let names: Vec<&str> = rep.combinations.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, vec!["average", "merge", "multi"]);
        for c in &rep.combinations {
            assert!(c.stable, "{}", c.name);
            assert!(c.fits["5"] > 90.0, "{}: {:?}", c.name, c.fits);
        }
        assert!(rep.best.is_some());
        // data from one model: the merge's χ² test does not reject
        let m = merge(&rep.per_record).unwrap();
        assert!(
            m.p_value > 0.001,
            "χ² {} dof {} p {}",
            m.chi2,
            m.dof,
            m.p_value
        );
    }
}
