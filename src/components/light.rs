//! `PointLight`: a point or spot light, an entity without a shape.
//!
//! ```
//! # use prism::scene_file::schema::LightSpec;
//! let l: LightSpec = ron::from_str("Point(position: (0.0, 2.0, 0.0), intensity: Rgb(5.0, 5.0, 5.0))").unwrap();
//! # let _ = l;
//! let l: LightSpec = ron::from_str(
//!     "Spot(position: (0.0, 2.9, 0.0), direction: (0.0, -1.0, 0.0), cone: 25.0, falloff: 5.0, intensity: Rgb(10.0, 10.0, 10.0))",
//! ).unwrap();
//! # let _ = l;
//! ```
//! `intensity` is radiant intensity (W/sr in scene units): a surface at distance d facing the
//! light receives irradiance intensity / d². A spot's `cone` is the half-angle of its cone;
//! intensity falls smoothly to zero over the last `falloff` degrees, as pbrt's spot light.

use glam::Vec3;

/// A point or spot light: a position, and for a spot an axis and a cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where the light is, world space.
    pub position: Vec3,
    /// Spot axis (unused by a point light).
    pub direction: Vec3,
    /// Linear sRGB intensity; `spectrum` is what spectral transport evaluates.
    pub intensity: Vec3,
    /// The emission spectrum spectral transport evaluates instead of `intensity`.
    pub spectrum: crate::spectrum::EmitterSpectrum,
    /// Cosine of the cone half-angle: −1 for an omnidirectional point light.
    pub cos_cone: f32,
    /// Cosine where the soft edge starts.
    pub cos_falloff_start: f32,
}

impl PointLight {
    /// Intensity towards unit direction `w` (from the light).
    #[inline]
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        if self.cos_cone <= -1.0 {
            return self.intensity;
        }
        self.intensity * self.falloff(w)
    }

    /// The spot's angular factor in [0, 1] towards unit direction `w` (1 for a point light).
    #[inline]
    pub fn falloff(&self, w: Vec3) -> f32 {
        if self.cos_cone <= -1.0 {
            return 1.0;
        }
        let c = w.dot(self.direction);
        if c >= self.cos_falloff_start {
            1.0
        } else if c <= self.cos_cone {
            0.0
        } else {
            let x = (c - self.cos_cone) / (self.cos_falloff_start - self.cos_cone);
            x * x * (3.0 - 2.0 * x)
        }
    }

    /// Emitted power (scene units), for choosing lights by power.
    pub fn power(&self) -> Vec3 {
        let solid_angle = if self.cos_cone <= -1.0 {
            4.0 * std::f32::consts::PI
        } else {
            // As pbrt: the cone to the middle of the soft edge.
            2.0 * std::f32::consts::PI * (1.0 - 0.5 * (self.cos_cone + self.cos_falloff_start))
        };
        self.intensity * solid_angle
    }
}
