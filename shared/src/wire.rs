//! UART messages between the host and the controller: postcard payloads in COBS frames.
//!
//! Every message is one frame on the wire: the postcard encoding of a [`HostMessage`] or a
//! [`DeviceMessage`], COBS-encoded (so it holds no `0x00`), followed by one `0x00` delimiter.
//! A frame, delimiter included, is at most [`MAX_FRAME_LEN`] bytes. Empty frames (two
//! delimiters in a row) are ignored, so a sender may start with a `0x00` to resynchronise.
//!
//! Receivers feed bytes one at a time into a [`FrameAccumulator`]; it returns each complete
//! decoded frame, or a typed error for an overlong or badly encoded one, and then
//! resynchronises at the next `0x00`.
//!
//! Conversation: the device sends [`DeviceMessage::Banner`] when its UART is up. Each host
//! message gets exactly one answer: `Ping` → `Pong`; `LoadModel` → `ModelLoaded`;
//! `Measurement` → `Ack`; `PredictRequest` → `Prediction`; `Reset` → `Ack` with
//! [`AckStatus::Cleared`]; `TrackMeasurement` → `TrackAck`; `TrackPredictRequest` →
//! `TrackPrediction`; any failure → `Error` with an [`ErrorCode`]. `Shutdown` is for tests
//! under an emulator and is not answered. The track messages (protocol 2) were appended, so
//! every message of protocol 1 keeps its bytes.

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::blob::BlobError;
use crate::model::ModelError;

/// Version of this message set, sent in the banner.
pub const PROTOCOL_VERSION: u16 = 2;
/// Largest prediction horizon H (steps ahead) a `PredictRequest` may ask for.
pub const MAX_HORIZON: usize = 64;
/// Largest postcard message (before COBS): a `LoadModel` with a [`MAX_BLOB_LEN`](crate::blob::MAX_BLOB_LEN) blob needs
/// `MAX_BLOB_LEN + 3`, a 64-step `Prediction` 263.
pub const MAX_MESSAGE_LEN: usize = 384;
/// Largest COBS-encoded message, without the delimiter: one overhead byte per 254 bytes.
pub const MAX_ENCODED_LEN: usize = MAX_MESSAGE_LEN + MAX_MESSAGE_LEN / 254 + 1;
/// Largest frame on the wire, delimiter included (387 bytes).
pub const MAX_FRAME_LEN: usize = MAX_ENCODED_LEN + 1;

/// Predicted outputs of a [`DeviceMessage::Prediction`] (at most [`MAX_HORIZON`]).
pub type Values = Vec<f32, MAX_HORIZON>;
/// Future commands of a [`HostMessage::PredictRequest`] (at most `MAX_HORIZON − 1`).
pub type FutureInputs = Vec<f32, { MAX_HORIZON - 1 }>;
/// Largest horizon of a [`HostMessage::TrackPredictRequest`]: its 3·H values fit [`Values`].
pub const MAX_TRACK_HORIZON: usize = MAX_HORIZON / 3;

/// Host → device.
// Messages live on the stack of a no-alloc device: variants are inline by design.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum HostMessage<'a> {
    /// Liveness check; answered with [`DeviceMessage::Pong`].
    Ping,
    /// A model blob (see [`crate::blob`]); replaces the current model and resets the state.
    LoadModel(&'a [u8]),
    /// One sample: command `u(t)`, measured yaw rate `y(t)` (NaN when missing) and, when
    /// logged, the measured heading `ψ(t)` in degrees. Runs one predictor update.
    Measurement {
        /// Commanded angle u(t).
        u: f32,
        /// Measured output y(t); non-finite means missing.
        y: f32,
        /// Measured heading ψ(t) in degrees, if any.
        psi: Option<f32>,
    },
    /// Ask for ŷ(t+1|t) … ŷ(t+H|t); `future_u` holds u(t+1) … u(t+H−1) (at least H−1 values).
    PredictRequest {
        /// H, `1..=MAX_HORIZON`.
        horizon: u8,
        /// Future commands u(t+1), u(t+2), ….
        future_u: FutureInputs,
    },
    /// Clear the predictor state (x̂, delay line, actuator, heading) and the sample counter.
    Reset,
    /// End the emulator run with this exit code (semihosting); ignored on hardware.
    Shutdown {
        /// Process exit code.
        code: u8,
    },
    /// A `Measurement` with the navigation channels: runs the yaw-rate update, then the
    /// heading/track update (the model must have a track part).
    TrackMeasurement {
        /// Commanded angle u(t).
        u: f32,
        /// Measured yaw rate y(t); non-finite means missing.
        y: f32,
        /// Measured heading ψ(t) in degrees, if any.
        psi: Option<f32>,
        /// Ground velocity (north, east) in m/s, if measured.
        velocity: Option<[f32; 2]>,
        /// Position fix (north, east) in metres, if measured.
        fix: Option<[f32; 2]>,
    },
    /// Ask for the heading and position at t+1 … t+H (H ≤ [`MAX_TRACK_HORIZON`]), from the
    /// yaw-rate prediction with these future commands.
    TrackPredictRequest {
        /// H, `1..=MAX_TRACK_HORIZON`.
        horizon: u8,
        /// Future commands u(t+1), u(t+2), ….
        future_u: FutureInputs,
    },
}

