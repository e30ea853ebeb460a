//! Criterion benches of the lane math and of sample generation: one function per operation
//! and lane form, over the same 4,096 arguments, so the figures are time per 4,096 results at
//! each width.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use prism::simd::{self, Float, LaneKernel, Lanes, math};
use std::hint::black_box;

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

fn forms() -> Vec<(String, Lanes)> {
    let mut v = vec![
        ("w1".to_string(), Lanes::scalar()),
        ("portable8".to_string(), Lanes::portable(8)),
    ];
    if let Some(l) = Lanes::native8() {
        v.push(("w8".to_string(), l));
    }
    if let Some(l) = Lanes::native16() {
        v.push(("w16".to_string(), l));
    }
    v
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
            // differ in sample index, as in the packet kernel.
            let (x, y, index) = (k.shri::<4>(), F::U32::splat(7), k & F::U32::splat(15));
            let r = if self.rays {
                let c = prism::integrator::path::camera_rays::<F, false>(&self.ctx, x, y, index);
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

criterion_group!(benches, lane_math, sample_generation);
criterion_main!(benches);
