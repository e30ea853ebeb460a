//! The film: tile films and their accumulation into the image, and comparison of images. Image
//! files live in [`crate::imageio`], re-exported here.

pub mod compare;
pub mod estimate;
pub mod tile;

pub use crate::imageio::*;
pub use compare::*;
pub use tile::{Film, HALF_B, TILE, Tile, TileFilm, TileWork, mean_image, tiles};
