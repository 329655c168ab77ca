//! The report page of a demo run: its sections, tables and plots.

use super::{effect_phrase, Fits, ModelResult, Outcome, HORIZON_KEYS, MPC_REFERENCE};
use crate::io::report::{Block, Cell, Line, Report, Section, Status};

fn fmt_fit(f: &Fits, k: &str) -> String {
    match f.get(k) {
        Some(v) if v.is_finite() => format!("{v:.1} %"),
        _ => "—".into(),
    }
}

fn fits_row(label: &str, f: &Fits) -> Vec<Cell> {
    let mut r = vec![Cell::text(label)];
    for k in HORIZON_KEYS {
        r.push(Cell::num(f.get(k).copied().unwrap_or(f64::NAN), 1));
    }
    r
}

fn fits_vec(f: &Fits) -> Vec<f64> {
    HORIZON_KEYS
        .iter()
        .map(|k| f.get(*k).copied().unwrap_or(f64::NAN))
        .collect()
}

fn horizon_head(first: &str) -> Vec<String> {
    let mut h = vec![first.to_string()];
    for k in HORIZON_KEYS {
        h.push(if k == "sim" {
            "simulation".into()
        } else {
            format!("{k}-step")
        });
    }
    h
}

fn std_class(v: f64) -> &'static str {
    if !v.is_finite() || v > 50.0 {
        "bad"
    } else if v > 10.0 {
        "warn"
    } else {
        "good"
    }
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        })
}

impl Outcome {
    /// The report page.
    pub fn report(&self) -> Report {
        let f = |m: &ModelResult, k: &str| m.fit.get(k).copied().unwrap_or(f64::NAN);
        let tuned_wins = f(&self.tuned, "5") > f(&self.conventional, "5");
        let aug_ok = f(&self.augmented, "10") >= f(&self.tuned, "10");
        let fw_ok = self.firmware.bit_exact();
        let right = self.diagnosis_right();
        let status = if right && tuned_wins && aug_ok && fw_ok {
            Status::Pass
        } else if fw_ok {
            Status::Warn
        } else {
            Status::Fail
        };
        let headline = if self.diagnosed_effect == "none" {
            "No missing physics found: the model explains the trials".to_string()
        } else {
            format!(
                "The trials carry {} that the simulator lacks — found, added, and the error fell",
                effect_phrase(&self.diagnosed_effect)
            )
        };
        let headline = if right {
            headline
        } else {
            format!(
                "Diagnosis named `{}`, the hidden effect was `{}`",
                self.diagnosed_effect, self.hidden_effect
            )
        };
        let mut r = Report::new(
            &format!("yawcast report — {} (seed {})", self.ship, self.seed),
            &format!(
                "{} identification records, {} lake trials · hidden effect revealed at the end · run took {:.1} s",
                self.ident.len(),
                self.trials.len(),
                self.seconds
            ),
            status,
            &headline,
        );
        r.verdict.push(format!(
            "Diagnosis: {} (hidden: {} — {}).",
            self.diagnosed_effect,
            self.hidden_effect,
            if right { "right" } else { "wrong" }
        ));
        r.verdict.push(self.explanation.clone());
        r.verdict.push(format!(
            "GA tuning: 5-step fit on the trials {} → {} (conventional → tuned); {}.",
            fmt_fit(&self.conventional.fit, "5"),
            fmt_fit(&self.tuned.fit, "5"),
            if tuned_wins {
                "the tuned model predicts better"
            } else {
                "the tuned model does NOT predict better"
            }
        ));
        r.verdict.push(format!(
            "Augmented with {}: 10-step fit {} → {}, simulation fit {} → {}.",
            self.diagnosed_effect,
            fmt_fit(&self.tuned.fit, "10"),
            fmt_fit(&self.augmented.fit, "10"),
            fmt_fit(&self.tuned.fit, "sim"),
            fmt_fit(&self.augmented.fit, "sim"),
        ));
        r.verdict.push(format!(
            "Firmware: {} of {} predicted values bit-exact natively; QEMU: {}.",
            self.firmware.native_equal, self.firmware.values, self.firmware.qemu_note
        ));
        r.fact(
            "5-step fit, tuned",
            fmt_fit(&self.tuned.fit, "5"),
            &format!("conventional {}", fmt_fit(&self.conventional.fit, "5")),
        );
        r.fact(
            "10-step fit, augmented",
            fmt_fit(&self.augmented.fit, "10"),
            &format!("tuned {}", fmt_fit(&self.tuned.fit, "10")),
        );
        r.fact(
            "simulation fit, augmented",
            fmt_fit(&self.augmented.fit, "sim"),
            &format!("tuned {}", fmt_fit(&self.tuned.fit, "sim")),
        );
        r.fact(
            "missing physics",
            self.diagnosed_effect.clone(),
            &format!("hidden: {}", self.hidden_effect),
        );
        r.fact(
            "firmware",
            if fw_ok { "bit-exact" } else { "MISMATCH" },
            &if self.firmware.qemu_equal.is_some() {
                "native and QEMU Cortex-M4F".to_string()
            } else {
                "native (QEMU not run)".to_string()
            },
        );
        r.fact(
            "run time",
            format!("{:.1} s", self.seconds),
            &format!("seed {}", self.seed),
        );
        r.sections.push(self.data_section());
        r.sections.push(self.fits_section());
        r.sections.push(self.parameters_section());
        r.sections.push(self.residuals_section());
        r.sections.push(self.regimes_section());
        r.sections.push(self.diagnosis_section());
        r.sections.push(self.augmentation_section());
        if let Some(t) = &self.track {
            r.sections.push(track_section(t));
        }
        r.sections.push(self.firmware_section());
        r
    }

