//! Data in and out: measurement records (CSV, NMEA), the model blob and its JSON twin, the
//! report, and hardware in the loop.

pub mod data;
pub mod export;
pub mod hil;
pub mod nav;
pub mod nmea;
pub mod report;
