// Each test binary uses only part of the shared helpers.
#![allow(dead_code)]

pub mod chi2;
pub mod colour;
pub mod estimators;
pub mod furnace;
pub mod quadrature;
pub mod render;