    fn data_section(&self) -> Section {
        let mut rows = Vec::new();
        for (role, recs) in [
            ("identification", &self.ident),
            ("lake trial", &self.trials),
        ] {
            for rec in recs.iter() {
                let (u0, u1) = range(&rec.u);
                let (y0, y1) = range(&rec.y);
                rows.push(vec![
                    Cell::text(&rec.name),
                    Cell::text(role),
                    Cell::num(rec.len() as f64, 0),
                    Cell::num(rec.len() as f64 * rec.ts, 0),
                    Cell::text(format!("{u0:.1} … {u1:.1}")),
                    Cell::text(format!("{y0:.2} … {y1:.2}")),
                ]);
            }
        }
        let mut s = Section::new(
            "data",
            "The data",
            "Identification records come from the simulator without the hidden effect; the lake \
             trials come from the simulator with it, plus sensor noise. The model is identified on \
             the first and judged on the second, as in the paper.",
        );
        for (role, rec) in [
            ("identification", self.ident.first()),
            ("lake trial", self.trials.get(self.example)),
        ] {
            if let Some(rec) = rec {
                s = s.with(Block::lines(
                    &format!("{role} record {}", rec.name),
                    "time [s]",
                    "δ [deg] · r [deg/s ×10]",
                    &[
                        Line::new("pod angle δ [deg]", rec.t.clone(), rec.u.clone(), 2),
                        Line::new(
                            "yaw rate r [deg/s] ×10",
                            rec.t.clone(),
                            rec.y.iter().map(|v| v * 10.0).collect(),
                            1,
                        ),
                    ],
                    &format!(
                        "{role} record {}: pseudo-random pod commands and the yaw-rate response (scaled ×10 to share the axis).",
                        rec.name
                    ),
                ));
            }
        }
        s.with(Block::Table {
            caption: "Records".into(),
            head: vec![
                "record".into(),
                "role".into(),
                "samples".into(),
                "duration [s]".into(),
                "δ range [deg]".into(),
                "r range [deg/s]".into(),
            ],
            rows,
        })
    }

