//! Argument groups and helpers shared by every subcommand: reading records and models,
//! JSON summaries, seeds, progress bars and the bad-input marker behind exit code 2.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use yawcast::identify::model::Model;
use yawcast::io::data::{self, Columns, Limits, Record};
use yawcast::io::nav::{parse_nav_csv, Nav, NavColumns};
use yawcast::io::nmea::{self, Clock, NmeaOptions};
use yawcast_shared::blob::FORMAT_VERSION;
use yawcast_shared::nav::TrackSpec;

/// Marks an error as caused by the user's input (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Wraps any error as bad input, keeping its message.
pub fn bad<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::Error::new(BadInput(e.to_string()))
}

/// Whether an error chain is bad input: our marker, or a data/model/blob error from the library.
pub fn is_bad_input(err: &anyhow::Error) -> bool {
    err.chain().any(|c| {
        c.is::<BadInput>()
            || c.is::<data::DataError>()
            || c.is::<nmea::NmeaError>()
            || c.is::<yawcast::identify::model::ModelError>()
            || c.is::<yawcast_shared::blob::BlobError>()
            || c.is::<yawcast_shared::model::ModelError>()
            || c.is::<serde_json::Error>()
            || c.is::<toml::de::Error>()
            || c.is::<clap::Error>()
    })
}

/// Angle unit of CSV columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AngleUnit {
    /// Degrees.
    Deg,
    /// Radians.
    Rad,
}

/// Rate unit of the yaw-rate column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RateUnit {
    /// Degrees per second.
    Degps,
    /// Radians per second.
    Radps,
}

/// Unit of the CSV speed columns (speed over ground, wind speed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SpeedUnit {
    /// Metres per second.
    Mps,
    /// Knots (1 852 m an hour).
    Kn,
    /// Kilometres an hour.
    Kmh,
}

impl SpeedUnit {
    /// What a value in this unit is multiplied by to give m/s.
    fn to_mps(self) -> f64 {
        match self {
            SpeedUnit::Mps => 1.0,
            SpeedUnit::Kn => 1852.0 / 3600.0,
            SpeedUnit::Kmh => 1.0 / 3.6,
        }
    }
}

/// Unit of the CSV time column (when it holds numbers, not date-times).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TimeUnit {
    /// Seconds.
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
}

impl TimeUnit {
    /// What a value in this unit is multiplied by to give seconds.
    fn to_s(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
        }
    }
}

/// File format of a record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// By extension (`.nmea` → NMEA; `.csv`, `.tsv` → CSV; `.log`, `.txt` → NMEA when they
    /// hold a `$` sentence) and otherwise content (a `$` sentence first).
    Auto,
    /// Measurement CSV.
    Csv,
    /// NMEA 0183 log.
    Nmea,
}