/// Device → host.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum DeviceMessage {
    /// Sent once at boot, when the UART is ready.
    Banner {
        /// [`PROTOCOL_VERSION`].
        protocol: u16,
        /// Model blob format version the device reads.
        blob_version: u16,
        /// The model order the device runs.
        order: u8,
        /// Whether a model linked into flash is already loaded.
        model_loaded: bool,
    },
    /// Answer to `Ping`.
    Pong,
    /// A model was accepted.
    ModelLoaded {
        /// Its order.
        order: u8,
        /// How many effects it carries.
        effects: u8,
        /// CRC-32 of its blob payload, to identify it.
        crc: u32,
    },
    /// Answer to `Measurement` (and `Reset`).
    Ack {
        /// Number of measurements processed since the model was loaded or reset.
        sample: u32,
        /// What the update did.
        status: AckStatus,
    },
    /// Answer to `PredictRequest`: ŷ(t+1|t) … ŷ(t+H|t).
    Prediction {
        /// Number of measurements the prediction is based on.
        sample: u32,
        /// The H predicted outputs.
        values: Values,
    },
    /// A request failed; the device keeps running.
    Error {
        /// What went wrong.
        code: ErrorCode,
    },
    /// Answer to `TrackMeasurement`.
    TrackAck {
        /// Number of measurements processed since the model was loaded or reset.
        sample: u32,
        /// What the yaw-rate update did.
        status: AckStatus,
        /// What became of the ground velocity.
        velocity: NavStatus,
        /// What became of the position fix.
        fix: NavStatus,
        /// The track state went non-finite and was reset.
        reset: bool,
    },
    /// Answer to `TrackPredictRequest`: `ψ̂ (deg), n (m), e (m)` at t+1, then at t+2, …
    /// (3·H values).
    TrackPrediction {
        /// Number of measurements the prediction is based on.
        sample: u32,
        /// The 3·H values, row after row.
        values: Values,
    },
}

/// What became of one navigation measurement, as reported in [`DeviceMessage::TrackAck`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum NavStatus {
    /// Not measured.
    Absent,
    /// Applied.
    Applied,
    /// Not finite: skipped.
    Rejected,
    /// Innovation beyond its gate (a jump): skipped.
    Gated,
}

/// Outcome of a measurement update, as reported in [`DeviceMessage::Ack`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum AckStatus {
    /// Measurement used: innovation correction applied.
    Corrected,
    /// Measurement missing or non-finite: time update only, correction skipped.
    SkippedCorrection,
    /// The state became non-finite and was reset to zero.
    NonFiniteReset,
    /// The state was cleared on request.
    Cleared,
}

/// Error codes sent in [`DeviceMessage::Error`]. The number is the postcard encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
#[repr(u8)]
pub enum ErrorCode {
    /// A frame was longer than [`MAX_FRAME_LEN`].
    FrameTooLong = 0,
    /// A frame was not valid COBS.
    BadCobs = 1,
    /// A frame did not hold a host message.
    BadMessage = 2,
    /// `Measurement` or `PredictRequest` before any model was loaded.
    NoModel = 3,
    /// Blob shorter than its header says.
    BlobTruncated = 4,
    /// Blob longer than allowed or than its header says.
    BlobOversized = 5,
    /// Blob magic wrong.
    BlobBadMagic = 6,
    /// Blob format version not supported.
    BlobBadVersion = 7,
    /// Blob CRC mismatch.
    BlobBadCrc = 8,
    /// Blob payload not a model.
    BlobBadPayload = 9,
    /// Model parameters out of range (order, lengths, non-finite, effect parameters).
    ModelInvalid = 10,
    /// Model or its predictor unstable.
    ModelUnstable = 11,
    /// Model order differs from the order this firmware runs.
    UnsupportedOrder = 12,
    /// Horizon outside `1..=MAX_HORIZON`.
    HorizonOutOfRange = 13,
    /// Fewer future inputs than the horizon needs.
    NotEnoughInputs = 14,
    /// The prediction went non-finite.
    NonFinite = 15,
    /// The blob's track part is not valid.
    TrackInvalid = 16,
    /// A track request, but the loaded model has no track part.
    NoTrack = 17,
}

