//! yawcast: ship-trial data to a yaw-rate predictor — simulator, identification, tuning,
//! diagnosis and export. f64 throughout; firmware-exact numbers come from `yawcast-firmware`.
#![deny(missing_docs)]

pub mod augment;
pub mod compare;
pub mod data;
pub mod demo;
pub mod diagnose;
pub mod export;
pub mod ga;
pub mod hil;
pub mod merge;
pub mod model;
pub mod nmea;
mod par;
pub mod pem;
pub mod predict;
pub mod report;
pub mod resid;
pub mod sim;
pub mod tables;
