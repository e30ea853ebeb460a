//! Sample generation and the warps that turn uniform samples into
//! directions, points and discrete choices.
//!
//! - [`Sampler`]: stateless per-pixel sample sequences (Owen-scrambled Sobol
//!   or independent PCG32).
//! - [`AliasTable`]: O(1) sampling of discrete distributions.
//! - [`warp`]: square-to-domain mappings, each beside its pdf.
//! - [`sobol`]: the Sobol and scrambling primitives behind the sampler.

pub mod alias;
pub mod sampler;
pub mod sobol;
pub mod warp;

pub use alias::AliasTable;
pub use sampler::{Sampler, SamplerKind, u32_to_unit_f32};
pub use warp::*;
