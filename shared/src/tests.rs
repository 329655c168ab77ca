//! Golden byte vectors for the blob and every wire message, and a randomised robustness
//! test of the decoders (seeded, so every run sees the same inputs).

use std::vec::Vec as StdVec;

use crate::blob::{
    decode_blob, decode_blob_with_track, encode_blob, encode_blob_with_track, BlobError,
    MAX_BLOB_LEN,
};
use crate::crc::crc32;
use crate::model::{Effect, ModelSpec, Units};
use crate::nav::{TrackError, TrackField, TrackSpec};
use crate::wire::{
    AckStatus, DeviceMessage, ErrorCode, Feed, FrameAccumulator, HostMessage, NavStatus, WireError,
    MAX_FRAME_LEN,
};

/// The reference model: order 4 with a two-sample dead time, in difference form (the
/// shift-form companion row (−0.1, 0.2, −0.3, 0.6)).
fn reference_model() -> ModelSpec {
    ModelSpec::new(
        4,
        0.5,
        &[-0.6, -2.6, -4.5, -3.4],
        &[0.01, 0.01, 0.005, 0.002],
        &[0.1, 0.01, 0.0, 0.0],
        Units::default(),
        &[Effect::DeadTime { samples: 2 }],
    )
    .unwrap()
}

/// Its blob, byte for byte: header, postcard payload, CRC-32.
const REFERENCE_BLOB: [u8; 73] = [
    0x59, 0x41, 0x57, 0x43, // "YAWC"
    0x02, 0x00, // version 2
    0x3d, 0x00, // payload length 61
    0x04, // order
    0x00, 0x00, 0x00, 0x3f, // ts = 0.5
    0x04, 0x9a, 0x99, 0x19, 0xbf, 0x66, 0x66, 0x26, 0xc0, 0x00, 0x00, 0x90, 0xc0, 0x9a, 0x99, 0x59,
    0xc0, // a
    0x04, 0x0a, 0xd7, 0x23, 0x3c, 0x0a, 0xd7, 0x23, 0x3c, 0x0a, 0xd7, 0xa3, 0x3b, 0x6f, 0x12, 0x03,
    0x3b, // b
    0x04, 0xcd, 0xcc, 0xcc, 0x3d, 0x0a, 0xd7, 0x23, 0x3c, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, // k
    0x00, 0x00, // units: deg, deg/s
    0x01, 0x02, 0x02, // one effect: DeadTime { samples: 2 }
    0xbf, 0x60, 0x5e, 0xe0, // CRC-32
];

#[test]
fn reference_blob_bytes() {
    let mut buf = [0u8; MAX_BLOB_LEN];
    let blob = encode_blob(&reference_model(), &mut buf).unwrap();
    assert_eq!(blob, &REFERENCE_BLOB[..]);
    assert_eq!(crc32(&REFERENCE_BLOB[8..69]), 0xe05e_60bf);
    assert_eq!(decode_blob(&REFERENCE_BLOB), Ok(reference_model()));
}

/// The reference model's track part (values exact in binary).
fn reference_track() -> TrackSpec {
    let mut t = TrackSpec::new(0.5, 1.25, true).unwrap();
    t.sway = -0.0625;
    t.speed_loss = 0.007_812_5;
    t
}

