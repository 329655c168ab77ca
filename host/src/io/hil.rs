//! Hardware in the loop: the firmware predicts while the host feeds it measurements.
//!
//! The firmware runs either in QEMU (`-machine netduinoplus2`, USART1 on a local TCP port)
//! or on a real STM32F405 board behind a serial device. Each sample goes to it as a
//! `Measurement`; a `PredictRequest` brings back ŷ(t+1|t) … ŷ(t+H|t). The host runs the same
//! model through the firmware library natively ([`NativePredictor`]) and compares every
//! predicted value bit for bit.
//!
//! ```
//! use yawcast::io::hil::NativePredictor;
//! use yawcast_shared::model::{ModelSpec, Units};
//! let m = ModelSpec::new(2, 1.0, &[-0.75, -1.5], &[0.5, -0.25], &[0.5, -0.375],
//!                        Units::default(), &[]).unwrap();
//! let mut p = NativePredictor::new(&m).unwrap();
//! p.update(1.0, 2.0, None);
//! let mut out = [0.0f32; 3];
//! p.predict(&mut out, &[2.0, 0.0]).unwrap();
//! assert_eq!(out, [1.5, 1.5, 0.375]);
//! ```

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use thiserror::Error;
use yawcast_firmware::{Predictor, PredictorError};
use yawcast_shared::blob::{encode_blob, MAX_BLOB_LEN};
use yawcast_shared::model::{ModelError, ModelSpec, MAX_DEAD_TIME};
use yawcast_shared::wire::{
    DeviceMessage, Feed, FrameAccumulator, FutureInputs, HostMessage, MAX_FRAME_LEN,
};

use crate::io::data::Record;

/// The thumb target of the firmware.
pub const THUMB_TARGET: &str = "thumbv7em-none-eabihf";

/// Environment variable naming a prebuilt firmware ELF.
pub const ELF_VAR: &str = "YAWCAST_FW_ELF";

/// How to build the firmware ELF.
pub const BUILD_HINT: &str = "build it with `rustup target add thumbv7em-none-eabihf && \
     cargo fw-build` (or point YAWCAST_FW_ELF at an ELF)";

/// Errors of the hardware-in-the-loop link.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum HilError {
    /// QEMU is not installed.
    #[error("qemu-system-arm is not installed (apt-get install -y --no-install-recommends qemu-system-arm)")]
    NoQemu,
    /// No firmware ELF was found.
    #[error("no firmware ELF found (looked in {looked}); {BUILD_HINT}")]
    NoElf {
        /// Places looked at.
        looked: String,
    },
    /// Starting or talking to the device failed.
    #[error("{0}")]
    Link(String),
    /// The device answered something unexpected.
    #[error("device: expected {expected}, got {got}")]
    Protocol {
        /// What we waited for.
        expected: &'static str,
        /// What came.
        got: String,
    },
    /// The model cannot run on the firmware.
    #[error("the firmware cannot run this model: {0}")]
    Model(String),
    /// The firmware library refused a step.
    #[error("firmware predictor: {0}")]
    Predictor(#[from] PredictorError),
}

/// The firmware predictor run natively, for any order 2..=8.
#[derive(Debug, Clone)]
pub enum NativePredictor {
    /// Order 2.
    N2(Predictor<2>),
    /// Order 3.
    N3(Predictor<3>),
    /// Order 4.
    N4(Predictor<4>),
    /// Order 5.
    N5(Predictor<5>),
    /// Order 6.
    N6(Predictor<6>),
    /// Order 7.
    N7(Predictor<7>),
    /// Order 8.
    N8(Predictor<8>),
}

macro_rules! each {
    ($s:expr, $p:ident => $e:expr) => {
        match $s {
            NativePredictor::N2($p) => $e,
            NativePredictor::N3($p) => $e,
            NativePredictor::N4($p) => $e,
            NativePredictor::N5($p) => $e,
            NativePredictor::N6($p) => $e,
            NativePredictor::N7($p) => $e,
            NativePredictor::N8($p) => $e,
        }
    };
}

