//! serde types of the RON scene file: its public contract, documented for users field by field
//! in `docs/scene-format.md`.
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

/// A top-level scene: `Scene(render: .., camera: .., ..)`; only `camera` is required.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Image and integrator settings; every one has a default.
    #[serde(default, deserialize_with = "render::checked_render")]
    pub render: Render,
    /// The camera; an `animation`'s keyframes override its placement, not its lens or shutter.
    pub camera: Camera,
    /// Keyframed camera path; absent, the camera holds still.
    #[serde(default)]
    pub animation: Option<Animation>,
    /// Radiance seen by rays that escape the scene; absent, black.
    #[serde(default)]
    pub environment: Option<Environment>,
    /// The scene objects; default none.
    #[serde(default)]
    pub entities: Vec<Entity>,
}

/// One scene object: a shape with a material and/or a medium, or a shapeless `light`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entity {
    /// Label for messages and `--set entities["NAME"]..`; absent, the entity is `#index`.
    #[serde(default)]
    pub name: Option<String>,
    /// The surface; required unless the entity is a `light`.
    #[serde(default)]
    pub shape: Option<Shape>,
    /// Object-to-world placement of the shape (or of a light's position); default identity.
    #[serde(default)]
    pub transform: Option<Transform>,
    /// How the surface scatters or emits; required on a shape unless a `medium` makes it a
    /// pure boundary.
    #[serde(default)]
    pub material: Option<Material>,
    /// Albedo and normal textures over the shape's uv; a mesh needs uvs for it.
    #[serde(default)]
    pub texture: Option<TextureSpec>,
    /// Rigid motion during the shutter; absent, the entity is static.
    #[serde(default)]
    pub motion: Option<Motion>,
    /// A medium filling the shape, which must be a closed Sphere or Box with no material or a
    /// Dielectric.
    #[serde(default)]
    pub medium: Option<MediumSpec>,
    /// A point or spot light; excludes `shape` and `material`.
    #[serde(default)]
    pub light: Option<LightSpec>,
}
