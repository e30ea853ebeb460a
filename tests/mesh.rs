//! Triangle meshes: watertight intersection, the perfect-split kd-tree against brute force,
//! self-intersection after spawning, shading normals, and the OBJ / PLY loaders.

use glam::{Vec2, Vec3};
use prism::geometry::mesh::{MeshError, MeshHit, TriangleMesh};
use prism::geometry::mesh_io::{load_mesh, read_mesh};
use prism::geometry::{Aabb, Ray, offset_ray_origin};
use prism::kdtree::{KdParams, KdTree};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// Mesh generators

type Mesh = (Vec<Vec3>, Vec<[u32; 3]>);

use prism::geometry::mesh::icosphere;

/// Moves every vertex radially by up to ±`radial` and sideways by up to `tangent`.
fn perturb(mut m: Mesh, radial: f32, tangent: f32, rng: &mut Pcg64) -> Mesh {
    for p in &mut m.0 {
        let jitter = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        *p = *p * (1.0 + rng.random_range(-radial..radial)) + jitter * tangent;
    }
    m
}

/// An n × n grid of unit squares on z = 0 with integer coordinates: every edge and vertex
/// lies on candidate split planes, and all triangles lie in the plane z = 0.
fn grid(n: u32) -> Mesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            p.push(Vec3::new(i as f32, j as f32, 0.0));
        }
    }
    let mut f = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Alternate diagonals so that both edge directions occur.
            if (i + j) % 2 == 0 {
                f.extend([[a, b, c], [a, c, d]]);
            } else {
                f.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    (p, f)
}

