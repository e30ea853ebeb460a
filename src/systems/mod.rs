//! Systems: plain functions over `&World` that build the render-time scene
//! ([`crate::scene::RenderScene`]): the effects manifest, the flat primitive arrays, the
//! kd-tree and the light list, which live beside the world.

pub mod effects;
pub mod lights;
pub mod primitives;

pub use effects::detect_effects;
pub use lights::gather_lights;
pub use primitives::gather_primitives;

use crate::geometry::Aabb;
use crate::kdtree::{KdParams, KdTree};
use crate::scene::{Primitives, RenderScene};
use crate::scene_file::LoadedScene;

/// Builds the acceleration structure over the gathered primitives.
pub fn build_accel(prims: &Primitives, params: &KdParams) -> KdTree {
    KdTree::build(prims, params)
}

/// Runs the systems in order for frame 0: effects, primitives, kd-tree, lights.
pub fn prepare(scene: &LoadedScene, params: &KdParams) -> RenderScene {
    prepare_frame(scene, params, 0)
}

/// The shutter interval of `frame` in scene time.
pub fn shutter_of(scene: &LoadedScene, frame: u32) -> (f32, f32) {
    let (open, close) = scene.camera.shutter;
    (frame as f32 + open, frame as f32 + close)
}

/// Runs the systems for one frame of the scene.
pub fn prepare_frame(scene: &LoadedScene, params: &KdParams, frame: u32) -> RenderScene {
    let shutter = shutter_of(scene, frame);
    let effects = detect_effects(
        &scene.world,
        &scene.camera,
        scene.camera_path.as_ref(),
        shutter,
        &scene.environment_spectrum,
        scene.sky.as_deref(),
    );
    let mut prims = gather_primitives(&scene.world);
    prims.sweep = shutter;
    let t0 = std::time::Instant::now();
    let accel = build_accel(&prims, params);
    let accel_seconds = t0.elapsed().as_secs_f64();
    let bounds: Aabb = accel.bounds();
    let lights = gather_lights(
        &scene.world,
        &mut prims,
        scene.environment,
        scene.environment_map.as_ref(),
        scene.sky.as_ref(),
        &bounds,
    );
    let s = &scene.render;
    let camera_at = |t: f32| match &scene.camera_path {
        Some(p) => p.at(t, &scene.camera),
        None => scene.camera,
    };
    let camera_moves = scene
        .camera_path
        .as_ref()
        .is_some_and(|p| p.moves_within(shutter.0, shutter.1));
    RenderScene {
        camera: camera_at(shutter.0).frame(s.width, s.height),
        base_camera: scene.camera,
        camera_path: scene.camera_path.clone(),
        camera_moves,
        camera_medium: prims.medium_at(camera_at(shutter.0).position),
        frame,
        shutter,
        prims,
        accel,
        lights,
        environment: scene.environment,
        environment_spectrum: scene.environment_spectrum,
        effects,
        settings: s.clone(),
        accel_seconds,
    }
}

impl RenderScene {
    /// Moves a prepared scene to another frame of the same loaded scene: the camera follows
    /// its path, and the kd-tree is rebuilt only when primitives move (their bounds cover
    /// the new shutter interval). A static scene keeps its tree for the whole series.
    pub fn set_frame(&mut self, scene: &LoadedScene, params: &KdParams, frame: u32) {
        let shutter = shutter_of(scene, frame);
        self.frame = frame;
        self.shutter = shutter;
        self.effects = detect_effects(
            &scene.world,
            &scene.camera,
            scene.camera_path.as_ref(),
            shutter,
            &scene.environment_spectrum,
            scene.sky.as_deref(),
        );
        let cam = match &scene.camera_path {
            Some(p) => p.at(shutter.0, &scene.camera),
            None => scene.camera,
        };
        self.camera = cam.frame(self.settings.width, self.settings.height);
        self.camera_moves = scene
            .camera_path
            .as_ref()
            .is_some_and(|p| p.moves_within(shutter.0, shutter.1));
        if self.prims.has_motion() {
            self.prims.sweep = shutter;
            let t0 = std::time::Instant::now();
            self.accel = build_accel(&self.prims, params);
            self.accel_seconds = t0.elapsed().as_secs_f64();
        }
    }
}
