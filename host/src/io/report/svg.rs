//! Small inline-SVG charts for the report: line charts, grouped bars and stem plots with
//! confidence bands. Plain SVG 1.1 elements, styled by the page's CSS classes, no scripts.

use std::fmt::Write as _;

/// Chart width and height in SVG user units.
const W: f64 = 860.0;
const H: f64 = 260.0;
/// Margins: left, right, top, bottom.
const ML: f64 = 58.0;
const MR: f64 = 16.0;
const MT: f64 = 26.0;
const MB: f64 = 38.0;

/// Colours of the series, in order (a palette readable by colour-blind people).
pub const PALETTE: [&str; 6] = [
    "#1b1b1b", "#d55e00", "#0072b2", "#009e73", "#cc79a7", "#e69f00",
];

/// One line of a line chart.
#[derive(Debug, Clone)]
pub struct Line {
    /// Legend label.
    pub label: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values (non-finite values break the line).
    pub y: Vec<f64>,
    /// Colour (CSS).
    pub color: String,
    /// Dashed.
    pub dashed: bool,
    /// Stroke width.
    pub width: f64,
}

impl Line {
    /// A solid line of colour `PALETTE[i]`.
    pub fn new(label: &str, x: Vec<f64>, y: Vec<f64>, i: usize) -> Line {
        Line {
            label: label.to_string(),
            x,
            y,
            color: PALETTE[i % PALETTE.len()].to_string(),
            dashed: false,
            width: if i == 0 { 1.6 } else { 1.3 },
        }
    }

