//! `yawcast resid`: residual tests of a model on records (MATLAB `resid`): the one-step
//! residuals' autocorrelation with its ±2.58/√N band and the Ljung–Box portmanteau p-value,
//! the residual–input cross-correlation with its band, the k-step error by regime and the
//! worst time windows; as a table, JSON and stem plots.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use yawcast::diagnose::resid::{resid, Correlation, ResidConfig, ResidReport};
use yawcast::io::report::svg::stem_chart;

use super::common::{bad, check_record_for_model, read_model, JsonArg, Outputs, ReadArgs};

/// Arguments of `yawcast resid`.
#[derive(Debug, Args)]
pub struct ResidArgs {
    /// The model (`.postcard` blob with its `.json` twin beside it, or the `.json` twin).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// Measured records (CSV or NMEA); repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Largest lag of the autocorrelation and cross-correlation (samples).
    #[arg(long, value_name = "LAGS", default_value_t = 25)]
    pub max_lag: usize,
    /// Horizon (steps) of the error by regime and of the worst windows.
    #[arg(long, value_name = "STEPS", default_value_t = 10)]
    pub horizon: usize,
    /// Directory for the plots (`acf.svg`, `ccf.svg`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Runs `resid`.
pub fn run(args: &ResidArgs) -> Result<()> {
    if args.max_lag == 0 || args.horizon == 0 {
        return Err(bad("--max-lag and --horizon must be at least 1"));
    }
    let (acf, ccf) = match &args.out {
        Some(d) => (Some(d.join("acf.svg")), Some(d.join("ccf.svg"))),
        None => (None, None),
    };
    let mut outputs = Outputs::check(&[acf.as_deref(), ccf.as_deref(), args.json.json.as_deref()])?;
    let model = read_model(&args.model)?;
    let mut records = Vec::new();
    for p in &args.data {
        let rec = args.read.read(p)?;
        check_record_for_model(&rec, &model, p)?;
        let needed = (2 * args.max_lag).max(4 * args.horizon);
        if rec.len() < needed {
            return Err(bad(format!(
                "{}: {} samples; --max-lag {} and --horizon {} need at least {needed}",
                p.display(),
                rec.len(),
                args.max_lag,
                args.horizon
            )));
        }
        records.push(rec);
    }
    let cfg = ResidConfig {
        max_lag: args.max_lag,
        horizon: args.horizon,
        ..ResidConfig::default()
    };
    let rep = resid(&model, &records, &cfg).map_err(bad)?;
    for (what, v) in [("residual RMS", rep.rms), ("k-step RMSE", rep.k_rmse)] {
        if !v.is_finite() {
            anyhow::bail!(
                "the model's {what} on these records is not finite: it does not describe them"
            );
        }
    }
    print_report(&rep);
    // Every output is made in memory first, then written together: all or none.
    if let (Some(acf), Some(ccf)) = (&acf, &ccf) {
        let stem = |c: &Correlation, title: &str| {
            let lags: Vec<f64> = c.lags.iter().map(|&l| l as f64).collect();
            stem_chart(title, "lag (samples)", &lags, &c.values, &[c.band]).into_bytes()
        };
        outputs.add(
            acf,
            stem(&rep.acf, "autocorrelation of the one-step residuals"),
        );
        outputs.add(
            ccf,
            stem(&rep.ccf, "cross-correlation of residuals and input"),
        );
    }
    outputs.json(&args.json, &rep)?;
    outputs.commit()?;
    if let Some(dir) = &args.out {
        println!("plots written to {}", dir.display());
    }
    Ok(())
}

fn lags_outside(c: &Correlation) -> String {
    if c.outside.is_empty() {
        "none".into()
    } else {
        c.outside
            .iter()
            .map(i64::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn print_report(rep: &ResidReport) {
    println!(
        "one-step residuals: {} samples, RMS {:.4} deg/s",
        rep.samples, rep.rms
    );
    println!(
        "autocorrelation, lags 1…{}: band ±{:.4}; outside at lags {}",
        rep.acf.lags.last().copied().unwrap_or(0),
        rep.acf.band,
        lags_outside(&rep.acf)
    );
    println!(
        "Ljung–Box: Q = {:.2}, {} degrees of freedom, p = {:.4}",
        rep.ljung_box.q, rep.ljung_box.df, rep.ljung_box.p_value
    );
    println!(
        "cross-correlation with the input, lags ±{}: band ±{:.4}; outside at lags {}",
        rep.ccf.lags.last().copied().unwrap_or(0),
        rep.ccf.band,
        lags_outside(&rep.ccf)
    );
    println!(
        "{}-step error by regime (RMSE {:.4} deg/s overall; ratio = bin RMSE / overall):",
        rep.horizon, rep.k_rmse
    );
    for g in &rep.regimes {
        let bins: Vec<String> = g
            .bins
            .iter()
            .map(|b| format!("{} {:.2}", b.label, b.ratio))
            .collect();
        println!("  {:<12} {}", g.dimension, bins.join(" · "));
    }
    for w in &rep.worst {
        println!(
            "  worst window {} {:.0}–{:.0} s: RMSE {:.4} ({:.1}× overall), {}",
            w.record, w.t_start, w.t_end, w.rmse, w.ratio, w.what
        );
    }
    println!(
        "{}: {}",
        if rep.white { "white" } else { "not white" },
        rep.summary
    );
}
