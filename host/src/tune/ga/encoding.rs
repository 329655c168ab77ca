//! The chromosome: gene decoding, what the genes stand for, and the genetic operators.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::GaConfig;
use crate::identify::model::Model;

/// Decodes a gene code into `[lo, hi]`.
///
/// ```
/// use yawcast::tune::ga::decode;
/// assert_eq!(decode(0, 13, (1e-8, 100.0), false), 1e-8);
/// assert_eq!(decode(8191, 13, (1e-8, 100.0), false), 100.0);
/// assert!((decode(8191, 13, (1e-8, 100.0), true) - 100.0).abs() < 1e-9);
/// ```
pub fn decode(code: u16, bits: u32, range: (f64, f64), log_scale: bool) -> f64 {
    let max = ((1u32 << bits) - 1) as f64;
    let f = f64::from(code) / max;
    let (lo, hi) = range;
    if f >= 1.0 {
        return hi;
    }
    if f <= 0.0 {
        return lo;
    }
    if log_scale {
        lo * (hi / lo).powf(f)
    } else {
        lo + (hi - lo) * f
    }
}

/// What the genes of a chromosome stand for.
#[derive(Debug, Clone)]
pub(super) struct Genome {
    /// For each parameter, the gene index of its R weight.
    pub(super) r_gene: Vec<usize>,
    /// Gene index of λ.
    lambda_gene: usize,
    /// Genes in total.
    pub(super) len: usize,
}

impl Genome {
    pub(super) fn new(base: &Model, grouped: bool) -> Genome {
        let n = base.n;
        let p = 3 * n + base.effect_gains().len();
        let (r_gene, lambda_gene) = if grouped {
            let has_effects = p > 3 * n;
            let r_gene: Vec<usize> = (0..p).map(|i| if i < 3 * n { i / n } else { 3 }).collect();
            (r_gene, if has_effects { 4 } else { 3 })
        } else {
            ((0..p).collect(), p)
        };
        Genome {
            r_gene,
            lambda_gene,
            len: lambda_gene + 1,
        }
    }

    pub(super) fn decode(&self, genes: &[u16], cfg: &GaConfig) -> (f64, Vec<f64>) {
        let lambda = decode(
            genes[self.lambda_gene],
            cfg.bits,
            cfg.lambda_range,
            cfg.log_scale,
        );
        let r = self
            .r_gene
            .iter()
            .map(|g| decode(genes[*g], cfg.bits, cfg.r_range, cfg.log_scale))
            .collect();
        (lambda, r)
    }
}

/// Selection (rank scaling, stochastic universal sampling), crossover, mutation, elitism.
pub(super) fn next_generation(
    pop: &[Vec<u16>],
    fit: &[f64],
    cfg: &GaConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<Vec<u16>> {
    let size = pop.len();
    let mut order: Vec<usize> = (0..size).collect();
    order.sort_by(|a, b| fit[*b].total_cmp(&fit[*a]).then(a.cmp(b)));
    // rank scaling 1/√rank; rejected members get no offspring (unless all are rejected)
    let mut scaled = vec![0.0; size];
    for (rank, &i) in order.iter().enumerate() {
        if fit[i].is_finite() {
            scaled[i] = 1.0 / ((rank + 1) as f64).sqrt();
        }
    }
    if scaled.iter().all(|v| *v == 0.0) {
        scaled.fill(1.0);
    }
    let mut next: Vec<Vec<u16>> = order[..cfg.elite].iter().map(|&i| pop[i].clone()).collect();
    let children = size - cfg.elite;
    // stochastic universal sampling
    let total: f64 = scaled.iter().sum();
    let step = total / children as f64;
    let mut pointer = rng.random::<f64>() * step;
    let mut parents = Vec::with_capacity(children);
    let mut acc = 0.0;
    let mut i = 0;
    while parents.len() < children {
        while acc + scaled[i] < pointer && i + 1 < size {
            acc += scaled[i];
            i += 1;
        }
        parents.push(pop[i].clone());
        pointer += step;
    }
    // shuffle so that pairs mix
    for j in (1..parents.len()).rev() {
        let k = rng.random_range(0..=j);
        parents.swap(j, k);
    }
    let len = pop[0].len();
    let mut j = 0;
    while j + 1 < parents.len() {
        if rng.random::<f64>() < cfg.crossover {
            let (a, b) = parents.split_at_mut(j + 1);
            let (x, y) = (&mut a[j], &mut b[0]);
            let mut swapped = false;
            for g in 0..len {
                if rng.random::<bool>() {
                    std::mem::swap(&mut x[g], &mut y[g]);
                    swapped = true;
                }
            }
            if !swapped {
                let g = rng.random_range(0..len);
                std::mem::swap(&mut x[g], &mut y[g]);
            }
        }
        j += 2;
    }
    for c in &mut parents {
        for g in c.iter_mut() {
            if rng.random::<f64>() < cfg.mutation {
                let bit = rng.random_range(0..cfg.bits);
                let mut v = *g ^ (1 << bit);
                for b in 0..cfg.bits {
                    if b != bit && rng.random::<f64>() < 1.0 / f64::from(cfg.bits) {
                        v ^= 1 << b;
                    }
                }
                *g = v;
            }
        }
    }
    next.extend(parents);
    next
}
