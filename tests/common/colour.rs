//! Colorimetry the tests compare colours with.

use glam::Vec3;

/// CIELAB (CIE 15:2004) of an XYZ colour relative to `white`.
pub fn lab(xyz: Vec3, white: Vec3) -> Vec3 {
    let f = |t: f32| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(xyz.x / white.x), f(xyz.y / white.y), f(xyz.z / white.z));
    Vec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
}
