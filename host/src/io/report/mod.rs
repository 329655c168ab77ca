//! `report.html`: one self-contained page per run — inline CSS and SVG, no scripts, no
//! network. A [`Report`] is a verdict box and a list of [`Section`]s made of [`Block`]s
//! (text, tables, charts); [`Report::render`] turns it into HTML.
//!
//! ```
//! use yawcast::io::report::{Block, Report, Section, Status};
//! let mut r = Report::new("Demo", "built-in ship", Status::Pass, "All good");
//! r.sections.push(Section::new("fits", "Fits", "How well it predicts.")
//!     .with(Block::bars("fit", "%", &["5"], &[("model", vec![91.0])])));
//! let html = r.render();
//! assert!(html.contains(r#"<section id="fits""#) && html.contains("<svg"));
//! assert!(!html.contains("<script"));
//! ```

pub mod svg;

use std::fmt::Write as _;
use std::path::Path;

pub use svg::Line;

/// How the run went, for the colour of the verdict box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Everything checked passed.
    Pass,
    /// It worked, with something to look at.
    Warn,
    /// A check failed.
    Fail,
}

impl Status {
    fn class(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Warn => "warn",
            Status::Fail => "fail",
        }
    }
    fn word(self) -> &'static str {
        match self {
            Status::Pass => "PASS",
            Status::Warn => "CHECK",
            Status::Fail => "FAIL",
        }
    }
}

/// A key number in the summary box.
#[derive(Debug, Clone)]
pub struct Fact {
    /// What it is.
    pub label: String,
    /// The number, formatted.
    pub value: String,
    /// A short note under it.
    pub note: String,
}

/// A table cell, optionally highlighted.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Text.
    pub text: String,
    /// CSS class: `good`, `bad`, `warn`, `num`, or empty.
    pub class: &'static str,
}

impl Cell {
    /// A plain text cell.
    pub fn text(s: impl Into<String>) -> Cell {
        Cell {
            text: s.into(),
            class: "",
        }
    }
    /// A number with `dec` decimals (right-aligned); non-finite shows as "—".
    pub fn num(v: f64, dec: usize) -> Cell {
        Cell {
            text: if v.is_finite() {
                format!("{v:.dec$}")
            } else {
                "—".into()
            },
            class: "num",
        }
    }
    /// The same cell with a highlight class.
    pub fn class(mut self, class: &'static str) -> Cell {
        self.class = class;
        self
    }
}

/// One piece of a section.
#[derive(Debug, Clone)]
pub enum Block {
    /// A paragraph (plain text; escaped).
    Text(String),
    /// A note in a muted box.
    Note(String),
    /// A table with a header row.
    Table {
        /// Caption.
        caption: String,
        /// Header cells.
        head: Vec<String>,
        /// Rows.
        rows: Vec<Vec<Cell>>,
    },
    /// An inline SVG chart (from [`svg`]).
    Chart {
        /// Caption under the chart.
        caption: String,
        /// The `<svg>` element.
        svg: String,
    },
}

