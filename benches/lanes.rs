//! Criterion benches of the lane math and of sample generation: one function per operation
//! and lane form, over the same 4,096 arguments, so the figures are time per 4,096 results at
//! each width.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use prism::simd::{self, Float, LaneKernel, math};
use std::hint::black_box;

#[path = "common/forms.rs"]
mod forms;
use forms::forms;

#[derive(Clone, Copy)]
enum Op {
    SinCos,
    Exp,
    Ln,
    Atan2,
    Acos,
    Powf,
}

struct Run<'a> {
    op: Op,
    a: &'a [f32],
    b: &'a [f32],
    out: &'a mut [f32],
}

impl LaneKernel for Run<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        for i in (0..self.a.len()).step_by(F::WIDTH) {
            let x = F::load(&self.a[i..]);
            let y = F::load(&self.b[i..]);
            let r = match self.op {
                Op::SinCos => {
                    let (s, c) = math::sin_cos(x);
                    s + c
                }
                Op::Exp => math::exp(x),
                Op::Ln => math::ln(x),
                Op::Atan2 => math::atan2(x, y),
                Op::Acos => math::acos(y),
                Op::Powf => math::powf(x, y),
            };
            r.store(&mut self.out[i..]);
        }
    }
}

fn lane_math(c: &mut Criterion) {
    let n = 4096;
    let a: Vec<f32> = (0..n).map(|i| 0.01 + i as f32 * 0.002).collect();
    let b: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin() * 0.99).collect();
    let mut out = vec![0.0f32; n];
    let mut g = c.benchmark_group("lane_math");
    g.throughput(Throughput::Elements(n as u64));
    for (name, op) in [
        ("sin_cos", Op::SinCos),
        ("exp", Op::Exp),
        ("ln", Op::Ln),
        ("atan2", Op::Atan2),
        ("acos", Op::Acos),
        ("powf", Op::Powf),
    ] {
        for (form, lanes) in forms() {
            g.bench_function(format!("{name}_{form}"), |bench| {
                bench.iter(|| {
                    simd::dispatch(
                        lanes,
                        Run {
                            op,
                            a: black_box(&a),
                            b: black_box(&b),
                            out: &mut out,
                        },
                    );
                    black_box(out[7])
                })
            });
        }
    }
    g.finish();
}

/// Sample generation alone: 4,096 2-D Owen-Sobol samples, and 4,096 camera rays of the
/// Cornell box (tent-filtered film samples through the pinhole).
struct Generate<'a> {
    ctx: prism::integrator::Ctx<'a>,
    rays: bool,
    out: &'a mut [f32],
}

impl LaneKernel for Generate<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        use prism::simd::UInt;
        let w = self.ctx.width;
        for i in (0..self.out.len()).step_by(F::WIDTH) {
            let k = F::U32::from_fn(|l| (i + l) as u32);
            // Sixteen samples of each pixel along a row: neighbouring lanes share pixels and
            // differ in sample index, as in the kernel.
            let (x, y, index) = (k.shri::<4>(), F::U32::splat(7), k & F::U32::splat(15));
            let r = if self.rays {
                let c =
                    prism::integrator::generate::camera_rays::<F, false>(&self.ctx, x, y, index);
                c.d.x + c.d.y + c.d.z
            } else {
                let pixel = y.wrapping_mul(F::U32::splat(w)).wrapping_add(x);
                let (a, b) = self
                    .ctx
                    .sampler
                    .get_2d_lanes::<F>(pixel, index, F::U32::splat(8));
                a + b
            };
            r.store(&mut self.out[i..]);
        }
    }
}

fn sample_generation(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let loaded = prism::scene_file::load(&path, &[]).expect("cornell.ron loads");
    let scene = prism::systems::prepare(&loaded, &prism::kdtree::KdParams::default());
    let ctx = prism::integrator::Ctx::new(&scene, false);
    let n = 4096;
    let mut out = vec![0.0f32; n];
    let mut g = c.benchmark_group("sample_generation");
    g.throughput(Throughput::Elements(n as u64));
    for (name, rays) in [("sobol_2d", false), ("camera_rays", true)] {
        for (form, lanes) in forms() {
            g.bench_function(format!("{name}_{form}"), |bench| {
                bench.iter(|| {
                    simd::dispatch(
                        lanes,
                        Generate {
                            ctx: black_box(ctx),
                            rays,
                            out: &mut out,
                        },
                    );
                    black_box(out[7])
                })
            });
        }
    }
    g.finish();
}