impl NativePredictor {
    /// A predictor in the zero state for `spec`: the one dispatch from a model's order to the
    /// firmware's const-generic `Predictor<N>` (export's check and `hil` both go through it).
    ///
    /// # Errors
    /// [`PredictorError::InvalidModel`] with [`ModelError::Order`] for an order outside 2..=8, or the
    /// firmware library's own refusal of the model.
    pub fn new(spec: &ModelSpec) -> Result<NativePredictor, PredictorError> {
        Ok(match spec.order {
            2 => NativePredictor::N2(Predictor::new(spec)?),
            3 => NativePredictor::N3(Predictor::new(spec)?),
            4 => NativePredictor::N4(Predictor::new(spec)?),
            5 => NativePredictor::N5(Predictor::new(spec)?),
            6 => NativePredictor::N6(Predictor::new(spec)?),
            7 => NativePredictor::N7(Predictor::new(spec)?),
            8 => NativePredictor::N8(Predictor::new(spec)?),
            n => return Err(ModelError::Order(n).into()),
        })
    }

    /// Starts from the state `x0` (the model's difference coordinates, one value per state)
    /// and integrated heading `psi0` (deg), with an empty delay line and the actuator at 0.
    ///
    /// # Errors
    /// [`PredictorError::InvalidState`] when a value is not finite.
    pub fn start_from(&mut self, x0: &[f64], psi0: f64) -> Result<(), PredictorError> {
        each!(self, p => {
            let mut st = p.state();
            st.x.fill(0.0);
            for (xi, v) in st.x.iter_mut().zip(x0) {
                *xi = *v as f32;
            }
            st.delay = [0.0; MAX_DEAD_TIME as usize];
            st.delay_head = 0;
            st.u_prev = 0.0;
            st.psi = psi0 as f32;
            p.restore(st)
        })
    }

    /// One measurement update (`y` NaN when missing).
    pub fn update(&mut self, u: f32, y: f32, psi: Option<f32>) {
        each!(self, p => { p.update_with_heading(u, y, psi); })
    }

    /// ŷ(t+1|t) … ŷ(t+H|t) into `out` (H = `out.len()`), `future_u` = u(t+1) … u(t+H−1).
    ///
    /// # Errors
    /// [`PredictorError`] for a bad horizon, too few inputs or a non-finite prediction.
    pub fn predict(&self, out: &mut [f32], future_u: &[f32]) -> Result<(), PredictorError> {
        each!(self, p => p.predict_into(out, future_u))
    }
}

/// The future commands u(t+1) … u(t+H−1) of a record (the last command repeated past the end).
pub fn future_inputs(u: &[f32], t: usize, h: usize) -> Vec<f32> {
    let last = u.last().copied().unwrap_or(0.0);
    (1..h)
        .map(|j| u.get(t + j).copied().unwrap_or(last))
        .collect()
}

/// The record's channels as the firmware sees them (f32).
#[derive(Debug, Clone)]
pub struct F32Record {
    /// Commands.
    pub u: Vec<f32>,
    /// Measured yaw rate.
    pub y: Vec<f32>,
    /// Measured heading, when logged.
    pub psi: Option<Vec<f32>>,
}

impl F32Record {
    /// Converts a record.
    pub fn new(rec: &Record) -> F32Record {
        let f = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<_>>();
        F32Record {
            u: f(&rec.u),
            y: f(&rec.y),
            psi: rec.psi.as_deref().map(f),
        }
    }
    fn psi(&self, t: usize) -> Option<f32> {
        self.psi.as_ref().map(|p| p[t])
    }
}

