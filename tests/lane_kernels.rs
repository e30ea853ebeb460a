//! The sampler, the warps, camera rays and shape intersection over lanes: every width and form
//! gives, lane for lane, the bits of the scalar functions. For the sampler, warps and camera
//! those are the same code at width 1; the shapes' scalar intersection is separate (faster)
//! code, held to the same bits here.

mod common;
use common::render::scene_file;
use glam::{Vec2, Vec3, Vec3Swizzles};
use prism::integrator::Ctx;
use prism::integrator::generate::camera_rays;
use prism::sampling::warp::{self, lanes as lw};
use prism::sampling::{Sampler, SamplerKind};
use prism::scene::{Effect, RenderScene};
use prism::simd::{self, Float, LaneKernel, Lanes, UInt, V3};
use std::path::Path;

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix;

fn forms() -> Vec<Lanes> {
    for (have, what) in [
        (Lanes::native8().is_some(), "native width 8 (AVX2 + FMA)"),
        (
            Lanes::native16().is_some(),
            "native width 16 (AVX-512F and BW)",
        ),
    ] {
        if !have {
            println!("lane kernels: {what} not on this CPU: skipped");
        }
    }
    Lanes::all_available()
}

/// Runs `f` on `n` items in chunks of the lane width (the tail padded with item 0) and
/// collects one `Vec<T>` per item.
fn chunks<F: Float, T: Default + Clone>(
    n: usize,
    mut f: impl FnMut(&dyn Fn(usize) -> usize) -> Vec<Vec<T>>,
) -> Vec<Vec<T>> {
    let mut out = Vec::with_capacity(n);
    for base in (0..n).step_by(F::WIDTH) {
        let idx = move |l: usize| if base + l < n { base + l } else { 0 };
        let lanes = f(&idx);
        for (l, v) in lanes.into_iter().enumerate() {
            if base + l < n {
                out.push(v);
            }
        }
    }
    out
}

/// Lane `l` of a set of lane values, as f32 bits.
fn bits_of<F: Float>(vals: &[F]) -> Vec<Vec<u32>> {
    (0..F::WIDTH)
        .map(|l| vals.iter().map(|v| v.lane(l).to_bits()).collect())
        .collect()
}

struct SamplerKernel<'a> {
    s: Sampler,
    args: &'a [(u32, u32, u32)],
}

impl LaneKernel for SamplerKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let args = self.args;
        chunks::<F, u32>(args.len(), |idx| {
            let p = F::U32::from_fn(|l| args[idx(l)].0);
            let i = F::U32::from_fn(|l| args[idx(l)].1);
            let d = F::U32::from_fn(|l| args[idx(l)].2);
            let x = self.s.get_1d_lanes::<F>(p, i, d);
            let (u, v) = self.s.get_2d_lanes::<F>(p, i, d);
            bits_of(&[x, u, v])
        })
    }
}

#[test]
fn lane_samples_are_the_scalar_samples() {
    let mut g = SplitMix(31);
    let mut args: Vec<(u32, u32, u32)> = (0..20_000)
        .map(|_| {
            let r = g.next();
            (r as u32, (r >> 32) as u32 % 70_000, (g.next() % 300) as u32)
        })
        .collect();
    args.extend([
        (0, 0, 0),
        (u32::MAX, u32::MAX, u32::MAX),
        (7, 1 << 31, 1 << 20),
    ]);
    for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
        let s = Sampler::new(kind, 77);
        let want: Vec<Vec<u32>> = args
            .iter()
            .map(|&(p, i, d)| {
                let v = s.get_2d(p, i, d);
                vec![s.get_1d(p, i, d).to_bits(), v.x.to_bits(), v.y.to_bits()]
            })
            .collect();
        for lanes in forms() {
            let got = simd::dispatch(lanes, SamplerKernel { s, args: &args });
            assert_eq!(got.len(), want.len());
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g, w, "{kind:?} {} at {:?}", lanes.describe(), args[k]);
            }
        }
    }
}

struct WarpKernel<'a>(&'a [(f32, f32)]);

