//! Bit-exactness of the firmware predictor: golden files == firmware lib on this machine ==
//! firmware binary on a Cortex-M4F in QEMU, compared with `to_bits()` over whole
//! trajectories, for the base model and one model per effect. Also: the firmware answers
//! garbage, split frames and bad blobs with error frames and keeps serving.

use yawcast_firmware::MAX_HORIZON;
use yawcast_shared::blob::{decode_blob, encode_blob, MAX_BLOB_LEN};
use yawcast_shared::model::ModelSpec;
use yawcast_shared::wire::{
    AckStatus, DeviceMessage, ErrorCode, FutureInputs, HostMessage, MAX_ENCODED_LEN,
};
use yawcast_tests::data::{self, decode_golden, encode_golden, golden_bytes, Trajectory};
use yawcast_tests::qemu::{self, Qemu};
use yawcast_tests::{reference_models, run_native, StepOut, HORIZON, STEPS};

fn blob_of(m: &ModelSpec) -> Vec<u8> {
    encode_blob(m, &mut [0u8; MAX_BLOB_LEN]).unwrap().to_vec()
}

/// Asserts two records are equal bit for bit, naming the first difference.
fn assert_bits_eq(what: &str, got: &[StepOut], want: &[StepOut]) {
    assert_eq!(got.len(), want.len(), "{what}: record length");
    for (t, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.status, w.status, "{what}: status at t={t}");
        for k in 0..HORIZON {
            assert_eq!(
                g.yhat[k].to_bits(),
                w.yhat[k].to_bits(),
                "{what}: ŷ(t+{}|t) at t={t}: got {:e}, golden {:e}",
                k + 1,
                g.yhat[k],
                w.yhat[k]
            );
        }
    }
}

/// A reference model with its name and golden record.
type Golden = (&'static str, ModelSpec, Vec<StepOut>);

fn goldens() -> (Trajectory, Vec<Golden>) {
    let traj = data::trajectory();
    let models = reference_models()
        .into_iter()
        .map(|(name, m)| {
            let native = run_native(&m, &traj);
            let golden = decode_golden(&golden_bytes(
                &format!("golden/{name}.bin"),
                &encode_golden(&native),
            ))
            .unwrap();
            (name, m, golden)
        })
        .collect();
    (traj, models)
}

#[test]
fn trajectory_is_deterministic_and_complete() {
    let traj = data::trajectory();
    assert_eq!(traj.u.len(), data::SAMPLES);
    assert_eq!(traj.ts, 0.5);
    let regen = data::generate_trajectory();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&traj.u), bits(&regen.u));
    assert_eq!(bits(&traj.y), bits(&regen.y));
    assert_eq!(
        traj.psi
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>(),
        regen
            .psi
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    );
    let missing = traj.y.iter().filter(|y| !y.is_finite()).count();
    assert_eq!(missing, 12, "11 NaN samples and one inf");
    let levels: std::collections::BTreeSet<u32> = traj.u.iter().map(|u| u.to_bits()).collect();
    assert_eq!(levels.len(), 6, "three amplitudes, both signs");
}

#[test]
fn reference_blobs_match_their_golden_bytes() {
    for (name, m) in reference_models() {
        let blob = blob_of(&m);
        let golden = golden_bytes(&format!("models/{name}.postcard"), &blob);
        assert_eq!(blob, golden, "blob of model {name}");
        assert_eq!(decode_blob(&golden), Ok(m));
    }
}

#[test]
fn native_predictions_equal_goldens_bit_for_bit() {
    let (traj, models) = goldens();
    let base = models[0].2.clone();
    for (name, m, golden) in &models {
        let native = run_native(m, &traj);
        assert_bits_eq(&format!("native, model {name}"), &native, golden);
        // every model sees corrected and skipped updates, and no reset
        let skipped = native.iter().filter(|s| s.status == 1).count();
        assert_eq!(skipped, 12, "model {name}");
        assert!(native.iter().all(|s| s.status != 2), "model {name}");
        // predictions move with the data and stay in a plausible range
        let spread = native
            .iter()
            .map(|s| s.yhat[9])
            .fold(0.0f32, |a, v| a.max(v.abs()));
        assert!(
            spread > 1.0 && spread < 100.0,
            "model {name}: |ŷ| max {spread}"
        );
        // each effect changes the predictions somewhere
        if *name != "base" {
            let differs = native
                .iter()
                .zip(&base)
                .filter(|(a, b)| a.yhat[HORIZON - 1] != b.yhat[HORIZON - 1])
                .count();
            assert!(
                differs > STEPS / 10,
                "model {name} differs from base at {differs} steps"
            );
        }
    }
}

