//! Placeholder for the `augment` module (being written).
