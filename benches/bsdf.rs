//! Criterion benches of the BSDFs over lanes: `sample`, and `eval` with `pdf` (what a light
//! sample costs), of each material at each lane width, over the same 4,096 (wo, wi, u)
//! arguments, so the figures are time per 4,096 results at each width.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use prism::energy::coat_table_cached;
use prism::integrator::bsdf::{Chan, Diffuse, Mode};
use prism::integrator::coat::Plastic;
use prism::integrator::microfacet::{Conductor, ConductorFresnel, Ggx, RoughDielectric};
use prism::simd::{self, Float, LaneKernel, Mask, UInt, V3};
use std::hint::black_box;

#[path = "common/forms.rs"]
mod forms;
use forms::forms;

#[derive(Clone, Copy)]
enum Bsdf {
    Diffuse,
    /// GGX conductor with exact complex Fresnel, α 0.3.
    Conductor {
        multiscatter: bool,
    },
    /// Frosted glass entering η 1.5, α 0.3.
    Dielectric {
        multiscatter: bool,
    },
    /// Rough plastic, η 1.5, α 0.3.
    Plastic,
}

#[derive(Clone, Copy)]
enum Op {
    Sample,
    EvalPdf,
}

/// Arguments in structure-of-arrays form: wo and wi (unit, wo above), three uniforms.
struct Args {
    wo: [Vec<f32>; 3],
    wi: [Vec<f32>; 3],
    u: [Vec<f32>; 3],
}

impl Args {
    fn new(n: usize) -> Args {
        // A fixed low-discrepancy-ish spread: golden-ratio sequences, no RNG needed.
        let frac = |x: f64| (x - x.floor()) as f32;
        let dir = |a: f32, b: f32, below: bool| {
            let z = 0.02 + 0.98 * a;
            let r = (1.0 - z * z).sqrt();
            let phi = std::f32::consts::TAU * b;
            Vec3::new(r * phi.cos(), r * phi.sin(), if below { -z } else { z })
        };
        let g = [0.618_034, 0.754_878, 0.569_840, 0.430_159, 0.310_339];
        let (mut wo, mut wi, mut u) = (
            [vec![], vec![], vec![]],
            [vec![], vec![], vec![]],
            [vec![], vec![], vec![]],
        );
        for i in 0..n {
            let x = |k: usize| frac(0.5 + i as f64 * g[k]);
            let o = dir(x(0), x(1), false);
            let w = dir(x(2), x(3), i % 3 == 0);
            for c in 0..3 {
                wo[c].push(o[c]);
                wi[c].push(w[c]);
                u[c].push(frac(0.25 + i as f64 * g[(c + 2) % 5]).min(0.999_999));
            }
        }
        Args { wo, wi, u }
    }
}

struct Run<'a> {
    bsdf: Bsdf,
    op: Op,
    args: &'a Args,
    coat: &'a [f32],
    out: &'a mut [f32],
}

impl LaneKernel for Run<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: Float>(self) {
        let a = self.args;
        let alpha = F::splat(0.3);
        let no = F::Mask::splat(false);
        for i in (0..self.out.len()).step_by(F::WIDTH) {
            let v = |c: &[Vec<f32>; 3]| {
                V3::new(
                    F::load(&c[0][i..]),
                    F::load(&c[1][i..]),
                    F::load(&c[2][i..]),
                )
            };
            let (wo, wi) = (v(&a.wo), v(&a.wi));
            let (u0, u1, u2) = (
                F::load(&a.u[0][i..]),
                F::load(&a.u[1][i..]),
                F::load(&a.u[2][i..]),
            );
            let r = match self.bsdf {
                Bsdf::Diffuse => {
                    let d = Diffuse {
                        albedo: Chan([F::splat(0.5); 3]),
                    };
                    match self.op {
                        Op::Sample => {
                            let s = d.sample(wo, u1, u2);
                            s.weight.0[0] + s.pdf + s.wi.z
                        }
                        Op::EvalPdf => d.eval(wo, wi).0[0] + d.pdf(wo, wi),
                    }
                }
                Bsdf::Conductor { multiscatter } => {
                    let c: Conductor<F, 3> = Conductor {
                        dist: Ggx::isotropic(alpha),
                        smooth: no,
                        multiscatter: F::Mask::splat(multiscatter),
                        fresnel: ConductorFresnel {
                            eta: Chan([0.18, 0.42, 1.37].map(F::splat)),
                            k: Chan([3.42, 2.35, 1.77].map(F::splat)),
                            schlick: no,
                        },
                    };
                    match self.op {
                        Op::Sample => {
                            let s = c.sample(wo, u1, u2);
                            s.weight.0[0] + s.pdf + s.wi.z
                        }
                        Op::EvalPdf => c.eval(wo, wi).0[0] + c.pdf(wo, wi),
                    }
                }
                Bsdf::Dielectric { multiscatter } => {
                    let d = RoughDielectric {
                        dist: Ggx::isotropic(alpha),
                        eta: F::splat(1.5),
                        schlick: false,
                        multiscatter: F::Mask::splat(multiscatter),
                    };
                    match self.op {
                        Op::Sample => {
                            let s = d.sample::<Chan<F, 1>>(wo, u0, u1, u2, Mode::Radiance);
                            s.weight.0[0] + s.pdf + s.wi.z
                        }
                        Op::EvalPdf => d.eval(wo, wi, Mode::Radiance) + d.pdf(wo, wi),
                    }
                }
                Bsdf::Plastic => {
                    let p: Plastic<'_, F, 3> = Plastic {
                        dist: Ggx::isotropic(alpha),
                        smooth: no,
                        eta: F::splat(1.5),
                        albedo: Chan([F::splat(0.5); 3]),
                        tables: self.coat,
                        base: F::U32::splat(0),
                    };
                    match self.op {
                        Op::Sample => {
                            let s = p.sample(wo, u0, u1, u2);
                            s.weight.0[0] + s.pdf + s.wi.z
                        }
                        Op::EvalPdf => p.eval(wo, wi).0[0] + p.pdf(wo, wi),
                    }
                }
            };
            r.store(&mut self.out[i..]);
        }
    }
}

fn bsdfs(c: &mut Criterion) {
    let n = 4096;
    let args = Args::new(n);
    let coat = coat_table_cached(1.5);
    let mut out = vec![0.0f32; n];
    let mut g = c.benchmark_group("bsdf");
    g.throughput(Throughput::Elements(n as u64));
    for (name, bsdf) in [
        ("diffuse", Bsdf::Diffuse),
        (
            "conductor",
            Bsdf::Conductor {
                multiscatter: false,
            },
        ),
        ("conductor_ms", Bsdf::Conductor { multiscatter: true }),
        (
            "dielectric",
            Bsdf::Dielectric {
                multiscatter: false,
            },
        ),
        ("dielectric_ms", Bsdf::Dielectric { multiscatter: true }),
        ("plastic", Bsdf::Plastic),
    ] {
        for (op_name, op) in [("sample", Op::Sample), ("eval_pdf", Op::EvalPdf)] {
            for (form, lanes) in forms() {
                g.bench_function(format!("{name}_{op_name}_{form}"), |bench| {
                    bench.iter(|| {
                        simd::dispatch(
                            lanes,
                            Run {
                                bsdf,
                                op,
                                args: black_box(&args),
                                coat: &coat,
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

criterion_group!(benches, bsdfs);
criterion_main!(benches);
