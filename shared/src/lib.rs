//! yawcast-shared: the model schema, the versioned model blob and the UART wire format.
//!
//! `no_std`, no allocation. Shared by the host tools (which write models) and the firmware
//! (which reads them).
#![no_std]
#![deny(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod blob;
pub mod crc;
pub mod kernel;
pub mod model;
pub mod nav;
pub mod wire;

#[cfg(test)]
mod tests;