/// The cube [-1, 1]³, each face an n × n grid, vertices shared along edges, outward winding.
fn cube(n: u32) -> Mesh {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut p = Vec::new();
    let mut f = Vec::new();
    let mut vertex = |v: Vec3, p: &mut Vec<Vec3>| -> u32 {
        *index
            .entry([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
            .or_insert_with(|| {
                p.push(v);
                p.len() as u32 - 1
            })
    };
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let point = |i: u32, j: u32| {
                let mut q = Vec3::ZERO;
                q[axis] = side;
                q[u] = -1.0 + 2.0 * i as f32 / n as f32;
                q[v] = -1.0 + 2.0 * j as f32 / n as f32;
                q
            };
            for j in 0..n {
                for i in 0..n {
                    let a = vertex(point(i, j), &mut p);
                    let b = vertex(point(i + 1, j), &mut p);
                    let c = vertex(point(i + 1, j + 1), &mut p);
                    let d = vertex(point(i, j + 1), &mut p);
                    // (u, v, axis) is right-handed, so u × v points along +axis.
                    if side > 0.0 {
                        f.extend([[a, b, c], [a, c, d]]);
                    } else {
                        f.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
    }
    (p, f)
}

fn build(m: Mesh) -> TriangleMesh {
    TriangleMesh::new(m.0, m.1, None, None).expect("test mesh builds")
}

fn bunny_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj")
}

// ---------------------------------------------------------------------------------------------
// Sampling helpers

fn unit(rng: &mut Pcg64) -> Vec3 {
    let z = 1.0 - 2.0 * rng.random::<f32>();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn in_box(rng: &mut Pcg64, lo: Vec3, hi: Vec3) -> Vec3 {
    Vec3::new(
        rng.random_range(lo.x..hi.x),
        rng.random_range(lo.y..hi.y),
        rng.random_range(lo.z..hi.z),
    )
}

/// Uniform barycentrics (b1, b2).
fn bary(rng: &mut Pcg64) -> (f32, f32) {
    let (mut a, mut b) = (rng.random::<f32>(), rng.random::<f32>());
    if a + b > 1.0 {
        a = 1.0 - a;
        b = 1.0 - b;
    }
    (a, b)
}

/// A target on the mesh: a random interior point, a vertex (exactly), or an edge midpoint.
fn target(mesh: &TriangleMesh, kind: usize, rng: &mut Pcg64) -> Vec3 {
    let tri = mesh.triangle(rng.random_range(0..mesh.triangle_count() as u32));
    let k = rng.random_range(0..3);
    match kind % 3 {
        0 => {
            let (b1, b2) = bary(rng);
            (1.0 - b1 - b2) * tri[0] + b1 * tri[1] + b2 * tri[2]
        }
        1 => tri[k],
        _ => (tri[k] + tri[(k + 1) % 3]) * 0.5,
    }
}

// ---------------------------------------------------------------------------------------------
// Watertightness

#[test]
fn no_ray_escapes_a_perturbed_icosphere() {
    let mut rng = Pcg64::seed_from_u64(0x77a7e4);
    let mesh = build(perturb(icosphere(3), 0.06, 0.01, &mut rng));
    assert_eq!(mesh.triangle_count(), 1280);
    assert!(mesh.is_closed());
    let mut escapes = Vec::new();
    const RAYS: usize = 100_000;
    for i in 0..RAYS {
        // Inside: the surface stays beyond radius 0.9 - 0.02.
        let o = unit(&mut rng) * 0.5 * rng.random::<f32>().cbrt();
        // Direction lengths over six decades: the test must not depend on |d| ≈ 1.
        let d = (target(&mesh, i, &mut rng) - o) * 10f32.powf(rng.random_range(-3.0..3.0));
        let ray = Ray::new(o, d);
        let hit = mesh.intersect(&ray, f32::INFINITY);
        let blocked = mesh.occluded(&ray, f32::INFINITY);
        if hit.is_none() || !blocked {
            escapes.push((i % 3, ray));
        }
    }
    assert!(
        escapes.is_empty(),
        "{} escapes: {:?}",
        escapes.len(),
        &escapes[..escapes.len().min(5)]
    );
}

// ---------------------------------------------------------------------------------------------
// The kd-tree against brute force

struct Compare {
    rays: usize,
    hits: usize,
}

impl Compare {
    /// Checks the tree against `brute` (the brute-force closest hit with no range limit):
    /// the closest hit under `t_max` is that one if it lies under `t_max`, else none.
    fn check(&mut self, mesh: &TriangleMesh, ray: &Ray, t_max: f32, brute: Option<MeshHit>) {
        let want = brute.filter(|h| h.t < t_max);
        let got = mesh.intersect(ray, t_max);
        match (got, want) {
            (None, None) => {}
            (Some(g), Some(w)) => {
                let own = mesh.intersect_triangle(g.tri, ray, f32::INFINITY);
                // Another triangle is acceptable only as an exact tie (a shared edge or vertex).
                assert!(
                    g.t == w.t && (g.tri == w.tri || own.is_some_and(|h| h.t == w.t)),
                    "{ray:?} t_max {t_max}: tree {g:?}, brute force {w:?}"
                );
                assert_eq!(Some(g), own, "{ray:?}");
            }
            _ => panic!("{ray:?} t_max {t_max}: tree {got:?}, brute force {want:?}"),
        }
        assert_eq!(
            mesh.occluded(ray, t_max),
            want.is_some(),
            "occluded {ray:?} t_max {t_max}"
        );
        self.rays += 1;
        self.hits += usize::from(want.is_some());
    }
}

fn axis_dir(rng: &mut Pcg64, axis: usize) -> Vec3 {
    let mut d = Vec3::new(
        if rng.random_bool(0.5) { 0.0 } else { -0.0 },
        if rng.random_bool(0.5) { 0.0 } else { -0.0 },
        if rng.random_bool(0.5) { 0.0 } else { -0.0 },
    );
    d[axis] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    d
}

fn compare_mesh(mesh: &TriangleMesh, rays: usize, seed: u64) -> Compare {
    let mut rng = Pcg64::seed_from_u64(seed);
    let b = mesh.bounds();
    let margin = b.diagonal().max_element() * 0.5;
    let (lo, hi) = (b.min - margin, b.max + margin);
    let mut c = Compare { rays: 0, hits: 0 };
    for i in 0..rays {
        let o = in_box(&mut rng, lo, hi);
        let ray = match i % 6 {
            0 => Ray::new(o, unit(&mut rng) * rng.random_range(0.1..10.0)),
            // Through a vertex, an edge midpoint or an interior point.
            1..=3 => Ray::new(o, target(mesh, i, &mut rng) - o),
            // Axis-parallel from a vertex's coordinates: along edges, through vertices, in
            // the planes of axis-aligned faces.
            4 => {
                let v = target(mesh, 1, &mut rng);
                let axis = rng.random_range(0..3);
                let mut o2 = v;
                o2[axis] = o[axis];
                Ray::new(o2, axis_dir(&mut rng, axis))
            }
            // Lying in a coordinate plane through a vertex (the plane of a flat mesh or face).
            _ => {
                let v = target(mesh, 1 + (i / 6) % 2, &mut rng);
                let axis = rng.random_range(0..3);
                let mut o2 = o;
                o2[axis] = v[axis];
                let mut d = v - o2;
                d[axis] = if rng.random_bool(0.5) { 0.0 } else { -0.0 };
                Ray::new(o2, d)
            }
        };
        let brute = mesh.intersect_brute_force(&ray, f32::INFINITY);
        c.check(mesh, &ray, f32::INFINITY, brute);
        // A finite range ending before or after the first hit.
        let t_max = match brute {
            Some(h) => h.t * rng.random_range(0.5..1.5),
            None => rng.random_range(0.5..5.0),
        };
        c.check(mesh, &ray, t_max, brute);
    }
    c
}

#[test]
fn tree_matches_brute_force_on_curved_flat_and_boxy_meshes() {
    let mut rng = Pcg64::seed_from_u64(11);
    let meshes = [
        (
            "perturbed icosphere",
            build(perturb(icosphere(3), 0.06, 0.01, &mut rng)),
        ),
        ("grid on z = 0", build(grid(24))),
        ("subdivided cube", build(cube(8))),
        ("bunny", load_mesh(&bunny_path()).expect("bunny loads")),
    ];
    let mut total = 0;
    for (k, (name, mesh)) in meshes.iter().enumerate() {
        let tree = &mesh.stats().tree;
        assert_eq!(tree.skipped, 0, "{name}");
        assert!(tree.leaves > 16, "{name}: {tree}");
        let c = compare_mesh(mesh, 12_500, 100 + k as u64);
        let frac = c.hits as f64 / c.rays as f64;
        assert!(frac > 0.2 && frac < 0.95, "{name}: hit fraction {frac}");
        total += c.rays;
    }
    assert_eq!(total, 100_000);
}

#[test]
fn binned_trees_match_brute_force() {
    // Above the binning threshold with the mesh defaults, and with binning pushed down to
    // small nodes: upper levels binned, straddlers clipped, lower levels exact.
    let mut rng = Pcg64::seed_from_u64(12);
    let sphere = perturb(icosphere(6), 0.02, 0.002, &mut rng);
    assert!(sphere.1.len() > TriangleMesh::kd_params().binned_above);
    let low = KdParams {
        binned_above: 16,
        ..TriangleMesh::kd_params()
    };
    let meshes = [
        ("perturbed icosphere, default", build(sphere.clone())),
        (
            "perturbed icosphere, binned to 16",
            TriangleMesh::with_params(sphere.0, sphere.1, None, None, &low).unwrap(),
        ),
        (
            "grid, binned to 16",
            TriangleMesh::with_params(grid(40).0, grid(40).1, None, None, &low).unwrap(),
        ),
        (
            "cube, binned to 16",
            TriangleMesh::with_params(cube(12).0, cube(12).1, None, None, &low).unwrap(),
        ),
    ];
    for (k, (name, mesh)) in meshes.iter().enumerate() {
        let tree = &mesh.stats().tree;
        assert_eq!(tree.skipped, 0, "{name}");
        assert!(tree.prim_refs >= mesh.triangle_count(), "{name}: {tree}");
        let c = compare_mesh(mesh, 6_000, 300 + k as u64);
        assert!(c.hits > 1000, "{name}: {} hits", c.hits);
    }
}

#[test]
fn mesh_tree_is_the_same_whatever_the_thread_count() {
    let mut rng = Pcg64::seed_from_u64(13);
    let mesh = build(perturb(icosphere(6), 0.02, 0.002, &mut rng));
    let params = TriangleMesh::kd_params();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| mesh.build_tree(&params).tree)
    };
    let (one, two) = (on(1), on(2));
    assert_eq!(one.raw(), two.raw());
    assert_eq!(one.raw(), mesh.tree().raw());
    let (mut a, mut b) = (one.stats().clone(), two.stats().clone());
    (a.build_seconds, b.build_seconds) = (0.0, 0.0);
    assert_eq!(a, b);
    assert_eq!(one.sah_cost(&params), two.sah_cost(&params));
}

#[test]
fn perfect_splits_reference_fewer_triangles_than_box_splits() {
    // Long thin slivers in random directions: each triangle's box is far larger than the
    // triangle, so a tree over boxes duplicates references where clipped triangles do not.
    let mut rng = Pcg64::seed_from_u64(8);
    let mut p = Vec::new();
    let mut f = Vec::new();
    for i in 0..1500u32 {
        let a = in_box(&mut rng, Vec3::ZERO, Vec3::splat(100.0));
        let dir = unit(&mut rng) * 12.0;
        let side = dir.any_orthonormal_vector() * 0.3;
        p.extend([a, a + dir, a + dir * 0.5 + side]);
        f.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mesh = build((p, f));
    let boxes: Vec<Aabb> = (0..mesh.triangle_count() as u32)
        .map(|i| Aabb::from_points(&mesh.triangle(i)).padded(1e-6, 0.0))
        .collect();
    let plain = KdTree::build(&boxes, &KdParams::default());
    let (clipped, plain) = (&mesh.stats().tree, plain.stats());
    assert!(
        (clipped.prim_refs as f64) < 0.8 * plain.prim_refs as f64,
        "perfect splits {clipped}; box splits {plain}"
    );
    let c = compare_mesh(&mesh, 3000, 7);
    assert!(c.hits > 0);
}

// ---------------------------------------------------------------------------------------------
// Self-intersection of spawned rays

fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// Refraction into the side `n` points away from, with relative index `eta` (no total
/// internal reflection when entering a denser medium).
fn refract(d: Vec3, n: Vec3, eta: f32) -> Vec3 {
    let d = d.normalize();
    let cos_i = -d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    eta * d + (eta * cos_i - k.max(0.0).sqrt()) * n
}

#[test]
fn spawned_rays_never_rehit_their_own_surface() {
    let mut rng = Pcg64::seed_from_u64(0x5e1f);
    let sphere = icosphere(3);
    let g = grid(16);
    for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e5] {
        let center = Vec3::new(3.0, -2.0, 1.0) * scale;
        // Convex and closed: reflected rays leave for good, transmitted ones cross it.
        let ball = build((
            sphere.0.iter().map(|&p| center + p * scale).collect(),
            sphere.1.clone(),
        ));
        // A tilted plane: neither reflected nor transmitted rays may meet it again.
        let (u, v) = (Vec3::new(0.8, 0.6, 0.0), Vec3::new(-0.36, 0.48, 0.8));
        let plane = build((
            g.0.iter()
                .map(|&p| center + (u * (p.x - 8.0) + v * (p.y - 8.0)) * scale / 8.0)
                .collect(),
            g.1.clone(),
        ));
        for (closed, mesh) in [(true, &ball), (false, &plane)] {
            let mut hits = 0;
            for _ in 0..2000 {
                // Interior points: at an edge or vertex, the triangle reported may face away
                // from a ray that arrives through its neighbour, which is no offset question.
                let aim = target(mesh, 0, &mut rng);
                let o = center + unit(&mut rng) * 4.0 * scale;
                let ray = Ray::new(o, aim - o);
                let Some(hit) = mesh.intersect(&ray, f32::INFINITY) else {
                    continue;
                };
                hits += 1;
                let s = mesh.surface(&hit);
                // The barycentric point and o + t d agree to rounding.
                assert!((s.p - ray.at(hit.t)).length() < 1e-5 * scale, "{s:?}");
                let nf = if ray.d.dot(s.ng) < 0.0 { s.ng } else { -s.ng };
                let what = format!("scale {scale}, closed {closed}, {ray:?}, {hit:?}");

                let r = Ray::new(offset_ray_origin(s.p, nf), reflect(ray.d, nf));
                let again = mesh.intersect(&r, f32::INFINITY);
                assert!(again.is_none(), "reflected ray hit {again:?}: {what}");
                assert!(
                    !mesh.occluded(&r, f32::INFINITY),
                    "reflected, occluded: {what}"
                );

                let tr = Ray::new(offset_ray_origin(s.p, -nf), refract(ray.d, nf, 1.0 / 1.5));
                let through = mesh.intersect(&tr, f32::INFINITY);
                if closed {
                    let h = through.unwrap_or_else(|| panic!("transmitted ray escaped: {what}"));
                    assert_ne!(
                        h.tri, hit.tri,
                        "transmitted ray re-hit its triangle: {what}"
                    );
                } else {
                    assert!(through.is_none(), "transmitted ray hit {through:?}: {what}");
                }
            }
            assert!(hits > 1500, "scale {scale}: only {hits} hits");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Normals, UVs and topology

/// Barycentrics (b1, b2) of the point (1 − s) v_a + s v_b of a triangle with corners a, b.
fn edge_point(tri: [u32; 3], a: u32, b: u32, s: f32) -> (f32, f32) {
    let mut w = [0.0f32; 3];
    w[tri.iter().position(|&i| i == a).unwrap()] = 1.0 - s;
    w[tri.iter().position(|&i| i == b).unwrap()] = s;
    (w[1], w[2])
}

fn check_continuity(mesh: &TriangleMesh) -> usize {
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (t, tri) in mesh.indices().iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(t as u32);
        }
    }
    let mut checked = 0;
    for (&(a, b), tris) in &by_edge {
        let [t0, t1] = tris[..] else { continue };
        for s in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let at = |t: u32| {
                let (b1, b2) = edge_point(mesh.indices()[t as usize], a, b, s);
                mesh.surface(&MeshHit {
                    t: 1.0,
                    tri: t,
                    b1,
                    b2,
                })
            };
            let (s0, s1) = (at(t0), at(t1));
            assert!((s0.p - s1.p).length() < 1e-6, "{s0:?} {s1:?}");
            assert!(
                (s0.ns - s1.ns).length() < 1e-5,
                "edge {a}-{b} at {s}: {s0:?} {s1:?}"
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn shading_normals_are_continuous_across_edges() {
    let mut rng = Pcg64::seed_from_u64(3);
    let (p, f) = perturb(icosphere(3), 0.06, 0.01, &mut rng);
    let computed = TriangleMesh::new(p.clone(), f.clone(), None, None).unwrap();
    assert!(computed.stats().normals_computed);
    assert_eq!(check_continuity(&computed), 1920 * 5);
    // Input normals (arbitrary, unnormalised) interpolate continuously too.
    let given: Vec<Vec3> = p.iter().map(|&q| q * 3.0 + unit(&mut rng) * 0.5).collect();
    let from_input = TriangleMesh::new(p, f, Some(given), None).unwrap();
    assert!(!from_input.stats().normals_computed);
    assert_eq!(check_continuity(&from_input), 1920 * 5);
}

#[test]
fn flat_mesh_shades_with_its_face_normal() {
    let (p, f) = grid(6);
    let (u, v) = (Vec3::new(0.8, 0.6, 0.0), Vec3::new(-0.36, 0.48, 0.8));
    let n = u.cross(v);
    let p: Vec<Vec3> = p
        .iter()
        .map(|q| u * q.x + v * q.y + Vec3::splat(2.5))
        .collect();
    let mesh = TriangleMesh::new(p, f, None, None).unwrap();
    assert!((mesh.area() - 36.0).abs() < 1e-3, "{}", mesh.area());
    assert!(!mesh.is_closed());
    for nv in mesh.normals() {
        assert!((*nv - n).length() < 1e-6, "{nv} vs {n}");
    }
    let mut rng = Pcg64::seed_from_u64(4);
    for _ in 0..1000 {
        let tri = rng.random_range(0..mesh.triangle_count() as u32);
        let (b1, b2) = bary(&mut rng);
        let s = mesh.surface(&MeshHit {
            t: 1.0,
            tri,
            b1,
            b2,
        });
        assert!(
            (s.ng - n).length() < 1e-6 && (s.ns - n).length() < 1e-6,
            "{s:?}"
        );
    }
}

#[test]
fn computed_normals_of_a_sphere_point_outwards() {
    let mesh = build(icosphere(3));
    for (p, n) in mesh.positions().iter().zip(mesh.normals()) {
        assert!((n.length() - 1.0).abs() < 1e-6);
        assert!(n.dot(*p) > 0.999, "{p} {n}");
    }
    let mut rng = Pcg64::seed_from_u64(5);
    let bumpy = build(perturb(icosphere(3), 0.06, 0.01, &mut rng));
    for (p, n) in bumpy.positions().iter().zip(bumpy.normals()) {
        assert!(n.dot(p.normalize()) > 0.7, "{p} {n}");
    }
    assert!(bumpy.is_closed());
}

#[test]
fn normals_are_angle_weighted_independent_of_tessellation() {
    // A cube corner at the origin, faces facing into the positive octant. One face is a fan
    // of 16 slivers around the corner: counting triangles would pull the corner normal towards
    // that face, the angle weights (π/2 per face however it is cut) keep the diagonal.
    let mut p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let mut f = vec![[0, 3, 1], [0, 2, 3]]; // normals +y and +x
    let k = 16;
    let first = p.len() as u32;
    for i in 0..=k {
        let a = std::f32::consts::FRAC_PI_2 * i as f32 / k as f32;
        p.push(Vec3::new(a.cos(), a.sin(), 0.0));
    }
    for i in 0..k {
        f.push([0, first + i, first + i + 1]); // normal +z
    }
    let mesh = TriangleMesh::new(p, f, None, None).unwrap();
    let n = mesh.normals()[0];
    let want = Vec3::ONE.normalize();
    assert!((n - want).length() < 1e-5, "{n} vs {want}");
}

#[test]
fn unusable_input_normals_are_replaced_and_shading_stays_on_the_geometric_side() {
    let (p, f) = icosphere(2);
    let mut given: Vec<Vec3> = p.iter().map(|&q| -q).collect(); // all inward
    given[0] = Vec3::ZERO;
    given[1] = Vec3::NAN;
    given[2] = Vec3::new(f32::INFINITY, 0.0, 0.0);
    let mesh = TriangleMesh::new(p.clone(), f, Some(given), None).unwrap();
    assert_eq!(mesh.stats().normals_repaired, 3);
    for (k, n) in mesh.normals().iter().enumerate() {
        assert!((n.length() - 1.0).abs() < 1e-6);
        // Repaired ones are computed (outward); the rest are the input's, inward.
        let sign = if k < 3 { 1.0 } else { -1.0 };
        assert!(n.dot(p[k]) * sign > 0.99, "{k}: {n}");
    }
    let mut rng = Pcg64::seed_from_u64(6);
    for _ in 0..500 {
        let tri = rng.random_range(0..mesh.triangle_count() as u32);
        let (b1, b2) = bary(&mut rng);
        let s = mesh.surface(&MeshHit {
            t: 1.0,
            tri,
            b1,
            b2,
        });
        assert!(
            s.ns.dot(s.ng) > 0.0 && (s.ns.length() - 1.0).abs() < 1e-5,
            "{s:?}"
        );
    }
}

#[test]
fn uvs_and_their_derivatives() {
    let p = vec![
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(3.0, 1.0, 1.0),
        Vec3::new(3.0, 2.0, 1.0),
    ];
    let hit = MeshHit {
        t: 1.0,
        tri: 0,
        b1: 0.25,
        b2: 0.5,
    };
    // Without UVs the corners sit at (0,0), (1,0), (1,1): p(u, v) = p0 + u (p1 − p0) + v (p2 − p1).
    let mesh = TriangleMesh::new(p.clone(), vec![[0, 1, 2]], None, None).unwrap();
    assert!(!mesh.stats().has_uvs);
    let s = mesh.surface(&hit);
    assert!((s.uv - Vec2::new(0.75, 0.5)).length() < 1e-6, "{s:?}");
    assert!((s.dpdu - (p[1] - p[0])).length() < 1e-6, "{s:?}");
    assert!((s.dpdv - (p[2] - p[1])).length() < 1e-6, "{s:?}");
    assert!((s.p - Vec3::new(2.5, 1.5, 1.0)).length() < 1e-6);
    assert_eq!(s.ng, Vec3::Z);

    // Given UVs: a scaled, swapped mapping.
    let uvs = vec![Vec2::ZERO, Vec2::new(0.0, 4.0), Vec2::new(2.0, 4.0)];
    let mesh = TriangleMesh::new(p.clone(), vec![[0, 1, 2]], None, Some(uvs)).unwrap();
    let s = mesh.surface(&hit);
    assert!((s.uv - Vec2::new(1.0, 3.0)).length() < 1e-6, "{s:?}");
    assert!((s.dpdu - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6, "{s:?}");
    assert!((s.dpdv - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6, "{s:?}");

    // Degenerate UVs: an orthonormal frame around ng, with dpdu × dpdv along ng.
    let mesh = TriangleMesh::new(p, vec![[0, 1, 2]], None, Some(vec![Vec2::ONE; 3])).unwrap();
    let s = mesh.surface(&hit);
    assert!((s.dpdu.length() - 1.0).abs() < 1e-5 && (s.dpdv.length() - 1.0).abs() < 1e-5);
    assert!(s.dpdu.dot(s.dpdv).abs() < 1e-5);
    assert!(s.dpdu.cross(s.dpdv).dot(s.ng) > 0.999, "{s:?}");
}

#[test]
fn degenerate_triangles_are_dropped_and_counted() {
    let (mut p, mut f) = cube(1);
    assert_eq!(f.len(), 12);
    let n = p.len() as u32;
    p.extend([Vec3::ZERO, Vec3::splat(0.5), Vec3::ONE, Vec3::ZERO]);
    f.extend([
        [0, 0, 1],         // repeated index
        [n, n + 1, n + 2], // collinear
        [n, n + 3, 1],     // two corners at the same position
    ]);
    let mesh = TriangleMesh::new(p, f, None, None).unwrap();
    assert_eq!(mesh.stats().degenerate_dropped, 3);
    assert_eq!(mesh.triangle_count(), 12);
    assert!(mesh.is_closed());
    assert!((mesh.area() - 24.0).abs() < 1e-4);

    let collinear = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    let err = TriangleMesh::new(collinear, vec![[0, 1, 2]], None, None).unwrap_err();
    assert!(
        matches!(err, MeshError::Empty { dropped: 1, .. }),
        "{err:?}"
    );
}

#[test]
fn closedness_follows_the_topology() {
    assert!(build(icosphere(2)).is_closed());
    assert!(build(cube(3)).is_closed());
    assert!(!build(grid(3)).is_closed());
    let (p, mut f) = icosphere(1);
    f[7].swap(1, 2);
    assert!(
        !build((p.clone(), f.clone())).is_closed(),
        "inconsistent orientation"
    );
    f.remove(7);
    assert!(!build((p, f)).is_closed(), "a hole");
}

#[test]
fn constructor_errors_are_reported() {
    let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let e = TriangleMesh::new(p.clone(), vec![[0, 1, 3]], None, None).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                index: 3,
                vertices: 3,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("vertex 3"), "{e}");
    let mut bad = p.clone();
    bad[1].y = f32::NAN;
    let e = TriangleMesh::new(bad, vec![[0, 1, 2]], None, None).unwrap_err();
    assert!(matches!(e, MeshError::NonFinite { vertex: 1, .. }), "{e}");
    let e = TriangleMesh::new(p.clone(), vec![[0, 1, 2]], Some(vec![Vec3::Z]), None).unwrap_err();
    assert!(matches!(e, MeshError::AttributeCount { .. }), "{e}");
    let e = TriangleMesh::new(p, vec![], None, None).unwrap_err();
    assert!(matches!(e, MeshError::Empty { dropped: 0, .. }), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Loading

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

const GROUPS_OBJ: &str = "\
# two objects, groups, a quad and a pentagon, with uvs and normals
mtllib missing.mtl
o first
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
g quad
usemtl nothing
f 1/1/1 2/2/1 3/3/1 4/4/1
g tri
f -4/1/1 -3/2/1 -1/4/1
o second
v 0 0 1
v 2 0 1
v 3 1 1
v 1 2 1
v -1 1 1
f 5 6 7 8 9
l 5 6
";

#[test]
fn obj_with_groups_quads_and_polygons() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "groups.obj", GROUPS_OBJ);
    let mesh = load_mesh(&path).unwrap();
    // Quad → 2, triangle → 1, pentagon → 3; the line element is ignored.
    assert_eq!(mesh.triangle_count(), 6);
    assert_eq!(mesh.stats().degenerate_dropped, 0);
    // tobj makes a model per group and object, each with its own vertex list: 4 + 3 + 5.
    // Positions shared between groups are one vertex for normals and closedness.
    assert_eq!(mesh.stats().vertices, 12);
    assert_eq!(mesh.stats().welded_vertices, 9);
    assert!(mesh.stats().has_uvs);
    // The second object has no normals: those vertices get computed ones.
    assert!(!mesh.stats().normals_computed);
    assert_eq!(mesh.stats().normals_repaired, 5);
    assert!(
        (mesh.area() - (1.0 + 0.5 + 5.0)).abs() < 1e-5,
        "{}",
        mesh.area()
    );
    let up = Vec3::Z;
    assert!(mesh.normals().iter().all(|n| (*n - up).length() < 1e-6));

    let data = read_mesh(&path).unwrap();
    assert_eq!(data.positions.len(), 12);
    assert_eq!(data.indices.len(), 6);
    let uvs = data.uvs.unwrap();
    assert!(uvs[..7].iter().all(|u| u.is_finite()));
    assert!(uvs[7..].iter().all(|u| u.is_nan()));
}

/// The unit cube as 8 vertices and 6 quads (outward), with normals and UVs.
fn cube_ply(encoding: &str) -> Vec<u8> {
    let v: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    let faces: [[u32; 4]; 6] = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut out = format!(
        "ply\nformat {encoding} 1.0\ncomment written by the mesh tests\n\
         element vertex 8\nproperty float x\nproperty float y\nproperty double z\n\
         property uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n\
         property float s\nproperty float t\n\
         element face 6\nproperty uchar flags\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int vertex1\nproperty list ushort short extra\n\
         end_header\n"
    )
    .into_bytes();
    let big = encoding == "binary_big_endian";
    let put = |out: &mut Vec<u8>, le: &[u8]| {
        if big {
            out.extend(le.iter().rev());
        } else {
            out.extend_from_slice(le);
        }
    };
    for p in &v {
        let n = (Vec3::from_array(*p) - 0.5).normalize();
        let st = [p[0], p[1]];
        if encoding == "ascii" {
            out.extend(
                format!(
                    "{} {} {} 200 {} {} {} {} {}\n",
                    p[0], p[1], p[2], n.x, n.y, n.z, st[0], st[1]
                )
                .bytes(),
            );
        } else {
            put(&mut out, &p[0].to_le_bytes());
            put(&mut out, &p[1].to_le_bytes());
            put(&mut out, &f64::from(p[2]).to_le_bytes());
            out.push(200);
            for x in [n.x, n.y, n.z, st[0], st[1]] {
                put(&mut out, &x.to_le_bytes());
            }
        }
    }
    for f in &faces {
        if encoding == "ascii" {
            out.extend(format!("7 4 {} {} {} {}\n", f[0], f[1], f[2], f[3]).bytes());
        } else {
            out.push(7);
            out.push(4);
            for &i in f {
                put(&mut out, &(i as i32).to_le_bytes());
            }
        }
    }
    if encoding == "ascii" {
        out.extend(b"3 2 -1 5\n");
    } else {
        put(&mut out, &3i32.to_le_bytes());
        put(&mut out, &2u16.to_le_bytes());
        put(&mut out, &(-1i16).to_le_bytes());
        put(&mut out, &5i16.to_le_bytes());
    }
    out
}

const CUBE_OBJ: &str = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1
f 1 3 4 2
f 5 6 8 7
f 1 2 6 5
f 3 7 8 4
f 1 5 7 3
f 2 4 8 6
";

/// Each triangle's corner positions, in order.
fn triangles(data: &prism::geometry::mesh_io::MeshData) -> Vec<[Vec3; 3]> {
    data.indices
        .iter()
        .map(|t| t.map(|i| data.positions[i as usize]))
        .collect()
}

#[test]
fn ply_ascii_and_binary_load_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let obj = read_mesh(&write(dir.path(), "cube.obj", CUBE_OBJ)).unwrap();
    let want = triangles(&obj);
    assert_eq!(want.len(), 12);
    let mut first = None;
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let path = write(dir.path(), &format!("cube_{enc}.PLY"), cube_ply(enc));
        let data = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(data.positions.len(), 8, "{enc}");
        assert_eq!(triangles(&data), want, "{enc}");
        assert!(data.normals.is_some() && data.uvs.is_some(), "{enc}");
        match &first {
            None => first = Some(data),
            Some(f) => assert_eq!(&data, f, "{enc}"),
        }
        let mesh = load_mesh(&path).unwrap();
        assert!(mesh.is_closed(), "{enc}");
        assert!((mesh.area() - 6.0).abs() < 1e-5);
        assert!(!mesh.stats().normals_computed);
    }
    let mesh = load_mesh(&dir.path().join("cube.obj")).unwrap();
    assert!(mesh.is_closed());
    assert!(mesh.stats().normals_computed);
}

fn err_of(dir: &Path, name: &str, text: impl AsRef<[u8]>) -> MeshError {
    let path = write(dir, name, text);
    let e = load_mesh(&path).expect_err(name);
    let msg = e.to_string();
    assert!(
        msg.contains(&path.display().to_string()),
        "{name}: `{msg}` does not name the file"
    );
    e
}

#[test]
fn obj_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere/missing.obj");
    let e = load_mesh(&missing).unwrap_err();
    assert!(matches!(e, MeshError::Io { .. }));
    assert!(
        e.to_string().contains(&missing.display().to_string()),
        "{e}"
    );

    let e = err_of(
        dir.path(),
        "bad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n",
    );
    assert!(
        matches!(e, MeshError::Malformed { line: Some(3), .. }),
        "{e}"
    );
    assert!(e.to_string().contains("bad.obj:3:"), "{e}");

    let e = err_of(
        dir.path(),
        "face.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 a\n",
    );
    assert!(
        matches!(e, MeshError::Malformed { line: Some(5), .. }),
        "{e}"
    );

    let e = err_of(
        dir.path(),
        "range.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\nf 1 2 9\n",
    );
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(6),
                face: Some(1),
                index: 9,
                vertices: 3,
                ..
            }
        ),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "zero.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
    );
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(4),
                index: 0,
                ..
            }
        ),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "neg.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
    );
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(4),
                index: -4,
                ..
            }
        ),
        "{e}"
    );

    let e = err_of(
        dir.path(),
        "nan.obj",
        "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n",
    );
    assert!(
        matches!(
            e,
            MeshError::NonFinite {
                line: Some(3),
                vertex: 2,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("nan.obj:3:"), "{e}");

    let e = err_of(
        dir.path(),
        "empty.obj",
        "# nothing but vertices\nv 0 0 0\nv 1 0 0\n",
    );
    assert!(matches!(e, MeshError::Empty { dropped: 0, .. }), "{e}");
    let e = err_of(
        dir.path(),
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n",
    );
    assert!(matches!(e, MeshError::Empty { dropped: 2, .. }), "{e}");
    assert!(e.to_string().contains("no triangles"), "{e}");

    let e = err_of(dir.path(), "mesh.stl", "solid x\n");
    assert!(matches!(e, MeshError::Unsupported { .. }), "{e}");
}

#[test]
fn ply_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n";
    let ok = format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    assert_eq!(
        load_mesh(&write(dir.path(), "ok.ply", &ok))
            .unwrap()
            .triangle_count(),
        1
    );

    let e = err_of(
        dir.path(),
        "token.ply",
        format!("{head}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
    );
    assert!(
        matches!(e, MeshError::Malformed { line: Some(11), .. }),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "range.ply",
        format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
    );
    assert!(
        matches!(
            e,
            MeshError::IndexOutOfRange {
                line: Some(13),
                index: 3,
                ..
            }
        ),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "nan.ply",
        format!("{head}0 0 0\n1 0 0\n0 NaN 0\n3 0 1 2\n"),
    );
    assert!(
        matches!(
            e,
            MeshError::NonFinite {
                line: Some(12),
                vertex: 2,
                ..
            }
        ),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "short.ply",
        format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
    );
    assert!(matches!(e, MeshError::Malformed { .. }), "{e}");
    assert!(e.to_string().contains("end of file"), "{e}");
    let e = err_of(
        dir.path(),
        "flat.ply",
        format!("{head}0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"),
    );
    assert!(matches!(e, MeshError::Empty { dropped: 1, .. }), "{e}");
    let e = err_of(
        dir.path(),
        "header.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
    );
    assert!(
        matches!(e, MeshError::Malformed { .. }) && e.to_string().contains("end_header"),
        "{e}"
    );
    let e = err_of(
        dir.path(),
        "kind.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
    );
    assert!(
        matches!(e, MeshError::Malformed { line: Some(4), .. }),
        "{e}"
    );
    // A header claiming more than the file holds is refused at its line, before anything is
    // allocated: the largest count, and 10^11 binary vertices in a few bytes.
    for (name, count, format) in [
        ("huge.ply", "18446744073709551615", "ascii"),
        ("big.ply", "100000000000", "binary_little_endian"),
    ] {
        let e = err_of(
            dir.path(),
            name,
            format!(
                "ply\nformat {format} 1.0\nelement vertex {count}\nproperty float x\n\
                 property float y\nproperty float z\nend_header\n0 0 0\n"
            ),
        );
        assert!(
            matches!(e, MeshError::Malformed { line: Some(3), .. }),
            "{e}"
        );
        assert!(e.to_string().contains(&format!("claims {count}")), "{e}");
    }
    // More faces than the memory budget allows, refused at the line that claims them.
    let e = err_of(
        dir.path(),
        "faces.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
         property float y\nproperty float z\nelement face 40000000\n\
         property list uchar int vertex_indices\nend_header\n",
    );
    assert!(
        matches!(e, MeshError::Malformed { line: Some(7), .. }),
        "{e}"
    );
    assert!(
        e.to_string().contains("more than the 33554432 triangles"),
        "{e}"
    );
    let e = err_of(dir.path(), "magic.ply", "solid\n");
    assert!(
        matches!(e, MeshError::Malformed { line: Some(1), .. }),
        "{e}"
    );

    // Binary data cut short: the error gives the byte offset instead of a line.
    let mut bin = cube_ply("binary_little_endian");
    bin.truncate(bin.len() - 20);
    let e = err_of(dir.path(), "cut.ply", bin);
    assert!(matches!(e, MeshError::Malformed { line: None, .. }), "{e}");
    assert!(e.to_string().contains("byte"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// The shipped asset

#[test]
fn bunny_asset_loads_with_its_documented_counts() {
    let mesh = load_mesh(&bunny_path()).unwrap();
    let s = mesh.stats();
    assert_eq!(s.vertices, 1839);
    assert_eq!(s.triangles + s.degenerate_dropped, 3674);
    assert_eq!(s.triangles, 3674);
    assert_eq!(s.welded_vertices, 1839);
    assert!(s.normals_computed);
    assert!(!s.has_uvs);
    // Hole-free and consistently wound: every edge is shared by two triangles.
    assert!(mesh.is_closed());
    assert_eq!(s.tree.skipped, 0);
    assert!(mesh.area() > 0.0);
}
