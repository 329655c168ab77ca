//! The versioned model blob (`model.postcard`): what the host writes and the firmware loads.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 4 | magic `b"YAWC"` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`]) |
//! | 6 | 2 | payload length `L` (at most [`MAX_PAYLOAD_LEN`]) |
//! | 8 | `L` | postcard encoding of [`ModelSpec`] (version 3: followed by its [`TrackSpec`]) |
//! | 8 + `L` | 4 | CRC-32 (IEEE) of the payload |
//!
//! [`decode_blob`] checks every part and validates the model (finite, sane, stable), so a
//! blob that decodes is safe to hand to the firmware predictor.
//!
//! Version 2 carries the model in the difference form of [`crate::model`]; version 3 carries
//! the same model followed by its heading/track part ([`crate::nav`]). A model without a
//! track part is still written as version 2, byte for byte as before, so a controller
//! older than the track part keeps loading it; both versions are read. Version 1 carried
//! the shift-form companion row, which `f32` cannot hold for poles close to 1, and is refused
//! ([`BlobError::UnsupportedVersion`]): export the model again.

use crate::crc::crc32;
use crate::model::{ModelError, ModelSpec};
use crate::nav::{TrackError, TrackSpec};

/// First four bytes of every blob.
pub const MAGIC: [u8; 4] = *b"YAWC";
/// The newest blob format version (a model with its track part); this crate reads it and
/// [`MODEL_ONLY_VERSION`].
pub const FORMAT_VERSION: u16 = 3;
/// The version of a blob without a track part (written for such models, read as ever).
pub const MODEL_ONLY_VERSION: u16 = 2;
/// Bytes before the payload: magic, version, payload length.
pub const HEADER_LEN: usize = 8;
/// Bytes after the payload: the CRC.
pub const TRAILER_LEN: usize = 4;
/// Largest payload accepted. The largest valid model (order 8, all ten effects) needs 171,
/// 212 with a track part.
pub const MAX_PAYLOAD_LEN: usize = 256;
/// Largest blob: header, payload, CRC.
pub const MAX_BLOB_LEN: usize = HEADER_LEN + MAX_PAYLOAD_LEN + TRAILER_LEN;

/// Why a blob could not be written or read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum BlobError {
    /// The input ends before the header, payload or CRC is complete.
    Truncated {
        /// Bytes given.
        len: usize,
        /// Bytes the header says the blob has (or the header length).
        needed: usize,
    },
    /// The declared payload is longer than [`MAX_PAYLOAD_LEN`], or bytes follow the CRC.
    Oversized {
        /// Bytes given (or declared payload length).
        len: usize,
    },
    /// The first four bytes are not [`MAGIC`].
    BadMagic,
    /// The format version is neither [`MODEL_ONLY_VERSION`] nor [`FORMAT_VERSION`].
    UnsupportedVersion(u16),
    /// The stored CRC does not match the payload.
    BadCrc {
        /// CRC stored in the blob.
        stored: u32,
        /// CRC computed over the payload.
        computed: u32,
    },
    /// The payload is not a postcard-encoded model (or has bytes left over).
    BadPayload,
    /// The payload is a model, but not a valid one (non-finite, out of range, unstable).
    InvalidModel(ModelError),
    /// The output buffer given to [`encode_blob`] is too small.
    BufferTooSmall,
    /// The track part of a version 3 blob is not valid.
    InvalidTrack(TrackError),
}

impl core::fmt::Display for BlobError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            BlobError::Truncated { len, needed } => {
                write!(f, "model blob truncated: {len} bytes of {needed}")
            }
            BlobError::Oversized { len } => write!(
                f,
                "model blob oversized: {len} bytes (at most {MAX_BLOB_LEN}, nothing after the CRC)"
            ),
            BlobError::BadMagic => write!(f, "not a yawcast model blob (bad magic)"),
            BlobError::UnsupportedVersion(v) => write!(
                f,
                "model blob format version {v} is not supported (expected {MODEL_ONLY_VERSION} or {FORMAT_VERSION})"
            ),
            BlobError::BadCrc { stored, computed } => write!(
                f,
                "model blob CRC mismatch: stored {stored:#010x}, computed {computed:#010x}"
            ),
            BlobError::BadPayload => write!(f, "model blob payload is not a model"),
            BlobError::InvalidModel(e) => write!(f, "model blob holds an invalid model: {e}"),
            BlobError::BufferTooSmall => write!(f, "buffer too small for the model blob"),
            BlobError::InvalidTrack(e) => write!(f, "model blob holds an invalid {e}"),
        }
    }
}