impl LaneKernel for WarpKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let u = self.0;
        chunks::<F, u32>(u.len(), |idx| {
            let ux = F::from_fn(|l| u[idx(l)].0);
            let uy = F::from_fn(|l| u[idx(l)].1);
            let (dx, dy) = lw::square_to_uniform_disk_concentric(ux, uy);
            let c = lw::square_to_cosine_hemisphere(ux, uy);
            let s = lw::square_to_uniform_sphere(ux, uy);
            let h = lw::square_to_uniform_hemisphere(ux, uy);
            let k = lw::square_to_uniform_cone_one_minus_cos(ux, uy, F::splat(0.01));
            let (t0, t1) = lw::square_to_uniform_triangle(ux, uy);
            let (ft, fb) = lw::coordinate_system(s);
            bits_of(&[
                lw::sample_tent(ux),
                dx,
                dy,
                c.x,
                c.y,
                c.z,
                s.x,
                s.y,
                s.z,
                h.x,
                h.y,
                h.z,
                k.x,
                k.y,
                k.z,
                t0,
                t1,
                ft.x,
                ft.y,
                ft.z,
                fb.x,
                fb.y,
                fb.z,
            ])
        })
    }
}

#[test]
fn lane_warps_are_the_scalar_warps() {
    let mut g = SplitMix(32);
    let mut u: Vec<(f32, f32)> = (0..20_000)
        .map(|_| (g.range(0.0, 1.0) as f32, g.range(0.0, 1.0) as f32))
        .collect();
    // The square's centre, edges and corners, where the maps have their special cases.
    for a in [0.0, 0.5, 1.0 - f32::EPSILON / 2.0] {
        for b in [0.0, 0.5, 1.0 - f32::EPSILON / 2.0] {
            u.push((a, b));
        }
    }
    let want: Vec<Vec<u32>> = u
        .iter()
        .map(|&(x, y)| {
            let p = Vec2::new(x, y);
            let d = warp::square_to_uniform_disk_concentric(p);
            let v3 = |v: Vec3| [v.x, v.y, v.z];
            let s = warp::square_to_uniform_sphere(p);
            let (ft, fb) = warp::coordinate_system(s);
            let t = warp::square_to_uniform_triangle(p);
            let mut r = vec![warp::sample_tent(x), d.x, d.y];
            r.extend(v3(warp::square_to_cosine_hemisphere(p)));
            r.extend(v3(s));
            r.extend(v3(warp::square_to_uniform_hemisphere(p)));
            r.extend(v3(warp::square_to_uniform_cone_one_minus_cos(p, 0.01)));
            r.extend([t.x, t.y]);
            r.extend(v3(ft));
            r.extend(v3(fb));
            r.iter().map(|v| v.to_bits()).collect()
        })
        .collect();
    for lanes in forms() {
        let got = simd::dispatch(lanes, WarpKernel(&u));
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{} at {:?}", lanes.describe(), u[k]);
        }
    }
}

struct CameraKernel<'a> {
    ctx: Ctx<'a>,
    motion: bool,
    samples: &'a [(u32, u32, u32)],
}

impl LaneKernel for CameraKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let s = self.samples;
        chunks::<F, u32>(s.len(), |idx| {
            let x = F::U32::from_fn(|l| s[idx(l)].0);
            let y = F::U32::from_fn(|l| s[idx(l)].1);
            let i = F::U32::from_fn(|l| s[idx(l)].2);
            let r = if self.motion {
                camera_rays::<F, true>(&self.ctx, x, y, i)
            } else {
                camera_rays::<F, false>(&self.ctx, x, y, i)
            };
            let V3 {
                x: ox,
                y: oy,
                z: oz,
            } = r.o;
            let V3 {
                x: dx,
                y: dy,
                z: dz,
            } = r.d;
            bits_of(&[ox, oy, oz, dx, dy, dz, r.time])
        })
    }
}

fn shipped(name: &str) -> RenderScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    scene_file(&path, &[])
}

