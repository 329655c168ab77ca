//! `yawcast augment`: add a library effect to a model, re-identify it, compare held-out fits
//! before and after, export the result, and optionally write the effect into a ship file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use yawcast::demo::FitSummary;
use yawcast::diagnose::augment::{self, AugmentConfig, AugmentError, AugmentReport, Written};
use yawcast::identify::model::Model;
use yawcast::io::data::Record;
use yawcast::io::export;
use yawcast::sim::{Ship, SimEffect};
use yawcast_shared::model::EffectKind;

use super::common::{
    bad, check_record_for_model, read_model, read_track, JsonArg, Outputs, ReadArgs, SeedArg,
};
use std::collections::BTreeMap;
use yawcast::identify::track::evaluate;
use yawcast_shared::nav::TrackSpec;

mod summary;
pub use summary::{AugmentSummary, MoreSummary, TrackBeforeAfter};

/// Arguments of `yawcast augment`.
#[derive(Debug, Args)]
pub struct AugmentArgs {
    /// The model to augment (`.postcard` blob with its `.json` twin, or the `.json` twin).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// The effect to add, by its library name (docs/formats.md; a wrong name lists them),
    /// `auto` for the verdict of `yawcast diagnose`, or `none` (with `--more`: only the
    /// search).
    #[arg(long, value_name = "NAME")]
    pub effect: String,
    /// Then search the effects library: add further effects one at a time, each only while
    /// the held-out records pay for it (the same rule as for the named effect), for the best
    /// predictor — e.g. the hull's own nonlinear damping, which the simulator's records need
    /// as much as the trials, so `diagnose` does not name it.
    #[arg(long)]
    pub more: bool,
    /// Estimation records (CSV or NMEA); repeatable.
    #[arg(long, value_name = "FILE", required = true)]
    pub data: Vec<PathBuf>,
    /// Validation records; repeatable. Without them the last third of each estimation
    /// record is held out.
    #[arg(long, value_name = "FILE")]
    pub validate: Vec<PathBuf>,
    /// Reference records the model was identified from (the simulator's), for `--effect auto`.
    #[arg(long, value_name = "FILE")]
    pub reference: Vec<PathBuf>,
    /// Bootstrap replicates per effect of the diagnosis `--effect auto` runs (as `diagnose`).
    #[arg(long, value_name = "N", default_value_t = super::common::NULL_REPS)]
    pub null_reps: usize,
    /// Where the augmented model goes: `<PATH>.postcard` and its `<PATH>.json` twin. When
    /// the effect is not kept: the model re-identified on the records when it validates
    /// better than the input model, else the input model unchanged (`written` in the JSON).
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// Also write the effect, in physical units, into this ship file (created from the
    /// built-in ship when missing); only when the effect is kept.
    #[arg(long, value_name = "SHIP.toml")]
    pub ship: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// The track errors of `augment --effect current` on the held-out records (`val`, else
/// `est`), and the track part to write; `None` (with a note) when the model has no track
/// part or the records no navigation channels.
fn track_current(
    args: &AugmentArgs,
    given: &Model,
    written: &Model,
    paths_recs: (&[PathBuf], &[Record]),
) -> Result<Option<(TrackBeforeAfter, TrackSpec)>> {
    let Some(before_t) = read_track(&args.model, given)? else {
        eprintln!(
            "note: {}: the model has no heading/track part: the track error is not scored",
            args.model.display()
        );
        return Ok(None);
    };
    let (paths, recs) = paths_recs;
    let mut after_t = before_t;
    after_t.current = true;
    let defaults = TrackSpec::new(written.ts as f32, before_t.speed, true).map_err(bad)?;
    after_t.gain_current = defaults.gain_current;
    after_t.fix_current = defaults.fix_current;
    const SECS: [f64; 3] = [30.0, 60.0, 120.0];
    let mut sums: [BTreeMap<String, (f64, usize)>; 2] = Default::default();
    let mut scored = 0;
    for (p, r) in paths.iter().zip(recs) {
        let Some(nav) = args.read.read_nav(p, r)? else {
            continue;
        };
        if r.psi.is_none() {
            continue;
        }
        for (i, (m, t)) in [(given, &before_t), (written, &after_t)].iter().enumerate() {
            let e = evaluate(m, t, r, Some(&nav), &[], &SECS).map_err(bad)?;
            for (secs, v) in &e.track_error_m {
                if let Some(v) = v {
                    let x = sums[i].entry(format!("{secs}")).or_insert((0.0, 0));
                    x.0 += v;
                    x.1 += 1;
                }
            }
        }
        scored += 1;
    }
    if scored == 0 {
        eprintln!("note: no held-out record logs heading and navigation channels: the track error is not scored");
        return Ok(None);
    }
    let mean = |m: &BTreeMap<String, (f64, usize)>| -> BTreeMap<String, f64> {
        m.iter()
            .map(|(k, (s, n))| (k.clone(), s / *n as f64))
            .collect()
    };
    let (before, after) = (mean(&sums[0]), mean(&sums[1]));
    let kept = match (before.get("60"), after.get("60")) {
        (Some(b), Some(a)) => a < b,
        _ => false,
    };
    let line = |m: &BTreeMap<String, f64>| {
        SECS.iter()
            .filter_map(|s| m.get(&format!("{s}")).map(|v| format!("{s} s {v:.2} m")))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "track error on {scored} {}record(s): before {}; with the current estimated {}{}",
        if args.validate.is_empty() {
            ""
        } else {
            "held-out "
        },
        line(&before),
        line(&after),
        if kept { "" } else { " (not kept)" }
    );
    let t = if kept { after_t } else { before_t };
    Ok(Some((
        TrackBeforeAfter {
            before,
            after,
            kept,
            records: scored,
        },
        t,
    )))
}

fn effect_names(m: &Model) -> Vec<String> {
    m.effects
        .iter()
        .map(|e| e.kind().name().to_string())
        .collect()
}

/// What `--effect` asks for.
enum Wanted {
    /// One library effect.
    Named(EffectKind),
    /// The verdict of `diagnose`.
    Auto,
    /// No named effect (only the `--more` search).
    Nothing,
}

fn parse_effect(name: &str, more: bool) -> Result<Wanted> {
    match name {
        "auto" => return Ok(Wanted::Auto),
        "none" if more => return Ok(Wanted::Nothing),
        "none" => {
            return Err(bad(
                "--effect none adds nothing: give --more to search the effects library, \
                 or name an effect",
            ))
        }
        _ => {}
    }
    EffectKind::from_name(name)
        .map(Wanted::Named)
        .ok_or_else(|| {
            let names: Vec<&str> = EffectKind::ALL.iter().map(|k| k.name()).collect();
            bad(format!(
                "--effect: unknown effect `{name}`; valid names: {}, auto, none (with --more)",
                names.join(", ")
            ))
        })
}

fn read_checked(read: &ReadArgs, paths: &[PathBuf], model: &Model) -> Result<Vec<Record>> {
    paths
        .iter()
        .map(|p| {
            let r = read.read(p)?;
            check_record_for_model(&r, model, p)?;
            Ok(r)
        })
        .collect()
}

/// The library error as a CLI error: everything but a numerical failure is bad input.
fn cli_err(e: AugmentError) -> anyhow::Error {
    match e {
        AugmentError::Ident(yawcast::identify::pem::IdentError::AllStartsFailed(_))
        | AugmentError::Ident(yawcast::identify::pem::IdentError::Unstable) => {
            anyhow::Error::new(e).context("augment")
        }
        other => bad(other),
    }
}

/// Runs `yawcast augment`.
///
/// Long: the subcommand's steps in the order its outputs are written, each a few lines.
pub fn run(args: &AugmentArgs) -> Result<()> {
    let wanted = parse_effect(&args.effect, args.more)?;
    let (_, twin) = export::paths(&args.out);
    if args.json.json.as_ref() == Some(&twin) {
        return Err(bad(format!(
            "--json {} is the JSON twin of the model written by --out; choose another name",
            twin.display()
        )));
    }
    if args.null_reps == 0 {
        return Err(bad(
            "--null-reps 0: the null distributions need at least one replicate (default 40)",
        ));
    }
    let (blob, _) = export::paths(&args.out);
    let mut outputs = Outputs::check(&[
        Some(blob.as_path()),
        Some(twin.as_path()),
        args.ship.as_deref(),
        args.json.json.as_deref(),
    ])?;
    // The ship file is read before any work: a broken one must not surface after the model
    // was written.
    if let Some(p) = args.ship.as_ref().filter(|p| p.exists()) {
        Ship::from_file(p).map_err(|e| bad(format!("{}: {e}", p.display())))?;
    }
    let given = read_model(&args.model)?;
    let est = read_checked(&args.read, &args.data, &given)?;
    let val = read_checked(&args.read, &args.validate, &given)?;
    let reference = read_checked(&args.read, &args.reference, &given)?;
    let seed = args.seed.resolve_for(&[&reference, &est, &val]);
    let mut cfg = AugmentConfig::default();
    let (kind, auto, model, then, diagnosed) = match wanted {
        Wanted::Named(k) => (Some(k), false, given.clone(), None, None),
        Wanted::Nothing => (None, false, given.clone(), None, None),
        Wanted::Auto => {
            let Auto {
                kind,
                gear,
                then,
                parameter,
                damping_form,
            } = choose_auto(&given, &reference, &est, &val, seed, args.null_reps)?;
            cfg.damping_form = damping_form;
            if let (Some(t), false) = (then, args.more) {
                println!(
                    "diagnose ranks {} second: --more stacks it after {} when the held-out \
                     records pay for it",
                    t.name(),
                    kind.map_or("the verdict", |k| k.name())
                );
            }
            let check = if val.is_empty() { &est } else { &val };
            let trial_effects = augment::auto_kinds(kind, then, args.more);
            let (model, why) =
                augment::own_base(&given, gear, &trial_effects, &reference, check, &cfg);
            if let Some(w) = why.explain(given.ts) {
                println!("{w}");
            }
            (kind, true, model, then, parameter)
        }
    };
    // `--effect auto` adding nothing: the verdict `none` (the structure re-identified on the
    // trials, which are the ship's own records) or an effect the model carries (diagnose
    // tested it for a change: re-estimated, not added twice)
    let again = match kind {
        None if auto => Some(Again {
            kind: None,
            rep: augment::refit(&model, &est, &val, &cfg).map_err(cli_err)?,
            then: None,
        }),
        Some(k) if auto && model.effect(k).is_some() => Some(Again {
            kind: Some(k),
            rep: augment::reestimate(&model, k, &est, &val, &cfg)
                .map_err(cli_err)?
                .refit,
            then,
        }),
        _ => None,
    };
    let (Some(kind), None) = (kind, &again) else {
        if let Some(a) = &again {
            println!("{}", a.rep.explanation);
        }
        let model = again
            .as_ref()
            .map_or(model.clone(), |a| a.rep.model.clone());
        return write_unchanged(args, outputs, &given, &model, &est, &val, auto, &cfg, again);
    };
    let t0 = std::time::Instant::now();
    let rep = augment::augment(&model, kind, &est, &val, &cfg).map_err(cli_err)?;
    print_report(&rep, t0.elapsed().as_secs_f64());
    let estimate_check = diagnosed.and_then(|d| {
        let eff = rep.candidate.effect(kind)?;
        augment::check_estimate(eff, rep.std_pct.last().copied(), d, rep.candidate.ts)
    });
    if let Some(c) = &estimate_check {
        println!("{}", c.line());
    }
    let more = search_more(args, &rep.model, &est, &val, then, &cfg)?;
    let written = more.as_ref().map_or(&rep.model, |f| &f.model);
    let what = written_kind(&given, written);
    let searched = more.as_ref().is_some_and(|f| !f.added.is_empty());

    let check = val
        .first()
        .or(est.first())
        .context("no record to check the export on")?;
    // a current moves the track, whether or not it also turns the ship: the track part
    // estimates it when it is the effect, or (with --more) the ranked verdict's second
    let track_wanted =
        kind == EffectKind::Current || (args.more && then == Some(EffectKind::Current));
    if track_wanted && kind != EffectKind::Current {
        println!(
            "current (diagnose's second effect): it moves the ship's track; the heading/track \
             part estimates it{}",
            if written.effect(EffectKind::Current).is_some() {
                ", and the yaw-rate model carries its yaw moment"
            } else {
                " (the yaw rate gains nothing from it: no yaw moment to carry)"
            }
        );
    }
    let (track_report, track_part) = if track_wanted {
        let held = if val.is_empty() {
            (args.data.as_slice(), est.as_slice())
        } else {
            (args.validate.as_slice(), val.as_slice())
        };
        match track_current(args, &given, written, held)? {
            Some((r, t)) => (Some(r), Some(t)),
            None => (None, read_track(&args.model, &given)?),
        }
    } else {
        (None, read_track(&args.model, &given)?)
    };
    let ex = super::pipeline::add_model(&mut outputs, written, track_part, &args.out, check)?;
    let mut done = vec![format!(
        "model written to {} and {}{}",
        ex.blob_path.display(),
        ex.json_path.display(),
        describe_written(what)
    )];
    if track_report.as_ref().is_some_and(|t| t.kept) {
        done.push("its heading/track part now estimates the current".to_string());
    }

    let mut ship_written = None;
    let mut sim_effect = None;
    if let Some(path) = &args.ship {
        if rep.kept {
            let eff = rep.model.effect(kind).copied();
            let (ship, se, text) = ship_with(path, eff.as_ref(), &rep.model)?;
            outputs.add(path, text.into_bytes());
            done.push(format!(
                "ship file {} ({}) now carries {}",
                path.display(),
                ship.name,
                se.describe()
            ));
            ship_written = Some(path.clone());
            sim_effect = Some(se);
        } else {
            done.push(format!(
                "ship file {} left unchanged: the effect was not kept",
                path.display()
            ));
        }
    }
    outputs.json(
        &args.json,
        &AugmentSummary {
            command: "augment",
            effect: kind.name().to_string(),
            auto,
            kept: rep.kept,
            written: what,
            before: FitSummary {
                fit: rep.before.clone(),
            },
            baseline: FitSummary {
                fit: rep.baseline.clone(),
            },
            after: FitSummary {
                fit: rep.after.clone(),
            },
            fit_gain_pp: rep.fit_gain_pp,
            delta_aic: rep.delta_aic,
            delta_bic: rep.delta_bic,
            ljung_box_p_before: rep.ljung_box_p_before,
            ljung_box_p_after: rep.ljung_box_p_after,
            estimated: rep.candidate.effect(kind).copied(),
            std_pct: rep.std_pct.clone(),
            reasons: rep.reasons.clone(),
            explanation: format!(
                "{}{}",
                rep.explanation,
                own_physics_note(auto && !rep.kept && !searched, what)
            ),
            out: ex.blob_path,
            ship: ship_written,
            sim_effect,
            more: more.as_ref().map(|f| MoreSummary::of(f, then)),
            estimate_check,
            track_error_m: track_report,
            effects: effect_names(written),
        },
    )?;
    outputs.commit()?;
    for d in done {
        println!("{d}");
    }
    Ok(())
}

/// The `--more` search from `model` (`None` without `--more`), printed; `first`, the ranked
/// verdict's second effect, takes precedence in its first round.
fn search_more(
    args: &AugmentArgs,
    model: &Model,
    est: &[Record],
    val: &[Record],
    first: Option<EffectKind>,
    cfg: &AugmentConfig,
) -> Result<Option<augment::ForwardReport>> {
    if !args.more {
        return Ok(None);
    }
    let t0 = std::time::Instant::now();
    let f =
        augment::forward_ranked(model, est, val, &EffectKind::ALL, first, cfg).map_err(cli_err)?;
    println!(
        "--more: {} round{} over the effects library ({:.1} s){}",
        f.rounds.len(),
        if f.rounds.len() == 1 { "" } else { "s" },
        t0.elapsed().as_secs_f64(),
        first.map_or(String::new(), |k| format!(
            "; diagnose ranks {} second: it goes first when the held-out records pay for it{}",
            k.name(),
            if f.added.first() == Some(&k) {
                " (they do)"
            } else {
                " (they do not)"
            }
        ))
    );
    for (i, r) in f.rounds.iter().enumerate() {
        for line in round_lines(i + 1, r) {
            println!("{line}");
        }
    }
    println!("{}", f.explanation);
    Ok(Some(f))
}

/// `--effect auto` with the verdict `none` (the structure re-identified on the trials) or one
/// the model carries already (its value re-estimated with the rest).
struct Again {
    /// The verdict (`None` for `none`).
    kind: Option<EffectKind>,
    rep: augment::Refitted,
    then: Option<EffectKind>,
}

/// No effect added (`--effect auto` with the verdict `none` or one the model carries already
/// — `again`, re-estimated —, or `--effect none`): `model`, or with `--more` the result of
/// the search from it, is written.
#[allow(clippy::too_many_arguments)]
fn write_unchanged(
    args: &AugmentArgs,
    mut outputs: Outputs,
    given: &Model,
    model: &Model,
    est: &[Record],
    val: &[Record],
    auto: bool,
    cfg: &AugmentConfig,
    again: Option<Again>,
) -> Result<()> {
    let first = again.as_ref().and_then(|a| a.then);
    let more = search_more(args, model, est, val, first, cfg)?;
    let written = more.as_ref().map_or(model, |f| &f.model);
    let what = written_kind(given, written);
    let check = val
        .first()
        .or(est.first())
        .context("no record to check the export on")?;
    // the model's heading/track part goes with it unchanged
    let track = read_track(&args.model, given)?;
    let ex = super::pipeline::add_model(&mut outputs, written, track, &args.out, check)?;
    let mut done = vec![if what == Written::Input {
        format!(
            "no effect to add: the input model is written unchanged to {}",
            ex.blob_path.display()
        )
    } else {
        format!(
            "model written to {} and {}{}",
            ex.blob_path.display(),
            ex.json_path.display(),
            describe_written(what)
        )
    }];
    if let Some(p) = &args.ship {
        done.push(format!(
            "ship file {} left unchanged (it only takes a named effect)",
            p.display()
        ));
    }
    let searched = more.as_ref().is_some_and(|f| !f.added.is_empty());
    let own = own_physics_note(auto && !searched, what);
    // (`--effect auto` always comes with `again`: without it, no effect was named)
    let explanation = match &again {
        Some(a) if a.kind.is_some() => format!("{}{own}", a.rep.explanation),
        Some(a) => format!(
            "diagnose found no missing effect. {}{own}",
            a.rep.explanation
        ),
        None => "no effect named".to_string(),
    };
    let fits = |f: &BTreeMap<String, f64>| FitSummary { fit: f.clone() };
    let gain = again.as_ref().map_or(0.0, |a| {
        let g = |f: &BTreeMap<String, f64>| f.get("10").copied();
        match (g(&a.rep.after), g(&a.rep.before)) {
            (Some(x), Some(y)) if a.rep.written != Written::Input => x - y,
            _ => 0.0,
        }
    });
    outputs.json(
        &args.json,
        &serde_json::json!({
            "command": "augment",
            "effect": again.as_ref().and_then(|a| a.kind).map_or("none", |k| k.name()),
            "auto": auto,
            "kept": again
                .as_ref()
                .is_some_and(|a| a.kind.is_some() && a.rep.written != Written::Input),
            "written": what,
            "before": again.as_ref().map(|a| fits(&a.rep.before)),
            "after": again.as_ref().map(|a| fits(&a.rep.after)),
            "fit_gain_pp": gain,
            "delta_aic": serde_json::Value::Null,
            "delta_bic": serde_json::Value::Null,
            "explanation": explanation,
            "out": ex.blob_path,
            "ship": serde_json::Value::Null,
            "more": more.as_ref().map(|f| MoreSummary::of(f, first)),
            "estimate_check": serde_json::Value::Null,
            "effects": effect_names(written),
        }),
    )?;
    outputs.commit()?;
    for d in done {
        println!("{d}");
    }
    Ok(())
}

/// What the written model is against the model the user gave: `Augmented` when it carries
/// an effect kind that one lacks, `Input` when it is that model, else `Refit` (the same
/// structure re-identified — its own effects' values re-estimated with θ, as a refit of a
/// reference model that carries a steady moment does, is not an effect added).
fn written_kind(given: &Model, written: &Model) -> Written {
    if written == given {
        Written::Input
    } else if written
        .effects
        .iter()
        .any(|e| given.effect(e.kind()).is_none())
    {
        Written::Augmented
    } else {
        Written::Refit
    }
}

/// The sentence that ends the explanation where `--effect auto` writes a model `augmented`
/// against the model given with no effect kept (`none_kept`): the ship's own physics the
/// reference records show, which the base carries ("" otherwise).
fn own_physics_note(none_kept: bool, what: Written) -> &'static str {
    if none_kept && what == Written::Augmented {
        " The model written is `augmented` against the model given: it carries the ship's \
         own physics the reference records show."
    } else {
        ""
    }
}