impl ErrorCode {
    /// The numeric code (as sent on the wire).
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_shared::wire::ErrorCode;
    /// assert_eq!(ErrorCode::BlobBadCrc.code(), 8);
    /// ```
    pub const fn code(self) -> u8 {
        self as u8
    }
}

impl From<BlobError> for ErrorCode {
    fn from(e: BlobError) -> Self {
        match e {
            BlobError::Truncated { .. } => ErrorCode::BlobTruncated,
            BlobError::Oversized { .. } | BlobError::BufferTooSmall => ErrorCode::BlobOversized,
            BlobError::BadMagic => ErrorCode::BlobBadMagic,
            BlobError::UnsupportedVersion(_) => ErrorCode::BlobBadVersion,
            BlobError::BadCrc { .. } => ErrorCode::BlobBadCrc,
            BlobError::BadPayload => ErrorCode::BlobBadPayload,
            BlobError::InvalidModel(m) => m.into(),
            BlobError::InvalidTrack(_) => ErrorCode::TrackInvalid,
        }
    }
}

impl From<ModelError> for ErrorCode {
    fn from(e: ModelError) -> Self {
        match e {
            ModelError::UnstableModel | ModelError::UnstablePredictor => ErrorCode::ModelUnstable,
            _ => ErrorCode::ModelInvalid,
        }
    }
}

impl From<WireError> for ErrorCode {
    fn from(e: WireError) -> Self {
        match e {
            WireError::FrameTooLong => ErrorCode::FrameTooLong,
            WireError::BadCobs => ErrorCode::BadCobs,
            _ => ErrorCode::BadMessage,
        }
    }
}

/// Why a frame could not be built or read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum WireError {
    /// More than [`MAX_ENCODED_LEN`] bytes arrived without a delimiter.
    FrameTooLong,
    /// The frame is not valid COBS.
    BadCobs,
    /// The frame's bytes are not a message of the expected type.
    BadMessage,
    /// The message decoded but bytes were left over.
    TrailingBytes,
    /// The message does not fit the buffer given, or would exceed [`MAX_FRAME_LEN`].
    BufferTooSmall,
}

impl core::fmt::Display for WireError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            WireError::FrameTooLong => write!(
                f,
                "frame longer than {MAX_ENCODED_LEN} bytes before its delimiter"
            ),
            WireError::BadCobs => write!(f, "frame is not valid COBS"),
            WireError::BadMessage => write!(f, "frame does not hold a valid message"),
            WireError::TrailingBytes => write!(f, "message is followed by extra bytes"),
            WireError::BufferTooSmall => write!(
                f,
                "message does not fit the buffer or the {MAX_FRAME_LEN}-byte frame limit"
            ),
        }
    }
}

impl core::error::Error for WireError {}

/// Serialises `msg` into `buf` as one complete frame (COBS + `0x00`).
fn encode_frame<'b, T: Serialize>(msg: &T, buf: &'b mut [u8]) -> Result<&'b [u8], WireError> {
    let room = buf.len().min(MAX_FRAME_LEN);
    match postcard::to_slice_cobs(msg, &mut buf[..room]) {
        Ok(frame) => Ok(frame),
        Err(_) => Err(WireError::BufferTooSmall),
    }
}

/// Parses a whole decoded frame (no bytes may be left over).
fn decode_frame<'a, T: Deserialize<'a>>(frame: &'a [u8]) -> Result<T, WireError> {
    let (msg, rest) = postcard::take_from_bytes(frame).map_err(|_| WireError::BadMessage)?;
    if rest.is_empty() {
        Ok(msg)
    } else {
        Err(WireError::TrailingBytes)
    }
}