/// How to read record files: CSV column names and units, NMEA clock and grid.
#[derive(Debug, Clone, Args)]
#[command(next_help_heading = "Reading records (CSV columns, NMEA logs)")]
pub struct ReadArgs {
    /// File format of --data/--validate/--reference files.
    #[arg(long, value_enum, default_value = "auto")]
    pub format: Format,
    /// CSV column holding time: seconds, ISO 8601 date-times (2024-05-01T12:00:00.5Z) or
    /// times of day (12:00:00.5).
    #[arg(long, value_name = "NAME", default_value = "t_s")]
    pub col_time: String,
    /// CSV column holding the commanded pod/rudder angle.
    #[arg(long, value_name = "NAME", default_value = "delta_deg")]
    pub col_delta: String,
    /// CSV column holding the yaw rate.
    #[arg(long, value_name = "NAME", default_value = "r_degps")]
    pub col_rate: String,
    /// CSV column holding the heading (optional column).
    #[arg(long, value_name = "NAME", default_value = "psi_deg")]
    pub col_heading: String,
    /// CSV column holding the speed over ground in m/s (optional column).
    #[arg(long, value_name = "NAME", default_value = "u_mps")]
    pub col_speed: String,
    /// CSV column holding the relative wind speed in m/s (optional column).
    #[arg(long, value_name = "NAME", default_value = "wind_speed_mps")]
    pub col_wind_speed: String,
    /// CSV column holding the relative wind angle from the bow (optional column).
    #[arg(long, value_name = "NAME", default_value = "wind_angle_deg")]
    pub col_wind_angle: String,
    /// CSV column holding the course over ground in degrees (optional; with --col-speed it
    /// gives the ground velocity of the heading and track prediction, and diagnose's
    /// current its cross-track channel).
    #[arg(long, value_name = "NAME", default_value = "cog_deg")]
    pub col_cog: String,
    /// CSV column holding the latitude in degrees (optional; position fixes, with --col-lon).
    #[arg(long, value_name = "NAME", default_value = "lat_deg")]
    pub col_lat: String,
    /// CSV column holding the longitude in degrees (optional; with --col-lat).
    #[arg(long, value_name = "NAME", default_value = "lon_deg")]
    pub col_lon: String,
    /// CSV column holding the position north of an origin in metres (optional; position
    /// fixes, with --col-east, when there is no latitude/longitude).
    #[arg(long, value_name = "NAME", default_value = "north_m")]
    pub col_north: String,
    /// CSV column holding the position east of an origin in metres (optional; with --col-north).
    #[arg(long, value_name = "NAME", default_value = "east_m")]
    pub col_east: String,
    /// Multiply the command (CSV column or NMEA RSA) of every record read by this, after
    /// --angle-unit: -1 for a logger whose positive command turns the ship the other way,
    /// 0.35 for a rudder logged in per cent of its 35° maximum.
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub command_scale: f64,
    /// Unit of the CSV time column when it holds numbers (not ISO 8601 date-times).
    #[arg(long, value_enum, default_value = "s")]
    pub time_unit: TimeUnit,
    /// Unit of the CSV angle columns (angle, heading, wind angle).
    #[arg(long, value_enum, default_value = "deg")]
    pub angle_unit: AngleUnit,
    /// Unit of the CSV yaw-rate column.
    #[arg(long, value_enum, default_value = "degps")]
    pub rate_unit: RateUnit,
    /// Unit of the CSV speed columns (speed over ground, wind speed).
    #[arg(long, value_enum, default_value = "mps")]
    pub speed_unit: SpeedUnit,
    /// CSV: resample onto a uniform grid of this step (s) — command held, other channels
    /// interpolated — instead of requiring uniform time stamps.
    #[arg(long, value_name = "SECONDS")]
    pub resample: Option<f64>,
    /// CSV: fill up to N missing samples in a row (empty or NaN cells) of the heading, speed
    /// and wind channels by linear interpolation (the heading the shorter way round); 0: a
    /// missing sample is an error naming its row.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub fill_gaps: usize,
    /// Replace isolated spikes of the yaw rate (a logger's glitches: a sample that leaves
    /// the lines through its neighbours on both sides by more than 8 times the noise and a
    /// tenth of the yaw rate's range) by the value its neighbours make, and say which rows;
    /// without it such a record is an error naming them.
    #[arg(long)]
    pub despike: bool,
    /// Without a rate gyro: the yaw rate is the heading's change over each sample,
    /// (ψ_t − ψ_{t−1})/Ts, the first sample taking the second's; a CSV's yaw-rate column or
    /// an NMEA log's ROT sentences are not read (NMEA: the HDT/HDG heading sets the grid,
    /// and the log's ZDA/RMC clock is needed). The controller must form its measurement
    /// the same way.
    #[arg(long)]
    pub rate_from_heading: bool,
    /// NMEA logs without a ZDA/RMC clock: the rate (Hz) at which ROT sentences arrive.
    #[arg(long, value_name = "HZ")]
    pub nmea_rate: Option<f64>,
    /// NMEA logs: grid step (s) to resample onto [default: the usual ROT spacing].
    #[arg(long, value_name = "SECONDS")]
    pub nmea_ts: Option<f64>,
    /// NMEA logs: longest tolerated hole in a channel (s) [default: max(2 grid steps, 2.5 × its usual spacing)].
    #[arg(long, value_name = "SECONDS")]
    pub max_gap: Option<f64>,
    /// NMEA logs: drop sentences with a bad checksum instead of failing.
    #[arg(long)]
    pub skip_bad_checksums: bool,
    /// Largest plausible |commanded angle| (deg); a value beyond it is an error naming its row.
    #[arg(long, value_name = "DEG", default_value_t = Limits::default().angle_deg)]
    pub max_angle: f64,
    /// Largest plausible |yaw rate| (deg/s); a value beyond it is an error naming its row.
    #[arg(long, value_name = "DEGPS", default_value_t = Limits::default().rate_degps)]
    pub max_rate: f64,
    /// Largest plausible speed over ground or wind speed (m/s).
    #[arg(long, value_name = "MPS", default_value_t = Limits::default().speed_mps)]
    pub max_speed: f64,
}