/// The note after "model written to …".
fn describe_written(w: Written) -> &'static str {
    match w {
        Written::Augmented => "",
        Written::Refit => {
            " (no effect added: the input structure re-identified on these records, which \
             validates better than the input model)"
        }
        Written::Input => " (the input model, unchanged)",
    }
}

/// What `--effect auto` takes from the diagnosis.
struct Auto {
    /// The verdict (`None` for `none`).
    kind: Option<EffectKind>,
    /// The reference model with its own steering gear, when diagnose found one.
    gear: Option<Model>,
    /// The ranked verdict's second effect.
    then: Option<EffectKind>,
    /// Diagnose's estimate of the verdict's parameter and its uncertainty.
    parameter: Option<(f64, Option<f64>)>,
    /// The form of nonlinear damping the diagnosis measured (`y³`: true), fitted so.
    damping_form: Option<bool>,
}

/// `--effect auto`: the verdict of `diagnose`, printed with its reasons, and what augment
/// takes from it ([`Auto`]).
fn choose_auto(
    model: &Model,
    reference: &[Record],
    est: &[Record],
    val: &[Record],
    seed: u64,
    null_reps: usize,
) -> Result<Auto> {
    let cfg = yawcast::diagnose::DiagnoseConfig {
        seed,
        null_reps,
        // the refit below confirms the verdict
        confirm: false,
        ..Default::default()
    };
    let d = yawcast::diagnose::diagnose(model, reference, est, val, &cfg).map_err(bad)?;
    println!("diagnose: verdict {}: {}", d.verdict, d.explanation);
    let then = d.then.as_deref().and_then(EffectKind::from_name);
    let parameter = d
        .ranking
        .iter()
        .find(|r| r.effect == d.verdict)
        .and_then(|r| r.parameter.map(|p| (p, r.parameter_uncertainty)));
    let damping_form = d.verdict_effect.and_then(|e| e.damping_form());
    Ok(Auto {
        kind: d.verdict_kind(),
        gear: d.reference_gear,
        then,
        parameter,
        damping_form,
    })
}

