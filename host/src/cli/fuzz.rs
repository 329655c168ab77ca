//! In-process fuzzing of every reader and of `compare`'s path: measurement CSV files, model
//! blobs and JSON models, mutated by a seeded ChaCha8 mutator (bit flips, byte inserts and
//! deletes, truncation, numeric edge values, huge and empty fields, stray separators), must
//! give an error or a finite result — never a panic, never a non-finite figure reported as
//! a success. The work per case is bounded (inputs of at most 64 KiB, records of at most a
//! few thousand rows), so a hang would show as a test that does not end.
//!
//! Run: `cargo test --profile ci -p yawcast --bin yawcast fuzz -- --nocapture`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use yawcast::identify::model::Model;
use yawcast::identify::predict::{self, Horizon};
use yawcast::io::data::{self, Record};
use yawcast_shared::blob::{encode_blob, HEADER_LEN, MAX_BLOB_LEN, TRAILER_LEN};

use super::common::{check_record_for_model, model_from_bytes, ReadArgs, MIN_REPORTED_FIT};
use super::compare::fits;

/// Largest mutated input (bytes).
const MAX_INPUT: usize = 64 * 1024;

/// Text put in place of a field: numeric edge values, huge and empty fields, separators.
const EDGE: &[&str] = &[
    "1e308",
    "-1e308",
    "1.8e308",
    "-0",
    "0",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "3.4e200",
    "-3.4e38",
    "1e-320",
    "4.9e-324",
    "",
    " ",
    "0x1F",
    "1,5",
    "1;5",
    "\"",
    "\"1\"",
    "1e",
    "--1",
    "+",
    ".",
    "18446744073709551616",
    "null",
    "true",
    "[]",
    "{}",
    "\u{feff}1",
    "１",
];

/// Separators and structure put at random places.
const SEPARATORS: &[&[u8]] = &[
    b",", b";", b"\n", b"\r\n", b"\r", b"\t", b"\"", b"{", b"}", b"[", b"]", b":", b"\0",
];

/// What one case gave.
#[derive(Debug, Default, Clone, Copy)]
struct Counts {
    cases: usize,
    errors: usize,
    successes: usize,
    panics: usize,
    non_finite: usize,
}

impl Counts {
    fn add(&mut self, o: &Counts) {
        self.cases += o.cases;
        self.errors += o.errors;
        self.successes += o.successes;
        self.panics += o.panics;
        self.non_finite += o.non_finite;
    }
}

/// Bounds of the field around byte `i`: the run of bytes that are not separators.
fn field_at(bytes: &[u8], i: usize) -> (usize, usize) {
    let sep = |b: u8| b",;\n\r\t:[]{} \"".contains(&b);
    let mut a = i.min(bytes.len());
    while a > 0 && !sep(bytes[a - 1]) {
        a -= 1;
    }
    let mut b = i.min(bytes.len());
    while b < bytes.len() && !sep(bytes[b]) {
        b += 1;
    }
    (a, b)
}

/// One to three mutations of `input`, at most [`MAX_INPUT`] bytes.
fn mutate(rng: &mut ChaCha8Rng, input: &[u8]) -> Vec<u8> {
    let mut v = input.to_vec();
    for _ in 0..rng.random_range(1..=3) {
        let at = |rng: &mut ChaCha8Rng, v: &Vec<u8>| rng.random_range(0..=v.len());
        match rng.random_range(0..10) {
            0 => {
                if !v.is_empty() {
                    let i = rng.random_range(0..v.len());
                    v[i] ^= 1 << rng.random_range(0..8);
                }
            }
            1 => {
                let i = at(rng, &v);
                v.insert(i, rng.random());
            }
            2 => {
                if !v.is_empty() {
                    let i = rng.random_range(0..v.len());
                    let n = rng.random_range(1..=8).min(v.len() - i);
                    v.drain(i..i + n);
                }
            }
            3 => {
                let i = at(rng, &v);
                v.truncate(i);
            }
            4 | 5 => {
                // a field replaced by an edge value
                let i = at(rng, &v);
                let (a, b) = field_at(&v, i);
                let e = EDGE[rng.random_range(0..EDGE.len())].as_bytes();
                v.splice(a..b, e.iter().copied());
            }
            6 => {
                let i = at(rng, &v);
                let s = SEPARATORS[rng.random_range(0..SEPARATORS.len())];
                v.splice(i..i, s.iter().copied());
            }
            7 => {
                // a huge field: thousands of digits
                let i = at(rng, &v);
                let (a, b) = field_at(&v, i);
                let n = rng.random_range(300..5000);
                let mut f = vec![b'9'; n];
                if rng.random_bool(0.5) {
                    f.insert(1, b'.');
                }
                v.splice(a..b, f);
            }
            8 => {
                // a line (or a slice) repeated
                if !v.is_empty() {
                    let i = rng.random_range(0..v.len());
                    let n = rng.random_range(1..=200).min(v.len() - i);
                    let chunk: Vec<u8> = v[i..i + n].to_vec();
                    let j = at(rng, &v);
                    v.splice(j..j, chunk);
                }
            }
            _ => {
                // an empty field
                let i = at(rng, &v);
                let (a, b) = field_at(&v, i);
                v.drain(a..b);
            }
        }
        v.truncate(MAX_INPUT);
    }
    v
}