    fn fits_section(&self) -> Section {
        let mut rows = vec![
            fits_row(&self.conventional.label, &self.conventional.fit),
            fits_row(&self.tuned.label, &self.tuned.fit),
            fits_row(&self.augmented.label, &self.augmented.fit),
        ];
        let mut gain = vec![Cell::text("tuned − conventional [pp]")];
        for k in HORIZON_KEYS {
            let g = self.tuned.fit.get(k).copied().unwrap_or(f64::NAN)
                - self.conventional.fit.get(k).copied().unwrap_or(f64::NAN);
            gain.push(Cell::num(g, 1).class(if g > 0.0 { "good" } else { "bad" }));
        }
        rows.push(gain);
        let mut paper = Vec::new();
        for (k, refv) in MPC_REFERENCE {
            let t = self.tuned.fit.get(k).copied().unwrap_or(f64::NAN);
            let c = self.conventional.fit.get(k).copied().unwrap_or(f64::NAN);
            paper.push(vec![
                Cell::text(format!("{k}-step")),
                Cell::num(refv, 0),
                Cell::num(c, 1),
                Cell::num(t, 1),
                Cell::num(t - refv, 1).class(if t >= refv { "good" } else { "bad" }),
                Cell::num(t - c, 1).class(if t > c { "good" } else { "bad" }),
            ]);
        }
        let mut combos = Vec::new();
        for m in &self.combos {
            let mut row = fits_row(&m.label, &m.fit);
            row.push(Cell::text(if m.label == self.chosen {
                "chosen".to_string()
            } else {
                m.note.clone()
            }));
            combos.push(row);
        }
        let mut combo_head = horizon_head("combination");
        combo_head.push("note".into());
        let mut s = Section::new(
            "fits",
            "How well it predicts",
            "Fit % = 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) on the lake trials (mean over records), k-step-ahead \
             predictions as MATLAB's predict/compare. The paper's benchmark for an MPC model is 80 % \
             at short and 65 % at long horizon.",
        )
        .with(Block::bars(
            "Fit on the lake trials per horizon",
            "fit [%]",
            &["1-step", "5-step", "10-step", "20-step", "simulation"],
            &[
                (self.conventional.label.as_str(), fits_vec(&self.conventional.fit)),
                (self.tuned.label.as_str(), fits_vec(&self.tuned.fit)),
                (self.augmented.label.as_str(), fits_vec(&self.augmented.fit)),
            ],
        ))
        .with(Block::Table {
            caption: "Fit % on the lake trials (the paper's Table 4, our numbers)".into(),
            head: horizon_head("model"),
            rows,
        })
        .with(Block::Table {
            caption: "Improvement of the tuned model (the paper's Table 5, our numbers)".into(),
            head: vec![
                "horizon".into(),
                "MPC reference".into(),
                "conventional".into(),
                "GA-tuned".into(),
                "tuned − reference [pp]".into(),
                "tuned − conventional [pp]".into(),
            ],
            rows: paper,
        });
        if let Some(rec) = self.trials.get(self.example) {
            let mut lines = vec![Line::new("measured r", rec.t.clone(), rec.y.clone(), 0)];
            for (i, (label, yh)) in self.example_series.iter().enumerate() {
                lines.push(Line::new(label, rec.t.clone(), yh.clone(), i + 1));
            }
            let (lo, hi) = range(&rec.y);
            let pad = 0.5 * (hi - lo);
            s = s.with(Block::lines_clipped(
                &format!("Measured vs predicted, trial {}", rec.name),
                "time [s]",
                "yaw rate [deg/s]",
                &lines,
                (lo - pad, hi + pad),
                &format!(
                    "Tuned model on trial {}: the longer the horizon, the further the prediction drifts.",
                    rec.name
                ),
            ));
        }
        s.with(Block::Text(self.tuning_note.clone()))
            .with(Block::Table {
                caption: "Several trials → one model".into(),
                head: combo_head,
                rows: combos,
            })
    }

