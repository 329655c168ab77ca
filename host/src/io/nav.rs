//! Navigation channels of a record: ground velocity (speed and course over ground) and
//! position fixes (latitude/longitude, or north/east in metres), for the heading and track
//! prediction (`identify::track`).
//!
//! An empty or NaN navigation cell is a missing measurement: its correction is skipped and
//! counted, never guessed. Text that is not a number, a negative speed over ground, a latitude
//! or longitude out of range, or half of a pair of columns is an error naming the file, row
//! and column. Courses wrap through 360° freely (only their sine and cosine are used).

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Mean earth radius (m) of the local north/east projection of latitude and longitude.
pub const EARTH_RADIUS_M: f64 = 6_371_000.0;

/// Column names of the navigation channels in a measurement CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct NavColumns {
    /// Speed over ground (m/s) — the record's own speed column.
    pub sog: String,
    /// Course over ground (deg from north, clockwise).
    pub cog: String,
    /// Latitude (deg, north positive).
    pub lat: String,
    /// Longitude (deg, east positive).
    pub lon: String,
    /// Position north of an origin (m).
    pub north: String,
    /// Position east of an origin (m).
    pub east: String,
    /// Multiply the speed-over-ground column by this to get m/s (1 for m/s).
    pub sog_scale: f64,
}

impl Default for NavColumns {
    fn default() -> Self {
        NavColumns {
            sog: "u_mps".into(),
            cog: "cog_deg".into(),
            lat: "lat_deg".into(),
            lon: "lon_deg".into(),
            north: "north_m".into(),
            east: "east_m".into(),
            sog_scale: 1.0,
        }
    }
}