impl Default for ReadArgs {
    fn default() -> Self {
        ReadArgs {
            format: Format::Auto,
            col_time: "t_s".into(),
            col_delta: "delta_deg".into(),
            col_rate: "r_degps".into(),
            col_heading: "psi_deg".into(),
            col_speed: "u_mps".into(),
            col_wind_speed: "wind_speed_mps".into(),
            col_wind_angle: "wind_angle_deg".into(),
            col_cog: "cog_deg".into(),
            col_lat: "lat_deg".into(),
            col_lon: "lon_deg".into(),
            col_north: "north_m".into(),
            col_east: "east_m".into(),
            command_scale: 1.0,
            time_unit: TimeUnit::S,
            angle_unit: AngleUnit::Deg,
            rate_unit: RateUnit::Degps,
            speed_unit: SpeedUnit::Mps,
            nmea_rate: None,
            nmea_ts: None,
            max_gap: None,
            skip_bad_checksums: false,
            resample: None,
            rate_from_heading: false,
            fill_gaps: 0,
            despike: false,
            max_angle: Limits::default().angle_deg,
            max_rate: Limits::default().rate_degps,
            max_speed: Limits::default().speed_mps,
        }
    }
}

impl ReadArgs {
    /// The CSV column mapping.
    pub fn columns(&self) -> Columns {
        let rad = 180.0 / std::f64::consts::PI;
        Columns {
            t: self.col_time.clone(),
            u: self.col_delta.clone(),
            y: self.col_rate.clone(),
            psi: self.col_heading.clone(),
            speed: self.col_speed.clone(),
            wind_speed: self.col_wind_speed.clone(),
            wind_angle: self.col_wind_angle.clone(),
            cog: self.col_cog.clone(),
            angle_scale: match self.angle_unit {
                AngleUnit::Deg => 1.0,
                AngleUnit::Rad => rad,
            },
            rate_scale: match self.rate_unit {
                RateUnit::Degps => 1.0,
                RateUnit::Radps => rad,
            },
            speed_scale: self.speed_unit.to_mps(),
            time_scale: self.time_unit.to_s(),
            resample: self.resample,
            rate_from_heading: self.rate_from_heading,
            fill_gaps: self.fill_gaps,
        }
    }

