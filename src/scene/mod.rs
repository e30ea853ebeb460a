//! The render-time scene: what every render reads, built once per frame from the world by
//! `systems`, and the questions the integrator asks of it: closest hit and any hit (one ray,
//! or a packet of rays), surface reconstruction at a hit, light samples, the medium a point
//! lies in and the transmittance along a shadow ray. It knows nothing of hecs or of the
//! integrator.

pub mod effects;
pub mod envmap;
pub mod light_lanes;
pub mod lights;
pub mod packet;
pub mod primitives;
pub mod sky;

pub use effects::{Effect, Effects};
pub use lights::{LightKind, LightSample, Lights};
pub use primitives::{Hit, PrimKind, Primitives};

use crate::components::Camera;
use crate::components::camera::{CameraFrame, CameraPath};
use crate::geometry::Ray;
use crate::kdtree::KdTree;
use crate::scene_file::RenderSettings;
use glam::Vec3;

/// Everything a render reads, built once per frame from the world.
pub struct RenderScene {
    /// Every primitive, material, texture and medium, flattened into arrays.
    pub prims: Primitives,
    /// Kd-tree over `prims`.
    pub accel: KdTree,
    /// Emitters and the distribution that picks among them.
    pub lights: Lights,
    /// The camera at the start of the frame's shutter; what every ray uses unless the camera
    /// moves within the shutter.
    pub camera: CameraFrame,
    /// The camera at rest and its path, for cameras that move within the shutter.
    pub base_camera: Camera,
    /// The camera's keyframe path, if it has one.
    pub camera_path: Option<CameraPath>,
    /// Whether the camera moves within this frame's shutter.
    pub camera_moves: bool,
    /// The medium around the camera (`primitives::NO_MEDIUM` for none).
    pub camera_medium: u32,
    /// Frame number being rendered.
    pub frame: u32,
    /// Shutter interval of this frame in scene time (frames): [frame + open, frame + close].
    pub shutter: (f32, f32),
    /// Radiance of the constant environment, linear sRGB (zero for none).
    pub environment: Vec3,
    /// What spectral transport evaluates for the environment.
    pub environment_spectrum: crate::spectrum::EmitterSpectrum,
    /// Which optional effects the kernel runs for this scene.
    pub effects: Effects,
    /// Render settings, `--set` overrides applied.
    pub settings: RenderSettings,
    /// Wall-clock seconds the kd-tree build took.
    pub accel_seconds: f64,
}

