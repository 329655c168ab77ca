//! yawcast-shared: the model schema, the versioned model blob and the UART wire format.
//!
//! `no_std`, no allocation. Shared by the host tools (which write models) and the firmware
//! (which reads them).
#![no_std]
#![deny(missing_docs)]

pub mod model;