    /// The plausibility limits.
    ///
    /// Errors when a limit is not a positive number (bad input).
    pub fn limits(&self) -> Result<Limits> {
        for (flag, v) in [
            ("--max-angle", self.max_angle),
            ("--max-rate", self.max_rate),
            ("--max-speed", self.max_speed),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(format!("{flag} {v}: expected a positive number")));
            }
        }
        Ok(Limits {
            angle_deg: self.max_angle,
            rate_degps: self.max_rate,
            speed_mps: self.max_speed,
        })
    }

    /// The NMEA options.
    pub fn nmea(&self) -> NmeaOptions {
        NmeaOptions {
            clock: self.nmea_rate.map_or(Clock::Log, Clock::Rate),
            ts: self.nmea_ts,
            max_gap: self.max_gap,
            skip_bad_checksums: self.skip_bad_checksums,
            rate_from_heading: self.rate_from_heading,
        }
    }

    /// Whether `path` (its text `text`) is read as NMEA: `--format`, else by its name —
    /// `.nmea` and `.nmea0183` are NMEA, `.csv` and `.tsv` tables — and for a logger's
    /// `.log` or `.txt` by its text (NMEA sentences start with `$`, which no table holds);
    /// any other name by whether its first line is a sentence.
    pub fn is_nmea(&self, path: &Path, text: &str) -> bool {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match self.format {
            Format::Nmea => true,
            Format::Csv => false,
            Format::Auto => match ext.as_str() {
                "nmea" | "nmea0183" => true,
                "csv" | "tsv" => false,
                "log" | "txt" => text.contains('$'),
                _ => nmea::looks_like_nmea(text),
            },
        }
    }

    /// Reads one record file (CSV or NMEA).
    ///
    /// Errors name the file, row/line and column/sentence; they count as bad input.
    pub fn read(&self, path: &Path) -> Result<Record> {
        let bytes = std::fs::read(path)
            .map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))?;
        let rec = self.parse(&bytes, path)?;
        for w in data::unit_warnings(&rec) {
            eprintln!("warning: {}: {w}", path.display());
        }
        Ok(rec)
    }

    /// [`ReadArgs::read`] on the bytes of `path` (already read), without the unit warnings.
    pub fn parse(&self, bytes: &[u8], path: &Path) -> Result<Record> {
        let text = data::decode_text(bytes);
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let is_nmea = self.is_nmea(path, &text);
        if !(self.command_scale.is_finite() && self.command_scale != 0.0) {
            return Err(bad(format!(
                "--command-scale {}: expected a non-zero number",
                self.command_scale
            )));
        }
        let (mut rec, mut cols) = if is_nmea {
            let rec = nmea::parse_nmea(&text, path, &name, &self.nmea())?;
            let cols = Columns {
                u: "RSA rudder angle".into(),
                y: "ROT rate of turn".into(),
                psi: "HDT/HDG heading".into(),
                speed: "VTG speed over ground".into(),
                wind_speed: "MWV wind speed".into(),
                ..Columns::default()
            };
            (rec, cols)
        } else {
            let cols = self.columns();
            (data::parse_csv(&text, path, &name, &cols)?, cols)
        };
        if self.command_scale != 1.0 {
            rec.u.iter_mut().for_each(|u| *u *= self.command_scale);
        }
        if self.rate_from_heading {
            // the checks name the channel the rate was formed from
            cols.y = format!("{}'s change per sample (--rate-from-heading)", cols.psi);
        }
        if self.despike {
            let s = data::despike(&mut rec.y);
            if !s.is_empty() {
                eprintln!(
                    "warning: {}: column `{}`: {} spike(s) replaced by the value their \
                     neighbours make (--despike), rows {}",
                    path.display(),
                    cols.y,
                    s.len(),
                    data::spike_rows(&s)
                );
            }
        }
        data::validate_record(&rec, path, &self.limits()?, &cols)?;
        Ok(rec)
    }

    /// The CSV column mapping of the navigation channels.
    pub fn nav_columns(&self) -> NavColumns {
        NavColumns {
            sog: self.col_speed.clone(),
            cog: self.col_cog.clone(),
            lat: self.col_lat.clone(),
            lon: self.col_lon.clone(),
            north: self.col_north.clone(),
            east: self.col_east.clone(),
            sog_scale: self.speed_unit.to_mps(),
        }
    }

    /// The navigation channels of the record `rec` read from `path` (speed and course over
    /// ground, positions; from CSV columns or NMEA `VTG`, `RMC`, `GGA`): `Ok(None)` when the
    /// file has none or was resampled (the heading and track prediction is then skipped,
    /// never guessed; the caller says so).
    ///
    /// Errors name the file, row and column (bad input).
    pub fn read_nav(&self, path: &Path, rec: &Record) -> Result<Option<Nav>> {
        let bytes = std::fs::read(path)
            .map_err(|e| bad(format!("{}: cannot read: {e}", path.display())))?;
        let text = data::decode_text(&bytes);
        let is_nmea = self.is_nmea(path, &text);
        if is_nmea {
            let nn = nmea::parse_nmea_nav(&text, path, &self.nmea(), rec)
                .map_err(|e| bad(e.to_string()))?;
            return Ok(yawcast::io::nav::from_nmea(rec, &nn));
        }
        // resampled records have no rows to match the navigation cells to
        if self.resample.is_some() {
            return Ok(None);
        }
        let nav = parse_nav_csv(&text, path, &self.nav_columns(), rec.len(), rec.ts)
            .map_err(|e| bad(e.to_string()))?;
        if let Some(w) = nav.as_ref().and_then(|n| n.speed_unit_warning(rec.ts)) {
            eprintln!("warning: {}: {w}", path.display());
        }
        Ok(nav)
    }

    /// Reads several record files, in order.
    pub fn read_all(&self, paths: &[PathBuf]) -> Result<Vec<Record>> {
        paths.iter().map(|p| self.read(p)).collect()
    }
}

