//! `prism info`: what a scene holds and what the renderer will make of it.

use super::CliError;
use super::args::InfoArgs;
use super::scene::{load_scene, prepare};
use crate::components::material::EmissionSyntax;
use crate::components::{Name, PointLight};
use crate::integrator;

/// `prism info`: the scene's settings, entities, effects manifest, lights, meshes and
/// kd-tree, on stdout.
pub(super) fn info(a: InfoArgs) -> Result<(), CliError> {
    let scene = load_scene(&a.scene, &a.set, &[])?;
    let rs = prepare(&scene, &a.force, 0)?;
    let s = &rs.settings;
    println!("scene: {}", a.scene.display());
    println!(
        "render: {}x{}, {} spp, max depth {}, seed {}, {:?} light sampling, rr depth {}, {:?} Fresnel, {:?} sampler, {:?} filter",
        s.width,
        s.height,
        s.spp,
        s.max_depth,
        s.seed,
        s.light_sampling,
        s.rr_depth,
        s.fresnel,
        s.sampler,
        s.filter
    );
    let (kind, why) = integrator::bdpt::choose(&rs);
    println!("estimator: {kind:?} ({why})");
    match crate::simd::Lanes::resolve(s.simd) {
        Ok(lanes) => println!("simd: {}", integrator::describe_lanes(lanes)),
        Err(e) => println!("simd: {e}"),
    }
    // Point and spot lights are not primitives; file order.
    let mut points: Vec<_> = scene
        .world
        .query::<(hecs::Entity, &Name, &PointLight)>()
        .iter()
        .map(|(e, n, l)| (e.id(), n.0.clone(), *l))
        .collect();
    points.sort_by_key(|p| p.0);
    println!("entities: {}", rs.prims.len() + points.len());
    for i in 0..rs.prims.len() {
        let m = rs.prims.materials[rs.prims.material[i] as usize];
        let texture = rs
            .prims
            .texture_of(i as u32)
            .map_or(String::new(), |t| format!(", texture: {t}"));
        println!(
            "  {}: {:?}, {m}{texture}",
            crate::components::quoted(&rs.prims.names[i]),
            rs.prims.kind[i]
        );
    }
    for (_, name, light) in points {
        println!("  {}: light: {light}", crate::components::quoted(&name));
    }
    let chosen = |l: &crate::scene::Lights| {
        l.environment.map_or(String::new(), |i| {
            format!(
                "; chosen for a light sample with probability {:.3}",
                l.table.pmf(i as usize)
            )
        })
    };
    // As the light table weighs them: the power an infinite light sends through a disc the
    // size of the scene (radius r), π r² ∫ L dω, as luminance.
    let bounds = rs.accel.bounds();
    let r = if bounds.is_empty() {
        1.0
    } else {
        0.5 * bounds.diagonal().length()
    };
    let power = |integral: glam::Vec3| {
        format!(
            "power {:.4e} W through the scene's disc (radius {r:.4})",
            std::f32::consts::PI * r * r * crate::scene::lights::luminance(integral)
        )
    };
    if let (Some(sky), Some(map)) = (&rs.lights.sky, &rs.lights.map) {
        let p = sky.params();
        let (w, h) = map.size();
        let sun = if sky.has_sun() {
            let c = sky.sun_rgb();
            format!(
                "; sun: disc of {:.4e} sr towards {:.4}, radiance ({:.4e}, {:.4e}, {:.4e}), \
                 {}, sampled uniformly on its disc{}",
                sky.sun_solid_angle(),
                sky.sun_direction(),
                c.x,
                c.y,
                c.z,
                power(c * sky.sun_solid_angle()),
                rs.lights.sun.map_or(String::new(), |i| format!(
                    ", chosen with probability {:.3}",
                    rs.lights.table.pmf(i as usize)
                ))
            )
        } else {
            "; no sun".into()
        };
        println!(
            "environment: {p}; spectral Hosek–Wilkie sky, {}, sampled by its {w}×{h} \
             tabulation's {}{}{sun}",
            power(map.mean() * 4.0 * std::f32::consts::PI),
            map.sampling(),
            chosen(&rs.lights)
        );
    } else if let Some(map) = &rs.lights.map {
        let (w, h) = map.size();
        let m = map.mean();
        println!(
            "environment: {map}; {w}×{h} texels, mean radiance ({:.4}, {:.4}, {:.4}), {}; \
             sampled by {}{}",
            m.x,
            m.y,
            m.z,
            power(m * 4.0 * std::f32::consts::PI),
            map.sampling(),
            chosen(&rs.lights)
        );
    } else if let Some(sky) = &scene.sky {
        println!(
            "environment: {}; black (scale 0): it lights nothing",
            sky.params()
        );
    } else if let Some(map) = &scene.environment_map {
        let (w, h) = map.size();
        println!("environment: {map}; {w}×{h} texels, all black: it lights nothing");
    } else if scene.environment != glam::Vec3::ZERO {
        println!(
            "environment: Constant({}); {}; sampled uniformly over the sphere{}",
            EmissionSyntax(scene.environment, scene.environment_spectrum),
            power(scene.environment * 4.0 * std::f32::consts::PI),
            chosen(&rs.lights)
        );
    }
    for w in rs.warnings() {
        println!("warning: {w}");
    }
    println!("effects:");
    for line in rs.effects.to_string().lines() {
        println!("  {line}");
    }
    let counts = rs
        .prims
        .counts()
        .iter()
        .map(|(k, n)| format!("{n} {k:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    println!("primitives: {} ({counts})", rs.prims.len());
    let kinds = &rs.lights.lights;
    let count = |f: fn(&crate::scene::LightKind) -> bool| kinds.iter().filter(|k| f(k)).count();
    let points = count(|k| matches!(k, crate::scene::LightKind::Point(_)));
    println!(
        "lights: {} ({} area{}{}{})",
        kinds.len(),
        count(|k| matches!(k, crate::scene::LightKind::Area(_))),
        if points > 0 {
            format!(", {points} point or spot")
        } else {
            String::new()
        },
        if rs.lights.environment.is_some() {
            ", environment"
        } else {
            ""
        },
        if rs.lights.sun.is_some() { ", sun" } else { "" }
    );
    for (i, m) in rs.prims.meshes.iter().enumerate() {
        let b = m.shape.bounds();
        println!(
            "mesh {i}: {}; object bounds ({:.4}, {:.4}, {:.4})..({:.4}, {:.4}, {:.4})",
            m.shape.stats(),
            b.min.x,
            b.min.y,
            b.min.z,
            b.max.x,
            b.max.y,
            b.max.z
        );
    }
    let k = rs.accel.stats();
    println!(
        "kd-tree: {} nodes ({} leaves, {} empty), depth {}, {:.2} primitives per leaf, {} references, built in {:.3} ms",
        k.nodes,
        k.leaves,
        k.empty_leaves,
        k.max_depth,
        k.mean_leaf_prims,
        k.prim_refs,
        rs.accel_seconds * 1e3
    );
    Ok(())
}