/// The reference model with its track part: a version 3 blob, byte for byte.
const REFERENCE_TRACK_BLOB: [u8; 114] = [
    0x59, 0x41, 0x57, 0x43, // "YAWC"
    0x03, 0x00, // version 3
    0x66, 0x00, // payload length 102: the model's 61 bytes, then the track part's 41
    0x04, 0x00, 0x00, 0x00, 0x3f, 0x04, 0x9a, 0x99, 0x19, 0xbf, 0x66, 0x66, 0x26, 0xc0, 0x00, 0x00,
    0x90, 0xc0, 0x9a, 0x99, 0x59, 0xc0, 0x04, 0x0a, 0xd7, 0x23, 0x3c, 0x0a, 0xd7, 0x23, 0x3c, 0x0a,
    0xd7, 0xa3, 0x3b, 0x6f, 0x12, 0x03, 0x3b, 0x04, 0xcd, 0xcc, 0xcc, 0x3d, 0x0a, 0xd7, 0x23, 0x3c,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x02,
    0x02, // the model, as in REFERENCE_BLOB
    0x00, 0x00, 0xa0, 0x3f, // speed 1.25
    0x00, 0x00, 0x80, 0xbd, // sway −0.0625
    0x00, 0x00, 0x00, 0x3c, // speed loss 0.0078125
    0x01, // current estimated
    0xcd, 0xcc, 0x4c, 0x3d, // gain_speed 0.05
    0x6f, 0x12, 0x03, 0x3b, // gain_current 0.002
    0x00, 0x00, 0x00, 0x3f, // gain_position 0.5
    0x0a, 0xd7, 0xa3, 0x3c, // fix_speed 0.01/0.5
    0x6f, 0x12, 0x83, 0x3b, // fix_current 0.002/0.5
    0x00, 0x00, 0x40, 0x40, // gate_velocity 3
    0x00, 0x00, 0x48, 0x43, // gate_position 200
    0xd2, 0x3a, 0x71, 0xea, // CRC-32
];

#[test]
fn reference_track_blob_bytes() {
    let mut buf = [0u8; MAX_BLOB_LEN];
    let blob =
        encode_blob_with_track(&reference_model(), Some(&reference_track()), &mut buf).unwrap();
    assert_eq!(blob, &REFERENCE_TRACK_BLOB[..]);
    assert_eq!(
        decode_blob_with_track(&REFERENCE_TRACK_BLOB),
        Ok((reference_model(), Some(reference_track())))
    );
    // the model alone from a version 3 blob, and a version 2 blob without a track part
    assert_eq!(decode_blob(&REFERENCE_TRACK_BLOB), Ok(reference_model()));
    assert_eq!(
        decode_blob_with_track(&REFERENCE_BLOB),
        Ok((reference_model(), None))
    );
    // a bad track part is refused on encode, and on decode with a correct CRC
    let mut bad = reference_track();
    bad.gate_velocity = -1.0;
    assert_eq!(
        encode_blob_with_track(&reference_model(), Some(&bad), &mut buf),
        Err(BlobError::InvalidTrack(TrackError::OutOfRange(
            TrackField::GateVelocity
        )))
    );
    let mut b = REFERENCE_TRACK_BLOB;
    b[102..106].copy_from_slice(&(-1.0f32).to_le_bytes());
    let crc = crc32(&b[8..110]);
    b[110..114].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(
        decode_blob_with_track(&b),
        Err(BlobError::InvalidTrack(TrackError::OutOfRange(
            TrackField::GateVelocity
        )))
    );
    // a version 3 blob cut after the model: not a model with its track part
    let mut b = [0u8; 73];
    b.copy_from_slice(&REFERENCE_BLOB);
    b[4] = 3;
    assert_eq!(decode_blob(&b), Err(BlobError::BadPayload));
    // an unknown version names both readable ones
    b[4] = 4;
    assert_eq!(
        std::string::ToString::to_string(&decode_blob(&b).unwrap_err()),
        "model blob format version 4 is not supported (expected 2 or 3)"
    );
}

