//! Systems: plain functions over `&World` that turn the scene into the flat arrays the
//! integrator reads. The acceleration structure and light list live beside the world.

pub mod effects;
pub mod lights;
pub mod primitives;

pub use effects::{Effect, Effects, detect_effects};
pub use lights::{LightKind, LightSample, Lights, gather_lights};
pub use primitives::{Hit, PrimKind, Primitives, gather_primitives};

use crate::components::camera::CameraFrame;
use crate::geometry::{Aabb, Ray};
use crate::kdtree::{KdParams, KdTree};
use crate::scene_file::{LoadedScene, RenderSettings};
use glam::Vec3;

/// Everything a render reads, built once per frame from the world.
pub struct RenderScene {
    pub prims: Primitives,
    pub accel: KdTree,
    pub lights: Lights,
    pub camera: CameraFrame,
    pub shutter: (f32, f32),
    pub environment: Vec3,
    pub effects: Effects,
    pub settings: RenderSettings,
    pub accel_seconds: f64,
}

/// Builds the acceleration structure over the gathered primitives.
pub fn build_accel(prims: &Primitives, params: &KdParams) -> KdTree {
    KdTree::build(prims, params)
}

/// Runs the systems in order: effects, primitives, kd-tree, lights.
pub fn prepare(scene: &LoadedScene, params: &KdParams) -> RenderScene {
    let effects = detect_effects(&scene.world, &scene.camera);
    let mut prims = gather_primitives(&scene.world);
    let t0 = std::time::Instant::now();
    let accel = build_accel(&prims, params);
    let accel_seconds = t0.elapsed().as_secs_f64();
    let bounds: Aabb = accel.bounds();
    let lights = gather_lights(&mut prims, scene.environment, &bounds);
    let s = &scene.render;
    RenderScene {
        camera: scene.camera.frame(s.width, s.height),
        shutter: scene.camera.shutter,
        prims,
        accel,
        lights,
        environment: scene.environment,
        effects,
        settings: s.clone(),
        accel_seconds,
    }
}

impl RenderScene {
    /// Closest hit along `ray` before `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut best = None;
        self.accel.closest_hit(ray, t_max, |prim, t_max| {
            let (t, u, v) = self.prims.intersect(prim, ray, t_max)?;
            best = Some(Hit { t, prim, u, v });
            Some(t)
        })?;
        best
    }

    /// Whether anything blocks `ray` before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel.any_hit(ray, t_max, |prim, t_max| {
            self.prims.intersect(prim, ray, t_max).is_some()
        })
    }
}
