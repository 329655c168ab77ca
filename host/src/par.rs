//! Maps that run on rayon's pool when allowed and one after the other otherwise, with the
//! same result either way (the order of the items is kept).

use rayon::prelude::*;

/// `items.iter().map(f).collect()`, in parallel when `parallel`.
pub(crate) fn map<T, R, F>(items: &[T], parallel: bool, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync + Send,
{
    if parallel {
        items.par_iter().map(f).collect()
    } else {
        items.iter().map(f).collect()
    }
}

/// `items.into_iter().map(f).collect()`, in parallel when `parallel`.
pub(crate) fn map_owned<T, R, F>(items: Vec<T>, parallel: bool, f: F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync + Send,
{
    if parallel {
        items.into_par_iter().map(f).collect()
    } else {
        items.into_iter().map(f).collect()
    }
}

/// `(0..n).map(f).collect()`, in parallel when `parallel`.
pub(crate) fn map_range<R, F>(n: usize, parallel: bool, f: F) -> Vec<R>
where
    R: Send,
    F: Fn(usize) -> R + Sync + Send,
{
    if parallel {
        (0..n).into_par_iter().map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_and_sequential_maps_agree_in_order() {
        let v: Vec<u64> = (0..1000).map(|i| i * 7919 % 1013).collect();
        let sq = |x: &u64| x * x + 1;
        assert_eq!(map(&v, true, sq), map(&v, false, sq));
        assert_eq!(map(&v, false, sq)[3], v[3] * v[3] + 1);
        assert_eq!(
            map_owned(v.clone(), true, |x| x + 2),
            map_owned(v.clone(), false, |x| x + 2)
        );
        let r = map_range(500, true, |i| v[i] ^ 5);
        assert_eq!(r, map_range(500, false, |i| v[i] ^ 5));
        assert_eq!(r[499], v[499] ^ 5);
        assert!(map_range(0, true, |i| i).is_empty());
    }
}