    fn parameters_section(&self) -> Section {
        let names = self.tuned.model.param_names();
        let th_c = self.conventional.model.theta();
        let th_t = self.tuned.model.theta();
        let mut rows = Vec::new();
        for (i, name) in names.iter().enumerate().take(th_t.len()) {
            let sc = self
                .conventional
                .std_pct
                .get(i)
                .copied()
                .unwrap_or(f64::NAN);
            let st = self.tuned.std_pct.get(i).copied().unwrap_or(f64::NAN);
            rows.push(vec![
                Cell::text(name),
                Cell::num(th_c.get(i).copied().unwrap_or(f64::NAN), 5),
                Cell::num(sc, 1).class(std_class(sc)),
                Cell::num(th_t[i], 5),
                Cell::num(st, 1).class(std_class(st)),
            ]);
        }
        let groups: Vec<&str> = names.iter().take(th_t.len()).map(String::as_str).collect();
        let cap = |v: &[f64]| -> Vec<f64> { v.iter().take(groups.len()).copied().collect() };
        let unreliable = |m: &ModelResult| m.std_pct.iter().filter(|v| **v > 10.0).count();
        Section::new(
            "parameters",
            "Parameters and their uncertainty",
            "θ = (a, b, k) of the canonical innovations model with the standard deviation of each \
             estimate in % of its value. The paper's rule: above 10 % a parameter is unreliable, \
             above 50 % unusable. Regularisation (λ, R tuned by the GA) is what brings the b's down.",
        )
        .with(Block::bars_capped(
            "STD % per parameter (bars cut at 100 %)",
            "STD [% of value]",
            &groups,
            &[
                (self.conventional.label.as_str(), cap(&self.conventional.std_pct)),
                (self.tuned.label.as_str(), cap(&self.tuned.std_pct)),
            ],
            100.0,
        ))
        .with(Block::Table {
            caption: "Parameters and STD % (the paper's Tables 3 and 6, our numbers)".into(),
            head: vec![
                "parameter".into(),
                format!("{}", self.conventional.label),
                "STD %".into(),
                format!("{}", self.tuned.label),
                "STD %".into(),
            ],
            rows,
        })
        .with(Block::Note(format!(
            "Parameters above 10 % STD: {} in the conventional model, {} in the tuned model.",
            unreliable(&self.conventional),
            unreliable(&self.tuned)
        )))
    }

    fn residuals_section(&self) -> Section {
        let mut s = Section::new(
            "residuals",
            "Where it fails: residual tests",
            "One-step residuals on the trials should be white and uncorrelated with the input. \
             Dashed lines: 99 % bands (ACF ±2.58/√N; CCF with MATLAB's band). Orange stems leave \
             the band.",
        );
        for r in [&self.resid_before, &self.resid_after] {
            if r.acf.is_empty() {
                continue;
            }
            let lags: Vec<f64> = (1..r.acf.len()).map(|l| l as f64).collect();
            s = s.with(
                Block::stems(
                    &format!("Residual autocorrelation — {}", r.label),
                    "lag [samples]",
                    &lags,
                    &r.acf[1..],
                    &[r.acf_band],
                )
                .caption(&format!(
                    "{}: ACF at lags 1…{}, N = {}, Ljung–Box p = {:.3}{}.",
                    r.label,
                    r.acf.len() - 1,
                    r.n,
                    r.ljung_box_p,
                    if r.ljung_box_p < 0.01 {
                        " — not white"
                    } else {
                        ""
                    }
                )),
            );
            if !r.ccf.is_empty() {
                s = s.with(
                    Block::stems(
                        &format!("Input–residual cross-correlation — {}", r.label),
                        "lag [samples]",
                        &r.ccf_lags,
                        &r.ccf,
                        &r.ccf_band,
                    )
                    .caption(&format!(
                        "{}: correlation of the residual with the pod command at each lag.",
                        r.label
                    )),
                );
            }
        }
        s
    }

    fn regimes_section(&self) -> Section {
        let mut s = Section::new(
            "regimes",
            "Where it fails: error by regime",
            "10-step prediction RMSE [deg/s] binned by what the ship was doing, before and after \
             augmentation. An effect that is missing shows up as error concentrated in one regime.",
        );
        for g in &self.regimes {
            let groups: Vec<&str> = g.bins.iter().map(String::as_str).collect();
            s = s.with(Block::bars(
                &format!("10-step RMSE by {}", g.dimension),
                "RMSE [deg/s]",
                &groups,
                &[
                    (self.tuned.label.as_str(), g.before.clone()),
                    (self.augmented.label.as_str(), g.after.clone()),
                ],
            ));
        }
        if !self.worst.is_empty() {
            let rows = self
                .worst
                .iter()
                .map(|(rec, a, b, e, what)| {
                    vec![
                        Cell::text(rec),
                        Cell::text(format!("{a:.0}–{b:.0} s")),
                        Cell::num(*e, 3),
                        Cell::text(what),
                    ]
                })
                .collect();
            s = s.with(Block::Table {
                caption: "Worst time windows (before augmentation)".into(),
                head: vec![
                    "record".into(),
                    "window".into(),
                    "RMSE [deg/s]".into(),
                    "what was happening".into(),
                ],
                rows,
            });
        }
        s
    }

