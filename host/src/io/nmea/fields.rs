//! The fields of single NMEA sentences: checksum, detection, and the ROT, RSA and HDG/HDT parsers.

/// XOR checksum of the characters between `$` and `*`.
///
/// ```
/// assert_eq!(yawcast::io::nmea::checksum("GPHDT,274.07,T"), 0x03);
/// ```
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |c, b| c ^ b)
}

/// Whether `text` looks like an NMEA log (its first non-blank line holds a `$` sentence
/// before any comma).
///
/// ```
/// use yawcast::io::nmea::looks_like_nmea;
/// assert!(looks_like_nmea("\n$HEROT,1.0,A*2A\n"));
/// assert!(!looks_like_nmea("t_s,delta_deg,r_degps\n"));
/// ```
pub fn looks_like_nmea(text: &str) -> bool {
    let Some(line) = text.lines().map(str::trim).find(|l| !l.is_empty()) else {
        return false;
    };
    match (line.find('$'), line.find(',')) {
        (Some(d), Some(c)) => d < c,
        (Some(_), None) => true,
        _ => false,
    }
}

/// Parses the fields of a `ROT` sentence (after `$--ROT,`, before `*`): the rate of turn in
/// deg/s, or `None` when the status is `V` (invalid) or the field is empty.
///
/// # Errors
/// A message when the rate is not a number or the status is not `A`/`V`.
///
/// ```
/// use yawcast::io::nmea::parse_rot;
/// assert_eq!(parse_rot("-12.0,A"), Ok(Some(-0.2)));
/// assert_eq!(parse_rot("3.0,V"), Ok(None));
/// assert!(parse_rot("fast,A").is_err());
/// ```
pub fn parse_rot(fields: &str) -> Result<Option<f64>, String> {
    let f: Vec<&str> = fields.split(',').collect();
    let rate = num_field(f.first().copied(), "rate of turn (deg/min)")?;
    match f.get(1).copied().unwrap_or("A") {
        "A" | "" => Ok(rate.map(|r| r / 60.0)),
        "V" => Ok(None),
        s => Err(format!("status must be A or V, found `{s}`")),
    }
}

/// Parses the fields of an `RSA` sentence: starboard (or single) and port rudder sensor
/// angles, each with status `A`/`V`. Returns the mean of the valid ones (deg), `None` when
/// neither is valid.
///
/// # Errors
/// A message when an angle is not a number or a status is not `A`/`V`.
///
/// ```
/// use yawcast::io::nmea::parse_rsa;
/// assert_eq!(parse_rsa("10.0,A,,V"), Ok(Some(10.0)));
/// assert_eq!(parse_rsa("10.0,A,12.0,A"), Ok(Some(11.0)));
/// assert_eq!(parse_rsa("10.0,V,,"), Ok(None));
/// assert!(parse_rsa("ten,A,,").is_err());
/// ```
pub fn parse_rsa(fields: &str) -> Result<Option<f64>, String> {
    let f: Vec<&str> = fields.split(',').collect();
    let mut sum = 0.0;
    let mut count = 0;
    for (i, side) in [(0, "starboard"), (2, "port")] {
        let angle = num_field(f.get(i).copied(), &format!("{side} rudder angle (deg)"))?;
        let ok = match f.get(i + 1).copied().unwrap_or("") {
            "A" => true,
            "V" | "" => false,
            s => return Err(format!("{side} status must be A or V, found `{s}`")),
        };
        if let (true, Some(a)) = (ok, angle) {
            sum += a;
            count += 1;
        }
    }
    Ok((count > 0).then(|| sum / count as f64))
}

/// Parses the fields of an `HDG` sentence: true heading (deg) = magnetic sensor heading +
/// deviation + variation (east positive; an empty deviation or variation counts as 0).
///
/// # Errors
/// A message when a number is malformed or a direction is not `E`/`W`.
///
/// ```
/// use yawcast::io::nmea::parse_hdg;
/// assert_eq!(parse_hdg("100.0,2.0,W,5.0,E"), Ok(Some(103.0)));
/// assert_eq!(parse_hdg("100.0,,,,"), Ok(Some(100.0)));
/// assert_eq!(parse_hdg(",,,,"), Ok(None));
/// ```
pub fn parse_hdg(fields: &str) -> Result<Option<f64>, String> {
    let f: Vec<&str> = fields.split(',').collect();
    let Some(h) = num_field(f.first().copied(), "magnetic sensor heading (deg)")? else {
        return Ok(None);
    };
    let mut total = h;
    for (i, what) in [(1, "deviation"), (3, "variation")] {
        let v = num_field(f.get(i).copied(), what)?.unwrap_or(0.0);
        total += match f.get(i + 1).copied().unwrap_or("") {
            "E" | "" => v,
            "W" => -v,
            s => return Err(format!("{what} direction must be E or W, found `{s}`")),
        };
    }
    Ok(Some(total.rem_euclid(360.0)))
}

fn num_field(f: Option<&str>, what: &str) -> Result<Option<f64>, String> {
    match f.map(str::trim) {
        None | Some("") => Ok(None),
        Some(s) => match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(format!("{what}: expected a number, found `{s}`")),
        },
    }
}
