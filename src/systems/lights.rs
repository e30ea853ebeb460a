//! `gather_lights`: the emitters, chosen by power through an alias table.

use crate::geometry::Aabb;
use crate::sampling::AliasTable;
use crate::scene::envmap::EnvMap;
use crate::scene::lights::luminance;
use crate::scene::sky::Sky;
use crate::scene::{LightKind, Lights, PrimKind, Primitives};
use glam::Vec3;

/// Collects the emitters and builds the power-proportional selection table. Records each
/// emitter's light index on its primitive, so a path that hits it by chance finds its pdf.
pub fn gather_lights(
    world: &hecs::World,
    prims: &mut Primitives,
    environment: Vec3,
    map: Option<&std::sync::Arc<EnvMap>>,
    sky: Option<&std::sync::Arc<Sky>>,
    scene_bounds: &Aabb,
) -> Lights {
    let mut lights = Vec::new();
    let mut power = Vec::new();
    let mut points: Vec<(hecs::Entity, crate::components::PointLight)> = world
        .query::<(hecs::Entity, &crate::components::PointLight)>()
        .iter()
        .map(|(e, l)| (e, *l))
        .collect();
    points.sort_by_key(|(e, _)| e.id());
    for (_, l) in points {
        lights.push(LightKind::Point(l));
        power.push(luminance(l.power()).max(1e-6));
    }
    for i in 0..prims.len() {
        let m = prims.materials[prims.material[i] as usize];
        if !m.is_emissive() {
            continue;
        }
        let l = prims.local[i] as usize;
        let area = match prims.kind[i] {
            PrimKind::Sphere => prims.spheres[l].area(),
            PrimKind::Rect | PrimKind::Disk => prims.planars[l].area(),
            PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => continue,
        };
        let (e, sides) = match m {
            crate::components::Material::Light {
                emission,
                two_sided,
                ..
            } => (emission, if two_sided { 2.0 } else { 1.0 }),
            _ => unreachable!("is_emissive"),
        };
        prims.light[i] = lights.len() as u32;
        lights.push(LightKind::Area(i as u32));
        power.push(std::f32::consts::PI * area * sides * luminance(e).max(1e-6));
    }
    let mut env_index = None;
    // As pbrt does, an infinite light's power is that of a disc the size of the scene facing
    // it from every direction (or from the sun's).
    let (centre, r) = if scene_bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (
            scene_bounds.center(),
            (0.5 * scene_bounds.diagonal().length()).max(1e-6),
        )
    };
    let map = map.filter(|m| m.emits());
    let (kind, radiance) = match map {
        Some(m) => (LightKind::EnvMap, m.mean()),
        None => (LightKind::Environment(environment), environment),
    };
    if radiance.max_element() > 0.0 {
        env_index = Some(lights.len() as u32);
        lights.push(kind);
        power.push(
            4.0 * std::f32::consts::PI
                * std::f32::consts::PI
                * r
                * r
                * luminance(radiance).max(1e-6),
        );
    }
    let mut sun = None;
    if let Some(s) = sky.filter(|s| s.has_sun()) {
        sun = Some(lights.len() as u32);
        lights.push(LightKind::Sun);
        power.push(
            std::f32::consts::PI * r * r * s.sun_solid_angle() * luminance(s.sun_rgb()).max(1e-6),
        );
    }
    Lights {
        table: AliasTable::new(&power),
        lights,
        environment: env_index,
        map: map.cloned(),
        sky: sky.cloned(),
        sun,
        sphere: (centre, r),
    }
}