    fn diagnosis_section(&self) -> Section {
        let groups: Vec<&str> = self.ranking.iter().map(|e| e.effect.as_str()).collect();
        let gains: Vec<f64> = self.ranking.iter().map(|e| e.fit_gain_pp).collect();
        let rows = self
            .ranking
            .iter()
            .map(|e| {
                vec![
                    Cell::text(&e.effect).class(if e.selected { "good" } else { "" }),
                    Cell::num(e.statistic, 1),
                    Cell::text(if e.p_value < 1e-4 {
                        "< 0.0001".to_string()
                    } else {
                        format!("{:.4}", e.p_value)
                    }),
                    Cell::num(e.fit_gain_pp, 2),
                    Cell::text(&e.evidence),
                ]
            })
            .collect();
        Section::new(
            "diagnosis",
            "Which physics is missing",
            "Every effect of the library is tested on the trials and on the simulator's reference \
             records; what the trials have and the reference lacks is what the simulator misses. \
             p-values are calibrated by re-simulation; an effect is reported only when significant \
             and material.",
        )
        .with(Block::Text(self.explanation.clone()))
        .with(Block::bars(
            "Held-out fit gain per effect",
            "fit gain [pp]",
            &groups,
            &[("10-step fit gain when added", gains)],
        ))
        .with(Block::Table {
            caption: "Effect ranking".into(),
            head: vec![
                "effect".into(),
                "statistic".into(),
                "p-value".into(),
                "fit gain [pp]".into(),
                "evidence".into(),
            ],
            rows,
        })
        .with(Block::Note(format!(
            "Hidden effect of this run (revealed now): {} — {}.",
            self.hidden_effect, self.hidden_detail
        )))
    }

    fn augmentation_section(&self) -> Section {
        let mut s = Section::new(
            "augmentation",
            "Before and after augmentation",
            "The diagnosed effect is added to the model and re-identified; the same effect with its \
             estimated parameters goes into the ship's simulator file, and the simulator's own \
             records then match the trials better.",
        )
        .with(Block::bars(
            "Fit on the lake trials, before and after",
            "fit [%]",
            &["1-step", "5-step", "10-step", "20-step", "simulation"],
            &[
                (self.tuned.label.as_str(), fits_vec(&self.tuned.fit)),
                (self.augmented.label.as_str(), fits_vec(&self.augmented.fit)),
            ],
        ));
        if let Some(rec) = self.trials.get(self.example) {
            let before = self
                .example_series
                .iter()
                .find(|(l, _)| l.contains("10"))
                .map(|(_, v)| v.clone())
                .unwrap_or_default();
            let (lo, hi) = range(&rec.y);
            let pad = 0.5 * (hi - lo);
            s = s.with(Block::lines_clipped(
                &format!("10-step prediction before and after, trial {}", rec.name),
                "time [s]",
                "yaw rate [deg/s]",
                &[
                    Line::new("measured r", rec.t.clone(), rec.y.clone(), 0),
                    Line::new(&self.tuned.label, rec.t.clone(), before, 1),
                    Line::new(
                        &self.augmented.label,
                        rec.t.clone(),
                        self.example_augmented.clone(),
                        3,
                    ),
                ],
                (lo - pad, hi + pad),
                "",
            ));
        }
        s.with(Block::Table {
            caption: "Simulator vs trials: a model identified on the simulator's records, scored on the trials".into(),
            head: horizon_head("ship file"),
            rows: vec![
                fits_row("before (no effect)", &self.ship_before),
                fits_row("after (effect written in)", &self.ship_after),
            ],
        })
        .with(Block::Text(self.ship_note.clone()))
    }