fn host_golden() -> StdVec<(HostMessage<'static>, &'static [u8])> {
    std::vec![
        (HostMessage::Ping, &[0x01, 0x01, 0x00][..]),
        (
            HostMessage::LoadModel(&[1, 0, 2, 3]),
            &[0x04, 0x01, 0x04, 0x01, 0x03, 0x02, 0x03, 0x00],
        ),
        (
            HostMessage::Measurement {
                u: 1.5,
                y: -0.25,
                psi: Some(90.0),
            },
            &[
                0x02, 0x02, 0x01, 0x03, 0xc0, 0x3f, 0x01, 0x04, 0x80, 0xbe, 0x01, 0x01, 0x03, 0xb4,
                0x42, 0x00,
            ],
        ),
        (
            HostMessage::Measurement {
                u: 0.0,
                y: f32::INFINITY,
                psi: None,
            },
            &[0x02, 0x02, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x7f, 0x01, 0x00,],
        ),
        (
            HostMessage::PredictRequest {
                horizon: 3,
                future_u: heapless::Vec::from_slice(&[1.0, -2.0]).unwrap(),
            },
            &[0x04, 0x03, 0x03, 0x02, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x02, 0xc0, 0x00,],
        ),
        (HostMessage::Reset, &[0x02, 0x04, 0x00]),
        (HostMessage::Shutdown { code: 7 }, &[0x03, 0x05, 0x07, 0x00]),
        (
            HostMessage::TrackMeasurement {
                u: 1.5,
                y: -0.25,
                psi: Some(90.0),
                velocity: Some([1.0, -0.5]),
                fix: None,
            },
            &[
                0x02, 0x06, 0x01, 0x03, 0xc0, 0x3f, 0x01, 0x04, 0x80, 0xbe, 0x01, 0x01, 0x04, 0xb4,
                0x42, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x02, 0xbf, 0x01, 0x00,
            ],
        ),
        (
            HostMessage::TrackMeasurement {
                u: 0.0,
                y: 0.0,
                psi: None,
                velocity: None,
                fix: Some([2.0, 4.0]),
            },
            &[
                0x02, 0x06, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x02, 0x01, 0x01,
                0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x40, 0x00,
            ],
        ),
        (
            HostMessage::TrackPredictRequest {
                horizon: 2,
                future_u: heapless::Vec::from_slice(&[1.0]).unwrap(),
            },
            &[0x04, 0x07, 0x02, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x00],
        ),
    ]
}

fn device_golden() -> StdVec<(DeviceMessage, &'static [u8])> {
    std::vec![
        (
            DeviceMessage::Banner {
                protocol: 1,
                blob_version: 1,
                order: 4,
                model_loaded: false,
            },
            &[0x01, 0x04, 0x01, 0x01, 0x04, 0x01, 0x00][..],
        ),
        (DeviceMessage::Pong, &[0x02, 0x01, 0x00]),
        (
            DeviceMessage::ModelLoaded {
                order: 4,
                effects: 1,
                crc: 0xDEAD_BEEF,
            },
            &[0x09, 0x02, 0x04, 0x01, 0xef, 0xfd, 0xb6, 0xf5, 0x0d, 0x00],
        ),
        (
            DeviceMessage::Ack {
                sample: 300,
                status: AckStatus::SkippedCorrection,
            },
            &[0x05, 0x03, 0xac, 0x02, 0x01, 0x00],
        ),
        (
            DeviceMessage::Prediction {
                sample: 1,
                values: heapless::Vec::from_slice(&[0.5, 1.0]).unwrap(),
            },
            &[0x04, 0x04, 0x01, 0x02, 0x01, 0x01, 0x02, 0x3f, 0x01, 0x03, 0x80, 0x3f, 0x00,],
        ),
        (
            DeviceMessage::Error {
                code: ErrorCode::BlobBadCrc,
            },
            &[0x03, 0x05, 0x08, 0x00],
        ),
        (
            DeviceMessage::TrackAck {
                sample: 2,
                status: AckStatus::Corrected,
                velocity: NavStatus::Applied,
                fix: NavStatus::Gated,
                reset: false,
            },
            &[0x03, 0x06, 0x02, 0x03, 0x01, 0x03, 0x01, 0x00],
        ),
        (
            DeviceMessage::TrackPrediction {
                sample: 1,
                values: heapless::Vec::from_slice(&[90.0, 1.0, -0.5]).unwrap(),
            },
            &[
                0x04, 0x07, 0x01, 0x03, 0x01, 0x03, 0xb4, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
                0x02, 0xbf, 0x00,
            ],
        ),
        (
            DeviceMessage::Error {
                code: ErrorCode::TrackInvalid,
            },
            &[0x03, 0x05, 0x10, 0x00],
        ),
        (
            DeviceMessage::Error {
                code: ErrorCode::NoTrack,
            },
            &[0x03, 0x05, 0x11, 0x00],
        ),
    ]
}

