//! `yawcast compare`: fit % per record and horizon, measured vs predicted series.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use std::collections::BTreeMap;
use yawcast::identify::model::Model;
use yawcast::identify::predict::{self, Horizon};
use yawcast::io::data::Record;

use super::common::{
    bad, check_fit, check_horizons_fit, check_record_for_model, parse_horizons, read_model,
    JsonArg, Outputs, ReadArgs,
};

/// The horizons compared when `--horizons` is not given (those not shorter than a record are
/// left out with a note; horizons given explicitly must fit every record).
const DEFAULT_HORIZONS: &str = "1,5,10,20,sim";

/// Arguments of `yawcast compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The model (`.postcard` blob with its `.json` twin beside it, or the `.json` twin).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// Measured records (CSV or NMEA); repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Horizons: whole numbers of steps and/or `sim` (pure simulation).
    #[arg(long, value_name = "LIST", default_value = DEFAULT_HORIZONS)]
    pub horizons: String,
    /// Directory for the measured-vs-predicted series (one CSV per record).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// One record's result.
#[derive(Debug, Serialize)]
pub struct RecordFit {
    /// Record name (file stem).
    pub name: String,
    /// Samples.
    pub samples: usize,
    /// Fit % keyed by horizon ("1", "5", …, "sim").
    pub fit: BTreeMap<String, f64>,
}

/// The JSON summary of `compare`.
#[derive(Debug, Serialize)]
pub struct CompareSummary {
    /// Always "compare".
    pub command: &'static str,
    /// Model file.
    pub model: String,
    /// Horizons, as keys.
    pub horizons: Vec<String>,
    /// Per-record fits.
    pub records: Vec<RecordFit>,
    /// Mean fit over records, keyed by horizon.
    pub mean_fit: BTreeMap<String, f64>,
}

/// Runs `compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    // Where the outputs go is checked first (the series' names follow the records).
    let series_dir = args.out.as_ref().map(|d| d.join("record.compare.csv"));
    let mut outputs = Outputs::check(&[series_dir.as_deref(), args.json.json.as_deref()])?;
    let model = read_model(&args.model)?;
    let horizons = parse_horizons(&args.horizons)?;
    let mut records = Vec::new();
    for p in &args.data {
        let rec = args.read.read(p)?;
        check_record_for_model(&rec, &model, p)?;
        records.push(rec);
    }
    if args.out.is_some() {
        // One series file per record, named after it: two records of one name would share it.
        for (i, (r, p)) in records.iter().zip(&args.data).enumerate() {
            if let Some(q) = records[..i]
                .iter()
                .zip(&args.data)
                .find_map(|(o, q)| (o.name == r.name).then_some(q))
            {
                return Err(bad(format!(
                    "{} and {}: both records are named `{}`, so their series would go to one \
                     file {}.compare.csv under --out; rename one",
                    q.display(),
                    p.display(),
                    r.name,
                    r.name
                )));
            }
        }
    }
    let horizons = if args.horizons == DEFAULT_HORIZONS {
        // The default horizons shrink to what short records can hold, with a word.
        let shortest = records.iter().map(|r| r.len()).min().unwrap_or(0);
        let (keep, drop): (Vec<Horizon>, Vec<Horizon>) = horizons
            .into_iter()
            .partition(|h| !matches!(h, Horizon::Steps(k) if *k >= shortest));
        if !drop.is_empty() {
            let keys: Vec<String> = drop.iter().map(Horizon::key).collect();
            eprintln!(
                "note: horizon(s) {} left out: not shorter than the shortest record ({shortest} samples)",
                keys.join(", ")
            );
        }
        keep
    } else {
        check_horizons_fit(&horizons, &records, &args.data)?;
        horizons
    };
    let mut out = Vec::new();
    let mut series = Vec::new();
    for (rec, path) in records.iter().zip(&args.data) {
        let (fit, cols) = fits(&model, rec, &horizons, path)?;
        series.push(cols);
        out.push(RecordFit {
            name: rec.name.clone(),
            samples: rec.len(),
            fit,
        });
    }
    let mut mean_fit = BTreeMap::new();
    for h in &horizons {
        let k = h.key();
        let m = out.iter().map(|r| r.fit[&k]).sum::<f64>() / out.len() as f64;
        mean_fit.insert(k, m);
    }
    print_table(&horizons, &out, &mean_fit);
    // Every output is made in memory, then written together: all of them or none.
    if let Some(dir) = &args.out {
        for (rec, cols) in records.iter().zip(&series) {
            let mut s = String::from("t_s,delta_deg,r_degps");
            for (h, _) in cols {
                s.push_str(&format!(",rhat_{}_degps", h.key()));
            }
            s.push('\n');
            for i in 0..rec.len() {
                s.push_str(&format!("{},{},{}", rec.t[i], rec.u[i], rec.y[i]));
                for (_, y) in cols {
                    s.push_str(&format!(",{}", y[i]));
                }
                s.push('\n');
            }
            outputs.add(
                &dir.join(format!("{}.compare.csv", rec.name)),
                s.into_bytes(),
            );
        }
    }
    outputs.json(
        &args.json,
        &CompareSummary {
            command: "compare",
            model: args.model.display().to_string(),
            horizons: horizons.iter().map(Horizon::key).collect(),
            records: out,
            mean_fit,
        },
    )?;
    outputs.commit()?;
    if let Some(dir) = &args.out {
        println!("series written to {}", dir.display());
    }
    Ok(())
}

/// Predicted series per horizon.
type Series = Vec<(Horizon, Vec<f64>)>;

/// Fit % of `model` on `rec` at every horizon (x̂(0) estimated from the record), with the
/// predicted series; a fit that is not finite or shows a diverging prediction is an error
/// naming the record and horizon (exit 1), never a result.
pub fn fits(
    model: &Model,
    rec: &Record,
    horizons: &[Horizon],
    path: &Path,
) -> Result<(BTreeMap<String, f64>, Series)> {
    let x0 = predict::estimate_x0(model, rec);
    let mut fit = BTreeMap::new();
    let mut cols = Vec::new();
    for &h in horizons {
        let yhat = predict::predict(model, rec, &x0, h);
        let f = predict::fit(&rec.y, &yhat);
        check_fit(f, &h.key(), path)?;
        fit.insert(h.key(), f);
        cols.push((h, yhat));
    }
    Ok((fit, cols))
}

fn print_table(horizons: &[Horizon], rows: &[RecordFit], mean: &BTreeMap<String, f64>) {
    let name_w = rows.iter().map(|r| r.name.len()).max().unwrap_or(6).max(6);
    print!("{:<name_w$}", "record");
    for h in horizons {
        print!(" {:>8}", format!("fit@{}", h.key()));
    }
    println!();
    for r in rows {
        print!("{:<name_w$}", r.name);
        for h in horizons {
            print!(" {:>8.2}", r.fit[&h.key()]);
        }
        println!();
    }
    print!("{:<name_w$}", "mean");
    for h in horizons {
        print!(" {:>8.2}", mean[&h.key()]);
    }
    println!();
}