    fn firmware_section(&self) -> Section {
        let fw = &self.firmware;
        let ok = |b: bool| if b { "good" } else { "bad" };
        let native = fw.values > 0 && fw.native_equal == fw.values;
        let mut rows = vec![
            vec![
                Cell::text(
                    "firmware library (x86_64) on the exported blob = export-time golden vectors",
                ),
                Cell::text(format!("{} / {}", fw.native_equal, fw.values)).class(ok(native)),
            ],
            vec![
                Cell::text("firmware on Cortex-M4F (QEMU netduinoplus2) = native"),
                match fw.qemu_equal {
                    Some(q) => Cell::text(format!("{q} / {}", fw.values)).class(ok(q == fw.values)),
                    None => Cell::text(format!("not run: {}", fw.qemu_note)).class("warn"),
                },
            ],
            vec![
                Cell::text("10-step fit: host f64 vs firmware f32"),
                Cell::text(format!(
                    "{:.4} % vs {:.4} % (Δ {:.4} pp)",
                    fw.fit_f64,
                    fw.fit_f32,
                    (fw.fit_f64 - fw.fit_f32).abs()
                ))
                .class(ok((fw.fit_f64 - fw.fit_f32).abs() <= 0.01)),
            ],
        ];
        rows.push(vec![
            Cell::text("model blob"),
            Cell::text(format!("{} bytes (magic, version, CRC-32)", fw.blob_bytes)),
        ]);
        let diff: Vec<f64> = fw
            .host
            .iter()
            .zip(&fw.firmware)
            .map(|(a, b)| (a - b) * 1e6)
            .collect();
        Section::new(
            "firmware",
            "On the controller",
            "The exported model runs through the firmware's f32 predictor: natively on this machine \
             and, when QEMU is installed, on an emulated Cortex-M4F. Predictions must agree bit for \
             bit, and the f32 fit must equal the host's f64 fit to 0.01 pp.",
        )
        .with(Block::Table {
            caption: "Firmware checks".into(),
            head: vec!["check".into(), "result".into()],
            rows,
        })
        .with(Block::lines(
            "Host f64 vs firmware f32, 10-step predictions",
            "time [s]",
            "yaw rate [deg/s]",
            &[
                Line::new("measured r", fw.t.clone(), fw.y.clone(), 0),
                Line::new("host f64", fw.t.clone(), fw.host.clone(), 2),
                Line::new("firmware f32", fw.t.clone(), fw.firmware.clone(), 1).dashed(),
            ],
            "",
        ))
        .with(Block::lines(
            "f64 − f32 difference of the 10-step predictions",
            "time [s]",
            "difference [µdeg/s]",
            &[Line::new("host − firmware", fw.t.clone(), diff, 4)],
            "Rounding differences of f32 arithmetic only: micro-degrees per second.",
        ))
    }
}

/// The heading and track prediction on the demo's current case.
fn track_section(t: &super::TrackCase) -> Section {
    let row = |label: &str, f: &Fits| {
        let mut r = vec![Cell::text(label)];
        for k in ["30", "60", "120"] {
            r.push(Cell::num(f.get(k).copied().unwrap_or(f64::NAN), 1));
        }
        r
    };
    let mut heading = vec![Cell::text("heading fit [%]")];
    for k in ["1", "5", "10", "20"] {
        heading.push(Cell::num(
            t.heading_fit.get(k).copied().unwrap_or(f64::NAN),
            2,
        ));
    }
    Section::new(
        "track",
        "Heading and track: a current case",
        &format!(
            "A uniform current of {:.1} m/s setting towards {:.0}° moves the ship without \
             turning it: the yaw-rate error cannot show it, the track error does. The \
             conventional model with the heading/track part fitted on effect-free simulator \
             records predicts heading and position on a record with that current, without \
             and with the track's estimate of the current (corrected from speed and course \
             over ground and position fixes).",
            t.current_mps, t.towards_deg
        ),
    )
    .with(Block::Table {
        caption: "Median track error [m] at each horizon".into(),
        head: vec![
            "track part".into(),
            "30 s".into(),
            "60 s".into(),
            "120 s".into(),
        ],
        rows: vec![
            row("without the current", &t.before),
            row("current estimated", &t.after),
        ],
    })
    .with(Block::Table {
        caption: "Heading fit on the current record".into(),
        head: vec![
            "".into(),
            "1-step".into(),
            "5-step".into(),
            "10-step".into(),
            "20-step".into(),
        ],
        rows: vec![heading],
    })
}
