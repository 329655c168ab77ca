//! The measurement CSV: reading (column names, separators, resampling) and writing.

use std::path::Path;

use super::timestamp::Clock;
use super::{check_uniform, unwrap_degrees, write_atomic, DataError, Record};

/// Column names of the measurement CSV (overridable for other loggers).
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// Time (s).
    pub t: String,
    /// Commanded angle.
    pub u: String,
    /// Yaw rate.
    pub y: String,
    /// Heading (optional column).
    pub psi: String,
    /// Speed over ground (optional column).
    pub speed: String,
    /// Relative wind speed (optional column).
    pub wind_speed: String,
    /// Relative wind angle (optional column).
    pub wind_angle: String,
    /// Course over ground in degrees (optional column; an empty or `NaN` cell is a missing
    /// sample; not scaled by `angle_scale`, as the navigation reader takes it).
    pub cog: String,
    /// Multiply the angle columns (`u`, `psi`, `wind_angle`) by this to get degrees.
    pub angle_scale: f64,
    /// Multiply the yaw-rate column by this to get deg/s.
    pub rate_scale: f64,
    /// Multiply the speed columns (`speed`, `wind_speed`) by this to get m/s.
    pub speed_scale: f64,
    /// Multiply a numeric time column by this to get seconds (1e-3 for milliseconds; not
    /// applied to ISO 8601 date-times).
    pub time_scale: f64,
    /// Resample onto a uniform grid of this step (s) instead of requiring uniform time stamps.
    pub resample: Option<f64>,
    /// Fill up to this many missing samples in a row (empty or `NaN` cells) of the heading,
    /// speed and wind channels by interpolation ([`fill_gaps`]); 0: a missing sample is an
    /// error.
    pub fill_gaps: usize,
    /// No rate gyro: the yaw rate is the heading's change over each sample
    /// ([`heading_rate`]), and the yaw-rate column is not read.
    pub rate_from_heading: bool,
}

impl Default for Columns {
    fn default() -> Self {
        Columns {
            t: "t_s".into(),
            u: "delta_deg".into(),
            y: "r_degps".into(),
            psi: "psi_deg".into(),
            speed: "u_mps".into(),
            wind_speed: "wind_speed_mps".into(),
            wind_angle: "wind_angle_deg".into(),
            cog: "cog_deg".into(),
            angle_scale: 1.0,
            rate_scale: 1.0,
            speed_scale: 1.0,
            time_scale: 1.0,
            resample: None,
            rate_from_heading: false,
            fill_gaps: 0,
        }
    }
}

/// Reads a measurement CSV with the default column names.
///
/// # Errors
/// [`DataError`] naming the file, row and column for missing columns, non-numeric or
/// non-finite cells, non-monotonic or non-uniform time, or fewer than 2 samples.
pub fn read_csv(path: &Path) -> Result<Record, DataError> {
    read_csv_with(path, &Columns::default())
}

