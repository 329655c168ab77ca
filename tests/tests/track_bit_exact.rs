//! Bit-exactness of the heading/track predictor: golden file == firmware lib on this machine
//! == firmware binary on a Cortex-M4F in QEMU, compared with `to_bits()` over the whole
//! trajectory (heading and position at t+1 … t+20 at each of 1 000 steps, with missing,
//! non-finite and jumping navigation inputs). Also: the version 3 blob's golden bytes, every
//! version 2 golden blob still decoding, and the device's errors for track requests.

use yawcast_firmware::track::NavMeasurement;
use yawcast_shared::blob::{
    decode_blob_with_track, encode_blob_with_track, MAX_BLOB_LEN, MODEL_ONLY_VERSION,
};
use yawcast_shared::wire::{
    AckStatus, DeviceMessage, ErrorCode, FutureInputs, HostMessage, NavStatus, MAX_TRACK_HORIZON,
};
use yawcast_tests::data::{self, golden_bytes};
use yawcast_tests::qemu::{self, Qemu};
use yawcast_tests::track::{
    decode_track_golden, encode_track_golden, nav_inputs, run_track_native, track_model,
    TrackStepOut, TRACK_HORIZON,
};
use yawcast_tests::{reference_models, STEPS};

fn assert_track_bits_eq(what: &str, got: &[TrackStepOut], want: &[TrackStepOut]) {
    assert_eq!(got.len(), want.len(), "{what}: record length");
    for (t, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.status, w.status, "{what}: status at t={t}");
        for k in 0..TRACK_HORIZON {
            for j in 0..3 {
                assert_eq!(
                    g.rows[k][j].to_bits(),
                    w.rows[k][j].to_bits(),
                    "{what}: row {k} column {j} at t={t}: got {:e}, golden {:e}",
                    g.rows[k][j],
                    w.rows[k][j]
                );
            }
        }
    }
}

fn golden() -> (data::Trajectory, Vec<NavMeasurement>, Vec<TrackStepOut>) {
    let traj = data::trajectory();
    let nav = nav_inputs(&traj);
    let (m, t) = track_model();
    let native = run_track_native(&m, &t, &traj, &nav);
    let golden = decode_track_golden(&golden_bytes(
        "golden/track.bin",
        &encode_track_golden(&native),
    ))
    .unwrap();
    (traj, nav, golden)
}

fn track_blob() -> Vec<u8> {
    let (m, t) = track_model();
    encode_blob_with_track(&m, Some(&t), &mut [0u8; MAX_BLOB_LEN])
        .unwrap()
        .to_vec()
}

#[test]
fn native_track_equals_golden_bit_for_bit() {
    let (traj, nav, golden) = golden();
    let (m, t) = track_model();
    let native = run_track_native(&m, &t, &traj, &nav);
    assert_track_bits_eq("native", &native, &golden);
    let count = |col: usize, code: u8| native.iter().filter(|s| s.status[col] == code).count();
    // velocity: one NaN rejected (t = 150), one 20 m/s jump gated (t = 400), every 97th absent
    assert_eq!((count(1, 2), count(1, 3), count(1, 0)), (1, 1, 11));
    // fixes: every 10th sample, the 5 km jump gated (t = 600), the NaN rejected (t = 700)
    assert_eq!((count(2, 1), count(2, 2), count(2, 3)), (98, 1, 1));
    assert_eq!(count(3, 1), 0, "no reset");
    // the current is found: the state after the run, and positions that move
    let last = &native[STEPS - 1].rows;
    let step = ((last[1][1] - last[0][1]).powi(2) + (last[1][2] - last[0][2]).powi(2)).sqrt();
    assert!(step > 0.2 && step < 1.2, "one 0.5-s step moves {step} m");
    // the heading rows follow the yaw-rate prediction less the gyro offset
    assert!(native
        .iter()
        .all(|s| s.rows.iter().all(|r| r[0].is_finite())));
}

#[test]
fn track_blob_matches_its_golden_bytes_and_version_2_blobs_still_decode() {
    let blob = track_blob();
    let golden = golden_bytes("models/track.postcard", &blob);
    assert_eq!(blob, golden);
    assert_eq!(&golden[4..6], &[3, 0]);
    let (m, t) = track_model();
    assert_eq!(decode_blob_with_track(&golden), Ok((m, Some(t))));
    // every checked-in version 2 blob decodes as before, without a track part
    for (name, m) in reference_models() {
        let path = data::data_dir().join(format!("models/{name}.postcard"));
        let old = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(&old[4..6], &MODEL_ONLY_VERSION.to_le_bytes(), "{name}");
        assert_eq!(decode_blob_with_track(&old), Ok((m, None)), "{name}");
    }
}

fn boot() -> Qemu {
    let elf = qemu::firmware_elf().unwrap_or_else(|e| panic!("{e}"));
    Qemu::boot(&elf).unwrap_or_else(|e| panic!("{e}")).0
}

fn code(s: NavStatus) -> u8 {
    match s {
        NavStatus::Absent => 0,
        NavStatus::Applied => 1,
        NavStatus::Rejected => 2,
        NavStatus::Gated => 3,
    }
}

