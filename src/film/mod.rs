//! The film's output side: images, their files (PNG, EXR with provenance), and comparison.

pub mod compare;
pub mod output;

pub use compare::*;
pub use output::*;