#[test]
fn lane_camera_rays_are_the_scalar_camera_rays() {
    // A pinhole, a thin lens, and a camera that moves within the shutter.
    let cases = [
        ("cornell.ron", false),
        ("earth_dof.ron", false),
        ("flyby.ron", true),
    ];
    for (name, motion) in cases {
        let scene = shipped(name);
        assert_eq!(scene.effects.has(Effect::Motion), motion, "{name}");
        if name == "earth_dof.ron" {
            assert!(scene.effects.has(Effect::Lens), "{name} has a lens");
        }
        if motion {
            assert!(scene.camera_moves, "{name}: the camera moves");
        }
        let ctx = Ctx::new(&scene, scene.effects.has(Effect::Lens));
        let (w, h) = (scene.settings.width, scene.settings.height);
        let mut g = SplitMix(33);
        let samples: Vec<(u32, u32, u32)> = (0..4000)
            .map(|_| {
                let r = g.next();
                (
                    (r as u32) % w,
                    ((r >> 32) as u32) % h,
                    (g.next() % 4096) as u32,
                )
            })
            .collect();
        let want: Vec<Vec<u32>> = samples
            .iter()
            .map(|&(x, y, i)| {
                let p = if motion {
                    camera_rays::<f32, true>(&ctx, x, y, i)
                } else {
                    camera_rays::<f32, false>(&ctx, x, y, i)
                };
                let (o, d) = (p.o, p.d);
                [o.x, o.y, o.z, d.x, d.y, d.z, p.time]
                    .iter()
                    .map(|v| v.to_bits())
                    .collect()
            })
            .collect();
        for lanes in forms() {
            let got = simd::dispatch(
                lanes,
                CameraKernel {
                    ctx,
                    motion,
                    samples: &samples,
                },
            );
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g, w, "{name} {} at {:?}", lanes.describe(), samples[k]);
            }
        }
    }
}

/// Rays for the intersection tests: random ones through a region around the shapes, and the
/// hard cases (axis-parallel rays on slab planes, rays along a plane, tangent and grazing
/// rays, origins on the surface, zero and tiny t_max).
fn test_rays() -> Vec<([f32; 3], [f32; 3], f32)> {
    let mut g = SplitMix(34);
    let unit = |g: &mut SplitMix| {
        let v = Vec3::new(
            g.range(-1.0, 1.0) as f32,
            g.range(-1.0, 1.0) as f32,
            g.range(-1.0, 1.0) as f32,
        );
        v.normalize_or(Vec3::X)
    };
    let mut rays = Vec::new();
    for k in 0..20_000 {
        let o = Vec3::new(
            g.range(-3.0, 3.0) as f32,
            g.range(-3.0, 3.0) as f32,
            g.range(-3.0, 3.0) as f32,
        );
        // Half aimed near the origin, where the shapes are.
        let d = if k % 2 == 0 {
            (unit(&mut g) * 0.8 - o).normalize()
        } else {
            unit(&mut g)
        };
        let t_max = if k % 7 == 0 {
            g.range(0.0, 3.0) as f32
        } else {
            f32::INFINITY
        };
        rays.push((o.to_array(), d.to_array(), t_max));
    }
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        for s in [-1.0f32, 1.0] {
            // On the unit slab planes and tangent to the unit sphere.
            rays.push((
                (axis * s + axis.zxy() * -3.0).to_array(),
                axis.zxy().to_array(),
                f32::INFINITY,
            ));
            rays.push(((axis * s).to_array(), (axis * -s).to_array(), f32::INFINITY));
            rays.push(((axis * s).to_array(), (axis * s).to_array(), 0.0));
            rays.push(((axis * 3.0 * s).to_array(), (axis * -s).to_array(), 1e-30));
        }
    }
    rays.push(([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], f32::INFINITY));
    rays
}

struct Shapes<'a> {
    rays: &'a [([f32; 3], [f32; 3], f32)],
    sphere: prism::geometry::Sphere,
    rect: prism::geometry::Planar,
    boxed: prism::geometry::OrientedBox,
}