/// A blob mutated inside its payload and sealed again (length and CRC made right), so the
/// mutation reaches the decoder and the model checks rather than the CRC; f32 edge values
/// written over payload bytes.
fn mutate_sealed(rng: &mut ChaCha8Rng, blob: &[u8]) -> Vec<u8> {
    let mut payload = blob[HEADER_LEN..blob.len() - TRAILER_LEN].to_vec();
    for _ in 0..rng.random_range(1..=3) {
        match rng.random_range(0..4) {
            0 if !payload.is_empty() => {
                let i = rng.random_range(0..payload.len());
                payload[i] ^= 1 << rng.random_range(0..8);
            }
            1 if payload.len() >= 4 => {
                let edge = [
                    f32::NAN,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                    -0.0,
                    f32::MAX,
                    f32::MIN_POSITIVE,
                    1e-45,
                    3.4e38,
                    1e6,
                    1.000_001,
                ];
                let i = rng.random_range(0..=payload.len() - 4);
                let x: f32 = edge[rng.random_range(0..edge.len())];
                payload[i..i + 4].copy_from_slice(&x.to_le_bytes());
            }
            2 => {
                let i = rng.random_range(0..=payload.len());
                payload.insert(i, rng.random());
            }
            _ if !payload.is_empty() => {
                let i = rng.random_range(0..payload.len());
                payload.remove(i);
            }
            _ => {}
        }
    }
    payload.truncate(MAX_BLOB_LEN);
    let mut out = blob[..HEADER_LEN].to_vec();
    out[6..8].copy_from_slice(&(payload.len() as u16).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&yawcast_shared::crc::crc32(&payload).to_le_bytes());
    out
}

/// `compare`'s path on a model and a record: the record checked against the model, then
/// the fits at 1, 5 and 20 steps and in simulation. A success must report finite figures
/// above [`MIN_REPORTED_FIT`].
fn compare_case(model: &Model, rec: &Record, path: &Path) -> Counts {
    let res = catch_unwind(AssertUnwindSafe(|| {
        check_record_for_model(rec, model, path)?;
        let horizons = [
            Horizon::Steps(1),
            Horizon::Steps(5),
            Horizon::Steps(20),
            Horizon::Sim,
        ];
        fits(model, rec, &horizons, path).map(|(f, _)| f)
    }));
    match res {
        Err(_) => Counts {
            cases: 1,
            panics: 1,
            ..Counts::default()
        },
        Ok(Err(_)) => Counts {
            cases: 1,
            errors: 1,
            ..Counts::default()
        },
        Ok(Ok(f)) => {
            let finite =
                f.values().all(|v| v.is_finite() && *v >= MIN_REPORTED_FIT) && f.len() == 4;
            Counts {
                cases: 1,
                successes: 1,
                non_finite: usize::from(!finite),
                ..Counts::default()
            }
        }
    }
}

/// Reads `bytes` with `read`, then (when it reads) runs `compare`'s path on what it gave.
fn case<T>(read: impl FnOnce() -> anyhow::Result<T>, then: impl FnOnce(&T) -> Counts) -> Counts {
    match catch_unwind(AssertUnwindSafe(read)) {
        Err(_) => Counts {
            cases: 1,
            panics: 1,
            ..Counts::default()
        },
        Ok(Err(_)) => Counts {
            cases: 1,
            errors: 1,
            ..Counts::default()
        },
        Ok(Ok(v)) => then(&v),
    }
}

/// The seed model and record: a stable 2nd-order model and 160 samples it produces (with
/// noise) from a switching input.
fn seeds() -> (Model, Record) {
    let model =
        Model::new(0.5, vec![-0.2, 0.7], vec![0.01, 0.02], vec![0.5, 0.2]).expect("a valid model");
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let u: Vec<f64> = (0..160)
        .map(|i| if (i / 9) % 2 == 0 { 10.0 } else { -10.0 })
        .collect();
    let mut rec = Record::from_uy("seed", 0.5, u, vec![0.0; 160]);
    let y = predict::simulate(&model, &rec, &[0.0, 0.0]);
    rec.y = y
        .iter()
        .map(|v| v + 0.01 * (rng.random::<f64>() - 0.5))
        .collect();
    (model, rec)
}