impl RenderScene {
    /// What in the scene will surprise its author, one line each: a scene with no light renders
    /// black, a `Light` with zero emission emits nothing, a camera inside a closed opaque shape
    /// sees only its inside.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.lights.is_empty() {
            out.push(
                "the scene has no light (no emitter, point or spot light, or environment): \
                 it renders black"
                    .to_string(),
            );
        }
        for (i, name) in self.prims.names.iter().enumerate() {
            let m = &self.prims.materials[self.prims.material[i] as usize];
            if let crate::components::Material::Light { emission, .. } = m
                && emission.max_element() <= 0.0
            {
                out.push(format!(
                    "entity {}: a Light with zero emission emits nothing",
                    crate::components::quoted(name)
                ));
            }
            if self.lamp_faces_nothing(i) {
                out.push(format!(
                    "entity {}: a one-sided Light whose front faces no other entity \
                     and not the camera lights nothing (turn it, or set two_sided: true)",
                    crate::components::quoted(name)
                ));
            }
            let opaque = !matches!(
                m,
                crate::components::Material::Dielectric { .. }
                    | crate::components::Material::Boundary
            );
            if opaque && self.prims.contains(i as u32, self.camera.origin).is_some() {
                out.push(format!(
                    "the camera is inside entity {}, a closed opaque shape: it sees only \
                     its inside",
                    crate::components::quoted(name)
                ));
            }
        }
        out
    }

    /// Whether primitive `i` is a static one-sided emitting rectangle or disk with every
    /// other entity's bounds and the camera behind or in its plane: its light reaches nothing.
    fn lamp_faces_nothing(&self, i: usize) -> bool {
        use crate::components::Material;
        let prims = &self.prims;
        let Material::Light {
            emission,
            two_sided: false,
            ..
        } = prims.materials[prims.material[i] as usize]
        else {
            return false;
        };
        if emission.max_element() <= 0.0
            || !matches!(prims.kind[i], PrimKind::Rect | PrimKind::Disk)
            || prims.motion[i] != primitives::NO_MOTION
        {
            return false;
        }
        let pl = &prims.planars[prims.local[i] as usize];
        let front = |p: glam::Vec3| (p - pl.center).dot(pl.n) > 0.0;
        let lights_something = (0..prims.len()).any(|j| {
            let b = prims.bounds_of(j as u32);
            j != i
                && (0..8).any(|c| {
                    front(glam::Vec3::new(
                        if c & 1 == 0 { b.min.x } else { b.max.x },
                        if c & 2 == 0 { b.min.y } else { b.max.y },
                        if c & 4 == 0 { b.min.z } else { b.max.z },
                    ))
                })
        });
        !lights_something && !front(self.camera.origin)
    }

    /// Closest hit along `ray` before `t_max`, at `time` when MOTION is on.
    #[inline]
    pub fn intersect<const MOTION: bool>(&self, ray: &Ray, t_max: f32, time: f32) -> Option<Hit> {
        let mut best = None;
        self.accel.closest_hit(ray, t_max, |prim, t_max| {
            let (t, u, v, sub) = self
                .prims
                .intersect_sub_at::<f32, MOTION>(prim, ray, t_max, time)?;
            best = Some(Hit { t, prim, sub, u, v });
            Some(t)
        })?;
        best
    }

    /// Transmittance along a shadow ray that starts in `medium`: medium boundaries are crossed
    /// (ordered traversal, Beer–Lambert per segment), any other surface blocks it.
    pub fn transmittance<const MOTION: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        time: f32,
        medium: u32,
    ) -> Vec3 {
        self.transmittance_with::<MOTION, Vec3>(ray, t_max, time, medium, |m, d| {
            self.prims.media[m as usize].transmittance(d)
        })
    }

    /// [`Self::transmittance`] in any channels: `medium_tr(m, d)` is medium `m`'s
    /// transmittance over distance `d`. Always inlined, for the same reason as the medium's
    /// estimators (`integrator::transport::MediumOps`).
    #[inline(always)]
    pub fn transmittance_with<const MOTION: bool, S: crate::spectrum::Channels>(
        &self,
        ray: &Ray,
        t_max: f32,
        time: f32,
        mut medium: u32,
        medium_tr: impl Fn(u32, f32) -> S,
    ) -> S {
        let len = ray.d.length();
        let mut r = *ray;
        let mut t_left = t_max;
        let mut tr = S::ONE;
        // A ray crosses each boundary once per pass through it; nesting deeper than this
        // would be a loop from rounding, and the light is treated as blocked.
        for _ in 0..64 {
            let seg = |m: u32, t: f32| {
                if m == primitives::NO_MEDIUM {
                    S::ONE
                } else {
                    medium_tr(m, t * len)
                }
            };
            let Some(hit) = self.intersect::<MOTION>(&r, t_left, time) else {
                return tr * seg(medium, t_left);
            };
            let m = self.prims.materials[self.prims.material[hit.prim as usize] as usize];
            if !matches!(m, crate::components::Material::Boundary) {
                return S::ZERO;
            }
            tr *= seg(medium, hit.t);
            if tr == S::ZERO {
                return tr;
            }
            let sp = self.prims.surface_at::<MOTION>(&r, &hit, time);
            medium = self.prims.medium_after_crossing(hit.prim, sp.front, medium);
            // Continue from just past the boundary; the direction keeps its length, so the
            // parameter left shrinks by what was travelled.
            let o = crate::geometry::offset_ray_origin(sp.p, -sp.facing());
            t_left -= ((o - r.o).dot(r.d) / (len * len)).max(0.0);
            r = Ray::new(o, r.d);
            if t_left <= 0.0 {
                return tr;
            }
        }
        S::ZERO
    }

    /// Whether anything blocks `ray` before `t_max`, at `time` when MOTION is on.
    #[inline]
    pub fn occluded<const MOTION: bool>(&self, ray: &Ray, t_max: f32, time: f32) -> bool {
        self.accel.any_hit(ray, t_max, |prim, t_max| {
            self.prims
                .occluded_at::<f32, MOTION>(prim, ray, t_max, time)
        })
    }
}