/// Reads a measurement CSV with the given column names and unit scales.
///
/// # Errors
/// As [`read_csv`].
pub fn read_csv_with(path: &Path, cols: &Columns) -> Result<Record, DataError> {
    let bytes = std::fs::read(path).map_err(|source| DataError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = decode_text(&bytes);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse_csv(&text, path, &name, cols)
}

/// Parses CSV text (`path` only labels errors).
///
/// # Errors
/// As [`read_csv`].
///
/// ```
/// use yawcast::io::data::{parse_csv, Columns};
/// let txt = "t_s,delta_deg,r_degps\n0,1,0\n1,1,0.5\n2,-1,0.2\n";
/// let r = parse_csv(txt, "x.csv".as_ref(), "x", &Columns::default()).unwrap();
/// assert_eq!(r.ts, 1.0);
/// assert_eq!(r.y, vec![0.0, 0.5, 0.2]);
/// ```
pub fn parse_csv(text: &str, path: &Path, name: &str, cols: &Columns) -> Result<Record, DataError> {
    let csv_err = |e: csv::Error| DataError::Csv {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let (dialect, mut rdr, headers) = Dialect::table(text).map_err(csv_err)?;
    for (j, h) in headers.iter().enumerate() {
        if let Some(k) = headers[..j].iter().position(|g| g == h) {
            return Err(DataError::DuplicateColumn {
                path: path.to_path_buf(),
                column: h.clone(),
                first: k + 1,
                second: j + 1,
            });
        }
    }
    let find = |c: &str| headers.iter().position(|h| h == c);
    let need = |c: &str| {
        find(c).ok_or_else(|| DataError::MissingColumn {
            path: path.to_path_buf(),
            column: c.to_string(),
            found: headers.join(","),
        })
    };
    let it = need(&cols.t)?;
    let iu = need(&cols.u)?;
    let ipsi = find(&cols.psi);
    let iy = if cols.rate_from_heading {
        // the rate is the heading's change (below); a rate column is not read
        need(&cols.psi)?;
        None
    } else {
        match (find(&cols.y), ipsi) {
            (Some(i), _) => Some(i),
            (None, Some(_)) => {
                return Err(DataError::NoRate {
                    path: path.to_path_buf(),
                    column: cols.y.clone(),
                    heading: cols.psi.clone(),
                    found: headers.join(","),
                })
            }
            (None, None) => Some(need(&cols.y)?),
        }
    };
    let isp = find(&cols.speed);
    let iws = find(&cols.wind_speed);
    let iwa = find(&cols.wind_angle);
    let icog = find(&cols.cog);
    let mut rec = Record {
        name: name.to_string(),
        psi: ipsi.map(|_| Vec::new()),
        speed: isp.map(|_| Vec::new()),
        wind_speed: iws.map(|_| Vec::new()),
        wind_angle: iwa.map(|_| Vec::new()),
        cog: icog.map(|_| Vec::new()),
        ..Record::default()
    };
    let mut clock = Clock::Seconds;
    for (i, row) in rdr.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let rown = i + 1;
        let cell = |idx: usize| -> Result<f64, DataError> {
            let s = row.get(idx).unwrap_or("");
            match dialect.number(s) {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(DataError::BadCell {
                    path: path.to_path_buf(),
                    row: rown,
                    column: headers[idx].clone(),
                    value: s.to_string(),
                }),
            }
        };
        // an optional channel's cell: empty or NaN is a dropout, kept as NaN to be filled
        // below where --fill-gaps allows, else an error that names the option
        let optional = |idx: usize| -> Result<f64, DataError> {
            let s = row.get(idx).unwrap_or("");
            if dropout(s) {
                if cols.fill_gaps > 0 {
                    return Ok(f64::NAN);
                }
                return Err(DataError::Dropout {
                    path: path.to_path_buf(),
                    row: rown,
                    column: headers[idx].clone(),
                    value: s.to_string(),
                });
            }
            cell(idx)
        };
        // the time: seconds, or ISO 8601 date-times or times of day when the first row
        // holds one (then seconds from that first stamp)
        let raw_t = row.get(it).unwrap_or("");
        if rown == 1 {
            clock = Clock::of(raw_t);
        }
        let last = rec.t.last().copied().unwrap_or(0.0);
        let number = |c: &str| dialect.number(c).ok().filter(|v| v.is_finite());
        let t = match clock.seconds(raw_t, number, cols.time_scale, last) {
            Some(t) => t,
            // a number's error names the cell as any other column's does
            None if clock == Clock::Seconds => cell(it)?,
            None => {
                return Err(DataError::BadTime {
                    path: path.to_path_buf(),
                    row: rown,
                    column: headers[it].clone(),
                    value: raw_t.to_string(),
                })
            }
        };
        rec.t.push(t);
        rec.u.push(cell(iu)? * cols.angle_scale);
        rec.y.push(match iy {
            Some(i) => cell(i)? * cols.rate_scale,
            None => 0.0,
        });
        if let (Some(i), Some(v)) = (ipsi, rec.psi.as_mut()) {
            v.push(optional(i)? * cols.angle_scale);
        }
        if let (Some(i), Some(v)) = (isp, rec.speed.as_mut()) {
            v.push(optional(i)? * cols.speed_scale);
        }
        if let (Some(i), Some(v)) = (iws, rec.wind_speed.as_mut()) {
            v.push(optional(i)? * cols.speed_scale);
        }
        if let (Some(i), Some(v)) = (iwa, rec.wind_angle.as_mut()) {
            v.push(optional(i)? * cols.angle_scale);
        }
        if let (Some(i), Some(v)) = (icog, rec.cog.as_mut()) {
            // a GPS drop-out leaves the course empty (or NaN): missing, not an error
            let s = row.get(i).unwrap_or("");
            let missing = dropout(s);
            // degrees whatever --angle-unit says, as the navigation reader takes it (and
            // with its words for a cell that is not a number)
            let c = if missing {
                f64::NAN
            } else {
                cell(i).map_err(|_| DataError::Csv {
                    path: path.to_path_buf(),
                    message: format!(
                        "row {rown}, column `{}`: expected a number (or an empty cell), \
                         found `{s}`",
                        headers[i]
                    ),
                })?
            };
            v.push(c);
        }
    }
    if rec.t.len() < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            found: rec.t.len(),
            needed: 2,
        });
    }
    if cols.fill_gaps > 0 {
        for (v, column, angle) in [
            (rec.psi.as_mut(), &cols.psi, true),
            (rec.speed.as_mut(), &cols.speed, false),
            (rec.wind_speed.as_mut(), &cols.wind_speed, false),
            (rec.wind_angle.as_mut(), &cols.wind_angle, true),
        ] {
            if let Some(v) = v {
                fill_gaps(v, cols.fill_gaps, angle).map_err(|(first, missing)| DataError::Gap {
                    path: path.to_path_buf(),
                    column: column.clone(),
                    first: first + 1,
                    missing,
                    limit: cols.fill_gaps,
                })?;
            }
        }
    }
    if let Some(psi) = rec.psi.as_mut() {
        unwrap_degrees(psi);
    }
    let mut rec = match cols.resample {
        Some(dt) => resample(&rec, dt, path)?,
        None => {
            rec.ts = check_uniform(&rec.t, path)?;
            rec
        }
    };
    if cols.rate_from_heading {
        if let Some(psi) = rec.psi.as_ref() {
            rec.y = heading_rate(psi, rec.ts);
        }
    }
    Ok(rec)
}

