//! yawcast-tests: cross-crate tests (golden vectors → firmware lib on x86_64 → firmware bin
//! on Cortex-M4F in QEMU, bit for bit).
//!
//! This library holds the pieces the test binary (`tests/bit_exact.rs`) uses: the reference
//! models, the recorded trajectory and golden outputs under `tests/data/`, and a driver that
//! boots the firmware in QEMU and talks to it over its UART.
//!
//! Golden files are compared, never rewritten, unless `YAWCAST_REGEN_GOLDEN=1` is set.

pub mod data;
pub mod qemu;
pub mod track;

use yawcast_firmware::{Predictor, UpdateStatus};
use yawcast_shared::model::{Effect, ModelSpec, Units};

/// Prediction horizon checked at every step (k = 1..=HORIZON).
pub const HORIZON: usize = 20;
/// Steps of the trajectory replayed (the recording has HORIZON more for future commands).
pub const STEPS: usize = 1000;

/// The base 4th-order model: poles 0.95, 0.7, 0.3 ± 0.2i, sample time 0.5 s, in the
/// difference form of the blob (`δ⁴ + 1.75 δ³ + 1.035 δ² + 0.2065 δ + 0.00795`, the
/// shift-form companion row (−0.086 45, 0.6135, −1.785, 2.25)); `b` and `k` chosen so that
/// every entry is non-zero.
pub fn base_model() -> ModelSpec {
    with_effects(&[])
}

/// The base model with `effects`.
///
/// # Panics
/// When the model does not validate (the parameters here are fixed and valid).
pub fn with_effects(effects: &[Effect]) -> ModelSpec {
    ModelSpec::new(
        4,
        0.5,
        &[-0.007_95, -0.2065, -1.035, -1.75],
        &[0.02, 0.015, -0.005, 0.002],
        &[0.55, -0.1, 0.02, -0.01],
        Units::default(),
        effects,
    )
    .expect("reference model validates")
}

/// The twelve reference models: the base model, the base model with each effect, and the
/// base model with every effect of format 2's first release stacked (as `yawcast augment
/// --more` builds them); the dead band came later and has its own record, so the older
/// golden files stay as they were written.
pub fn reference_models() -> Vec<(&'static str, ModelSpec)> {
    vec![
        ("base", base_model()),
        ("bias", with_effects(&[Effect::Bias { beta: 0.35 }])),
        ("gyro-bias", with_effects(&[Effect::GyroBias { d_y: 0.12 }])),
        (
            "dead-time",
            with_effects(&[Effect::DeadTime { samples: 2 }]),
        ),
        (
            "rate-limit",
            with_effects(&[Effect::RateLimit { rate: 5.0 }]),
        ),
        (
            "saturation",
            with_effects(&[Effect::Saturation { limit: 7.0 }]),
        ),
        (
            "asymmetry",
            with_effects(&[Effect::Asymmetry { beta: 0.2 }]),
        ),
        (
            "nonlinear-damping",
            with_effects(&[Effect::NonlinearDamping {
                beta: -0.04,
                cubic: false,
            }]),
        ),
        (
            "wind",
            with_effects(&[Effect::Wind {
                beta_s2: 0.6,
                beta_c2: -0.4,
                beta_s1: 0.3,
                beta_c1: 0.5,
            }]),
        ),
        (
            "current",
            with_effects(&[Effect::Current {
                beta_s: 0.5,
                beta_c: -0.3,
            }]),
        ),
        (
            "dead-band",
            with_effects(&[
                Effect::DeadBand { width: 1.5 },
                Effect::RateLimit { rate: 5.0 },
            ]),
        ),
        (
            "stack",
            with_effects(&[
                Effect::Asymmetry { beta: 0.2 },
                Effect::NonlinearDamping {
                    beta: -0.04,
                    cubic: false,
                },
                Effect::RateLimit { rate: 5.0 },
                Effect::DeadTime { samples: 2 },
                Effect::Saturation { limit: 7.0 },
                Effect::Bias { beta: 0.35 },
                Effect::GyroBias { d_y: 0.12 },
                Effect::Wind {
                    beta_s2: 0.6,
                    beta_c2: -0.4,
                    beta_s1: 0.3,
                    beta_c1: 0.5,
                },
                Effect::Current {
                    beta_s: 0.5,
                    beta_c: -0.3,
                },
            ]),
        ),
    ]
}

/// One step of a golden record: the update status and ŷ(t+k|t) for k = 1..=HORIZON.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOut {
    /// 0 corrected, 1 correction skipped, 2 non-finite reset.
    pub status: u8,
    /// The predictions.
    pub yhat: [f32; HORIZON],
}

/// Status code of an update, as stored in the golden files.
pub fn status_code(s: UpdateStatus) -> u8 {
    match s {
        UpdateStatus::Corrected => 0,
        UpdateStatus::SkippedCorrection => 1,
        _ => 2,
    }
}

/// Runs the firmware library (this machine's build) over the trajectory.
///
/// # Panics
/// When the model is not of order 4 or a prediction fails.
pub fn run_native(model: &ModelSpec, traj: &data::Trajectory) -> Vec<StepOut> {
    let mut p = Predictor::<4>::new(model).expect("order-4 model");
    (0..STEPS)
        .map(|t| {
            let status = status_code(p.update_with_heading(traj.u[t], traj.y[t], traj.psi[t]));
            let mut yhat = [0.0f32; HORIZON];
            p.predict_into(&mut yhat, traj.future_u(t))
                .expect("prediction of a stable model");
            StepOut { status, yhat }
        })
        .collect()
}
