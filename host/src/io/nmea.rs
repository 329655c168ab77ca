//! NMEA 0183 trial logs → uniformly sampled [`Record`]s.
//!
//! # Sentences read
//!
//! | sentence | channel | unit conversion |
//! |---|---|---|
//! | `$--ROT` rate of turn | yaw rate `r` (required; not read with [`NmeaOptions::rate_from_heading`]) | deg/min → deg/s; `-` = bow to port |
//! | `$--RSA` rudder sensor angle | angle `δ` (required) | deg; both sensors valid → their mean |
//! | `$--HDT` true heading | heading `ψ` | deg (unwrapped) |
//! | `$--HDG` magnetic heading | heading `ψ` when no HDT | sensor + deviation + variation (E +) |
//! | `$--VTG` course/speed over ground | speed `u`; course `cog` (and navigation) | knots (or km/h) → m/s; deg true |
//! | `$--MWV` wind speed and angle | relative wind | `R` reference only; N/M/K/S → m/s |
//! | `$--ZDA`, `$--RMC` | the clock | UTC time and date |
//! | `$--GGA` (else `$--RMC`) | position (navigation) | latitude, longitude in degrees (valid fixes only) |
//! | `$--RMC` | course `cog` (and navigation) when there is no `VTG` | deg true |
//!
//! The navigation channels (course over ground, position) never shape the record: they are
//! read by [`parse_nmea_nav`] onto the record's own grid, a gap in them leaving `NaN` (a
//! skipped correction) rather than an error. The course over ground read so also fills the
//! record's [`Record::cog`] (what `diagnose` reads the current across the track and the true
//! wind from, as from a CSV `cog_deg` column).
//!
//! HDT, VTG, MWV, ZDA and RMC are parsed by the `nmea` crate; ROT, RSA and HDG by the small
//! parsers here ([`parse_rot`], [`parse_rsa`], [`parse_hdg`]). Other sentences are checked
//! for their checksum and otherwise ignored. Text before the `$` on a line (a logger's own
//! time stamp) is ignored.
//!
//! # Time
//!
//! Sentences carry no time of their own, so the log needs a clock:
//!
//! - [`Clock::Log`] (default): the `ZDA` sentences (else `RMC`) are the clock. The samples of a
//!   channel between two clock sentences are spread evenly over that interval. When a channel
//!   has fewer than half the samples its usual rate predicts in an interval, the interval holds
//!   a gap: its samples keep the usual spacing from the interval start, and the gap shows up in
//!   the gap check below. Sentences before the first clock sentence are dropped.
//! - [`Clock::Rate`]`(hz)`: no clock in the log; the k-th `ROT` sentence is at `k/hz` seconds and
//!   every other sentence takes the time of the latest `ROT`. Gaps cannot be seen this way.
//!
//! # Resampling
//!
//! Every channel present is linearly interpolated (heading and wind angle after unwrapping)
//! onto a uniform grid of step [`NmeaOptions::ts`] (default: the usual `ROT` spacing, rounded
//! to 1 ms; the heading's with [`NmeaOptions::rate_from_heading`], whose yaw rate is then the
//! heading's change over each grid step) over the time span where every present channel has data. `t_s` counts from the
//! first grid point. A channel whose samples are further apart than the gap limit anywhere
//! in that span is an error naming the channel, the clock time and line where the gap starts,
//! and its length. The limit is [`NmeaOptions::max_gap`], by default the larger of two grid
//! steps and 2.5 times the channel's usual spacing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::io::data::{days_from_civil, Record};

mod fields;
mod grid;

use grid::{interp_gaps, median_step, resample};

pub use fields::{checksum, looks_like_nmea, parse_hdg, parse_rot, parse_rsa};

/// Where sample times come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clock {
    /// `ZDA` (else `RMC`) sentences in the log.
    Log,
    /// No clock: `ROT` sentences arrive at this rate (Hz).
    Rate(f64),
}