impl LaneKernel for Shapes<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let r = self.rays;
        chunks::<F, u32>(r.len(), |idx| {
            let o = V3::<F>::from_fn(|l| Vec3::from(r[idx(l)].0));
            let d = V3::<F>::from_fn(|l| Vec3::from(r[idx(l)].1));
            let t_max = F::from_fn(|l| r[idx(l)].2);
            let one = F::one();
            let flag = |m: F::Mask| F::select(m, one, F::zero());
            let (ts, hs, os) = self.sphere.intersect_lanes(o, d, t_max);
            let (tr, ar, br, hr) = self.rect.intersect_lanes(o, d, t_max, false);
            let (td, ad, bd, hd) = self.rect.intersect_lanes(o, d, t_max, true);
            let (tb, hb, ob) = self.boxed.intersect_lanes(o, d, t_max);
            // Only what a hit reports is compared: a miss's t is not part of the contract.
            let keep = |m: F::Mask, v: F| F::select(m, v, F::zero());
            bits_of(&[
                flag(hs),
                keep(hs, ts),
                keep(hs, flag(os)),
                flag(hr),
                keep(hr, tr),
                keep(hr, ar),
                keep(hr, br),
                flag(hd),
                keep(hd, td),
                keep(hd, ad),
                keep(hd, bd),
                flag(hb),
                keep(hb, tb),
                keep(hb, flag(ob)),
            ])
        })
    }
}

#[test]
fn lane_intersections_are_the_scalar_intersections() {
    use prism::geometry::{OrientedBox, Planar, Ray, Sphere};
    let sphere = Sphere {
        center: Vec3::new(0.1, -0.2, 0.05),
        radius: 1.0,
    };
    let rect = Planar::new(
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::new(1.0, 0.0, 0.2),
        Vec3::new(0.0, 0.1, -1.0),
        false,
    );
    let boxed = OrientedBox::new(
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
        glam::Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0, 0.5, 2.0),
            glam::Quat::from_rotation_y(0.4) * glam::Quat::from_rotation_x(-0.3),
            Vec3::new(0.2, 0.0, -0.1),
        ),
    );
    let rays = test_rays();
    let mut hits = [0usize; 4];
    let want: Vec<Vec<u32>> = rays
        .iter()
        .map(|&(o, d, t_max)| {
            let ray = Ray::new(Vec3::from(o), Vec3::from(d));
            let mut v = Vec::new();
            let f = |b: bool| if b { 1.0f32 } else { 0.0 };
            match sphere.intersect(&ray, t_max) {
                Some((t, out)) => {
                    hits[0] += 1;
                    v.extend([1.0, t, f(out)]);
                }
                None => v.extend([0.0; 3]),
            }
            for (i, disk) in [(1, false), (2, true)] {
                match rect.intersect(&ray, t_max, disk) {
                    Some((t, a, b)) => {
                        hits[i] += 1;
                        v.extend([1.0, t, a, b]);
                    }
                    None => v.extend([0.0; 4]),
                }
            }
            match boxed.intersect(&ray, t_max) {
                Some((t, out)) => {
                    hits[3] += 1;
                    v.extend([1.0, t, f(out)]);
                }
                None => v.extend([0.0; 3]),
            }
            v.iter().map(|x| x.to_bits()).collect()
        })
        .collect();
    // The rays really exercise every shape.
    assert!(hits.iter().all(|&h| h > 1000), "hits per shape {hits:?}");
    for lanes in forms() {
        let got = simd::dispatch(
            lanes,
            Shapes {
                rays: &rays,
                sphere,
                rect,
                boxed,
            },
        );
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{} at {:?}", lanes.describe(), rays[k]);
        }
    }
}

struct OffsetKernel<'a>(&'a [(Vec3, Vec3)]);

impl LaneKernel for OffsetKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let a = self.0;
        chunks::<F, u32>(a.len(), |idx| {
            let p = V3::<F>::from_fn(|l| a[idx(l)].0);
            let n = V3::<F>::from_fn(|l| a[idx(l)].1);
            let o = prism::geometry::offset_ray_origin_lanes(p, n);
            bits_of(&[o.x, o.y, o.z])
        })
    }
}

