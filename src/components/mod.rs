//! ECS components: plain data attached to scene entities by `scene_file::load`.

pub mod camera;
pub mod light;
pub mod material;
pub mod medium;
pub mod motion;
pub mod shape;
pub mod texture;

pub use camera::Camera;
pub use light::PointLight;
pub use material::{Alpha, ConductorIor, Material};
pub use medium::Medium;
pub use motion::Motion;
pub use shape::Shape;
pub use texture::Texture;

use glam::Affine3A;

/// The entity's name in the scene file; every error about an entity uses it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Name(pub String);

/// The longest name a message shows in full, in characters.
pub const SHOWN_NAME_CHARS: usize = 64;

/// `name` in double quotes as messages and `prism info` print it: control characters,
/// quotes and backslashes escaped (a name cannot move the cursor or recolour a terminal), and
/// cut after [`SHOWN_NAME_CHARS`] characters with the full length given.
pub fn quoted(name: &str) -> String {
    let mut out = String::with_capacity(name.len().min(4 * SHOWN_NAME_CHARS) + 2);
    out.push('"');
    out.extend(
        name.chars()
            .take(SHOWN_NAME_CHARS)
            .flat_map(char::escape_debug),
    );
    out.push('"');
    let n = name.chars().count();
    if n > SHOWN_NAME_CHARS {
        out.push_str(&format!("… ({n} characters)"));
    }
    out
}

/// `text` with its control characters escaped (`\n`, `\u{1b}`), so that a file path or value
/// from a scene, echoed in a message, keeps the message on one line and cannot drive the
/// terminal.
pub fn escape_controls(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Object-to-world placement: scale, then rotation R = Rz·Ry·Rx (degrees), then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Object-to-world matrix.
    pub to_world: Affine3A,
    /// The uniform scale factor when the transform is a similarity (rotation and uniform
    /// scale), which spheres require.
    pub uniform_scale: Option<f32>,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            to_world: Affine3A::IDENTITY,
            uniform_scale: Some(1.0),
        }
    }
}