/// How to read a log.
#[derive(Debug, Clone, PartialEq)]
pub struct NmeaOptions {
    /// The clock.
    pub clock: Clock,
    /// Grid step (s); `None` = the usual `ROT` spacing.
    pub ts: Option<f64>,
    /// Largest tolerated spacing of a channel's samples (s); `None` = see module docs.
    pub max_gap: Option<f64>,
    /// Drop sentences with a bad or missing checksum instead of failing.
    pub skip_bad_checksums: bool,
    /// No rate of turn: the yaw rate is the heading's change over each grid step
    /// ([`crate::io::data::heading_rate`]); `ROT` sentences are not read, `HDT`/`HDG` are
    /// required and set the grid step. Needs the log's clock ([`Clock::Log`]).
    pub rate_from_heading: bool,
}

impl Default for NmeaOptions {
    fn default() -> Self {
        NmeaOptions {
            clock: Clock::Log,
            ts: None,
            max_gap: None,
            skip_bad_checksums: false,
            rate_from_heading: false,
        }
    }
}

/// Errors reading an NMEA log.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NmeaError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The checksum after `*` does not match the sentence, or is missing.
    #[error("{path}: line {line}: bad checksum: {detail} (pass --skip-bad-checksums to drop such lines)")]
    Checksum {
        /// File concerned.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was found and expected.
        detail: String,
    },
    /// A sentence of a type we read has a field we cannot read.
    #[error("{path}: line {line}: {sentence}: {message}")]
    Malformed {
        /// File concerned.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Sentence type, e.g. `ROT`.
        sentence: String,
        /// What is wrong.
        message: String,
    },
    /// The clock runs backwards.
    #[error("{path}: line {line}: clock goes back from {from} to {to}")]
    ClockBackwards {
        /// File concerned.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Previous clock time (hh:mm:ss.ss).
        from: String,
        /// This clock time.
        to: String,
    },
    /// The log has no usable clock.
    #[error("{path}: {message}")]
    NoClock {
        /// File concerned.
        path: PathBuf,
        /// What is missing and what to do.
        message: String,
    },
    /// A required channel has no valid sample.
    #[error("{path}: no valid {sentence} sentence ({what}); it is required{hint}")]
    Missing {
        /// File concerned.
        path: PathBuf,
        /// Sentence type.
        sentence: &'static str,
        /// What it carries.
        what: &'static str,
        /// What else would do, with its leading separator (empty when nothing would).
        hint: &'static str,
    },
    /// A channel has a hole longer than the gap limit.
    #[error("{path}: gap of {length:.2} s in {sentence} ({what}) after {at} (line {line}); the limit is {limit:.2} s (--max-gap)")]
    Gap {
        /// File concerned.
        path: PathBuf,
        /// Sentence type of the channel.
        sentence: &'static str,
        /// What it carries.
        what: &'static str,
        /// Clock time of the last sample before the gap (hh:mm:ss.ss).
        at: String,
        /// 1-based line of that sample.
        line: usize,
        /// Length of the gap (s).
        length: f64,
        /// The limit in force (s).
        limit: f64,
    },
    /// Too few grid points.
    #[error("{path}: only {found} samples after resampling, at least {needed} needed")]
    TooShort {
        /// File concerned.
        path: PathBuf,
        /// Samples found.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A bad option value.
    #[error("{0}")]
    Option(String),
}

/// The channels of a record, in the order they are resampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Chan {
    Rate,
    Angle,
    Heading,
    Speed,
    WindSpeed,
    WindAngle,
    /// Course over ground (navigation).
    Course,
    /// Latitude (navigation).
    Lat,
    /// Longitude (navigation).
    Lon,
}

impl Chan {
    /// The navigation channels, read beside the record, never into it.
    fn is_nav(self) -> bool {
        matches!(self, Chan::Course | Chan::Lat | Chan::Lon)
    }
    fn sentence(self) -> &'static str {
        match self {
            Chan::Rate => "ROT",
            Chan::Angle => "RSA",
            Chan::Heading => "HDT/HDG",
            Chan::Speed => "VTG",
            Chan::WindSpeed | Chan::WindAngle => "MWV",
            Chan::Course => "VTG/RMC",
            Chan::Lat | Chan::Lon => "GGA/RMC",
        }
    }
    fn what(self) -> &'static str {
        match self {
            Chan::Rate => "rate of turn",
            Chan::Angle => "rudder angle",
            Chan::Heading => "heading",
            Chan::Speed => "speed over ground",
            Chan::WindSpeed => "relative wind speed",
            Chan::WindAngle => "relative wind angle",
            Chan::Course => "course over ground",
            Chan::Lat => "latitude",
            Chan::Lon => "longitude",
        }
    }
    fn angular(self) -> bool {
        matches!(self, Chan::Heading | Chan::WindAngle | Chan::Course)
    }
}