/// The kernel spawns rays with the lane form of the robust offset: the same bits as the
/// scalar one, at every magnitude (near the origin, where the absolute offset takes over; at
/// ±0; at huge coordinates; on either side of zero).
#[test]
fn lane_ray_offsets_are_the_scalar_offsets() {
    let mut g = SplitMix(77);
    let special = [
        0.0f32,
        -0.0,
        1e-30,
        -1e-30,
        0.03,
        -0.03,
        1.0 / 32.0,
        1e30,
        -1e30,
        3.4e38,
    ];
    let mut a = Vec::new();
    for &x in &special {
        for &y in &special {
            let n = Vec3::new(g.range(-1.0, 1.0) as f32, 1.0, g.range(-1.0, 1.0) as f32);
            a.push((Vec3::new(x, y, -x), n.normalize()));
        }
    }
    for _ in 0..20_000 {
        let scale = 10f64.powf(g.range(-6.0, 6.0)) as f32;
        let p = Vec3::new(
            g.range(-1.0, 1.0) as f32,
            g.range(-1.0, 1.0) as f32,
            g.range(-1.0, 1.0) as f32,
        ) * scale;
        let n = prism::sampling::square_to_uniform_sphere(Vec2::new(
            g.range(0.0, 1.0) as f32,
            g.range(0.0, 1.0) as f32,
        ));
        a.push((p, n));
    }
    let want: Vec<Vec<u32>> = a
        .iter()
        .map(|&(p, n)| {
            let o = prism::geometry::offset_ray_origin(p, n);
            vec![o.x.to_bits(), o.y.to_bits(), o.z.to_bits()]
        })
        .collect();
    for lanes in forms() {
        let got = simd::dispatch(lanes, OffsetKernel(&a));
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{} at {:?}", lanes.describe(), a[k]);
        }
    }
}

struct LightKernel<'a> {
    scene: &'a RenderScene,
    /// Reference point, light choice, (ux, uy).
    queries: &'a [(Vec3, f32, f32, f32)],
}

/// A light sample's direction, radiance, density, delta flag, and point with its normal.
type LightFields = (Vec3, Vec3, f32, bool, Option<(Vec3, Vec3)>);

/// A light sample as comparable numbers: `[0]` without a sample, else its fields and its
/// source (as printed).
fn light_record(s: Option<LightFields>, source: String) -> Vec<u32> {
    let Some((wi, radiance, pdf, delta, point)) = s else {
        return vec![0];
    };
    let (q, nq) = point.unwrap_or((Vec3::NAN, Vec3::NAN));
    let mut v = vec![1, u32::from(delta), u32::from(point.is_some())];
    v.extend(
        [wi, radiance, q, nq]
            .iter()
            .flat_map(|x| x.to_array())
            .chain([pdf])
            .map(f32::to_bits),
    );
    v.extend(source.bytes().map(u32::from));
    v
}

impl LaneKernel for LightKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let (q, lights, prims) = (self.queries, &self.scene.lights, &self.scene.prims);
        chunks::<F, u32>(q.len(), |idx| {
            let p = V3::<F>::from_fn(|l| q[idx(l)].0);
            let sel = F::from_fn(|l| q[idx(l)].1);
            let (ux, uy) = (F::from_fn(|l| q[idx(l)].2), F::from_fn(|l| q[idx(l)].3));
            let mut sources = [prism::scene::lights::LightSource::Environment; 16];
            let all = <F::Mask as simd::Mask>::splat(true);
            let s = lights.sample_lanes::<F, false>(
                prims,
                p,
                all,
                sel,
                ux,
                uy,
                F::zero(),
                true,
                Some(&mut sources),
            );
            (0..F::WIDTH)
                .map(|l| {
                    let has = simd::Mask::lane(s.has, l);
                    let point =
                        simd::Mask::lane(s.at_point, l).then(|| (s.q.lane(l), s.nq.lane(l)));
                    let rec = has.then(|| {
                        let delta = simd::Mask::lane(s.delta, l);
                        (
                            s.wi.lane(l),
                            s.radiance.lane(l),
                            s.pdf.lane(l),
                            delta,
                            point,
                        )
                    });
                    light_record(
                        rec,
                        if has {
                            format!("{:?}", sources[l])
                        } else {
                            String::new()
                        },
                    )
                })
                .collect()
        })
    }
}

