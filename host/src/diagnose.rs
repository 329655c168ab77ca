//! Placeholder for the `diagnose` module (being written).