/// One parsed sentence that matters: a clock tick or a channel value.
#[derive(Debug, Clone, Copy)]
enum Item {
    Clock(f64),
    Value(Chan, f64),
    /// A ROT tick when the clock is the ROT count (value may be invalid).
    RotTick,
}

/// Reads an NMEA 0183 log into a uniformly sampled record.
///
/// # Errors
/// [`NmeaError`] naming the file, line, sentence or gap.
pub fn read_nmea(path: &Path, opts: &NmeaOptions) -> Result<Record, NmeaError> {
    let bytes = std::fs::read(path).map_err(|source| NmeaError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = crate::io::data::decode_text(&bytes);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse_nmea(&text, path, &name, opts)
}

/// Parses NMEA log text (`path` only labels errors).
///
/// # Errors
/// As [`read_nmea`].
///
/// ```
/// use yawcast::io::nmea::{parse_nmea, NmeaOptions, Clock};
/// let log = "$HEROT,60.0,A*1D\n$IIRSA,5.0,A,,V*7C\n$HEROT,120.0,A*28\n$IIRSA,6.0,A,,V*7F\n\
///            $HEROT,60.0,A*1D\n$IIRSA,5.0,A,,V*7C\n";
/// let opts = NmeaOptions { clock: Clock::Rate(2.0), ..NmeaOptions::default() };
/// let r = parse_nmea(log, "x.nmea".as_ref(), "x", &opts).unwrap();
/// assert_eq!(r.ts, 0.5);
/// assert_eq!(r.y, vec![1.0, 2.0, 1.0]);
/// assert_eq!(r.u, vec![5.0, 6.0, 5.0]);
/// ```
pub fn parse_nmea(
    text: &str,
    path: &Path,
    name: &str,
    opts: &NmeaOptions,
) -> Result<Record, NmeaError> {
    if let Clock::Rate(hz) = opts.clock {
        if opts.rate_from_heading {
            return Err(NmeaError::Option(
                "the rate from the heading needs the log's ZDA/RMC clock; --nmea-rate counts \
                 ROT sentences"
                    .to_string(),
            ));
        }
        if !(hz.is_finite() && hz > 0.0) {
            return Err(NmeaError::Option(format!(
                "the ROT rate must be a positive number of Hz, found {hz}"
            )));
        }
    }
    for (v, what) in [(opts.ts, "grid step"), (opts.max_gap, "gap limit")] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(NmeaError::Option(format!(
                    "the {what} must be a positive number of seconds, found {v}"
                )));
            }
        }
    }
    let all = scan(text, path, opts)?;
    let items: Vec<(usize, Item)> = all
        .iter()
        .copied()
        .filter(|(_, it)| !matches!(it, Item::Value(c, _) if c.is_nav()))
        .collect();
    let series = timestamp(&items, path, opts)?;
    let mut rec = resample(series, path, name, opts)?;
    // the course over ground on the record's own grid, as `parse_nmea_nav` reads it (`NaN`
    // where missing): the ground-velocity channels of `diagnose` read it from the record
    if let Ok(all) = timestamp(&all, path, opts) {
        rec.cog = nav_on_grid(&all, opts, &rec).course;
    }
    Ok(rec)
}

/// The navigation channels of an NMEA log on the grid of its record `rec` (as
/// [`parse_nmea`] made it with the same options): the course over ground (deg) and the
/// position `[lat, lon]` (deg), each `None` when the log has none. Grid points outside a
/// channel's span or inside a hole longer than the gap limit are `NaN` (missing).
///
/// # Errors
/// As [`parse_nmea`] (the same log is read).
pub fn parse_nmea_nav(
    text: &str,
    path: &Path,
    opts: &NmeaOptions,
    rec: &Record,
) -> Result<NmeaNav, NmeaError> {
    let items = scan(text, path, opts)?;
    let series = timestamp(&items, path, opts)?;
    Ok(nav_on_grid(&series, opts, rec))
}