fn cornell(size: u32, spp: u32) -> prism::scene::RenderScene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let o = vec![
        ("render.width".to_string(), size.to_string()),
        ("render.height".to_string(), size.to_string()),
        ("render.spp".to_string(), spp.to_string()),
    ];
    let loaded = prism::scene_file::load(&path, &o).expect("cornell.ron loads");
    prism::systems::prepare(&loaded, &prism::kdtree::KdParams::default())
}

/// The whole Cornell render (camera rays to film) at each lane form.
fn render_widths(c: &mut Criterion) {
    use prism::integrator::{RenderOptions, render};
    let scene = cornell(64, 4);
    let mut g = c.benchmark_group("render_widths");
    g.sample_size(10);
    g.throughput(Throughput::Elements(64 * 64 * 4));
    // The portable forms are test oracles with out-of-line operations: not timed here.
    for (form, lanes) in forms().into_iter().filter(|(_, l)| l.is_native()) {
        let opts = RenderOptions::new(4, lanes);
        g.bench_function(format!("cornell_64x64_4spp_{form}"), |b| {
            b.iter(|| render(&scene, &opts, &|_| {}).stats.samples)
        });
    }
    g.finish();
}

#[inline(always)]
fn load3<F: Float>(a: &[[f32; 4096]; 3], i: usize) -> prism::simd::V3<F> {
    prism::simd::V3::new(
        F::load(&a[0][i..]),
        F::load(&a[1][i..]),
        F::load(&a[2][i..]),
    )
}

/// Closest hits of SoA rays, a packet per `F::WIDTH` rays: the packet kd walk, or each lane's
/// own single-ray walk.
struct Closest<'a> {
    scene: &'a prism::scene::RenderScene,
    o: &'a [[f32; 4096]; 3],
    d: &'a [[f32; 4096]; 3],
    packet: bool,
}

impl LaneKernel for Closest<'_> {
    type Output = u32;
    #[inline(always)]
    fn run<F: Float>(self) -> u32 {
        use prism::simd::Mask;
        let mut found = 0;
        for i in (0..4096).step_by(F::WIDTH) {
            let (o, d) = (load3::<F>(self.o, i), load3::<F>(self.d, i));
            if self.packet {
                let h = self.scene.intersect_packet::<F, false>(
                    o,
                    d,
                    <F::Mask as Mask>::splat(true),
                    F::zero(),
                );
                found += h.hit.count();
            } else {
                for l in 0..F::WIDTH {
                    let ray = prism::geometry::Ray::new(o.lane(l), d.lane(l));
                    found += u32::from(
                        self.scene
                            .intersect::<false>(&ray, f32::INFINITY, 0.0)
                            .is_some(),
                    );
                }
            }
        }
        found
    }
}

