//! `Motion`: rigid motion of an entity over time.
//!
//! ```
//! # use prism::scene_file::schema::Motion;
//! let m: Motion = ron::from_str("(velocity: Some((0.0, 0.6, 0.0)), angular_velocity: Some((0.0, 90.0, 0.0)))").unwrap();
//! # let _ = m;
//! ```
//! `velocity` is in scene units per frame; `angular_velocity` in degrees per frame about the
//! object origin (the transform's translation), composed as Rz·Ry·Rx. Time is measured in
//! frames: frame f covers [f, f + 1) and the camera's shutter is the open fraction of it.

use glam::Vec3;

/// Rigid motion of an entity: a constant linear and angular velocity.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Motion {
    /// Scene units per frame.
    pub velocity: Vec3,
    /// Degrees per frame.
    pub angular_velocity: Vec3,
}

impl Motion {
    /// Whether the entity does not move.
    pub fn is_static(&self) -> bool {
        self.velocity == Vec3::ZERO && self.angular_velocity == Vec3::ZERO
    }
}
