//! The recorded trajectory and the golden files under `tests/data/`.
//!
//! `trajectory.csv` (`t_s,delta_deg,r_degps,psi_deg`) is a deterministic recording: a
//! seeded PRBS-like command with random switching intervals and three amplitudes driving a
//! plant with the base model's poles (f64, innovations form, shift form) with Irwin–Hall
//! noise; the heading integrates the yaw
//! rate. Some yaw-rate samples are missing (`NaN`, one `inf`), some headings too. Values are
//! written in Rust's shortest round-trip form, so reading them back gives the same bits.
//!
//! `golden/<model>.bin`: per step, one status byte and HORIZON little-endian f32.
//! `models/<model>.postcard`: the model blob.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use crate::{StepOut, HORIZON, STEPS};

/// Samples in the recording.
pub const SAMPLES: usize = STEPS + HORIZON;

/// Environment variable that allows golden files to be rewritten.
pub const REGEN_VAR: &str = "YAWCAST_REGEN_GOLDEN";

/// Whether this run regenerates golden files.
pub fn regenerate() -> bool {
    std::env::var(REGEN_VAR).is_ok_and(|v| v == "1")
}

/// `tests/data/`.
pub fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// A recording: command, measured yaw rate, measured heading (None when not logged).
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Sample time (s).
    pub ts: f32,
    /// Commanded angle (deg).
    pub u: Vec<f32>,
    /// Yaw rate (deg/s); NaN/inf = missing.
    pub y: Vec<f32>,
    /// Heading (deg).
    pub psi: Vec<Option<f32>>,
}

impl Trajectory {
    /// The commands after step `t` that a HORIZON-step prediction needs.
    pub fn future_u(&self, t: usize) -> &[f32] {
        &self.u[t + 1..t + HORIZON]
    }
}

/// xorshift64* generator.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Approximately standard normal (sum of 12 uniforms − 6): no libm, same bits everywhere.
    fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.uniform()).sum::<f64>() - 6.0
    }
}

/// Generates the recording (deterministic: same seed, same numbers).
pub fn generate_trajectory() -> Trajectory {
    // the plant that made the recording: the base model's poles in shift form, f64
    let a = [-0.086_45f32, 0.6135, -1.785, 2.25].map(f64::from);
    let b = [0.02f32, 0.035, 0.045, 0.05].map(f64::from);
    let k = [0.55f32, 0.45, 0.35, 0.25].map(f64::from);
    let ts = f64::from(crate::base_model().ts);
    let mut rng = Rng(0x00C0_FFEE_5EED_2021);
    let (mut u, mut y, mut psi) = (Vec::new(), Vec::new(), Vec::new());
    let mut x = [0.0f64; 4];
    let mut heading = 30.0f64;
    let mut level = 0.0f64;
    let mut hold = 0usize;
    for t in 0..SAMPLES {
        if hold == 0 {
            let amp = [3.0, 6.0, 12.0][(rng.next_u64() % 3) as usize];
            let sign = if level > 0.0 { -1.0 } else { 1.0 };
            level = sign * amp;
            hold = 2 + (rng.next_u64() % 24) as usize;
        }
        hold -= 1;
        let e = 0.08 * rng.normal();
        let yt = x[0] + e;
        let last = a[0] * x[0] + a[1] * x[1] + a[2] * x[2] + a[3] * x[3];
        let nx = [
            x[1] + b[0] * level + k[0] * e,
            x[2] + b[1] * level + k[1] * e,
            x[3] + b[2] * level + k[2] * e,
            last + b[3] * level + k[3] * e,
        ];
        x = nx;
        u.push(level as f32);
        let ym = if t == 500 {
            f32::INFINITY
        } else if t % 97 == 13 {
            f32::NAN
        } else {
            yt as f32
        };
        y.push(ym);
        psi.push(if (600..640).contains(&t) {
            None
        } else if t % 50 == 7 {
            Some(f32::NAN)
        } else {
            Some(heading as f32)
        });
        heading += ts * yt;
    }
    Trajectory {
        ts: crate::base_model().ts,
        u,
        y,
        psi,
    }
}

/// Writes the recording as CSV.
pub fn write_trajectory(path: &Path, tr: &Trajectory) -> std::io::Result<()> {
    let mut s = String::from("t_s,delta_deg,r_degps,psi_deg\n");
    for i in 0..tr.u.len() {
        let psi = tr.psi[i].map(|p| format!("{p:?}")).unwrap_or_default();
        let _ = writeln!(
            s,
            "{:?},{:?},{:?},{psi}",
            i as f32 * tr.ts,
            tr.u[i],
            tr.y[i]
        );
    }
    fs::write(path, s)
}

/// Reads a recording written by [`write_trajectory`].
///
/// # Errors
/// A message naming the file and line that does not parse.
pub fn read_trajectory(path: &Path) -> Result<Trajectory, String> {
    let text = fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (mut u, mut y, mut psi, mut t) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (no, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || format!("{}:{}: bad row {line:?}", path.display(), no + 1);
        if f.len() != 4 {
            return Err(bad());
        }
        let num = |s: &str| s.parse::<f32>().map_err(|_| bad());
        t.push(num(f[0])?);
        u.push(num(f[1])?);
        y.push(num(f[2])?);
        psi.push(if f[3].is_empty() {
            None
        } else {
            Some(num(f[3])?)
        });
    }
    let ts = if t.len() > 1 { t[1] - t[0] } else { 0.0 };
    Ok(Trajectory { ts, u, y, psi })
}

/// Serialises a golden record.
pub fn encode_golden(steps: &[StepOut]) -> Vec<u8> {
    let mut out = Vec::with_capacity(steps.len() * (1 + 4 * HORIZON));
    for s in steps {
        out.push(s.status);
        for v in s.yhat {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// Parses a golden record.
///
/// # Errors
/// When the length is not a whole number of steps.
pub fn decode_golden(bytes: &[u8]) -> Result<Vec<StepOut>, String> {
    let step = 1 + 4 * HORIZON;
    if bytes.len() % step != 0 {
        return Err(format!(
            "golden file of {} bytes is not whole steps",
            bytes.len()
        ));
    }
    Ok(bytes
        .chunks(step)
        .map(|c| {
            let mut yhat = [0.0f32; HORIZON];
            for (k, v) in yhat.iter_mut().enumerate() {
                let o = 1 + 4 * k;
                *v = f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
            }
            StepOut { status: c[0], yhat }
        })
        .collect())
}

/// Loads the trajectory, generating it first when regenerating.
///
/// # Panics
/// When the file is missing or unreadable (with the command that regenerates it).
pub fn trajectory() -> Trajectory {
    let path = data_dir().join("trajectory.csv");
    if regenerate() {
        fs::create_dir_all(data_dir()).expect("create tests/data");
        write_trajectory(&path, &generate_trajectory()).expect("write trajectory");
    }
    read_trajectory(&path).unwrap_or_else(|e| {
        panic!("{e}\n(generate golden data with {REGEN_VAR}=1 cargo test -p yawcast-tests)")
    })
}

/// Compares `bytes` with the golden file `rel` under `tests/data/` (or writes it when
/// regenerating). Returns the golden bytes.
///
/// # Panics
/// When the file is missing.
pub fn golden_bytes(rel: &str, bytes: &[u8]) -> Vec<u8> {
    let path = data_dir().join(rel);
    if regenerate() {
        fs::create_dir_all(path.parent().expect("parent")).expect("create golden dir");
        fs::write(&path, bytes).expect("write golden");
    }
    fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}\n(generate golden data with {REGEN_VAR}=1 cargo test -p yawcast-tests)",
            path.display()
        )
    })
}
