//! Identification: the f64 model with its effects, its predictor, prediction-error
//! identification (PEM) and several trials into one model.

pub mod merge;
pub mod model;
pub mod pem;
pub mod predict;
pub mod track;
