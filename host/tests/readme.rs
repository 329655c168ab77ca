//! The README's tour, run verbatim.
//!
//! The shell block between `<!-- session:begin -->` and `<!-- session:end -->` in README.md
//! runs under `bash -euo pipefail` in a scratch directory, with the built `yawcast` first on
//! PATH (where `cargo install --path host` puts it for a reader). Then:
//!
//! - the session exited 0, so every command in it did (`-e`; `-x` traces which one failed);
//! - every file a `yawcast` line names with `--out`, `--json`, `--save-ship` or `--ship`
//!   exists (`--out PATH` of a model: `PATH.postcard` and `PATH.json`);
//! - every JSON field a `#   FILE.json: a, b.c` comment line names is present in that file;
//! - what the README says of seed 1 below the session holds: `diagnose` names `gyro-bias`,
//!   `augment` adds it to the ship's own damping and angle limit, keeps it and writes it
//!   (only it) into `my-ship.toml`, the blob is 87 bytes.
//!
//! The demo's QEMU check is left out (`YAWCAST_FW_ELF` removed): `.ci/browser-test.sh` runs
//! it, and the demo says when it skipped it.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const BEGIN: &str = "<!-- session:begin -->";
const END: &str = "<!-- session:end -->";

fn readme() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The ```sh block between the markers.
fn session(readme: &str) -> String {
    let begin = readme
        .find(BEGIN)
        .expect("README.md has <!-- session:begin -->");
    let end = readme
        .find(END)
        .expect("README.md has <!-- session:end -->");
    assert!(begin < end, "session markers out of order");
    let block = &readme[begin + BEGIN.len()..end];
    let open = block
        .find("```sh\n")
        .expect("a ```sh block between the markers");
    let body = &block[open + "```sh\n".len()..];
    let close = body.rfind("```").expect("the ```sh block is closed");
    body[..close].to_string()
}

