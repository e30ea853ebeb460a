//! `Camera`: a pinhole or thin-lens camera, not an entity but a resource beside the world.
//!
//! ```
//! # use prism::scene_file::schema::Camera;
//! let c: Camera = ron::from_str("(position: (0.0, 1.0, 6.0), look_at: (0.0, 1.0, 0.0), up: (0.0, 1.0, 0.0), fov_y: 40.0,
//!     lens: Some((aperture_radius: 0.05, focus_distance: 6.0, blades: 0)))").unwrap();
//! # let _ = c;
//! ```
//! `fov_y` is the vertical field of view in degrees; the image's right is `forward × up`.

use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    pub fov_y: f32,
    pub aperture_radius: f32,
    pub focus_distance: f32,
    /// 0 for a round aperture, otherwise the number of polygon sides.
    pub blades: u32,
    pub shutter: (f32, f32),
}

/// The camera's orthonormal frame and film scale, computed once per render.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame {
    pub origin: Vec3,
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    /// Half extents of the film plane at distance 1.
    pub half: Vec2,
    pub aperture_radius: f32,
    pub focus_distance: f32,
    pub blades: u32,
}

impl Camera {
    pub fn frame(&self, width: u32, height: u32) -> CameraFrame {
        let forward = (self.look_at - self.position).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let ty = (self.fov_y.to_radians() * 0.5).tan();
        let tx = ty * width as f32 / height as f32;
        CameraFrame {
            origin: self.position,
            forward,
            right,
            up,
            half: Vec2::new(tx, ty),
            aperture_radius: self.aperture_radius,
            focus_distance: self.focus_distance,
            blades: self.blades,
        }
    }
}
