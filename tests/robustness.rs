//! Spawned rays never re-hit their own surface at t ≈ 0, at any scene scale.

use glam::{Vec2, Vec3};
use prism::geometry::{Planar, Ray, Sphere, offset_ray_origin};
use prism::integrator::bsdf::{reflect, refract};
use prism::sampling::{Sampler, SamplerKind, square_to_uniform_sphere};

fn rng(seed: u64) -> impl FnMut(u32) -> Vec2 {
    let s = Sampler::new(SamplerKind::Independent, seed);
    move |i| s.get_2d(0, i, 0)
}

/// Fires rays at a sphere of the given radius placed far from the origin, then spawns the
/// reflected ray (must escape: the sphere is convex) and the refracted one (must cross the
/// whole sphere, not stop at its entry point).
fn sphere_at_scale(scale: f32) {
    let mut u = rng(scale.to_bits() as u64);
    let sphere = Sphere {
        center: Vec3::new(0.3, -0.7, 1.1) * scale * 3.0,
        radius: scale,
    };
    let mut self_hits = 0;
    for i in 0..20_000 {
        let dir_to = square_to_uniform_sphere(u(2 * i));
        let o = sphere.center + dir_to * scale * 4.0;
        // Aim at a random point on the sphere, grazing ones included.
        let target = sphere.center + square_to_uniform_sphere(u(2 * i + 1)) * scale;
        let ray = Ray::new(o, (target - o).normalize());
        let Some((t, front)) = sphere.intersect(&ray, f32::INFINITY) else {
            continue;
        };
        let sp = sphere.surface(&ray, t, front);
        let wo = -ray.d;
        let n = sp.facing();
        let mut rd = reflect(wo, n);
        rd -= 2.0 * rd.dot(n).min(0.0) * n;
        let r = Ray::new(offset_ray_origin(sp.p, n), rd);
        if sphere.intersect(&r, f32::INFINITY).is_some() {
            self_hits += 1;
        }
        if let Some(wt) = refract(wo, n, 1.5) {
            let tr = Ray::new(offset_ray_origin(sp.p, -n), wt);
            match sphere.intersect(&tr, f32::INFINITY) {
                // A chord shorter than 1e-3 of the radius would be the entry point again;
                // a real chord at such a steep refracted angle is far longer.
                Some((t2, _)) if t2 < 1e-3 * scale => self_hits += 1,
                _ => {}
            }
        }
    }
    assert_eq!(self_hits, 0, "scale {scale}");
}

#[test]
fn sphere_spawned_rays_never_self_intersect() {
    for scale in [1e-3f32, 1e-1, 1.0, 1e2, 1e4, 1e5] {
        sphere_at_scale(scale);
    }
}

#[test]
fn rect_and_disk_spawned_rays_never_self_intersect() {
    for scale in [1e-3f32, 1.0, 1e3, 1e5] {
        for disk in [false, true] {
            let mut u = rng(7 + scale.to_bits() as u64);
            let c = Vec3::new(1.7, 2.3, -0.9) * scale;
            let p = Planar::new(
                c,
                Vec3::new(1.0, 0.2, 0.0) * scale,
                Vec3::new(0.0, 0.3, 0.9) * scale,
                disk,
            );
            let mut hits = 0;
            let mut self_hits = 0;
            for i in 0..20_000 {
                let o = c + square_to_uniform_sphere(u(2 * i)) * scale * 3.0;
                let a = u(2 * i + 1) * 2.0 - Vec2::ONE;
                let target = c + p.u * a.x + p.v * a.y;
                let ray = Ray::new(o, (target - o).normalize());
                let Some((t, a, b)) = p.intersect(&ray, f32::INFINITY, disk) else {
                    continue;
                };
                hits += 1;
                let _ = t;
                let sp = p.surface(&ray, a, b);
                let wo = -ray.d;
                let n = sp.facing();
                for d in [reflect(wo, n), -wo, refract(wo, n, 1.3).unwrap_or(-n)] {
                    let side = if d.dot(n) > 0.0 { n } else { -n };
                    let r = Ray::new(offset_ray_origin(sp.p, side), d);
                    if p.intersect(&r, f32::INFINITY, disk).is_some() {
                        self_hits += 1;
                    }
                }
            }
            assert!(hits > 1000);
            assert_eq!(self_hits, 0, "scale {scale} disk {disk}");
        }
    }
}
