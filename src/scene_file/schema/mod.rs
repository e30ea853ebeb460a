//! serde types of the RON scene file: the public contract of DESIGN.md.
//!
//! Value ranges are checked here, during deserialisation (`#[serde(try_from)]` newtypes), so
//! that a bad value is reported with the line and column where it stands. Parts of the schema
//! that this build does not simulate yet are parsed and then refused with a message that says
//! so, never ignored.

mod camera;
mod light;
mod material;
mod medium;
mod motion;
mod render;
mod shape;
mod texture;
mod values;

pub use camera::*;
pub use light::*;
pub use material::*;
pub use medium::*;
pub use motion::*;
pub use render::*;
pub use shape::*;
pub use texture::*;
pub use values::*;

use serde::Deserialize;

/// A top-level scene.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub render: Render,
    pub camera: Camera,
    #[serde(default)]
    pub animation: Option<Animation>,
    #[serde(default)]
    pub environment: Option<Environment>,
    #[serde(default)]
    pub entities: Vec<Entity>,
}

/// One scene object.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entity {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub shape: Option<Shape>,
    #[serde(default)]
    pub transform: Option<Transform>,
    #[serde(default)]
    pub material: Option<Material>,
    #[serde(default)]
    pub texture: Option<TextureSpec>,
    #[serde(default)]
    pub motion: Option<Motion>,
    #[serde(default)]
    pub medium: Option<MediumSpec>,
    #[serde(default)]
    pub light: Option<LightSpec>,
}
