//! `yawcast simulate`: measurement records from the 3-DOF ship simulator, one effect or more
//! switched on, seeded.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use rayon::prelude::*;
use serde::Serialize;
use yawcast::io::data::Record;
use yawcast::io::nav::csv_text_with_nav;
use yawcast::sim::{
    self, Autopilot, InputSpec, NoiseSpec, Scenario, Ship, SimEffect, World, WorldKind,
};
use yawcast_shared::model::EffectKind;

use super::common::{bad, JsonArg, Outputs, SeedArg};

/// Arguments of `yawcast simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Ship file (TOML; copy `host/ships/lng_1to24.toml` or write it with `--save-ship`).
    /// Default: the built-in 1:24 LNG carrier. Only with `--world lng`.
    #[arg(long, value_name = "SHIP.toml")]
    pub ship: Option<PathBuf>,
    /// Simulator: `lng` (the built-in 1:24 LNG carrier, pods, Ts 1 s), `kvlcc2` (the KVLCC2
    /// tanker by the MMG standard method, full scale L_pp 320 m, Ts 1 s), `mariner` (the
    /// Mariner cargo ship, Abkowitz-type, L_pp 160.93 m, Ts 1 s), `seiun-maru` (the Seiun
    /// Maru, a fine 105 m training ship by the MMG standard method, Ts 1 s), `container`
    /// (a high-speed container ship whose steering couples with its roll, Son & Nomoto,
    /// L_pp 175 m, Ts 1 s) or `esso-osaka` (the Esso Osaka tanker, its rudder in the
    /// propeller's race, Van Berlekom & Goddard, L_pp 304.8 m, Ts 1 s). The new worlds add a
    /// background yaw disturbance, gyro and compass errors and, with `--effect wind`, gusts;
    /// their `--effect`s are the built-in ship's carried over to the hull, their `prbs`
    /// holds stretched by the hull's L/U.
    #[arg(long, value_name = "NAME", default_value = "lng")]
    pub world: String,
    /// Length between perpendiculars (m) of a Froude-scaled `--world kvlcc2`, `seiun-maru`
    /// or `esso-osaka` (speeds and times by √(L/L_full), L_full 320, 105 or 304.8 m; the
    /// default Ts too).
    #[arg(long, value_name = "L_M")]
    pub scale: Option<f64>,
    /// Approach speed through the water (m/s at the world's scale) instead of the design
    /// speed: the propeller turns at the revolutions that hold it straight ahead (kvlcc2,
    /// seiun-maru, container and esso-osaka; 0.25–1.5 times the design speed). For records
    /// of a ship that ran slower than its source's design speed, as tank tests often do.
    #[arg(long, value_name = "MPS")]
    pub speed: Option<f64>,
    /// Switch on a library effect, by its name (docs/formats.md; a wrong name lists them),
    /// at its canonical strength (repeatable).
    #[arg(long, value_name = "NAME")]
    pub effect: Vec<String>,
    /// Strength of the `--effect`s (1 full, 0.5 half).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub strength: f64,
    /// Record length (s).
    #[arg(long, value_name = "S", default_value_t = 1800.0)]
    pub duration: f64,
    /// Sample time (s); default 1, on a scaled world √(L/L_full).
    #[arg(long, value_name = "S")]
    pub ts: Option<f64>,
    /// Command: `prbs` (identification input, random switching, 5–20°), `zigzag:10/10`,
    /// `autopilot` (closed-loop course keeping: a PD autopilot, course changes of ±10°
    /// held 60–180 s, tuned to the hull) or `autopilot:KP/KD/STEP` (heading gain, rate gain
    /// in s, course change in deg), `step:15` (step at t = 10 s) or `constant:10`.
    #[arg(long, value_name = "KIND", default_value = "prbs")]
    pub input: String,
    /// Rate-gyro noise (deg/s, standard deviation).
    #[arg(long, value_name = "DEG/S", default_value_t = 0.03)]
    pub gyro_noise: f64,
    /// Heading noise (deg, standard deviation).
    #[arg(long, value_name = "DEG", default_value_t = 0.0)]
    pub heading_noise: f64,
    /// Speed-over-ground noise (m/s, standard deviation).
    #[arg(long, value_name = "M/S", default_value_t = 0.0)]
    pub speed_noise: f64,
    /// Initial heading (deg); drawn from the seed when not given.
    #[arg(long, value_name = "DEG")]
    pub heading: Option<f64>,
    /// The background yaw disturbance times K (default 1: a first-order yaw moment whose
    /// standard deviation is what 0.5° of rudder gives, time constant L_pp/U; 2 a rougher
    /// day, 0 none). Only on the new worlds: the built-in ship has none.
    #[arg(long, value_name = "K", default_value_t = 1.0)]
    pub disturbance: f64,
    /// Log the steering gear's angle in `delta_deg` instead of the command: as a rig that
    /// logs the rudder's own angle (its feedback), the gear between the command and it.
    #[arg(long)]
    pub log_angle: bool,
    /// Log the apparent wind (anemometer) columns.
    #[arg(long)]
    pub log_wind: bool,
    /// Number of records (seeds `seed`, `seed+1`, …); with more than one, `-1`, `-2`, … is
    /// added to the file name before its extension.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub records: usize,
    /// The measurement CSV to write.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Also score the world's own K-step predictor on each record: the true simulator from
    /// the true state K samples back, driven by the logged commands (its random
    /// disturbances decaying towards their means). Its fit % is the best a model of the
    /// records can hope for (`oracle_fit_pct` in the JSON).
    #[arg(long, value_name = "K")]
    pub oracle_horizon: Option<usize>,
    /// Also write the ship used (with its effects) as TOML, to copy and edit.
    #[arg(long, value_name = "SHIP.toml")]
    pub save_ship: Option<PathBuf>,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub json: JsonArg,
}

