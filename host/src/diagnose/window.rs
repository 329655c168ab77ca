//! Long records: the blocks a record set longer than [`WINDOW`] samples is diagnosed on.

use crate::io::data::Record;

#[cfg(doc)]
use super::diagnose;

/// Samples of one record set (the trials, the reference records, the held-out records) that
/// [`diagnose`] works on at most. A longer set is read as blocks of [`WINDOW_BLOCK`] samples
/// spread evenly over each record ([`window`]); every statistic, replicate and refit then runs
/// on the blocks, so the time and memory a diagnosis takes stop growing with the records'
/// length. Each block is a record of its own (its own x̂(0)); the likelihood statistics and
/// their bootstrap nulls are measured on the same blocks, so the test keeps its level.
pub const WINDOW: usize = 12_000;
/// Length of the blocks of a set longer than [`WINDOW`] (samples).
pub const WINDOW_BLOCK: usize = 2_000;

/// The blocks `diagnose` reads of `recs` (see [`WINDOW`]), or `None` when the set holds at
/// most [`WINDOW`] samples and is used whole. Each record gets a share of the
/// `WINDOW / WINDOW_BLOCK` blocks in proportion to its length (at least one), as blocks of
/// `min(WINDOW_BLOCK, its length)` samples, the first at its start, the last at its end and
/// the others evenly between; block names are `name@first-sample`. `None` too when the
/// blocks would be the whole records (many records shorter than a block).
///
/// ```
/// use yawcast::{diagnose::{window, WINDOW_BLOCK}, io::data::Record};
/// let r = Record::from_uy("long", 1.0, vec![0.0; 100_000], vec![0.0; 100_000]);
/// let blocks = window(std::slice::from_ref(&r)).unwrap();
/// assert_eq!(blocks.len(), 6);
/// assert!(blocks.iter().all(|b| b.len() == WINDOW_BLOCK));
/// assert_eq!(blocks[1].name, "long@19600");
/// assert_eq!(blocks[5].t[WINDOW_BLOCK - 1], 99_999.0);
/// assert!(window(&[r.slice(0, 12_000)]).is_none());
/// // ten records of 1 800 samples: one block each would be each whole record
/// assert!(window(&vec![r.slice(0, 1_800); 10]).is_none());
/// ```
pub fn window(recs: &[Record]) -> Option<Vec<Record>> {
    let total: usize = recs.iter().map(Record::len).sum();
    if total <= WINDOW {
        return None;
    }
    let blocks = WINDOW / WINDOW_BLOCK;
    let mut out = Vec::new();
    for r in recs {
        let len = r.len();
        let l = WINDOW_BLOCK.min(len);
        let k = ((blocks * len + total / 2) / total).clamp(1, len / l.max(1));
        for j in 0..k {
            let st = if k == 1 { 0 } else { j * (len - l) / (k - 1) };
            let mut b = r.slice(st, st + l);
            b.name = format!("{}@{st}", r.name);
            out.push(b);
        }
    }
    // many short records: one whole record each is no window at all
    let kept: usize = out.iter().map(Record::len).sum();
    (kept < total).then_some(out)
}