impl<'a> HostMessage<'a> {
    /// Writes this message as one frame (COBS-encoded, `0x00`-terminated) into `buf`.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`] when the frame does not fit `buf` or [`MAX_FRAME_LEN`].
    ///
    /// ```
    /// use yawcast_shared::wire::HostMessage;
    /// let mut buf = [0u8; 16];
    /// assert_eq!(HostMessage::Ping.encode(&mut buf).unwrap(), &[0x01, 0x01, 0x00]);
    /// ```
    pub fn encode<'b>(&self, buf: &'b mut [u8]) -> Result<&'b [u8], WireError> {
        encode_frame(self, buf)
    }

    /// Parses a decoded frame (as returned by [`FrameAccumulator::push`]).
    ///
    /// # Errors
    /// [`WireError::BadMessage`] when the bytes are not a host message,
    /// [`WireError::TrailingBytes`] when bytes are left over.
    ///
    /// ```
    /// use yawcast_shared::wire::{HostMessage, WireError};
    /// assert_eq!(HostMessage::decode(&[0x04]), Ok(HostMessage::Reset));
    /// assert_eq!(HostMessage::decode(&[0x04, 0x00]), Err(WireError::TrailingBytes));
    /// assert_eq!(HostMessage::decode(&[0x63]), Err(WireError::BadMessage));
    /// ```
    pub fn decode(frame: &'a [u8]) -> Result<Self, WireError> {
        decode_frame(frame)
    }
}

impl DeviceMessage {
    /// Writes this message as one frame (COBS-encoded, `0x00`-terminated) into `buf`.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`] when the frame does not fit `buf` or [`MAX_FRAME_LEN`].
    ///
    /// ```
    /// use yawcast_shared::wire::DeviceMessage;
    /// let mut buf = [0u8; 16];
    /// assert_eq!(DeviceMessage::Pong.encode(&mut buf).unwrap(), &[0x02, 0x01, 0x00]);
    /// ```
    pub fn encode<'b>(&self, buf: &'b mut [u8]) -> Result<&'b [u8], WireError> {
        encode_frame(self, buf)
    }

    /// Parses a decoded frame (as returned by [`FrameAccumulator::push`]).
    ///
    /// # Errors
    /// [`WireError::BadMessage`] when the bytes are not a device message,
    /// [`WireError::TrailingBytes`] when bytes are left over.
    ///
    /// ```
    /// use yawcast_shared::wire::DeviceMessage;
    /// assert_eq!(DeviceMessage::decode(&[0x01]), Ok(DeviceMessage::Pong));
    /// ```
    pub fn decode(frame: &[u8]) -> Result<Self, WireError> {
        decode_frame(frame)
    }
}

/// What one byte fed to a [`FrameAccumulator`] produced.
#[derive(Debug, PartialEq, Eq)]
pub enum Feed<'a> {
    /// Nothing yet: the byte was stored, skipped, or was a delimiter ending an empty frame.
    Pending,
    /// A complete frame, COBS-decoded: the postcard bytes of one message.
    Frame(&'a [u8]),
    /// A broken frame; bytes up to the next `0x00` are dropped.
    Error(WireError),
}

/// Collects bytes into frames, one byte at a time; no allocation, fixed
/// [`MAX_ENCODED_LEN`]-byte buffer.
#[derive(Debug, Clone)]
pub struct FrameAccumulator {
    buf: [u8; MAX_ENCODED_LEN],
    len: usize,
    discarding: bool,
}

