//! Time stamps as loggers write them: ISO 8601 date-times (`2024-05-01T12:00:00.25Z`) or a
//! time of day alone (`23:59:59.5`) in the time column, read as seconds from the record's
//! first stamp.

/// A date-time read from an ISO 8601 stamp: whole seconds since 1970-01-01 UTC (the stamp's
/// offset applied; a stamp without one is taken as UTC, so a record's stamps compare with
/// each other as long as none carries an offset) and the fraction of a second.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Stamp {
    /// Whole seconds since the epoch.
    pub(crate) whole: i64,
    /// Fraction of a second, `0 ≤ frac < 1`.
    pub(crate) frac: f64,
}

impl Stamp {
    /// Seconds from `origin` to `self` (exact in the whole seconds, then the fractions).
    pub(crate) fn since(&self, origin: &Stamp) -> f64 {
        (self.whole - origin.whole) as f64 + (self.frac - origin.frac)
    }
}

/// Days since 1970-01-01 of a civil date (proleptic Gregorian), `None` for an invalid date
/// (a month outside 1–12, a day outside the month).
pub(crate) fn days_from_civil(y: i64, m: i64, d: i64) -> Option<i64> {
    if !(1..=12).contains(&m) || d < 1 || d > days_in_month(y, m) {
        return None;
    }
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some(era * 146_097 + doe - 719_468)
}

fn days_in_month(y: i64, m: i64) -> i64 {
    match m {
        4 | 6 | 9 | 11 => 30,
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        _ => 31,
    }
}

/// `n` ASCII digits at the start of `s` as a number, and the rest.
fn digits(s: &str, n: usize) -> Option<(i64, &str)> {
    let head = s.get(..n)?;
    if !head.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((head.parse().ok()?, &s[n..]))
}

/// `s` with the one byte `c` stripped from its start.
fn expect(s: &str, c: u8) -> Option<&str> {
    (s.as_bytes().first() == Some(&c)).then(|| &s[1..])
}

/// An ISO 8601 date-time: `YYYY-MM-DD`, then `T` or a space, `hh:mm[:ss[.f…]]` (a decimal
/// comma too), then nothing (UTC), `Z`, or an offset `±hh[:mm]` / `±hhmm`. `None` for
/// anything else (a plain number included).
pub(crate) fn parse_iso8601(s: &str) -> Option<Stamp> {
    let s = s.trim();
    let (y, r) = digits(s, 4)?;
    let (mo, r) = digits(expect(r, b'-')?, 2)?;
    let (d, r) = digits(expect(r, b'-')?, 2)?;
    let r = match r.as_bytes().first()? {
        b'T' | b't' | b' ' => &r[1..],
        _ => return None,
    };
    let (clock, r) = time_of_day(r)?;
    let offset = match r.as_bytes().first() {
        None => 0,
        Some(b'Z' | b'z') if r.len() == 1 => 0,
        Some(&c @ (b'+' | b'-')) => {
            let (oh, rest) = digits(&r[1..], 2)?;
            let rest = expect(rest, b':').unwrap_or(rest);
            let (om, rest) = if rest.is_empty() {
                (0, rest)
            } else {
                digits(rest, 2)?
            };
            if !rest.is_empty() || oh > 23 || om > 59 {
                return None;
            }
            let o = oh * 3600 + om * 60;
            if c == b'-' {
                -o
            } else {
                o
            }
        }
        Some(_) => return None,
    };
    let days = days_from_civil(y, mo, d)?;
    Some(Stamp {
        whole: days * 86_400 + clock.whole - offset,
        frac: clock.frac,
    })
}

/// `hh:mm[:ss[.f…]]` (a decimal comma too) at the start of `s`: the seconds since midnight,
/// and the rest.
fn time_of_day(s: &str) -> Option<(Stamp, &str)> {
    let (h, r) = digits(s, 2)?;
    let (mi, mut r) = digits(expect(r, b':')?, 2)?;
    let mut sec = 0;
    let mut frac = 0.0;
    if let Some(rest) = expect(r, b':') {
        let (ss, rest) = digits(rest, 2)?;
        sec = ss;
        r = rest;
        if let Some(rest) = expect(r, b'.').or_else(|| expect(r, b',')) {
            let n = rest.bytes().take_while(u8::is_ascii_digit).count();
            if n == 0 {
                return None;
            }
            frac = format!("0.{}", &rest[..n]).parse().ok()?;
            r = &rest[n..];
        }
    }
    // 60 admits a leap second, read as the next minute's first
    if h > 23 || mi > 59 || sec > 60 {
        return None;
    }
    Some((
        Stamp {
            whole: h * 3600 + mi * 60 + sec,
            frac,
        },
        r,
    ))
}

