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
        self.falloff_lanes::<f32>(crate::simd::V3::splat(w))
    }

    /// [`PointLight::falloff`] towards one unit direction per lane.
    #[inline(always)]
    pub fn falloff_lanes<F: crate::simd::Float>(&self, w: crate::simd::V3<F>) -> F {
        if self.cos_cone <= -1.0 {
            return F::one();
        }
        let d = self.direction;
        // glam's unfused dot product.
        let c = w.x * F::splat(d.x) + w.y * F::splat(d.y) + w.z * F::splat(d.z);
        let (cone, start) = (F::splat(self.cos_cone), F::splat(self.cos_falloff_start));
        let x = (c - cone) / (start - cone);
        let smooth = x * x * (F::splat(3.0) - F::splat(2.0) * x);
        let edge = F::select(c.le(cone), F::zero(), smooth);
        F::select(c.ge(start), F::one(), edge)
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

/// The light as a scene file writes it: `Point(position: .., intensity: ..)` or
/// `Spot(position: .., direction: .., cone: .., falloff: .., intensity: ..)`, angles in degrees
/// to five significant digits (they are stored as cosines).
impl std::fmt::Display for PointLight {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |v: Vec3| format!("({:?}, {:?}, {:?})", v.x, v.y, v.z);
        let intensity = super::material::EmissionSyntax(self.intensity, self.spectrum);
        if self.cos_cone <= -1.0 {
            return write!(
                f,
                "Point(position: {}, intensity: {intensity})",
                v(self.position)
            );
        }
        let degrees = |c: f32| {
            let d = f64::from(c.clamp(-1.0, 1.0)).acos().to_degrees();
            let p = 10f64.powi(4 - d.abs().max(1e-3).log10().floor() as i32);
            (d * p).round() / p
        };
        let cone = degrees(self.cos_cone);
        write!(
            f,
            "Spot(position: {}, direction: {}, cone: {cone:?}, falloff: {:?}, intensity: {intensity})",
            v(self.position),
            v(self.direction),
            ((cone - degrees(self.cos_falloff_start)) * 1e4).round() / 1e4
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_file::load::ron_options;
    use crate::scene_file::schema::LightSpec;
    use crate::spectrum::EmitterSpectrum;

    /// `prism info` prints lights as the scene file writes them, and the printed form parses
    /// back as a light, angles recovered from their cosines.
    #[test]
    fn lights_print_in_scene_syntax() {
        let spot = PointLight {
            position: Vec3::new(1.0, 2.0, 3.0),
            direction: Vec3::new(0.0, -1.0, 0.0),
            intensity: Vec3::new(1.0, 2.0, 3.0),
            spectrum: EmitterSpectrum::Rgb,
            cos_cone: 30f32.to_radians().cos(),
            cos_falloff_start: 25f32.to_radians().cos(),
        };
        let text = spot.to_string();
        assert_eq!(
            text,
            "Spot(position: (1.0, 2.0, 3.0), direction: (0.0, -1.0, 0.0), cone: 30.0, \
             falloff: 5.0, intensity: Rgb(1.0, 2.0, 3.0))"
        );
        let point = PointLight {
            cos_cone: -1.0,
            cos_falloff_start: -1.0,
            ..spot
        };
        assert_eq!(
            point.to_string(),
            "Point(position: (1.0, 2.0, 3.0), intensity: Rgb(1.0, 2.0, 3.0))"
        );
        for t in [text, point.to_string()] {
            ron_options()
                .from_str::<LightSpec>(&t)
                .unwrap_or_else(|e| panic!("{t}: {e}"));
        }
    }
}
