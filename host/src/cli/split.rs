//! `yawcast split`: record tables cut at their gaps and clock restarts into pieces the other
//! commands read whole (each piece keeps the header and its rows as written).

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use yawcast::io::data::{self, split_at_gaps, Break, BreakKind, Split};

use super::common::{bad, JsonArg, Outputs, ReadArgs, TimeUnit};

/// Arguments of `yawcast split`.
#[derive(Debug, Args)]
pub struct SplitArgs {
    /// Record tables (CSV: `,`, `;` or tab) to cut; repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Directory for the pieces: `NAME_1.csv`, `NAME_2.csv`, … of each `NAME.csv`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Pieces with fewer rows are left out (and listed).
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub min_samples: usize,
    /// CSV column holding time: seconds, ISO 8601 date-times or times of day.
    #[arg(long, value_name = "NAME", default_value = "t_s")]
    pub col_time: String,
    /// Unit of the CSV time column when it holds numbers.
    #[arg(long, value_enum, default_value = "s")]
    pub time_unit: TimeUnit,
    #[command(flatten)]
    pub json: JsonArg,
}

/// One piece in the `--json` summary.
#[derive(Debug, Serialize)]
struct PieceSummary {
    /// The file written, or `null` for a piece left out.
    file: Option<PathBuf>,
    first_row: usize,
    rows: usize,
    start_s: f64,
    duration_s: f64,
}

/// One table in the `--json` summary.
#[derive(Debug, Serialize)]
struct FileSummary {
    data: PathBuf,
    period_s: f64,
    breaks: Vec<Break>,
    pieces: Vec<PieceSummary>,
}

/// The `--json` summary.
#[derive(Debug, Serialize)]
struct Summary {
    min_samples: usize,
    files: Vec<FileSummary>,
}

/// Runs `split`.
pub fn run(args: &SplitArgs) -> Result<()> {
    if args.min_samples < 2 {
        return Err(bad(format!(
            "--min-samples {}: expected at least 2 (a record has 2 samples or more)",
            args.min_samples
        )));
    }
    let read = ReadArgs {
        col_time: args.col_time.clone(),
        time_unit: args.time_unit,
        ..ReadArgs::default()
    };
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let mut summary = Summary {
        min_samples: args.min_samples,
        files: Vec::new(),
    };
    for p in &args.data {
        let bytes =
            std::fs::read(p).map_err(|e| bad(format!("{}: cannot read: {e}", p.display())))?;
        let text = data::decode_text(&bytes);
        if read.is_nmea(p, &text) {
            return Err(bad(format!(
                "{}: an NMEA log; split cuts CSV tables (the NMEA reader bridges a hole up to \
                 --max-gap and names a longer one)",
                p.display()
            )));
        }
        let s = split_at_gaps(&text, p, &args.col_time, read.columns().time_scale)
            .map_err(|e| bad(e.to_string()))?;
        let (stem, ext) = name_parts(p);
        let dir = &args.out;
        let mut fs = FileSummary {
            data: p.clone(),
            period_s: s.period_s,
            breaks: s.breaks.clone(),
            pieces: Vec::new(),
        };
        let mut kept = 0usize;
        for (i, piece) in s.pieces.iter().enumerate() {
            let file = if piece.rows >= args.min_samples {
                kept += 1;
                let out = dir.join(format!("{stem}_{kept}.{ext}"));
                let body = s.piece_text(&text, i).ok_or_else(|| {
                    anyhow::anyhow!("{}: piece {} lies outside the text", p.display(), i + 1)
                })?;
                files.push((out.clone(), body.into_bytes()));
                Some(out)
            } else {
                None
            };
            fs.pieces.push(PieceSummary {
                file,
                first_row: piece.first_row,
                rows: piece.rows,
                start_s: piece.start_s,
                duration_s: piece.duration_s,
            });
        }
        print_file(p, &s, &fs, args.min_samples);
        if kept == 0 {
            return Err(bad(format!(
                "{}: no piece has --min-samples {} rows (the longest has {}); nothing written",
                p.display(),
                args.min_samples,
                s.pieces.iter().map(|q| q.rows).max().unwrap_or(0)
            )));
        }
        summary.files.push(fs);
    }
    let paths: Vec<Option<&Path>> = files
        .iter()
        .map(|(p, _)| Some(p.as_path()))
        .chain(std::iter::once(args.json.json.as_deref()))
        .collect();
    let mut outputs = Outputs::check(&paths)?;
    outputs.extend(files);
    outputs.json(&args.json, &summary)?;
    outputs.commit()
}

/// The stem and extension of a table's name (`csv` when it has none).
fn name_parts(p: &Path) -> (String, String) {
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "record".into());
    let ext = p
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "csv".into());
    (stem, ext)
}

fn print_file(p: &Path, s: &Split, fs: &FileSummary, min_samples: usize) {
    let cuts = match s.breaks.len() {
        0 => "no gap or clock restart".to_string(),
        1 => "1 cut".to_string(),
        n => format!("{n} cuts"),
    };
    println!("{}: period {} s, {cuts}", p.display(), s.period_s);
    for b in &s.breaks {
        let what = match b.kind {
            BreakKind::Gap => {
                let missing = (b.step_s / s.period_s).round() - 1.0;
                format!(
                    "a gap of {:.3} s ({missing:.0} sample{} missing)",
                    b.step_s,
                    if missing == 1.0 { "" } else { "s" }
                )
            }
            BreakKind::ClockBack => format!("the clock goes back {:.3} s", -b.step_s),
        };
        println!("  before row {}: {what}", b.row);
    }
    for q in &fs.pieces {
        let rows = format!(
            "rows {}–{} ({} samples, {:.3}–{:.3} s)",
            q.first_row,
            q.first_row + q.rows - 1,
            q.rows,
            q.start_s,
            q.start_s + q.duration_s
        );
        match &q.file {
            Some(f) => println!("  {}: {rows}", f.display()),
            None => println!("  left out: {rows}, fewer than --min-samples {min_samples}"),
        }
    }
}