/// Bootstrap replicates per effect of `diagnose`, and of the diagnosis `augment --effect
/// auto` runs: one default, so the two commands reach the same verdict on the same records.
pub const NULL_REPS: usize = 40;

/// `--json FILE`: where the machine-readable summary goes.
#[derive(Debug, Clone, Args)]
pub struct JsonArg {
    /// Write a machine-readable summary (stable field names) to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

impl JsonArg {
    /// Writes `value` as pretty JSON, atomically, when `--json` was given (a command whose
    /// only output it is; others add it to their [`Outputs`]).
    pub fn write<T: Serialize>(&self, value: &T) -> Result<()> {
        let mut out = Outputs::check(&[self.json.as_deref()])?;
        out.json(self, value)?;
        out.commit()
    }
}

/// Names the variable that makes the `n`-th rename of a command's outputs fail (fault
/// injection for the all-or-nothing tests; `0` or unset: no fault).
pub const FAIL_RENAME_VAR: &str = "YAWCAST_TEST_FAIL_RENAME";

/// Names the variable holding a path: after its first rename, the outputs' write creates
/// that file and waits (up to a minute) for a signal, which then rolls the write back
/// (for the interruption tests).
pub const PAUSE_RENAME_VAR: &str = "YAWCAST_TEST_PAUSE_RENAME";

/// A command's outputs: every path checked before any work ([`Outputs::check`]), the bytes
/// gathered as they are made, and all written together or none at the end
/// ([`Outputs::commit`]).
#[derive(Debug, Default)]
pub struct Outputs {
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Outputs {
    /// Checks the output paths (`None`: an output not asked for) and starts an empty set.
    /// Errors as bad input (exit 2) naming the path that cannot be written.
    pub fn check(paths: &[Option<&Path>]) -> Result<Outputs> {
        let paths: Vec<&Path> = paths.iter().flatten().copied().collect();
        data::check_outputs(&paths).map_err(|e| bad(format!("output {e}")))?;
        Ok(Outputs::default())
    }

    /// Adds a file.
    pub fn add(&mut self, path: &Path, bytes: Vec<u8>) {
        self.files.push((path.to_path_buf(), bytes));
    }

    /// Adds several files.
    pub fn extend(&mut self, files: Vec<(PathBuf, Vec<u8>)>) {
        self.files.extend(files);
    }

    /// Adds the `--json` summary, when asked for.
    pub fn json<T: Serialize>(&mut self, arg: &JsonArg, value: &T) -> Result<()> {
        if let Some(p) = &arg.json {
            self.add(p, json_bytes(value)?);
        }
        Ok(())
    }

    /// Writes every output, all together or none. A failure here (the paths were checked)
    /// is not the input's fault: exit 1; an interruption by a signal keeps its own error
    /// (exit 128 + the signal).
    pub fn commit(self) -> Result<()> {
        if self.files.is_empty() {
            return Ok(());
        }
        let fail_at: usize = std::env::var(FAIL_RENAME_VAR)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(0);
        let pause = std::env::var_os(PAUSE_RENAME_VAR).map(PathBuf::from);
        let mut calls = 0usize;
        let res = data::write_all_atomic_with(&self.files, &mut |from, to| {
            calls += 1;
            if calls == fail_at {
                return Err(std::io::Error::other(format!(
                    "rename {calls} failed ({FAIL_RENAME_VAR})"
                )));
            }
            std::fs::rename(from, to)?;
            if let (1, Some(marker)) = (calls, &pause) {
                std::fs::write(marker, b"")?;
                let mut waited = 0;
                while data::OUTPUTS.interrupted().is_none() && waited < 6000 {
                    std::thread::sleep(std::time::Duration::from_millis(10));
                    waited += 1;
                }
            }
            Ok(())
        });
        match res {
            Ok(()) => Ok(()),
            Err(e @ data::DataError::Interrupted { .. }) => Err(anyhow::Error::new(e)),
            Err(e) => Err(anyhow::anyhow!(
                "writing the outputs failed, none was written (files they would have replaced keep their content): {e}"
            )),
        }
    }
}

/// `value` as pretty JSON with a final newline (for [`yawcast::io::data::write_all_atomic`]).
pub fn json_bytes<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    let mut bytes = serde_json::to_vec_pretty(value).context("serialising the JSON summary")?;
    bytes.push(b'\n');
    Ok(bytes)
}

/// `--seed N`: the seed of every random choice; when not given, derived from the records
/// (`tune`, `diagnose`, `augment`: the same records give the same result) or drawn from the
/// clock (`demo`, `simulate`, `hil`), and printed.
#[derive(Debug, Clone, Args)]
pub struct SeedArg {
    /// Seed of every random choice (printed; the same seed gives the same result).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
}

impl SeedArg {
    /// The seed to use: the given one, or one drawn from the clock. Printed on stderr.
    pub fn resolve(&self) -> u64 {
        let seed = self.seed.unwrap_or_else(|| {
            let nanos = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_nanos() as u64)
                .unwrap_or(0);
            (nanos ^ (u64::from(std::process::id()) << 32)) % 1_000_000
        });
        eprintln!("seed {seed} (rerun with --seed {seed} to repeat)");
        seed
    }

