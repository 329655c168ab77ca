//! Isolated spikes in the yaw rate: samples that leave their neighbours and come back
//! within one sample by more than the gyro's noise and a ship's yaw rate allow — a logger's
//! glitch, a bit flipped on the line. Found ([`spikes`]), refused by
//! [`super::validate_record`], or replaced ([`despike`], `--despike`).
//!
//! Why they matter: a spike of a few °/s in 1 800 samples of a yaw rate that spans 1 °/s
//! is what a cubic damping term fits best, and effect-free trials with five spikes of 5 °/s
//! per record read `nonlinear-damping` (Mariner, the Seiun Maru and the built-in ship,
//! `bench/worlds/run.sh`'s records).
//!
//! How one is told from the ship's own motion: a sample's departure from the lines through
//! its two neighbours on either side, `y_i − (2y_{i−1} − y_{i−2})` and `y_i − (2y_{i+1} −
//! y_{i+2})`, the smaller where both go the same way ([`departure`]). A rudder step bends the
//! yaw rate (its acceleration jumps), and a bend lies on one of the two lines; a spike leaves
//! both. A sample is a spike where its departure exceeds both [`NOISE_TIMES`] the records'
//! own robust scale of second differences (the noise's, or on a noise-free record the
//! curvature's) and [`RANGE_SHARE`] of the yaw rate's range (its 1st to 99th percentile: a
//! record resolved to 0.001 °/s flips one step now and then). Measured on 985 clean
//! records — the six test worlds' references and trials (PRBS, ±20° zig-zags, heading and
//! speed noise ×1 and ×10), noise-free records of each world under PRBS, zig-zags and an
//! autopilot, MARIN's and HSVA's KVLCC2 records, the pond's Esso Osaka zig-zags — the
//! largest departure is 0.41 of that bound; spikes of 1 and 5 °/s on Mariner's, the Seiun
//! Maru's and the built-in ship's trials are 1.6–8.7 times it (`docs/benchmarks.md`).

/// A spike's departure is more than this many times the robust scale (1.4826 × the median
/// absolute value) of the record's second differences: Gaussian noise goes beyond it on both
/// sides at once less than once in 10¹⁵ samples.
pub const NOISE_TIMES: f64 = 8.0;

/// A spike's departure is more than this share of the yaw rate's range (1st to 99th
/// percentile). Of the two bounds the larger holds: no clean record measured departs by
/// more than 0.41 of it (module docs); alone, each is passed by some.
pub const RANGE_SHARE: f64 = 0.1;

/// One spike of a record's yaw rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spike {
    /// 0-based sample.
    pub index: usize,
    /// The value logged (°/s).
    pub value: f64,
    /// The value its neighbours make (the cubic through the nearest two on either side that
    /// are not spikes), which [`despike`] writes in its place (°/s).
    pub fitted: f64,
}

/// The robust scale (1.4826 × median |v|) of `v`; 0 for an empty slice.
fn robust_scale(v: impl Iterator<Item = f64>) -> f64 {
    let mut a: Vec<f64> = v.filter(|x| x.is_finite()).map(f64::abs).collect();
    if a.is_empty() {
        return 0.0;
    }
    let mid = a.len() / 2;
    let (_, m, _) = a.select_nth_unstable_by(mid, f64::total_cmp);
    1.4826 * *m
}

