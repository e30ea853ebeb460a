//! Scene file → ECS world: parse, apply `--set` overrides, spawn one entity per object.

use super::assets::AssetPolicy;
use super::error::{SceneError, context_at, offset_of};
use super::{patch, schema};
use crate::components::camera::{CameraKey, CameraPath};
use crate::components::{Camera, Material, Motion, Name, Shape, Transform};
use glam::{Affine3A, Quat, Vec3};
use std::path::{Path, PathBuf};

/// Integrator and image settings, after overrides.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Scattering events after which a path ends.
    pub max_depth: u32,
    /// Seed of the sampler: different seeds give independent images.
    pub seed: u64,
    /// Next-event estimation with MIS, or pure path tracing.
    pub light_sampling: schema::LightSampling,
    /// Scattering events before Russian roulette starts.
    pub rr_depth: u32,
    /// Exact or Schlick Fresnel term at dielectrics.
    pub fresnel: schema::Fresnel,
    /// Wavelengths per path in spectral transport: 1 ends the secondary wavelengths at once,
    /// any other value (up to 4) carries four.
    pub wavelengths: u32,
    /// Owen-scrambled Sobol or independent samples.
    pub sampler: schema::SamplerChoice,
    /// In media, also sample distances towards lights (equiangular sampling, MIS).
    pub equiangular: bool,
    /// The pixel filter camera samples are drawn from.
    pub filter: schema::Filter,
    /// Paths from the camera or from the lights.
    pub kind: schema::Estimator,
    /// The lane width the scene asks for (`--simd` overrides it).
    pub simd: crate::simd::SimdChoice,
    /// Render until the estimated relMSE is at most this (`--target-error` overrides it).
    pub target_error: Option<f64>,
}

/// A loaded scene: the world of entities and the resources beside it.
pub struct LoadedScene {
    /// The scene file, for messages and to resolve asset paths.
    pub path: PathBuf,
    /// One entity per scene object, with its components.
    pub world: hecs::World,
    /// The camera as the file describes it; a path's keyframes override its placement.
    pub camera: Camera,
    /// The animated camera path, when the scene has keyframes.
    pub camera_path: Option<CameraPath>,
    /// Render settings, overrides applied.
    pub render: RenderSettings,
    /// Radiance of the constant environment (zero when absent).
    pub environment: Vec3,
    /// What spectral transport evaluates for the environment.
    pub environment_spectrum: crate::spectrum::EmitterSpectrum,
    /// The environment map, when the environment is an `Image`.
    pub environment_map: Option<std::sync::Arc<crate::scene::envmap::EnvMap>>,
    /// The daylight sky, when the environment is a `Sky` (`environment_map` then holds its
    /// tabulation, which guides sampling).
    pub sky: Option<std::sync::Arc<crate::scene::sky::Sky>>,
    /// Hash of the scene text and every override except the sample count, so renders of the
    /// same scene with different sample ranges can be matched.
    pub hash: u64,
}

/// Reads and parses a scene file, with `--set` overrides applied; its mesh and image paths
/// must satisfy [`AssetPolicy::for_scene`] (inside the scene folder's parent by default).
pub fn load(path: &Path, overrides: &[(String, String)]) -> Result<LoadedScene, SceneError> {
    load_with(path, overrides, &AssetPolicy::for_scene(path))
}

