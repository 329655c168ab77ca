//! A logged table cut at its gaps and clock restarts into pieces yawcast reads whole
//! (`yawcast split`): each piece keeps the table's header and its own rows as written.

use std::ops::Range;
use std::path::Path;

use serde::Serialize;

use super::checks::median_step;
use super::csv_file::Dialect;
use super::timestamp::Clock;
use super::DataError;

/// Why a table is cut before a row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BreakKind {
    /// The time steps over one or more samples (a logger's drop-out): the step is 1.5
    /// periods or more.
    Gap,
    /// The time goes back: a clock restarted, or two runs were logged into one file.
    ClockBack,
}

/// One cut of a table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Break {
    /// 1-based data row the cut comes before (the first row of the next piece).
    pub row: usize,
    /// Why.
    pub kind: BreakKind,
    /// The time step there (s; negative where the clock went back).
    pub step_s: f64,
}

/// One piece of a table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Piece {
    /// 1-based data row of its first sample in the table.
    pub first_row: usize,
    /// Its rows.
    pub rows: usize,
    /// Time (s) of its first sample, from the table's first stamp.
    pub start_s: f64,
    /// Time from its first to its last sample (s).
    pub duration_s: f64,
    /// Its rows' bytes in the text (comment lines among them included).
    #[serde(skip)]
    pub bytes: Range<usize>,
}

/// A table cut at its gaps and clock restarts ([`split_at_gaps`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Split {
    /// The logger's period (s): the median of the steps that go forward.
    pub period_s: f64,
    /// The cuts, in row order.
    pub breaks: Vec<Break>,
    /// The pieces between them, in row order (every row in exactly one).
    pub pieces: Vec<Piece>,
    /// The bytes of the header (and any lines before it), which every piece repeats.
    #[serde(skip)]
    pub header: Range<usize>,
}

impl Split {
    /// The text of piece `i` of the table `text`: the header, then the piece's rows; `None`
    /// for an `i` past the last piece or a `text` this split was not made of.
    pub fn piece_text(&self, text: &str, i: usize) -> Option<String> {
        let piece = self.pieces.get(i)?;
        let (head, rows) = (
            text.get(self.header.clone())?,
            text.get(piece.bytes.clone())?,
        );
        let mut s = String::with_capacity(head.len() + rows.len() + 2);
        s.push_str(head);
        if !s.ends_with('\n') {
            s.push('\n');
        }
        s.push_str(rows);
        if !s.ends_with('\n') {
            s.push('\n');
        }
        Some(s)
    }
}