/// The kd-tree walked as a packet against one ray at a time per lane, on coherent camera
/// rays (four samples of each pixel, pixels along rows, as the kernel orders them) and
/// on incoherent diffuse-like rays (random points and directions inside the box).
fn kd_packet(c: &mut Criterion) {
    use prism::sampling::{Sampler, SamplerKind, square_to_uniform_sphere};
    let scene = cornell(32, 4);
    let ctx = prism::integrator::Ctx::new(&scene, false);
    let mut cam = ([[0.0f32; 4096]; 3], [[0.0f32; 4096]; 3]);
    for k in 0..4096u32 {
        let (p, idx) = (k / 4, k % 4);
        let r = prism::integrator::generate::camera_rays::<f32, false>(&ctx, p % 32, p / 32, idx);
        for (a, v) in [(&mut cam.0, r.o), (&mut cam.1, r.d)] {
            (a[0][k as usize], a[1][k as usize], a[2][k as usize]) = (v.x, v.y, v.z);
        }
    }
    let s = Sampler::new(SamplerKind::Independent, 3);
    let mut diffuse = ([[0.0f32; 4096]; 3], [[0.0f32; 4096]; 3]);
    for k in 0..4096u32 {
        let o = glam::Vec3::new(278.0, 273.0, 280.0)
            + square_to_uniform_sphere(s.get_2d(k, 0, 0)) * 200.0;
        let d = square_to_uniform_sphere(s.get_2d(k, 0, 2));
        for (a, v) in [(&mut diffuse.0, o), (&mut diffuse.1, d)] {
            (a[0][k as usize], a[1][k as usize], a[2][k as usize]) = (v.x, v.y, v.z);
        }
    }
    let mut g = c.benchmark_group("kd_packet");
    g.throughput(Throughput::Elements(4096));
    for (rays, (o, d)) in [("camera", &cam), ("diffuse", &diffuse)] {
        for (form, lanes) in forms() {
            for packet in [true, false] {
                if lanes.width() == 1 && !packet {
                    continue;
                }
                let walk = if packet { "packet" } else { "per_lane" };
                g.bench_function(format!("{rays}_{walk}_{form}"), |b| {
                    b.iter(|| {
                        simd::dispatch(
                            lanes,
                            Closest {
                                scene: &scene,
                                o,
                                d,
                                packet,
                            },
                        )
                    })
                });
            }
        }
    }
    g.finish();
}

struct TextureLookups<'a> {
    albedo: &'a prism::texture::AlbedoTexture,
    uv: &'a [[f32; 4096]; 2],
    lanes: bool,
    out: &'a mut [f32],
}

impl LaneKernel for TextureLookups<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        let all = F::zero().eq(F::zero());
        for i in (0..self.out.len()).step_by(F::WIDTH) {
            let (u, v) = (F::load(&self.uv[0][i..]), F::load(&self.uv[1][i..]));
            let c = if self.lanes {
                self.albedo.eval_lanes(u, v, all)
            } else {
                // The alternative the surface stage had: one scalar lookup per lane.
                prism::simd::V3::from_fn(|l| {
                    self.albedo.eval(glam::Vec2::new(u.lane(l), v.lane(l)))
                })
            };
            (c.x + c.y + c.z).store(&mut self.out[i..]);
        }
    }
}

/// An albedo texture's lookups for a packet: all lanes at once (gathers for an image) against
/// one scalar lookup per lane, over 4,096 random uv.
fn texture_lookup(c: &mut Criterion) {
    use prism::texture::{AlbedoTexture, Checker, TexImage, Wrap};
    let (w, h) = (1024u32, 512u32);
    let mut x = 0x2545_f491_u32;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        (x >> 8) as f32 / (1u32 << 24) as f32
    };
    let pixels = (0..w * h).map(|_| [next(), next(), next()]).collect();
    let image = AlbedoTexture::Image {
        image: std::sync::Arc::new(TexImage::from_pixels(w, h, pixels)),
        wrap: Wrap::Repeat,
    };
    let checker = AlbedoTexture::Checker(Checker {
        a: glam::Vec3::splat(0.8),
        b: glam::Vec3::splat(0.2),
        size: 0.05,
    });
    let mut uv = Box::new([[0.0f32; 4096]; 2]);
    for k in 0..4096 {
        uv[0][k] = next() * 2.0 - 0.5;
        uv[1][k] = next() * 2.0 - 0.5;
    }
    let mut out = vec![0.0f32; 4096];
    let mut g = c.benchmark_group("texture_lookup");
    g.throughput(Throughput::Elements(4096));
    for (name, albedo) in [("image_1024x512", &image), ("checker", &checker)] {
        for (form, lanes) in forms() {
            for (how, in_lanes) in [("lanes", true), ("per_lane", false)] {
                g.bench_function(format!("{name}_{how}_{form}"), |bench| {
                    bench.iter(|| {
                        simd::dispatch(
                            lanes,
                            TextureLookups {
                                albedo,
                                uv: &uv,
                                lanes: in_lanes,
                                out: &mut out,
                            },
                        );
                        black_box(out[7])
                    })
                });
            }
        }
    }
    g.finish();
}

criterion_group!(
    benches,
    texture_lookup,
    lane_math,
    sample_generation,
    render_widths,
    kd_packet
);
criterion_main!(benches);
