//! prism: a physically based spectral path tracer.
//!
//! A RON scene becomes a `hecs` world (`scene_file`); systems flatten it into arrays, a
//! kd-tree and a light list (`systems`, `kdtree`); a wavefront integrator pushes batches of
//! rays through them (`integrator`); the film writes PNG or EXR (`film`).

// `simd` alone may hold `unsafe` (intrinsics behind CPU feature detection); `tests/lanes.rs`
// checks that no other module does.
#![deny(unsafe_code)]

pub mod cli;
pub mod components;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod kdtree;
pub mod medium;
pub mod report;
pub mod sampling;
pub mod scene_file;
pub mod simd;
pub mod spectrum;
pub mod systems;
pub mod texture;
