//! Surface of revolution: cost per ray on the goblet, against the same goblet tessellated into
//! triangles behind the crate's kd-tree, and as the Newton tolerance varies.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use prism::geometry::revolution::{DEFAULT_TOLERANCE, Revolution, RevolutionStats};
use prism::geometry::{Aabb, Ray};
use prism::kdtree::{KdParams, KdTree};
use prism::sampling::{Sampler, SamplerKind, square_to_uniform_sphere};
use std::hint::black_box;

use prism::geometry::revolution::GOBLET_PROFILE as GOBLET;

const RAYS: u32 = 4096;

/// From a sphere of radius 3 around the goblet towards random points of its bounds: about
/// 60 % hit.
fn rays() -> Vec<Ray> {
    let s = Sampler::new(SamplerKind::Independent, 9);
    (0..RAYS)
        .map(|i| {
            let o = Vec3::new(0.0, 0.7, 0.0) + square_to_uniform_sphere(s.get_2d(i, 0, 0)) * 3.0;
            let u = Vec3::new(s.get_1d(i, 0, 2), s.get_1d(i, 0, 3), s.get_1d(i, 0, 4));
            let target = Vec3::new(-0.5, 0.0, -0.5) + u * Vec3::new(1.0, 1.4, 1.0);
            Ray::new(o, (target - o).normalize())
        })
        .collect()
}

/// The goblet as triangles: `per_span` rings per profile span, `n_phi` around.
struct Mesh {
    tris: Vec<[Vec3; 3]>,
    tree: KdTree,
}

fn de_boor(ctrl: &[[f32; 2]], knots: &[f32], x: f32) -> [f32; 2] {
    let n = ctrl.len();
    let mut l = 3;
    while l < n - 1 && x >= knots[l + 1] {
        l += 1;
    }
    let mut d = [[0.0; 2]; 4];
    d.copy_from_slice(&ctrl[l - 3..=l]);
    for r in 1..=3 {
        for j in (r..=3).rev() {
            let i = j + l - 3;
            let a = (x - knots[i]) / (knots[i + 4 - r] - knots[i]);
            d[j] = [
                (1.0 - a) * d[j - 1][0] + a * d[j][0],
                (1.0 - a) * d[j - 1][1] + a * d[j][1],
            ];
        }
    }
    d[3]
}

fn tessellate(per_span: usize, n_phi: usize) -> Mesh {
    let n = GOBLET.len();
    let m = n - 3;
    let ctrl: Vec<[f32; 2]> = GOBLET.iter().map(|&(r, h)| [r, h]).collect();
    let knots: Vec<f32> = (0..n + 4)
        .map(|i| ((i as f32 - 3.0) / m as f32).clamp(0.0, 1.0))
        .collect();
    let ns = per_span * m;
    let ring = |i: usize| -> Vec<Vec3> {
        let [r, h] = de_boor(&ctrl, &knots, i as f32 / ns as f32);
        (0..n_phi)
            .map(|j| {
                let phi = j as f32 / n_phi as f32 * std::f32::consts::TAU;
                Vec3::new(r * phi.cos(), h, r * phi.sin())
            })
            .collect()
    };
    let mut tris = Vec::new();
    let mut below = ring(0);
    for i in 0..ns {
        let above = ring(i + 1);
        for j in 0..n_phi {
            let j1 = (j + 1) % n_phi;
            tris.push([below[j], below[j1], above[j1]]);
            tris.push([below[j], above[j1], above[j]]);
        }
        below = above;
    }
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|t| Aabb::from_points(t).padded(4.0 * f32::EPSILON, 0.0))
        .collect();
    let tree = KdTree::build(&boxes, &KdParams::default());
    Mesh { tris, tree }
}

/// Möller–Trumbore.
#[inline]
fn ray_triangle(ray: &Ray, t: &[Vec3; 3], t_max: f32) -> Option<f32> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = ray.d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.o - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t < t_max).then_some(t)
}

fn revolution(c: &mut Criterion) {
    let rays = rays();
    let mut g = c.benchmark_group("revolution");
    g.throughput(Throughput::Elements(RAYS as u64));

    for tol in [DEFAULT_TOLERANCE, 1e-3, 1e-5, 1e-7] {
        let rev = Revolution::new(&GOBLET, tol).unwrap();
        let mut st = RevolutionStats::default();
        let hits = rays
            .iter()
            .filter(|r| rev.intersect(r, f32::INFINITY, &mut st).is_some())
            .count();
        eprintln!(
            "goblet, tolerance {tol:e}: {hits} hits of {RAYS}; {:.2} spans searched per ray, \
             {:.3} iterations per hit, {:.3} per bracket, {} non-converged",
            st.candidate_spans as f64 / st.rays as f64,
            st.newton_iterations as f64 / hits as f64,
            st.newton_iterations as f64 / st.brackets as f64,
            st.non_converged
        );
        g.bench_function(format!("goblet_closest_tol_{tol:e}"), |b| {
            b.iter(|| {
                let mut st = RevolutionStats::default();
                rays.iter()
                    .filter(|r| {
                        rev.intersect(black_box(r), f32::INFINITY, &mut st)
                            .is_some()
                    })
                    .count()
            })
        });
    }
    let rev = Revolution::new(&GOBLET, DEFAULT_TOLERANCE).unwrap();
    g.bench_function("goblet_any_hit", |b| {
        b.iter(|| {
            let mut st = RevolutionStats::default();
            rays.iter()
                .filter(|r| rev.occluded(black_box(r), f32::INFINITY, &mut st))
                .count()
        })
    });

    for (per_span, n_phi) in [(16, 64), (96, 256)] {
        let mesh = tessellate(per_span, n_phi);
        eprintln!(
            "goblet mesh {per_span}x{n_phi}: {} triangles, kd-tree {}",
            mesh.tris.len(),
            mesh.tree.stats()
        );
        g.bench_function(format!("goblet_mesh_{}_tris", mesh.tris.len()), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| {
                        mesh.tree
                            .closest_hit(black_box(r), f32::INFINITY, |i, t_max| {
                                ray_triangle(r, &mesh.tris[i as usize], t_max)
                            })
                            .is_some()
                    })
                    .count()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, revolution);
criterion_main!(benches);
