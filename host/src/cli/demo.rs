//! `yawcast demo`: the whole story on the built-in ship, one command.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use yawcast::demo::{self, DemoConfig};
use yawcast::sim::Ship;

use super::common::{bad, json_bytes, Outputs, SeedArg};

/// Arguments of `yawcast demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Run directory (records, models, ship file, report.html, summary.json)
    /// [default: runs/demo-SEED].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also write the JSON summary here (it is always written to DIR/summary.json).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Ship file to sail instead of the built-in 1:24 LNG carrier.
    #[arg(long, value_name = "SHIP.toml")]
    pub ship: Option<PathBuf>,
    /// Firmware ELF for the QEMU check [default: $YAWCAST_FW_ELF, else
    /// target/thumbv7em-none-eabihf/release/yawcast-fw when built].
    #[arg(long, value_name = "ELF")]
    pub elf: Option<PathBuf>,
    /// Record length (s) of every simulated record.
    #[arg(long, value_name = "S", default_value_t = 1800.0)]
    pub duration: f64,
    #[command(flatten)]
    pub seed: SeedArg,
}

/// Runs `yawcast demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    let ship = match &args.ship {
        Some(p) => Ship::from_file(p).map_err(bad)?,
        None => Ship::default_lng(),
    };
    if !(args.duration.is_finite() && args.duration >= 300.0) {
        return Err(bad(format!(
            "--duration {}: expected at least 300 s",
            args.duration
        )));
    }
    let elf = match &args.elf {
        Some(p) if p.is_file() => Some(p.clone()),
        Some(p) => return Err(bad(format!("--elf {}: no such file", p.display()))),
        None => std::env::current_dir()
            .ok()
            .and_then(|ws| yawcast::io::hil::find_elf(&ws).ok()),
    };
    let seed = args.seed.resolve();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("runs/demo-{seed}")));
    let report = out.join("report.html");
    let summary_path = out.join("summary.json");
    let mut outputs = Outputs::check(&[
        Some(report.as_path()),
        Some(summary_path.as_path()),
        args.json.as_deref(),
    ])?;
    let cfg = DemoConfig {
        seed,
        ship,
        duration_s: args.duration,
        elf,
        out: out.clone(),
        progress: console_is_tty(),
        ..DemoConfig::default()
    };
    std::fs::create_dir_all(&out)
        .with_context(|| format!("creating the run directory {}", out.display()))?;
    println!("yawcast demo — {} — seed {seed}", cfg.ship.name);
    let outcome = demo::run(&cfg, &mut |line| println!("  {line}"))?;
    // The page and the summaries appear together (the records and models the demo made on
    // its way are written as it goes, each atomically).
    outputs.add(&report, outcome.report().render().into_bytes());
    let summary = outcome.summary();
    outputs.add(&summary_path, json_bytes(&summary)?);
    if let Some(j) = &args.json {
        outputs.add(j, json_bytes(&summary)?);
    }
    outputs.commit()?;
    let f = |m: &demo::ModelResult, k: &str| m.fit.get(k).copied().unwrap_or(f64::NAN);
    println!();
    println!(
        "  hidden effect:    {} ({})",
        outcome.hidden_effect, outcome.hidden_detail
    );
    println!(
        "  diagnosed effect: {} — {}",
        outcome.diagnosed_effect,
        if outcome.diagnosis_right() {
            "right"
        } else {
            "WRONG"
        }
    );
    println!("  {}", outcome.explanation);
    println!("  fit % on the held-out trials     1-step  5-step 10-step 20-step    sim");
    for m in [&outcome.conventional, &outcome.tuned, &outcome.augmented] {
        println!(
            "  {:<32} {:>6.1} {:>7.1} {:>7.1} {:>7.1} {:>6.1}",
            m.label,
            f(m, "1"),
            f(m, "5"),
            f(m, "10"),
            f(m, "20"),
            f(m, "sim")
        );
    }
    println!("  ship file: {}", outcome.ship_note);
    println!(
        "  firmware: {} of {} predictions bit-exact (native); QEMU: {}",
        outcome.firmware.native_equal, outcome.firmware.values, outcome.firmware.qemu_note
    );
    println!("  {:.1} s in all", outcome.seconds);
    println!("  report: {}", report.display());
    Ok(())
}

fn console_is_tty() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal()
}