/// The navigation channels of `series` (a whole log's, timestamped) on the grid of its
/// record `rec` ([`parse_nmea_nav`]).
fn nav_on_grid(series: &Series, opts: &NmeaOptions, rec: &Record) -> NmeaNav {
    // the record's grid starts where every record channel has data (as in `resample`)
    let t_start = series
        .iter()
        .filter(|(c, _)| !c.is_nav())
        .map(|(_, v)| v[0].0)
        .fold(f64::NEG_INFINITY, f64::max);
    let grid: Vec<f64> = (0..rec.len())
        .map(|i| t_start + i as f64 * rec.ts)
        .collect();
    let on_grid = |c: Chan| -> Option<Vec<f64>> {
        let v = series.get(&c)?;
        let limit = opts
            .max_gap
            .unwrap_or((2.0 * rec.ts).max(2.5 * median_step(v)));
        Some(interp_gaps(v, &grid, c.angular(), limit))
    };
    let course = on_grid(Chan::Course);
    let position = match (on_grid(Chan::Lat), on_grid(Chan::Lon)) {
        (Some(la), Some(lo)) => Some(la.into_iter().zip(lo).map(|(a, b)| [a, b]).collect()),
        _ => None,
    };
    NmeaNav { course, position }
}

/// The navigation channels of an NMEA log on its record's grid ([`parse_nmea_nav`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NmeaNav {
    /// Course over ground (deg true), `NaN` where missing.
    pub course: Option<Vec<f64>>,
    /// Position `[latitude, longitude]` (deg), `NaN` where missing.
    pub position: Option<Vec<[f64; 2]>>,
}

