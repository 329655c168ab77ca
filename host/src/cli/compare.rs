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
    read_track, JsonArg, Outputs, ReadArgs,
};
use yawcast::identify::track::evaluate;
use yawcast_shared::nav::TrackSpec;

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
    /// Heading fit % of ψ̂(t+k|t) keyed by step horizon, when the record logs a heading.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_fit: Option<BTreeMap<String, f64>>,
    /// The same from the yaw-rate prediction integrated alone (no gyro offset taken out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_fit_rate_only: Option<BTreeMap<String, f64>>,
    /// Median track error (m) keyed by horizon in seconds ("30", "60", "120"), when the
    /// model has a track part and the record logs navigation channels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track_error_m: Option<BTreeMap<String, f64>>,
    /// Navigation corrections skipped: not finite, and jumps beyond the gates.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nav_skipped: Option<NavSkipped>,
}

/// Skipped navigation corrections of one record.
#[derive(Debug, Serialize)]
pub struct NavSkipped {
    /// Ground velocities not finite.
    pub velocity_rejected: usize,
    /// Ground velocities beyond the gate.
    pub velocity_gated: usize,
    /// Position fixes not finite.
    pub fix_rejected: usize,
    /// Position fixes beyond the gate (jumps).
    pub fix_gated: usize,
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
    /// Mean heading fit over the records that log a heading, keyed by step horizon.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub mean_heading_fit: BTreeMap<String, f64>,
    /// Mean over records of the median track error (m), keyed by horizon in seconds.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub mean_track_error_m: BTreeMap<String, f64>,
}

/// Track error horizons (s).
const TRACK_SECS: [f64; 3] = [30.0, 60.0, 120.0];

/// Runs `compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    // Where the outputs go is checked first (the series' names follow the records).
    let series_dir = args.out.as_ref().map(|d| d.join("record.compare.csv"));
    let mut outputs = Outputs::check(&[series_dir.as_deref(), args.json.json.as_deref()])?;
    let model = read_model(&args.model)?;
    let track = read_track(&args.model, &model)?;
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
    let mut navs = Vec::new();
    for (rec, p) in records.iter().zip(&args.data) {
        navs.push(args.read.read_nav(p, rec)?);
    }
    let without = navs.iter().filter(|n| n.is_none()).count();
    if track.is_none() && without < navs.len() {
        eprintln!(
            "note: {}: the model has no heading/track part (identify it from records with \
             speed and course over ground): no track error",
            args.model.display()
        );
    } else if track.is_some() && without > 0 {
        eprintln!(
            "note: {without} record(s) without speed and course over ground or positions: no \
             track error for them"
        );
    }
    let steps: Vec<usize> = horizons
        .iter()
        .filter_map(|h| match h {
            Horizon::Steps(k) => Some(*k),
            Horizon::Sim => None,
        })
        .collect();
    for ((rec, path), nav) in records.iter().zip(&args.data).zip(&navs) {
        let (fit, cols) = fits(&model, rec, &horizons, path)?;
        series.push(cols);
        let mut r = RecordFit {
            name: rec.name.clone(),
            samples: rec.len(),
            fit,
            heading_fit: None,
            heading_fit_rate_only: None,
            track_error_m: None,
            nav_skipped: None,
        };
        if rec.psi.is_some() && !steps.is_empty() {
            // the heading part needs no track parameters; without a track part the default
            // one (no current) only carries the sample time
            let tr = match track {
                Some(t) => t,
                None => TrackSpec::new(model.ts as f32, 0.0, false).map_err(bad)?,
            };
            let nav = nav.as_ref().filter(|_| track.is_some());
            let secs: Vec<f64> = TRACK_SECS
                .iter()
                .copied()
                .filter(|s| s / rec.ts < rec.len() as f64)
                .collect();
            let e = evaluate(&model, &tr, rec, nav, &steps, &secs).map_err(bad)?;
            let keyed = |v: &[(usize, f64)]| v.iter().map(|(k, f)| (k.to_string(), *f)).collect();
            r.heading_fit = Some(keyed(&e.heading_fit));
            r.heading_fit_rate_only = Some(keyed(&e.heading_fit_rate_only));
            if nav.is_some() {
                r.track_error_m = Some(
                    e.track_error_m
                        .iter()
                        .filter_map(|(s, m)| m.map(|m| (format!("{s}"), m)))
                        .collect(),
                );
                r.nav_skipped = Some(NavSkipped {
                    velocity_rejected: e.velocity_counts[1],
                    velocity_gated: e.velocity_counts[2],
                    fix_rejected: e.fix_counts[1],
                    fix_gated: e.fix_counts[2],
                });
                let skipped =
                    e.velocity_counts[1] + e.velocity_counts[2] + e.fix_counts[1] + e.fix_counts[2];
                if skipped > 0 {
                    eprintln!(
                        "note: {}: {skipped} navigation correction(s) skipped (not finite, or a \
                         jump beyond the gates): {} velocity, {} fix",
                        path.display(),
                        e.velocity_counts[1] + e.velocity_counts[2],
                        e.fix_counts[1] + e.fix_counts[2]
                    );
                }
            }
        }
        out.push(r);
    }
    let mut mean_fit = BTreeMap::new();
    for h in &horizons {
        let k = h.key();
        let m = out.iter().map(|r| r.fit[&k]).sum::<f64>() / out.len() as f64;
        mean_fit.insert(k, m);
    }
    let mean_of = |get: &dyn Fn(&RecordFit) -> Option<&BTreeMap<String, f64>>| {
        let mut sums: BTreeMap<String, (f64, usize)> = BTreeMap::new();
        for r in &out {
            for (k, v) in get(r).into_iter().flatten() {
                let e = sums.entry(k.clone()).or_insert((0.0, 0));
                e.0 += v;
                e.1 += 1;
            }
        }
        sums.into_iter()
            .map(|(k, (s, n))| (k, s / n as f64))
            .collect::<BTreeMap<String, f64>>()
    };
    let mean_heading_fit = mean_of(&|r| r.heading_fit.as_ref());
    let mean_track_error_m = mean_of(&|r| r.track_error_m.as_ref());
    print_table(&horizons, &out, &mean_fit);
    if !mean_heading_fit.is_empty() {
        let s: Vec<String> = steps
            .iter()
            .filter_map(|k| {
                mean_heading_fit
                    .get(&k.to_string())
                    .map(|v| format!("{k}: {v:.2} %"))
            })
            .collect();
        println!("heading fit (mean): {}", s.join(", "));
    }
    if !mean_track_error_m.is_empty() {
        let s: Vec<String> = TRACK_SECS
            .iter()
            .filter_map(|k| {
                mean_track_error_m
                    .get(&format!("{k}"))
                    .map(|v| format!("{k} s: {v:.2} m"))
            })
            .collect();
        println!(
            "track error (mean of the records' medians): {}",
            s.join(", ")
        );
    }
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
            mean_heading_fit,
            mean_track_error_m,
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
