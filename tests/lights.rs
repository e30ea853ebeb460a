//! Chi-square tests of area-light sampling: the directions each emitter's `sample` produces
//! from a reference point follow the solid-angle pdf its `pdf` reports.

mod common;
use common::chi2::Chi2;
use glam::{Vec2, Vec3};
use prism::geometry::{Planar, Ray, Sphere};
use prism::sampling::coordinate_system;

/// Runs the test in a frame whose +z points from `p` towards `center`, over the cap of
/// directions with 1 − cos θ ≤ `omc` (the whole sphere when `omc` is 2).
fn check(
    p: Vec3,
    center: Vec3,
    omc: f64,
    sample: impl Fn(Vec2) -> Option<Vec3>,
    pdf_along: impl Fn(Vec3) -> f32,
) {
    let w = (center - p).normalize();
    let (t, b) = coordinate_system(w);
    let to_local = |d: Vec3| Vec3::new(d.dot(t), d.dot(b), d.dot(w));
    let to_world = |l: Vec3| t * l.x + b * l.y + w * l.z;
    let out = Chi2::new(200_000, 11)
        .res(48, 48)
        .tests(5)
        .max_depth(6)
        .directions(
            [0.0, omc],
            |u| sample(u).map(|q| to_local((q - p).normalize())),
            |l| pdf_along(to_world(l)),
        )
        .expect("test runs");
    assert!(out.passed(), "{out:?}");
}

#[test]
fn sphere_light_from_outside_is_uniform_in_its_cone() {
    let s = Sphere {
        center: Vec3::new(0.5, -0.2, 3.0),
        radius: 0.8,
    };
    let p = Vec3::new(0.1, 0.3, -0.4);
    let d = (s.center - p).length();
    let omc = 1.0 - (1.0 - (s.radius / d).powi(2)).sqrt();
    check(
        p,
        s.center,
        (omc * 1.05) as f64,
        |u| s.sample(p, u).map(|x| x.p),
        |dir| match s.intersect(&Ray::new(p, dir), f32::INFINITY) {
            Some((t, front)) => {
                let sp = s.surface(&Ray::new(p, dir), t, front);
                s.pdf(p, sp.p, sp.n)
            }
            None => 0.0,
        },
    );
}

#[test]
fn sphere_light_from_inside_is_sampled_by_area() {
    let s = Sphere {
        center: Vec3::new(0.0, 0.0, 0.0),
        radius: 2.0,
    };
    let p = Vec3::new(0.4, -0.9, 0.7);
    check(
        p,
        Vec3::new(0.0, 0.0, 5.0),
        2.0,
        |u| s.sample(p, u).map(|x| x.p),
        |dir| match s.intersect(&Ray::new(p, dir), f32::INFINITY) {
            Some((t, front)) => {
                let sp = s.surface(&Ray::new(p, dir), t, front);
                s.pdf(p, sp.p, sp.n)
            }
            None => 0.0,
        },
    );
}

fn planar_case(disk: bool) {
    // A sheared, non-square patch, as an affine transform makes of a Rect or a Disk.
    let q = Planar::new(
        Vec3::new(0.3, 1.5, 0.2),
        Vec3::new(0.9, 0.1, 0.3),
        Vec3::new(0.2, 0.05, -0.6),
        disk,
    );
    for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.5, 1.2, -0.4)] {
        check(
            p,
            q.center,
            0.8,
            |u| q.sample(p, u, disk).map(|x| x.p),
            |dir| match q.intersect(&Ray::new(p, dir), f32::INFINITY, disk) {
                Some((_, a, b)) => q.pdf(p, q.surface(&Ray::new(p, dir), a, b).p),
                None => 0.0,
            },
        );
    }
}

#[test]
fn rect_light_is_sampled_by_area() {
    planar_case(false);
}

#[test]
fn disk_light_is_sampled_by_area() {
    planar_case(true);
}
