//! `yawcast hil`: the firmware (QEMU or a board) predicts live while the host feeds it a
//! voyage; every prediction is checked bit for bit against the firmware library run here.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use yawcast::io::data::Record;
use yawcast::io::hil::{self, Device, F32Record, LiveFit, NativePredictor};

use super::common::{
    bad, check_record_for_model, progress, read_model, JsonArg, Outputs, ReadArgs, SeedArg,
};

/// Arguments of `yawcast hil`.
#[derive(Debug, Args)]
pub struct HilArgs {
    /// The model (`.postcard` blob; its `.json` twin beside it).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// A real board's serial device (configured first: `stty -F DEV 115200 raw -echo`).
    /// Without it the firmware runs in QEMU.
    #[arg(long, value_name = "DEVICE")]
    pub serial: Option<PathBuf>,
    /// The firmware ELF for QEMU [default: $YAWCAST_FW_ELF, else target/…/release/yawcast-fw].
    #[arg(long, value_name = "FILE")]
    pub elf: Option<PathBuf>,
    /// Replay this record instead of sailing the simulator.
    #[arg(long, value_name = "FILE")]
    pub data: Option<PathBuf>,
    /// Prediction horizon asked of the firmware.
    #[arg(long, default_value_t = 20, value_name = "STEPS")]
    pub horizon: usize,
    /// Samples to sail (simulator) or to replay at most.
    #[arg(long, default_value_t = 1200, value_name = "N")]
    pub steps: usize,
    /// Print the live fit every this many samples.
    #[arg(long, default_value_t = 100, value_name = "N")]
    pub every: usize,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub json: JsonArg,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// The JSON summary of `hil`.
#[derive(Debug, Serialize)]
pub struct HilSummary {
    /// Always "hil".
    pub command: &'static str,
    /// "qemu" or "serial".
    pub target: String,
    /// Samples run.
    pub samples: usize,
    /// Horizon.
    pub horizon: usize,
    /// Predicted values compared.
    pub values: usize,
    /// Values equal bit for bit to the firmware library run natively.
    pub equal: usize,
    /// All equal.
    pub bit_exact: bool,
    /// Final live fit of the device's predictions, keyed by horizon.
    pub fit: std::collections::BTreeMap<String, f64>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Runs `hil`.
///
/// Long: the subcommand's steps (connect, load, stream, compare, report) in order, each a few
/// lines.
pub fn run(args: &HilArgs) -> Result<()> {
    Outputs::check(&[args.json.json.as_deref()])?;
    if !(1..=yawcast_shared::wire::MAX_HORIZON).contains(&args.horizon) {
        return Err(bad(format!(
            "--horizon {} is outside 1..={}",
            args.horizon,
            yawcast_shared::wire::MAX_HORIZON
        )));
    }
    if args.steps == 0 {
        return Err(bad("--steps 0: the loop needs at least one step"));
    }
    let model = read_model(&args.model)?;
    let spec = model
        .to_spec()
        .map_err(|e| bad(format!("{}: {e}", args.model.display())))?;
    let voyage: Record = match &args.data {
        Some(p) => {
            let r = args.read.read(p)?;
            check_record_for_model(&r, &model, p)?;
            let n = r.len().min(args.steps);
            r.slice(0, n)
        }
        None => super::sail(&model, args.steps, args.seed.resolve())?,
    };
    let rec = F32Record::new(&voyage);
    let h = args.horizon;
    let start = Instant::now();
    let (mut dev, target) = match &args.serial {
        Some(p) => (
            Device::serial(p).with_context(|| format!("opening the board on {}", p.display()))?,
            format!("serial {}", p.display()),
        ),
        None => {
            let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .parent()
                .map(PathBuf::from)
                .unwrap_or_default();
            let elf = match &args.elf {
                Some(e) => e.clone(),
                None => hil::find_elf(&root)?,
            };
            let d = Device::qemu(&elf).context("booting the firmware in QEMU")?;
            (d, format!("QEMU netduinoplus2 ({})", elf.display()))
        }
    };
    let crc = dev
        .load(&spec)
        .context("loading the model into the firmware")?;
    println!(
        "hil: {target}; model loaded (order {}, {} effects, crc {crc:#010x}); {} samples, horizon {h}",
        spec.order,
        spec.effects.len(),
        rec.u.len()
    );
    let mut native = NativePredictor::new(&spec)?;
    let ks: Vec<usize> = [1, 5, 10, 20].into_iter().filter(|k| *k <= h).collect();
    let mut live = LiveFit::new(&ks);
    let (mut values, mut equal) = (0usize, 0usize);
    let mut first_diff: Option<(usize, usize, f32, f32)> = None;
    let pb = progress(rec.u.len() as u64, "hil");
    let n = rec.u.len();
    let mut t0 = 0;
    while t0 < n {
        let t1 = (t0 + dev.window.max(1)).min(n);
        let chunk = dev
            .steps(&rec, t0..t1, h)
            .with_context(|| format!("samples {t0}..{t1}"))?;
        for (t, got) in (t0..t1).zip(chunk) {
            let fu = hil::future_inputs(&rec.u, t, h);
            let psi = rec.psi.as_ref().map(|p| p[t]);
            native.update(rec.u[t], rec.y[t], psi);
            let mut want = vec![0.0f32; h];
            native.predict(&mut want, &fu)?;
            for (k, (a, b)) in got.iter().zip(&want).enumerate() {
                values += 1;
                if a.to_bits() == b.to_bits() {
                    equal += 1;
                } else if first_diff.is_none() {
                    first_diff = Some((t, k + 1, *a, *b));
                }
            }
            live.push(voyage.y[t], &got);
            pb.inc(1);
            if (t + 1) % args.every.max(1) == 0 || t + 1 == n {
                pb.suspend(|| {
                    let fits: Vec<String> = live
                        .fits()
                        .iter()
                        .map(|(k, f)| format!("fit@{k} {f:6.2} %"))
                        .collect();
                    println!(
                        "t = {:7.1} s  {}  bit-exact {equal}/{values}",
                        voyage.t[t],
                        fits.join("  ")
                    );
                });
            }
        }
        t0 = t1;
    }
    pb.finish_and_clear();
    dev.close();
    let fit: std::collections::BTreeMap<String, f64> = live
        .fits()
        .into_iter()
        .map(|(k, f)| (k.to_string(), f))
        .collect();
    let summary = HilSummary {
        command: "hil",
        target: if args.serial.is_some() {
            "serial".into()
        } else {
            "qemu".into()
        },
        samples: rec.u.len(),
        horizon: h,
        values,
        equal,
        bit_exact: values > 0 && equal == values,
        fit,
        seconds: start.elapsed().as_secs_f64(),
    };
    args.json.write(&summary)?;
    match first_diff {
        None => {
            println!(
                "hil: all {values} predicted values equal bit for bit to the firmware library on this machine ({:.1} s)",
                summary.seconds
            );
            Ok(())
        }
        Some((t, k, a, b)) => anyhow::bail!(
            "the device's predictions differ from the native firmware library: {} of {values} values; first at sample {t}, step {k}: device {a:e} vs native {b:e}",
            values - equal
        ),
    }
}
