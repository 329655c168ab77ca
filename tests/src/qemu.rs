//! Boots the firmware in QEMU (`netduinoplus2`, a Cortex-M4F STM32F405) and talks to it over
//! USART1, which QEMU exposes as a TCP server on 127.0.0.1, through the host's link
//! (`yawcast::io::hil::Device`); the firmware is built here when no ELF is given.

use std::path::{Path, PathBuf};
use std::process::Command;

use yawcast::io::hil::{Device, HilError};
pub use yawcast::io::hil::{ELF_VAR, THUMB_TARGET as TARGET};
use yawcast_shared::wire::{DeviceMessage, HostMessage};

const INSTALL_QEMU: &str = "qemu-system-arm is needed for the firmware-in-QEMU tests. Install it \
     with `sudo apt-get install -y --no-install-recommends qemu-system-arm` (Debian/Ubuntu; \
     `brew install qemu` on macOS), or run `bash .ci/run`, which installs what is missing.";

const INSTALL_TARGET: &str = "the Cortex-M4F target is needed to build the firmware. Install it \
     with `rustup target add thumbv7em-none-eabihf`, or run `bash .ci/run`.";

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

/// A running firmware in QEMU and its UART connection: the host's link
/// ([`yawcast::io::hil::Device`], the one `yawcast hil` uses), with the panics and string
/// errors a test wants.
#[derive(Debug)]
pub struct Qemu(Device);

impl Qemu {
    /// Boots `elf` and waits for its banner.
    ///
    /// # Errors
    /// When QEMU is missing, does not start, or no banner arrives.
    pub fn boot(elf: &Path) -> Result<(Qemu, DeviceMessage), String> {
        // the link checks for QEMU itself; a test says how to install it
        let mut d = Device::qemu(elf).map_err(|e| match e {
            HilError::NoQemu => INSTALL_QEMU.to_string(),
            e => e.to_string(),
        })?;
        let banner = d.banner.take().ok_or("QEMU came up without a banner")?;
        Ok((Qemu(d), banner))
    }

    /// Queues one message (written on [`Qemu::flush`] or the next receive).
    ///
    /// # Panics
    /// When the message does not fit a frame.
    pub fn send(&mut self, msg: &HostMessage<'_>) {
        self.0
            .send(msg)
            .unwrap_or_else(|e| panic!("message does not fit a frame: {e}"));
    }

    /// Queues raw bytes.
    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.0.send_raw(bytes);
    }

    /// Writes everything queued.
    ///
    /// # Errors
    /// On a socket error.
    pub fn flush(&mut self) -> Result<(), String> {
        self.0.flush().map_err(|e| e.to_string())
    }

    /// Receives the next device message (flushing anything queued first).
    ///
    /// # Errors
    /// On timeout, a closed connection or a frame that is not a device message.
    pub fn recv(&mut self) -> Result<DeviceMessage, String> {
        self.0.recv().map_err(|e| e.to_string())
    }

    /// Sends `Shutdown { code }` and waits for QEMU to exit; returns its exit code.
    ///
    /// # Errors
    /// When QEMU does not exit within 20 s.
    pub fn shutdown(self, code: u8) -> Result<i32, String> {
        self.0.shutdown(code).map_err(|e| e.to_string())
    }
}