/// Logical lines: continuation backslashes joined.
fn logical_lines(script: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for line in script.lines() {
        let t = line.trim_end();
        if let Some(head) = t.strip_suffix('\\') {
            cur.push_str(head);
            cur.push(' ');
        } else {
            cur.push_str(t);
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// A `yawcast` command line of the session, with the directory it ran in.
#[derive(Debug)]
struct Cmd {
    dir: PathBuf,
    words: Vec<String>,
}

/// A `#   FILE.json: field, field.sub` line.
#[derive(Debug)]
struct Fields {
    file: PathBuf,
    fields: Vec<String>,
}

fn parse(script: &str, root: &Path) -> (Vec<Cmd>, Vec<Fields>) {
    let mut dir = root.to_path_buf();
    let mut cmds = Vec::new();
    let mut fields = Vec::new();
    for line in logical_lines(script) {
        let t = line.trim();
        if let Some(comment) = t.strip_prefix('#') {
            if let Some((left, right)) = comment.split_once(".json:") {
                let name = left
                    .split_whitespace()
                    .last()
                    .expect("a file before .json:");
                fields.push(Fields {
                    file: dir.join(format!("{name}.json")),
                    fields: right.split(',').map(|f| f.trim().to_string()).collect(),
                });
            }
            continue;
        }
        // The command, without a trailing comment.
        let code = t.split(" #").next().unwrap_or("").trim();
        if let Some(d) = code.strip_prefix("cd ") {
            dir = dir.join(d.trim());
        } else if code.starts_with("yawcast ") {
            cmds.push(Cmd {
                dir: dir.clone(),
                words: code.split_whitespace().map(str::to_string).collect(),
            });
        }
    }
    (cmds, fields)
}

/// `a.b.c` in a JSON value: each step an object key.
fn lookup<'a>(v: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    path.split('.').try_fold(v, |v, key| v.get(key))
}

fn read_json(p: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: not JSON: {e}", p.display()))
}

#[test]
fn readme_session_runs_verbatim() {
    let script = session(&readme());
    let root = std::env::temp_dir().join(format!("yawcast-readme-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();

    let (cmds, fields) = parse(&script, &root);
    assert!(
        cmds.len() >= 6,
        "too few yawcast commands in the session: {cmds:?}"
    );
    assert!(!fields.is_empty(), "the session names no JSON fields");

    let bin = PathBuf::from(env!("CARGO_BIN_EXE_yawcast"));
    let bin_dir = bin.parent().expect("the binary's directory");
    let path = std::env::join_paths(std::iter::once(bin_dir.to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let file = root.join("session.sh");
    std::fs::write(&file, &script).unwrap();

    let started = Instant::now();
    let out = Command::new("bash")
        .args(["-euxo", "pipefail"])
        .arg(&file)
        .current_dir(&root)
        .env("PATH", &path)
        .env_remove("YAWCAST_FW_ELF")
        .output()
        .expect("runs bash");
    let seconds = started.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "the README session failed ({}):\n--- stdout\n{stdout}\n--- stderr (trace)\n{stderr}",
        out.status
    );
    eprintln!("README session: {} commands in {seconds:.1} s", cmds.len());

    // The files the commands name.
    for c in &cmds {
        for pair in c.words.windows(2) {
            let (flag, value) = (pair[0].as_str(), pair[1].as_str());
            if !matches!(flag, "--out" | "--json" | "--save-ship" | "--ship") {
                continue;
            }
            let p = c.dir.join(value);
            let model = c.words[1] != "simulate" && c.words[1] != "demo" && flag == "--out";
            if model && p.extension().is_none() {
                for ext in ["postcard", "json"] {
                    let f = p.with_extension(ext);
                    assert!(
                        f.is_file(),
                        "`{}` wrote no {}",
                        c.words.join(" "),
                        f.display()
                    );
                }
            } else {
                assert!(
                    p.exists(),
                    "`{}` wrote no {}",
                    c.words.join(" "),
                    p.display()
                );
            }
        }
    }

    // The JSON fields the comments name.
    for f in &fields {
        let v = read_json(&f.file);
        for name in &f.fields {
            assert!(
                lookup(&v, name).is_some(),
                "{} has no field `{name}`:\n{v:#}",
                f.file.display()
            );
        }
    }

    // What the README says of seed 1.
    let run = root.join("runs/demo-1");
    let diagnosis = read_json(&run.join("mine/diagnosis.json"));
    assert_eq!(diagnosis["verdict"], "gyro-bias", "{diagnosis:#}");
    let augment = read_json(&run.join("mine/augment.json"));
    assert_eq!(augment["effect"], "gyro-bias", "{augment:#}");
    assert_eq!(augment["kept"], true, "{augment:#}");
    assert_eq!(
        augment["effects"],
        serde_json::json!(["nonlinear-damping", "saturation", "gyro-bias"]),
        "{augment:#}"
    );
    let twin = read_json(&run.join("mine/augmented.json"));
    let limit = twin["model"]["effects"][1]["limit"].as_f64().unwrap();
    assert!((18.5..19.5).contains(&limit), "{limit}");
    let ship = std::fs::read_to_string(run.join("my-ship.toml")).unwrap();
    assert!(ship.contains("kind = \"gyro-bias\""), "{ship}");
    assert!(
        !ship.contains("damping") && !ship.contains("saturation"),
        "{ship}"
    );
    let export = read_json(&run.join("mine/export.json"));
    assert_eq!(export["blob_len"], 87, "{export:#}");
    assert_eq!(
        std::fs::metadata(run.join("mine/controller.postcard"))
            .unwrap()
            .len(),
        87
    );

    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn session_parser_reads_commands_files_and_fields() {
    let script = "yawcast demo --seed 1   # comment\ncd runs/x\n\
                  yawcast identify $(each --data a.csv) \\\n    --out m/c --json m/i.json\n\
                  #   m/i.json: order, gain.tuned_kept\n";
    let (cmds, fields) = parse(script, Path::new("/r"));
    assert_eq!(cmds.len(), 2);
    assert_eq!(cmds[0].words, ["yawcast", "demo", "--seed", "1"]);
    assert_eq!(cmds[1].dir, Path::new("/r/runs/x"));
    assert_eq!(cmds[1].words.last().unwrap(), "m/i.json");
    assert_eq!(fields.len(), 1);
    assert_eq!(fields[0].file, Path::new("/r/runs/x/m/i.json"));
    assert_eq!(fields[0].fields, ["order", "gain.tuned_kept"]);
    let v: serde_json::Value = serde_json::json!({"gain": {"tuned_kept": true}});
    assert!(lookup(&v, "gain.tuned_kept").is_some());
    assert!(lookup(&v, "gain.mean").is_none());
}
