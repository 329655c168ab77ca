//! Helpers the CLI tests share: running the binary, scratch directories, small records and models.

pub(crate) use std::path::{Path, PathBuf};
pub(crate) use std::process::{Command, Output};

pub(crate) fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_yawcast"))
}

/// A fresh scratch directory per test, removed when the test is done with it — kept when
/// the test fails, for a look at what it wrote (its path is in the failure's messages).
pub(crate) fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("yawcast-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// A scratch directory ([`scratch`]): a path that removes itself unless the test panicked.
pub(crate) struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = PathBuf;
    fn deref(&self) -> &PathBuf {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

pub(crate) fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("runs the binary")
}

/// `yawcast compare --model MODEL --data DATA` and `extra` arguments.
pub(crate) fn run_compare(model: &str, data: &str, extra: &[&str]) -> Output {
    let mut args = vec!["compare", "--model", model, "--data", data];
    args.extend_from_slice(extra);
    run(&args)
}

pub(crate) fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub(crate) fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub(crate) fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

pub(crate) fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// A small stable 2nd-order model as a JSON twin.
pub(crate) fn write_model(dir: &Path) -> PathBuf {
    let p = dir.join("m.json");
    std::fs::write(
        &p,
        r#"{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.5,0.2],"effects":[]}"#,
    )
    .unwrap();
    p
}

/// A measurement CSV with `n` rows and a PRBS-like input.
pub(crate) fn csv_text(n: usize, ts: f64) -> String {
    let mut s = String::from("t_s,delta_deg,r_degps\n");
    let mut y = 0.0;
    for i in 0..n {
        let u = if (i / 7) % 2 == 0 { 10.0 } else { -10.0 };
        y = 0.9 * y + 0.01 * u;
        s.push_str(&format!("{},{},{:.6}\n", i as f64 * ts, u, y));
    }
    s
}

/// The firmware ELF for QEMU, when this machine has QEMU and a built firmware.
pub(crate) fn qemu_elf() -> Option<PathBuf> {
    let qemu = Command::new("qemu-system-arm")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !qemu {
        return None;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()?
        .to_path_buf();
    // The ELF named by YAWCAST_FW_ELF, when set, and no other.
    let c: Vec<PathBuf> = match std::env::var_os("YAWCAST_FW_ELF") {
        Some(p) => vec![PathBuf::from(p)],
        None => ["target", "target/thumb"]
            .iter()
            .map(|sub| {
                root.join(sub)
                    .join("thumbv7em-none-eabihf/release/yawcast-fw")
            })
            .collect(),
    };
    c.into_iter().find(|p| p.is_file())
}

/// A 4th-order record with noise, deterministic.
pub(crate) fn csv4(n: usize, seed: u64, noise: f64) -> String {
    let a = [-0.086_45, 0.6135, -1.785, 2.25];
    let b = [0.02, 0.035, 0.045, 0.05];
    let mut s = seed
        .wrapping_mul(2_862_933_555_777_941_757)
        .wrapping_add(3_037_000_493);
    let mut next = || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut x = [0.0f64; 4];
    let mut u = 10.0;
    let mut out = String::from("t_s,delta_deg,r_degps\n");
    for t in 0..n {
        if t % 9 == 0 {
            u = [-20.0, -10.0, 10.0, 20.0][(next() * 4.0) as usize % 4];
        }
        let y = x[0] + noise * (next() - 0.5);
        out.push_str(&format!("{},{},{:.6}\n", t as f64 * 0.5, u, y));
        let x4 = a[0] * x[0] + a[1] * x[1] + a[2] * x[2] + a[3] * x[3] + b[3] * u;
        x = [x[1] + b[0] * u, x[2] + b[1] * u, x[3] + b[2] * u, x4];
    }
    out
}

/// Simulated records written as CSVs through the library: `<name>-<seed>.csv`.
pub(crate) fn sim_csvs(
    dir: &Path,
    name: &str,
    effect: Option<yawcast::sim::SimEffect>,
    seeds: &[u64],
) -> Vec<PathBuf> {
    use yawcast::sim::{simulate, Scenario, Ship};
    let sc = Scenario {
        effects: effect.into_iter().collect(),
        ..Scenario::default()
    };
    seeds
        .iter()
        .map(|&seed| {
            let rec = simulate(&Ship::default_lng(), &sc, seed).unwrap();
            let p = dir.join(format!("{name}-{seed}.csv"));
            yawcast::io::data::write_csv(&p, &rec).unwrap();
            p
        })
        .collect()
}

/// The model identified (PEM, defaults) on the records `csvs`, written as `dir/base.json`:
/// a reference model for `diagnose` and `augment`.
pub(crate) fn model_from(dir: &Path, csvs: &[PathBuf]) -> PathBuf {
    let recs: Vec<_> = csvs
        .iter()
        .map(|p| yawcast::io::data::read_csv(p).unwrap())
        .collect();
    let base = yawcast::identify::pem::identify(&recs, None, &Default::default())
        .unwrap()
        .model;
    let model = dir.join("base.json");
    std::fs::write(&model, serde_json::to_string(&base).unwrap()).unwrap();
    model
}

/// Runs `yawcast` with a time limit: a hang is a failure, not a stuck test run.
pub(crate) fn run_limited(args: &[String], limit: std::time::Duration) -> Option<Output> {
    use std::process::Stdio;
    let mut child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs the binary");
    let t0 = std::time::Instant::now();
    loop {
        if child.try_wait().expect("waits").is_some() {
            return Some(child.wait_with_output().expect("collects output"));
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Every file under `dir` (recursively) with its bytes, sorted by relative path.
pub(crate) fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            if p.is_dir() {
                out.push((rel + "/", Vec::new()));
                stack.push(p);
            } else {
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// `export` arguments writing four outputs under `out/`: the JSON twin, the golden vectors,
/// the blob and the `--json` summary, from the model `m` checked on `data`.
pub(crate) fn export_args(m: &Path, data: &Path, out: &Path) -> Vec<String> {
    let s = |p: PathBuf| p.to_str().unwrap().to_string();
    vec![
        "export".into(),
        "--model".into(),
        s(m.to_path_buf()),
        "--data".into(),
        s(data.to_path_buf()),
        "--out".into(),
        s(out.join("ship")),
        "--golden".into(),
        s(out.join("golden.txt")),
        "--json".into(),
        s(out.join("summary.json")),
    ]
}