/// [`load`] with an explicit asset policy.
pub fn load_with(
    path: &Path,
    overrides: &[(String, String)],
    assets: &AssetPolicy,
) -> Result<LoadedScene, SceneError> {
    let text =
        crate::files::read_text_bounded(path, crate::files::MAX_SCENE_BYTES).map_err(|source| {
            SceneError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
    load_text(&text, path, overrides, assets)
}

/// Parses scene text; `path` is used in messages and to resolve relative asset paths, which
/// may lie anywhere (the caller chose the text; [`load`] applies the asset root to files).
pub fn load_str(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    load_text(text, path, overrides, &AssetPolicy::Any)
}

fn load_text(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
    assets: &AssetPolicy,
) -> Result<LoadedScene, SceneError> {
    let mut hash = fnv1a(text.as_bytes(), FNV_OFFSET);
    // Entity paths edit the text, so their values are read and checked as the file's own.
    let mut patched = std::borrow::Cow::Borrowed(text);
    let mut spans: Vec<(&str, std::ops::Range<usize>)> = Vec::new();
    for (k, v) in overrides.iter().filter(|(k, _)| patch::is_entity_path(k)) {
        let (new, span) = patch::apply(&patched, k, v).map_err(|message| SceneError::Override {
            key: k.clone(),
            message,
        })?;
        let delta = new.len() as isize - patched.len() as isize;
        for (_, s) in &mut spans {
            if s.start >= span.start {
                *s = s.start.saturating_add_signed(delta)..s.end.saturating_add_signed(delta);
            }
        }
        spans.push((k, span));
        patched = std::borrow::Cow::Owned(new);
    }
    let mut scene = parse(&patched, path).map_err(|e| match &e {
        SceneError::Parse {
            line, col, message, ..
        } => {
            let at = offset_of(&patched, *line, *col);
            match spans.iter().find(|(_, s)| s.start <= at && at <= s.end) {
                Some((k, s)) => SceneError::Override {
                    key: k.to_string(),
                    message: format!("cannot use '{}': {message}", &patched[s.clone()]),
                },
                None => e,
            }
        }
        _ => e,
    })?;
    for (k, v) in overrides {
        if !patch::is_entity_path(k) {
            apply_override(&mut scene, k, v)?;
        }
        // Like the sample count, the target decides how many samples, not which: batches
        // rendered to different targets still merge.
        if k != "render.spp" && k != "render.target_error" {
            hash = fnv1a(k.as_bytes(), hash);
            hash = fnv1a(v.as_bytes(), hash);
        }
    }
    // The file's own size was checked as it was read; an override may have grown it.
    if let Some((k, _)) = overrides
        .iter()
        .rev()
        .find(|(k, _)| k == "render.width" || k == "render.height")
    {
        schema::check_film_size(scene.render.width.0, scene.render.height.0).map_err(
            |message| SceneError::Override {
                key: k.clone(),
                message,
            },
        )?;
    }
    build_world(scene, path, hash, assets).map_err(|e| e.located(&patched))
}

/// Deserialises the schema, turning RON's error position into file:line:col with the entity
/// and field it falls in.
pub fn parse(text: &str, path: &Path) -> Result<schema::Scene, SceneError> {
    ron_options().from_str::<schema::Scene>(text).map_err(|e| {
        let pos = e.span.start;
        let at = offset_of(text, pos.line, pos.col);
        let (entity, mut field) = context_at(text, at);
        let mut message = e.code.to_string();
        // A check of several fields together is raised where the group ends, after its last
        // field: such messages name their own field as "field `NAME`: ...".
        if let Some(rest) = message.strip_prefix("field `")
            && let Some((name, why)) = rest.split_once("`: ")
        {
            field = Some(name.to_string());
            message = why.to_string();
        }
        // RON's own words name no range.
        if matches!(e.code, ron::Error::IntegerOutOfBounds) {
            message = format!(
                "the number is out of range: must be {}",
                integer_range(field.as_deref())
            );
        }
        // A bare tuple where an enum is expected (`albedo: (0.8, 0.3, 0.2)`): RON's own words
        // do not say what is missing.
        if matches!(e.code, ron::Error::ExpectedIdentifier) && text[at..].starts_with('(') {
            message.push_str(
                ": name the kind of value before its parenthesis, e.g. `Rgb(0.8, 0.3, 0.2)` \
                 for a colour (docs/scene-format.md lists them)",
            );
        }
        SceneError::Parse {
            path: path.to_path_buf(),
            line: pos.line,
            col: pos.col,
            entity,
            field,
            message,
        }
    })
}

/// The valid range of an integer field, for a number too large (or negative) for its type.
fn integer_range(field: Option<&str>) -> &'static str {
    match field {
        Some("width" | "height") => "in 1..=65536 pixels",
        Some("spp") => "in 1..=4294967295 samples per pixel",
        Some("max_depth") => "in 0..=1024 scattering events",
        Some("blades") => "0 (round) or 3..=64",
        Some("wavelengths") => "1 or 4",
        Some("fps") => "in 1..=1000",
        Some("seed") => "in 0..=18446744073709551615",
        Some("rr_depth" | "frame") => "in 0..=4294967295",
        _ => "a whole number in 0..=4294967295 (0..=18446744073709551615 for `seed`)",
    }
}

/// RON options for scene files: optional fields may be written bare (`lens: (..)`) or as
/// `Some(..)`, whether or not the file enables `implicit_some` itself.
pub fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The keys `--set` understands, with the type their value is parsed as.
pub const OVERRIDE_KEYS: &[&str] = &[
    "render.width",
    "render.height",
    "render.spp",
    "render.max_depth",
    "render.seed",
    "render.integrator.light_sampling",
    "render.integrator.rr_depth",
    "render.integrator.fresnel",
    "render.integrator.wavelengths",
    "render.integrator.sampler",
    "render.integrator.equiangular",
    "render.integrator.kind",
    "render.filter",
    "render.simd",
    "camera.position",
    "camera.look_at",
    "camera.up",
    "camera.fov_y",
    "camera.lens.aperture_radius",
    "camera.lens.focus_distance",
    "camera.lens.blades",
    "render.newton_tolerance",
    "render.target_error",
    "environment",
];

/// Applies one `--set KEY=VALUE`; VALUE is RON for the field's type (`Schlick`, `64`,
/// `(0.0, 1.0, 5.0)`), checked like the field in the file.
pub fn apply_override(scene: &mut schema::Scene, key: &str, value: &str) -> Result<(), SceneError> {
    fn val<T: serde::de::DeserializeOwned>(key: &str, value: &str) -> Result<T, SceneError> {
        ron_options()
            .from_str(value)
            .map_err(|e| SceneError::Override {
                key: key.to_string(),
                message: format!("cannot use '{value}': {}", e.code),
            })
    }
    let r = &mut scene.render;
    let c = &mut scene.camera;
    let lens = || schema::Lens {
        aperture_radius: schema::NonNegative(0.0),
        focus_distance: schema::Positive(1.0),
        blades: schema::Blades(0),
    };
    match key {
        "render.width" => r.width = val(key, value)?,
        "render.height" => r.height = val(key, value)?,
        "render.spp" => r.spp = val(key, value)?,
        "render.max_depth" => r.max_depth = val(key, value)?,
        "render.seed" => r.seed = val(key, value)?,
        "render.integrator.light_sampling" => r.integrator.light_sampling = val(key, value)?,
        "render.integrator.rr_depth" => r.integrator.rr_depth = val(key, value)?,
        "render.integrator.fresnel" => r.integrator.fresnel = val(key, value)?,
        "render.integrator.wavelengths" => r.integrator.wavelengths = val(key, value)?,
        "render.integrator.sampler" => r.integrator.sampler = val(key, value)?,
        "render.integrator.equiangular" => r.integrator.equiangular = val(key, value)?,
        "render.integrator.kind" => r.integrator.kind = val(key, value)?,
        "render.filter" => r.filter = val(key, value)?,
        // `auto` as the CLI spells it, or a width.
        "render.simd" => {
            r.simd = value.parse().map_err(|message| SceneError::Override {
                key: key.to_string(),
                message,
            })?
        }
        "camera.position" => c.position = val(key, value)?,
        "camera.look_at" => c.look_at = val(key, value)?,
        "camera.up" => c.up = val(key, value)?,
        "camera.fov_y" => c.fov_y = val(key, value)?,
        "camera.lens.aperture_radius" => {
            c.lens.get_or_insert_with(lens).aperture_radius = val(key, value)?
        }
        "camera.lens.focus_distance" => {
            c.lens.get_or_insert_with(lens).focus_distance = val(key, value)?
        }
        "camera.lens.blades" => c.lens.get_or_insert_with(lens).blades = val(key, value)?,
        "render.newton_tolerance" => r.newton_tolerance = Some(val(key, value)?),
        "render.target_error" => r.target_error = Some(val(key, value)?),
        "environment" => scene.environment = Some(val(key, value)?),
        _ => {
            return Err(SceneError::Override {
                key: key.to_string(),
                message: format!(
                    "unknown key; valid keys: {}, and entity fields as entities[INDEX].field or \
                     entities[\"NAME\"].field",
                    OVERRIDE_KEYS.join(", ")
                ),
            });
        }
    }
    Ok(())
}

fn transform_of(t: &Option<schema::Transform>) -> Transform {
    let Some(t) = t else {
        return Transform::default();
    };
    let s = t.scale.map_or(Vec3::ONE, |s| Vec3::from_array(s.0));
    let r = t.rotate.map_or(Vec3::ZERO, |r| r.vec());
    let rot = Quat::from_rotation_z(r.z.to_radians())
        * Quat::from_rotation_y(r.y.to_radians())
        * Quat::from_rotation_x(r.x.to_radians());
    let tr = t.translate.map_or(Vec3::ZERO, |t| t.vec());
    let uniform = (s.x.abs() == s.y.abs() && s.y.abs() == s.z.abs()).then_some(s.x.abs());
    Transform {
        to_world: Affine3A::from_scale_rotation_translation(s, rot, tr),
        uniform_scale: uniform,
    }
}

fn build_world(
    scene: schema::Scene,
    path: &Path,
    hash: u64,
    assets: &AssetPolicy,
) -> Result<LoadedScene, SceneError> {
    let cam = &scene.camera;
    let (pos, at, up) = (cam.position.vec(), cam.look_at.vec(), cam.up.vec());
    let fwd = at - pos;
    if fwd.length_squared() == 0.0
        || fwd.cross(up).length_squared() <= 1e-12 * fwd.length_squared() * up.length_squared()
    {
        return Err(SceneError::Entity {
            path: path.to_path_buf(),
            at: None,
            key: "camera.look_at".into(),
            entity: "camera".into(),
            field: "look_at",
            message: "look_at must differ from position, and up must not be parallel to the view direction".into(),
        });
    }
    let camera = Camera {
        position: pos,
        look_at: at,
        up,
        fov_y: cam.fov_y.0,
        aperture_radius: cam.lens.as_ref().map_or(0.0, |l| l.aperture_radius.0),
        focus_distance: cam.lens.as_ref().map_or(1.0, |l| l.focus_distance.0),
        blades: cam.lens.as_ref().map_or(0, |l| l.blades.0),
        shutter: cam
            .shutter
            .as_ref()
            .map_or((0.0, 1.0), |s| (s.open, s.close)),
    };
    let r = &scene.render;
    let render = RenderSettings {
        width: r.width.0,
        height: r.height.0,
        spp: r.spp.0,
        max_depth: r.max_depth.0,
        seed: r.seed,
        light_sampling: r.integrator.light_sampling,
        rr_depth: r.integrator.rr_depth,
        fresnel: r.integrator.fresnel,
        wavelengths: r.integrator.wavelengths.0,
        sampler: r.integrator.sampler,
        equiangular: r.integrator.equiangular,
        filter: r.filter,
        kind: r.integrator.kind,
        simd: r.simd,
        target_error: r.target_error.map(|t| t.0),
    };
    let camera_path = scene.animation.as_ref().map(|a| CameraPath {
        fps: a.fps,
        keys: a
            .keyframes
            .iter()
            .map(|k| CameraKey {
                frame: k.frame as f32,
                position: k.position.vec(),
                look_at: k.look_at.vec(),
                up: k.up.map_or(camera.up, |u| u.vec()),
                fov_y: k.fov_y.map_or(camera.fov_y, |f| f.0),
                focus_distance: k.focus_distance.map_or(camera.focus_distance, |f| f.0),
            })
            .collect(),
    });
    if let Some(cp) = &camera_path {
        for (i, k) in cp.keys.iter().enumerate() {
            let fwd = k.look_at - k.position;
            if fwd.length_squared() == 0.0
                || fwd.cross(k.up).length_squared()
                    <= 1e-12 * fwd.length_squared() * k.up.length_squared()
            {
                return Err(SceneError::Entity {
                    path: path.to_path_buf(),
                    at: None,
                    key: format!("animation.keyframes[{i}].look_at").into(),
                    entity: format!("animation keyframe {i}"),
                    field: "look_at",
                    message: "look_at must differ from position, and up must not be parallel to the view direction".into(),
                });
            }
        }
    }
    let mut environment_map = None;
    let mut sky = None;
    let (environment, environment_spectrum) = match &scene.environment {
        Some(schema::Environment::Constant(e)) => (e.rgb, e.spectrum),
        Some(schema::Environment::Image {
            path: p,
            scale,
            rotate,
        }) => {
            let err = |message: String| SceneError::Entity {
                path: path.to_path_buf(),
                at: None,
                key: "environment.path".into(),
                entity: "environment".into(),
                field: "path",
                message,
            };
            let scene_dir = path.parent().unwrap_or(Path::new("."));
            assets.check(scene_dir, &p.0).map_err(err)?;
            let (img, _) = crate::imageio::read_image(&scene_dir.join(&p.0))
                .map_err(|e| err(e.to_string()))?;
            let map = crate::scene::envmap::EnvMap::new(
                img.width,
                img.height,
                &img.pixels,
                scale.map_or(1.0, |s| s.0),
                rotate.map_or(Vec3::ZERO, |r| r.vec()),
            )
            .map_err(|e| err(e.to_string()))?
            .with_source(&p.0);
            environment_map = Some(std::sync::Arc::new(map));
            (Vec3::ZERO, crate::spectrum::EmitterSpectrum::Rgb)
        }
        Some(schema::Environment::Sky {
            sun_elevation,
            sun_azimuth,
            turbidity,
            ground_albedo,
            sun,
            scale,
        }) => {
            let s = crate::scene::sky::Sky::new(crate::scene::sky::SkyParams {
                sun_elevation: sun_elevation.0,
                sun_azimuth: sun_azimuth.map_or(0.0, |a| a.0),
                turbidity: turbidity.map_or(3.0, |t| t.0),
                ground_albedo: ground_albedo.map_or(Vec3::splat(0.3), |a| a.0.vec()),
                sun: sun.unwrap_or(true),
                scale: scale.map_or(1.0, |s| s.0),
            });
            // 512 × 256 texels (0.7° each) guide the sky's sampling; the sun is a light of
            // its own.
            let map = s.tabulate(512, 256).map_err(|e| SceneError::Entity {
                path: path.to_path_buf(),
                at: None,
                key: "environment".into(),
                entity: "environment".into(),
                field: "Sky",
                message: e.to_string(),
            })?;
            environment_map = Some(std::sync::Arc::new(map));
            sky = Some(std::sync::Arc::new(s));
            (Vec3::ZERO, crate::spectrum::EmitterSpectrum::Rgb)
        }
        None => (Vec3::ZERO, crate::spectrum::EmitterSpectrum::Rgb),
    };

    let mut world = hecs::World::new();
    // One cache per scene: an image used by several entities is decoded once.
    let mut textures = crate::texture::TextureCache::default();
    let scene_dir = path.parent().unwrap_or(Path::new("."));
    let mut meshes: std::collections::HashMap<
        PathBuf,
        std::sync::Arc<crate::geometry::TriangleMesh>,
    > = std::collections::HashMap::new();
    for (i, e) in scene.entities.iter().enumerate() {
        let name = e.name.clone().unwrap_or_else(|| format!("#{i}"));
        let err = |field: &'static str, message: String| SceneError::Entity {
            path: path.to_path_buf(),
            at: None,
            key: format!("entities[{i}].{field}").into(),
            entity: name.clone(),
            field,
            message,
        };
        let transform = transform_of(&e.transform);
        // Files are checked against the asset root before anything reads them.
        if let Some(schema::Shape::Mesh { path: p }) = &e.shape {
            assets.check(scene_dir, p).map_err(|m| err("shape", m))?;
        }
        if let Some(t) = &e.texture {
            if let Some(schema::AlbedoSpec::Image { path: p, .. }) = &t.albedo {
                assets
                    .check(scene_dir, &p.0)
                    .map_err(|m| err("texture", m))?;
            }
            if let Some(schema::NormalMapSpec::Image { path: p, .. }) = &t.normal_map {
                assets
                    .check(scene_dir, &p.0)
                    .map_err(|m| err("texture", m))?;
            }
        }
        if let Some(l) = &e.light {
            if e.shape.is_some() || e.material.is_some() {
                return Err(err(
                    "light",
                    "a point or spot light has no shape or material; use a Light material for an area light".into(),
                ));
            }
            // Refused rather than ignored: a point light neither moves, fills a medium nor
            // carries a texture.
            for (field, present) in [
                ("motion", e.motion.is_some()),
                ("medium", e.medium.is_some()),
                ("texture", e.texture.is_some()),
            ] {
                if present {
                    return Err(err(
                        field,
                        format!(
                            "a point or spot light takes no {field}: it is placed by its position (and transform) alone"
                        ),
                    ));
                }
            }
            let light = match l {
                schema::LightSpec::Point {
                    position,
                    intensity,
                } => crate::components::light::PointLight {
                    position: transform.to_world.transform_point3(position.vec()),
                    direction: glam::Vec3::NEG_Y,
                    intensity: intensity.rgb,
                    spectrum: intensity.spectrum,
                    cos_cone: -1.0,
                    cos_falloff_start: -1.0,
                },
                schema::LightSpec::Spot {
                    position,
                    direction,
                    cone,
                    falloff,
                    intensity,
                } => crate::components::light::PointLight {
                    position: transform.to_world.transform_point3(position.vec()),
                    direction: transform
                        .to_world
                        .transform_vector3(direction.vec())
                        .normalize(),
                    intensity: intensity.rgb,
                    spectrum: intensity.spectrum,
                    cos_cone: cone.to_radians().cos(),
                    cos_falloff_start: (cone - falloff).to_radians().cos(),
                },
            };
            world.spawn((Name(name), light));
            continue;
        }
        let Some(shape) = &e.shape else {
            return Err(err(
                "shape",
                "every entity needs a shape (or a light: Point or Spot)".into(),
            ));
        };
        let shape = match shape.clone() {
            schema::Shape::Sphere { center, radius } => {
                if transform.uniform_scale.is_none() {
                    return Err(err(
                        "transform",
                        "a Sphere takes a uniform scale only (a non-uniform one would make an ellipsoid)".into(),
                    ));
                }
                Shape::Sphere {
                    center: center.vec(),
                    radius: radius.0,
                }
            }
            schema::Shape::Rect { center, u, v } => Shape::Rect {
                center: center.vec(),
                u: u.vec(),
                v: v.vec(),
            },
            schema::Shape::Disk {
                center,
                normal,
                radius,
            } => Shape::Disk {
                center: center.vec(),
                normal: normal.vec().normalize(),
                radius: radius.0,
            },
            schema::Shape::Box { min, max } => Shape::Box {
                min: min.vec(),
                max: max.vec(),
            },
            schema::Shape::Mesh { path: p } => {
                let file = scene_dir.join(&p);
                let key = file.canonicalize().unwrap_or_else(|_| file.clone());
                let mesh = match meshes.get(&key) {
                    Some(m) => m.clone(),
                    None => {
                        let m = crate::geometry::mesh_io::load_mesh(&file)
                            .map_err(|me| err("shape", format!("Mesh: {me}")))?;
                        let m = std::sync::Arc::new(m);
                        meshes.insert(key, m.clone());
                        m
                    }
                };
                Shape::Mesh(mesh)
            }
            schema::Shape::Revolution { profile, tolerance } => {
                let tol = scene
                    .render
                    .newton_tolerance
                    .map(|t| t.0)
                    .or(tolerance)
                    .unwrap_or(crate::geometry::revolution::DEFAULT_TOLERANCE);
                let rev = crate::geometry::Revolution::new(&profile, tol)
                    .map_err(|m| err("shape", format!("Revolution: {m}")))?;
                Shape::Revolution(std::sync::Arc::new(rev))
            }
        };
        let medium = e
            .medium
            .as_ref()
            .map(|m| crate::medium::HomogeneousMedium::new(m.sigma_a.vec(), m.sigma_s.vec(), m.g));
        if medium.is_some() && !matches!(shape, Shape::Sphere { .. } | Shape::Box { .. }) {
            return Err(err(
                "medium",
                "a medium needs a closed Sphere or Box around it (its inside must be decidable)"
                    .into(),
            ));
        }
        let material = match &e.material {
            None if medium.is_some() => Material::Boundary,
            None => {
                return Err(err(
                    "material",
                    "a shape needs a material (Diffuse, Mirror, Conductor, Dielectric, Plastic or Light)"
                        .into(),
                ));
            }
            Some(schema::Material::Diffuse { albedo }) => Material::Diffuse {
                albedo: albedo.0.vec(),
            },
            Some(schema::Material::Mirror { tint }) => Material::Mirror { tint: tint.0.vec() },
            Some(schema::Material::Plastic {
                albedo,
                ior,
                alpha,
                roughness,
            }) => {
                let ior = ior.unwrap_or(1.5);
                if !(1.0..=3.0).contains(&ior) {
                    return Err(err("material.ior", format!("must be in [1, 3], got {ior}")));
                }
                Material::Plastic {
                    albedo: albedo.0.vec(),
                    ior,
                    alpha: rough_alpha(*alpha, *roughness).map_err(|(field, m)| err(field, m))?,
                }
            }
            Some(schema::Material::Dielectric {
                ior,
                alpha,
                roughness,
                multiscatter,
            }) => Material::Dielectric {
                ior: ior.0,
                alpha: rough_alpha(*alpha, *roughness).map_err(|(field, m)| err(field, m))?,
                multiscatter: multiscatter.unwrap_or(true),
            },
            Some(schema::Material::Conductor {
                metal,
                eta,
                k,
                reflectance,
                alpha,
                roughness,
                multiscatter,
            }) => conductor(*metal, *eta, *k, *reflectance, *alpha, *roughness)
                .map(|m| match m {
                    Material::Conductor { ior, alpha, .. } => Material::Conductor {
                        ior,
                        alpha,
                        multiscatter: multiscatter.unwrap_or(true),
                    },
                    m => m,
                })
                .map_err(|(field, m)| err(field, m))?,
            Some(schema::Material::Light {
                emission,
                two_sided,
            }) => {
                if matches!(
                    shape,
                    Shape::Box { .. } | Shape::Revolution(_) | Shape::Mesh(_)
                ) {
                    return Err(err(
                        "material",
                        "a Light needs a Sphere, Rect or Disk (area lights are sampled on those)"
                            .into(),
                    ));
                }
                Material::Light {
                    emission: emission.rgb,
                    two_sided: *two_sided,
                    spectrum: emission.spectrum,
                }
            }
        };
        if medium.is_some()
            && matches!(
                material,
                Material::Mirror { .. }
                    | Material::Plastic { .. }
                    | Material::Light { .. }
                    | Material::Diffuse { .. }
                    | Material::Conductor { .. }
            )
        {
            return Err(err(
                "medium",
                "a medium fills a pure boundary (no material) or a Dielectric; an opaque surface would hide it".into(),
            ));
        }
        if let Some(t) = &e.texture
            && t.roughness.is_some()
            && material.alpha().is_none()
        {
            return Err(err(
                "texture.roughness",
                "a roughness texture needs a Conductor, Dielectric or Plastic".into(),
            ));
        }
        if let Shape::Mesh(m) = &shape
            && m.uvs().is_none()
            && material.alpha().is_some_and(|a| a.is_anisotropic())
        {
            return Err(err(
                "material.alpha",
                "this mesh has no UVs (vt lines or PLY u/v): an anisotropic roughness needs \
                 them for its tangent direction"
                    .into(),
            ));
        }
        if let (Some(_), Shape::Mesh(m)) = (&e.texture, &shape)
            && m.uvs().is_none()
        {
            return Err(err(
                "texture",
                "this mesh has no UVs (vt lines or PLY u/v), so a texture cannot be placed on it"
                    .into(),
            ));
        }
        let texture = match &e.texture {
            Some(spec) => Some(
                spec.build(scene_dir, &mut textures)
                    .map_err(|te| err("texture", te.to_string()))?,
            ),
            None => None,
        };
        let entity = world.spawn((Name(name), shape, transform, material));
        if let Some(t) = texture {
            world
                .insert_one(entity, t)
                .expect("entity was just spawned");
        }
        if let Some(m) = medium {
            world
                .insert_one(entity, m)
                .expect("entity was just spawned");
        }
        if let Some(m) = &e.motion {
            let motion = Motion {
                velocity: m.velocity.map_or(glam::Vec3::ZERO, |v| v.vec()),
                angular_velocity: m.angular_velocity.map_or(glam::Vec3::ZERO, |v| v.vec()),
            };
            if !motion.is_static() {
                world
                    .insert_one(entity, motion)
                    .expect("entity was just spawned");
            }
        }
    }
    Ok(LoadedScene {
        path: path.to_path_buf(),
        world,
        camera,
        camera_path,
        render,
        environment,
        environment_spectrum,
        environment_map,
        sky,
        hash,
    })
}

