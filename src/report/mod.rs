//! What accuracy costs in time: convergence studies against a reference, their plots and
//! summaries.

pub mod converge;
pub mod costs;
pub mod plot;
pub mod ssim;

pub use converge::{ConvergeOptions, ConvergeResult, Row, converge};