impl core::error::Error for BlobError {}

impl From<ModelError> for BlobError {
    fn from(e: ModelError) -> Self {
        BlobError::InvalidModel(e)
    }
}

/// Writes `spec` as a blob into `buf` and returns the bytes written.
///
/// # Errors
/// [`BlobError::InvalidModel`] when `spec` does not validate, [`BlobError::BufferTooSmall`]
/// when `buf` cannot hold the blob (a buffer of [`MAX_BLOB_LEN`] always can).
///
/// ```
/// use yawcast_shared::blob::{decode_blob, encode_blob, MAX_BLOB_LEN};
/// use yawcast_shared::model::{ModelSpec, Units};
/// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
///                        Units::default(), &[]).unwrap();
/// let mut buf = [0u8; MAX_BLOB_LEN];
/// let blob = encode_blob(&m, &mut buf).unwrap();
/// assert_eq!(&blob[..4], b"YAWC");
/// assert_eq!(blob.len(), 8 + 35 + 4);
/// assert_eq!(decode_blob(blob), Ok(m));
/// ```
pub fn encode_blob<'a>(spec: &ModelSpec, buf: &'a mut [u8]) -> Result<&'a [u8], BlobError> {
    encode_blob_with_track(spec, None, buf)
}

/// Writes `spec` and, when given, its track part as a blob into `buf` and returns the bytes
/// written: version [`FORMAT_VERSION`] with a track part, [`MODEL_ONLY_VERSION`] without.
///
/// # Errors
/// As [`encode_blob`], and [`BlobError::InvalidTrack`] when the track part does not validate
/// for the model's sample time.
///
/// ```
/// use yawcast_shared::blob::{decode_blob_with_track, encode_blob_with_track, MAX_BLOB_LEN};
/// use yawcast_shared::model::{ModelSpec, Units};
/// use yawcast_shared::nav::TrackSpec;
/// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
///                        Units::default(), &[]).unwrap();
/// let t = TrackSpec::new(1.0, 1.3, true).unwrap();
/// let mut buf = [0u8; MAX_BLOB_LEN];
/// let blob = encode_blob_with_track(&m, Some(&t), &mut buf).unwrap();
/// assert_eq!(&blob[4..6], &[3, 0]);
/// assert_eq!(blob.len(), 8 + 35 + 41 + 4);
/// assert_eq!(decode_blob_with_track(blob), Ok((m, Some(t))));
/// ```
pub fn encode_blob_with_track<'a>(
    spec: &ModelSpec,
    track: Option<&TrackSpec>,
    buf: &'a mut [u8],
) -> Result<&'a [u8], BlobError> {
    spec.validate()?;
    if let Some(t) = track {
        t.validate(spec.ts).map_err(BlobError::InvalidTrack)?;
    }
    if buf.len() < HEADER_LEN + TRAILER_LEN {
        return Err(BlobError::BufferTooSmall);
    }
    let room = (buf.len() - HEADER_LEN - TRAILER_LEN).min(MAX_PAYLOAD_LEN);
    let area = &mut buf[HEADER_LEN..HEADER_LEN + room];
    let model_len = postcard::to_slice(spec, area)
        .map_err(|_| BlobError::BufferTooSmall)?
        .len();
    let payload_len = match track {
        Some(t) => {
            model_len
                + postcard::to_slice(t, &mut area[model_len..])
                    .map_err(|_| BlobError::BufferTooSmall)?
                    .len()
        }
        None => model_len,
    };
    let version = if track.is_some() {
        FORMAT_VERSION
    } else {
        MODEL_ONLY_VERSION
    };
    let crc = crc32(&buf[HEADER_LEN..HEADER_LEN + payload_len]);
    buf[0..4].copy_from_slice(&MAGIC);
    buf[4..6].copy_from_slice(&version.to_le_bytes());
    // payload_len ≤ MAX_PAYLOAD_LEN < 2^16
    buf[6..8].copy_from_slice(&(payload_len as u16).to_le_bytes());
    let end = HEADER_LEN + payload_len;
    buf[end..end + TRAILER_LEN].copy_from_slice(&crc.to_le_bytes());
    Ok(&buf[..end + TRAILER_LEN])
}