/// Reads (or creates from the built-in ship) the ship file and adds the effect in physical
/// units; returns the ship, the effect and the file's new text.
fn ship_with(
    path: &Path,
    effect: Option<&yawcast::identify::model::Effect>,
    model: &Model,
) -> Result<(Ship, SimEffect, String)> {
    let ship = if path.exists() {
        Ship::from_file(path).map_err(bad)?
    } else {
        eprintln!(
            "{} does not exist: starting from the built-in ship",
            path.display()
        );
        Ship::default_lng()
    };
    let effect = effect.context("the kept model lacks the effect")?;
    let se = augment::to_sim_effect(effect, model, &ship).ok_or_else(|| {
        anyhow::anyhow!(
            "the estimated {} has no physical counterpart in the simulator \
             (e.g. damping of the wrong sign); ship file not written",
            effect.kind().name()
        )
    })?;
    let ship = ship.with_effect(se);
    let text = ship.to_toml_string().map_err(bad)?;
    Ok((ship, se, text))
}

fn print_report(rep: &AugmentReport, secs: f64) {
    for line in report_lines(rep, secs) {
        println!("{line}");
    }
}

/// A number for the terminal with `prec` decimals (`+` sign when `signed`), or "—" when it
/// is not finite: an effect that could not be identified has no fit, and the line saying why
/// follows it.
fn num(v: f64, prec: usize, signed: bool) -> String {
    match (v.is_finite(), signed) {
        (false, _) => "—".into(),
        (true, true) => format!("{v:+.prec$}"),
        (true, false) => format!("{v:.prec$}"),
    }
}

