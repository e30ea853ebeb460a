//! A white furnace seen from far away: a unit sphere in a constant white environment, whose
//! mean radiance over its disc follows from the whole image's mean.

use super::render::{mean_where, run, scene};
use prism::scene::Effect;
use std::f64::consts::PI;

/// A unit sphere seen from 400 units away, filling a 48×48 image to a radius of ≈ 19 px: the
/// view rays are parallel to 1/400, so the sphere's points are seen at cosines distributed
/// as 2μ dμ over its disc.
const DIST: f64 = 400.0;
const FOV_Y: f64 = 0.35;
const SIZE: u32 = 48;

pub fn far_sphere(material: &str, spp: u32, seed: u32, extra: &str, max_depth: u32) -> String {
    format!(
        r#"#![enable(implicit_some)]
Scene(
    render: (width: {SIZE}, height: {SIZE}, spp: {spp}, max_depth: {max_depth}, seed: {seed}{extra}),
    camera: (position: (0.0, 0.0, {DIST}), look_at: (0.0, 0.0, 0.0), fov_y: {FOV_Y}),
    environment: Constant(Rgb(1.0, 1.0, 1.0)),
    entities: [ (name: "ball", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: {material}) ],
)"#
    )
}

/// The sphere's share of the image: its silhouette is the cone of half-angle asin(1/d), a
/// disc of radius tan(asin(1/d)) / tan(fov/2) · H/2 pixels.
pub fn sphere_fraction() -> f64 {
    let half = (FOV_Y.to_radians() / 2.0).tan();
    let r = (1.0 / DIST).asin().tan() / half * f64::from(SIZE) / 2.0;
    PI * r * r / f64::from(SIZE * SIZE)
}

/// The mean radiance over the sphere's disc, from the whole image's mean: the pixel filter
/// is a partition of unity, so the image mean is the exact area mean of the radiance, and
/// the background is the environment's 1.
pub fn sphere_mean(material: &str, spp: u32, seed: u32, extra: &str) -> [f64; 3] {
    sphere_mean_in(material, spp, seed, extra, false, 16)
}

/// [`sphere_mean`] in RGB or spectral transport, paths of at most `max_depth` bounces.
pub fn sphere_mean_in(
    material: &str,
    spp: u32,
    seed: u32,
    extra: &str,
    spectral: bool,
    max_depth: u32,
) -> [f64; 3] {
    let mut s = scene(&far_sphere(material, spp, seed, extra, max_depth));
    if spectral {
        s.effects.force(Effect::Spectral).unwrap();
    }
    let img = run(&s).image();
    let f = sphere_fraction();
    std::array::from_fn(|c| {
        let all = mean_where(&img, c, |_, _| true);
        1.0 - (1.0 - all) / f
    })
}