/// Feeds `bytes` and collects every frame and error.
fn collect(acc: &mut FrameAccumulator, bytes: &[u8]) -> StdVec<Result<StdVec<u8>, WireError>> {
    let mut out = StdVec::new();
    for &b in bytes {
        match acc.push(b) {
            Feed::Pending => {}
            Feed::Frame(f) => out.push(Ok(f.to_vec())),
            Feed::Error(e) => out.push(Err(e)),
        }
    }
    out
}

#[test]
fn host_messages_golden_bytes_and_round_trip() {
    let mut buf = [0u8; MAX_FRAME_LEN];
    for (msg, bytes) in host_golden() {
        let frame = msg.encode(&mut buf).unwrap();
        assert_eq!(frame, bytes, "{msg:?}");
        let mut acc = FrameAccumulator::new();
        let got = collect(&mut acc, bytes);
        assert_eq!(got.len(), 1);
        let decoded = got[0].as_ref().unwrap();
        assert_eq!(HostMessage::decode(decoded).unwrap(), msg);
    }
}

#[test]
fn device_messages_golden_bytes_and_round_trip() {
    let mut buf = [0u8; MAX_FRAME_LEN];
    for (msg, bytes) in device_golden() {
        let frame = msg.encode(&mut buf).unwrap();
        assert_eq!(frame, bytes, "{msg:?}");
        let mut acc = FrameAccumulator::new();
        let got = collect(&mut acc, bytes);
        let decoded = got[0].as_ref().unwrap();
        assert_eq!(DeviceMessage::decode(decoded).unwrap(), msg);
    }
}

#[test]
fn split_frames_garbage_and_resync() {
    let mut stream = StdVec::new();
    stream.extend_from_slice(&[0x13, 0x37, 0xff]); // garbage before the first delimiter
    stream.push(0);
    for (_, bytes) in host_golden() {
        stream.extend_from_slice(bytes);
    }
    // Feed in chunks of every size: the result must not depend on the split.
    for chunk in 1..=7 {
        let mut acc = FrameAccumulator::new();
        let mut got = StdVec::new();
        for part in stream.chunks(chunk) {
            got.extend(collect(&mut acc, part));
        }
        assert_eq!(got.len(), 1 + host_golden().len());
        // 13 37 ff: code 0x13 promises 18 bytes, only 2 follow.
        assert_eq!(got[0], Err(WireError::BadCobs));
        for (g, (msg, _)) in got[1..].iter().zip(host_golden()) {
            assert_eq!(HostMessage::decode(g.as_ref().unwrap()).unwrap(), msg);
        }
    }
}

/// xorshift64*: small, seeded, good enough to drive mutation.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn byte(&mut self) -> u8 {
        self.next() as u8
    }
}

fn mutate(rng: &mut Rng, data: &mut StdVec<u8>) {
    for _ in 0..1 + rng.below(4) {
        match rng.below(6) {
            0 if !data.is_empty() => {
                let i = rng.below(data.len());
                data[i] ^= 1 << rng.below(8);
            }
            1 if !data.is_empty() => {
                let i = rng.below(data.len());
                data[i] = rng.byte();
            }
            2 => {
                let i = rng.below(data.len() + 1);
                data.insert(i, rng.byte());
            }
            3 if !data.is_empty() => {
                let i = rng.below(data.len());
                data.remove(i);
            }
            4 => {
                let n = rng.below(data.len() + 1);
                data.truncate(n);
            }
            _ => {
                let i = rng.below(data.len() + 1);
                let n = rng.below(8);
                for _ in 0..n {
                    data.insert(i, rng.byte());
                }
            }
        }
    }
}