/// A time of day alone, `hh:mm[:ss[.f…]]`, as a logger without a date writes it: seconds
/// since midnight (the caller counts the midnights a record crosses). `None` for anything
/// else.
pub(crate) fn parse_clock(s: &str) -> Option<Stamp> {
    match time_of_day(s.trim())? {
        (stamp, "") => Some(stamp),
        _ => None,
    }
}

/// What a time column holds, decided by its first cell: seconds (numbers), ISO 8601
/// date-times, or times of day alone (counting the midnights crossed so far). Later cells
/// are read as seconds from the first stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Clock {
    /// Numbers, in the column's unit.
    Seconds,
    /// ISO 8601 date-times, from this first stamp.
    Iso(Stamp),
    /// Times of day, from this first one, with the midnights crossed.
    Day(Stamp, i64),
}

impl Clock {
    /// The clock of a column whose first cell is `first`.
    pub(crate) fn of(first: &str) -> Clock {
        if let Some(stamp) = parse_iso8601(first) {
            Clock::Iso(stamp)
        } else if let Some(stamp) = parse_clock(first) {
            Clock::Day(stamp, 0)
        } else {
            Clock::Seconds
        }
    }

    /// The time (s) of the cell `raw`: a number through `number`, times `scale`, or a stamp
    /// of this clock from the first; `last` is the row before's time (a time of day that
    /// falls back by more than half a day crossed midnight). `None` when the cell is not a
    /// time of this clock.
    pub(crate) fn seconds(
        &mut self,
        raw: &str,
        number: impl Fn(&str) -> Option<f64>,
        scale: f64,
        last: f64,
    ) -> Option<f64> {
        match self {
            Clock::Seconds => number(raw).map(|v| v * scale),
            Clock::Iso(origin) => Some(parse_iso8601(raw)?.since(origin)),
            Clock::Day(origin, days) => {
                let t = parse_clock(raw)?.since(origin);
                if t + 86_400.0 * (*days as f64) < last - 43_200.0 {
                    *days += 1;
                }
                Some(t + 86_400.0 * (*days as f64))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso_stamps_are_read_to_the_second_and_below() {
        let a = parse_iso8601("2024-05-01T12:00:00Z").unwrap();
        // 19 844 days from 1970-01-01 to 2024-05-01
        assert_eq!(a.whole, 19_844 * 86_400 + 12 * 3600);
        assert_eq!(a.frac, 0.0);
        let b = parse_iso8601("2024-05-01 12:00:01.250").unwrap();
        assert_eq!(b.since(&a), 1.25);
        // an offset is applied: 14:00:02,5+02:00 is 12:00:02.5 UTC
        let c = parse_iso8601("2024-05-01T14:00:02,5+02:00").unwrap();
        assert_eq!(c.since(&a), 2.5);
        assert_eq!(parse_iso8601("2024-05-01T14:00:02.5+0200"), Some(c));
        assert_eq!(parse_iso8601("2024-05-01T07:00-05").unwrap().since(&a), 0.0);
        // across a month's and a leap year's end
        let d = parse_iso8601("2024-02-29T23:59:59Z").unwrap();
        let e = parse_iso8601("2024-03-01T00:00:00Z").unwrap();
        assert_eq!(e.since(&d), 1.0);
    }

    #[test]
    fn what_is_not_a_date_time_is_refused() {
        for s in [
            "12.5",
            "1714564800",
            "2024-05-01",
            "2024-13-01T00:00:00Z",
            "2023-02-29T00:00:00Z",
            "2024-05-01T24:00:00Z",
            "2024-05-01T12:00:00.Z",
            "2024-05-01T12:00:00 UTC",
            "2024-05-01T12:00:00+2",
            "12:00:00",
            "",
        ] {
            assert_eq!(parse_iso8601(s), None, "{s}");
        }
    }

    #[test]
    fn a_time_of_day_alone_is_seconds_since_midnight() {
        assert_eq!(
            parse_clock("23:59:59.5"),
            Some(Stamp {
                whole: 86_399,
                frac: 0.5
            })
        );
        assert_eq!(parse_clock(" 00:01 ").map(|s| s.whole), Some(60));
        for s in [
            "24:00:00",
            "12:00:00Z",
            "12.5",
            "2024-05-01T12:00:00Z",
            "1:00:00",
        ] {
            assert_eq!(parse_clock(s), None, "{s}");
        }
    }

    #[test]
    fn the_civil_calendar_matches_known_dates() {
        assert_eq!(days_from_civil(1970, 1, 1), Some(0));
        assert_eq!(days_from_civil(2000, 3, 1), Some(11_017));
        assert_eq!(days_from_civil(1969, 12, 31), Some(-1));
        assert_eq!(days_from_civil(2024, 4, 31), None);
    }
}