/// One written record in the JSON summary.
#[derive(Debug, Serialize)]
struct Written {
    path: String,
    seed: u64,
    samples: usize,
    ts: f64,
    /// Fit % of the world's own `oracle_horizon`-step predictions to the logged yaw rate.
    #[serde(skip_serializing_if = "Option::is_none")]
    oracle_fit_pct: Option<f64>,
}

/// The JSON summary of `yawcast simulate`.
#[derive(Debug, Serialize)]
struct Summary {
    command: &'static str,
    seed: u64,
    world: &'static str,
    ship: String,
    effects: Vec<SimEffect>,
    #[serde(skip_serializing_if = "Option::is_none")]
    oracle_horizon: Option<usize>,
    records: Vec<Written>,
}

fn parse_input(s: &str) -> Result<InputSpec> {
    let err = || {
        bad(format!(
            "--input {s:?}: expected prbs, zigzag:DELTA/PSI, autopilot, autopilot:KP/KD/STEP, \
             step:DELTA or constant:DELTA"
        ))
    };
    let (kind, arg) = s.split_once(':').unwrap_or((s, ""));
    let num = |v: &str| v.trim().parse::<f64>().map_err(|_| err());
    Ok(match kind {
        "prbs" if arg.is_empty() => InputSpec::default(),
        "zigzag" => {
            let (d, p) = arg.split_once('/').ok_or_else(err)?;
            InputSpec::ZigZag {
                delta_deg: num(d)?,
                psi_deg: num(p)?,
            }
        }
        "autopilot" if arg.is_empty() => InputSpec::autopilot(),
        "autopilot" => {
            let v: Vec<&str> = arg.split('/').collect();
            let [kp, kd, step] = v[..] else {
                return Err(err());
            };
            InputSpec::Autopilot(Autopilot {
                kp: num(kp)?,
                kd_s: num(kd)?,
                step_deg: num(step)?,
                ..Autopilot::default()
            })
        }
        "step" => InputSpec::Step {
            delta_deg: num(arg)?,
            at_s: 10.0,
        },
        "constant" => InputSpec::Constant {
            delta_deg: num(arg)?,
        },
        _ => return Err(err()),
    })
}