fn boot() -> (Qemu, DeviceMessage) {
    let elf = qemu::firmware_elf().unwrap_or_else(|e| panic!("{e}"));
    Qemu::boot(&elf).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn qemu_predictions_equal_native_and_goldens_bit_for_bit() {
    let (traj, models) = goldens();
    let (mut q, banner) = boot();
    assert_eq!(
        banner,
        DeviceMessage::Banner {
            protocol: yawcast_shared::wire::PROTOCOL_VERSION,
            blob_version: yawcast_shared::blob::FORMAT_VERSION,
            order: 4,
            model_loaded: false
        }
    );
    const BATCH: usize = 25;
    for (name, m, golden) in &models {
        let blob = blob_of(m);
        q.send(&HostMessage::LoadModel(&blob));
        match q.recv().unwrap() {
            DeviceMessage::ModelLoaded { order, effects, .. } => {
                assert_eq!(
                    (order, effects as usize),
                    (4, m.effects.len()),
                    "model {name}"
                );
            }
            other => panic!("model {name}: load answered {other:?}"),
        }
        let mut device = Vec::with_capacity(STEPS);
        for start in (0..STEPS).step_by(BATCH) {
            let end = (start + BATCH).min(STEPS);
            for t in start..end {
                q.send(&HostMessage::Measurement {
                    u: traj.u[t],
                    y: traj.y[t],
                    psi: traj.psi[t],
                });
                q.send(&HostMessage::PredictRequest {
                    horizon: HORIZON as u8,
                    future_u: FutureInputs::from_slice(traj.future_u(t)).unwrap(),
                });
            }
            for t in start..end {
                let status = match q.recv().unwrap() {
                    DeviceMessage::Ack { sample, status } => {
                        assert_eq!(sample as usize, t + 1, "model {name}");
                        match status {
                            AckStatus::Corrected => 0,
                            AckStatus::SkippedCorrection => 1,
                            _ => 2,
                        }
                    }
                    other => panic!("model {name}, t={t}: measurement answered {other:?}"),
                };
                let yhat = match q.recv().unwrap() {
                    DeviceMessage::Prediction { sample, values } => {
                        assert_eq!(sample as usize, t + 1);
                        <[f32; HORIZON]>::try_from(values.as_slice()).unwrap()
                    }
                    other => panic!("model {name}, t={t}: predict answered {other:?}"),
                };
                device.push(StepOut { status, yhat });
            }
        }
        let native = run_native(m, &traj);
        assert_bits_eq(&format!("QEMU vs native, model {name}"), &device, &native);
        assert_bits_eq(&format!("QEMU vs golden, model {name}"), &device, golden);
    }
    assert_eq!(q.shutdown(0).unwrap(), 0);
}

#[test]
fn qemu_answers_bad_input_with_errors_and_keeps_serving() {
    let (mut q, _) = boot();
    let expect = |q: &mut Qemu, what: &str, want: DeviceMessage| {
        let got = q.recv().unwrap();
        assert_eq!(got, want, "{what}");
    };
    let err = |code| DeviceMessage::Error { code };
    let meas = HostMessage::Measurement {
        u: 1.0,
        y: 0.5,
        psi: None,
    };
    // no model yet
    q.send(&meas);
    expect(
        &mut q,
        "measurement before a model",
        err(ErrorCode::NoModel),
    );
    q.send(&HostMessage::PredictRequest {
        horizon: 1,
        future_u: FutureInputs::new(),
    });
    expect(&mut q, "prediction before a model", err(ErrorCode::NoModel));
    // garbage: not COBS, COBS but not a message, an overlong frame
    q.send_raw(&[0x13, 0x37, 0xff, 0x00]);
    expect(&mut q, "garbage", err(ErrorCode::BadCobs));
    q.send_raw(&[0x03, 0x63, 0x63, 0x00]);
    expect(&mut q, "unknown message", err(ErrorCode::BadMessage));
    q.send_raw(&vec![0x5a; MAX_ENCODED_LEN + 20]);
    q.send_raw(&[0x00]);
    expect(&mut q, "overlong frame", err(ErrorCode::FrameTooLong));
    // a frame split across writes, with pauses
    for b in [0x01u8, 0x01, 0x00] {
        q.send_raw(&[b]);
        q.flush().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(30));
    }
    expect(&mut q, "split ping", DeviceMessage::Pong);
    // bad blobs, one error code each
    let base = &reference_models()[0].1;
    let good = blob_of(base);
    let mut cases: Vec<(&str, Vec<u8>, ErrorCode)> = Vec::new();
    cases.push((
        "truncated",
        good[..good.len() - 1].to_vec(),
        ErrorCode::BlobTruncated,
    ));
    let mut long = good.clone();
    long.push(0);
    cases.push(("trailing byte", long, ErrorCode::BlobOversized));
    let mut b = good.clone();
    b[0] = b'X';
    cases.push(("bad magic", b, ErrorCode::BlobBadMagic));
    let mut b = good.clone();
    b[4] = 9;
    cases.push(("bad version", b, ErrorCode::BlobBadVersion));
    let mut b = good.clone();
    b[20] ^= 0x40;
    cases.push(("bad CRC", b, ErrorCode::BlobBadCrc));
    let mut unstable = base.clone();
    unstable.a[3] = 3.0;
    cases.push(("unstable", raw_blob(&unstable), ErrorCode::ModelUnstable));
    let mut nan = base.clone();
    nan.b[1] = f32::NAN;
    cases.push(("non-finite", raw_blob(&nan), ErrorCode::ModelInvalid));
    let order2 = ModelSpec::new(
        2,
        0.5,
        &[-0.7, -1.5],
        &[0.1, -0.05],
        &[0.3, -0.2],
        Default::default(),
        &[],
    )
    .unwrap();
    cases.push(("order 2", blob_of(&order2), ErrorCode::UnsupportedOrder));
    for (what, bytes, code) in &cases {
        q.send(&HostMessage::LoadModel(bytes));
        expect(&mut q, what, err(*code));
    }
    // still serving: a good model, a measurement, predictions and their errors
    q.send(&HostMessage::LoadModel(&good));
    assert!(matches!(
        q.recv().unwrap(),
        DeviceMessage::ModelLoaded { order: 4, .. }
    ));
    q.send(&meas);
    expect(
        &mut q,
        "measurement",
        DeviceMessage::Ack {
            sample: 1,
            status: AckStatus::Corrected,
        },
    );
    q.send(&HostMessage::Measurement {
        u: 1.0,
        y: f32::NAN,
        psi: Some(10.0),
    });
    expect(
        &mut q,
        "missing measurement",
        DeviceMessage::Ack {
            sample: 2,
            status: AckStatus::SkippedCorrection,
        },
    );
    for (h, n, code) in [
        (0u8, 0usize, ErrorCode::HorizonOutOfRange),
        (MAX_HORIZON as u8 + 1, 63, ErrorCode::HorizonOutOfRange),
        (5, 3, ErrorCode::NotEnoughInputs),
    ] {
        q.send(&HostMessage::PredictRequest {
            horizon: h,
            future_u: FutureInputs::from_slice(&vec![1.0; n]).unwrap(),
        });
        expect(&mut q, "bad prediction request", err(code));
    }
    q.send(&HostMessage::PredictRequest {
        horizon: 3,
        future_u: FutureInputs::from_slice(&[1.0, f32::INFINITY]).unwrap(),
    });
    expect(&mut q, "non-finite future input", err(ErrorCode::NonFinite));
    // the device's prediction equals the native one after the same two updates
    let mut p = yawcast_firmware::Predictor::<4>::new(base).unwrap();
    p.update(1.0, 0.5);
    p.update_with_heading(1.0, f32::NAN, Some(10.0));
    let mut want = [0.0f32; 4];
    p.predict_into(&mut want, &[2.0, -2.0, 0.0]).unwrap();
    q.send(&HostMessage::PredictRequest {
        horizon: 4,
        future_u: FutureInputs::from_slice(&[2.0, -2.0, 0.0]).unwrap(),
    });
    match q.recv().unwrap() {
        DeviceMessage::Prediction { sample, values } => {
            assert_eq!(sample, 2);
            assert_eq!(
                values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                want.map(f32::to_bits).to_vec()
            );
        }
        other => panic!("prediction answered {other:?}"),
    }
    q.send(&HostMessage::Reset);
    expect(
        &mut q,
        "reset",
        DeviceMessage::Ack {
            sample: 0,
            status: AckStatus::Cleared,
        },
    );
    q.send(&HostMessage::Ping);
    expect(&mut q, "ping after all that", DeviceMessage::Pong);
    assert_eq!(q.shutdown(3).unwrap(), 3);
}

/// A blob with a correct CRC around any model, valid or not (bypasses `encode_blob`'s checks).
fn raw_blob(m: &ModelSpec) -> Vec<u8> {
    let mut payload = [0u8; 256];
    let p = postcard_bytes(m, &mut payload);
    let mut out = Vec::new();
    out.extend_from_slice(b"YAWC");
    out.extend_from_slice(&yawcast_shared::blob::MODEL_ONLY_VERSION.to_le_bytes());
    out.extend_from_slice(&(p.len() as u16).to_le_bytes());
    out.extend_from_slice(p);
    out.extend_from_slice(&yawcast_shared::crc::crc32(p).to_le_bytes());
    out
}

fn postcard_bytes<'a>(m: &ModelSpec, buf: &'a mut [u8]) -> &'a [u8] {
    postcard::to_slice(m, buf).unwrap()
}