    /// The seed to use for work on `records`: the given one, or one derived from the records'
    /// contents (sample time and every channel), so that the same records give the same
    /// result on every run. Printed on stderr with where it came from.
    pub fn resolve_for(&self, records: &[&[Record]]) -> u64 {
        if let Some(seed) = self.seed {
            eprintln!("seed {seed} (given)");
            return seed;
        }
        let seed = records_seed(records.iter().flat_map(|set| set.iter()));
        eprintln!("seed {seed} (from the records; --seed N overrides)");
        seed
    }
}

/// A seed in `0..1_000_000` from the records' contents (FNV-1a over the bits of the sample
/// time and of every sample of every channel, channel presence included).
pub fn records_seed<'a>(records: impl Iterator<Item = &'a Record>) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(PRIME);
        }
    };
    for r in records {
        eat(r.ts.to_bits());
        for ch in [Some(&r.u), Some(&r.y), r.psi.as_ref(), r.speed.as_ref()] {
            match ch {
                Some(v) => {
                    eat(v.len() as u64);
                    v.iter().for_each(|x| eat(x.to_bits()));
                }
                None => eat(u64::MAX),
            }
        }
    }
    h % 1_000_000
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress(len: u64, msg: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg:>12} [{bar:30}] {pos}/{len} {elapsed_precise} {wide_msg:.dim}",
    ) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb
}

/// Reads a model: a `.postcard` blob (with its `.json` twin beside it, whose f64 numbers are
/// used when they agree with the blob), or a `.json` twin directly.
pub fn read_model(path: &Path) -> Result<Model> {
    let bytes = std::fs::read(path)
        .map_err(|e| bad(format!("{}: cannot read the model: {e}", path.display())))?;
    model_from_bytes(&bytes, path)
}

