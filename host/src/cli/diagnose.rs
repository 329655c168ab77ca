//! `yawcast diagnose`: which physical effect is the model missing? Evidence for every library
//! effect on the trial records and on the reference records, a ranking and a verdict.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use yawcast::demo::FitSummary;
use yawcast::diagnose::{diagnose, DiagnoseConfig, Diagnosis, Ranked};
use yawcast::identify::model::Model;
use yawcast::io::data::Record;

use super::common::{bad, check_record_for_model, read_model, JsonArg, Outputs, ReadArgs, SeedArg};

/// Arguments of `yawcast diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// The model (`.postcard` blob with its `.json` twin beside it, or the `.json` twin).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// Trial records (CSV or NMEA); repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Reference records the model was identified from (the simulator's); repeatable.
    /// Without them the verdict is weaker.
    #[arg(long, value_name = "FILE")]
    pub reference: Vec<PathBuf>,
    /// Held-out trial records for the confirming refit; repeatable (default: the last part of
    /// each trial record is held out).
    #[arg(long, value_name = "FILE")]
    pub validate: Vec<PathBuf>,
    /// Bootstrap replicates per effect for the null distributions.
    #[arg(long, value_name = "N", default_value_t = super::common::NULL_REPS)]
    pub null_reps: usize,
    /// Significance level.
    #[arg(long, value_name = "P", default_value_t = 0.01)]
    pub alpha: f64,
    /// Skip the confirming refit (materiality then rests on the statistics alone).
    #[arg(long)]
    pub no_confirm: bool,
    /// Directory for SVG plots of the evidence and the before/after fits.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// The JSON summary of `diagnose` (stable field names).
#[derive(Debug, Serialize)]
pub struct DiagnoseSummary {
    /// Always "diagnose".
    pub command: &'static str,
    /// The seed used.
    pub seed: u64,
    /// Model file.
    pub model: String,
    /// Effect name or "none".
    pub verdict: String,
    /// The second effect of a ranked verdict (measured against the model with the first), or
    /// null.
    pub then: Option<String>,
    /// Every effect not already in the model, best first.
    pub ranking: Vec<Ranked>,
    /// Held-out fits of the model.
    pub before: FitSummary,
    /// Held-out fits with the verdict's effect.
    pub after: FitSummary,
    /// Whether reference records were used.
    pub reference_used: bool,
    /// The verdict in words.
    pub explanation: String,
    /// What qualifies the verdict, typed (`{"caveat": "no-reference"}`, …).
    pub caveats: Vec<yawcast::diagnose::Caveat>,
    /// The confirming refit's own explanation, when done.
    pub augment_explanation: Option<String>,
}

fn read_checked(args: &DiagnoseArgs, paths: &[PathBuf], model: &Model) -> Result<Vec<Record>> {
    let mut out = Vec::new();
    for p in paths {
        let rec = args.read.read(p)?;
        check_record_for_model(&rec, model, p)?;
        out.push(rec);
    }
    Ok(out)
}

/// Runs `diagnose`.
pub fn run(args: &DiagnoseArgs) -> Result<()> {
    let plots = args.out.as_ref().map(|d| {
        (
            d.join("diagnose_evidence.svg"),
            d.join("diagnose_before_after.svg"),
        )
    });
    let mut outputs = Outputs::check(&[
        plots.as_ref().map(|p| p.0.as_path()),
        plots.as_ref().map(|p| p.1.as_path()),
        args.json.json.as_deref(),
    ])?;
    let model = read_model(&args.model)?;
    let est = read_checked(args, &args.data, &model)?;
    let reference = read_checked(args, &args.reference, &model)?;
    let val = read_checked(args, &args.validate, &model)?;
    if args.null_reps == 0 {
        return Err(bad(
            "--null-reps 0: the null distributions need at least one replicate (default 40)",
        ));
    }
    if !(args.alpha > 0.0 && args.alpha < 1.0) {
        return Err(bad(format!("--alpha {} is not in (0, 1)", args.alpha)));
    }
    // the same records give the same verdict on every run (a borderline case cannot flip)
    let seed = args.seed.resolve_for(&[&reference, &est, &val]);
    let cfg = DiagnoseConfig {
        seed,
        null_reps: args.null_reps,
        alpha: args.alpha,
        confirm: !args.no_confirm,
        progress: true,
        ..DiagnoseConfig::default()
    };
    let d = diagnose(&model, &reference, &est, &val, &cfg).map_err(bad)?;
    print_report(&d);
    if let Some((evidence, fits)) = &plots {
        outputs.add(evidence, plot_evidence(&d, cfg.alpha)?.into_bytes());
        outputs.add(fits, plot_fits(&d)?.into_bytes());
    }
    outputs.json(
        &args.json,
        &DiagnoseSummary {
            command: "diagnose",
            seed,
            model: args.model.display().to_string(),
            verdict: d.verdict.clone(),
            then: d.then.clone(),
            ranking: d.ranking.clone(),
            before: FitSummary {
                fit: d.before.clone(),
            },
            after: FitSummary {
                fit: d.after.clone(),
            },
            reference_used: d.reference_used,
            explanation: d.explanation.clone(),
            caveats: d.caveats.clone(),
            augment_explanation: d.augment.as_ref().map(|a| a.explanation.clone()),
        },
    )?;
    outputs.commit()?;
    if let Some(dir) = &args.out {
        println!("plots written to {}", dir.display());
    }
    Ok(())
}

/// A held-out gain (pp) for the table: two decimals, or in exponent form when a refit that
/// diverged in simulation lost more than the column holds (`-6.1e38`, `-inf`).
fn pp(v: f64) -> String {
    if v.is_finite() && v.abs() < 1e5 {
        format!("{v:.2}")
    } else if v.is_finite() {
        format!("{v:.1e}")
    } else {
        v.to_string()
    }
}

