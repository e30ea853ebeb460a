//! The RON scene file: schema (the public contract), loading into an ECS world, errors.

pub mod assets;
pub mod error;
pub mod load;
pub mod patch;
pub mod schema;

pub use assets::AssetPolicy;
pub use error::SceneError;
pub use load::{LoadedScene, RenderSettings, apply_override, load, load_str, load_with};