    /// The same line, dashed.
    pub fn dashed(mut self) -> Line {
        self.dashed = true;
        self
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A "nice" tick step for a span.
fn nice_step(span: f64, ticks: f64) -> f64 {
    let raw = (span / ticks).max(1e-12);
    let mag = 10f64.powf(raw.log10().floor());
    let r = raw / mag;
    let m = if r < 1.5 {
        1.0
    } else if r < 3.0 {
        2.0
    } else if r < 7.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

fn fmt_tick(v: f64, step: f64) -> String {
    let dec = if step >= 1.0 {
        0
    } else {
        (-step.log10()).ceil() as usize
    };
    let s = format!("{v:.dec$}");
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// Frame: axes, grid, ticks, labels. Returns the SVG head and the mapping closures' params.
struct Frame {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    h: f64,
}

impl Frame {
    fn new(x0: f64, x1: f64, y0: f64, y1: f64, h: f64) -> Frame {
        let (x0, x1) = if x1 > x0 {
            (x0, x1)
        } else {
            (x0 - 1.0, x0 + 1.0)
        };
        let (y0, y1) = if y1 > y0 {
            let pad = 0.05 * (y1 - y0);
            (y0 - pad, y1 + pad)
        } else {
            (y0 - 1.0, y0 + 1.0)
        };
        Frame { x0, x1, y0, y1, h }
    }
    fn px(&self, x: f64) -> f64 {
        ML + (x - self.x0) / (self.x1 - self.x0) * (W - ML - MR)
    }
    fn py(&self, y: f64) -> f64 {
        self.h - MB - (y - self.y0) / (self.y1 - self.y0) * (self.h - MT - MB)
    }
    fn axes(&self, out: &mut String, xlabel: &str, ylabel: &str, xticks: bool) {
        let ys = nice_step(self.y1 - self.y0, 5.0);
        let mut v = (self.y0 / ys).ceil() * ys;
        while v <= self.y1 + 1e-9 * ys {
            let y = self.py(v);
            let _ = write!(
                out,
                r#"<line class="grid" x1="{ML}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}"/><text class="tick" x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                W - MR,
                ML - 6.0,
                y + 4.0,
                fmt_tick(v, ys)
            );
            v += ys;
        }
        if xticks {
            let xs = nice_step(self.x1 - self.x0, 8.0);
            let mut v = (self.x0 / xs).ceil() * xs;
            while v <= self.x1 + 1e-9 * xs {
                let x = self.px(v);
                let _ = write!(
                    out,
                    r#"<text class="tick" x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                    self.h - MB + 16.0,
                    fmt_tick(v, xs)
                );
                v += xs;
            }
        }
        let _ = write!(
            out,
            r#"<rect class="frame" x="{ML}" y="{MT}" width="{:.1}" height="{:.1}"/><text class="axlabel" x="{:.1}" y="{:.1}" text-anchor="middle">{}</text><text class="axlabel" transform="translate(14 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
            W - ML - MR,
            self.h - MT - MB,
            (ML + W - MR) / 2.0,
            self.h - 6.0,
            esc(xlabel),
            (MT + self.h - MB) / 2.0,
            esc(ylabel)
        );
        if self.y0 < 0.0 && self.y1 > 0.0 {
            let y = self.py(0.0);
            let _ = write!(
                out,
                r#"<line class="zero" x1="{ML}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}"/>"#,
                W - MR
            );
        }
    }
}

fn open(out: &mut String, h: f64, title: &str) {
    let _ = write!(
        out,
        r#"<svg class="chart" viewBox="0 0 {W} {h}" role="img" aria-label="{t}" xmlns="http://www.w3.org/2000/svg"><title>{t}</title>"#,
        t = esc(title)
    );
}

fn legend(out: &mut String, items: &[(String, String, bool)]) {
    let mut x = ML + 6.0;
    for (label, color, dashed) in items {
        let dash = if *dashed {
            r#" stroke-dasharray="6 4""#
        } else {
            ""
        };
        let _ = write!(
            out,
            r#"<line x1="{x:.1}" y1="14" x2="{:.1}" y2="14" stroke="{color}" stroke-width="2.4"{dash}/><text class="legend" x="{:.1}" y="18">{}</text>"#,
            x + 18.0,
            x + 22.0,
            esc(label)
        );
        x += 30.0 + 7.0 * label.chars().count() as f64;
    }
}

/// Decimates a series to at most `max` points, keeping each bucket's min and max (so
/// spikes survive).
fn decimate(x: &[f64], y: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    if n <= max {
        return (0..n).map(|i| (x[i], y[i])).collect();
    }
    let buckets = max / 2;
    let mut out = Vec::with_capacity(max);
    for b in 0..buckets {
        let i0 = b * n / buckets;
        let i1 = ((b + 1) * n / buckets).max(i0 + 1);
        let (mut imin, mut imax) = (i0, i0);
        for i in i0..i1 {
            if y[i] < y[imin] {
                imin = i;
            }
            if y[i] > y[imax] {
                imax = i;
            }
        }
        let (a, c) = if imin < imax {
            (imin, imax)
        } else {
            (imax, imin)
        };
        out.push((x[a], y[a]));
        if c != a {
            out.push((x[c], y[c]));
        }
    }
    out
}

/// A line chart. Non-finite points are skipped (the line breaks there). `y_clip` limits
/// the y range (a diverging prediction would otherwise flatten everything else).
pub fn line_chart(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    lines: &[Line],
    y_clip: Option<(f64, f64)>,
) -> String {
    let mut x0 = f64::INFINITY;
    let mut x1 = f64::NEG_INFINITY;
    let mut y0 = f64::INFINITY;
    let mut y1 = f64::NEG_INFINITY;
    for l in lines {
        for (&x, &y) in l.x.iter().zip(&l.y) {
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if let Some((lo, hi)) = y_clip {
        y0 = y0.max(lo);
        y1 = y1.min(hi);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let f = Frame::new(x0, x1, y0, y1, H);
    let mut out = String::new();
    open(&mut out, H, title);
    f.axes(&mut out, xlabel, ylabel, true);
    let _ = write!(
        out,
        r#"<clipPath id="c{id}"><rect x="{ML}" y="{MT}" width="{:.1}" height="{:.1}"/></clipPath><g clip-path="url(#c{id})">"#,
        W - ML - MR,
        H - MT - MB,
        id = clip_id(title)
    );
    for l in lines {
        let pts = decimate(&l.x, &l.y, 1600);
        let mut d = String::new();
        let mut pen = false;
        for (x, y) in pts {
            if !(x.is_finite() && y.is_finite()) {
                pen = false;
                continue;
            }
            let y = y.clamp(f.y0 - (f.y1 - f.y0), f.y1 + (f.y1 - f.y0));
            let _ = write!(
                d,
                "{}{:.1},{:.1}",
                if pen { " L" } else { " M" },
                f.px(x),
                f.py(y)
            );
            pen = true;
        }
        let dash = if l.dashed {
            r#" stroke-dasharray="6 4""#
        } else {
            ""
        };
        let _ = write!(
            out,
            r#"<path d="{}" fill="none" stroke="{}" stroke-width="{}"{dash}/>"#,
            d.trim(),
            l.color,
            l.width
        );
    }
    out.push_str("</g>");
    let items: Vec<_> = lines
        .iter()
        .map(|l| (l.label.clone(), l.color.clone(), l.dashed))
        .collect();
    legend(&mut out, &items);
    out.push_str("</svg>");
    out
}

/// A bar's value label: three significant digits, at most one decimal above 10.
fn bar_label(v: f64) -> String {
    let a = v.abs();
    if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 || a == 0.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        let dec = (2.0 - a.log10().floor()) as usize;
        format!("{v:.dec$}")
    }
}

fn clip_id(title: &str) -> String {
    let h = title.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    format!("{h:016x}")
}

/// Stem plot of a correlation function with a ±band (constant or per-lag): bars outside the
/// band are drawn in the alert colour.
pub fn stem_chart(title: &str, xlabel: &str, lags: &[f64], values: &[f64], band: &[f64]) -> String {
    let lim = values
        .iter()
        .chain(band.iter())
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-6);
    let x0 = lags.first().copied().unwrap_or(0.0) - 0.5;
    let x1 = lags.last().copied().unwrap_or(1.0) + 0.5;
    let f = Frame::new(x0, x1, -lim, lim, H);
    let mut out = String::new();
    open(&mut out, H, title);
    f.axes(&mut out, xlabel, "correlation", true);
    // Band as a polyline pair (above and below).
    let mut up = String::new();
    let mut dn = String::new();
    for (i, &l) in lags.iter().enumerate() {
        let b = band.get(i).or(band.last()).copied().unwrap_or(0.0);
        let _ = write!(up, "{:.1},{:.1} ", f.px(l), f.py(b));
        let _ = write!(dn, "{:.1},{:.1} ", f.px(l), f.py(-b));
    }
    let _ = write!(
        out,
        r#"<polyline class="band" points="{}"/><polyline class="band" points="{}"/>"#,
        up.trim(),
        dn.trim()
    );
    let mut d_in = String::new();
    let mut d_out = String::new();
    for (i, (&l, &v)) in lags.iter().zip(values).enumerate() {
        if !v.is_finite() {
            continue;
        }
        let b = band
            .get(i)
            .or(band.last())
            .copied()
            .unwrap_or(f64::INFINITY);
        let target = if v.abs() > b { &mut d_out } else { &mut d_in };
        let _ = write!(
            target,
            " M{:.1},{:.1} L{:.1},{:.1}",
            f.px(l),
            f.py(0.0),
            f.px(l),
            f.py(v)
        );
    }
    let _ = write!(
        out,
        r#"<path class="stem" d="{}"/><path class="stem out" d="{}"/>"#,
        d_in.trim(),
        d_out.trim()
    );
    legend(
        &mut out,
        &[
            ("inside the band".into(), PALETTE[2].into(), false),
            ("outside".into(), PALETTE[1].into(), false),
            ("99 % band".into(), "#888".into(), true),
        ],
    );
    out.push_str("</svg>");
    out
}

/// Grouped horizontal-axis bars: `groups` along x, one bar per series in each group.
/// Values below `floor` (above `cap`) are drawn to the floor (cap) and labelled with their
/// true value.
pub fn bar_chart(
    title: &str,
    ylabel: &str,
    groups: &[String],
    series: &[(String, Vec<f64>)],
    floor: Option<f64>,
    cap: Option<f64>,
) -> String {
    let mut lo = 0.0f64;
    let mut hi = f64::NEG_INFINITY;
    for (_, v) in series {
        for &x in v {
            if x.is_finite() {
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
    }
    if let Some(fl) = floor {
        lo = lo.max(fl);
    }
    if !hi.is_finite() {
        hi = 1.0;
    }
    if let Some(c) = cap {
        hi = hi.min(c);
    }
    let f = Frame::new(-0.5, groups.len() as f64 - 0.5, lo, hi.max(lo + 1e-9), H);
    let mut out = String::new();
    open(&mut out, H, title);
    f.axes(&mut out, "", ylabel, false);
    let ns = series.len().max(1) as f64;
    let gw = (W - ML - MR) / groups.len().max(1) as f64;
    let bw = (gw * 0.8 / ns).min(60.0);
    for (g, name) in groups.iter().enumerate() {
        let cx = f.px(g as f64);
        let _ = write!(
            out,
            r#"<text class="tick" x="{cx:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            H - MB + 16.0,
            esc(name)
        );
        for (s, (_, vals)) in series.iter().enumerate() {
            let v = vals.get(g).copied().unwrap_or(f64::NAN);
            let x = cx - bw * ns / 2.0 + bw * s as f64;
            let color = PALETTE[(s + 1) % PALETTE.len()];
            if !v.is_finite() {
                let _ = write!(
                    out,
                    r#"<text class="barval" x="{:.1}" y="{:.1}" text-anchor="middle">n/a</text>"#,
                    x + bw / 2.0,
                    f.py(0.0) - 4.0
                );
                continue;
            }
            let shown = v.max(f.y0).min(f.y1);
            let (ya, yb) = (f.py(shown.max(0.0)), f.py(shown.min(0.0).max(f.y0)));
            let _ = write!(
                out,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{color}"><title>{}: {v:.2}</title></rect><text class="barval" x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                x + 1.0,
                ya.min(yb),
                (bw - 2.0).max(1.0),
                (yb - ya).abs().max(0.5),
                esc(&series[s].0),
                x + bw / 2.0,
                ya.min(yb) - 3.0,
                bar_label(v)
            );
        }
    }
    let items: Vec<_> = series
        .iter()
        .enumerate()
        .map(|(s, (n, _))| {
            (
                n.clone(),
                PALETTE[(s + 1) % PALETTE.len()].to_string(),
                false,
            )
        })
        .collect();
    legend(&mut out, &items);
    out.push_str("</svg>");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_chart_has_paths_and_survives_nan() {
        let s = line_chart(
            "t",
            "x",
            "y",
            &[Line::new(
                "a",
                vec![0.0, 1.0, 2.0, 3.0],
                vec![0.0, f64::NAN, 1.0, 2.0],
                0,
            )],
            None,
        );
        assert!(s.starts_with("<svg") && s.ends_with("</svg>"));
        assert!(s.contains("<path d=\"M"));
        assert!(!s.contains("NaN"));
    }

    #[test]
    fn stems_outside_the_band_are_marked() {
        let s = stem_chart("acf", "lag", &[1.0, 2.0], &[0.5, 0.01], &[0.1]);
        assert!(s.contains(r#"class="stem out" d="M"#));
        assert!(s.contains("<polyline"));
    }

    #[test]
    fn bars_with_floor_and_missing_values() {
        let s = bar_chart(
            "fit",
            "%",
            &["1".into(), "5".into()],
            &[
                ("a".into(), vec![90.0, -500.0]),
                ("b".into(), vec![f64::NAN, 50.0]),
            ],
            Some(-50.0),
            None,
        );
        assert!(s.contains("n/a") && s.contains("-500"));
    }

    #[test]
    fn bar_labels_keep_three_significant_digits() {
        assert_eq!(bar_label(0.0123), "0.0123");
        assert_eq!(bar_label(0.2), "0.200");
        assert_eq!(bar_label(4.2), "4.20");
        assert_eq!(bar_label(88.04), "88.0");
        assert_eq!(bar_label(-512.3), "-512");
    }

    #[test]
    fn decimation_keeps_extremes() {
        let x: Vec<f64> = (0..10_000).map(f64::from).collect();
        let mut y = vec![0.0; 10_000];
        y[5_123] = 9.0;
        let d = decimate(&x, &y, 400);
        assert!(d.len() <= 400);
        assert!(d.iter().any(|p| p.1 == 9.0));
    }
}