/// Path of record `i` (1-based) of `n`.
fn numbered(out: &Path, i: usize, n: usize) -> PathBuf {
    if n == 1 {
        return out.to_path_buf();
    }
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match out.extension() {
        Some(ext) => format!("{stem}-{i}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{i}"),
    };
    out.with_file_name(name)
}

/// Runs `yawcast simulate`.
///
/// Long: the subcommand's checks and steps in the order its outputs are written, each a few
/// lines.
pub fn run(args: &SimulateArgs) -> Result<()> {
    for (flag, v) in [
        ("--gyro-noise", args.gyro_noise),
        ("--heading-noise", args.heading_noise),
        ("--speed-noise", args.speed_noise),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(bad(format!("{flag} {v}: expected a finite number ≥ 0")));
        }
    }
    let kind = WorldKind::from_name(&args.world).ok_or_else(|| {
        let names: Vec<&str> = WorldKind::ALL.iter().map(|k| k.name()).collect();
        bad(format!(
            "--world {:?}: unknown world (expected one of {})",
            args.world,
            names.join(", ")
        ))
    })?;
    if kind != WorldKind::Lng && (args.ship.is_some() || args.save_ship.is_some()) {
        return Err(bad(format!(
            "--ship and --save-ship are for the built-in ship family (--world lng), not --world {}",
            kind.name()
        )));
    }
    let world = World::new(kind, args.scale).map_err(|e| bad(format!("--scale: {e}")))?;
    let world = match args.speed {
        Some(u) => world
            .at_speed(u)
            .map_err(|e| bad(format!("--speed: {e}")))?,
        None => world,
    };
    let records: Vec<PathBuf> = match &args.out {
        Some(out) => (1..=args.records)
            .map(|i| numbered(out, i, args.records))
            .collect(),
        None => Vec::new(),
    };
    let mut wanted: Vec<Option<&Path>> = records.iter().map(|p| Some(p.as_path())).collect();
    wanted.extend([args.save_ship.as_deref(), args.json.json.as_deref()]);
    let mut outputs = Outputs::check(&wanted)?;
    let ship = match &args.ship {
        Some(p) => Ship::from_file(p).map_err(bad)?,
        None => Ship::default_lng(),
    };
    let mut effects = Vec::new();
    for name in &args.effect {
        let kind = EffectKind::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = EffectKind::ALL.iter().map(|k| k.name()).collect();
            bad(format!(
                "--effect {name:?}: unknown effect (expected one of {})",
                names.join(", ")
            ))
        })?;
        effects.push(world.hidden(kind, args.strength));
    }
    if !(args.strength.is_finite() && args.strength > 0.0) {
        return Err(bad(format!(
            "--strength {}: expected a positive number",
            args.strength
        )));
    }
    let ts = args.ts.unwrap_or_else(|| world.default_ts());
    if !(args.duration.is_finite() && ts.is_finite() && ts > 0.0 && args.duration > 0.0) {
        return Err(bad("--duration and --ts must be positive numbers"));
    }
    let n_samples = (args.duration / ts).round() as usize;
    if args.records == 0 {
        return Err(bad("--records: expected at least 1"));
    }
    if let Some(k) = args.oracle_horizon {
        if k == 0 || k >= n_samples {
            return Err(bad(format!(
                "--oracle-horizon {k}: expected 1 to {} steps (shorter than the record)",
                n_samples.saturating_sub(1)
            )));
        }
    }
    if !(args.disturbance.is_finite() && args.disturbance >= 0.0) {
        return Err(bad(format!(
            "--disturbance {}: expected a number ≥ 0 (1 is the world's own)",
            args.disturbance
        )));
    }
    if kind == WorldKind::Lng && args.disturbance != 1.0 {
        return Err(bad(
            "--disturbance: the built-in ship (--world lng) has no background yaw disturbance \
             to scale; it is on the kvlcc2, mariner, seiun-maru, container and esso-osaka worlds",
        ));
    }
    if args.out.is_none() && args.save_ship.is_none() {
        return Err(bad(
            "nothing to write: give --out FILE.csv (and/or --save-ship)",
        ));
    }
    let scenario = Scenario {
        name: "sim".into(),
        ts,
        n_samples,
        input: match parse_input(&args.input)? {
            InputSpec::Prbs { .. } => world.default_input(),
            // the default autopilot is tuned to the hull's time; given gains stand
            InputSpec::Autopilot(_) if args.input == "autopilot" => world.default_autopilot(),
            other => other,
        },
        noise: NoiseSpec {
            gyro_std_degps: args.gyro_noise,
            heading_std_deg: args.heading_noise,
            speed_std_mps: args.speed_noise,
        },
        effects: effects.clone(),
        log_wind: args.log_wind,
        log_angle: args.log_angle,
        initial_heading_deg: args.heading,
        disturbance: args.disturbance,
        ..Scenario::default()
    };
    scenario.validate().map_err(bad)?;
    let seed = args.seed.resolve();
    let mut written = Vec::new();
    let mut done = Vec::new();
    if args.out.is_some() {
        let seeds: Vec<u64> = (0..args.records as u64).map(|i| seed + i).collect();
        // the built-in ship family also logs course over ground and position
        // without --oracle-horizon nothing is replayed: 0 steps ahead is the run itself
        let horizon = args.oracle_horizon.unwrap_or(0);
        let recs: Vec<(Record, Option<sim::SimNav>, sim::Oracle)> = seeds
            .par_iter()
            .map(|&s| {
                let (mut r, n, o) = if kind == WorldKind::Lng {
                    sim::simulate_with_oracle(&ship, &scenario, s, horizon)
                        .map(|(r, n, o)| (r, Some(n), o))?
                } else {
                    world
                        .simulate_with_oracle(&scenario, s, horizon)
                        .map(|(r, o)| (r, None, o))?
                };
                r.name = format!("{}-{s}", scenario.name);
                Ok((r, n, o))
            })
            .collect::<Result<Vec<_>, sim::SimError>>()
            .map_err(bad)?;
        for (((rec, nav, oracle), s), path) in recs.iter().zip(&seeds).zip(&records) {
            let text = match nav {
                Some(n) => csv_text_with_nav(rec, &n.cog_deg, &n.north_m, &n.east_m),
                None => yawcast::io::data::csv_text(rec),
            };
            outputs.add(path, text.into_bytes());
            let oracle_fit_pct = args.oracle_horizon.map(|_| oracle.fit(rec));
            done.push(format!(
                "{}: {} samples at Ts = {} s, seed {s}{}",
                path.display(),
                rec.len(),
                rec.ts,
                match oracle_fit_pct {
                    Some(f) => format!(
                        "; the world's own {}-step predictor fits its yaw rate at {f:.2} %",
                        oracle.horizon
                    ),
                    None => String::new(),
                }
            ));
            written.push(Written {
                path: path.display().to_string(),
                seed: *s,
                samples: rec.len(),
                ts: rec.ts,
                oracle_fit_pct,
            });
        }
    }
    let mut ship_out = ship.clone();
    for e in &effects {
        ship_out = ship_out.with_effect(*e);
    }
    if let Some(p) = &args.save_ship {
        let text = ship_out.to_toml_string().map_err(bad)?;
        outputs.add(p, text.into_bytes());
        done.push(format!("{}: ship file ({})", p.display(), ship_out.name));
    }
    if !effects.is_empty() {
        let names: Vec<&str> = effects.iter().map(|e| e.kind().name()).collect();
        done.push(format!("effects on: {}", names.join(", ")));
    }
    outputs.json(
        &args.json,
        &Summary {
            command: "simulate",
            seed,
            world: kind.name(),
            ship: match args.ship {
                Some(_) => ship.name.clone(),
                None => world.name(),
            },
            effects,
            oracle_horizon: args.oracle_horizon,
            records: written,
        },
    )?;
    outputs.commit()?;
    for d in done {
        println!("{d}");
    }
    Ok(())
}