#[test]
fn decoders_survive_100k_random_and_mutated_inputs() {
    let mut rng = Rng(0x5EED_CAFE_F00D_0001);
    let mut frames: StdVec<StdVec<u8>> = host_golden().iter().map(|(_, b)| b.to_vec()).collect();
    frames.extend(device_golden().iter().map(|(_, b)| b.to_vec()));
    let mut buf = [0u8; MAX_FRAME_LEN];
    frames.push(
        HostMessage::LoadModel(&REFERENCE_BLOB)
            .encode(&mut buf)
            .unwrap()
            .to_vec(),
    );

    let (mut frames_ok, mut frame_errs, mut msgs_ok, mut msg_errs) = (0u32, 0u32, 0u32, 0u32);
    let mut acc = FrameAccumulator::new();
    for case in 0..60_000 {
        let input: StdVec<u8> = if case % 4 == 0 {
            // pure noise, sometimes long enough to overflow the accumulator
            let n = rng.below(if case % 40 == 0 { 1000 } else { 64 });
            (0..n).map(|_| rng.byte()).collect()
        } else {
            let mut f = frames[rng.below(frames.len())].clone();
            mutate(&mut rng, &mut f);
            f
        };
        for r in collect(&mut acc, &input) {
            match r {
                Ok(f) => {
                    frames_ok += 1;
                    match (HostMessage::decode(&f), DeviceMessage::decode(&f)) {
                        (Err(_), Err(_)) => msg_errs += 1,
                        _ => msgs_ok += 1,
                    }
                    if let Ok(HostMessage::LoadModel(b)) = HostMessage::decode(&f) {
                        if let Ok(m) = decode_blob(b) {
                            assert_eq!(m.validate(), Ok(()));
                        }
                    }
                }
                Err(WireError::BadCobs | WireError::FrameTooLong) => frame_errs += 1,
                Err(e) => panic!("accumulator returned {e:?}"),
            }
        }
    }
    assert!(
        frames_ok > 2_000 && frame_errs > 10_000,
        "{frames_ok} {frame_errs}"
    );
    assert!(msgs_ok > 1_000 && msg_errs > 1_000, "{msgs_ok} {msg_errs}");

    // Blobs: mutate, and half of the time fix the CRC so payload parsing and model
    // validation see the damage.
    let models = [
        reference_model(),
        ModelSpec::new(
            2,
            1.0,
            &[-0.7, -1.5],
            &[0.1, -0.05],
            &[0.3, -0.2],
            Units::default(),
            &[
                Effect::Wind {
                    beta_s2: 0.1,
                    beta_c2: -0.1,
                    beta_s1: 0.2,
                    beta_c1: 0.0,
                },
                Effect::Saturation { limit: 35.0 },
            ],
        )
        .unwrap(),
    ];
    let mut seen = [0u32; 8];
    for case in 0..60_000 {
        let mut b = encode_blob(&models[case % 2], &mut [0u8; MAX_BLOB_LEN])
            .unwrap()
            .to_vec();
        mutate(&mut rng, &mut b);
        if case % 2 == 0 && b.len() >= 12 {
            let plen = b.len() - 12;
            b[6..8].copy_from_slice(&(plen as u16).to_le_bytes());
            let crc = crc32(&b[8..8 + plen]);
            let n = b.len();
            b[n - 4..].copy_from_slice(&crc.to_le_bytes());
        }
        let slot = match decode_blob(&b) {
            Ok(m) => {
                assert_eq!(m.validate(), Ok(()));
                0
            }
            Err(BlobError::Truncated { .. }) => 1,
            Err(BlobError::Oversized { .. }) => 2,
            Err(BlobError::BadMagic) => 3,
            Err(BlobError::UnsupportedVersion(_)) => 4,
            Err(BlobError::BadCrc { .. }) => 5,
            Err(BlobError::BadPayload) => 6,
            Err(BlobError::InvalidModel(_)) => 7,
            Err(e) => panic!("decode returned {e:?}"),
        };
        seen[slot] += 1;
    }
    // every outcome occurs, so the generator reaches every check
    assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
}
