//! yawcast-bench: instruction-count benchmark kernels for `bench/firmware/run.sh`.
//!
//! The same kernels run on the Cortex-M4F (in QEMU, counted from a single-step execution
//! trace) and on x86_64 (counted by callgrind). Each kernel calls the predictor through a
//! non-inlined function, as an application would, with inputs hidden from the optimiser.
//! Counting N and 2N calls and taking the difference removes start-up and measurement
//! overhead; an identical loop around an empty call gives the harness cost to subtract.
//!
//! The `cycle` kernel is what a track controller runs per sample: the yaw-rate update, the
//! heading/track update (measured heading and ground velocity), a 20-step yaw-rate prediction
//! and the 20-step heading and track prediction from it.
//!
//! On the M4 the phases are separated by calls to `bench_marker`; on the host the phase is
//! chosen on the command line: `yawcast-bench update|predict|empty|cycle N`.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

use core::hint::black_box;
use yawcast_firmware::track::{NavMeasurement, Tracker};
use yawcast_firmware::{Predictor, PredictorError, UpdateStatus};
use yawcast_shared::model::{ModelSpec, Units};
use yawcast_shared::nav::TrackSpec;

/// Prediction horizon benchmarked.
const H: usize = 20;

/// The base 4th-order model of the golden tests (`tests/src/lib.rs`).
fn base_model() -> Option<ModelSpec> {
    ModelSpec::new(
        4,
        0.5,
        &[-0.007_95, -0.2065, -1.035, -1.75],
        &[0.02, 0.015, -0.005, 0.002],
        &[0.55, -0.1, 0.02, -0.01],
        Units::default(),
        &[],
    )
    .ok()
}

#[inline(never)]
fn one_update(p: &mut Predictor<4>, u: f32, y: f32) -> UpdateStatus {
    p.update(u, y)
}

#[inline(never)]
fn one_predict(
    p: &Predictor<4>,
    out: &mut [f32; H],
    fu: &[f32; H - 1],
) -> Result<(), PredictorError> {
    p.predict_into(out, fu)
}

#[inline(never)]
fn empty_call(p: &mut Predictor<4>, u: f32, y: f32) -> UpdateStatus {
    black_box((p, u, y));
    UpdateStatus::Corrected
}

/// `n` updates with alternating measurements.
#[inline(never)]
fn run_updates(p: &mut Predictor<4>, n: u32) {
    for i in 0..n {
        let y = if i & 1 == 0 { 0.5 } else { -0.25 };
        black_box(one_update(p, black_box(2.0), black_box(y)));
    }
}

/// The harness of `run_updates` around an empty call.
#[inline(never)]
fn run_empty(p: &mut Predictor<4>, n: u32) {
    for i in 0..n {
        let y = if i & 1 == 0 { 0.5 } else { -0.25 };
        black_box(empty_call(p, black_box(2.0), black_box(y)));
    }
}

/// `n` 20-step predictions.
#[inline(never)]
fn run_predicts(p: &Predictor<4>, out: &mut [f32; H], fu: &[f32; H - 1], n: u32) {
    for _ in 0..n {
        let r = one_predict(black_box(p), out, black_box(fu));
        let _ = black_box(r);
        black_box(&out);
    }
}

/// One controller cycle: yaw-rate and track updates, then both 20-step predictions.
#[inline(never)]
fn one_cycle(
    p: &mut Predictor<4>,
    t: &mut Tracker,
    meas: (f32, f32, f32),
    nav: &NavMeasurement,
    out: &mut [f32; H],
    track: &mut [[f32; 3]; H],
    fu: &[f32; H - 1],
) -> Result<(), PredictorError> {
    let (u, y, psi) = meas;
    p.update(u, y);
    t.update(y, Some(psi), nav);
    p.predict_into(out, fu)?;
    t.predict_into(track, out)
}