/// Runs the firmware library natively over a record: after each update, the H-step
/// prediction. Returns `H` values per sample.
///
/// # Errors
/// [`HilError`] when the model is refused or a prediction fails.
pub fn native_run(spec: &ModelSpec, rec: &F32Record, h: usize) -> Result<Vec<Vec<f32>>, HilError> {
    let mut p = NativePredictor::new(spec)?;
    let mut out = Vec::with_capacity(rec.u.len());
    for t in 0..rec.u.len() {
        p.update(rec.u[t], rec.y[t], rec.psi(t));
        let mut yhat = vec![0.0f32; h];
        p.predict(&mut yhat, &future_inputs(&rec.u, t, h))?;
        out.push(yhat);
    }
    Ok(out)
}

/// Where the firmware ELF may be: `$YAWCAST_FW_ELF`, then the usual build directories.
pub fn elf_candidates(workspace: &Path) -> Vec<PathBuf> {
    elf_candidates_with(std::env::var_os(ELF_VAR).as_deref(), workspace)
}

/// [`elf_candidates`] with the value of [`ELF_VAR`] given (`None`: not set).
///
/// ```
/// use std::{ffi::OsStr, path::Path};
/// let c = yawcast::io::hil::elf_candidates_with(Some(OsStr::new("/fw.elf")), Path::new("/ws"));
/// assert_eq!(c[0], Path::new("/fw.elf"));
/// assert_eq!(c[1], Path::new("/ws/target/thumbv7em-none-eabihf/release/yawcast-fw"));
/// ```
pub fn elf_candidates_with(var: Option<&std::ffi::OsStr>, workspace: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    if let Some(p) = var {
        v.push(PathBuf::from(p));
    }
    for sub in ["target", "target/thumb"] {
        v.push(
            workspace
                .join(sub)
                .join(THUMB_TARGET)
                .join("release")
                .join("yawcast-fw"),
        );
    }
    v
}

/// The first firmware ELF that exists.
///
/// # Errors
/// [`HilError::NoElf`] naming the places looked at.
pub fn find_elf(workspace: &Path) -> Result<PathBuf, HilError> {
    first_elf(&elf_candidates(workspace))
}