/// Three significant digits: a resolution spans mm/s (a model's current) to degrees.
fn sig3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.digits$}")
}

fn print_report(d: &Diagnosis) {
    // ranked by the likelihood gain above noise; far-tail p-values are not compared
    // held-out gains: at the effect's own horizon ("gain pp"), then at 10 steps and in
    // simulation (what the ranking rule compares); "shows from": the smallest change of the
    // parameter the trials show at the level applied (`resolution`)
    println!(
        "{:<18} {:>12} {:>12} {:>10} {:>9} {:>7} {:>7} {:>4} {:>4} {:>10} {:>11}",
        "effect",
        "statistic",
        "above noise",
        "p",
        "gain pp",
        "10 pp",
        "sim pp",
        "sig",
        "mat",
        "parameter",
        "shows from"
    );
    for r in &d.ranking {
        println!(
            "{:<18} {:>12.1} {:>12.1} {:>10} {:>9} {:>7} {:>7} {:>4} {:>4} {:>10} {:>11}",
            r.effect,
            r.statistic,
            r.above_noise,
            if r.p_value < 1e-16 {
                "<1e-16".to_string()
            } else {
                format!("{:.2e}", r.p_value)
            },
            pp(r.fit_gain_pp),
            pp(r.fit_gain_10_pp),
            pp(r.fit_gain_sim_pp),
            if r.significant { "yes" } else { "no" },
            if r.material { "yes" } else { "no" },
            r.parameter.map_or("-".to_string(), |p| format!("{p:.3}")),
            r.resolution.map_or("-".to_string(), sig3)
        );
    }
    println!();
    for r in d.ranking.iter().filter(|r| r.significant) {
        println!("{}: {}", r.effect, r.evidence);
    }
    let keys = ["1", "5", "10", "20", "sim"];
    let row = |m: &BTreeMap<String, f64>| {
        keys.iter()
            .map(|k| m.get(*k).map_or("-".into(), |v| format!("{v:.2}")))
            .collect::<Vec<_>>()
            .join(" / ")
    };
    println!("held-out fit % (1/5/10/20/sim) before: {}", row(&d.before));
    println!("held-out fit % (1/5/10/20/sim) after:  {}", row(&d.after));
    match &d.then {
        Some(t) => println!("verdict: {}, then {t}", d.verdict),
        None => println!("verdict: {}", d.verdict),
    }
    println!("{}", d.explanation);
}

fn plot_err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing the plot: {e:?}")
}

/// Bar chart of −log10 p per effect, with the significance level.
fn plot_evidence(d: &Diagnosis, alpha: f64) -> Result<String> {
    use plotters::prelude::*;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let vals: Vec<f64> = d
            .ranking
            .iter()
            .map(|r| -(r.p_value.max(1e-300)).log10())
            .collect();
        let top = vals.iter().copied().fold(-alpha.log10(), f64::max) * 1.1;
        let n = vals.len().max(1);
        let mut chart = ChartBuilder::on(&root)
            .caption("evidence per effect (−log10 p)", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(60)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..n as f64, 0.0..top)
            .map_err(plot_err)?;
        let names: Vec<String> = d.ranking.iter().map(|r| r.effect.clone()).collect();
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| names.get(x.floor() as usize).cloned().unwrap_or_default())
            .y_desc("−log10 p")
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(vals.iter().enumerate().map(|(i, v)| {
                let c = if d.ranking[i].effect == d.verdict {
                    RED
                } else {
                    BLUE
                };
                Rectangle::new([(i as f64 + 0.15, 0.0), (i as f64 + 0.85, *v)], c.filled())
            }))
            .map_err(plot_err)?;
        let lvl = -alpha.log10();
        chart
            .draw_series(LineSeries::new(vec![(0.0, lvl), (n as f64, lvl)], BLACK))
            .map_err(plot_err)?
            .label(format!("α = {alpha}"));
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

/// Held-out fit per horizon before and after adding the verdict's effect.
fn plot_fits(d: &Diagnosis) -> Result<String> {
    use plotters::prelude::*;
    let keys = ["1", "5", "10", "20", "sim"];
    let get = |m: &BTreeMap<String, f64>, k: &str| m.get(k).copied().unwrap_or(0.0).max(-100.0);
    let lo = keys
        .iter()
        .flat_map(|k| [get(&d.before, k), get(&d.after, k)])
        .fold(0.0_f64, f64::min);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (640, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("held-out fit %, before / after ({})", d.verdict),
                ("sans-serif", 20),
            )
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..keys.len() as f64, lo..100.0)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_labels(keys.len())
            .x_label_formatter(&|x| keys.get(x.floor() as usize).unwrap_or(&"").to_string())
            .y_desc("fit %")
            .draw()
            .map_err(plot_err)?;
        for (i, k) in keys.iter().enumerate() {
            let x = i as f64;
            chart
                .draw_series([
                    Rectangle::new(
                        [(x + 0.1, lo), (x + 0.45, get(&d.before, k))],
                        BLUE.filled(),
                    ),
                    Rectangle::new([(x + 0.55, lo), (x + 0.9, get(&d.after, k))], RED.filled()),
                ])
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::pp;

    #[test]
    fn gains_beyond_the_column_are_printed_in_exponent_form() {
        assert_eq!(pp(7.514), "7.51");
        assert_eq!(pp(-0.004), "-0.00");
        assert_eq!(pp(-6.078e38), "-6.1e38");
        assert_eq!(pp(f64::NEG_INFINITY), "-inf");
    }
}
