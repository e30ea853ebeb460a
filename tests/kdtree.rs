//! The kd-tree against brute force: random spheres plus axis-aligned rectangles (flat boxes,
//! many sharing planes), queried with random, axis-parallel, on-plane, inside and grazing rays.

use glam::Vec3;
use prism::geometry::{Aabb, Ray};
use prism::kdtree::{KdParams, KdPrimitives, KdTree};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

const EXTENT: f32 = 100.0;
/// Box padding: reported hits may round a little outside a shape's exact bounds.
const PAD: f32 = 1e-3;

#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere {
        c: Vec3,
        r: f32,
    },
    /// The rectangle `lo..=hi` (in the two other axes, cyclic order) lying in `x[axis] = pos`.
    Rect {
        axis: usize,
        pos: f32,
        lo: [f32; 2],
        hi: [f32; 2],
    },
}

impl Shape {
    fn bounds(&self) -> Aabb {
        match *self {
            Shape::Sphere { c, r } => Aabb::new(c - Vec3::splat(r + PAD), c + Vec3::splat(r + PAD)),
            Shape::Rect { axis, pos, lo, hi } => {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let (mut a, mut b) = (Vec3::ZERO, Vec3::ZERO);
                // Flat along the normal, so that the builder sees a planar primitive.
                a[axis] = pos;
                b[axis] = pos;
                a[u] = lo[0] - PAD;
                a[v] = lo[1] - PAD;
                b[u] = hi[0] + PAD;
                b[v] = hi[1] + PAD;
                Aabb::new(a, b)
            }
        }
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        match *self {
            Shape::Sphere { c, r } => {
                let oc = ray.o - c;
                let a = ray.d.length_squared();
                let b = oc.dot(ray.d);
                let disc = b * b - a * (oc.length_squared() - r * r);
                if disc < 0.0 {
                    return None;
                }
                let sq = disc.sqrt();
                [(-b - sq) / a, (-b + sq) / a]
                    .into_iter()
                    .find(|&t| t > 0.0 && t < t_max)
            }
            Shape::Rect { axis, pos, lo, hi } => {
                if ray.d[axis] == 0.0 {
                    return None;
                }
                let t = (pos - ray.o[axis]) / ray.d[axis];
                if !(t > 0.0 && t < t_max) {
                    return None;
                }
                let p = ray.at(t);
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                (p[u] >= lo[0] && p[u] <= hi[0] && p[v] >= lo[1] && p[v] <= hi[1]).then_some(t)
            }
        }
    }
}

struct Scene {
    shapes: Vec<Shape>,
    boxes: Vec<Aabb>,
}

impl KdPrimitives for Scene {
    fn len(&self) -> usize {
        self.shapes.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        self.boxes[i as usize]
    }
}

fn unit(rng: &mut Pcg64) -> Vec3 {
    let z = 1.0 - 2.0 * rng.random::<f32>();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn point(rng: &mut Pcg64, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(
        rng.random_range(lo..hi),
        rng.random_range(lo..hi),
        rng.random_range(lo..hi),
    )
}

fn scene(spheres: usize, rects: usize, seed: u64) -> Scene {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut shapes = Vec::with_capacity(spheres + rects);
    for _ in 0..spheres {
        shapes.push(Shape::Sphere {
            c: point(&mut rng, 0.0, EXTENT),
            r: rng.random_range(0.2..2.5),
        });
    }
    for _ in 0..rects {
        // Few plane positions per axis, so that rectangles share planes and overlap.
        let axis = rng.random_range(0..3);
        let pos = rng.random_range(0..6) as f32 * 20.0;
        let lo = [
            rng.random_range(0.0..EXTENT - 10.0),
            rng.random_range(0.0..EXTENT - 10.0),
        ];
        let hi = [
            lo[0] + rng.random_range(1.0..10.0),
            lo[1] + rng.random_range(1.0..10.0),
        ];
        shapes.push(Shape::Rect { axis, pos, lo, hi });
    }
    let boxes = shapes.iter().map(Shape::bounds).collect();
    Scene { shapes, boxes }
}

fn brute(scene: &Scene, ray: &Ray) -> Option<(u32, f32)> {
    let mut best: Option<(u32, f32)> = None;
    for (i, s) in scene.shapes.iter().enumerate() {
        if let Some(t) = s.intersect(ray, best.map_or(f32::INFINITY, |b| b.1)) {
            best = Some((i as u32, t));
        }
    }
    best
}

fn closest(tree: &KdTree, scene: &Scene, ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
    let mut prim = None;
    let t = tree.closest_hit(ray, t_max, |p, t_now| {
        let t = scene.shapes[p as usize].intersect(ray, t_now);
        if t.is_some() {
            prim = Some(p);
        }
        t
    })?;
    Some((prim.expect("a hit names its primitive"), t))
}

struct Checker<'a> {
    scene: &'a Scene,
    tree: KdTree,
    rays: usize,
    hits: usize,
}

