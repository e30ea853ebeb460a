//! Criterion benches of the environment map (`assets/env/studio.exr`, 1024×512): a bilinear
//! lookup with its MIS density (what an escaping path pays), and a light sample (a direction
//! drawn from the luminance distribution with its radiance and density), each over the same
//! 4,096 arguments, so the figures are time per 4,096 results. The constant environment's
//! lookup is a copy, its sample a uniform sphere warp: the map's cost is what these add.
//! The daylight sky (elevation 30°, turbidity 3): the model's 11 bands along a direction (an
//! RGB escape), its spectrum at 4 wavelengths (a spectral escape), and a sun sample.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use prism::scene::envmap::EnvMap;
use std::hint::black_box;

const N: usize = 4096;

fn map() -> EnvMap {
    let (img, _) = prism::film::read_image(std::path::Path::new("assets/env/studio.exr"))
        .expect("assets/env/studio.exr");
    EnvMap::new(
        img.width,
        img.height,
        &img.pixels,
        1.0,
        Vec3::new(0.0, 30.0, 0.0),
    )
    .expect("finite map")
}

/// Deterministic arguments: uniforms from a Weyl sequence, directions from them.
fn args() -> (Vec<Vec2>, Vec<Vec3>) {
    let u: Vec<Vec2> = (0..N)
        .map(|i| {
            let a = (i as f64 * 0.754_877_666_246_692_7).fract() as f32;
            let b = (i as f64 * 0.569_840_290_998_053_2).fract() as f32;
            Vec2::new(a, b)
        })
        .collect();
    let d = u
        .iter()
        .map(|u| prism::sampling::square_to_uniform_sphere(*u))
        .collect();
    (u, d)
}

fn environment(c: &mut Criterion) {
    let map = map();
    let (u, d) = args();
    let mut g = c.benchmark_group("environment");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("map lookup + pdf", |b| {
        b.iter(|| {
            let mut acc = Vec3::ZERO;
            for d in &d {
                acc += map.eval(black_box(*d)) * map.pdf(*d);
            }
            acc
        })
    });
    g.bench_function("map sample", |b| {
        b.iter(|| {
            let mut acc = Vec3::ZERO;
            for u in &u {
                if let Some((wi, l, pdf)) = map.sample(black_box(*u)) {
                    acc += wi + l / pdf;
                }
            }
            acc
        })
    });
    g.bench_function("constant: uniform sphere sample", |b| {
        b.iter(|| {
            let mut acc = Vec3::ZERO;
            for u in &u {
                acc += prism::sampling::square_to_uniform_sphere(black_box(*u));
            }
            acc
        })
    });
    let sky = prism::scene::sky::Sky::new(prism::scene::sky::SkyParams {
        sun_elevation: 30.0,
        sun_azimuth: 120.0,
        turbidity: 3.0,
        ground_albedo: Vec3::splat(0.3),
        sun: true,
        scale: 1.0,
    });
    g.bench_function("sky: rgb along a direction", |b| {
        b.iter(|| {
            let mut acc = Vec3::ZERO;
            for d in &d {
                acc += sky.rgb(black_box(*d));
            }
            acc
        })
    });
    g.bench_function("sky: spectrum at 4 wavelengths", |b| {
        b.iter(|| {
            let mut acc = 0.0f32;
            for (d, u) in d.iter().zip(&u) {
                let l = 360.0 + 470.0 * u.x;
                let v = sky.radiance(black_box(*d), [l, l + 117.5, l + 235.0, l + 352.5]);
                acc += v[0] + v[1] + v[2] + v[3];
            }
            acc
        })
    });
    g.bench_function("sky: sun sample", |b| {
        b.iter(|| {
            let mut acc = Vec3::ZERO;
            for u in &u {
                acc += sky.sample_sun(black_box(*u));
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, environment);
criterion_main!(benches);
