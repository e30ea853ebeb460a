//! Criterion benches of the spine: one function per operation.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use prism::geometry::{Aabb, Ray};
use prism::integrator::{Ctx, RenderOptions, generate::camera_rays as lane_camera_rays, render};
use prism::kdtree::{KdParams, KdTree};
use prism::sampling::{Sampler, SamplerKind, square_to_uniform_sphere};
use prism::scene::RenderScene;
use prism::systems::prepare;
use std::hint::black_box;
use std::path::Path;

fn cornell(size: u32, spp: u32) -> RenderScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let o = vec![
        ("render.width".to_string(), size.to_string()),
        ("render.height".to_string(), size.to_string()),
        ("render.spp".to_string(), spp.to_string()),
    ];
    prepare(
        &prism::scene_file::load(&path, &o).unwrap(),
        &KdParams::default(),
    )
}

/// Scene text prepared for rendering at `w`×`h` (the path resolves relative assets).
fn scene_text(text: &str, path: &Path, w: u32, h: u32) -> RenderScene {
    let o = vec![
        ("render.width".to_string(), w.to_string()),
        ("render.height".to_string(), h.to_string()),
    ];
    prepare(
        &prism::scene_file::load_str(text, path, &o).unwrap(),
        &KdParams::default(),
    )
}

/// Render options for `spp` samples per pixel at the widest native width.
fn opts(spp: u32) -> RenderOptions {
    RenderOptions::new(spp, prism::simd::Lanes::auto())
}

fn random_boxes(n: usize) -> Vec<Aabb> {
    let s = Sampler::new(SamplerKind::Independent, 1);
    (0..n as u32)
        .map(|i| {
            let c = Vec3::new(s.get_1d(i, 0, 0), s.get_1d(i, 0, 1), s.get_1d(i, 0, 2)) * 100.0;
            let e = Vec3::new(s.get_1d(i, 0, 3), s.get_1d(i, 0, 4), s.get_1d(i, 0, 5)) + 0.1;
            Aabb::new(c - e, c + e)
        })
        .collect()
}

fn kdtree(c: &mut Criterion) {
    let mut g = c.benchmark_group("kdtree");
    let boxes = random_boxes(10_000);
    g.bench_function("build_10k_boxes", |b| {
        b.iter(|| KdTree::build(black_box(&boxes[..]), &KdParams::default()))
    });
    let scene = cornell(64, 1);
    let s = Sampler::new(SamplerKind::Independent, 3);
    let rays: Vec<Ray> = (0..4096u32)
        .map(|i| {
            let o = Vec3::new(278.0, 273.0, 250.0)
                + square_to_uniform_sphere(s.get_2d(i, 0, 0)) * 100.0;
            Ray::new(o, square_to_uniform_sphere(s.get_2d(i, 0, 2)))
        })
        .collect();
    g.bench_function("closest_hit_cornell_4096", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| scene.intersect::<false>(r, f32::INFINITY, 0.0).is_some())
                .count()
        })
    });
    g.bench_function("any_hit_cornell_4096", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| scene.occluded::<false>(r, 300.0, 0.0))
                .count()
        })
    });
    g.finish();
}

fn camera_rays<const MOTION: bool>(ctx: &Ctx) -> Vec2 {
    let mut acc = Vec2::ZERO;
    for y in 0..64 {
        for x in 0..64 {
            let r = lane_camera_rays::<f32, MOTION>(ctx, x, y, 0);
            acc += glam::Vec3::from(r.d).truncate() + r.time;
        }
    }
    acc
}

fn camera(c: &mut Criterion) {
    let mut g = c.benchmark_group("camera");
    let scene = cornell(64, 1);
    for (name, lens) in [("pinhole", false), ("lens", true)] {
        let ctx = Ctx::new(&scene, lens);
        g.bench_function(format!("rays_64x64_{name}"), |b| {
            b.iter(|| camera_rays::<false>(&ctx))
        });
        g.bench_function(format!("rays_64x64_{name}_motion"), |b| {
            b.iter(|| camera_rays::<true>(&ctx))
        });
    }
    // A camera moving within the shutter evaluates its path for every ray.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/flyby.ron");
    let o = vec![
        ("render.width".to_string(), "64".to_string()),
        ("render.height".to_string(), "64".to_string()),
    ];
    let flyby = prepare(
        &prism::scene_file::load(&path, &o).unwrap(),
        &KdParams::default(),
    );
    let ctx = Ctx::new(&flyby, false);
    g.bench_function("rays_64x64_moving_camera", |b| {
        b.iter(|| camera_rays::<true>(&ctx))
    });
    g.finish();
}