/// Whether a cell of an optional channel marks a sensor's drop-out: empty or `NaN`.
fn dropout(cell: &str) -> bool {
    cell.is_empty() || cell.eq_ignore_ascii_case("nan")
}

/// Fills the NaN samples of `v` (dropouts) by linear interpolation between their
/// neighbours — for an angle (deg) along the shorter way round — and holds the nearest
/// value before the first or after the last sample logged. A run of more than `limit`
/// NaN, or a channel with no value at all, is `Err((first index, run length))`.
///
/// ```
/// let mut v = vec![f64::NAN, 1.0, f64::NAN, f64::NAN, 4.0];
/// yawcast::io::data::fill_gaps(&mut v, 2, false).unwrap();
/// assert_eq!(v, vec![1.0, 1.0, 2.0, 3.0, 4.0]);
/// let mut a = vec![358.0, f64::NAN, 2.0];
/// yawcast::io::data::fill_gaps(&mut a, 1, true).unwrap();
/// assert_eq!(a[1], 360.0);
/// let mut long = vec![0.0, f64::NAN, f64::NAN, f64::NAN, 1.0];
/// assert_eq!(yawcast::io::data::fill_gaps(&mut long, 2, false), Err((1, 3)));
/// ```
///
/// # Errors
/// The first run of NaN longer than `limit`.
pub fn fill_gaps(v: &mut [f64], limit: usize, angle: bool) -> Result<(), (usize, usize)> {
    let mut i = 0;
    while i < v.len() {
        if !v[i].is_nan() {
            i += 1;
            continue;
        }
        let end = (i..v.len()).find(|&j| !v[j].is_nan()).unwrap_or(v.len());
        if end - i > limit {
            return Err((i, end - i));
        }
        match (i.checked_sub(1).map(|k| v[k]), v.get(end).copied()) {
            (Some(a), Some(b)) => {
                let d = if angle {
                    (b - a + 180.0).rem_euclid(360.0) - 180.0
                } else {
                    b - a
                };
                let n = (end - i + 1) as f64;
                for (k, x) in v[i..end].iter_mut().enumerate() {
                    *x = a + d * (k + 1) as f64 / n;
                }
            }
            (Some(a), None) => v[i..end].fill(a),
            (None, Some(b)) => v[i..end].fill(b),
            (None, None) => return Err((i, end - i)),
        }
        i = end;
    }
    Ok(())
}