/// Cuts the table `text` (the records' CSV: `,`, `;` or tab, as the reader takes it) before
/// every row whose time stamp (column `col_time`: numbers times `time_scale`, ISO 8601
/// date-times or times of day, as the reader takes them) steps 1.5 periods or more past the
/// row before — one sample or more missing — or goes back. A repeated stamp or an extra
/// sample is not a cut: the reader names those rows. `path` only labels errors.
///
/// # Errors
/// [`DataError::MissingColumn`] without the time column, [`DataError::BadCell`] or
/// [`DataError::BadTime`] naming a row whose time cannot be read, [`DataError::TooShort`]
/// for fewer than 2 rows, [`DataError::Csv`] for a malformed table.
///
/// ```
/// use yawcast::io::data::{split_at_gaps, BreakKind};
/// let txt = "t_s,delta_deg,r_degps\n0,1,0\n1,1,0\n2,1,0\n5,1,0\n6,1,0\n0,2,0\n1,2,0\n";
/// let s = split_at_gaps(txt, "x.csv".as_ref(), "t_s", 1.0).unwrap();
/// assert_eq!(s.period_s, 1.0);
/// assert_eq!(s.breaks.iter().map(|b| (b.row, b.kind)).collect::<Vec<_>>(),
///            vec![(4, BreakKind::Gap), (6, BreakKind::ClockBack)]);
/// assert_eq!(s.pieces.iter().map(|p| p.rows).collect::<Vec<_>>(), vec![3, 2, 2]);
/// assert_eq!(s.piece_text(txt, 1).unwrap(), "t_s,delta_deg,r_degps\n5,1,0\n6,1,0\n");
/// assert_eq!(s.piece_text(txt, 3), None);
/// ```
pub fn split_at_gaps(
    text: &str,
    path: &Path,
    col_time: &str,
    time_scale: f64,
) -> Result<Split, DataError> {
    let csv_err = |e: csv::Error| DataError::Csv {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let (dialect, mut rdr, headers) = Dialect::table(text).map_err(csv_err)?;
    let it =
        headers
            .iter()
            .position(|h| h == col_time)
            .ok_or_else(|| DataError::MissingColumn {
                path: path.to_path_buf(),
                column: col_time.to_string(),
                found: headers.join(","),
            })?;
    // each row's time and where its bytes start
    let mut t: Vec<f64> = Vec::new();
    let mut start: Vec<usize> = Vec::new();
    let mut clock = Clock::Seconds;
    for (i, row) in rdr.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let rown = i + 1;
        let raw = row.get(it).unwrap_or("");
        if rown == 1 {
            clock = Clock::of(raw);
        }
        let last = t.last().copied().unwrap_or(0.0);
        let number = |c: &str| dialect.number(c).ok().filter(|v| v.is_finite());
        let ti = clock
            .seconds(raw, number, time_scale, last)
            .ok_or_else(|| {
                if clock == Clock::Seconds {
                    DataError::BadCell {
                        path: path.to_path_buf(),
                        row: rown,
                        column: headers[it].clone(),
                        value: raw.to_string(),
                    }
                } else {
                    DataError::BadTime {
                        path: path.to_path_buf(),
                        row: rown,
                        column: headers[it].clone(),
                        value: raw.to_string(),
                    }
                }
            })?;
        t.push(ti);
        // a record's position is known once read; `csv` gives it for every record
        start.push(row.position().map_or(text.len(), |p| p.byte() as usize));
    }
    if t.len() < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            found: t.len(),
            needed: 2,
        });
    }
    let period = median_step(&t);
    let mut breaks = Vec::new();
    for (i, w) in t.windows(2).enumerate() {
        let step = w[1] - w[0];
        let kind = if step < 0.0 {
            Some(BreakKind::ClockBack)
        } else if step >= 1.5 * period {
            Some(BreakKind::Gap)
        } else {
            None
        };
        if let Some(kind) = kind {
            breaks.push(Break {
                row: i + 2,
                kind,
                step_s: step,
            });
        }
    }
    let firsts: Vec<usize> = std::iter::once(1)
        .chain(breaks.iter().map(|b| b.row))
        .collect();
    let pieces = firsts
        .iter()
        .enumerate()
        .map(|(k, &first)| {
            let end = firsts.get(k + 1).copied().unwrap_or(t.len() + 1);
            let bytes_end = if end <= t.len() {
                start[end - 1]
            } else {
                text.len()
            };
            Piece {
                first_row: first,
                rows: end - first,
                start_s: t[first - 1],
                duration_s: t[end - 2] - t[first - 1],
                bytes: start[first - 1]..bytes_end,
            }
        })
        .collect();
    Ok(Split {
        period_s: period,
        breaks,
        pieces,
        header: 0..start[0],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::data::{parse_csv, Columns};

    fn split(txt: &str) -> Result<Split, DataError> {
        split_at_gaps(txt, "x.csv".as_ref(), "t_s", 1.0)
    }

    #[test]
    fn every_row_lands_in_one_piece_and_each_piece_reads_whole() {
        // 0.5 s logger; 3 samples missing before row 7; the clock restarts at row 12; a
        // comment line inside the second piece; no final newline
        let mut rows: Vec<String> = Vec::new();
        let mut times: Vec<f64> = (0..6).map(|i| 0.5 * i as f64).collect();
        times.extend((0..5).map(|i| 4.5 + 0.5 * i as f64));
        times.extend((0..4).map(|i| 0.25 + 0.5 * i as f64));
        for (i, t) in times.iter().enumerate() {
            rows.push(format!("{t},{},{}", i % 3, 0.1 * i as f64));
        }
        rows.insert(8, "# operator note".into());
        let txt = format!("t_s,delta_deg,r_degps\n{}", rows.join("\n"));
        let s = split(&txt).unwrap();
        assert_eq!(s.period_s, 0.5);
        assert_eq!(
            s.breaks,
            vec![
                Break {
                    row: 7,
                    kind: BreakKind::Gap,
                    step_s: 2.0
                },
                Break {
                    row: 12,
                    kind: BreakKind::ClockBack,
                    step_s: 0.25 - 6.5
                },
            ]
        );
        let shape: Vec<_> = s
            .pieces
            .iter()
            .map(|p| (p.first_row, p.rows, p.start_s, p.duration_s))
            .collect();
        assert_eq!(
            shape,
            vec![(1, 6, 0.0, 2.5), (7, 5, 4.5, 2.0), (12, 4, 0.25, 1.5)]
        );
        let mut ys = Vec::new();
        for i in 0..3 {
            let piece = s.piece_text(&txt, i).unwrap();
            assert!(piece.starts_with("t_s,delta_deg,r_degps\n"), "{piece}");
            let r = parse_csv(&piece, "p.csv".as_ref(), "p", &Columns::default()).unwrap();
            assert_eq!(r.ts, 0.5);
            assert_eq!(r.len(), s.pieces[i].rows);
            ys.extend(r.y);
        }
        let want: Vec<f64> = (0..times.len()).map(|i| 0.1 * i as f64).collect();
        assert_eq!(ys, want);
        assert!(s.piece_text(&txt, 1).unwrap().contains("# operator note"));
        // the whole table is refused by the reader at the first cut
        assert!(parse_csv(&txt, "x.csv".as_ref(), "x", &Columns::default()).is_err());
    }

    #[test]
    fn stamps_are_read_as_the_reader_reads_them() {
        // times of day across midnight: no cut there; one sample missing after it
        let txt = "t_s;delta_deg;r_degps\n23:59:58,5;1;0\n23:59:59,5;1;0\n00:00:00,5;1;0\n\
                   00:00:02,5;1;0\n00:00:03,5;1;0\n";
        let s = split(txt).unwrap();
        assert_eq!(s.period_s, 1.0);
        assert_eq!(s.breaks.len(), 1);
        assert_eq!((s.breaks[0].row, s.breaks[0].kind), (4, BreakKind::Gap));
        // ISO 8601 date-times, tab-separated
        let txt = "t_s\tdelta_deg\tr_degps\n2024-05-01T12:00:00Z\t1\t0\n\
                   2024-05-01T12:00:01Z\t1\t0\n2024-05-01T12:00:02Z\t1\t0\n\
                   2024-05-01T11:00:00Z\t1\t0\n2024-05-01T11:00:01Z\t1\t0\n";
        let s = split(txt).unwrap();
        assert_eq!(s.breaks.len(), 1);
        assert_eq!(
            (s.breaks[0].row, s.breaks[0].kind, s.breaks[0].step_s),
            (4, BreakKind::ClockBack, -3602.0)
        );
        // milliseconds
        let txt = "ms,delta_deg,r_degps\n0,1,0\n500,1,0\n1000,1,0\n2500,1,0\n";
        let s = split_at_gaps(txt, "x.csv".as_ref(), "ms", 1e-3).unwrap();
        assert_eq!((s.period_s, s.breaks.len()), (0.5, 1));
    }

    #[test]
    fn repeats_and_jitter_are_not_cuts_and_bad_times_are_named() {
        let txt = "t_s,delta_deg,r_degps\n0,1,0\n1.02,1,0\n1.98,1,0\n1.98,1,0\n3,1,0\n";
        assert!(split(txt).unwrap().breaks.is_empty());
        let e = split("t_s,delta_deg,r_degps\n0,1,0\n1,1,0\nx,1,0\n").unwrap_err();
        assert!(
            e.to_string().contains("row 3") && e.to_string().contains("`x`"),
            "{e}"
        );
        let e = split("t_s,delta_deg,r_degps\n2024-05-01T12:00:00Z,1,0\n5,1,0\n").unwrap_err();
        assert!(matches!(e, DataError::BadTime { row: 2, .. }), "{e}");
        let e = split("time,delta_deg\n0,1\n1,1\n").unwrap_err();
        assert!(matches!(e, DataError::MissingColumn { .. }), "{e}");
        let e = split("t_s,delta_deg\n0,1\n").unwrap_err();
        assert!(matches!(e, DataError::TooShort { found: 1, .. }), "{e}");
    }
}
