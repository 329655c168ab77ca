//! All outputs or none: faults and signals during a write, and the exit-code contract.

use crate::common::*;

/// A write that fails after its first output was renamed into place (fault injection
/// through `YAWCAST_TEST_FAIL_RENAME`) leaves no output: new files are taken back, files it
/// would have replaced keep their bytes, no temporary file or backup remains; exit 1 (the
/// paths were checked first, so this is not the input's fault).
#[test]
fn a_write_failing_after_the_first_output_leaves_none() {
    let d = scratch("fault");
    let m = write_model(&d);
    let a = d.join("a.csv");
    std::fs::write(&a, csv_text(300, 0.5)).unwrap();
    let b = d.join("b.csv");
    std::fs::write(&b, csv_text(260, 0.5)).unwrap();
    // New destinations, in a directory the write would create.
    let fresh = d.join("fresh/runs");
    for fail_at in [2, 3, 4] {
        let o = bin()
            .args(export_args(&m, &a, &fresh))
            .env("YAWCAST_TEST_FAIL_RENAME", fail_at.to_string())
            .output()
            .unwrap();
        assert_eq!(code(&o), 1, "rename {fail_at}: {}", stderr(&o));
        let first = stderr(&o).lines().next().unwrap_or("").to_string();
        assert!(
            first.starts_with("error: writing the outputs failed, none was written")
                && first.contains(&format!("rename {fail_at} failed")),
            "{first}"
        );
        assert!(
            !d.join("fresh").exists(),
            "rename {fail_at}: {:?}",
            tree(&d)
        );
    }
    // Existing outputs from a first run, then a run on other data that fails half-way.
    let out = d.join("out");
    let o = bin().args(export_args(&m, &a, &out)).output().unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let before = tree(&out);
    let names: Vec<&str> = before.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["golden.txt", "ship.json", "ship.postcard", "summary.json"]
    );
    // Another model (so the blob differs too) on other data.
    let m2 = d.join("m2.json");
    std::fs::write(
        &m2,
        r#"{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[0.01,0.02],"k":[0.4,0.1],"effects":[]}"#,
    )
    .unwrap();
    for fail_at in [2, 3, 4] {
        let o = bin()
            .args(export_args(&m2, &b, &out))
            .env("YAWCAST_TEST_FAIL_RENAME", fail_at.to_string())
            .output()
            .unwrap();
        assert_eq!(code(&o), 1, "rename {fail_at}: {}", stderr(&o));
        assert!(tree(&out) == before, "rename {fail_at}: outputs changed");
    }
    // The same run without the fault replaces all four.
    let o = bin().args(export_args(&m2, &b, &out)).output().unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let after = tree(&out);
    assert_eq!(after.len(), 4);
    for ((n0, b0), (n1, b1)) in before.iter().zip(&after) {
        assert_eq!(n0, n1);
        assert_ne!(b0, b1, "{n0} was not rewritten from b.csv");
    }
}