/// The yaw rate a controller without a rate gyro forms from its (unwrapped) heading: the
/// change over each sample, `(ψ_t − ψ_{t−1})/Ts` (deg/s), the first sample taking the
/// second's — causal, so the controller can form the same measurement as it sails.
///
/// ```
/// let r = yawcast::io::data::heading_rate(&[10.0, 10.5, 11.5, 11.5], 0.5);
/// assert_eq!(r, vec![1.0, 1.0, 2.0, 0.0]);
/// ```
pub fn heading_rate(psi: &[f64], ts: f64) -> Vec<f64> {
    let mut r: Vec<f64> = psi.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
    if let Some(&first) = r.first() {
        r.insert(0, first);
    } else if !psi.is_empty() {
        r.push(0.0);
    }
    r
}

/// Resamples a record onto the uniform grid `t_0, t_0 + dt, …` within its time span: the
/// command zero-order held (it is held over each logged interval), every other channel
/// linearly interpolated (heading and wind angle after unwrapping). The time stamps only need
/// to increase; a logger's jitter, gaps and another rate are all absorbed.
///
/// # Errors
/// [`DataError::NonUniform`] naming the first row whose time does not increase,
/// [`DataError::TooShort`] when the grid holds fewer than 2 samples, and
/// [`DataError::Csv`] when `dt` is not a positive number.
///
/// ```
/// use yawcast::io::data::{resample, Record};
/// let mut r = Record::from_uy("r", 0.0, vec![1.0, 2.0, 3.0], vec![0.0, 1.0, 3.0]);
/// r.t = vec![0.0, 0.4, 1.1];
/// let g = resample(&r, 0.5, "r.csv".as_ref()).unwrap();
/// assert_eq!(g.t, vec![0.0, 0.5, 1.0]);
/// assert_eq!(g.u, vec![1.0, 2.0, 2.0]);
/// assert!((g.y[1] - (1.0 + 2.0 * 0.1 / 0.7)).abs() < 1e-12);
/// assert_eq!(g.ts, 0.5);
/// ```
pub fn resample(rec: &Record, dt: f64, path: &Path) -> Result<Record, DataError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(DataError::Csv {
            path: path.to_path_buf(),
            message: format!("--resample {dt}: expected a positive number of seconds"),
        });
    }
    if let Some(i) = rec
        .t
        .windows(2)
        .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(DataError::NonUniform {
            path: path.to_path_buf(),
            row: i + 2,
            step: rec.t[i + 1] - rec.t[i],
            expected: dt,
            what: "time must increase from row to row, even when resampling".into(),
        });
    }
    let (t0, t1) = (rec.t[0], rec.t[rec.t.len() - 1]);
    let grid = uniform_grid(t0, t1, dt);
    let n = grid.len();
    if n < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            found: n,
            needed: 2,
        });
    }
    // For each grid time, the logged interval [t_j, t_{j+1}) that holds it and where in it.
    let mut at = Vec::with_capacity(n);
    let mut j = 0;
    for &tg in &grid {
        while j + 2 < rec.t.len() && rec.t[j + 1] <= tg {
            j += 1;
        }
        let w = ((tg - rec.t[j]) / (rec.t[j + 1] - rec.t[j])).clamp(0.0, 1.0);
        at.push((j, w));
    }
    let held = |v: &[f64]| -> Vec<f64> {
        at.iter()
            .map(|&(j, w)| if w >= 1.0 { v[j + 1] } else { v[j] })
            .collect()
    };
    let linear = |v: &[f64]| -> Vec<f64> {
        at.iter()
            .map(|&(j, w)| v[j] + w * (v[j + 1] - v[j]))
            .collect()
    };
    let unwrapped = |v: &[f64]| {
        let mut v = v.to_vec();
        unwrap_degrees(&mut v);
        linear(&v)
    };
    Ok(Record {
        name: rec.name.clone(),
        ts: dt,
        t: grid,
        u: held(&rec.u),
        y: linear(&rec.y),
        psi: rec.psi.as_deref().map(unwrapped),
        speed: rec.speed.as_deref().map(linear),
        wind_speed: rec.wind_speed.as_deref().map(linear),
        wind_angle: rec.wind_angle.as_deref().map(unwrapped),
        cog: rec.cog.as_deref().map(|c| course(c, &at)),
    })
}