/// The spikes of the yaw rate `y` (module docs), each as [`despike`] would replace it, in
/// order of their samples. The bound is measured once on `y` as logged (robust: spikes do
/// not move a median). Two spikes in a row, of opposite signs or the same, are both found
/// and replaced from the samples around them; a rudder's bend beside a spike is not taken
/// for one. The first two and last two samples, which lack two neighbours on one side, are
/// not judged. Non-finite values, or fewer than 5 samples: none.
///
/// ```
/// use yawcast::io::data::spikes;
/// let mut y: Vec<f64> = (0..200).map(|i| (i as f64 * 0.05).sin()).collect();
/// assert!(spikes(&y).is_empty());
/// y[50] += 4.0;
/// let s = spikes(&y);
/// assert_eq!(s.len(), 1);
/// assert_eq!(s[0].index, 50);
/// assert!((s[0].fitted - (2.5f64).sin()).abs() < 1e-3);
/// ```
pub fn spikes(y: &[f64]) -> Vec<Spike> {
    let n = y.len();
    if n < 5 || y.iter().any(|v| !v.is_finite()) {
        return Vec::new();
    }
    let noise = robust_scale((1..n - 1).map(|i| y[i + 1] - 2.0 * y[i] + y[i - 1]));
    let mut sorted = y.to_vec();
    sorted.sort_by(f64::total_cmp);
    let at_share = |q: f64| sorted[(q * (n - 1) as f64) as usize];
    let range = at_share(0.99) - at_share(0.01);
    let bound = (NOISE_TIMES * noise).max(RANGE_SHARE * range);
    if bound <= 0.0 {
        return Vec::new();
    }
    // a spike bends its neighbours' lines too: a neighbour that is also a rudder's bend
    // can pass the bound beside it. So each sample past the bound is judged again against
    // the record with all of them replaced from the samples around them, itself as logged
    let mut past: Vec<usize> = (2..n - 2)
        .filter(|&i| departure(y, i, y[i]) > bound)
        .collect();
    // two in a row the same way: each leaves the lines through the two samples beyond the
    // pair on either side
    for i in 2..n.saturating_sub(3) {
        if pair_departure(y, i) > bound {
            past.extend([i, i + 1]);
        }
    }
    past.sort_unstable();
    past.dedup();
    let mut z = y.to_vec();
    fill(&mut z, &past);
    let at: Vec<usize> = past
        .into_iter()
        .filter(|&i| departure(&z, i, y[i]) > bound)
        .collect();
    let mut z = y.to_vec();
    fill(&mut z, &at);
    at.into_iter()
        .map(|i| Spike {
            index: i,
            value: y[i],
            fitted: z[i],
        })
        .collect()
}

/// How far the samples `i` and `i + 1` both leave the lines through the two samples before
/// and the two after the pair, the same way from both (as [`departure`]; the smaller of the
/// four departures where all agree in sign, else 0; `2 ≤ i < len − 3`).
fn pair_departure(y: &[f64], i: usize) -> f64 {
    let slope_in = y[i - 1] - y[i - 2];
    let slope_out = y[i + 3] - y[i + 2];
    let d = [
        y[i] - (y[i - 1] + slope_in),
        y[i + 1] - (y[i - 1] + 2.0 * slope_in),
        y[i] - (y[i + 2] - 2.0 * slope_out),
        y[i + 1] - (y[i + 2] - slope_out),
    ];
    if d.iter().all(|v| *v > 0.0) || d.iter().all(|v| *v < 0.0) {
        d.iter().fold(f64::INFINITY, |m, v| m.min(v.abs()))
    } else {
        0.0
    }
}

/// How far the value `v` at sample `i` leaves the lines through `y`'s two neighbours on
/// either side, the same way from both: the smaller of the two departures where they agree
/// in sign, else 0 (`2 ≤ i < len − 2`). A bend of the yaw rate (a rudder step) lies on one
/// of the lines.
fn departure(y: &[f64], i: usize, v: f64) -> f64 {
    let left = v - (2.0 * y[i - 1] - y[i - 2]);
    let right = v - (2.0 * y[i + 1] - y[i + 2]);
    if left * right > 0.0 {
        left.abs().min(right.abs())
    } else {
        0.0
    }
}

/// Replaces the samples `set` (ascending) of `z` by the cubic through the nearest two samples
/// on either side of each run of them that are not in `set` (as many as the record has).
fn fill(z: &mut [f64], set: &[usize]) {
    let n = z.len();
    let mut k = 0;
    while k < set.len() {
        let a = set[k];
        let mut b = a;
        while k + 1 < set.len() && set[k + 1] == b + 1 {
            k += 1;
            b += 1;
        }
        k += 1;
        let kept = |j: &usize| set.binary_search(j).is_err();
        let left = (0..a).rev().filter(kept).take(2);
        let right = (b + 1..n).filter(kept).take(2);
        let pts: Vec<(f64, f64)> = left.chain(right).map(|j| (j as f64, z[j])).collect();
        for i in a..=b {
            z[i] = lagrange(&pts, i as f64);
        }
    }
}

/// The polynomial through `pts` at `x`.
fn lagrange(pts: &[(f64, f64)], x: f64) -> f64 {
    let mut sum = 0.0;
    for (i, &(xi, yi)) in pts.iter().enumerate() {
        let mut w = 1.0;
        for (j, &(xj, _)) in pts.iter().enumerate() {
            if i != j {
                w *= (x - xj) / (xi - xj);
            }
        }
        sum += w * yi;
    }
    sum
}