impl Block {
    /// A line chart block.
    pub fn lines(title: &str, xlabel: &str, ylabel: &str, lines: &[Line], caption: &str) -> Block {
        Block::Chart {
            caption: caption.to_string(),
            svg: svg::line_chart(title, xlabel, ylabel, lines, None),
        }
    }
    /// A line chart block with a clipped y range.
    pub fn lines_clipped(
        title: &str,
        xlabel: &str,
        ylabel: &str,
        lines: &[Line],
        clip: (f64, f64),
        caption: &str,
    ) -> Block {
        Block::Chart {
            caption: caption.to_string(),
            svg: svg::line_chart(title, xlabel, ylabel, lines, Some(clip)),
        }
    }
    /// A grouped bar chart block (bars below −100 are cut at −100 and labelled).
    pub fn bars(title: &str, ylabel: &str, groups: &[&str], series: &[(&str, Vec<f64>)]) -> Block {
        let groups: Vec<String> = groups.iter().map(|s| s.to_string()).collect();
        let series: Vec<(String, Vec<f64>)> = series
            .iter()
            .map(|(n, v)| (n.to_string(), v.clone()))
            .collect();
        Block::Chart {
            caption: String::new(),
            svg: svg::bar_chart(title, ylabel, &groups, &series, Some(-100.0), None),
        }
    }
    /// A grouped bar chart block with bars above `cap` cut there (and labelled).
    pub fn bars_capped(
        title: &str,
        ylabel: &str,
        groups: &[&str],
        series: &[(&str, Vec<f64>)],
        cap: f64,
    ) -> Block {
        let groups: Vec<String> = groups.iter().map(|s| s.to_string()).collect();
        let series: Vec<(String, Vec<f64>)> = series
            .iter()
            .map(|(n, v)| (n.to_string(), v.clone()))
            .collect();
        Block::Chart {
            caption: String::new(),
            svg: svg::bar_chart(title, ylabel, &groups, &series, Some(-100.0), Some(cap)),
        }
    }
    /// A correlation stem chart with its band.
    pub fn stems(title: &str, xlabel: &str, lags: &[f64], values: &[f64], band: &[f64]) -> Block {
        Block::Chart {
            caption: String::new(),
            svg: svg::stem_chart(title, xlabel, lags, values, band),
        }
    }
    /// The same chart block with a caption.
    pub fn caption(self, c: &str) -> Block {
        match self {
            Block::Chart { svg, .. } => Block::Chart {
                caption: c.to_string(),
                svg,
            },
            other => other,
        }
    }
}

/// A titled part of the page with a stable `id`.
#[derive(Debug, Clone)]
pub struct Section {
    /// HTML id (stable: tests and links use it).
    pub id: String,
    /// Heading.
    pub title: String,
    /// One-paragraph lead: what this section shows and how to read it.
    pub lead: String,
    /// Contents.
    pub blocks: Vec<Block>,
}

impl Section {
    /// An empty section.
    pub fn new(id: &str, title: &str, lead: &str) -> Section {
        Section {
            id: id.to_string(),
            title: title.to_string(),
            lead: lead.to_string(),
            blocks: Vec::new(),
        }
    }
    /// Adds a block.
    pub fn with(mut self, b: Block) -> Section {
        self.blocks.push(b);
        self
    }
}

