//! CLI contract tests: they run the built `yawcast` binary and pin exit codes, messages,
//! file formats and JSON field names.
//!
//! One test binary, its tests grouped by what they pin.

mod bad_input;
mod common;
mod diagnose_augment;
mod inputs;
mod pipeline;
mod robustness;
