//! yawcast-fw: the on-board app for STM32F405 (and QEMU `netduinoplus2`).
//!
//! Talks COBS-framed postcard messages (`yawcast_shared::wire`) on USART1 (PA9 TX, PA10 RX,
//! 115 200 baud from the 16 MHz internal oscillator), logs with defmt over semihosting.
//! At boot it sends a `Banner`, loads the model linked into flash if one was built in
//! (`YAWCAST_BUILTIN_MODEL`), then serves requests forever: `LoadModel`, `Measurement`,
//! `PredictRequest`, `Reset`, `Ping`; every failure is answered with an `Error` frame.
//! This build runs models of order 4.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod app {
    use cortex_m as _; // critical-section implementation (single core)
    use cortex_m_rt::entry;
    use defmt_semihosting as _;
    use yawcast_firmware::{Predictor, PredictorError, UpdateStatus, MAX_HORIZON};
    use yawcast_shared::blob::{self, FORMAT_VERSION};
    use yawcast_shared::wire::{
        AckStatus, DeviceMessage, ErrorCode, Feed, FrameAccumulator, HostMessage, Values,
        MAX_FRAME_LEN, PROTOCOL_VERSION,
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

    /// The app's state: the predictor (once a model is loaded) and the sample counter.
    struct App {
        predictor: Option<Predictor<ORDER>>,
        sample: u32,
    }

    impl App {
        // Called from two places (the built-in model at start-up, a LoadModel frame): inlined,
        // blob decoding and model validation would be laid down twice (≈ 5 KiB of flash).
        #[inline(never)]
        fn load(&mut self, bytes: &[u8]) -> DeviceMessage {
            let spec = match blob::decode_blob(bytes) {
                Ok(spec) => spec,
                Err(e) => {
                    defmt::warn!(
                        "model blob refused: error code {=u8}",
                        ErrorCode::from(e).code()
                    );
                    return DeviceMessage::Error { code: e.into() };
                }
            };
            match Predictor::<ORDER>::new(&spec) {
                Ok(p) => {
                    self.predictor = Some(p);
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
                HostMessage::Measurement { u, y, psi } => match self.predictor.as_mut() {
                    None => DeviceMessage::Error {
                        code: ErrorCode::NoModel,
                    },
                    Some(p) => {
                        let status = match p.update_with_heading(u, y, psi) {
                            UpdateStatus::Corrected => AckStatus::Corrected,
                            UpdateStatus::SkippedCorrection => AckStatus::SkippedCorrection,
                            _ => {
                                defmt::warn!("state went non-finite; reset");
                                AckStatus::NonFiniteReset
                            }
                        };
                        self.sample = self.sample.wrapping_add(1);
                        DeviceMessage::Ack {
                            sample: self.sample,
                            status,
                        }
                    }
                },
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
                                    code: match e {
                                        PredictorError::HorizonOutOfRange(_) => {
                                            ErrorCode::HorizonOutOfRange
                                        }
                                        PredictorError::NotEnoughInputs { .. } => {
                                            ErrorCode::NotEnoughInputs
                                        }
                                        _ => ErrorCode::NonFinite,
                                    },
                                },
                            }
                        }
                    }
                }
                HostMessage::Reset => {
                    if let Some(p) = self.predictor.as_mut() {
                        p.reset();
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