/// The lines of one round of `--more`: each effect tried with its held-out gain (or "—" and,
/// on a line of its own, why it has none), and the one added.
fn round_lines(number: usize, r: &augment::Round) -> Vec<String> {
    let tried: Vec<String> = r
        .tried
        .iter()
        .map(|t| {
            format!(
                "{} {}{}",
                t.effect.name(),
                num(t.fit_gain_pp, 2, true),
                if t.kept { "*" } else { "" }
            )
        })
        .collect();
    let mut lines = vec![format!(
        "  round {number}: {} (pp at 10 steps; * kept; — not identified) → {}",
        tried.join(", "),
        r.added.as_ref().map_or("none added", |a| a.effect.name())
    )];
    for t in r.tried.iter().filter(|t| !t.fit_gain_pp.is_finite()) {
        let why = t
            .note
            .clone()
            .unwrap_or_else(|| "not identified on these records".into());
        lines.push(format!("    {} —: {why}", t.effect.name()));
    }
    lines
}

/// The lines of an augment report: fits per horizon before, with the baseline refit and
/// after, then the verdict with its statistics ("—" for any that could not be computed).
fn report_lines(rep: &AugmentReport, secs: f64) -> Vec<String> {
    let mut lines = vec![format!(
        "{:>8} {:>10} {:>10} {:>10}",
        "horizon", "before", "baseline", "after"
    )];
    let mut keys: Vec<&String> = rep.before.keys().collect();
    keys.sort_by_key(|k| yawcast::identify::predict::Horizon::parse(k));
    let get = |m: &std::collections::BTreeMap<String, f64>, k: &str| {
        num(m.get(k).copied().unwrap_or(f64::NAN), 2, false)
    };
    for k in keys {
        lines.push(format!(
            "{:>8} {:>10} {:>10} {:>10}",
            k,
            get(&rep.before, k),
            get(&rep.baseline, k),
            get(&rep.after, k)
        ));
    }
    lines.push(format!(
        "{}: {} (ΔAIC {}, ΔBIC {}, Ljung–Box p {} → {}; {:.1} s)",
        rep.effect.name(),
        if rep.kept { "kept" } else { "not kept" },
        num(rep.delta_aic, 1, true),
        num(rep.delta_bic, 1, true),
        num(rep.ljung_box_p_before, 3, false),
        num(rep.ljung_box_p_after, 3, false),
        secs
    ));
    lines.push(rep.explanation.clone());
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refit_of_a_model_with_its_own_moment_is_a_refit_not_an_augmentation() {
        // a reference model that carries a steady moment, re-identified: the moment's value
        // moves with θ, no effect is added — `written` says "refit", as the text does
        use yawcast::identify::model::Effect;
        let given = Model::new(1.0, vec![-0.3, 0.9], vec![0.5, 0.4], vec![0.2, 0.1])
            .unwrap()
            .with_effect(Effect::Bias { beta: 1.0 });
        let mut refit = given.clone();
        refit.a[0] = -0.31;
        refit.effects = vec![Effect::Bias { beta: 1.4 }];
        assert_eq!(written_kind(&given, &given), Written::Input);
        assert_eq!(written_kind(&given, &refit), Written::Refit);
        let added = refit.clone().with_effect(Effect::DeadTime { samples: 2 });
        assert_eq!(written_kind(&given, &added), Written::Augmented);
    }

    fn tried(effect: EffectKind, gain: f64, note: Option<&str>) -> augment::Tried {
        augment::Tried {
            effect,
            kept: false,
            fit_10: gain + 80.0,
            fit_gain_pp: gain,
            delta_bic: if gain.is_finite() { -3.0 } else { f64::NAN },
            note: note.map(String::from),
        }
    }

    /// An effect that could not be identified (its fits NaN, as `augment` reports it) is
    /// shown as "—" with the reason, never as "NaN".
    #[test]
    fn an_effect_without_a_fit_is_a_dash_with_its_reason_not_nan() {
        let r = augment::Round {
            tried: vec![
                tried(EffectKind::Bias, 1.234, None),
                tried(
                    EffectKind::Saturation,
                    f64::NAN,
                    Some("an angle limit: not kept: the search found no stable model"),
                ),
                tried(EffectKind::DeadTime, f64::INFINITY, None),
            ],
            added: None,
        };
        let lines = round_lines(2, &r);
        assert_eq!(
            lines,
            [
                "  round 2: bias +1.23, saturation —, dead-time — (pp at 10 steps; * kept; — \
                 not identified) → none added",
                "    saturation —: an angle limit: not kept: the search found no stable model",
                "    dead-time —: not identified on these records",
            ]
        );
        assert!(lines
            .iter()
            .all(|l| !l.contains("NaN") && !l.contains("inf")));
        assert_eq!(num(f64::NAN, 2, true), "—");
        assert_eq!(num(-0.0, 1, true), "-0.0");
        assert_eq!(num(0.126, 2, false), "0.13");
    }
}