/// Every kind of light sampled over lanes (the environment, point and spot lights, Rect, Disk
/// and Sphere emitters, and a textured one, which takes the one-lane path) gives, lane for
/// lane, the scalar sample's bits and source; reference points include ones inside the
/// sphere light, behind the one-sided lamps and on the spot's edge.
#[test]
fn lane_light_samples_are_the_scalar_light_samples() {
    let dir = std::env::temp_dir().join(format!("prism-lane-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lights.ron");
    std::fs::write(
        &path,
        r#"#![enable(implicit_some)]
Scene(
    render: (width: 8, height: 8, spp: 1),
    camera: (position: (0.0, 1.0, 6.0), look_at: (0.0, 1.0, 0.0), fov_y: 40.0),
    environment: Constant(Rgb(0.1, 0.2, 0.3)),
    entities: [
        (name: "rect", shape: Rect(center: (0.0, 3.0, 0.0), u: (0.5, 0.0, 0.0), v: (0.0, 0.0, 0.5)),
         material: Light(emission: Rgb(4.0, 3.0, 2.0))),
        (name: "disk", shape: Disk(center: (2.0, 2.0, 0.0), normal: (-1.0, -1.0, 0.0), radius: 0.4),
         material: Light(emission: Rgb(2.0, 2.0, 5.0), two_sided: true)),
        (name: "ball", shape: Sphere(center: (-2.0, 1.0, 0.0), radius: 0.5),
         material: Light(emission: Rgb(6.0, 1.0, 1.0))),
        (name: "tex", shape: Rect(center: (0.0, 1.0, -3.0), u: (1.0, 0.0, 0.0), v: (0.0, 1.0, 0.0)),
         material: Light(emission: Rgb(1.0, 1.0, 1.0)),
         texture: (albedo: Checker(a: Rgb(0.9, 0.9, 0.9), b: Rgb(0.1, 0.2, 0.6), size: 0.25))),
        (name: "bulb", light: Point(position: (1.0, 2.5, 1.0), intensity: Rgb(5.0, 4.0, 3.0))),
        (name: "spot", light: Spot(position: (-1.0, 3.0, 1.0), direction: (0.3, -1.0, 0.0),
         cone: 30.0, falloff: 10.0, intensity: Rgb(20.0, 20.0, 20.0))),
        (name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (5.0, 0.0, 0.0), v: (0.0, 0.0, -5.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#,
    )
    .unwrap();
    let scene = scene_file(&path, &[]);
    std::fs::remove_dir_all(&dir).ok();
    let mut rng = SplitMix(0x11_6475);
    let mut u = move || (rng.unit() as f32).min(0.999_999_94);
    let mut queries = Vec::new();
    for k in 0..20_000 {
        let p = match k % 4 {
            // Inside the sphere light, near its surface, and anywhere in the room.
            0 => Vec3::new(-2.0, 1.0, 0.0) + (Vec3::new(u(), u(), u()) - 0.5) * 0.9,
            1 => Vec3::new(-2.0, 1.0, 0.0) + (Vec3::new(u(), u(), u()) - 0.5) * 1.2,
            _ => Vec3::new(u() * 8.0 - 4.0, u() * 5.0 - 0.5, u() * 8.0 - 4.0),
        };
        queries.push((p, u(), u(), u()));
    }
    let want: Vec<Vec<u32>> = queries
        .iter()
        .map(|&(p, sel, ux, uy)| {
            let s =
                scene
                    .lights
                    .sample::<false>(&scene.prims, p, sel, Vec2::new(ux, uy), 0.0, true);
            let source = s.map(|s| format!("{:?}", s.source)).unwrap_or_default();
            light_record(
                s.map(|s| (s.wi, s.radiance, s.pdf, s.delta, s.point)),
                source,
            )
        })
        .collect();
    // Every kind of light gave samples.
    let printed: Vec<String> = want
        .iter()
        .map(|v| v.iter().skip(16).map(|&b| b as u8 as char).collect())
        .collect();
    for kind in ["Environment", "Point", "Area"] {
        let n = printed.iter().filter(|s| s.starts_with(kind)).count();
        assert!(n > 1000, "{kind}: {n} samples");
    }
    for lanes in forms() {
        let got = simd::dispatch(
            lanes,
            LightKernel {
                scene: &scene,
                queries: &queries,
            },
        );
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{} at {:?}", lanes.describe(), queries[k]);
        }
    }
}

struct TextureKernel<'a> {
    albedos: &'a [prism::texture::AlbedoTexture],
    uvs: &'a [(f32, f32)],
}

impl LaneKernel for TextureKernel<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let (albedos, uvs) = (self.albedos, self.uvs);
        chunks::<F, u32>(uvs.len(), |idx| {
            let u = F::from_fn(|l| uvs[idx(l)].0);
            let v = F::from_fn(|l| uvs[idx(l)].1);
            let all = F::splat(0.0).eq(F::splat(0.0));
            let vals: Vec<F> = albedos
                .iter()
                .flat_map(|a| {
                    let c = a.eval_lanes(u, v, all);
                    [c.x, c.y, c.z]
                })
                .collect();
            bits_of(&vals)
        })
    }
}

#[test]
fn lane_texture_lookups_are_the_scalar_lookups() {
    use prism::texture::{AlbedoTexture, Bricks, Checker, TexImage, Wrap};
    use std::sync::Arc;
    let mut rng = SplitMix(0x7e_c5);
    // Odd sizes, so no index arithmetic hides behind a power of two.
    let (w, h) = (5, 3);
    let pixels = (0..w * h)
        .map(|_| [rng.unit() as f32, rng.unit() as f32, rng.unit() as f32])
        .collect();
    let image = Arc::new(TexImage::from_pixels(w, h, pixels));
    let mut albedos: Vec<AlbedoTexture> = [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror]
        .into_iter()
        .map(|wrap| AlbedoTexture::Image {
            image: image.clone(),
            wrap,
        })
        .collect();
    albedos.push(AlbedoTexture::Checker(Checker {
        a: Vec3::new(0.9, 0.8, 0.7),
        b: Vec3::new(0.1, 0.2, 0.3),
        size: 0.3,
    }));
    albedos.push(AlbedoTexture::Bricks(Bricks {
        brick: Vec3::new(0.5, 0.15, 0.1),
        mortar: Vec3::new(0.8, 0.8, 0.75),
        size: Vec2::new(0.4, 0.2),
        joint: 0.02,
    }));
    // Every special coordinate against every other, then random ones over several periods
    // and texel centres and edges exactly.
    let special = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        2.0,
        0.5,
        -1e-10,
        1e-10,
        -1e-45,
        1e-45,
        -f32::MIN_POSITIVE,
        1.0 - f32::EPSILON / 2.0,
        0.1 / 5.0,
        0.5 / 3.0,
        1e30,
        -1e30,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    let mut uvs: Vec<(f32, f32)> = special
        .iter()
        .flat_map(|&a| special.iter().map(move |&b| (a, b)))
        .collect();
    uvs.extend((0..20_000).map(|_| {
        (
            (rng.unit() * 8.0 - 4.0) as f32,
            (rng.unit() * 8.0 - 4.0) as f32,
        )
    }));
    uvs.extend((0..=2 * w).map(|k| (k as f32 / (2 * w) as f32, k as f32 / (2 * h) as f32)));
    let want: Vec<Vec<u32>> = uvs
        .iter()
        .map(|&(u, v)| {
            albedos
                .iter()
                .flat_map(|a| a.eval(Vec2::new(u, v)).to_array().map(f32::to_bits))
                .collect()
        })
        .collect();
    for lanes in forms() {
        let got = simd::dispatch(
            lanes,
            TextureKernel {
                albedos: &albedos,
                uvs: &uvs,
            },
        );
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{} at {:?}", lanes.describe(), uvs[k]);
        }
    }
}