/// The whole page.
#[derive(Debug, Clone)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// Line under the title (ship, seed, date…).
    pub subtitle: String,
    /// Verdict colour.
    pub status: Status,
    /// Verdict headline, first thing on the page.
    pub headline: String,
    /// Verdict details (one sentence each).
    pub verdict: Vec<String>,
    /// Key numbers.
    pub facts: Vec<Fact>,
    /// Sections in page order.
    pub sections: Vec<Section>,
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const CSS: &str = r#"
:root{--ink:#1d232a;--muted:#5b6670;--line:#d9dee3;--bg:#f6f7f9;--pass:#1f7a4d;--warn:#a86400;--fail:#b3261e;--accent:#0b5cad}
*{box-sizing:border-box}
body{margin:0;background:var(--bg);color:var(--ink);font:15px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif}
header{background:#14324f;color:#fff;padding:22px 40px 18px}
header h1{margin:0;font-size:26px;font-weight:650;letter-spacing:.2px}
header p{margin:4px 0 0;color:#c9d6e3}
nav{background:#fff;border-bottom:1px solid var(--line);padding:8px 40px;display:flex;flex-wrap:wrap;gap:4px 16px}
nav a{color:var(--accent);text-decoration:none;font-size:14px;white-space:nowrap}
main{max-width:1000px;margin:0 auto;padding:22px 24px 60px}
section{background:#fff;border:1px solid var(--line);border-radius:8px;padding:18px 24px 20px;margin:0 0 22px}
h2{margin:0 0 6px;font-size:20px}
p.lead{margin:0 0 12px;color:var(--muted)}
.verdict{border-left:8px solid var(--pass);padding:14px 20px;border-radius:6px;background:#eef7f1;margin-bottom:16px}
.verdict.warn{border-color:var(--warn);background:#fbf3e6}
.verdict.fail{border-color:var(--fail);background:#fbecea}
.verdict .badge{display:inline-block;font-weight:700;font-size:13px;color:#fff;background:var(--pass);border-radius:4px;padding:2px 8px;margin-right:10px;vertical-align:2px}
.verdict.warn .badge{background:var(--warn)}.verdict.fail .badge{background:var(--fail)}
.verdict h2{display:inline;font-size:21px}
.verdict ul{margin:10px 0 0;padding-left:20px}
.facts{display:grid;grid-template-columns:repeat(auto-fill,minmax(180px,1fr));gap:10px}
.fact{border:1px solid var(--line);border-radius:6px;padding:10px 12px;background:#fbfcfd}
.fact .v{font-size:22px;font-weight:650;font-variant-numeric:tabular-nums}
.fact .l{font-size:13px;color:var(--muted)}
.fact .n{font-size:12px;color:var(--muted)}
table{border-collapse:collapse;margin:8px 0 14px;font-size:14px;font-variant-numeric:tabular-nums}
caption{text-align:left;font-weight:600;padding:4px 0;color:var(--ink)}
th,td{border-bottom:1px solid var(--line);padding:4px 10px;text-align:left}
th{background:#f0f3f6;font-weight:600}
td.num{text-align:right}
td.good{color:var(--pass);font-weight:600}td.bad{color:var(--fail);font-weight:600}td.warn{color:var(--warn);font-weight:600}
figure{margin:6px 0 14px}
figcaption{font-size:13px;color:var(--muted)}
svg.chart{width:100%;height:auto;background:#fff}
svg .grid{stroke:#eceff2;stroke-width:1}
svg .zero{stroke:#9aa4ad;stroke-width:1}
svg .frame{fill:none;stroke:#b8c0c8;stroke-width:1}
svg .tick{font-size:11px;fill:#5b6670}
svg .axlabel{font-size:12px;fill:#36414b}
svg .legend{font-size:12px;fill:#1d232a}
svg .barval{font-size:10px;fill:#36414b}
svg .band{fill:none;stroke:#888;stroke-width:1.2;stroke-dasharray:6 4}
svg .stem{stroke:#0072b2;stroke-width:3;fill:none}
svg .stem.out{stroke:#d55e00}
.note{background:#f3f5f8;border-radius:6px;padding:8px 12px;color:#36414b;font-size:14px}
footer{color:var(--muted);font-size:12px;text-align:center;padding:10px}
"#;

impl Report {
    /// A report with a verdict and no sections yet.
    pub fn new(title: &str, subtitle: &str, status: Status, headline: &str) -> Report {
        Report {
            title: title.to_string(),
            subtitle: subtitle.to_string(),
            status,
            headline: headline.to_string(),
            verdict: Vec::new(),
            facts: Vec::new(),
            sections: Vec::new(),
        }
    }

    /// Adds a key number to the summary box.
    pub fn fact(&mut self, label: &str, value: impl Into<String>, note: &str) {
        self.facts.push(Fact {
            label: label.to_string(),
            value: value.into(),
            note: note.to_string(),
        });
    }

    /// The page as HTML.
    pub fn render(&self) -> String {
        let mut h = String::with_capacity(1 << 20);
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width,initial-scale=1\"><title>{}</title><style>{CSS}</style></head><body>",
            esc(&self.title)
        );
        let _ = write!(
            h,
            "<header><h1>{}</h1><p>{}</p></header><nav><a href=\"#summary\">Summary</a>",
            esc(&self.title),
            esc(&self.subtitle)
        );
        for s in &self.sections {
            let _ = write!(h, "<a href=\"#{}\">{}</a>", esc(&s.id), esc(&s.title));
        }
        h.push_str("</nav><main>");
        let _ = write!(
            h,
            "<section id=\"summary\"><div class=\"verdict {c}\"><span class=\"badge\">{w}</span><h2>{}</h2><ul>",
            esc(&self.headline),
            c = self.status.class(),
            w = self.status.word()
        );
        for v in &self.verdict {
            let _ = write!(h, "<li>{}</li>", esc(v));
        }
        h.push_str("</ul></div><div class=\"facts\">");
        for f in &self.facts {
            let _ = write!(
                h,
                "<div class=\"fact\"><div class=\"l\">{}</div><div class=\"v\">{}</div><div class=\"n\">{}</div></div>",
                esc(&f.label),
                esc(&f.value),
                esc(&f.note)
            );
        }
        h.push_str("</div></section>");
        for s in &self.sections {
            let _ = write!(
                h,
                "<section id=\"{}\"><h2>{}</h2><p class=\"lead\">{}</p>",
                esc(&s.id),
                esc(&s.title),
                esc(&s.lead)
            );
            for b in &s.blocks {
                render_block(&mut h, b);
            }
            h.push_str("</section>");
        }
        h.push_str("</main><footer>yawcast report — self-contained page: inline SVG and CSS, no scripts, no network.</footer></body></html>\n");
        h
    }

    /// Writes the page atomically.
    ///
    /// # Errors
    /// [`crate::io::data::DataError::Io`] when the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), crate::io::data::DataError> {
        crate::io::data::write_atomic(path, self.render().as_bytes())
    }
}

fn render_block(h: &mut String, b: &Block) {
    match b {
        Block::Text(t) => {
            let _ = write!(h, "<p>{}</p>", esc(t));
        }
        Block::Note(t) => {
            let _ = write!(h, "<p class=\"note\">{}</p>", esc(t));
        }
        Block::Table {
            caption,
            head,
            rows,
        } => {
            let _ = write!(h, "<table><caption>{}</caption><thead><tr>", esc(caption));
            for c in head {
                let _ = write!(h, "<th>{}</th>", esc(c));
            }
            h.push_str("</tr></thead><tbody>");
            for r in rows {
                h.push_str("<tr>");
                for c in r {
                    if c.class.is_empty() {
                        let _ = write!(h, "<td>{}</td>", esc(&c.text));
                    } else {
                        let _ = write!(h, "<td class=\"{}\">{}</td>", c.class, esc(&c.text));
                    }
                }
                h.push_str("</tr>");
            }
            h.push_str("</tbody></table>");
        }
        Block::Chart { caption, svg } => {
            let _ = write!(h, "<figure>{svg}");
            if !caption.is_empty() {
                let _ = write!(h, "<figcaption>{}</figcaption>", esc(caption));
            }
            h.push_str("</figure>");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_is_self_contained_and_escaped() {
        let mut r = Report::new("T <1>", "s", Status::Warn, "head & shoulders");
        r.fact("fit", "91.2 %", "5 steps");
        r.sections.push(
            Section::new("data", "Data", "lead")
                .with(Block::Text("a<b".into()))
                .with(Block::Table {
                    caption: "c".into(),
                    head: vec!["x".into()],
                    rows: vec![vec![Cell::num(1.234, 2).class("good")]],
                })
                .with(Block::lines(
                    "y",
                    "t",
                    "r",
                    &[Line::new("m", vec![0.0, 1.0], vec![1.0, 2.0], 0)],
                    "cap",
                )),
        );
        let html = r.render();
        assert!(html.contains("T &lt;1&gt;") && html.contains("head &amp; shoulders"));
        assert!(html.contains("a&lt;b"));
        assert!(html.contains(r#"<td class="good">1.23</td>"#));
        assert!(html.contains(r##"<a href="#data">Data</a>"##));
        assert!(!html.contains("href=\"http") && !html.contains("url(http"));
        assert!(!html.contains("<script") && !html.contains("src="));
    }
}