/// Replaces the spikes of the yaw rate `y` ([`spikes`]) by the values their neighbours make,
/// and returns them (as logged).
///
/// ```
/// use yawcast::io::data::despike;
/// let mut y: Vec<f64> = (0..200).map(|i| 0.3 * (i as f64 * 0.05).sin()).collect();
/// let clean = y.clone();
/// y[20] -= 2.0;
/// y[120] += 3.0;
/// let s = despike(&mut y);
/// assert_eq!(s.iter().map(|s| s.index).collect::<Vec<_>>(), vec![20, 120]);
/// assert!(y.iter().zip(&clean).all(|(a, b)| (a - b).abs() < 1e-3));
/// ```
pub fn despike(y: &mut [f64]) -> Vec<Spike> {
    let s = spikes(y);
    for k in &s {
        y[k.index] = k.fitted;
    }
    s
}

/// The 1-based rows of `spikes`, the first ten, as the messages list them.
///
/// ```
/// use yawcast::io::data::{spike_rows, Spike};
/// let s = |index| Spike { index, value: 1.0, fitted: 0.0 };
/// assert_eq!(spike_rows(&[s(4), s(9)]), "5, 10");
/// assert_eq!(spike_rows(&(0..12).map(s).collect::<Vec<_>>()), "1, 2, 3, 4, 5, 6, 7, 8, 9, 10, …");
/// ```
pub fn spike_rows(spikes: &[Spike]) -> String {
    let mut s: Vec<String> = spikes
        .iter()
        .take(10)
        .map(|k| (k.index + 1).to_string())
        .collect();
    if spikes.len() > 10 {
        s.push("…".into());
    }
    s.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// A yaw rate of a ship answering a PRBS (first order, T = 20 s, Ts = 1 s) with white
    /// gyro noise `sigma`.
    fn yaw(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut r = 0.0;
        let mut u = 10.0;
        (0..n)
            .map(|i| {
                if i % 37 == 0 {
                    u = -u;
                }
                r += (0.05 * u - r) / 20.0;
                r + sigma * crate::stats::standard_normal(&mut rng)
            })
            .collect()
    }

    #[test]
    fn noise_and_rudder_steps_are_not_spikes_and_glitches_are() {
        // noisy and noise-free: neither the noise nor the rudder's steps (the yaw rate's
        // kinks) are spikes
        for sigma in [0.0, 1e-6, 0.02, 0.1] {
            for seed in 0..5 {
                assert!(spikes(&yaw(1800, sigma, seed)).is_empty(), "{sigma} {seed}");
            }
        }
        // five glitches of ±2 °/s found where they are, the yaw rate given back to within
        // its noise; two in a row of opposite signs, and two of the same, found both
        let clean = yaw(1800, 0.02, 7);
        let mut y = clean.clone();
        let at = [100, 400, 401, 900, 1500];
        for (k, &i) in at.iter().enumerate() {
            y[i] += if k % 2 == 0 { 2.0 } else { -2.0 };
        }
        y[1200] += 2.0;
        y[1201] += 2.0;
        let s = despike(&mut y);
        let mut all = at.to_vec();
        all.extend([1200, 1201]);
        all.sort_unstable();
        assert_eq!(s.iter().map(|s| s.index).collect::<Vec<_>>(), all);
        assert_eq!(s[0].value.to_bits(), (clean[100] + 2.0).to_bits());
        for &i in &all {
            assert!((y[i] - clean[i]).abs() < 0.1, "{i}: {} {}", y[i], clean[i]);
        }
        // a spike under the noise's bound is left: 0.1 °/s on 0.02 °/s of noise
        let mut y = clean.clone();
        y[300] += 0.1;
        assert!(spikes(&y).is_empty());
        // a spike beside a rudder's bend: the bend is not taken for a spike (a fast hull,
        // pole 0.9, the command switching every 7 samples, noise-free)
        let mut fast = Vec::new();
        let mut r = 0.0;
        for i in 0..200 {
            r = 0.9 * r + if (i / 7) % 2 == 0 { 0.1 } else { -0.1 };
            fast.push(r);
        }
        assert!(spikes(&fast).is_empty());
        let mut y = fast.clone();
        y[74] += 1.0;
        let s = spikes(&y);
        assert_eq!(s.iter().map(|s| s.index).collect::<Vec<_>>(), vec![74]);
        assert!((s[0].fitted - fast[74]).abs() < 0.02, "{s:?} {}", fast[74]);
        // too short, or not finite: nothing is said
        assert!(spikes(&[0.0, 5.0, 0.0]).is_empty());
        assert!(spikes(&[0.0, 1.0, f64::NAN, 1.0, 0.0, 1.0]).is_empty());
    }
}
