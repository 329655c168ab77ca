//! yawcast-firmware: the on-board f32 yaw-rate predictor.
#![no_std]
#![deny(missing_docs)]