fn integrator(c: &mut Criterion) {
    let mut g = c.benchmark_group("integrator");
    g.sample_size(10);
    let scene = cornell(64, 4);
    for (name, lanes) in [
        ("w1", prism::simd::Lanes::scalar()),
        ("auto", prism::simd::Lanes::auto()),
    ] {
        let opts = RenderOptions::new(4, lanes);
        g.bench_function(format!("cornell_64x64_4spp_{name}"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    // The motion-blur scene against the same scene with its motion removed.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/motion_blur.ron"),
    )
    .unwrap();
    let still = text
        .replace("motion: (velocity: (1.6, 0.3, 0.0))", "")
        .replace("motion: (angular_velocity: (0.0, 60.0, 0.0))", "");
    assert_ne!(
        text, still,
        "motion_blur.ron still has the motions this bench removes"
    );
    for (name, t) in [("motion_blur", &text), ("motion_blur_static", &still)] {
        let scene = scene_text(t, Path::new("scenes/motion_blur.ron"), 64, 36);
        let opts = opts(4);
        g.bench_function(format!("{name}_64x36_4spp"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

/// One pass per effect set, forced on the Cornell box, so a regression in one
/// effect's cost shows on its own.
fn effects(c: &mut Criterion) {
    use prism::scene::Effect;
    let mut g = c.benchmark_group("effects");
    g.sample_size(10);
    let opts = opts(2);
    let sets: [(&str, &[Effect]); 5] = [
        ("none", &[]),
        ("lens", &[Effect::Lens]),
        ("motion", &[Effect::Motion]),
        ("lens_motion", &[Effect::Lens, Effect::Motion]),
        ("spectral", &[Effect::Spectral]),
    ];
    for (name, set) in sets {
        let mut scene = cornell(48, 2);
        for e in set {
            scene.effects.force(*e).unwrap();
        }
        g.bench_function(format!("cornell_48x48_2spp_{name}"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

/// Spectral transport (4 hero wavelengths) against RGB on the non-dispersive Cornell box with
/// SPECTRAL forced on: the price of carrying wavelengths where no effect needs them.
fn spectral(c: &mut Criterion) {
    use prism::scene::Effect;
    let mut g = c.benchmark_group("spectral");
    g.sample_size(10);
    let opts = opts(4);
    for (name, force) in [("rgb", false), ("spectral_4", true)] {
        let mut scene = cornell(64, 4);
        if force {
            scene.effects.force(Effect::Spectral).unwrap();
            // The upsampling table is built on first use; keep it out of the timing.
            prism::spectrum::rgb2spec::init_table();
        }
        g.bench_function(format!("cornell_64x64_4spp_{name}"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

/// Texture lookups, and a pass over the textures scene against the same scene untextured.
fn textures(c: &mut Criterion) {
    let mut g = c.benchmark_group("textures");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cache = prism::texture::TextureCache::default();
    let earth = cache
        .get(
            &dir.join("assets/earth.jpg"),
            prism::texture::ColorSpace::Srgb,
        )
        .unwrap();
    let s = Sampler::new(SamplerKind::Independent, 7);
    let uvs: Vec<Vec2> = (0..4096u32).map(|i| s.get_2d(i, 0, 0)).collect();
    g.bench_function("bilinear_earth_4096", |b| {
        b.iter(|| {
            uvs.iter()
                .map(|uv| earth.bilinear(*uv, prism::texture::Wrap::Repeat).x)
                .sum::<f32>()
        })
    });
    let bricks = prism::texture::AlbedoTexture::Bricks(prism::texture::Bricks {
        brick: glam::Vec3::new(0.5, 0.15, 0.1),
        mortar: glam::Vec3::splat(0.8),
        size: Vec2::new(0.4, 0.2),
        joint: 0.02,
    });
    g.bench_function("bricks_albedo_and_height_4096", |b| {
        b.iter(|| {
            uvs.iter()
                .map(|uv| bricks.eval(*uv).x + bricks.height(*uv))
                .sum::<f32>()
        })
    });
    g.sample_size(10);
    let text = std::fs::read_to_string(dir.join("scenes/textures.ron")).unwrap();
    let plain: String = text
        .lines()
        .filter(|l| !l.contains("texture:") && !l.trim_start().starts_with("normal_map:"))
        .collect::<Vec<_>>()
        .join("\n")
        .replace(
            "material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0)),",
            "material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0))),",
        );
    for (name, t) in [("textured", &text), ("untextured", &plain)] {
        let scene = scene_text(t, &dir.join("scenes/textures.ron"), 64, 48);
        let opts = opts(4);
        g.bench_function(format!("pass_{name}_64x48_4spp"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

/// The MEDIA effect's cost: the Cornell box filled with thin fog against the same box clear.
fn media(c: &mut Criterion) {
    let mut g = c.benchmark_group("media");
    g.sample_size(10);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(dir.join("scenes/cornell.ron")).unwrap();
    let fog = text.replacen(
        "entities: [",
        "entities: [\n        (name: \"fog\", shape: Box(min: (-1.0, -1.0, -1.0), max: (557.0, 550.0, 560.0)),\n         medium: (sigma_a: Rgb(0.0002, 0.0002, 0.0002), sigma_s: Rgb(0.001, 0.001, 0.001), g: 0.3)),",
        1,
    );
    let opts = opts(2);
    for (name, t) in [("clear", &text), ("thin_fog", &fog)] {
        let scene = scene_text(t, &dir.join("scenes/cornell.ron"), 48, 48);
        g.bench_function(format!("cornell_48x48_2spp_{name}"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

criterion_group!(
    benches, kdtree, camera, integrator, effects, spectral, textures, media
);
criterion_main!(benches);