/// SIGTERM or SIGINT arriving between two renames of the outputs (the write paused there by
/// `YAWCAST_TEST_PAUSE_RENAME` until the signal comes, so the moment is certain): the new
/// JSON twin already renamed is taken back, the old blob and twin are as they were, no
/// temporary file or backup is left, and the exit code is 128 + the signal — for `export`
/// and for `tune`.
#[test]
fn a_signal_during_the_write_rolls_back_and_exits_128_plus_the_signal() {
    let d = scratch("signal");
    let m = write_model(&d);
    let a = d.join("a.csv");
    std::fs::write(&a, csv_text(300, 0.5)).unwrap();
    let b = d.join("b.csv");
    std::fs::write(&b, csv_text(260, 0.5)).unwrap();
    let out = d.join("out");
    let o = bin().args(export_args(&m, &a, &out)).output().unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let before = tree(&out);
    for (signal, expected) in [("TERM", 143), ("INT", 130)] {
        let marker = d.join(format!("paused-{signal}"));
        let mut child = bin()
            .args(export_args(&m, &b, &out))
            .env("YAWCAST_TEST_PAUSE_RENAME", &marker)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Wait for the pause (bounded: a run that never gets there fails the test).
        let mut polls = 0;
        while !marker.exists() {
            assert!(
                child.try_wait().unwrap().is_none(),
                "the run ended before its write"
            );
            assert!(polls < 60_000, "the write never paused");
            std::thread::sleep(std::time::Duration::from_millis(5));
            polls += 1;
        }
        // The first output is in place beside the old ones: the moment a signal must not
        // leave as it is.
        assert_ne!(
            std::fs::read(out.join("ship.json")).unwrap(),
            before.iter().find(|(n, _)| n == "ship.json").unwrap().1
        );
        let k = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(k.success());
        let o = child.wait_with_output().unwrap();
        assert_eq!(code(&o), expected, "SIG{signal}: {}", stderr(&o));
        assert!(
            stderr(&o).starts_with(&format!("error: interrupted by SIG{signal}")),
            "{}",
            stderr(&o)
        );
        assert!(tree(&out) == before, "SIG{signal}: outputs changed");
    }
    // tune's five outputs (blob, twin, both tables, summary), interrupted after the first.
    let t = d.join("tune");
    let sim = run(&[
        "simulate",
        "--duration",
        "600",
        "--records",
        "2",
        "--seed",
        "1",
        "--out",
        t.join("sim.csv").to_str().unwrap(),
    ]);
    assert_eq!(code(&sim), 0, "{}", stderr(&sim));
    let tune = |data: &str, validate: &str| -> Command {
        let mut c = bin();
        c.args(["tune", "--generations", "2", "--order", "2", "--seed", "3"]);
        c.arg("--data").arg(t.join(data));
        c.arg("--validate").arg(t.join(validate));
        c.arg("--out").arg(t.join("out/ship"));
        c.arg("--json").arg(t.join("out/summary.json"));
        c
    };
    let o = tune("sim-1.csv", "sim-2.csv").output().unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let before = tree(&t.join("out"));
    assert_eq!(
        before.len(),
        5,
        "{:?}",
        before.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    let marker = t.join("paused");
    let mut child = tune("sim-2.csv", "sim-1.csv")
        .env("YAWCAST_TEST_PAUSE_RENAME", &marker)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut polls = 0;
    while !marker.exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "tune ended before its write"
        );
        assert!(polls < 60_000, "tune's write never paused");
        std::thread::sleep(std::time::Duration::from_millis(5));
        polls += 1;
    }
    assert!(
        tree(&t.join("out")) != before,
        "nothing renamed before the pause"
    );
    let k = Command::new("kill")
        .args(["-INT".to_string(), child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(code(&o), 130, "{}", stderr(&o));
    assert!(tree(&t.join("out")) == before, "tune's outputs changed");
}

/// The exit-code contract, one table: 0 success, 2 bad input or arguments (the run names
/// the file, row, field or flag), 1 an internal or numerical failure.
#[test]
fn exit_codes_follow_one_contract() {
    let d = scratch("exit-codes");
    let m = write_model(&d);
    std::fs::write(d.join("good.csv"), csv4(400, 1, 0.02)).unwrap();
    std::fs::write(d.join("good2.csv"), csv4(400, 2, 0.02)).unwrap();
    std::fs::write(d.join("short.csv"), csv_text(300, 0.5)).unwrap();
    std::fs::write(d.join("file"), b"a file").unwrap();
    std::fs::create_dir_all(d.join("sub")).unwrap();
    std::fs::write(d.join("sub/short.csv"), csv_text(300, 0.5)).unwrap();
    // navigation channels: good ones (courses through 360°), and four kinds of bad input
    let nav = |cols: &str, cell: &dyn Fn(usize) -> String| {
        let mut out = String::new();
        for (i, line) in csv_text(300, 0.5).lines().enumerate() {
            out.push_str(line);
            out.push(',');
            if i == 0 {
                out.push_str(cols);
            } else {
                out.push_str(&cell(i));
            }
            out.push('\n');
        }
        out
    };
    type Cell<'a> = &'a dyn Fn(usize) -> String;
    let files: [(&str, &str, Cell); 5] = [
        ("nav-good.csv", "psi_deg,u_mps,cog_deg", &|i| {
            format!("{},1.2,{}", 355 + i % 10, (355 + i % 10) % 360)
        }),
        ("nav-negative.csv", "u_mps,cog_deg", &|i| {
            format!("{},10", if i == 7 { -0.5 } else { 1.0 })
        }),
        ("nav-text.csv", "u_mps,cog_deg", &|i| {
            format!("1.0,{}", if i == 9 { "north" } else { "10" })
        }),
        ("nav-half.csv", "lat_deg", &|_| "60.0".to_string()),
        ("nav-lat.csv", "lat_deg,lon_deg", &|i| {
            format!("{},10.0", if i == 4 { 95.0 } else { 60.0 })
        }),
    ];
    for (name, cols, cell) in files {
        std::fs::write(d.join(name), nav(cols, cell)).unwrap();
    }
    // A valid, stable model whose gain is 10⁴ times the records': its simulation runs off
    // the record (fit about −10⁶ %), a numerical failure, not a result to print.
    std::fs::write(
        d.join("wild.json"),
        r#"{"n":2,"ts":0.5,"a":[-0.2,0.7],"b":[100.0,200.0],"k":[0.5,0.2],"effects":[]}"#,
    )
    .unwrap();
    let cases: &[(&str, i32, &str)] = &[
        ("help", 0, "--help"),
        ("version", 0, "--version"),
        ("unknown subcommand", 2, "fly"),
        ("simulate", 0, "simulate --duration 100 --seed 1 --out {d}/sim.csv --json {d}/sim.json"),
        ("simulate, bad --ts", 2, "simulate --ts 0 --out {d}/x.csv"),
        ("simulate, output under a file", 2, "simulate --duration 100 --out {d}/file/x.csv"),
        ("identify", 0, "identify --data {d}/good.csv --out {d}/m4 --json {d}/m4-summary.json"),
        ("identify, bad --orders", 2, "identify --data {d}/good.csv --orders 1..9"),
        ("identify, --json under a file", 2, "identify --data {d}/good.csv --json {d}/file/s.json"),
        ("average", 0, "average --data {d}/good.csv --data {d}/good2.csv --validate {d}/good2.csv --out {d}/avg"),
        ("average, no --validate", 2, "average --data {d}/good.csv"),
        ("tune, 0 generations", 2, "tune --data {d}/good.csv --validate {d}/good2.csv --generations 0"),
        ("tune, --out under a file", 2, "tune --data {d}/good.csv --validate {d}/good2.csv --out {d}/file/t"),
        ("export", 0, "export --model {model} --data {d}/short.csv --out {d}/exp --golden {d}/golden.txt"),
        ("export, --golden is a directory", 2, "export --model {model} --data {d}/short.csv --out {d}/exp2 --golden {d}"),
        ("compare", 0, "compare --model {model} --data {d}/short.csv --out {d}/series --json {d}/cmp.json"),
        ("compare, diverging model", 1, "compare --model {d}/wild.json --data {d}/short.csv --horizons sim"),
        ("compare, two records of one name", 2, "compare --model {model} --data {d}/short.csv --data {d}/sub/short.csv --out {d}/series2"),
        ("compare, missing model", 2, "compare --model {d}/nowhere.json --data {d}/short.csv"),
        ("compare, navigation channels", 0, "compare --model {model} --data {d}/nav-good.csv"),
        ("compare, negative speed over ground", 2, "compare --model {model} --data {d}/nav-negative.csv"),
        ("compare, text as a course", 2, "compare --model {model} --data {d}/nav-text.csv"),
        ("compare, latitude without longitude", 2, "compare --model {model} --data {d}/nav-half.csv"),
        ("compare, latitude beyond 90°", 2, "compare --model {model} --data {d}/nav-lat.csv"),
        ("resid", 0, "resid --model {model} --data {d}/short.csv --out {d}/plots"),
        ("resid, --max-lag 0", 2, "resid --model {model} --data {d}/short.csv --max-lag 0"),
        ("diagnose, --alpha 2", 2, "diagnose --model {model} --data {d}/short.csv --alpha 2"),
        ("diagnose, --out under a file", 2, "diagnose --model {model} --data {d}/short.csv --out {d}/file/plots"),
        ("augment", 0, "augment --model {model} --effect bias --data {d}/short.csv --out {d}/aug"),
        ("augment, unknown effect", 2, "augment --model {model} --effect waves --data {d}/short.csv --out {d}/aug2"),
        ("augment, --ship under a file", 2, "augment --model {model} --effect bias --data {d}/short.csv --out {d}/aug3 --ship {d}/file/s.toml"),
        ("hil, --steps 0", 2, "hil --model {model} --steps 0"),
        ("demo, --duration 0", 2, "demo --duration 0 --out {d}/demo"),
        ("split", 0, "split --data {d}/short.csv --out {d}/pieces --json {d}/split.json"),
        ("split, --min-samples beyond every piece", 2, "split --data {d}/short.csv --min-samples 301 --out {d}/pieces2"),
        ("split, --out under a file", 2, "split --data {d}/short.csv --out {d}/file/p"),
    ];
    let mut failures = Vec::new();
    for (name, expected, args) in cases {
        let args: Vec<String> = args
            .split_whitespace()
            .map(|a| {
                a.replace("{d}", d.to_str().unwrap())
                    .replace("{model}", m.to_str().unwrap())
            })
            .collect();
        let Some(o) = run_limited(&args, std::time::Duration::from_secs(120)) else {
            failures.push(format!("{name}: hangs"));
            continue;
        };
        let e = stderr(&o);
        if code(&o) != *expected {
            failures.push(format!(
                "{name}: exit {} (expected {expected}): {e}",
                code(&o)
            ));
        } else if *expected != 0 && !e.starts_with("error: ") && *name != "unknown subcommand" {
            failures.push(format!("{name}: the first line is not the cause: {e}"));
        }
        if e.contains("panicked") {
            failures.push(format!("{name}: panics: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Outputs of the successful runs are there, those of the refused ones are not.
    for f in [
        "sim.csv",
        "sim.json",
        "m4.postcard",
        "m4.json",
        "avg.postcard",
        "exp.postcard",
        "golden.txt",
        "cmp.json",
        "plots/acf.svg",
        "aug.postcard",
        "pieces/short_1.csv",
        "split.json",
    ] {
        assert!(d.join(f).exists(), "{f} missing");
    }
    for f in [
        "series2",
        "x.csv",
        "exp2.postcard",
        "aug2.postcard",
        "aug3.postcard",
        "t.postcard",
        "demo",
        "pieces2",
        "file/p",
    ] {
        assert!(!d.join(f).exists(), "{f} written by a refused run");
    }
}