/// `n` controller cycles with a slowly turning heading.
#[inline(never)]
fn run_cycles(
    p: &mut Predictor<4>,
    t: &mut Tracker,
    out: &mut [f32; H],
    track: &mut [[f32; 3]; H],
    fu: &[f32; H - 1],
    n: u32,
) {
    let nav = NavMeasurement {
        velocity: Some([1.1, 0.4]),
        fix: None,
    };
    for i in 0..n {
        let y = if i & 1 == 0 { 0.5 } else { -0.25 };
        let psi = (i & 63) as f32;
        let r = one_cycle(
            p,
            t,
            (black_box(2.0), black_box(y), black_box(psi)),
            black_box(&nav),
            out,
            track,
            black_box(fu),
        );
        let _ = black_box(r);
        black_box(&track);
    }
}

/// The heading/track predictor of the benchmark: current estimated, sway and speed loss.
fn tracker() -> Option<Tracker> {
    let mut spec = TrackSpec::new(0.5, 1.2, true).ok()?;
    spec.sway = -0.07;
    spec.speed_loss = 0.009;
    Tracker::new(&base_model()?, &spec).ok()
}

/// Builds a predictor warmed up with a few samples.
fn predictor() -> Option<Predictor<4>> {
    let mut p = Predictor::<4>::new(&base_model()?).ok()?;
    for i in 0..50 {
        let u = if (i / 7) % 2 == 0 { 5.0 } else { -5.0 };
        p.update(u, 0.1 * i as f32);
    }
    Some(p)
}

fn future_u() -> [f32; H - 1] {
    core::array::from_fn(|i| if i % 5 < 2 { 4.0 } else { -3.0 })
}

#[cfg(target_os = "none")]
mod m4 {
    use super::*;
    use cortex_m as _;
    use cortex_m_rt::entry;
    use defmt_semihosting as _;

    /// Calls per phase; the script counts N and 2N.
    const N: u32 = 200;

    /// Phase boundary, found in the trace by its address.
    #[inline(never)]
    fn bench_marker(id: u32) {
        black_box(id);
    }

    #[entry]
    fn main() -> ! {
        let Some(mut p) = predictor() else {
            semihosting::process::exit(2)
        };
        let fu = future_u();
        let mut out = [0.0f32; H];
        // built before the first marker: model validation is not part of any phase
        let Some(mut t) = tracker() else {
            semihosting::process::exit(2)
        };
        let mut track = [[0.0f32; 3]; H];
        bench_marker(0);
        run_updates(&mut p, N);
        bench_marker(1);
        run_updates(&mut p, 2 * N);
        bench_marker(2);
        run_predicts(&p, &mut out, &fu, N);
        bench_marker(3);
        run_predicts(&p, &mut out, &fu, 2 * N);
        bench_marker(4);
        run_empty(&mut p, N);
        bench_marker(5);
        run_empty(&mut p, 2 * N);
        bench_marker(6);
        run_cycles(&mut p, &mut t, &mut out, &mut track, &fu, N);
        bench_marker(7);
        run_cycles(&mut p, &mut t, &mut out, &mut track, &fu, 2 * N);
        bench_marker(8);
        defmt::info!("bench done, last prediction {=f32}", out[H - 1]);
        semihosting::process::exit(0)
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        semihosting::process::exit(101)
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: yawcast-bench update|predict|empty|cycle N";
    let (Some(mode), Some(n)) = (args.get(1), args.get(2).and_then(|n| n.parse::<u32>().ok()))
    else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let mut p = predictor().expect("benchmark model");
    let fu = future_u();
    let mut out = [0.0f32; H];
    let mut t = tracker().expect("benchmark track part");
    let mut track = [[0.0f32; 3]; H];
    match mode.as_str() {
        "cycle" => run_cycles(&mut p, &mut t, &mut out, &mut track, &fu, n),
        "update" => run_updates(&mut p, n),
        "predict" => run_predicts(&p, &mut out, &fu, n),
        "empty" => run_empty(&mut p, n),
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    }
    println!("{mode} x{n}: last prediction {:e}", out[H - 1]);
}
