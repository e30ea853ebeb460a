//! Textures and normal maps in rendered scenes: flat maps change nothing, tilted ones keep
//! energy, every shape has a usable tangent frame, and a missing image is a located error.

mod common;
use common::render::{mean_where, run, scene};
use glam::Vec3;
use prism::geometry::Ray;
use prism::sampling::{Sampler, SamplerKind, square_to_uniform_sphere};
use std::path::Path;

fn png(dir: &Path, name: &str, rgb: [u8; 3]) -> String {
    let p = dir.join(name);
    image::RgbImage::from_pixel(8, 8, image::Rgb(rgb))
        .save(&p)
        .unwrap();
    p.to_str().unwrap().to_string()
}

fn lit_wall(normal_map: &str) -> String {
    format!(
        r#"Scene(
    render: (width: 48, height: 32, spp: 32, max_depth: 4, seed: 2),
    camera: (position: (0.0, 0.0, 3.0), look_at: (0.0, 0.0, 0.0), fov_y: 40.0),
    environment: Constant(Rgb(0.2, 0.2, 0.2)),
    entities: [
        (name: "lamp", shape: Sphere(center: (1.5, 1.0, 1.0), radius: 0.3), material: Light(emission: Rgb(5.0, 5.0, 5.0))),
        (name: "wall", shape: Rect(center: (0.0, 0.0, 0.0), u: (2.0, 0.0, 0.0), v: (0.0, 2.0, 0.0)),
         material: Diffuse(albedo: Rgb(0.7, 0.7, 0.7)), texture: (albedo: Checker(a: Rgb(1.0, 1.0, 1.0), b: Rgb(0.5, 0.5, 0.5), size: 0.1){normal_map})),
    ],
)"#
    )
}

#[test]
fn a_flat_normal_map_renders_like_no_normal_map() {
    let d = tempfile::tempdir().unwrap();
    let flat = png(d.path(), "flat.png", [128, 128, 255]);
    let plain = run(&scene(&lit_wall(""))).image();
    let mapped = run(&scene(&lit_wall(&format!(
        ", normal_map: Image(path: \"{flat}\")"
    ))))
    .image();
    // Code 128 is 1/255 off zero, so the normal tilts by under 0.006 rad: a change far below
    // the noise of 32 samples, yet the same samples are drawn, so the images nearly match.
    let m = prism::film::compare(&mapped, &plain).unwrap();
    assert!(m.relmse < 1e-4, "{}", m.relmse);
}

#[test]
fn a_strongly_tilted_normal_map_keeps_the_furnace_at_most_one() {
    let d = tempfile::tempdir().unwrap();
    let tilted = png(d.path(), "tilted.png", [235, 128, 150]);
    let text = format!(
        r#"Scene(
    render: (width: 32, height: 32, spp: 64, max_depth: 64, seed: 4),
    camera: (position: (0.0, 0.0, 4.0), look_at: (0.0, 0.0, 0.0), fov_y: 30.0),
    environment: Constant(Rgb(1.0, 1.0, 1.0)),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0)),
                 texture: (normal_map: Image(path: "{tilted}"))) ],
)"#
    );
    let s = scene(&text);
    let out = run(&s);
    assert_eq!(out.stats.dropped, 0);
    let img = out.image();
    let m = mean_where(&img, 1, |x, y| {
        let (dx, dy) = (x as f32 + 0.5 - 16.0, y as f32 + 0.5 - 16.0);
        (dx * dx + dy * dy).sqrt() < 12.0
    });
    // Directions sent below the geometric surface are absorbed, never created: ≤ 1.
    assert!(m <= 1.01, "furnace {m}");
    assert!(m > 0.5, "the map should not absorb most light: {m}");
}

#[test]
fn every_shape_has_an_orthonormal_tangent_frame() {
    let s = scene(
        r#"Scene(
    camera: (position: (0.0, 0.0, 9.0), look_at: (0.0, 0.0, 0.0)),
    entities: [
        (name: "globe", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), transform: (rotate: (10.0, 20.0, 30.0)),
         material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0)), texture: (normal_map: FromHeight(strength: 1.0), albedo: Checker(a: Rgb(1.0, 1.0, 1.0), b: Rgb(0.0, 0.0, 0.0), size: 0.1))),
        (name: "rect", shape: Rect(center: (3.0, 0.0, 0.0), u: (0.5, 0.0, 0.2), v: (0.0, 0.7, 0.0)), material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0))),
        (name: "disk", shape: Disk(center: (-3.0, 0.0, 0.0), normal: (0.3, 0.2, 1.0), radius: 0.6), material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0))),
        (name: "box", shape: Box(min: (-0.5, -0.5, -0.5), max: (0.5, 0.5, 0.5)), transform: (translate: (0.0, 3.0, 0.0), rotate: (0.0, 40.0, 10.0), scale: (1.0, 2.0, 0.5)),
         material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0))),
    ],
)"#,
    );
    let sampler = Sampler::new(SamplerKind::Independent, 1);
    let targets = [
        Vec3::ZERO,
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(-3.0, 0.0, 0.0),
        Vec3::new(0.0, 3.0, 0.0),
    ];
    let mut checked = 0;
    for i in 0..4000u32 {
        let target = targets[(i % 4) as usize];
        let o = target + square_to_uniform_sphere(sampler.get_2d(i, 0, 0)) * 5.0;
        let aim = target + square_to_uniform_sphere(sampler.get_2d(i, 0, 2)) * 0.6;
        // Every 50th ray goes straight at the globe's poles (in its rotated frame).
        let aim = if i % 50 == 0 {
            glam::Quat::from_rotation_z(30f32.to_radians())
                * glam::Quat::from_rotation_y(20f32.to_radians())
                * glam::Quat::from_rotation_x(10f32.to_radians())
                * Vec3::Y
        } else {
            aim
        };
        let o = if i % 50 == 0 { aim * 5.0 } else { o };
        let ray = Ray::new(o, (aim - o).normalize());
        let Some(hit) = s.intersect::<false>(&ray, f32::INFINITY, 0.0) else {
            continue;
        };
        let sp = s.prims.surface_at::<false>(&ray, &hit, 0.0);
        let (uv, dpdu, dpdv) = s.prims.uv_frame::<false>(&ray, &hit, &sp, 0.0);
        assert!(uv.is_finite() && dpdu.is_finite() && dpdv.is_finite());
        let (t, b) = prism::texture::tangent_frame(sp.ns, dpdu, dpdv);
        for (x, y) in [(t, b), (t, sp.ns), (b, sp.ns)] {
            assert!(x.dot(y).abs() < 1e-4, "not orthogonal at {uv:?}");
        }
        assert!((t.length() - 1.0).abs() < 1e-4 && (b.length() - 1.0).abs() < 1e-4);
        if let Some(tex) = s.prims.texture_of(hit.prim) {
            let n = tex.shading_normal(uv, sp.ns, dpdu, dpdv);
            assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-3);
        }
        checked += 1;
    }
    assert!(checked > 2000);
}

#[test]
fn a_missing_image_names_the_file_and_the_entity() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("s.ron");
    std::fs::write(
        &scene,
        r#"Scene(camera: (position: (0.0, 0.0, 3.0), look_at: (0.0, 0.0, 0.0)),
    entities: [ (name: "globe", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0),
                 material: Diffuse(albedo: Rgb(1.0, 1.0, 1.0)), texture: (albedo: Image(path: "nowhere/earth.jpg"))) ])"#,
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["render", scene.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("nowhere/earth.jpg") && e.contains("\"globe\""),
        "{e}"
    );
    assert_eq!(e.trim_end().lines().count(), 1);
}
