//! Build script: links the workspace's `memory.x` into the bare-metal binary and embeds an
//! optional built-in model.
//!
//! For `target_os = "none"` it copies `../memory.x` (the one memory map of the workspace)
//! into `OUT_DIR`, puts that directory on the linker search path and passes `-Tlink.x`
//! (cortex-m-rt) and `-Tdefmt.x` (defmt) to the binaries. Host builds get neither.
//!
//! `YAWCAST_BUILTIN_MODEL=path/to/model.postcard` embeds that blob in flash; the app loads
//! it at boot. Without it the embedded blob is empty and the app waits for `LoadModel`.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR"));
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=YAWCAST_BUILTIN_MODEL");

    let model = match env::var_os("YAWCAST_BUILTIN_MODEL") {
        Some(path) => {
            let path = PathBuf::from(path);
            println!("cargo:rerun-if-changed={}", path.display());
            fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
        }
        None => Vec::new(),
    };
    fs::write(out.join("builtin_model.bin"), model).expect("writing builtin_model.bin");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        let memory_x = manifest.join("..").join("memory.x");
        println!("cargo:rerun-if-changed={}", memory_x.display());
        fs::copy(&memory_x, out.join("memory.x"))
            .unwrap_or_else(|e| panic!("copying {}: {e}", memory_x.display()));
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}