impl<'a> Checker<'a> {
    fn new(scene: &'a Scene) -> Self {
        let tree = KdTree::build(scene, &KdParams::default());
        assert_eq!(tree.stats().primitives, scene.shapes.len());
        assert_eq!(tree.stats().skipped, 0);
        Self {
            scene,
            tree,
            rays: 0,
            hits: 0,
        }
    }

    /// Closest and any hit, with an infinite and a finite range, against brute force.
    fn check(&mut self, ray: Ray, rng: &mut Pcg64) {
        let want = brute(self.scene, &ray);
        let shadow_t = match want {
            Some((_, t)) => t * rng.random_range(0.5..1.5),
            None => rng.random_range(1.0..200.0),
        };
        for t_max in [f32::INFINITY, shadow_t] {
            let want = want.filter(|h| h.1 < t_max);
            let got = closest(&self.tree, self.scene, &ray, t_max);
            let same = match (got, want) {
                (None, None) => true,
                // A different primitive is fine only as a tie at exactly the same distance.
                (Some((gp, gt)), Some((wp, wt))) => {
                    gt == wt
                        && (gp == wp
                            || self.scene.shapes[gp as usize].intersect(&ray, f32::INFINITY)
                                == Some(wt))
                }
                _ => false,
            };
            assert!(
                same,
                "closest: {ray:?} t_max {t_max}: kd {got:?}, brute {want:?}"
            );
            let any = self.tree.any_hit(&ray, t_max, |p, tm| {
                self.scene.shapes[p as usize].intersect(&ray, tm).is_some()
            });
            assert_eq!(any, want.is_some(), "any: {ray:?} t_max {t_max}");
            self.hits += usize::from(want.is_some());
        }
        self.rays += 1;
    }

    /// Guards against a generator that makes trivially empty or trivially full tests.
    fn finish(&self, rays: usize) {
        assert_eq!(self.rays, rays);
        let frac = self.hits as f64 / (2 * self.rays) as f64;
        assert!(frac > 0.05 && frac < 0.98, "hit fraction {frac}");
    }
}

fn the_scene() -> Scene {
    scene(2500, 400, 0x5eed)
}

