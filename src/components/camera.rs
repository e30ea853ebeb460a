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

/// One keyframe of a camera path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraKey {
    /// Frame number of the key (may be fractional).
    pub frame: f32,
    /// Eye point, world space.
    pub position: Vec3,
    /// Point the camera looks at, world space.
    pub look_at: Vec3,
    /// Up direction; need not be orthogonal to the view direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    /// Distance from the eye to the plane in focus, scene units.
    pub focus_distance: f32,
}

/// A camera path through keyframes. Position and look-at point follow Hermite splines whose
/// tangents are Catmull–Rom differences over frame numbers (so unevenly spaced keys keep a
/// steady speed); up, field of view and focus distance are interpolated linearly. The view
/// orientation is rebuilt from the interpolated look-at frame at every time, so it turns the
/// short way between keys and never rolls unless `up` says so. Before the first key and after
/// the last the camera holds still.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    /// Frames per second, for animated output.
    pub fps: u32,
    /// Keyframes in increasing frame order.
    pub keys: Vec<CameraKey>,
}

impl CameraPath {
    fn tangent(&self, i: usize, f: impl Fn(&CameraKey) -> Vec3) -> Vec3 {
        let k = &self.keys;
        let n = k.len();
        if n < 2 {
            return Vec3::ZERO;
        }
        let (a, b) = if i == 0 {
            (0, 1)
        } else if i == n - 1 {
            (n - 2, n - 1)
        } else {
            (i - 1, i + 1)
        };
        (f(&k[b]) - f(&k[a])) / (k[b].frame - k[a].frame)
    }

    /// The camera at time `t` (frames), keeping `base`'s lens and shutter.
    pub fn at(&self, t: f32, base: &Camera) -> Camera {
        let k = &self.keys;
        let mut c = *base;
        let last = k.len() - 1;
        let pick = |key: &CameraKey, c: &mut Camera| {
            c.position = key.position;
            c.look_at = key.look_at;
            c.up = key.up;
            c.fov_y = key.fov_y;
            c.focus_distance = key.focus_distance;
        };
        if t <= k[0].frame || last == 0 {
            pick(&k[0], &mut c);
            return c;
        }
        if t >= k[last].frame {
            pick(&k[last], &mut c);
            return c;
        }
        let i = k.partition_point(|key| key.frame <= t) - 1;
        let (a, b) = (&k[i], &k[i + 1]);
        let h = b.frame - a.frame;
        let s = (t - a.frame) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        );
        let herm = |f: &dyn Fn(&CameraKey) -> Vec3| {
            f(a) * h00
                + self.tangent(i, f) * (h10 * h)
                + f(b) * h01
                + self.tangent(i + 1, f) * (h11 * h)
        };
        c.position = herm(&|k: &CameraKey| k.position);
        c.look_at = herm(&|k: &CameraKey| k.look_at);
        c.up = a.up.lerp(b.up, s).normalize_or(a.up);
        c.fov_y = a.fov_y + (b.fov_y - a.fov_y) * s;
        c.focus_distance = a.focus_distance + (b.focus_distance - a.focus_distance) * s;
        c
    }

    /// Whether the camera changes anywhere in `[t0, t1]`.
    pub fn moves_within(&self, t0: f32, t1: f32) -> bool {
        let k = &self.keys;
        if k.len() < 2 || t1 <= k[0].frame || t0 >= k[k.len() - 1].frame {
            return false;
        }
        // Between two identical keys the spline can still bulge from its neighbours'
        // tangents, so any span that overlaps the interval counts as moving unless every
        // key is the same.
        k.windows(2).any(|w| {
            w[0].position != w[1].position
                || w[0].look_at != w[1].look_at
                || w[0].up != w[1].up
                || w[0].fov_y != w[1].fov_y
                || w[0].focus_distance != w[1].focus_distance
        })
    }
}

/// A pinhole or thin-lens camera as the scene file describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye point (lens centre), world space.
    pub position: Vec3,
    /// Point the camera looks at, world space.
    pub look_at: Vec3,
    /// Up direction; need not be orthogonal to the view direction.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    /// Lens radius, scene units; 0 for a pinhole.
    pub aperture_radius: f32,
    /// Distance from the eye to the plane in focus, scene units.
    pub focus_distance: f32,
    /// 0 for a round aperture, otherwise the number of polygon sides.
    pub blades: u32,
    /// Shutter (open, close) as fractions of a frame, `0 <= open <= close <= 1`.
    pub shutter: (f32, f32),
}

/// The camera's orthonormal frame and film scale, computed once per render.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame {
    /// Eye point, world space.
    pub origin: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit right direction of the film, `forward × up`.
    pub right: Vec3,
    /// Unit up direction of the film, orthogonal to `forward` and `right`.
    pub up: Vec3,
    /// Half extents of the film plane at distance 1.
    pub half: Vec2,
    /// Lens radius, scene units; 0 for a pinhole.
    pub aperture_radius: f32,
    /// Distance from the eye to the plane in focus, scene units.
    pub focus_distance: f32,
    /// 0 for a round aperture, otherwise the number of polygon sides.
    pub blades: u32,
}

impl Camera {
    /// The frame for an image of `width` × `height` pixels.
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