/// The heading/track part of the model at `path`: from a format 3 blob, else from the
/// `track` key of its JSON twin; `None` when the model has none. Bad input when it does not
/// validate for the model's sample time.
pub fn read_track(path: &Path, model: &Model) -> Result<Option<TrackSpec>> {
    let is_json = path.extension().is_some_and(|e| e == "json");
    if !is_json {
        if let Ok(bytes) = std::fs::read(path) {
            if let Ok((_, Some(t))) = yawcast_shared::blob::decode_blob_with_track(&bytes) {
                return Ok(Some(t));
            }
        }
    }
    let twin = if is_json {
        path.to_path_buf()
    } else {
        path.with_extension("json")
    };
    let Ok(text) = std::fs::read_to_string(&twin) else {
        return Ok(None);
    };
    let v: serde_json::Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(_) => return Ok(None),
    };
    let Some(t) = v.get("track").filter(|t| !t.is_null()) else {
        return Ok(None);
    };
    let t: TrackSpec = serde_json::from_value(t.clone())
        .map_err(|e| bad(format!("{}: track: {e}", twin.display())))?;
    t.validate(model.ts as f32)
        .map_err(|e| bad(format!("{}: {e}", twin.display())))?;
    Ok(Some(t))
}

/// [`read_model`] on the bytes of `path` (already read): a `.json` twin, or a blob with the
/// twin beside it consulted as [`read_model`] does.
pub fn model_from_bytes(bytes: &[u8], path: &Path) -> Result<Model> {
    let is_json = path.extension().is_some_and(|e| e == "json");
    if is_json {
        return model_from_json(bytes, path);
    }
    let twin = path.with_extension("json");
    let spec = match yawcast_shared::blob::decode_blob(bytes) {
        Ok(spec) => spec,
        Err(yawcast_shared::blob::BlobError::UnsupportedVersion(v)) if v < FORMAT_VERSION => {
            // an older blob: the JSON twin holds the same model in f64, whatever the format
            let tb = std::fs::read(&twin).map_err(|_| {
                bad(format!(
                    "{}: model blob format {v} is older than this yawcast's ({FORMAT_VERSION}) \
                     and its JSON twin {} is not there: identify or export the model again",
                    path.display(),
                    twin.display()
                ))
            })?;
            eprintln!(
                "warning: {}: model blob format {v} is older than {FORMAT_VERSION}: the model is \
                 read from its JSON twin {}; export it again before loading it on the \
                 controller",
                path.display(),
                twin.display()
            );
            return model_from_json(&tb, &twin);
        }
        Err(e) => return Err(bad(format!("{}: {e}", path.display()))),
    };
    let from_blob = Model::from_spec(&spec).map_err(|e| bad(format!("{}: {e}", path.display())))?;
    if let Ok(tb) = std::fs::read(&twin) {
        if let Ok(m) = model_from_json(&tb, &twin) {
            // The twin must describe the same model as the blob (to f32 precision).
            if m.to_spec().ok().as_ref() == Some(&spec) {
                return Ok(m);
            }
            eprintln!(
                "warning: {} does not match {}; using the blob's f32 numbers",
                twin.display(),
                path.display()
            );
        }
    }
    Ok(from_blob)
}

fn model_from_json(bytes: &[u8], path: &Path) -> Result<Model> {
    let v: serde_json::Value = serde_json::from_slice(bytes)
        .map_err(|e| bad(format!("{}: not JSON: {e}", path.display())))?;
    // The twin may hold the model at the top level or under "model".
    let inner = v.get("model").cloned().unwrap_or(v);
    let m: Model = serde_json::from_value(inner)
        .map_err(|e| bad(format!("{}: not a yawcast model: {e}", path.display())))?;
    m.validate()
        .map_err(|e| bad(format!("{}: {e}", path.display())))?;
    // The same checks a blob gets on loading (magnitudes, stability of A and A − KC in the
    // controller's f32 numbers): a model that could not be exported is not used either.
    let spec = m
        .to_spec()
        .map_err(|e| bad(format!("{}: {e}", path.display())))?;
    spec.validate().map_err(|e| {
        bad(format!(
            "{}: the model fails the checks a model blob gets: {e}",
            path.display()
        ))
    })?;
    Ok(m)
}

/// Parses `--horizons 1,5,10,20,sim`.
pub fn parse_horizons(s: &str) -> Result<Vec<yawcast::identify::predict::Horizon>> {
    s.split(',')
        .map(|p| {
            yawcast::identify::predict::Horizon::parse(p).ok_or_else(|| {
                bad(format!(
                    "--horizons: `{p}` is not a horizon (a whole number ≥ 1 or `sim`)"
                ))
            })
        })
        .collect()
}