/// A `Conductor` from its scene fields: exactly one source of its Fresnel term, at most one
/// of `alpha` and `roughness`, each value in its range. An error names the field it is about.
fn conductor(
    metal: Option<crate::spectrum::Metal>,
    eta: Option<schema::Color>,
    k: Option<schema::Color>,
    reflectance: Option<schema::Albedo>,
    alpha: Option<schema::Rough>,
    roughness: Option<schema::Rough>,
) -> Result<Material, (&'static str, String)> {
    use crate::components::ConductorIor;
    let complex = |c: schema::Color, field: &'static str, lo_open: bool| {
        let v = c.vec();
        let ok = v.is_finite()
            && v.max_element() <= 100.0
            && if lo_open {
                v.min_element() > 0.0
            } else {
                v.min_element() >= 0.0
            };
        if ok {
            Ok(v)
        } else {
            let range = if lo_open { "(0, 100]" } else { "[0, 100]" };
            Err((
                field,
                format!(
                    "every channel must be in {range}, got Rgb({}, {}, {})",
                    v.x, v.y, v.z
                ),
            ))
        }
    };
    let ior = match (metal, eta, k, reflectance) {
        (Some(m), None, None, None) => ConductorIor::metal(m),
        (None, Some(eta), Some(k), None) => ConductorIor::Complex {
            eta: complex(eta, "material.eta", true)?,
            k: complex(k, "material.k", false)?,
        },
        (None, None, None, Some(r)) => ConductorIor::Reflectance(r.0.vec()),
        (None, Some(_), None, None) => {
            return Err(("material.k", "`eta` needs `k` beside it".into()));
        }
        (None, None, Some(_), None) => {
            return Err(("material.eta", "`k` needs `eta` beside it".into()));
        }
        (None, None, None, None) => {
            return Err((
                "material",
                "a Conductor needs `metal`, `eta` with `k`, or `reflectance`".into(),
            ));
        }
        _ => {
            return Err((
                "material",
                "a Conductor takes one of `metal`, `eta` with `k`, or `reflectance`, not several"
                    .into(),
            ));
        }
    };
    Ok(Material::Conductor {
        ior,
        alpha: rough_alpha(alpha, roughness)?,
        multiscatter: true,
    })
}

/// A rough material's GGX α from its `alpha` or `roughness` field (α = roughness²; a pair
/// is anisotropic), each value in [0, 1], at most one of them; neither is smooth (α = 0).
fn rough_alpha(
    alpha: Option<schema::Rough>,
    roughness: Option<schema::Rough>,
) -> Result<crate::components::Alpha, (&'static str, String)> {
    use crate::components::Alpha;
    let unit = |r: schema::Rough, field: &'static str| {
        let schema::Rough(x, y) = r;
        if (0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y) {
            Ok(Alpha { x, y })
        } else if x == y {
            Err((field, format!("must be in [0, 1], got {x}")))
        } else {
            Err((
                field,
                format!("each of the pair must be in [0, 1], got ({x}, {y})"),
            ))
        }
    };
    match (alpha, roughness) {
        (Some(_), Some(_)) => Err((
            "material.roughness",
            "give `alpha` or `roughness` (α = roughness²), not both".into(),
        )),
        (Some(a), None) => unit(a, "material.alpha"),
        (None, Some(r)) => unit(r, "material.roughness").map(|r| Alpha {
            x: r.x * r.x,
            y: r.y * r.y,
        }),
        (None, None) => Ok(Alpha::ZERO),
    }
}