/// A course (deg) at the grid points `at` (interval and place in it): the unit vectors
/// interpolated, so a course through north stays near north; a missing end leaves the
/// point missing (`NaN`).
fn course(c: &[f64], at: &[(usize, f64)]) -> Vec<f64> {
    at.iter()
        .map(|&(j, w)| {
            let (s0, c0) = c[j].to_radians().sin_cos();
            let (s1, c1) = c[j + 1].to_radians().sin_cos();
            let (s, c) = (s0 + w * (s1 - s0), c0 + w * (c1 - c0));
            s.atan2(c).to_degrees().rem_euclid(360.0)
        })
        .collect()
}

/// A log file's bytes as text: UTF-8 (a byte-order mark dropped), or where they are not
/// valid UTF-8, Latin-1 — the Windows logger's `delta [°]` written in its own code page
/// reads as `delta [°]`, not as a replacement character no `--col-*` option can name.
///
/// ```
/// use yawcast::io::data::decode_text;
/// assert_eq!(decode_text(b"\xef\xbb\xbft_s,d [\xc2\xb0]"), "t_s,d [°]");
/// assert_eq!(decode_text(b"t_s,d [\xb0]"), "t_s,d [°]");
/// ```
pub fn decode_text(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    }
}

/// How a CSV text separates its fields, read from its header (the first line that is not
/// empty or a `#` comment): `,` as written by yawcast; `;` where the header has a `;` and
/// no `,` (the spreadsheet export of locales with a decimal comma); a tab where the header
/// has a tab and neither (a logger's or spreadsheet's tab-separated text). In `;`- and
/// tab-separated text a cell's decimal comma is read as a point (`1,5` is 1.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Dialect {
    /// The field separator.
    pub(crate) delimiter: u8,
    /// Whether a cell's `,` is its decimal point.
    pub(crate) decimal_comma: bool,
}

/// A table opened by [`Dialect::table`]: its dialect, a reader over its rows, its header.
pub(crate) type Table<'a> = (Dialect, csv::Reader<&'a [u8]>, Vec<String>);