/// Reads and validates a blob.
///
/// Checks, in order: length of the header, magic, version, declared payload length, total
/// length, CRC, postcard payload (no bytes left over), and [`ModelSpec::validate`].
///
/// # Errors
/// One [`BlobError`] variant per failed check; never panics, whatever the input.
///
/// ```
/// use yawcast_shared::blob::{decode_blob, encode_blob, BlobError, MAX_BLOB_LEN};
/// use yawcast_shared::model::{ModelSpec, Units};
/// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
///                        Units::default(), &[]).unwrap();
/// let mut buf = [0u8; MAX_BLOB_LEN];
/// let len = encode_blob(&m, &mut buf).unwrap().len();
/// assert_eq!(decode_blob(&buf[..len - 1]), Err(BlobError::Truncated { len: 46, needed: 47 }));
/// buf[10] ^= 1;
/// assert!(matches!(decode_blob(&buf[..len]), Err(BlobError::BadCrc { .. })));
/// assert_eq!(decode_blob(b"PNG\x89...."), Err(BlobError::BadMagic));
/// ```
pub fn decode_blob(bytes: &[u8]) -> Result<ModelSpec, BlobError> {
    decode_blob_with_track(bytes).map(|(spec, _)| spec)
}

/// Reads and validates a blob of either version with its track part (`None` in a version 2
/// blob); the checks of [`decode_blob`], then the track part's own for the model's sample
/// time.
///
/// # Errors
/// As [`decode_blob`], and [`BlobError::InvalidTrack`].
///
/// ```
/// use yawcast_shared::blob::{decode_blob_with_track, encode_blob, MAX_BLOB_LEN};
/// use yawcast_shared::model::{ModelSpec, Units};
/// let m = ModelSpec::new(2, 1.0, &[-0.7, -1.5], &[0.1, -0.05], &[0.3, -0.2],
///                        Units::default(), &[]).unwrap();
/// let mut buf = [0u8; MAX_BLOB_LEN];
/// let blob = encode_blob(&m, &mut buf).unwrap(); // no track part: version 2
/// assert_eq!(&blob[4..6], &[2, 0]);
/// assert_eq!(decode_blob_with_track(blob), Ok((m, None)));
/// ```
pub fn decode_blob_with_track(bytes: &[u8]) -> Result<(ModelSpec, Option<TrackSpec>), BlobError> {
    if bytes.len() < HEADER_LEN {
        return Err(BlobError::Truncated {
            len: bytes.len(),
            needed: HEADER_LEN,
        });
    }
    if bytes[0..4] != MAGIC {
        return Err(BlobError::BadMagic);
    }
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    if version != FORMAT_VERSION && version != MODEL_ONLY_VERSION {
        return Err(BlobError::UnsupportedVersion(version));
    }
    let payload_len = usize::from(u16::from_le_bytes([bytes[6], bytes[7]]));
    if payload_len > MAX_PAYLOAD_LEN {
        return Err(BlobError::Oversized { len: payload_len });
    }
    let total = HEADER_LEN + payload_len + TRAILER_LEN;
    if bytes.len() < total {
        return Err(BlobError::Truncated {
            len: bytes.len(),
            needed: total,
        });
    }
    if bytes.len() > total {
        return Err(BlobError::Oversized { len: bytes.len() });
    }
    let payload = &bytes[HEADER_LEN..HEADER_LEN + payload_len];
    let t = HEADER_LEN + payload_len;
    let stored = u32::from_le_bytes([bytes[t], bytes[t + 1], bytes[t + 2], bytes[t + 3]]);
    let computed = crc32(payload);
    if stored != computed {
        return Err(BlobError::BadCrc { stored, computed });
    }
    let (spec, rest): (ModelSpec, &[u8]) =
        postcard::take_from_bytes(payload).map_err(|_| BlobError::BadPayload)?;
    let (track, rest) = if version == FORMAT_VERSION {
        let (t, rest): (TrackSpec, &[u8]) =
            postcard::take_from_bytes(rest).map_err(|_| BlobError::BadPayload)?;
        (Some(t), rest)
    } else {
        (None, rest)
    };
    if !rest.is_empty() {
        return Err(BlobError::BadPayload);
    }
    spec.validate()?;
    if let Some(t) = &track {
        t.validate(spec.ts).map_err(BlobError::InvalidTrack)?;
    }
    Ok((spec, track))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Units, EVERY_EFFECT, MAX_ORDER};

    fn full_model() -> ModelSpec {
        // order 8 with every effect: the largest payload there is. (δ + 0.5)⁸: eight poles
        // at z = 0.5.
        let a = [
            -0.003_906_25,
            -0.0625,
            -0.4375,
            -1.75,
            -4.375,
            -7.0,
            -7.0,
            -4.0,
        ];
        let mut k = [0.0f32; MAX_ORDER];
        k[0] = 0.1;
        ModelSpec::new(8, 0.5, &a, &[0.1; 8], &k, Units::default(), &EVERY_EFFECT).unwrap()
    }

    #[test]
    fn largest_model_fits_and_round_trips() {
        let m = full_model();
        let mut buf = [0u8; MAX_BLOB_LEN];
        let blob = encode_blob(&m, &mut buf).unwrap();
        assert_eq!(blob.len(), HEADER_LEN + 171 + TRAILER_LEN);
        assert_eq!(decode_blob(blob), Ok(m));
    }

    #[test]
    fn every_check_has_its_own_error() {
        let m = full_model();
        let mut buf = [0u8; MAX_BLOB_LEN];
        let blob: std::vec::Vec<u8> = encode_blob(&m, &mut buf).unwrap().to_vec();
        let n = blob.len();
        assert_eq!(
            decode_blob(&blob[..5]),
            Err(BlobError::Truncated { len: 5, needed: 8 })
        );
        let mut b = blob.clone();
        b[0] = b'X';
        assert_eq!(decode_blob(&b[..n]), Err(BlobError::BadMagic));
        let mut b = blob.clone();
        // version 1 held the shift-form companion row: refused, never misread
        b[4] = 1;
        assert_eq!(decode_blob(&b[..n]), Err(BlobError::UnsupportedVersion(1)));
        let mut b = blob.clone();
        b[6] = 0xFF;
        b[7] = 0x01;
        assert_eq!(
            decode_blob(&b[..n]),
            Err(BlobError::Oversized { len: 0x1FF })
        );
        let mut long = [0u8; MAX_BLOB_LEN + 1];
        long[..n].copy_from_slice(&blob[..n]);
        assert_eq!(
            decode_blob(&long[..n + 1]),
            Err(BlobError::Oversized { len: n + 1 })
        );
        let mut b = blob.clone();
        b[n - 1] ^= 0x80;
        assert!(matches!(
            decode_blob(&b[..n]),
            Err(BlobError::BadCrc { .. })
        ));
        // A payload that is not a model, with a correct CRC: order byte then garbage.
        let mut b = [0u8; 16];
        b[..4].copy_from_slice(&MAGIC);
        b[4..6].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
        b[6..8].copy_from_slice(&4u16.to_le_bytes());
        b[8..12].copy_from_slice(&[4, 0xFF, 0xFF, 0xFF]);
        let crc = crc32(&b[8..12]);
        b[12..16].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(decode_blob(&b), Err(BlobError::BadPayload));
        // A well-formed payload of an unstable model.
        let mut bad = full_model();
        bad.a[7] = 1.5;
        let mut pb = [0u8; MAX_PAYLOAD_LEN];
        let p = postcard::to_slice(&bad, &mut pb).unwrap();
        let plen = p.len();
        let mut b = [0u8; MAX_BLOB_LEN];
        b[..4].copy_from_slice(&MAGIC);
        b[4..6].copy_from_slice(&MODEL_ONLY_VERSION.to_le_bytes());
        b[6..8].copy_from_slice(&(plen as u16).to_le_bytes());
        b[8..8 + plen].copy_from_slice(&pb[..plen]);
        let crc = crc32(&pb[..plen]);
        b[8 + plen..12 + plen].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(
            decode_blob(&b[..12 + plen]),
            Err(BlobError::InvalidModel(ModelError::UnstableModel))
        );
        // encode refuses invalid models and small buffers
        assert_eq!(
            encode_blob(&bad, &mut [0u8; MAX_BLOB_LEN]),
            Err(BlobError::InvalidModel(ModelError::UnstableModel))
        );
        assert_eq!(
            encode_blob(&m, &mut [0u8; 100]),
            Err(BlobError::BufferTooSmall)
        );
    }
}
