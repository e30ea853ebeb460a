//! The film: tile films and their accumulation into the image, images, their files (PNG, EXR
//! with provenance), and comparison.

pub mod compare;
pub mod output;
pub mod tile;

pub use compare::*;
pub use output::*;
pub use tile::{Film, TILE, Tile, TileFilm, mean_image, tiles};
