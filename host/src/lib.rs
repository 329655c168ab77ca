//! yawcast: ship-trial data to a yaw-rate predictor — simulator, identification, tuning,
//! diagnosis and export. f64 throughout; firmware-exact numbers come from `yawcast-firmware`.
//!
//! The modules follow the data flow: [`sim`] (records of a simulated ship) → [`identify`]
//! (PEM, the f64 model and predictor, several trials into one model) → [`tune`] (GA over the
//! regularisation) → [`diagnose`] (compare, residual tests, which effect is missing, augment)
//! → [`io`] (records in, the blob out, reports, hardware in the loop) → the firmware.
#![deny(missing_docs)]

pub mod demo;
pub mod diagnose;
pub mod effects;
pub mod identify;
pub mod io;
mod par;
pub mod sim;
pub mod stats;
pub mod tune;
