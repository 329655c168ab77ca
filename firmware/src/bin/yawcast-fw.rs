//! yawcast-fw: the on-board app for STM32F405 (and QEMU `netduinoplus2`).
//!
//! Talks COBS-framed postcard messages (`yawcast_shared::wire`) on USART1 (PA9 TX, PA10 RX,
//! 115 200 baud from the 16 MHz internal oscillator), logs with defmt over semihosting.
//! At boot it sends a `Banner`, loads the model linked into flash if one was built in
//! (`YAWCAST_BUILTIN_MODEL`), then serves requests forever: `LoadModel`, `Measurement`,
//! `PredictRequest`, `TrackMeasurement`, `TrackPredictRequest`, `Reset`, `Ping`; every
//! failure is answered with an `Error` frame. A model with a track part (blob version 3)
//! also runs the heading/track predictor: every measurement updates it (a plain
//! `Measurement` without navigation channels).
//! This build runs models of order 4.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod app {
    use cortex_m as _; // critical-section implementation (single core)
    use cortex_m_rt::entry;
    use defmt_semihosting as _;
    use yawcast_firmware::track::{Correction, NavMeasurement, Tracker};
    use yawcast_firmware::{Predictor, PredictorError, UpdateStatus, MAX_HORIZON};
    use yawcast_shared::blob::{self, FORMAT_VERSION};
    use yawcast_shared::wire::{
        AckStatus, DeviceMessage, ErrorCode, Feed, FrameAccumulator, HostMessage, NavStatus,
        Values, MAX_FRAME_LEN, MAX_TRACK_HORIZON, PROTOCOL_VERSION,
    };

    /// Model order this build runs.
    const ORDER: usize = 4;

    /// A model blob linked into flash at build time (empty when none was given).
    static BUILTIN_MODEL: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/builtin_model.bin"));

    /// Polled USART1 driver, STM32F4 register layout.
    #[allow(unsafe_code)]
    mod usart {
        const RCC: usize = 0x4002_3800;
        const RCC_AHB1ENR: usize = RCC + 0x30;
        const RCC_APB2ENR: usize = RCC + 0x44;
        const GPIOA: usize = 0x4002_0000;
        const GPIOA_MODER: usize = GPIOA;
        const GPIOA_AFRH: usize = GPIOA + 0x24;
        const USART1: usize = 0x4001_1000;
        const SR: usize = USART1;
        const DR: usize = USART1 + 0x04;
        const BRR: usize = USART1 + 0x08;
        const CR1: usize = USART1 + 0x0C;
        const SR_RXNE: u32 = 1 << 5;
        const SR_TXE: u32 = 1 << 7;
        const SR_ORE: u32 = 1 << 3;
        const CR1_UE: u32 = 1 << 13;
        const CR1_TE: u32 = 1 << 3;
        const CR1_RE: u32 = 1 << 2;
        /// 16 MHz HSI / 115 200 baud = 138.9 → mantissa 8, fraction 11.
        const BRR_115200_AT_16MHZ: u32 = (8 << 4) | 11;

        fn read(addr: usize) -> u32 {
            // SAFETY: `addr` is one of the fixed, aligned peripheral registers above.
            unsafe { core::ptr::read_volatile(addr as *const u32) }
        }

        fn write(addr: usize, value: u32) {
            // SAFETY: as in `read`; these registers accept any 32-bit write.
            unsafe { core::ptr::write_volatile(addr as *mut u32, value) }
        }

        /// Clocks GPIOA and USART1, routes PA9/PA10 to AF7, enables TX and RX at 115 200 Bd.
        /// (QEMU has no RCC/GPIO model; the writes are ignored there.)
        pub fn init() {
            write(RCC_AHB1ENR, read(RCC_AHB1ENR) | 1);
            write(RCC_APB2ENR, read(RCC_APB2ENR) | (1 << 4));
            let moder = read(GPIOA_MODER) & !(0b1111 << 18);
            write(GPIOA_MODER, moder | (0b10 << 18) | (0b10 << 20));
            let afrh = read(GPIOA_AFRH) & !(0xFF << 4);
            write(GPIOA_AFRH, afrh | (7 << 4) | (7 << 8));
            write(BRR, BRR_115200_AT_16MHZ);
            write(CR1, CR1_UE | CR1_TE | CR1_RE);
        }

        /// Blocks until a byte arrives.
        pub fn read_byte() -> u8 {
            loop {
                let sr = read(SR);
                if sr & (SR_RXNE | SR_ORE) != 0 {
                    // reading DR clears RXNE (and ORE after the SR read)
                    return (read(DR) & 0xFF) as u8;
                }
            }
        }

        /// Sends `bytes`, waiting for room before each one.
        pub fn write_all(bytes: &[u8]) {
            for &b in bytes {
                while read(SR) & SR_TXE == 0 {}
                write(DR, u32::from(b));
            }
        }
    }

    /// The app's state: the predictor (once a model is loaded), the heading/track predictor
    /// (when the model has a track part) and the sample counter.
    struct App {
        predictor: Option<Predictor<ORDER>>,
        tracker: Option<Tracker>,
        sample: u32,
    }

    fn nav_status(c: Correction) -> NavStatus {
        match c {
            Correction::Absent => NavStatus::Absent,
            Correction::Applied => NavStatus::Applied,
            Correction::Rejected => NavStatus::Rejected,
            Correction::Gated => NavStatus::Gated,
        }
    }

    fn predictor_error(e: PredictorError) -> ErrorCode {
        match e {
            PredictorError::HorizonOutOfRange(_) => ErrorCode::HorizonOutOfRange,
            PredictorError::NotEnoughInputs { .. } => ErrorCode::NotEnoughInputs,
            _ => ErrorCode::NonFinite,
        }
    }

    impl App {
        // Called from two places (the built-in model at start-up, a LoadModel frame): inlined,
        // blob decoding and model validation would be laid down twice (≈ 5 KiB of flash).
        #[inline(never)]
        fn load(&mut self, bytes: &[u8]) -> DeviceMessage {
            let (spec, track) = match blob::decode_blob_with_track(bytes) {
                Ok(decoded) => decoded,
                Err(e) => {
                    defmt::warn!(
                        "model blob refused: error code {=u8}",
                        ErrorCode::from(e).code()
                    );
                    return DeviceMessage::Error { code: e.into() };
                }
            };
            let tracker = match track.map(|t| Tracker::new(&spec, &t)) {
                None => None,
                Some(Ok(t)) => Some(t),
                Some(Err(_)) => {
                    return DeviceMessage::Error {
                        code: ErrorCode::TrackInvalid,
                    }
                }
            };
            match Predictor::<ORDER>::new(&spec) {
                Ok(p) => {
                    self.predictor = Some(p);
                    self.tracker = tracker;
                    self.sample = 0;
                    // a decoded blob ends with its 4-byte CRC
                    let crc = match bytes.len().checked_sub(4).and_then(|i| bytes.get(i..)) {
                        Some(&[b0, b1, b2, b3]) => u32::from_le_bytes([b0, b1, b2, b3]),
                        _ => 0,
                    };
                    let effects = spec.effects.len() as u8;
                    defmt::info!(
                        "model loaded: order {=u8}, {=u8} effects, crc {=u32:#010x}",
                        spec.order,
                        effects,
                        crc
                    );
                    DeviceMessage::ModelLoaded {
                        order: spec.order,
                        effects,
                        crc,
                    }
                }
                Err(PredictorError::OrderMismatch { found, .. }) => {
                    defmt::warn!(
                        "model of order {=u8} refused: this build runs order 4",
                        found
                    );
                    DeviceMessage::Error {
                        code: ErrorCode::UnsupportedOrder,
                    }
                }
                Err(_) => DeviceMessage::Error {
                    code: ErrorCode::ModelInvalid,
                },
            }
        }

        /// One measurement: the yaw-rate update, then (with a track part) the heading/track
        /// update with the rate the predictor used; `nav` is `Some` for a `TrackMeasurement`
        /// (answered with `TrackAck`, refused before any state moves when the model has no
        /// track part), `None` for a `Measurement` (answered with `Ack`).
        fn measured(
            &mut self,
            u: f32,
            y: f32,
            psi: Option<f32>,
            nav: Option<NavMeasurement>,
        ) -> DeviceMessage {
            let Some(p) = self.predictor.as_mut() else {
                return DeviceMessage::Error {
                    code: ErrorCode::NoModel,
                };
            };
            if nav.is_some() && self.tracker.is_none() {
                return DeviceMessage::Error {
                    code: ErrorCode::NoTrack,
                };
            }
            let before = p.prediction();
            let status = match p.update_with_heading(u, y, psi) {
                UpdateStatus::Corrected => AckStatus::Corrected,
                UpdateStatus::SkippedCorrection => AckStatus::SkippedCorrection,
                _ => {
                    defmt::warn!("state went non-finite; reset");
                    AckStatus::NonFiniteReset
                }
            };
            let rate = if y.is_finite() { y } else { before };
            let track = self
                .tracker
                .as_mut()
                .map(|t| t.update(rate, psi, &nav.unwrap_or_default()));
            self.sample = self.sample.wrapping_add(1);
            match (nav, track) {
                (Some(_), Some(t)) => DeviceMessage::TrackAck {
                    sample: self.sample,
                    status,
                    velocity: nav_status(t.velocity),
                    fix: nav_status(t.fix),
                    reset: t.reset,
                },
                _ => DeviceMessage::Ack {
                    sample: self.sample,
                    status,
                },
            }
        }

        fn handle(&mut self, frame: &[u8]) -> Option<DeviceMessage> {
            let msg = match HostMessage::decode(frame) {
                Ok(m) => m,
                Err(e) => {
                    defmt::warn!("undecodable frame of {=usize} bytes", frame.len());
                    return Some(DeviceMessage::Error { code: e.into() });
                }
            };
            let reply = match msg {
                HostMessage::Ping => DeviceMessage::Pong,
                HostMessage::LoadModel(bytes) => self.load(bytes),
                HostMessage::Measurement { u, y, psi } => self.measured(u, y, psi, None),
                HostMessage::TrackMeasurement {
                    u,
                    y,
                    psi,
                    velocity,
                    fix,
                } => self.measured(u, y, psi, Some(NavMeasurement { velocity, fix })),
                HostMessage::TrackPredictRequest { horizon, future_u } => {
                    match (self.predictor.as_ref(), self.tracker.as_ref()) {
                        (None, _) => DeviceMessage::Error {
                            code: ErrorCode::NoModel,
                        },
                        (Some(_), None) => DeviceMessage::Error {
                            code: ErrorCode::NoTrack,
                        },
                        (Some(p), Some(t)) => {
                            let h = usize::from(horizon);
                            let mut rates = [0.0f32; MAX_TRACK_HORIZON];
                            let mut rows = [[0.0f32; 3]; MAX_TRACK_HORIZON];
                            let result = match (rates.get_mut(..h), rows.get_mut(..h)) {
                                (Some(r), Some(o)) if h > 0 => p
                                    .predict_into(r, &future_u)
                                    .and_then(|()| t.predict_into(o, r)),
                                _ => Err(PredictorError::HorizonOutOfRange(h)),
                            };
                            match result {
                                Ok(()) => DeviceMessage::TrackPrediction {
                                    sample: self.sample,
                                    values: rows
                                        .as_flattened()
                                        .get(..3 * h)
                                        .and_then(|v| Values::from_slice(v).ok())
                                        .unwrap_or_default(),
                                },
                                Err(e) => DeviceMessage::Error {
                                    code: predictor_error(e),
                                },
                            }
                        }
                    }
                }
                HostMessage::PredictRequest { horizon, future_u } => {
                    match self.predictor.as_ref() {
                        None => DeviceMessage::Error {
                            code: ErrorCode::NoModel,
                        },
                        Some(p) => {
                            let h = usize::from(horizon);
                            let mut out = [0.0f32; MAX_HORIZON];
                            let result = match out.get_mut(..h) {
                                Some(o) => p.predict_into(o, &future_u),
                                None => Err(PredictorError::HorizonOutOfRange(h)),
                            };
                            match result {
                                Ok(()) => DeviceMessage::Prediction {
                                    sample: self.sample,
                                    values: Values::from_slice(&out[..h]).unwrap_or_default(),
                                },
                                Err(e) => DeviceMessage::Error {
                                    code: predictor_error(e),
                                },
                            }
                        }
                    }
                }
                HostMessage::Reset => {
                    if let Some(p) = self.predictor.as_mut() {
                        p.reset();
                    }
                    if let Some(t) = self.tracker.as_mut() {
                        t.reset();
                    }
                    self.sample = 0;
                    DeviceMessage::Ack {
                        sample: 0,
                        status: AckStatus::Cleared,
                    }
                }
                HostMessage::Shutdown { code } => {
                    defmt::info!("shutdown requested, exit code {=u8}", code);
                    semihosting::process::exit(i32::from(code))
                }
            };
            Some(reply)
        }
    }

    fn send(msg: &DeviceMessage, tx: &mut [u8; MAX_FRAME_LEN]) {
        match msg.encode(tx) {
            Ok(frame) => usart::write_all(frame),
            Err(_) => defmt::error!("reply does not fit a frame"),
        }
    }

    #[entry]
    fn main() -> ! {
        usart::init();
        defmt::info!("yawcast-fw {=str} up", env!("CARGO_PKG_VERSION"));
        let mut app = App {
            predictor: None,
            tracker: None,
            sample: 0,
        };
        let mut tx = [0u8; MAX_FRAME_LEN];
        if !BUILTIN_MODEL.is_empty() {
            let reply = app.load(BUILTIN_MODEL);
            if let DeviceMessage::Error { .. } = reply {
                defmt::error!("the built-in model was refused");
            }
        }
        send(
            &DeviceMessage::Banner {
                protocol: PROTOCOL_VERSION,
                blob_version: FORMAT_VERSION,
                order: ORDER as u8,
                model_loaded: app.predictor.is_some(),
            },
            &mut tx,
        );
        let mut acc = FrameAccumulator::new();
        loop {
            let byte = usart::read_byte();
            let reply = match acc.push(byte) {
                Feed::Pending => None,
                Feed::Frame(frame) => app.handle(frame),
                Feed::Error(e) => {
                    defmt::warn!("bad frame");
                    Some(DeviceMessage::Error { code: e.into() })
                }
            };
            if let Some(r) = reply {
                send(&r, &mut tx);
            }
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        defmt::error!("panic");
        semihosting::process::exit(101)
    }
}

/// Host builds of the workspace compile this stub; the app itself needs the thumb target.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "yawcast-fw runs on thumbv7em-none-eabihf: `cargo fw-build`, then `cargo fw-run` (QEMU)"
    );
    std::process::exit(2);
}
