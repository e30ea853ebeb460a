//! What each effect costs: time per sample of a scene as it is, and with every effect it does
//! not need forced on.

use crate::integrator::{RenderOptions, render};
use crate::kdtree::KdParams;
use crate::scene::Effect;
use crate::scene_file;
use crate::systems;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Median of `runs` timings of a render, in nanoseconds per sample.
fn ns_per_sample(rs: &crate::scene::RenderScene, spp: u32, runs: usize) -> f64 {
    let opts = RenderOptions {
        sample_offset: 0,
        spp,
        time_limit: None,
        lanes: crate::simd::Lanes::auto(),
        monochromatic: None,
        stop: None,
        target_error: None,
        strategy: None,
    };
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let out = render(rs, &opts, &|_| {});
            out.seconds * 1e9 / out.stats.samples.max(1) as f64
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// A markdown table: per scene, the effects it uses, its time per sample, and the ratio
/// with each absent (implemented) effect forced on. Runs alternate between the plain and the
/// forced scene so machine noise hits both alike.
pub fn effect_costs(
    scenes: &[PathBuf],
    set: &[(String, String)],
    spp: u32,
    runs: usize,
) -> Result<String, String> {
    let mut s = String::from(
        "| scene | effects on | ns/sample | forced effect | ns/sample | ratio |\n|---|---|---|---|---|---|\n",
    );
    for path in scenes {
        let loaded = scene_file::load(path, set).map_err(|e| e.to_string())?;
        let base = systems::prepare(&loaded, &KdParams::default());
        let on: Vec<&str> = Effect::ALL
            .iter()
            .filter(|e| base.effects.has(**e))
            .map(|e| e.name())
            .collect();
        let on = if on.is_empty() {
            "none".to_string()
        } else {
            on.join(", ")
        };
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().to_string());
        let mut any = false;
        for e in Effect::ALL
            .into_iter()
            .filter(|e| e.implemented() && !base.effects.has(*e))
        {
            let mut forced = systems::prepare(&loaded, &KdParams::default());
            forced.effects.force(e)?;
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for _ in 0..runs {
                a.push(ns_per_sample(&base, spp, 1));
                b.push(ns_per_sample(&forced, spp, 1));
            }
            a.sort_by(f64::total_cmp);
            b.sort_by(f64::total_cmp);
            let (ma, mb) = (a[a.len() / 2], b[b.len() / 2]);
            writeln!(
                s,
                "| {name} | {on} | {ma:.0} | {} | {mb:.0} | {:.3}× |",
                e.name(),
                mb / ma
            )
            .unwrap();
            any = true;
        }
        if !any {
            let m = ns_per_sample(&base, spp, runs);
            writeln!(s, "| {name} | {on} | {m:.0} | – | – | – |").unwrap();
        }
    }
    Ok(s)
}