impl Default for FrameAccumulator {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameAccumulator {
    /// An empty accumulator.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_shared::wire::{Feed, FrameAccumulator};
    /// let mut acc = FrameAccumulator::new();
    /// assert_eq!(acc.push(0x00), Feed::Pending);
    /// ```
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_ENCODED_LEN],
            len: 0,
            discarding: false,
        }
    }

    /// Feeds one byte.
    ///
    /// On `0x00` the collected bytes are COBS-decoded in place and returned as
    /// [`Feed::Frame`] (an empty frame gives [`Feed::Pending`]). When the buffer
    /// overflows, [`Feed::Error`] with [`WireError::FrameTooLong`] is returned once and
    /// bytes are dropped up to and including the next `0x00`.
    ///
    /// # Errors
    /// Reported in-band as [`Feed::Error`]: [`WireError::FrameTooLong`] or
    /// [`WireError::BadCobs`]. The accumulator is ready for the next frame afterwards.
    ///
    /// ```
    /// use yawcast_shared::wire::{Feed, FrameAccumulator, WireError};
    /// let mut acc = FrameAccumulator::new();
    /// assert_eq!(acc.push(0x02), Feed::Pending);
    /// assert_eq!(acc.push(0x07), Feed::Pending);
    /// assert_eq!(acc.push(0x00), Feed::Frame(&[0x07]));
    /// // 0x05 promises four more bytes, but the frame ends after one.
    /// acc.push(0x05);
    /// acc.push(0x01);
    /// assert_eq!(acc.push(0x00), Feed::Error(WireError::BadCobs));
    /// ```
    pub fn push(&mut self, byte: u8) -> Feed<'_> {
        if byte == 0 {
            let len = self.len;
            self.len = 0;
            if self.discarding {
                self.discarding = false;
                return Feed::Pending;
            }
            if len == 0 {
                return Feed::Pending;
            }
            let frame = &mut self.buf[..len];
            return match cobs::decode_in_place(frame) {
                Ok(n) if n <= len => Feed::Frame(&self.buf[..n]),
                _ => Feed::Error(WireError::BadCobs),
            };
        }
        if self.discarding {
            return Feed::Pending;
        }
        if self.len >= MAX_ENCODED_LEN {
            self.len = 0;
            self.discarding = true;
            return Feed::Error(WireError::FrameTooLong);
        }
        self.buf[self.len] = byte;
        self.len += 1;
        Feed::Pending
    }

    /// Drops any partly received frame.
    ///
    /// # Errors
    /// None.
    ///
    /// ```
    /// use yawcast_shared::wire::{Feed, FrameAccumulator};
    /// let mut acc = FrameAccumulator::new();
    /// acc.push(0x02);
    /// acc.clear();
    /// assert_eq!(acc.push(0x00), Feed::Pending);
    /// ```
    pub fn clear(&mut self) {
        self.len = 0;
        self.discarding = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blob::MAX_BLOB_LEN;
    use std::vec::Vec as StdVec;

    fn frames(bytes: &[u8]) -> StdVec<Result<StdVec<u8>, WireError>> {
        let mut acc = FrameAccumulator::new();
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
    fn overlong_frame_is_reported_once_then_resyncs() {
        let mut bytes = StdVec::new();
        bytes.extend(core::iter::repeat_n(0x11u8, MAX_ENCODED_LEN + 50));
        bytes.push(0);
        bytes.extend_from_slice(&[0x01, 0x01, 0x00]); // Ping
        let got = frames(&bytes);
        assert_eq!(got, [Err(WireError::FrameTooLong), Ok(std::vec![0x00])]);
        // exactly MAX_ENCODED_LEN bytes is still a frame
        let mut bytes = std::vec![0x01u8; MAX_ENCODED_LEN];
        bytes.push(0);
        let got = frames(&bytes);
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].as_ref().unwrap().len(), MAX_ENCODED_LEN - 1);
    }

    #[test]
    fn largest_messages_fit_the_frame_limit() {
        let blob = [0xAAu8; MAX_BLOB_LEN];
        let mut buf = [0u8; MAX_FRAME_LEN];
        let f = HostMessage::LoadModel(&blob).encode(&mut buf).unwrap();
        assert!(f.len() <= MAX_FRAME_LEN);
        let mut values = Vec::new();
        values.resize(MAX_HORIZON, -1.0e30).unwrap();
        let msg = DeviceMessage::Prediction {
            sample: u32::MAX,
            values,
        };
        let f = msg.encode(&mut buf).unwrap();
        assert!(f.len() <= MAX_FRAME_LEN, "{}", f.len());
        let mut fu = Vec::new();
        fu.resize(MAX_HORIZON - 1, 1.0).unwrap();
        let msg = HostMessage::PredictRequest {
            horizon: 64,
            future_u: fu,
        };
        let f = msg.encode(&mut buf).unwrap();
        assert!(f.len() <= MAX_FRAME_LEN);
        // too big for the buffer
        assert_eq!(
            HostMessage::LoadModel(&blob).encode(&mut [0u8; 10]),
            Err(WireError::BufferTooSmall)
        );
        let big = [0u8; MAX_MESSAGE_LEN + 10];
        let mut huge = [0u8; 2 * MAX_FRAME_LEN];
        assert_eq!(
            HostMessage::LoadModel(&big).encode(&mut huge),
            Err(WireError::BufferTooSmall)
        );
    }

    #[test]
    fn error_codes_are_their_postcard_encoding() {
        let all = [
            ErrorCode::FrameTooLong,
            ErrorCode::BadCobs,
            ErrorCode::BadMessage,
            ErrorCode::NoModel,
            ErrorCode::BlobTruncated,
            ErrorCode::BlobOversized,
            ErrorCode::BlobBadMagic,
            ErrorCode::BlobBadVersion,
            ErrorCode::BlobBadCrc,
            ErrorCode::BlobBadPayload,
            ErrorCode::ModelInvalid,
            ErrorCode::ModelUnstable,
            ErrorCode::UnsupportedOrder,
            ErrorCode::HorizonOutOfRange,
            ErrorCode::NotEnoughInputs,
            ErrorCode::NonFinite,
        ];
        for (i, c) in all.iter().enumerate() {
            let mut buf = [0u8; 4];
            let b = postcard::to_slice(c, &mut buf).unwrap();
            assert_eq!(b, &[i as u8]);
            assert_eq!(c.code(), i as u8);
        }
    }
}