/// The first of `c` that is a file, or [`HilError::NoElf`] naming them all.
fn first_elf(c: &[PathBuf]) -> Result<PathBuf, HilError> {
    c.iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or_else(|| HilError::NoElf {
            looked: c
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// Whether `qemu-system-arm` can be run.
pub fn qemu_available() -> bool {
    Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

trait Port: Read + Write + Send + std::fmt::Debug {}
impl<T: Read + Write + Send + std::fmt::Debug> Port for T {}

/// A firmware on the other end of a UART: QEMU or a board.
#[derive(Debug)]
pub struct Device {
    port: Box<dyn Port>,
    child: Option<Child>,
    acc: FrameAccumulator,
    rx: Vec<u8>,
    rx_pos: usize,
    tx: Vec<u8>,
    /// The model order the firmware runs (from its banner; 0 when unknown).
    pub order: u8,
    /// Where QEMU's own output (defmt log) goes, when running under QEMU: a file in the
    /// temporary directory, removed when the device is dropped (kept if the thread panics).
    pub log: Option<PathBuf>,
    /// Samples sent ahead before reading answers (QEMU applies flow control on its socket,
    /// so it can take many; a board's UART is read one sample at a time).
    pub window: usize,
    /// The banner the firmware sent as it booted (under QEMU); `None` on a serial link to
    /// a firmware that was already running.
    pub banner: Option<DeviceMessage>,
    /// The other end closed or reset the link.
    dropped: bool,
    /// A byte has arrived.
    heard: bool,
}

/// Boots [`Device::qemu`] tries in all when QEMU closes or resets the UART before a byte.
pub const QEMU_BOOTS: usize = 3;

impl Device {
    /// Boots `elf` in QEMU and waits for the banner. A boot whose UART the other end closes
    /// or resets before a byte arrives is tried again, on a fresh port, up to [`QEMU_BOOTS`]
    /// times in all (a test run saw QEMU reset its socket once, with nothing in its log).
    ///
    /// # Errors
    /// [`HilError::NoQemu`], or [`HilError::Link`] when QEMU does not come up.
    pub fn qemu(elf: &Path) -> Result<Device, HilError> {
        if !qemu_available() {
            return Err(HilError::NoQemu);
        }
        let mut boots = 1;
        loop {
            match Device::qemu_once(elf) {
                Err((_, true)) if boots < QEMU_BOOTS => boots += 1,
                Err((HilError::Link(m), true)) => {
                    return Err(HilError::Link(format!(
                        "{m} (QEMU closed or reset its UART before a byte came, in each of \
                         {boots} boots)"
                    )))
                }
                r => return r.map_err(|(e, _)| e),
            }
        }
    }

    /// One boot of [`Device::qemu`]; on failure the error, and whether the UART was closed
    /// or reset before a byte arrived.
    fn qemu_once(elf: &Path) -> Result<Device, (HilError, bool)> {
        let link = |e: String| (HilError::Link(e), false);
        let port = TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map_err(|e| link(format!("no free local port: {e}")))?
            .port();
        let log = std::env::temp_dir().join(format!("yawcast-hil-qemu-{port}.log"));
        let logf = std::fs::File::create(&log).map_err(|e| link(e.to_string()))?;
        let logf2 = logf.try_clone().map_err(|e| link(e.to_string()))?;
        let child = Command::new("qemu-system-arm")
            .args([
                "-machine",
                "netduinoplus2",
                "-nographic",
                "-monitor",
                "none",
            ])
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-serial")
            .arg(format!("tcp:127.0.0.1:{port},server=on,wait=on"))
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::null())
            .stdout(logf)
            .stderr(logf2)
            .spawn()
            .map_err(|e| link(format!("starting qemu-system-arm: {e}")))?;
        let mut child = Some(child);
        let start = Instant::now();
        let stream = loop {
            match TcpStream::connect(("127.0.0.1", port)) {
                Ok(s) => break s,
                Err(e) if start.elapsed() > Duration::from_secs(20) => {
                    if let Some(mut c) = child.take() {
                        let _ = c.kill();
                        let _ = c.wait();
                    }
                    return Err(link(format!(
                        "QEMU did not open its UART on port {port}: {e} (QEMU's output: {})",
                        log.display()
                    )));
                }
                Err(_) => std::thread::sleep(Duration::from_millis(20)),
            }
        };
        stream
            .set_read_timeout(Some(Duration::from_secs(30)))
            .map_err(|e| link(e.to_string()))?;
        stream.set_nodelay(true).map_err(|e| link(e.to_string()))?;
        let mut d = Device::over(Box::new(stream));
        d.child = child;
        d.log = Some(log);
        d.window = 32;
        if let Err(e) = d.expect_banner() {
            let dropped = d.dropped && !d.heard;
            let e = match e {
                // QEMU's own output says why the firmware did not start: kept, and named
                // (unless the boot is tried again: the log, which QEMU left empty, goes with
                // the device)
                HilError::Link(m) if !dropped => match d.log.take() {
                    Some(l) => HilError::Link(format!("{m} (QEMU's output: {})", l.display())),
                    None => HilError::Link(m),
                },
                e => e,
            };
            return Err((e, dropped));
        }
        Ok(d)
    }

    /// Opens a serial device (already configured: `stty -F DEV 115200 raw -echo`), pings
    /// the firmware and reads its order from a fresh banner if one arrives.
    ///
    /// # Errors
    /// [`HilError::Link`] when the device cannot be opened or does not answer.
    pub fn serial(path: &Path) -> Result<Device, HilError> {
        let f = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| HilError::Link(format!("{}: {e}", path.display())))?;
        let mut d = Device::over(Box::new(f));
        // Resynchronise with an empty frame, then ping.
        d.tx.push(0);
        d.send(&HostMessage::Ping)?;
        loop {
            match d.recv()? {
                DeviceMessage::Pong => break,
                b @ DeviceMessage::Banner { order, .. } => {
                    d.order = order;
                    d.banner = Some(b);
                }
                other => {
                    return Err(HilError::Protocol {
                        expected: "Pong",
                        got: format!("{other:?}"),
                    })
                }
            }
        }
        Ok(d)
    }

    fn over(port: Box<dyn Port>) -> Device {
        Device {
            port,
            child: None,
            acc: FrameAccumulator::new(),
            rx: Vec::new(),
            rx_pos: 0,
            tx: Vec::new(),
            order: 0,
            log: None,
            window: 1,
            banner: None,
            dropped: false,
            heard: false,
        }
    }

    fn expect_banner(&mut self) -> Result<(), HilError> {
        match self.recv()? {
            b @ DeviceMessage::Banner { order, .. } => {
                self.order = order;
                self.banner = Some(b);
                Ok(())
            }
            other => Err(HilError::Protocol {
                expected: "Banner",
                got: format!("{other:?}"),
            }),
        }
    }

    /// Queues a message.
    ///
    /// # Errors
    /// [`HilError::Link`] when the message does not fit a frame.
    pub fn send(&mut self, msg: &HostMessage<'_>) -> Result<(), HilError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let frame = msg
            .encode(&mut buf)
            .map_err(|e| HilError::Link(format!("encoding a message: {e}")))?;
        self.tx.extend_from_slice(frame);
        Ok(())
    }

    /// Queues raw bytes, framed or not (the firmware's tests send it malformed frames so).
    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }

    /// Writes everything queued.
    ///
    /// # Errors
    /// [`HilError::Link`] when the write fails.
    pub fn flush(&mut self) -> Result<(), HilError> {
        if !self.tx.is_empty() {
            self.port
                .write_all(&self.tx)
                .and_then(|()| self.port.flush())
                .map_err(|e| HilError::Link(format!("UART write: {e}")))?;
            self.tx.clear();
        }
        Ok(())
    }

    /// Flushes what is queued and receives the next message.
    ///
    /// # Errors
    /// [`HilError::Link`] on a closed link, a timeout or a bad frame.
    pub fn recv(&mut self) -> Result<DeviceMessage, HilError> {
        let link = |e: String| HilError::Link(e);
        self.flush()?;
        loop {
            while self.rx_pos < self.rx.len() {
                let b = self.rx[self.rx_pos];
                self.rx_pos += 1;
                match self.acc.push(b) {
                    Feed::Pending => {}
                    Feed::Frame(f) => {
                        return DeviceMessage::decode(f)
                            .map_err(|e| link(format!("device sent a bad message: {e}")));
                    }
                    Feed::Error(e) => return Err(link(format!("device sent a bad frame: {e}"))),
                }
            }
            self.rx.resize(4096, 0);
            self.rx_pos = 0;
            match self.port.read(&mut self.rx) {
                Ok(0) => {
                    self.dropped = true;
                    return Err(link("UART closed".into()));
                }
                Ok(n) => {
                    self.heard = true;
                    self.rx.truncate(n);
                }
                Err(e) => {
                    use std::io::ErrorKind::{BrokenPipe, ConnectionAborted, ConnectionReset};
                    self.dropped =
                        matches!(e.kind(), ConnectionReset | ConnectionAborted | BrokenPipe);
                    return Err(link(format!("UART read: {e}")));
                }
            }
        }
    }

    /// Loads a model (as a blob); returns the CRC the device reports.
    ///
    /// # Errors
    /// [`HilError::Model`] when the device refuses it.
    pub fn load(&mut self, spec: &ModelSpec) -> Result<u32, HilError> {
        if self.order != 0 && self.order != spec.order {
            return Err(HilError::Model(format!(
                "this firmware build runs models of order {}, the model has order {}",
                self.order, spec.order
            )));
        }
        let mut buf = [0u8; MAX_BLOB_LEN];
        let blob = encode_blob(spec, &mut buf).map_err(|e| HilError::Model(e.to_string()))?;
        self.send(&HostMessage::LoadModel(blob))?;
        match self.recv()? {
            DeviceMessage::ModelLoaded { crc, .. } => Ok(crc),
            DeviceMessage::Error { code } => Err(HilError::Model(format!(
                "the device refused the model (error {code:?})"
            ))),
            other => Err(HilError::Protocol {
                expected: "ModelLoaded",
                got: format!("{other:?}"),
            }),
        }
    }

    /// One measurement and the H-step prediction after it.
    ///
    /// # Errors
    /// [`HilError`] when the device answers with an error or not at all.
    pub fn step(
        &mut self,
        u: f32,
        y: f32,
        psi: Option<f32>,
        future_u: &[f32],
        h: usize,
    ) -> Result<Vec<f32>, HilError> {
        self.queue_step(u, y, psi, future_u, h)?;
        self.answer()
    }

    fn queue_step(
        &mut self,
        u: f32,
        y: f32,
        psi: Option<f32>,
        future_u: &[f32],
        h: usize,
    ) -> Result<(), HilError> {
        let fu: FutureInputs = future_u.iter().copied().take(h.saturating_sub(1)).collect();
        self.send(&HostMessage::Measurement { u, y, psi })?;
        self.send(&HostMessage::PredictRequest {
            horizon: h as u8,
            future_u: fu,
        })
    }

    fn answer(&mut self) -> Result<Vec<f32>, HilError> {
        match self.recv()? {
            DeviceMessage::Ack { .. } => {}
            other => {
                return Err(HilError::Protocol {
                    expected: "Ack",
                    got: format!("{other:?}"),
                })
            }
        }
        match self.recv()? {
            DeviceMessage::Prediction { values, .. } => Ok(values.to_vec()),
            other => Err(HilError::Protocol {
                expected: "Prediction",
                got: format!("{other:?}"),
            }),
        }
    }

    /// Runs a whole record through the device (after loading `spec`).
    ///
    /// # Errors
    /// As [`Device::step`].
    pub fn run(
        &mut self,
        spec: &ModelSpec,
        rec: &F32Record,
        h: usize,
    ) -> Result<Vec<Vec<f32>>, HilError> {
        self.load(spec)?;
        self.steps(rec, 0..rec.u.len(), h)
    }

    /// Runs samples `range` of a record through the device (model already loaded),
    /// [`Device::window`] samples in flight at a time.
    ///
    /// # Errors
    /// As [`Device::step`].
    pub fn steps(
        &mut self,
        rec: &F32Record,
        range: std::ops::Range<usize>,
        h: usize,
    ) -> Result<Vec<Vec<f32>>, HilError> {
        let mut out = Vec::with_capacity(range.len());
        let w = self.window.max(1);
        let mut t = range.start;
        while t < range.end {
            let end = (t + w).min(range.end);
            for s in t..end {
                self.queue_step(
                    rec.u[s],
                    rec.y[s],
                    rec.psi(s),
                    &future_inputs(&rec.u, s, h),
                    h,
                )?;
            }
            for _ in t..end {
                out.push(self.answer()?);
            }
            t = end;
        }
        Ok(out)
    }

    /// Ends a QEMU run with `Shutdown { code }` and waits (20 s at most) for QEMU to exit;
    /// returns QEMU's exit code, which the firmware sets to `code` through semihosting.
    ///
    /// # Errors
    /// [`HilError::Link`] on a serial link (a board has no semihosting exit), when the
    /// message cannot be written, or when QEMU does not exit in time.
    pub fn shutdown(mut self, code: u8) -> Result<i32, HilError> {
        if self.child.is_none() {
            return Err(HilError::Link(
                "Shutdown ends a QEMU run; a board on a serial link has no exit".into(),
            ));
        }
        self.send(&HostMessage::Shutdown { code })?;
        self.flush()?;
        let start = Instant::now();
        while let Some(c) = self.child.as_mut() {
            if let Some(st) = c
                .try_wait()
                .map_err(|e| HilError::Link(format!("waiting for QEMU: {e}")))?
            {
                self.child = None;
                return Ok(st.code().unwrap_or(-1));
            }
            if start.elapsed() > Duration::from_secs(20) {
                return Err(HilError::Link("QEMU did not exit after Shutdown".into()));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        Err(HilError::Link("QEMU is not running".into()))
    }

    /// Ends a QEMU run (`Shutdown`), or just closes a serial link.
    pub fn close(self) {
        if self.child.is_some() {
            let _ = self.shutdown(0);
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            if let Ok(None) = c.try_wait() {
                let _ = c.kill();
            }
            let _ = c.wait();
        }
        if let Some(log) = self.log.take().filter(|_| !std::thread::panicking()) {
            let _ = std::fs::remove_file(log);
        }
    }
}

/// Bit-for-bit comparison of two prediction runs: (values compared, values equal, first
/// differing (sample, step)).
pub fn compare_bits(a: &[Vec<f32>], b: &[Vec<f32>]) -> (usize, usize, Option<(usize, usize)>) {
    let mut total = 0;
    let mut equal = 0;
    let mut first = None;
    for (t, (x, y)) in a.iter().zip(b).enumerate() {
        for (k, (p, q)) in x.iter().zip(y).enumerate() {
            total += 1;
            if p.to_bits() == q.to_bits() {
                equal += 1;
            } else if first.is_none() {
                first = Some((t, k));
            }
        }
        if x.len() != y.len() && first.is_none() {
            first = Some((t, x.len().min(y.len())));
        }
    }
    if a.len() != b.len() && first.is_none() {
        first = Some((a.len().min(b.len()), 0));
    }
    (total, equal, first)
}

/// Running fit % of the k-step predictions made so far: for each k in `ks`, ŷ(t|t−k) from
/// the predictions issued at t−k against the measured y(t).
#[derive(Debug, Clone)]
pub struct LiveFit {
    ks: Vec<usize>,
    y: Vec<f64>,
    preds: Vec<Vec<f64>>,
}

impl LiveFit {
    /// Tracks the horizons `ks` (each ≥ 1).
    pub fn new(ks: &[usize]) -> LiveFit {
        LiveFit {
            ks: ks.to_vec(),
            y: Vec::new(),
            preds: Vec::new(),
        }
    }

    /// Adds the measurement y(t) and the prediction vector issued at t (ŷ(t+1|t) …).
    pub fn push(&mut self, y: f64, pred: &[f32]) {
        self.y.push(y);
        self.preds
            .push(pred.iter().map(|v| f64::from(*v)).collect());
    }

    /// Fit % per tracked horizon over the samples so far (NaN until there are enough).
    ///
    /// ```
    /// use yawcast::io::hil::LiveFit;
    /// let mut f = LiveFit::new(&[1]);
    /// for t in 0..10 {
    ///     let y = t as f64;
    ///     f.push(y, &[(t + 1) as f32]); // perfect one-step predictions
    /// }
    /// assert_eq!(f.fits(), vec![(1, 100.0)]);
    /// ```
    pub fn fits(&self) -> Vec<(usize, f64)> {
        self.ks
            .iter()
            .map(|&k| {
                let mut y = Vec::new();
                let mut yh = Vec::new();
                for t in k..self.y.len() {
                    if let Some(v) = self.preds[t - k].get(k - 1) {
                        y.push(self.y[t]);
                        yh.push(*v);
                    }
                }
                let f = if y.len() < 3 {
                    f64::NAN
                } else {
                    crate::identify::predict::fit(&y, &yh)
                };
                (k, f)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests;
