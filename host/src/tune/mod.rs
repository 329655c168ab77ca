//! Tuning: the genetic algorithm over the regularisation (λ, R) scored on trial records, and
//! the paper-shaped parameter and fit tables.

pub mod ga;
pub mod tables;