/// Checks that every k-step horizon is shorter than every record (a horizon as long as the
/// record predicts nothing from measurements: ask for `sim` instead).
pub fn check_horizons_fit(
    horizons: &[yawcast::identify::predict::Horizon],
    records: &[Record],
    paths: &[PathBuf],
) -> Result<()> {
    for h in horizons {
        let yawcast::identify::predict::Horizon::Steps(k) = *h else {
            continue;
        };
        for (rec, p) in records.iter().zip(paths) {
            if k >= rec.len() {
                return Err(bad(format!(
                    "{}: horizon {k} steps is not shorter than the record ({} samples); \
                     use a shorter horizon, or `sim` for pure simulation",
                    p.display(),
                    rec.len()
                )));
            }
        }
    }
    Ok(())
}

/// Smallest fit % reported as a result: below it the prediction error is more than 100 times
/// the record's own spread, i.e. the prediction diverges (−∞ %, −1e58 %, …).
pub const MIN_REPORTED_FIT: f64 = -1.0e4;

/// Errors (exit 1, a numerical failure) when a fit is not finite or the prediction diverges,
/// naming the record and horizon: such a number is never printed as a result.
pub fn check_fit(fit: f64, horizon: &str, path: &Path) -> Result<()> {
    if fit.is_finite() && fit >= MIN_REPORTED_FIT {
        return Ok(());
    }
    Err(anyhow::anyhow!(
        "{}: the model's prediction at horizon {horizon} diverges on this record (fit {fit:.3e} %): \
         the model does not describe these data (another ship, sample time or unit?)",
        path.display()
    ))
}

/// Checks a record against a model (sample time, length).
pub fn check_record_for_model(rec: &Record, model: &Model, path: &Path) -> Result<()> {
    let rel = (rec.ts - model.ts).abs() / model.ts;
    if rel > 1e-3 {
        return Err(bad(format!(
            "{}: sampled every {} s, the model every {} s (resample the record or identify a model at {} s)",
            path.display(),
            rec.ts,
            model.ts,
            rec.ts
        )));
    }
    let needed = 4 * model.n + 2;
    if rec.len() < needed {
        return Err(bad(format!(
            "{}: {} samples, at least {needed} needed for a model of order {}",
            path.display(),
            rec.len(),
            model.n
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seed_follows_the_records_not_the_clock() {
        let a = Record::from_uy("a", 0.5, vec![1.0, -1.0, 2.0], vec![0.1, 0.2, 0.3]);
        let mut b = a.clone();
        let s = records_seed([&a].into_iter());
        assert_eq!(s, records_seed([&a.clone()].into_iter()));
        assert!(s < 1_000_000);
        b.y[2] = 0.300_000_000_000_000_1;
        assert_ne!(s, records_seed([&b].into_iter()));
        b.y[2] = 0.3;
        b.psi = Some(vec![0.0; 3]);
        assert_ne!(s, records_seed([&b].into_iter()));
        let arg = SeedArg { seed: None };
        assert_eq!(arg.resolve_for(&[std::slice::from_ref(&a)]), s);
        assert_eq!(SeedArg { seed: Some(7) }.resolve_for(&[&[a]]), 7);
    }

    #[test]
    fn diverging_or_non_finite_fits_are_errors_naming_record_and_horizon() {
        let p = Path::new("trials/t1.csv");
        assert!(check_fit(93.5, "10", p).is_ok());
        assert!(check_fit(-250.0, "sim", p).is_ok());
        for bad_fit in [f64::NEG_INFINITY, f64::NAN, -1.9e58, MIN_REPORTED_FIT - 1.0] {
            let e = check_fit(bad_fit, "sim", p).unwrap_err();
            let msg = e.to_string();
            assert!(
                msg.contains("trials/t1.csv") && msg.contains("horizon sim"),
                "{msg}"
            );
            assert!(
                !is_bad_input(&e),
                "a diverging prediction is a numerical failure (exit 1)"
            );
        }
    }
}
