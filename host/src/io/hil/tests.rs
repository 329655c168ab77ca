//! Tests of the UART link and the native runs.

use super::*;
use yawcast_shared::model::Units;

fn spec() -> ModelSpec {
    ModelSpec::new(
        4,
        0.5,
        &[-0.007_95, -0.2065, -1.035, -1.75],
        &[0.02, 0.015, -0.005, 0.002],
        &[0.55, -0.1, 0.02, -0.01],
        Units::default(),
        &[],
    )
    .unwrap()
}

fn rec() -> F32Record {
    let u: Vec<f32> = (0..200)
        .map(|i| if (i / 17) % 2 == 0 { 10.0 } else { -10.0 })
        .collect();
    let y: Vec<f32> = (0..200).map(|i| (i as f32 * 0.05).sin()).collect();
    F32Record { u, y, psi: None }
}

#[test]
fn native_run_is_deterministic_and_sized() {
    let a = native_run(&spec(), &rec(), 20).unwrap();
    let b = native_run(&spec(), &rec(), 20).unwrap();
    assert_eq!(a.len(), 200);
    assert!(a.iter().all(|v| v.len() == 20));
    assert_eq!(compare_bits(&a, &b), (4000, 4000, None));
    let mut c = b.clone();
    c[7][3] = f32::from_bits(c[7][3].to_bits() ^ 1);
    assert_eq!(compare_bits(&a, &c), (4000, 3999, Some((7, 3))));
}

#[test]
fn future_inputs_repeat_the_last_command() {
    assert_eq!(future_inputs(&[1.0, 2.0, 3.0], 1, 4), vec![3.0, 3.0, 3.0]);
    assert_eq!(future_inputs(&[1.0, 2.0, 3.0], 0, 1), Vec::<f32>::new());
}

#[test]
fn missing_elf_names_where_it_looked() {
    // Whatever the environment: an ELF named by the variable but absent, and none built.
    let c = elf_candidates_with(
        Some(std::ffi::OsStr::new("/nonexistent-fw.elf")),
        Path::new("/nonexistent-ws"),
    );
    let e = first_elf(&c).unwrap_err().to_string();
    assert!(
        e.contains(
            "/nonexistent-fw.elf, /nonexistent-ws/target/thumbv7em-none-eabihf/release/yawcast-fw, \
             /nonexistent-ws/target/thumb/thumbv7em-none-eabihf/release/yawcast-fw"
        ) && e.contains("fw-build"),
        "{e}"
    );
    match std::env::var_os(ELF_VAR) {
        // Without the variable, the build directories are where it looks.
        None => {
            let e = find_elf(Path::new("/nonexistent-ws"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("/nonexistent-ws/target"), "{e}");
        }
        // With it (as in CI), the ELF it names must be there and be the one found.
        Some(v) => {
            assert!(
                Path::new(&v).is_file(),
                "{ELF_VAR}={} names no file: build the firmware first",
                Path::new(&v).display()
            );
            assert_eq!(
                find_elf(Path::new("/nonexistent-ws")).unwrap(),
                PathBuf::from(v)
            );
        }
    }
}

/// A UART that gives its bytes, then ends the way its kind says (`UnexpectedEof`: closed).
#[derive(Debug)]
struct Ends(Vec<u8>, std::io::ErrorKind);

impl Read for Ends {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.0.is_empty() {
            return match self.1 {
                std::io::ErrorKind::UnexpectedEof => Ok(0),
                k => Err(k.into()),
            };
        }
        let n = self.0.len().min(buf.len());
        buf[..n].copy_from_slice(&self.0[..n]);
        self.0.drain(..n);
        Ok(n)
    }
}

impl Write for Ends {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn a_link_closed_or_reset_before_a_byte_is_told_from_other_failures() {
    use std::io::ErrorKind::{ConnectionReset, TimedOut, UnexpectedEof};
    // (bytes first, how the link ends) → (dropped, heard)
    for (bytes, end, want) in [
        (vec![], ConnectionReset, (true, false)),
        (vec![], UnexpectedEof, (true, false)),
        (vec![], TimedOut, (false, false)),
        (vec![7, 7], ConnectionReset, (true, true)),
    ] {
        let mut d = Device::over(Box::new(Ends(bytes, end)));
        assert!(matches!(d.recv(), Err(HilError::Link(_))));
        assert_eq!((d.dropped, d.heard), want, "{end:?}");
    }
}