impl Dialect {
    /// The dialect of `text` (type docs).
    pub(crate) fn of(text: &str) -> Dialect {
        let header = text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.starts_with('#'))
            .unwrap_or("");
        let delimiter = if header.contains(',') {
            b','
        } else if header.contains(';') {
            b';'
        } else if header.contains('\t') {
            b'\t'
        } else {
            b','
        };
        Dialect {
            delimiter,
            decimal_comma: delimiter != b',',
        }
    }

    /// A reader of `text` in this dialect: fields trimmed, `#` lines skipped.
    pub(crate) fn reader<'a>(&self, text: &'a str) -> csv::Reader<&'a [u8]> {
        csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .delimiter(self.delimiter)
            .from_reader(text.as_bytes())
    }

    /// A table's dialect, a reader over its rows and its header's names: what every reader
    /// of the records' tables opens with.
    pub(crate) fn table(text: &str) -> Result<Table<'_>, csv::Error> {
        let dialect = Dialect::of(text);
        let mut rdr = dialect.reader(text);
        let headers = rdr.headers()?.iter().map(str::to_string).collect();
        Ok((dialect, rdr, headers))
    }

    /// `cell` as a number, its decimal comma read as a point where the dialect has one.
    pub(crate) fn number(&self, cell: &str) -> Result<f64, std::num::ParseFloatError> {
        if self.decimal_comma {
            cell.replace(',', ".").parse::<f64>()
        } else {
            cell.parse::<f64>()
        }
    }
}

/// Writes a record as a measurement CSV ([`csv_text`]), atomically (temp file, then rename).
///
/// # Errors
/// [`DataError::Io`] when the file cannot be written.
pub fn write_csv(path: &Path, rec: &Record) -> Result<(), DataError> {
    write_atomic(path, csv_text(rec).as_bytes())
}

/// A record as a measurement CSV: the header, then one row per sample (numbers in Rust's
/// shortest round-trip form).
///
/// ```
/// let r = yawcast::io::data::Record::from_uy("r", 0.5, vec![1.0, -2.5], vec![0.125, 0.0]);
/// assert_eq!(yawcast::io::data::csv_text(&r), "t_s,delta_deg,r_degps\n0,1,0.125\n0.5,-2.5,0\n");
/// ```
pub fn csv_text(rec: &Record) -> String {
    let mut out = String::new();
    out.push_str("t_s,delta_deg,r_degps");
    let opt = [
        (&rec.psi, "psi_deg"),
        (&rec.speed, "u_mps"),
        (&rec.wind_speed, "wind_speed_mps"),
        (&rec.wind_angle, "wind_angle_deg"),
        (&rec.cog, "cog_deg"),
    ];
    for (v, name) in &opt {
        if v.is_some() {
            out.push(',');
            out.push_str(name);
        }
    }
    out.push('\n');
    for i in 0..rec.len() {
        out.push_str(&format!("{},{},{}", rec.t[i], rec.u[i], rec.y[i]));
        for (v, _) in &opt {
            if let Some(v) = v {
                out.push_str(&format!(",{}", v[i]));
            }
        }
        out.push('\n');
    }
    out
}

/// The uniform grid `t0, t0 + ts, …` up to `t1` (inclusive, to within 10⁻⁹ of a period), on
/// which a record logged at uneven times is resampled: empty when `t1 < t0`. The CSV and NMEA
/// readers both resample onto it, and each refuses a grid of fewer than 2 times with its own
/// error.
pub(crate) fn uniform_grid(t0: f64, t1: f64, ts: f64) -> Vec<f64> {
    if t1 < t0 {
        return Vec::new();
    }
    let n = ((t1 - t0) / ts + 1e-9).floor() as usize + 1;
    (0..n).map(|k| t0 + k as f64 * ts).collect()
}

#[cfg(test)]
mod tests {
    use super::uniform_grid;

    #[test]
    fn the_grid_reaches_the_last_time_to_within_a_rounding_and_no_further() {
        // 0.3 / 0.1 is 2.999…96 in binary: the last time still counts.
        let g = uniform_grid(0.0, 0.3, 0.1);
        assert_eq!(g.len(), 4);
        assert_eq!(g[3].to_bits(), (3.0f64 * 0.1).to_bits());
        // A time short of the next grid point by more than a rounding does not.
        assert_eq!(uniform_grid(10.0, 10.299, 0.1).len(), 3);
        assert_eq!(uniform_grid(5.0, 5.0, 1.0), vec![5.0]);
        assert!(uniform_grid(2.0, 1.0, 1.0).is_empty());
    }
}