/// A box face of a random primitive: the builder's candidate planes are exactly these.
fn face(scene: &Scene, rng: &mut Pcg64) -> (usize, f32) {
    let b = scene.boxes[rng.random_range(0..scene.boxes.len())];
    let axis = rng.random_range(0..3);
    let pos = if rng.random_bool(0.5) {
        b.min[axis]
    } else {
        b.max[axis]
    };
    (axis, pos)
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

const RAYS: usize = 20_000;

#[test]
fn random_rays_match_brute_force() {
    let scene = the_scene();
    let mut c = Checker::new(&scene);
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..RAYS {
        // Origins both outside the scene and among the primitives.
        let o = point(&mut rng, -0.3 * EXTENT, 1.3 * EXTENT);
        let d = unit(&mut rng) * rng.random_range(0.1..10.0);
        c.check(Ray::new(o, d), &mut rng);
    }
    c.finish(RAYS);
}

#[test]
fn axis_parallel_rays_match_brute_force() {
    let scene = the_scene();
    let mut c = Checker::new(&scene);
    let mut rng = Pcg64::seed_from_u64(2);
    for _ in 0..RAYS {
        let o = point(&mut rng, -0.1 * EXTENT, 1.1 * EXTENT);
        let axis = rng.random_range(0..3);
        let d = axis_dir(&mut rng, axis);
        c.check(Ray::new(o, d), &mut rng);
    }
    c.finish(RAYS);
}

#[test]
fn rays_from_split_planes_match_brute_force() {
    let scene = the_scene();
    let mut c = Checker::new(&scene);
    let mut rng = Pcg64::seed_from_u64(3);
    for i in 0..RAYS {
        let mut o = point(&mut rng, 0.0, EXTENT);
        let (axis, pos) = face(&scene, &mut rng);
        o[axis] = pos;
        if i % 4 == 0 {
            // On two planes at once: along the edge where they meet.
            let (a2, p2) = face(&scene, &mut rng);
            o[a2] = p2;
        }
        let d = match i % 3 {
            // Lying in the plane, both axis-parallel and oblique.
            0 => axis_dir(&mut rng, (axis + 1 + (i / 3) % 2) % 3),
            1 => {
                let mut d = unit(&mut rng);
                d[axis] = if rng.random_bool(0.5) { 0.0 } else { -0.0 };
                d
            }
            // Leaving the plane.
            _ => unit(&mut rng),
        };
        c.check(Ray::new(o, d), &mut rng);
    }
    c.finish(RAYS);
}

#[test]
fn rays_from_inside_primitives_match_brute_force() {
    let scene = the_scene();
    let mut c = Checker::new(&scene);
    let mut rng = Pcg64::seed_from_u64(4);
    for _ in 0..RAYS {
        let o = match scene.shapes[rng.random_range(0..scene.shapes.len())] {
            Shape::Sphere { c, r } => c + unit(&mut rng) * r * rng.random::<f32>(),
            // On the rectangle itself: its own hit at t = 0 must not count.
            Shape::Rect { axis, pos, lo, hi } => {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut o = Vec3::ZERO;
                o[axis] = pos;
                o[u] = rng.random_range(lo[0]..hi[0]);
                o[v] = rng.random_range(lo[1]..hi[1]);
                o
            }
        };
        c.check(Ray::new(o, unit(&mut rng)), &mut rng);
    }
    c.finish(RAYS);
}

#[test]
fn grazing_rays_match_brute_force() {
    let scene = the_scene();
    let mut c = Checker::new(&scene);
    let mut rng = Pcg64::seed_from_u64(5);
    for i in 0..RAYS {
        let shape = scene.shapes[rng.random_range(0..scene.shapes.len())];
        let ray = match (shape, i % 2) {
            // Tangent to a sphere.
            (Shape::Sphere { c, r }, _) => {
                let d = unit(&mut rng);
                let (a, b) = d.any_orthonormal_pair();
                let phi = std::f32::consts::TAU * rng.random::<f32>();
                let side = a * phi.cos() + b * phi.sin();
                let touch = c + side * r;
                Ray::new(touch - d * rng.random_range(0.5..60.0), d)
            }
            // Through a rectangle's edge.
            (Shape::Rect { axis, pos, lo, hi }, 0) => {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut p = Vec3::ZERO;
                p[axis] = pos;
                p[u] = if rng.random_bool(0.5) { lo[0] } else { hi[0] };
                p[v] = rng.random_range(lo[1]..hi[1]);
                let d = unit(&mut rng);
                Ray::new(p - d * rng.random_range(0.5..60.0), d)
            }
            // Almost in a rectangle's plane.
            (Shape::Rect { axis, pos, lo, hi }, _) => {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut p = Vec3::ZERO;
                p[axis] = pos;
                p[u] = rng.random_range(lo[0]..hi[0]);
                p[v] = rng.random_range(lo[1]..hi[1]);
                let mut d = unit(&mut rng);
                d[axis] = rng.random_range(-1e-4..1e-4);
                Ray::new(p - d * rng.random_range(0.5..60.0), d)
            }
        };
        c.check(ray, &mut rng);
    }
    c.finish(RAYS);
}

#[test]
fn empty_and_single_primitive_trees() {
    let mut rng = Pcg64::seed_from_u64(6);
    let empty = KdTree::build(&Vec::<Aabb>::new(), &KdParams::default());
    assert_eq!(empty.stats().nodes, 0);
    assert_eq!(empty.stats().leaves, 0);
    for _ in 0..100 {
        let ray = Ray::new(point(&mut rng, -1.0, 1.0), unit(&mut rng));
        assert_eq!(
            empty.closest_hit(&ray, f32::INFINITY, |_, _| Some(0.5)),
            None
        );
        assert!(!empty.any_hit(&ray, f32::INFINITY, |_, _| true));
    }

    // One sphere, then one flat rectangle (a tree whose bounds are themselves flat).
    let one_sphere = [Shape::Sphere {
        c: Vec3::splat(1.0),
        r: 0.5,
    }];
    let one_rect = [Shape::Rect {
        axis: 2,
        pos: 1.0,
        lo: [0.5, 0.5],
        hi: [1.5, 1.5],
    }];
    for shapes in [&one_sphere[..], &one_rect[..]] {
        let scene = Scene {
            shapes: shapes.to_vec(),
            boxes: shapes.iter().map(Shape::bounds).collect(),
        };
        let mut c = Checker::new(&scene);
        assert_eq!(c.tree.stats().nodes, 1);
        assert_eq!(c.tree.stats().prim_refs, 1);
        assert_eq!(c.tree.bounds(), scene.boxes[0]);
        for i in 0..2000 {
            // Aim near the primitive so that about half the rays hit.
            let target = Vec3::splat(1.0) + unit(&mut rng) * 0.7;
            let o = if i % 2 == 0 {
                point(&mut rng, -3.0, 5.0)
            } else {
                target + unit(&mut rng) * 0.1
            };
            c.check(Ray::new(o, target - o), &mut rng);
        }
        c.finish(2000);
    }
}