/// Bad navigation input.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NavError {
    /// A navigation cell is not acceptable.
    #[error("{path}: row {row}, column `{column}`: {what}")]
    BadCell {
        /// File concerned.
        path: PathBuf,
        /// 1-based data row.
        row: usize,
        /// Column name.
        column: String,
        /// What is wrong with it.
        what: String,
    },
    /// One column of a pair without the other.
    #[error("{path}: column `{found}` is there but `{missing}` is not: give both (or map them with --col-*)")]
    HalfPair {
        /// File concerned.
        path: PathBuf,
        /// The column present.
        found: String,
        /// The column missing.
        missing: String,
    },
    /// The navigation rows do not match the record's samples.
    #[error("{path}: {rows} navigation rows for {samples} samples")]
    Length {
        /// File concerned.
        path: PathBuf,
        /// Rows read.
        rows: usize,
        /// Samples of the record.
        samples: usize,
    },
    /// The CSV layer failed.
    #[error("{path}: {message}")]
    Csv {
        /// File concerned.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// The navigation channels of one record, per sample, in metres and m/s north/east.
#[derive(Debug, Clone, PartialEq)]
pub struct Nav {
    velocity: Option<Vec<[f64; 2]>>,
    fix: Option<Vec<[f64; 2]>>,
    reference: Vec<[f64; 2]>,
    /// Samples whose velocity or fix was missing (empty or NaN cell).
    pub missing: usize,
    /// Where the channels came from, for notes (`"u_mps + cog_deg, lat_deg/lon_deg"`).
    pub source: String,
}

impl Nav {
    /// Builds the channels of a record of sample time `ts` from a ground velocity per sample
    /// and/or a position per sample (NaN entries = missing). `None` when both are absent.
    /// The reference track the predictions are scored against is the positions when given,
    /// else the ground velocity integrated (a missing velocity holds the last one).
    ///
    /// ```
    /// use yawcast::io::nav::Nav;
    /// let v = vec![[1.0, 0.0], [f64::NAN, 0.0], [0.0, 2.0]];
    /// let nav = Nav::new(1.0, Some(v), None, "test").unwrap();
    /// assert_eq!(nav.missing, 1);
    /// assert!(nav.velocity(1).unwrap()[0].is_nan());
    /// assert_eq!(nav.reference().unwrap(), &[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]);
    /// assert!(Nav::new(1.0, None, None, "none").is_none());
    /// ```
    pub fn new(
        ts: f64,
        velocity: Option<Vec<[f64; 2]>>,
        fix: Option<Vec<[f64; 2]>>,
        source: &str,
    ) -> Option<Nav> {
        let bad = |p: &[f64; 2]| !(p[0].is_finite() && p[1].is_finite());
        let reference = match (&fix, &velocity) {
            (Some(f), _) => f.clone(),
            (None, Some(v)) => {
                let mut p = [0.0, 0.0];
                let mut last = [0.0, 0.0];
                let mut out = Vec::with_capacity(v.len());
                for vi in v {
                    out.push(p);
                    if !bad(vi) {
                        last = *vi;
                    }
                    p = [p[0] + ts * last[0], p[1] + ts * last[1]];
                }
                out
            }
            (None, None) => return None,
        };
        let n = reference.len();
        let missing = (0..n)
            .filter(|&t| {
                velocity.as_ref().is_some_and(|v| bad(&v[t]))
                    || fix.as_ref().is_some_and(|f| bad(&f[t]))
            })
            .count();
        Some(Nav {
            velocity,
            fix,
            reference,
            missing,
            source: source.to_string(),
        })
    }

    /// The ground velocity at sample `t` (components NaN when missing), `None` without the
    /// channel.
    pub fn velocity(&self, t: usize) -> Option<[f64; 2]> {
        self.velocity.as_ref().and_then(|v| v.get(t).copied())
    }

    /// The position fix at sample `t` (NaN when missing), `None` without the channel.
    pub fn fix(&self, t: usize) -> Option<[f64; 2]> {
        self.fix.as_ref().and_then(|v| v.get(t).copied())
    }

    /// The measured track (m) the predictions are scored against.
    pub fn reference(&self) -> Option<&[[f64; 2]]> {
        Some(&self.reference)
    }

    /// Whether the ground velocity is logged.
    pub fn has_velocity(&self) -> bool {
        self.velocity.is_some()
    }

    /// A warning when the speed over ground and the positions disagree by the factor of a
    /// unit mix-up: the distance the speed integrates to, against the distance the fixes
    /// travel (over steps of 10 samples, so position noise does not add up), 1.94 for knots
    /// and 3.6 for km/h read as m/s. `None` with one of the two channels missing, fewer than
    /// 100 m travelled, or a ratio that is no such factor.
    ///
    /// ```
    /// use yawcast::io::nav::Nav;
    /// // 600 s at 5 m/s north, the speed column in knots (9.72) read as m/s
    /// let v = vec![[5.0 * 3600.0 / 1852.0, 0.0]; 600];
    /// let fix: Vec<[f64; 2]> = (0..600).map(|t| [5.0 * t as f64, 0.0]).collect();
    /// let nav = Nav::new(1.0, Some(v), Some(fix.clone()), "test").unwrap();
    /// assert!(nav.speed_unit_warning(1.0).unwrap().contains("--speed-unit kn"));
    /// let nav = Nav::new(1.0, Some(vec![[5.0, 0.0]; 600]), Some(fix), "test").unwrap();
    /// assert_eq!(nav.speed_unit_warning(1.0), None);
    /// ```
    pub fn speed_unit_warning(&self, ts: f64) -> Option<String> {
        const STEP: usize = 10;
        let (v, f) = (self.velocity.as_ref()?, self.fix.as_ref()?);
        let ok = |p: &[f64; 2]| p[0].is_finite() && p[1].is_finite();
        let (mut by_speed, mut by_fix) = (0.0, 0.0);
        let mut t = 0;
        while t + STEP < f.len().min(v.len()) {
            let (a, b) = (f[t], f[t + STEP]);
            let seg = &v[t..t + STEP];
            if ok(&a) && ok(&b) && seg.iter().all(ok) {
                by_fix += (b[0] - a[0]).hypot(b[1] - a[1]);
                by_speed += seg.iter().map(|p| p[0].hypot(p[1]) * ts).sum::<f64>();
            }
            t += STEP;
        }
        if by_fix < 100.0 {
            return None;
        }
        let ratio = by_speed / by_fix;
        let unit = [(3600.0 / 1852.0, "kn", "knots"), (3.6, "kmh", "km/h")]
            .into_iter()
            .find(|(k, _, _)| (ratio / k - 1.0).abs() < 0.1)?;
        Some(format!(
            "the speed over ground integrates to {ratio:.2} times the distance the positions \
             travel: if it is in {}, give --speed-unit {}",
            unit.2, unit.1
        ))
    }

    /// Whether position fixes are logged.
    pub fn has_fix(&self) -> bool {
        self.fix.is_some()
    }
}

/// Ground velocity `(v_n, v_e)` from speed `sog` (m/s) and course `cog_deg`.
///
/// ```
/// use yawcast::io::nav::ground_velocity;
/// let v = ground_velocity(2.0, 450.0); // 450° = 90°: due east
/// assert!(v[0].abs() < 1e-12 && (v[1] - 2.0).abs() < 1e-12);
/// ```
pub fn ground_velocity(sog: f64, cog_deg: f64) -> [f64; 2] {
    let (s, c) = cog_deg.to_radians().sin_cos();
    [sog * c, sog * s]
}

/// Local north/east metres of `(lat, lon)` about `origin` (equirectangular, fine over a
/// trial's few kilometres; longitude differences wrap through ±180°).
///
/// ```
/// use yawcast::io::nav::{local_metres, EARTH_RADIUS_M};
/// let p = local_metres([60.0, 10.0], [60.001, 10.0]);
/// assert!((p[0] - EARTH_RADIUS_M * 0.001f64.to_radians()).abs() < 1e-6 && p[1] == 0.0);
/// let q = local_metres([0.0, 179.9995], [0.0, -179.9995]); // across the date line
/// assert!((q[1] - EARTH_RADIUS_M * 0.001f64.to_radians()).abs() < 1e-3);
/// ```
pub fn local_metres(origin: [f64; 2], p: [f64; 2]) -> [f64; 2] {
    let dlat = p[0] - origin[0];
    let dlon = (p[1] - origin[1] + 540.0).rem_euclid(360.0) - 180.0;
    [
        EARTH_RADIUS_M * dlat.to_radians(),
        EARTH_RADIUS_M * origin[0].to_radians().cos() * dlon.to_radians(),
    ]
}

/// Reads the navigation columns of a measurement CSV (`text`, `path` only labels errors) for
/// a record of `samples` samples and sample time `ts`. `Ok(None)` when the file has neither a
/// course column with the speed column nor a position pair.
///
/// # Errors
/// [`NavError`] naming file, row and column (module docs).
///
/// ```
/// use yawcast::io::nav::{parse_nav_csv, NavColumns};
/// let txt = "t_s,delta_deg,r_degps,u_mps,cog_deg\n0,0,0,1.0,359\n1,0,0,1.0,\n2,0,0,1.0,1\n";
/// let nav = parse_nav_csv(txt, "x.csv".as_ref(), &NavColumns::default(), 3, 1.0)
///     .unwrap().unwrap();
/// assert_eq!(nav.missing, 1);
/// assert!((nav.velocity(0).unwrap()[0] - 1.0).abs() < 1e-3);
/// // the same speeds in knots
/// let kn = NavColumns { sog_scale: 1852.0 / 3600.0, ..NavColumns::default() };
/// let nav = parse_nav_csv(txt, "x.csv".as_ref(), &kn, 3, 1.0).unwrap().unwrap();
/// assert!((nav.velocity(0).unwrap()[0] - 0.514).abs() < 1e-3);
/// let bad = "t_s,delta_deg,r_degps,u_mps,cog_deg\n0,0,0,-1.0,3\n";
/// let e = parse_nav_csv(bad, "x.csv".as_ref(), &NavColumns::default(), 1, 1.0).unwrap_err();
/// assert_eq!(e.to_string(), "x.csv: row 1, column `u_mps`: speed over ground -1 m/s is negative");
/// ```
pub fn parse_nav_csv(
    text: &str,
    path: &Path,
    cols: &NavColumns,
    samples: usize,
    ts: f64,
) -> Result<Option<Nav>, NavError> {
    let csv_err = |e: csv::Error| NavError::Csv {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let (dialect, mut rdr, headers) = crate::io::data::Dialect::table(text).map_err(csv_err)?;
    let find = |c: &str| headers.iter().position(|h| h == c);
    let pair = |a: &str, b: &str| -> Result<Option<(usize, usize)>, NavError> {
        match (find(a), find(b)) {
            (Some(i), Some(j)) => Ok(Some((i, j))),
            (None, None) => Ok(None),
            (Some(_), None) => Err(NavError::HalfPair {
                path: path.to_path_buf(),
                found: a.to_string(),
                missing: b.to_string(),
            }),
            (None, Some(_)) => Err(NavError::HalfPair {
                path: path.to_path_buf(),
                found: b.to_string(),
                missing: a.to_string(),
            }),
        }
    };
    let vel_cols = match (find(&cols.sog), find(&cols.cog)) {
        (Some(i), Some(j)) => Some((i, j)),
        (None, Some(_)) => {
            return Err(NavError::HalfPair {
                path: path.to_path_buf(),
                found: cols.cog.clone(),
                missing: cols.sog.clone(),
            })
        }
        _ => None,
    };
    let latlon = pair(&cols.lat, &cols.lon)?;
    let ne = if latlon.is_some() {
        None
    } else {
        pair(&cols.north, &cols.east)?
    };
    if vel_cols.is_none() && latlon.is_none() && ne.is_none() {
        return Ok(None);
    }
    let mut vel = Vec::new();
    let mut pos = Vec::new();
    let mut origin: Option<[f64; 2]> = None;
    for (i, row) in rdr.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let rown = i + 1;
        let cell = |idx: usize| -> Result<f64, NavError> {
            let s = row.get(idx).unwrap_or("");
            if s.is_empty() {
                return Ok(f64::NAN);
            }
            match dialect.number(s) {
                Ok(v) if !v.is_infinite() => Ok(v),
                _ => Err(NavError::BadCell {
                    path: path.to_path_buf(),
                    row: rown,
                    column: headers[idx].clone(),
                    what: format!("expected a number (or an empty cell), found `{s}`"),
                }),
            }
        };
        let bad = |idx: usize, what: String| NavError::BadCell {
            path: path.to_path_buf(),
            row: rown,
            column: headers[idx].clone(),
            what,
        };
        if let Some((is, ic)) = vel_cols {
            let sog = cell(is)?;
            if sog < 0.0 {
                return Err(bad(is, format!("speed over ground {sog} m/s is negative")));
            }
            vel.push(ground_velocity(sog * cols.sog_scale, cell(ic)?));
        }
        if let Some((ia, io)) = latlon {
            let (lat, lon) = (cell(ia)?, cell(io)?);
            if lat.abs() > 90.0 {
                return Err(bad(ia, format!("latitude {lat} is outside ±90°")));
            }
            if lon.abs() > 180.0 {
                return Err(bad(io, format!("longitude {lon} is outside ±180°")));
            }
            if lat.is_finite() && lon.is_finite() {
                let o = *origin.get_or_insert([lat, lon]);
                pos.push(local_metres(o, [lat, lon]));
            } else {
                pos.push([f64::NAN, f64::NAN]);
            }
        } else if let Some((i_n, i_e)) = ne {
            pos.push([cell(i_n)?, cell(i_e)?]);
        }
    }
    let rows = vel.len().max(pos.len());
    if rows != samples {
        return Err(NavError::Length {
            path: path.to_path_buf(),
            rows,
            samples,
        });
    }
    let mut source = Vec::new();
    if vel_cols.is_some() {
        source.push(format!("{} + {}", cols.sog, cols.cog));
    }
    if latlon.is_some() {
        source.push(format!("{}/{}", cols.lat, cols.lon));
    } else if ne.is_some() {
        source.push(format!("{}/{}", cols.north, cols.east));
    }
    Ok(Nav::new(
        ts,
        vel_cols.map(|_| vel),
        (!pos.is_empty()).then_some(pos),
        &source.join(", "),
    ))
}

/// The measurement CSV of a record ([`csv_text`](crate::io::data::csv_text)) with the
/// navigation columns `cog_deg,north_m,east_m` appended (one value per sample each).
///
/// ```
/// use yawcast::io::{data::Record, nav::csv_text_with_nav};
/// let r = Record::from_uy("r", 1.0, vec![0.0, 1.0], vec![0.5, 0.25]);
/// let t = csv_text_with_nav(&r, &[359.5, 0.5], &[0.0, 1.0], &[0.0, -0.25]);
/// assert_eq!(t, "t_s,delta_deg,r_degps,cog_deg,north_m,east_m\n0,0,0.5,359.5,0,0\n1,1,0.25,0.5,1,-0.25\n");
/// ```
pub fn csv_text_with_nav(
    rec: &crate::io::data::Record,
    cog_deg: &[f64],
    north_m: &[f64],
    east_m: &[f64],
) -> String {
    // the course is written here, once, whether or not the record carries it
    let bare = crate::io::data::Record {
        cog: None,
        ..rec.clone()
    };
    let base = crate::io::data::csv_text(&bare);
    let mut out = String::with_capacity(base.len() + 32 * rec.len());
    for (i, line) in base.lines().enumerate() {
        out.push_str(line);
        if i == 0 {
            out.push_str(",cog_deg,north_m,east_m");
        } else {
            let j = i - 1;
            let at = |v: &[f64]| v.get(j).copied().unwrap_or(f64::NAN);
            out.push_str(&format!(",{},{},{}", at(cog_deg), at(north_m), at(east_m)));
        }
        out.push('\n');
    }
    out
}

/// The navigation channels of an NMEA record: the ground velocity from its speed over ground
/// (`VTG`) and the course (`VTG`, else `RMC`), the positions (`GGA`, else `RMC`) in metres
/// about the first fix; `None` when the log has neither.
///
/// ```
/// use yawcast::io::{data::Record, nav::from_nmea, nmea::NmeaNav};
/// let mut r = Record::from_uy("r", 1.0, vec![0.0; 3], vec![0.0; 3]);
/// r.speed = Some(vec![2.0; 3]);
/// let nn = NmeaNav { course: Some(vec![90.0, f64::NAN, 90.0]), position: None };
/// let nav = from_nmea(&r, &nn).unwrap();
/// assert_eq!(nav.missing, 1);
/// assert!((nav.velocity(0).unwrap()[1] - 2.0).abs() < 1e-12);
/// ```
pub fn from_nmea(rec: &crate::io::data::Record, nn: &crate::io::nmea::NmeaNav) -> Option<Nav> {
    let velocity = match (&rec.speed, &nn.course) {
        (Some(sog), Some(cog)) => Some(
            sog.iter()
                .zip(cog)
                .map(|(s, c)| ground_velocity(*s, *c))
                .collect::<Vec<_>>(),
        ),
        _ => None,
    };
    let fix = nn.position.as_ref().map(|p| {
        let origin = p
            .iter()
            .find(|q| q[0].is_finite() && q[1].is_finite())
            .copied();
        p.iter()
            .map(|q| match origin {
                Some(o) if q[0].is_finite() && q[1].is_finite() => local_metres(o, *q),
                _ => [f64::NAN, f64::NAN],
            })
            .collect::<Vec<_>>()
    });
    let mut source = Vec::new();
    if velocity.is_some() {
        source.push("VTG speed and course");
    }
    if fix.is_some() {
        source.push("GGA/RMC positions");
    }
    Nav::new(rec.ts, velocity, fix, &source.join(", "))
}
