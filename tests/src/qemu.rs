//! Boots the firmware in QEMU (`netduinoplus2`, a Cortex-M4F STM32F405) and talks to it over
//! USART1, which QEMU exposes as a TCP server on 127.0.0.1.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use yawcast_shared::wire::{DeviceMessage, Feed, FrameAccumulator, HostMessage, MAX_FRAME_LEN};

/// The thumb target the firmware is built for.
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// Environment variable naming a prebuilt firmware ELF (set by `.ci/run`).
pub const ELF_VAR: &str = "YAWCAST_FW_ELF";

const INSTALL_QEMU: &str = "qemu-system-arm is needed for the firmware-in-QEMU tests. Install it \
     with `sudo apt-get install -y --no-install-recommends qemu-system-arm` (Debian/Ubuntu; \
     `brew install qemu` on macOS), or run `bash .ci/run`, which installs what is missing.";

const INSTALL_TARGET: &str = "the Cortex-M4F target is needed to build the firmware. Install it \
     with `rustup target add thumbv7em-none-eabihf`, or run `bash .ci/run`.";

/// Checks that QEMU can be run.
///
/// # Errors
/// A message saying how to install it.
pub fn check_qemu() -> Result<(), String> {
    match Command::new("qemu-system-arm").arg("--version").output() {
        Ok(o) if o.status.success() => Ok(()),
        _ => Err(INSTALL_QEMU.to_string()),
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// The firmware ELF: `$YAWCAST_FW_ELF` when set, else built here (release, thumb target)
/// into `target/thumb` so the outer cargo's lock on `target/` is not needed.
///
/// # Errors
/// When the build fails, with how to install the target.
pub fn firmware_elf() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os(ELF_VAR) {
        let p = PathBuf::from(p);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(format!("{ELF_VAR}={} is not a file", p.display()))
        };
    }
    let root = workspace_root();
    let target_dir = root.join("target").join("thumb");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(&root)
        .args([
            "build",
            "-p",
            "yawcast-firmware",
            "--bin",
            "yawcast-fw",
            "--release",
            "--target",
            TARGET,
        ])
        .env("CARGO_TARGET_DIR", &target_dir)
        .output()
        .map_err(|e| format!("running cargo: {e}"))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let hint = if stderr.contains("target may not be installed")
            || stderr.contains("can't find crate for `core`")
        {
            INSTALL_TARGET
        } else {
            "building the firmware failed"
        };
        return Err(format!("{hint}\n{stderr}"));
    }
    Ok(target_dir.join(TARGET).join("release").join("yawcast-fw"))
}

/// A running firmware in QEMU and its UART connection.
#[derive(Debug)]
pub struct Qemu {
    child: Child,
    stream: TcpStream,
    acc: FrameAccumulator,
    tx: Vec<u8>,
    rx: Vec<u8>,
    rx_pos: usize,
    /// What the log file of this run is called (QEMU's stdout/stderr: defmt frames). It is
    /// removed when the run is dropped, and kept when a test panics, for a look.
    pub log: PathBuf,
}

impl Qemu {
    /// Boots `elf` and waits for its banner.
    ///
    /// # Errors
    /// When QEMU is missing, does not start, or no banner arrives.
    pub fn boot(elf: &Path) -> Result<(Qemu, DeviceMessage), String> {
        check_qemu()?;
        let port = TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map_err(|e| format!("no free port: {e}"))?
            .port();
        let log = std::env::temp_dir().join(format!("yawcast-qemu-{port}.log"));
        let logf = std::fs::File::create(&log).map_err(|e| e.to_string())?;
        let child = Command::new("timeout")
            .args(["--kill-after=5", "900", "qemu-system-arm"])
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
            .stdout(logf.try_clone().map_err(|e| e.to_string())?)
            .stderr(logf)
            .spawn()
            .map_err(|e| format!("starting qemu-system-arm: {e}\n{INSTALL_QEMU}"))?;
        let start = Instant::now();
        let stream = loop {
            match TcpStream::connect(("127.0.0.1", port)) {
                Ok(s) => break s,
                Err(e) if start.elapsed() > Duration::from_secs(20) => {
                    return Err(format!("QEMU did not open its UART port {port}: {e}"));
                }
                Err(_) => std::thread::sleep(Duration::from_millis(20)),
            }
        };
        stream
            .set_read_timeout(Some(Duration::from_secs(30)))
            .map_err(|e| e.to_string())?;
        stream.set_nodelay(true).map_err(|e| e.to_string())?;
        let mut q = Qemu {
            child,
            stream,
            acc: FrameAccumulator::new(),
            tx: Vec::new(),
            rx: Vec::new(),
            rx_pos: 0,
            log,
        };
        let banner = q.recv()?;
        Ok((q, banner))
    }

    /// Queues one message (written on [`Qemu::flush`] or the next receive).
    ///
    /// # Panics
    /// When the message does not fit a frame.
    pub fn send(&mut self, msg: &HostMessage<'_>) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let frame = msg.encode(&mut buf).expect("message fits a frame");
        self.tx.extend_from_slice(frame);
    }

    /// Queues raw bytes.
    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }

    /// Writes everything queued.
    ///
    /// # Errors
    /// On a socket error.
    pub fn flush(&mut self) -> Result<(), String> {
        if !self.tx.is_empty() {
            self.stream
                .write_all(&self.tx)
                .map_err(|e| format!("UART write: {e}"))?;
            self.tx.clear();
        }
        Ok(())
    }

    /// Receives the next device message (flushing anything queued first).
    ///
    /// # Errors
    /// On timeout, a closed connection or a frame that is not a device message.
    pub fn recv(&mut self) -> Result<DeviceMessage, String> {
        self.flush()?;
        loop {
            while self.rx_pos < self.rx.len() {
                let byte = self.rx[self.rx_pos];
                self.rx_pos += 1;
                match self.acc.push(byte) {
                    Feed::Pending => {}
                    Feed::Frame(f) => {
                        return DeviceMessage::decode(f)
                            .map_err(|e| format!("device sent a bad message: {e}"));
                    }
                    Feed::Error(e) => return Err(format!("device sent a bad frame: {e}")),
                }
            }
            self.rx.resize(4096, 0);
            self.rx_pos = 0;
            match self.stream.read(&mut self.rx) {
                Ok(0) => return Err("UART connection closed".into()),
                Ok(n) => self.rx.truncate(n),
                Err(e) => return Err(format!("UART read: {e}")),
            }
        }
    }

    /// Sends `Shutdown { code }` and waits for QEMU to exit; returns its exit code.
    ///
    /// # Errors
    /// When QEMU does not exit within 20 s.
    pub fn shutdown(mut self, code: u8) -> Result<i32, String> {
        self.send(&HostMessage::Shutdown { code });
        self.flush()?;
        let start = Instant::now();
        loop {
            if let Some(st) = self.child.try_wait().map_err(|e| e.to_string())? {
                return Ok(st.code().unwrap_or(-1));
            }
            if start.elapsed() > Duration::from_secs(20) {
                return Err("QEMU did not exit after Shutdown".into());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            // SIGTERM to `timeout`, which passes it on to QEMU; then reap.
            let _ = Command::new("kill")
                .arg("-TERM")
                .arg(self.child.id().to_string())
                .status();
            let _ = self.child.wait();
        }
        if !std::thread::panicking() {
            let _ = std::fs::remove_file(&self.log);
        }
    }
}
