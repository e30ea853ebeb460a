//! The film: tile films and their accumulation into the image, and comparison of images. Image
//! files live in [`crate::imageio`], re-exported here.

pub mod compare;
pub mod tile;

pub use crate::imageio::*;
pub use compare::*;
pub use tile::{Film, TILE, Tile, TileFilm, mean_image, tiles};
