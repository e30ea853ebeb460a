//! Adaptive against uniform sampling at equal true error, and the estimate against the truth.
//!
//! For each scene (at `--size`, default 128×128): a reference rendered adaptively to a twentieth
//! of the target (or for `--ref-seconds`, default 120), whose own estimated noise is subtracted
//! from every true error (and printed); an adaptive
//! render to `--target` (default 0.01) over `--seeds` seeds; and a ladder of uniform renders
//! (doubling sample counts) whose time to the adaptive render's true error is interpolated on
//! the log–log line between the rungs around it. Prints a Markdown table.
//!
//! ```text
//! cargo run --release --example adaptive -- scenes/cornell.ron scenes/caustics.ron
//! ```

use prism::film;
use prism::integrator::{MAX_ADAPTIVE_SPP, RenderOptions, render};
use prism::kdtree::KdParams;
use prism::simd::Lanes;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let mut scenes: Vec<PathBuf> = Vec::new();
    let (mut size, mut target, mut seeds, mut ref_seconds) = (128u32, 0.01f64, 1u64, 120.0f64);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().expect("a value after the option");
        match a.as_str() {
            "--size" => size = value().parse().expect("--size N"),
            "--target" => target = value().parse().expect("--target T"),
            "--seeds" => seeds = value().parse().expect("--seeds N"),
            "--ref-seconds" => ref_seconds = value().parse().expect("--ref-seconds S"),
            _ => scenes.push(a.into()),
        }
    }
    if scenes.is_empty() {
        for s in ["cornell", "textures", "fog_lamps", "caustics"] {
            scenes.push(format!("scenes/{s}.ron").into());
        }
    }
    println!(
        "| scene | seed | adaptive s | mean spp | estimated | true | true / target | uniform s (same true error) | uniform spp | adaptive / uniform |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for path in &scenes {
        let load = |seed: u64| {
            let o: Vec<(String, String)> = vec![
                ("render.width".into(), size.to_string()),
                ("render.height".into(), size.to_string()),
                ("render.seed".into(), seed.to_string()),
            ];
            let scene = prism::scene_file::load(path, &o).expect("scene loads");
            prism::systems::prepare(&scene, &KdParams::default())
        };
        let adaptive = |seed: u64, t: f64, limit: Option<f64>| {
            let rs = load(seed);
            let mut o = RenderOptions::new(MAX_ADAPTIVE_SPP, Lanes::auto());
            o.target_error = Some(t);
            o.time_limit = limit;
            let t0 = Instant::now();
            let out = render(&rs, &o, &|_| {});
            (out, t0.elapsed().as_secs_f64())
        };
        let (reference, _) = adaptive(999, target / 20.0, Some(ref_seconds));
        let ref_noise = reference.estimate.unwrap_or(0.0);
        eprintln!(
            "{}: reference {:.0} spp on average, estimated relMSE {ref_noise:.2e}",
            path.display(),
            reference.mean_spp()
        );
        let ref_img = reference.image();
        let truth = |img: &film::Image| film::compare(img, &ref_img).unwrap().relmse - ref_noise;
        for seed in 1..=seeds {
            let (out, t_a) = adaptive(seed, target, None);
            let e_a = truth(&out.image());
            // Uniform ladder until its true error drops below the adaptive one.
            let rs = load(seed);
            let mut rungs: Vec<(u32, f64, f64)> = Vec::new();
            let mut spp = 8u32;
            loop {
                let t0 = Instant::now();
                let img = render(&rs, &RenderOptions::new(spp, Lanes::auto()), &|_| {}).image();
                let t = t0.elapsed().as_secs_f64();
                let e = truth(&img);
                rungs.push((spp, t, e));
                if e <= e_a || spp >= 1 << 16 {
                    break;
                }
                spp *= 2;
            }
            let (t_u, n_u) = match rungs.len() {
                0 => (f64::NAN, f64::NAN),
                1 => (rungs[0].1, f64::from(rungs[0].0)),
                k => {
                    let (a, b) = (rungs[k - 2], rungs[k - 1]);
                    // log e linear in log t between the two rungs (e > 0 on both).
                    let f = if a.2 > 0.0 && b.2 > 0.0 && a.2 != b.2 {
                        ((e_a.max(1e-12)).ln() - a.2.ln()) / (b.2.ln() - a.2.ln())
                    } else {
                        1.0
                    };
                    let f = f.clamp(0.0, 1.0);
                    let t = (a.1.ln() + f * (b.1.ln() - a.1.ln())).exp();
                    let n = (f64::from(a.0).ln() + f * (f64::from(b.0).ln() - f64::from(a.0).ln()))
                        .exp();
                    (t, n)
                }
            };
            println!(
                "| {} | {seed} | {t_a:.2} | {:.0} | {:.2e} | {e_a:.2e} | {:.2} | {t_u:.2} | {n_u:.0} | {:.2} |",
                path.file_stem().unwrap().to_string_lossy(),
                out.mean_spp(),
                out.estimate.unwrap_or(f64::NAN),
                e_a / target,
                t_a / t_u
            );
        }
    }
}