/// Pass 1: every line → items, checksums verified.
///
/// Long: one pass over the sentences with the per-talker state; each sentence type is a short
/// arm.
fn scan(text: &str, path: &Path, opts: &NmeaOptions) -> Result<Vec<(usize, Item)>, NmeaError> {
    let mut out = Vec::new();
    let has_hdt = text.contains("HDT,");
    let has_zda = text.contains("ZDA,");
    let has_vtg = text.contains("VTG,");
    let has_gga = text.contains("GGA,");
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let Some(start) = raw.find('$') else {
            continue;
        };
        let s = raw[start..].trim_end();
        let bad = |detail: String| NmeaError::Checksum {
            path: path.to_path_buf(),
            line,
            detail,
        };
        let (body, given) = match s.rfind('*') {
            Some(star) => (&s[1..star], Some(&s[star + 1..])),
            None => (&s[1..], None),
        };
        let computed = checksum(body);
        let ok = match given {
            None => Err(bad("no `*hh` checksum".into())),
            Some(g) => match u8::from_str_radix(g.trim(), 16) {
                Ok(v) if g.trim().len() == 2 && v == computed => Ok(()),
                _ => Err(bad(format!(
                    "the sentence says `{g}`, its characters give `{computed:02X}`"
                ))),
            },
        };
        if let Err(e) = ok {
            if opts.skip_bad_checksums {
                continue;
            }
            return Err(e);
        }
        if body.len() < 6 || !body.is_ascii() {
            continue;
        }
        let kind = &body[2..5];
        let fields = body.get(6..).unwrap_or("");
        let malformed = |message: String| NmeaError::Malformed {
            path: path.to_path_buf(),
            line,
            sentence: kind.to_string(),
            message,
        };
        match kind {
            "ROT" => {
                let v = parse_rot(fields).map_err(malformed)?;
                if matches!(opts.clock, Clock::Rate(_)) {
                    out.push((line, Item::RotTick));
                }
                if let Some(v) = v {
                    out.push((line, Item::Value(Chan::Rate, v)));
                }
            }
            "RSA" => {
                if let Some(v) = parse_rsa(fields).map_err(malformed)? {
                    out.push((line, Item::Value(Chan::Angle, v)));
                }
            }
            "HDG" if !has_hdt => {
                if let Some(v) = parse_hdg(fields).map_err(malformed)? {
                    out.push((line, Item::Value(Chan::Heading, v)));
                }
            }
            "HDT" | "VTG" | "MWV" | "ZDA" | "RMC" | "GGA" => {
                let parsed = nmea::parse_str(s)
                    .map_err(|e| malformed(format!("cannot read the sentence ({e:?})")))?;
                match parsed {
                    nmea::ParseResult::HDT(h) => {
                        if let Some(v) = h.heading {
                            out.push((line, Item::Value(Chan::Heading, f64::from(v))));
                        }
                    }
                    nmea::ParseResult::VTG(v) => {
                        if let Some(kn) = v.speed_over_ground {
                            out.push((line, Item::Value(Chan::Speed, knots(f64::from(kn)))));
                        }
                        if let Some(c) = v.true_course {
                            out.push((line, Item::Value(Chan::Course, f64::from(c))));
                        }
                    }
                    nmea::ParseResult::GGA(g) => {
                        use nmea::sentences::FixType;
                        let valid = !matches!(g.fix_type, None | Some(FixType::Invalid));
                        if let (true, Some(la), Some(lo)) = (valid, g.latitude, g.longitude) {
                            out.push((line, Item::Value(Chan::Lat, la)));
                            out.push((line, Item::Value(Chan::Lon, lo)));
                        }
                    }
                    nmea::ParseResult::MWV(w) => {
                        use nmea::sentences::mwv::{MwvReference, MwvWindSpeedUnits as U};
                        if w.data_valid && w.reference == Some(MwvReference::Relative) {
                            if let (Some(a), Some(sp), Some(unit)) =
                                (w.wind_direction, w.wind_speed, w.wind_speed_units)
                            {
                                let sp = f64::from(sp);
                                let mps = match unit {
                                    U::MetersPerSecond => sp,
                                    U::Knots => knots(sp),
                                    U::KilometersPerHour => sp / 3.6,
                                    U::MilesPerHour => sp * 0.447_04,
                                };
                                out.push((line, Item::Value(Chan::WindSpeed, mps)));
                                out.push((line, Item::Value(Chan::WindAngle, f64::from(a))));
                            }
                        }
                    }
                    nmea::ParseResult::ZDA(z) if opts.clock == Clock::Log => {
                        if let Some(t) = z.utc_time {
                            let day = match (z.year, z.month, z.day) {
                                (Some(y), Some(m), Some(d)) => {
                                    days_from_civil(i64::from(y), i64::from(m), i64::from(d))
                                }
                                _ => None,
                            };
                            out.push((line, Item::Clock(clock_seconds(t, day))));
                        }
                    }
                    nmea::ParseResult::RMC(r) => {
                        if opts.clock == Clock::Log && !has_zda {
                            if let Some(t) = r.fix_time {
                                use chrono::Datelike;
                                let day = r.fix_date.map(|d| {
                                    days_from_civil(
                                        i64::from(d.year()),
                                        i64::from(d.month()),
                                        i64::from(d.day()),
                                    )
                                });
                                out.push((line, Item::Clock(clock_seconds(t, day.flatten()))));
                            }
                        }
                        use nmea::sentences::rmc::RmcStatusOfFix;
                        if r.status_of_fix != RmcStatusOfFix::Invalid {
                            if let (false, Some(la), Some(lo)) = (has_gga, r.lat, r.lon) {
                                out.push((line, Item::Value(Chan::Lat, la)));
                                out.push((line, Item::Value(Chan::Lon, lo)));
                            }
                            if let (false, Some(c)) = (has_vtg, r.true_course) {
                                out.push((line, Item::Value(Chan::Course, f64::from(c))));
                            }
                        }
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

fn knots(kn: f64) -> f64 {
    kn * 1852.0 / 3600.0
}

fn clock_seconds(t: chrono::NaiveTime, day: Option<i64>) -> f64 {
    use chrono::Timelike;
    let s = f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9;
    match day {
        Some(d) => d as f64 * 86_400.0 + s,
        None => s,
    }
}

/// hh:mm:ss.ss of a clock value (seconds, possibly with a day offset).
fn hms(t: f64) -> String {
    let s = t.rem_euclid(86_400.0);
    let h = (s / 3600.0).floor();
    let m = ((s - h * 3600.0) / 60.0).floor();
    let sec = s - h * 3600.0 - m * 60.0;
    format!("{:02}:{:02}:{:05.2}", h as u32, m as u32, sec)
}

/// A channel's samples: (time, value, line).
type Series = BTreeMap<Chan, Vec<(f64, f64, usize)>>;

/// Pass 2: items → time-stamped series per channel.
///
/// Long: the timestamp rules of every sentence type side by side (date roll-over, gaps,
/// back-steps), each a short arm with its own error.
fn timestamp(
    items: &[(usize, Item)],
    path: &Path,
    opts: &NmeaOptions,
) -> Result<Series, NmeaError> {
    let mut series: Series = BTreeMap::new();
    if let Clock::Rate(hz) = opts.clock {
        let mut ticks = 0usize;
        let mut now = None;
        for &(line, it) in items {
            match it {
                Item::RotTick => {
                    now = Some(ticks as f64 / hz);
                    ticks += 1;
                }
                Item::Value(c, v) => {
                    if let Some(t) = now {
                        series.entry(c).or_default().push((t, v, line));
                    }
                }
                Item::Clock(_) => {}
            }
        }
        return Ok(series);
    }
    // Clock ticks, with midnight roll-over for undated clocks.
    let mut clocks: Vec<(usize, f64, usize)> = Vec::new(); // (item index, time, line)
    let mut roll = 0.0;
    for (idx, &(line, it)) in items.iter().enumerate() {
        if let Item::Clock(raw) = it {
            let mut t = raw + roll;
            if let Some(&(_, prev, _)) = clocks.last() {
                if raw < 86_400.0 && t < prev - 43_200.0 {
                    roll += 86_400.0;
                    t += 86_400.0;
                }
                if t < prev {
                    return Err(NmeaError::ClockBackwards {
                        path: path.to_path_buf(),
                        line,
                        from: hms(prev),
                        to: hms(t),
                    });
                }
                if t == prev {
                    continue;
                }
            }
            clocks.push((idx, t, line));
        }
    }
    if clocks.len() < 2 {
        return Err(NmeaError::NoClock {
            path: path.to_path_buf(),
            message: format!(
                "{} ZDA/RMC clock sentence(s) with a time; at least 2 are needed \
                 (or give the ROT rate with --nmea-rate HZ)",
                clocks.len()
            ),
        });
    }
    let mut dts: Vec<f64> = clocks.windows(2).map(|w| w[1].1 - w[0].1).collect();
    dts.sort_by(f64::total_cmp);
    let dt_med = dts[dts.len() / 2];
    // Items per interval, per channel. The interval after the last clock gets the median length.
    let n_int = clocks.len();
    let interval = |k: usize| -> (usize, usize, f64, f64) {
        let (i0, t0, _) = clocks[k];
        match clocks.get(k + 1) {
            Some(&(i1, t1, _)) => (i0, i1, t0, t1 - t0),
            None => (i0, items.len(), t0, dt_med),
        }
    };
    // Usual rate of each channel: median over normal-length intervals of count/Δ.
    let mut rates: BTreeMap<Chan, Vec<f64>> = BTreeMap::new();
    let mut counts: Vec<BTreeMap<Chan, usize>> = Vec::with_capacity(n_int);
    for k in 0..n_int {
        let (i0, i1, _, dt) = interval(k);
        let mut c: BTreeMap<Chan, usize> = BTreeMap::new();
        for &(_, it) in &items[i0..i1] {
            if let Item::Value(ch, _) = it {
                *c.entry(ch).or_default() += 1;
            }
        }
        if dt <= 1.5 * dt_med && k + 1 < n_int {
            for (&ch, &m) in &c {
                rates.entry(ch).or_default().push(m as f64 / dt);
            }
        }
        counts.push(c);
    }
    let rate_of = |ch: Chan| -> f64 {
        match rates.get(&ch) {
            Some(v) if !v.is_empty() => {
                let mut v = v.clone();
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            }
            _ => 1.0 / dt_med,
        }
    };
    for k in 0..n_int {
        let (i0, i1, t0, dt) = interval(k);
        let mut seen: BTreeMap<Chan, usize> = BTreeMap::new();
        for &(line, it) in &items[i0..i1] {
            if let Item::Value(ch, v) = it {
                let m = counts[k][&ch];
                let j = seen.entry(ch).or_default();
                let rate = rate_of(ch);
                let step = if (m as f64) >= 0.5 * rate * dt {
                    dt / m as f64
                } else {
                    1.0 / rate
                };
                series
                    .entry(ch)
                    .or_default()
                    .push((t0 + *j as f64 * step, v, line));
                *j += 1;
            }
        }
    }
    Ok(series)
}

#[cfg(test)]
pub(crate) mod tests;