#[test]
fn qemu_track_equals_native_and_golden_bit_for_bit() {
    let (traj, nav, golden) = golden();
    let mut q = boot();
    q.send(&HostMessage::LoadModel(&track_blob()));
    assert!(matches!(
        q.recv().unwrap(),
        DeviceMessage::ModelLoaded {
            order: 4,
            effects: 1,
            ..
        }
    ));
    const BATCH: usize = 25;
    let mut device = Vec::with_capacity(STEPS);
    for start in (0..STEPS).step_by(BATCH) {
        let end = (start + BATCH).min(STEPS);
        for t in start..end {
            q.send(&HostMessage::TrackMeasurement {
                u: traj.u[t],
                y: traj.y[t],
                psi: traj.psi[t],
                velocity: nav[t].velocity,
                fix: nav[t].fix,
            });
            q.send(&HostMessage::TrackPredictRequest {
                horizon: TRACK_HORIZON as u8,
                future_u: FutureInputs::from_slice(traj.future_u(t)).unwrap(),
            });
        }
        for t in start..end {
            let status = match q.recv().unwrap() {
                DeviceMessage::TrackAck {
                    sample,
                    status,
                    velocity,
                    fix,
                    reset,
                } => {
                    assert_eq!(sample as usize, t + 1);
                    let s = match status {
                        AckStatus::Corrected => 0,
                        AckStatus::SkippedCorrection => 1,
                        _ => 2,
                    };
                    [s, code(velocity), code(fix), u8::from(reset)]
                }
                other => panic!("t={t}: track measurement answered {other:?}"),
            };
            let rows = match q.recv().unwrap() {
                DeviceMessage::TrackPrediction { sample, values } => {
                    assert_eq!(sample as usize, t + 1);
                    assert_eq!(values.len(), 3 * TRACK_HORIZON);
                    let mut rows = [[0.0f32; 3]; TRACK_HORIZON];
                    for (k, row) in rows.iter_mut().enumerate() {
                        row.copy_from_slice(&values[3 * k..3 * k + 3]);
                    }
                    rows
                }
                other => panic!("t={t}: track prediction answered {other:?}"),
            };
            device.push(TrackStepOut { status, rows });
        }
    }
    let (m, t) = track_model();
    let native = run_track_native(&m, &t, &traj, &nav);
    assert_track_bits_eq("QEMU vs native", &device, &native);
    assert_track_bits_eq("QEMU vs golden", &device, &golden);
    assert_eq!(q.shutdown(0).unwrap(), 0);
}

#[test]
fn qemu_answers_bad_track_requests_with_errors() {
    let mut q = boot();
    let track_meas = HostMessage::TrackMeasurement {
        u: 1.0,
        y: 0.5,
        psi: Some(10.0),
        velocity: Some([1.0, 0.0]),
        fix: None,
    };
    let err = |code| DeviceMessage::Error { code };
    q.send(&track_meas);
    assert_eq!(q.recv().unwrap(), err(ErrorCode::NoModel));
    // a model without a track part: track requests refused, the state untouched
    let base = &reference_models()[0].1;
    let v2 = yawcast_shared::blob::encode_blob(base, &mut [0u8; MAX_BLOB_LEN])
        .unwrap()
        .to_vec();
    q.send(&HostMessage::LoadModel(&v2));
    assert!(matches!(
        q.recv().unwrap(),
        DeviceMessage::ModelLoaded { .. }
    ));
    q.send(&track_meas);
    assert_eq!(q.recv().unwrap(), err(ErrorCode::NoTrack));
    q.send(&HostMessage::TrackPredictRequest {
        horizon: 2,
        future_u: FutureInputs::from_slice(&[0.0]).unwrap(),
    });
    assert_eq!(q.recv().unwrap(), err(ErrorCode::NoTrack));
    q.send(&HostMessage::Measurement {
        u: 1.0,
        y: 0.5,
        psi: None,
    });
    assert_eq!(
        q.recv().unwrap(),
        DeviceMessage::Ack {
            sample: 1,
            status: AckStatus::Corrected
        }
    );
    // a version 3 blob with a bad track part (correct CRC)
    let mut bad = track_blob();
    let n = bad.len();
    bad[n - 12..n - 8].copy_from_slice(&(-3.0f32).to_le_bytes()); // gate_velocity
    let crc = yawcast_shared::crc::crc32(&bad[8..n - 4]);
    bad[n - 4..].copy_from_slice(&crc.to_le_bytes());
    q.send(&HostMessage::LoadModel(&bad));
    assert_eq!(q.recv().unwrap(), err(ErrorCode::TrackInvalid));
    // the track model: a jump and a NaN are reported, horizons beyond 21 refused
    q.send(&HostMessage::LoadModel(&track_blob()));
    assert!(matches!(
        q.recv().unwrap(),
        DeviceMessage::ModelLoaded { .. }
    ));
    q.send(&HostMessage::TrackMeasurement {
        u: 0.0,
        y: 0.0,
        psi: Some(0.0),
        velocity: Some([f32::NAN, 0.0]),
        fix: Some([9000.0, 0.0]),
    });
    assert_eq!(
        q.recv().unwrap(),
        DeviceMessage::TrackAck {
            sample: 1,
            status: AckStatus::Corrected,
            velocity: NavStatus::Rejected,
            fix: NavStatus::Gated,
            reset: false
        }
    );
    for (h, n, code) in [
        (0u8, 0usize, ErrorCode::HorizonOutOfRange),
        (
            MAX_TRACK_HORIZON as u8 + 1,
            40,
            ErrorCode::HorizonOutOfRange,
        ),
        (5, 3, ErrorCode::NotEnoughInputs),
    ] {
        q.send(&HostMessage::TrackPredictRequest {
            horizon: h,
            future_u: FutureInputs::from_slice(&vec![1.0; n]).unwrap(),
        });
        assert_eq!(q.recv().unwrap(), err(code), "horizon {h}");
    }
    q.send(&HostMessage::Ping);
    assert_eq!(q.recv().unwrap(), DeviceMessage::Pong);
    assert_eq!(q.shutdown(0).unwrap(), 0);
}
