//! prism: a physically based spectral path tracer.
//!
//! A RON scene becomes a `hecs` world (`scene_file`); systems flatten it into arrays, a
//! kd-tree and a light list (`systems`, `kdtree`); the integrator traces packets of paths
//! through them, one per SIMD lane (`integrator`); the film accumulates them and writes PNG
//! or EXR (`film`).

// `simd` alone may hold `unsafe` (intrinsics behind CPU feature detection); `tests/lanes.rs`
// checks that no other module does.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod cli;
pub mod components;
pub mod energy;
pub mod files;
pub mod film;
pub mod geometry;
pub mod imageio;
pub mod integrator;
pub mod kdtree;
pub mod medium;
pub mod report;
pub mod sampling;
pub mod scene;
pub mod scene_file;
pub mod simd;
pub mod spectrum;
pub mod systems;
pub mod texture;
