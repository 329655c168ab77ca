//! `yawcast identify`, `tune`, `average` and `export`: the paper's pipeline on the command line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use yawcast::identify::model::Model;
use yawcast::identify::{merge, pem, predict};
use yawcast::io::data::Record;
use yawcast::{io::export, tune::ga, tune::tables};

use super::common::{bad, read_model, JsonArg, Outputs, ReadArgs, SeedArg};

/// Reads every path of a repeatable option, naming the option when none was given.
fn read_records(read: &ReadArgs, paths: &[PathBuf], option: &str) -> Result<Vec<Record>> {
    if paths.is_empty() {
        return Err(bad(format!("no {option} FILE given")));
    }
    paths
        .iter()
        .map(|p| read.read(p))
        .collect::<Result<Vec<_>>>()
}

/// The files of a repeatable option, for messages: `a.csv, b.csv`.
fn names(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Adds `model` with its heading/track part (when it has one: a format 3 blob and the twin's
/// `track`) as `<out>.postcard` + `<out>.json` to `outputs`, checked through the firmware on
/// `check` (also `augment`'s).
pub(super) fn add_model(
    outputs: &mut Outputs,
    model: &Model,
    track: Option<yawcast_shared::nav::TrackSpec>,
    out: &Path,
    check: &Record,
) -> Result<export::ExportReport> {
    let cfg = export::ExportConfig {
        track,
        ..export::ExportConfig::default()
    };
    let (report, files) = export::prepare_with(model, out, check, &cfg)
        .with_context(|| format!("exporting the model {}", out.display()))?;
    outputs.extend(files);
    Ok(report)
}

/// The heading/track part fitted on the identification records when every one of them logs
/// a heading and a ground velocity (speed and course over ground); `None` with a note
/// otherwise (the track is then not predicted, never guessed).
pub(super) fn track_from_records(
    read: &super::common::ReadArgs,
    model: &Model,
    recs: &[Record],
    paths: &[PathBuf],
    current: bool,
) -> Result<Option<yawcast_shared::nav::TrackSpec>> {
    let mut navs = Vec::new();
    for (r, p) in recs.iter().zip(paths) {
        match read.read_nav(p, r)? {
            Some(n) if n.has_velocity() && r.psi.is_some() => navs.push(n),
            _ => {
                eprintln!(
                    "note: {}: no heading with speed and course over ground: the model gets no \
                     heading/track part",
                    p.display()
                );
                return Ok(None);
            }
        }
    }
    let pairs: Vec<(&Record, &yawcast::io::nav::Nav)> = recs.iter().zip(&navs).collect();
    let t =
        yawcast::identify::track::fit_track(model.ts, model.d_y(), &pairs, current).map_err(bad)?;
    println!(
        "track part: speed {:.3} m/s, speed loss {:.4} (m/s)/(deg/s)², sway {:.4} (m/s)/(deg/s){}",
        t.speed,
        t.speed_loss,
        t.sway,
        if current { ", current estimated" } else { "" }
    );
    Ok(Some(t))
}

/// The paths of `<out>.postcard` and `<out>.json`, when `--out` was given.
fn model_paths(out: Option<&Path>) -> [Option<PathBuf>; 2] {
    match out.map(export::paths) {
        Some((b, j)) => [Some(b), Some(j)],
        None => [None, None],
    }
}

/// Refuses a `--json` path that is the model's own JSON twin (`--out` would be overwritten).
fn check_json_vs_out(out: Option<&Path>, json: &JsonArg) -> Result<()> {
    if let (Some(out), Some(j)) = (out, &json.json) {
        let (_, twin) = export::paths(out);
        if &twin == j {
            return Err(bad(format!(
                "--json {} is the JSON twin of the model written by --out; choose another name",
                j.display()
            )));
        }
    }
    Ok(())
}

fn print_params(names: &[String], theta: &[f64], std_pct: &[f64]) {
    println!("{:<22} {:>14} {:>9}", "parameter", "value", "STD %");
    for (i, n) in names.iter().enumerate() {
        let v = theta.get(i).copied().unwrap_or(f64::NAN);
        let s = std_pct.get(i).copied().unwrap_or(f64::NAN);
        let flag = if s > 50.0 {
            "  unusable"
        } else if s > 10.0 {
            "  unreliable"
        } else {
            ""
        };
        println!("{n:<22} {v:>14.6} {s:>9.2}{flag}");
    }
}

fn all_params(m: &Model) -> Vec<f64> {
    let mut v = m.theta();
    v.extend(m.effect_gains());
    v
}

fn parse_orders(s: &str) -> Result<Vec<usize>> {
    let err = || {
        bad(format!(
            "--orders `{s}`: expected a range like 2..6 or a list like 2,4,6"
        ))
    };
    let v: Vec<usize> = if let Some((a, b)) = s.split_once("..") {
        let a: usize = a.trim().parse().map_err(|_| err())?;
        let b: usize = b
            .trim_start_matches('=')
            .trim()
            .parse()
            .map_err(|_| err())?;
        (a..=b).collect()
    } else {
        s.split(',')
            .map(|x| x.trim().parse().map_err(|_| err()))
            .collect::<Result<_>>()?
    };
    if v.is_empty() || v.iter().any(|n| !(2..=8).contains(n)) {
        return Err(bad(format!("--orders `{s}`: orders must lie in 2..=8")));
    }
    Ok(v)
}

/// Arguments of `yawcast identify`.
#[derive(Debug, Args)]
pub struct IdentifyArgs {
    /// Records to identify from (CSV or NMEA); repeatable (one multi-record identification).
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Records to validate on (fit per horizon); repeatable.
    #[arg(long, value_name = "FILE")]
    pub validate: Vec<PathBuf>,
    /// Model order n.
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub order: usize,
    /// Order selection instead: identify each order (e.g. `2..6`) and report fit, AIC, BIC.
    #[arg(long, value_name = "RANGE")]
    pub orders: Option<String>,
    /// Regularisation weight λ (0: plain PEM); R is the identity.
    #[arg(long, default_value_t = 0.0, value_name = "LAMBDA")]
    pub lambda: f64,
    /// Refine the PEM optimum to minimise K-step prediction errors (MATLAB's Focus) — for a
    /// predictor used K steps ahead when the model structure is not exact. A list
    /// (`1,2,5,10,20`) minimises the mean over the horizons of each one's error relative to
    /// the start's. STD%, AIC and BIC stay those of the one-step optimum it starts from.
    #[arg(long, value_name = "K[,K…]", value_delimiter = ',')]
    pub focus: Vec<usize>,
    /// Where the model goes: `<PATH>.postcard` and its `<PATH>.json` twin.
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// The JSON summary of `identify`.
#[derive(Debug, Serialize)]
pub struct IdentifySummary {
    /// Always "identify".
    pub command: &'static str,
    /// Order.
    pub order: usize,
    /// λ.
    pub lambda: f64,
    /// Parameter names.
    pub names: Vec<String>,
    /// Values, in `names` order.
    pub values: Vec<f64>,
    /// STD% per parameter.
    pub std_pct: Vec<f64>,
    /// The paper's verdict: reliable, unreliable or unusable.
    pub reliability: pem::Reliability,
    /// AIC.
    pub aic: f64,
    /// BIC.
    pub bic: f64,
    /// LM iterations.
    pub iterations: usize,
    /// One-step fit % per identification record.
    pub fit_identification: Vec<f64>,
    /// How many times over the 10-step prediction carries white noise on the yaw rate.
    pub noise_gain_10: f64,
    /// Mean fit % on the validation records per horizon (empty without --validate).
    pub fit: BTreeMap<String, f64>,
    /// Model files written.
    pub model: Option<String>,
    /// Wall-clock seconds of the identification itself (reading and writing excluded).
    pub identify_s: f64,
    /// The longest horizon of `--focus` (null: plain one-step PEM).
    pub focus: Option<usize>,
    /// Every horizon of `--focus`, ascending (empty: plain one-step PEM).
    pub focus_horizons: Vec<usize>,
    /// The start whose minimum was taken (`arx`, `armax`, `subspace`, `template`).
    pub start: pem::Start,
    /// Set when that minimum is not the lowest-cost one: the test that chose it.
    pub start_choice: Option<pem::choose::StartChoice>,
    /// Set when the records carry a steady offset the plain structure has no term for (held
    /// by a pole on the unit circle, left in the mean of its one-step errors, or shown by
    /// the heading): the offset effect added (`effect`, `value`, `radius_without`,
    /// `radius_with`, `reason`, `delta_bic`, `heading_gyro_bias`).
    pub offset: Option<pem::offset::OffsetChoice>,
}

/// Runs `identify`.
///
/// Long: the subcommand's steps in the order its outputs are written (read, identify, offset,
/// focus, report, write), each a few lines.
pub fn identify(args: &IdentifyArgs) -> Result<()> {
    check_json_vs_out(args.out.as_deref(), &args.json)?;
    let [blob, twin] = model_paths(args.out.as_deref());
    let mut outputs =
        Outputs::check(&[blob.as_deref(), twin.as_deref(), args.json.json.as_deref()])?;
    if !(args.lambda.is_finite() && args.lambda >= 0.0) {
        return Err(bad(format!(
            "--lambda {}: expected a finite number ≥ 0",
            args.lambda
        )));
    }
    let recs = read_records(&args.read, &args.data, "--data")?;
    let from = || format!("identifying from {}", names(&args.data));
    let val = args.read.read_all(&args.validate)?;
    let cfg = pem::PemConfig {
        order: args.order,
        lambda: args.lambda,
        ..pem::PemConfig::default()
    };
    if args.focus.contains(&0) {
        return Err(bad("--focus: every horizon must be a whole number ≥ 1"));
    }
    let mut horizons = args.focus.clone();
    horizons.sort_unstable();
    horizons.dedup();
    if let Some(&k) = horizons.last() {
        // The focus criterion needs k-step errors over most of every record.
        for (r, p) in recs.iter().zip(&args.data) {
            if 4 * k > r.len() {
                return Err(bad(format!(
                    "{}: --focus {k} needs records of at least {} samples (4 × the horizon); this one has {}",
                    p.display(),
                    4 * k,
                    r.len()
                )));
            }
        }
    }
    if let Some(o) = &args.orders {
        if !horizons.is_empty() {
            return Err(bad(
                "--focus refines one model; it does not go with --orders",
            ));
        }
        let orders = parse_orders(o)?;
        let lines = pem::select_order(&recs, &orders, &cfg)
            .map_err(input_ident)
            .with_context(from)?;
        println!(
            "{:>5} {:>6} {:>12} {:>12} {:>12} {:>8} {:>8} {:>8} {:>8} {:>10}",
            "order",
            "params",
            "cost",
            "AIC",
            "BIC",
            "fit@1",
            "fit@5",
            "fit@10",
            "fit@sim",
            "max STD%"
        );
        for l in &lines {
            let f = |k: &str| l.fit.get(k).copied().unwrap_or(f64::NAN);
            println!(
                "{:>5} {:>6} {:>12.5e} {:>12.1} {:>12.1} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>10.1}{}",
                l.order,
                l.params,
                l.cost,
                l.aic,
                l.bic,
                f("1"),
                f("5"),
                f("10"),
                f("sim"),
                l.max_std_pct,
                l.error.as_deref().map(|e| format!("  failed: {e}")).unwrap_or_default()
            );
        }
        if let Some(best) = lines
            .iter()
            .filter(|l| l.error.is_none() && l.bic.is_finite())
            .min_by(|a, b| a.bic.total_cmp(&b.bic))
        {
            println!("lowest BIC: order {}", best.order);
        }
        outputs.json(
            &args.json,
            &serde_json::json!({
                "command": "identify",
                "orders": lines,
            }),
        )?;
        return outputs.commit();
    }
    let started = std::time::Instant::now();
    let (rep, offset) = pem::offset::identify(&recs, &cfg)
        .map_err(input_ident)
        .with_context(from)?;
    let model = if horizons.iter().any(|k| *k > 1) {
        let fc = pem::focus::FocusConfig {
            horizons: horizons.clone(),
            ..Default::default()
        };
        let f = pem::focus::refine(&recs, &rep.model, &fc)
            .map_err(input_ident)
            .with_context(from)?;
        let per: Vec<String> = f
            .horizons
            .iter()
            .zip(f.mse_before.iter().zip(&f.mse))
            .map(|(k, (a, b))| format!("{k}: {a:.4e} → {b:.4e}"))
            .collect();
        let ks: Vec<String> = f.horizons.iter().map(usize::to_string).collect();
        println!(
            "focus on {}-step errors: mean square {} after {} steps",
            ks.join(","),
            per.join(", "),
            f.iterations
        );
        f.model
    } else {
        rep.model.clone()
    };
    let identify_s = started.elapsed().as_secs_f64();
    println!(
        "identified order {} on {} record(s), {} samples: {} after {} iterations; paper's rule: {:?}",
        rep.model.n,
        recs.len(),
        rep.samples,
        rep.termination.describe(),
        rep.iterations,
        rep.reliability
    );
    if let Some(c) = &rep.choice {
        println!("{}", c.describe(rep.start));
    }
    if let Some(o) = &offset {
        println!("{}", o.describe());
    }
    print_params(&rep.names, &all_params(&model), &rep.std_pct);
    let noise_gain_10 = predict::noise_gain(&model, 10);
    println!("{}", predict::noise_gain_words(noise_gain_10));
    let fit = if val.is_empty() {
        BTreeMap::new()
    } else {
        merge::validation_fits(&model, &val)
    };
    if !fit.is_empty() {
        let s: Vec<String> = predict::Horizon::REPORT
            .iter()
            .filter_map(|h| fit.get(&h.key()).map(|v| format!("{}: {v:.2} %", h.key())))
            .collect();
        println!(
            "validation fit (mean over {} records): {}",
            val.len(),
            s.join(", ")
        );
    }
    let mut written = None;
    let mut done = None;
    if let Some(out) = &args.out {
        let check = val.first().unwrap_or(&recs[0]);
        let track = track_from_records(&args.read, &model, &recs, &args.data, false)?;
        let r = add_model(&mut outputs, &model, track, out, check)?;
        done = Some(format!(
            "model written to {} and {}",
            r.blob_path.display(),
            r.json_path.display()
        ));
        written = Some(r.blob_path.display().to_string());
    }
    outputs.json(
        &args.json,
        &IdentifySummary {
            command: "identify",
            order: rep.model.n,
            lambda: rep.lambda,
            names: rep.names.clone(),
            values: all_params(&model),
            std_pct: rep.std_pct.clone(),
            reliability: rep.reliability,
            aic: rep.aic,
            bic: rep.bic,
            iterations: rep.iterations,
            fit_identification: rep.fit.clone(),
            noise_gain_10,
            fit,
            model: written,
            identify_s,
            focus: horizons.last().copied(),
            focus_horizons: horizons,
            start: rep.start,
            start_choice: rep.choice.clone(),
            offset,
        },
    )?;
    outputs.commit()?;
    if let Some(d) = done {
        println!("{d}");
    }
    Ok(())
}

/// Identification errors caused by the data are bad input; a search that found no stable
/// model is a failure.
fn input_ident(e: pem::IdentError) -> anyhow::Error {
    if e.is_bad_input() {
        bad(e.to_string())
    } else {
        anyhow::Error::new(e)
    }
}

/// Gene layout of the GA.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Genes {
    /// R_a, R_b, R_k (and effect gains) and λ: the paper's groups.
    Grouped,
    /// One R_i per parameter, and λ.
    PerParameter,
}

/// Centre θ₀ of the GA's penalty λ (θ − θ₀)ᵀ R (θ − θ₀).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Centre {
    /// θ₀ = 0 (the paper).
    Zero,
    /// θ₀ = the model identified on all `--data` records together (the simulator's prior).
    Simulation,
    /// Both: one GA run around each, and the run that predicts the trials best wins.
    Both,
}

/// Arguments of `yawcast tune`.
#[derive(Debug, Args)]
pub struct TuneArgs {
    /// Simulation records to identify from; repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Trial records the fitness is scored on; repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub validate: Vec<PathBuf>,
    /// Model order n.
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub order: usize,
    /// Gene layout.
    #[arg(long, value_enum, default_value = "grouped")]
    pub genes: Genes,
    /// Centre of the penalty λ (θ − θ₀)ᵀ R (θ − θ₀).
    #[arg(long, value_enum, default_value = "both")]
    pub centre: Centre,
    /// Decode genes on a log scale (the paper: linear).
    #[arg(long)]
    pub log_scale: bool,
    /// One multi-record identification instead of averaging per-record models.
    #[arg(long)]
    pub joint: bool,
    /// Generation cap.
    #[arg(long, default_value_t = 50, value_name = "N")]
    pub generations: usize,
    /// Fitness horizons (mean k-step fit over them).
    #[arg(long, default_value = "5,10", value_name = "LIST")]
    pub horizons: String,
    /// Where the tuned model goes (`<PATH>.postcard`, `.json`, and the paper's tables as
    /// `<PATH>.tables.md`/`.tables.json`).
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Runs `tune`.
///
/// Long: the subcommand's steps in the order its outputs are written, each a few lines.
pub fn tune(args: &TuneArgs) -> Result<()> {
    check_json_vs_out(args.out.as_deref(), &args.json)?;
    let [blob, twin] = model_paths(args.out.as_deref());
    let (md, tj) = match args.out.as_deref().map(tables::Tables::paths) {
        Some((m, t)) => (Some(m), Some(t)),
        None => (None, None),
    };
    let mut outputs = Outputs::check(&[
        blob.as_deref(),
        twin.as_deref(),
        md.as_deref(),
        tj.as_deref(),
        args.json.json.as_deref(),
    ])?;
    if args.generations == 0 {
        return Err(bad("--generations 0: at least one generation is needed"));
    }
    let sim = read_records(&args.read, &args.data, "--data")?;
    let trials = read_records(&args.read, &args.validate, "--validate")?;
    let horizons: Vec<usize> = args
        .horizons
        .split(',')
        .map(|h| {
            h.trim()
                .parse::<usize>()
                .ok()
                .filter(|k| *k >= 1)
                .ok_or_else(|| bad(format!("--horizons: `{h}` is not a whole number ≥ 1")))
        })
        .collect::<Result<_>>()?;
    // Every record checked before the GA starts, not found wanting after it.
    let kmax = horizons.iter().copied().max().unwrap_or(1);
    let ts = sim[0].ts;
    for (r, p) in sim
        .iter()
        .zip(&args.data)
        .chain(trials.iter().zip(&args.validate))
    {
        if (r.ts - ts).abs() > 1e-6 * ts {
            return Err(bad(format!(
                "{}: sampled every {} s, {} every {ts} s; resample one of them (--resample)",
                p.display(),
                r.ts,
                args.data[0].display()
            )));
        }
    }
    for (r, p) in trials.iter().zip(&args.validate) {
        let needed = (4 * kmax).max(4 * args.order + 2);
        if r.len() < needed {
            return Err(bad(format!(
                "{}: {} samples; scoring the {kmax}-step fit of an order-{} model needs at least {needed}",
                p.display(),
                r.len(),
                args.order
            )));
        }
    }
    let seed = args.seed.resolve_for(&[&sim, &trials]);
    let mut cfg = ga::GaConfig {
        seed,
        max_generations: args.generations,
        horizons,
        log_scale: args.log_scale,
        grouped: args.genes == Genes::Grouped,
        combine: if args.joint {
            ga::Combine::Joint
        } else {
            ga::Combine::Average
        },
        pem: pem::PemConfig {
            order: args.order,
            ..ga::GaConfig::default().pem
        },
        ..ga::GaConfig::default()
    };
    let base_cfg = pem::PemConfig {
        order: args.order,
        ..pem::PemConfig::default()
    };
    let base = pem::identify(&sim[..1], None, &base_cfg)
        .map_err(input_ident)
        .context("the starting model")?
        .model;
    if args.centre != Centre::Zero {
        let all = pem::identify(&sim, None, &base_cfg)
            .map_err(input_ident)
            .context("the model of all --data records (the penalty centre)")?
            .model;
        cfg.centres = match args.centre {
            Centre::Simulation => vec![Some(all.theta())],
            _ => vec![None, Some(all.theta())],
        };
    }
    let centre_name = |i: usize| match (args.centre, i) {
        (Centre::Zero, _) | (Centre::Both, 0) => "zero",
        _ => "simulation",
    };
    let rep = ga::tune(&sim, &trials, &base, &cfg).map_err(|e| match e {
        ga::GaError::NoSimulation
        | ga::GaError::NoTrials
        | ga::GaError::Config(_)
        | ga::GaError::Trial { .. } => bad(e),
        other => anyhow::Error::new(other),
    })?;
    println!(
        "GA: {} generations ({:?}), {} candidates, {} rejected; seed {}",
        rep.generations, rep.termination, rep.evaluations, rep.rejected, rep.seed
    );
    println!(
        "λ = {:.4}, penalty centre {}, best fitness {:.3} %",
        rep.lambda,
        centre_name(rep.centre),
        rep.best_fit
    );
    if let Some(g) = &rep.gain {
        println!(
            "gain over the conventional model on the {} tuning records: {:+.3} ± {:.3} pp (mean ± standard error); {}",
            g.records,
            g.mean,
            g.se,
            if g.tuned_kept {
                "the tuned model is kept"
            } else {
                "not above twice its standard error: the conventional model is kept"
            }
        );
    }
    let tables = tables::Tables::from_ga(&rep, &trials).ok();
    if let Some(t) = &tables {
        println!("{}", t.to_markdown());
    }
    let mut done = Vec::new();
    if let Some(out) = &args.out {
        // the ship's heading/track part, from the trials (the ship's own records)
        let track =
            track_from_records(&args.read, &rep.best_model, &trials, &args.validate, false)?;
        let r = add_model(&mut outputs, &rep.best_model, track, out, &trials[0])?;
        let which = match &rep.gain {
            Some(g) if !g.tuned_kept => "conventional",
            _ => "tuned",
        };
        done.push(format!(
            "{which} model written to {} and {}",
            r.blob_path.display(),
            r.json_path.display()
        ));
        if let Some(t) = &tables {
            outputs.extend(t.files(out));
            let (md, js) = tables::Tables::paths(out);
            done.push(format!(
                "tables written to {} and {}",
                md.display(),
                js.display()
            ));
        }
    }
    outputs.json(&args.json, &serde_json::json!({
        "command": "tune",
        "seed": rep.seed,
        "lambda": rep.lambda,
        "r": rep.r,
        "centre": centre_name(rep.centre),
        "best_fit": rep.best_fit,
        "generations": rep.generations,
        "termination": rep.termination,
        "tuned": { "fit": rep.tuned.fits, "std_pct": rep.tuned.std_pct },
        "conventional": rep.conventional.as_ref().map(|c| serde_json::json!({ "fit": c.fits, "std_pct": c.std_pct })),
        "history": rep.history,
        "gain": rep.gain,
    }))?;
    outputs.commit()?;
    for d in done {
        println!("{d}");
    }
    Ok(())
}

/// Which combination `average` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// The one that validates best.
    Best,
    /// Plain parameter average (the paper).
    Average,
    /// Covariance-weighted merge with a χ² consistency test.
    Merge,
    /// One multi-record identification.
    Multi,
}

/// Arguments of `yawcast average`.
#[derive(Debug, Args)]
pub struct AverageArgs {
    /// Records, one model each (and all together for `multi`); repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Validation records the combinations are compared on; repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub validate: Vec<PathBuf>,
    /// Model order n.
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub order: usize,
    /// Which combination to write.
    #[arg(long, value_enum, default_value = "best")]
    pub method: Method,
    /// Where the chosen model goes (`<PATH>.postcard` and `.json`).
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Runs `average`.
pub fn average(args: &AverageArgs) -> Result<()> {
    check_json_vs_out(args.out.as_deref(), &args.json)?;
    let [blob, twin] = model_paths(args.out.as_deref());
    let mut outputs =
        Outputs::check(&[blob.as_deref(), twin.as_deref(), args.json.json.as_deref()])?;
    let recs = read_records(&args.read, &args.data, "--data")?;
    let val = read_records(&args.read, &args.validate, "--validate")?;
    let cfg = pem::PemConfig {
        order: args.order,
        ..pem::PemConfig::default()
    };
    let rep = merge::compare(&recs, &val, None, &cfg).map_err(|e| match e {
        merge::MergeError::Identification { .. }
        | merge::MergeError::NoValidation
        | merge::MergeError::CommandSign { .. }
        | merge::MergeError::CommandUnit { .. } => bad(e),
        other => anyhow::Error::new(other),
    })?;
    println!(
        "{:<8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7}  note",
        "method", "fit@1", "fit@5", "fit@10", "fit@20", "fit@sim", "stable"
    );
    for c in &rep.combinations {
        let f = |k: &str| c.fits.get(k).copied().unwrap_or(f64::NAN);
        println!(
            "{:<8} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>7}  {}",
            c.name,
            f("1"),
            f("5"),
            f("10"),
            f("20"),
            f("sim"),
            c.stable,
            c.note
        );
    }
    if let Some(e) = &rep.merge_error {
        println!("merge not available: {e}");
    }
    let want = match args.method {
        Method::Best => rep.best.clone(),
        Method::Average => Some("average".into()),
        Method::Merge => Some("merge".into()),
        Method::Multi => Some("multi".into()),
    };
    let chosen = want
        .as_deref()
        .and_then(|w| rep.combinations.iter().find(|c| c.name == w));
    if let Some(c) = chosen {
        println!("chosen: {}", c.name);
    }
    let mut done = None;
    if let Some(out) = &args.out {
        let c = chosen.ok_or_else(|| {
            anyhow::anyhow!(
                "the {:?} combination is not available (no stable combination, or merge failed)",
                args.method
            )
        })?;
        let track = track_from_records(&args.read, &c.model, &recs, &args.data, false)?;
        let r = add_model(&mut outputs, &c.model, track, out, &val[0])?;
        done = Some(format!(
            "model written to {} and {}",
            r.blob_path.display(),
            r.json_path.display()
        ));
    }
    outputs.json(
        &args.json,
        &serde_json::json!({
            "command": "average",
            "best": rep.best,
            "chosen": chosen.map(|c| c.name.clone()),
            "combinations": rep.combinations.iter().map(|c| serde_json::json!({
                "name": c.name, "fit": c.fits, "stable": c.stable, "note": c.note,
            })).collect::<Vec<_>>(),
            "merge_error": rep.merge_error,
        }),
    )?;
    outputs.commit()?;
    if let Some(d) = done {
        println!("{d}");
    }
    Ok(())
}

/// Arguments of `yawcast export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The model (a `.json` twin or a `.postcard` blob).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// The record the firmware check runs on (host f64 vs firmware f32 fit within 0.01 pp).
    #[arg(long, value_name = "FILE")]
    pub data: PathBuf,
    /// Where the blob goes: `<PATH>.postcard` and its `<PATH>.json` twin.
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// Also write golden vectors (20-step predictions) for the firmware tests to this file.
    #[arg(long, value_name = "FILE")]
    pub golden: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Runs `export`.
pub fn export_cmd(args: &ExportArgs) -> Result<()> {
    check_json_vs_out(Some(&args.out), &args.json)?;
    let [blob, twin] = model_paths(Some(&args.out));
    let mut outputs = Outputs::check(&[
        blob.as_deref(),
        twin.as_deref(),
        args.golden.as_deref(),
        args.json.json.as_deref(),
    ])?;
    let model = read_model(&args.model)?;
    let check = args.read.read(&args.data)?;
    super::common::check_record_for_model(&check, &model, &args.data)?;
    // the model's heading/track part goes into the blob with it (format 3)
    let cfg = export::ExportConfig {
        golden: args.golden.clone(),
        track: super::common::read_track(&args.model, &model)?,
        ..export::ExportConfig::default()
    };
    let (r, files) =
        export::prepare_with(&model, &args.out, &check, &cfg).map_err(|e| match e {
            export::ExportError::Check { .. } | export::ExportError::Model(_) => bad(e),
            other => anyhow::Error::new(other),
        })?;
    outputs.extend(files);
    outputs.json(&args.json, &r)?;
    outputs.commit()?;
    println!(
        "{:>8} {:>12} {:>14} {:>10}",
        "horizon", "host f64", "firmware f32", "Δ [pp]"
    );
    for c in &r.checks {
        println!(
            "{:>8} {:>12.4} {:>14.4} {:>10.5}",
            c.horizon,
            c.host_fit,
            c.firmware_fit,
            (c.host_fit - c.firmware_fit).abs()
        );
    }
    println!(
        "exported {} ({} bytes) and {}{}",
        r.blob_path.display(),
        r.blob_len,
        r.json_path.display(),
        r.golden_path
            .as_ref()
            .map(|g| format!("; golden vectors {}", g.display()))
            .unwrap_or_default()
    );
    Ok(())
}