#[test]
fn fuzz_readers_and_compare_never_panic_nor_report_non_finite_figures() {
    let (model, rec) = seeds();
    let csv = data::csv_text(&rec).into_bytes();
    let json = serde_json::to_vec(&model).unwrap();
    let mut buf = [0u8; MAX_BLOB_LEN];
    let blob = encode_blob(&model.to_spec().unwrap(), &mut buf)
        .unwrap()
        .to_vec();
    let read = ReadArgs::default();
    // The seeds themselves read and compare without error.
    let p_csv = Path::new("fuzz.csv");
    let p_json = Path::new("/nonexistent-yawcast-fuzz/model.json");
    let p_blob = Path::new("/nonexistent-yawcast-fuzz/model.postcard");
    let r0 = read.parse(&csv, p_csv).unwrap();
    assert_eq!(r0.len(), 160);
    assert_eq!(compare_case(&model, &r0, p_csv).successes, 1);
    let m_json = model_from_bytes(&json, p_json).unwrap();
    let m_blob = model_from_bytes(&blob, p_blob).unwrap();
    assert_eq!(m_json.a, model.a);
    assert_eq!(m_blob.n, 2);

    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_f022);
    let (mut c_csv, mut c_blob, mut c_sealed, mut c_json) = Default::default();
    let report = |c: &mut Counts, o: Counts| c.add(&o);
    for _ in 0..40_000 {
        let bytes = mutate(&mut rng, &csv);
        let o = case(
            || read.parse(&bytes, p_csv),
            |r| compare_case(&model, r, p_csv),
        );
        report(&mut c_csv, o);
    }
    for _ in 0..15_000 {
        let bytes = mutate(&mut rng, &blob);
        let o = case(
            || model_from_bytes(&bytes, p_blob),
            |m| compare_case(m, &rec, p_blob),
        );
        report(&mut c_blob, o);
    }
    for _ in 0..20_000 {
        let bytes = mutate_sealed(&mut rng, &blob);
        let o = case(
            || model_from_bytes(&bytes, p_blob),
            |m| compare_case(m, &rec, p_blob),
        );
        report(&mut c_sealed, o);
    }
    for _ in 0..30_000 {
        let bytes = mutate(&mut rng, &json);
        let o = case(
            || model_from_bytes(&bytes, p_json),
            |m| compare_case(m, &rec, p_json),
        );
        report(&mut c_json, o);
    }
    // `split` cuts the same mutated tables: every piece it reports lies in the text, and
    // the pieces hold every row once
    let mut c_split = Counts::default();
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_5b17);
    for _ in 0..10_000 {
        let bytes = mutate(&mut rng, &csv);
        let text = data::decode_text(&bytes);
        let o = case(
            || data::split_at_gaps(&text, p_csv, "t_s", 1.0).map_err(anyhow::Error::from),
            |s| {
                assert!((0..s.pieces.len()).all(|i| s.piece_text(&text, i).is_some()));
                assert!(s
                    .pieces
                    .windows(2)
                    .all(|w| w[0].first_row + w[0].rows == w[1].first_row));
                Counts {
                    cases: 1,
                    successes: 1,
                    ..Counts::default()
                }
            },
        );
        report(&mut c_split, o);
    }
    let mut all = Counts::default();
    for (name, c) in [
        ("CSV records", &c_csv),
        ("CSV records cut by split", &c_split),
        ("blobs", &c_blob),
        ("blobs, payload mutated and sealed", &c_sealed),
        ("JSON models", &c_json),
    ] {
        println!(
            "fuzz {name:<34} cases {:>6}  errors {:>6}  successes {:>6}  panics {}  non-finite successes {}",
            c.cases, c.errors, c.successes, c.panics, c.non_finite
        );
        all.add(c);
    }
    println!(
        "fuzz {:<34} cases {:>6}  errors {:>6}  successes {:>6}  panics {}  non-finite successes {}",
        "all", all.cases, all.errors, all.successes, all.panics, all.non_finite
    );
    assert!(all.cases >= 110_000, "{all:?}");
    assert_eq!(all.panics, 0, "{all:?}");
    assert_eq!(all.non_finite, 0, "{all:?}");
    // Both outcomes are reached: the mutator is neither too weak nor too wild (a raw blob
    // mutation rarely survives the CRC; the sealed ones reach the model checks).
    for c in [&c_csv, &c_split, &c_sealed, &c_json] {
        assert!(c.errors > 100 && c.successes > 100, "{c:?}");
    }
    assert!(c_blob.errors > 10_000, "{c_blob:?}");
}
