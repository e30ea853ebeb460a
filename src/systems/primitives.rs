//! `gather_primitives`: flattens the world's shapes into per-kind arrays for the hot loop,
//! keeping each primitive's entity for messages and statistics.

use crate::components::{Material, Motion, Name, Shape, Texture, Transform};
use crate::geometry::{OrientedBox, Planar, RigidMotion, Sphere};
use crate::scene::primitives::{NO_LIGHT, NO_MEDIUM, NO_MOTION, NO_TEXTURE, Placed};
use crate::scene::{PrimKind, Primitives};

/// Flattens every entity with a `Shape` into world-space primitives. Entities are taken in
/// spawn order so primitive indices, and thus images, are reproducible.
pub fn gather_primitives(world: &hecs::World) -> Primitives {
    let mut p = Primitives::default();
    type Row = (
        hecs::Entity,
        Shape,
        Transform,
        Material,
        String,
        Option<Motion>,
        Option<Texture>,
        Option<crate::medium::HomogeneousMedium>,
    );
    let mut rows: Vec<Row> = world
        .query::<(
            hecs::Entity,
            &Shape,
            &Transform,
            &Material,
            &Name,
            Option<&Motion>,
            Option<&Texture>,
            Option<&crate::medium::HomogeneousMedium>,
        )>()
        .iter()
        .map(|(e, s, t, m, n, mo, tx, me)| {
            (
                e,
                s.clone(),
                *t,
                *m,
                n.0.clone(),
                mo.copied(),
                tx.cloned(),
                me.copied(),
            )
        })
        .collect();
    rows.sort_by_key(|r| r.0.id());
    for (entity, shape, transform, material, name, motion, texture, medium) in rows {
        p.medium_inside.push(medium.map_or(NO_MEDIUM, |m| {
            p.media.push(m);
            (p.media.len() - 1) as u32
        }));
        p.medium_outside.push(NO_MEDIUM);
        p.texture.push(texture.map_or(NO_TEXTURE, |t| {
            p.textures.push(t);
            (p.textures.len() - 1) as u32
        }));
        let moving = motion.filter(|m| !m.is_static()).map(|m| {
            p.motions.push(RigidMotion {
                pivot: transform.to_world.translation.into(),
                velocity: m.velocity,
                angular: m.angular_velocity * (std::f32::consts::PI / 180.0),
            });
            (p.motions.len() - 1) as u32
        });
        p.motion.push(moving.unwrap_or(NO_MOTION));
        let m = p.materials.len() as u32;
        p.materials.push(material);
        let tw = transform.to_world;
        let (kind, local) = match shape {
            Shape::Sphere { center, radius } => {
                let scale = transform.uniform_scale.unwrap_or(1.0);
                p.spheres.push(Sphere {
                    center: tw.transform_point3(center),
                    radius: radius * scale,
                });
                let (_, rot, _) = tw.to_scale_rotation_translation();
                p.sphere_rotation.push(rot);
                (PrimKind::Sphere, p.spheres.len() - 1)
            }
            Shape::Rect { center, u, v } => {
                p.planars.push(Planar::new(
                    tw.transform_point3(center),
                    tw.transform_vector3(u),
                    tw.transform_vector3(v),
                    false,
                ));
                (PrimKind::Rect, p.planars.len() - 1)
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                let (t, b) = crate::sampling::coordinate_system(normal);
                p.planars.push(Planar::new(
                    tw.transform_point3(center),
                    tw.transform_vector3(t * radius),
                    tw.transform_vector3(b * radius),
                    true,
                ));
                (PrimKind::Disk, p.planars.len() - 1)
            }
            Shape::Box { min, max } => {
                p.boxes.push(OrientedBox::new(min, max, tw));
                (PrimKind::Box, p.boxes.len() - 1)
            }
            Shape::Revolution(r) => {
                p.revolutions.push(Placed::new(r, tw));
                (PrimKind::Revolution, p.revolutions.len() - 1)
            }
            Shape::Mesh(m) => {
                p.meshes.push(Placed::new(m, tw));
                (PrimKind::Mesh, p.meshes.len() - 1)
            }
        };
        p.kind.push(kind);
        p.local.push(local as u32);
        p.material.push(m);
        p.light.push(NO_LIGHT);
        p.entity.push(entity);
        p.names.push(name);
    }
    // Each medium shape's outside is the innermost other medium shape holding its centre.
    for i in 0..p.len() {
        if p.medium_inside[i] != NO_MEDIUM {
            let c = p.bounds_of(i as u32).center();
            p.medium_outside[i] = p.medium_at_excluding(c, Some(i as u32));
        }
    }
    // Plastics' coat tables, one per IOR.
    let mut at: Vec<(u32, u32)> = Vec::new();
    p.coat_offset = vec![0; p.materials.len()];
    for (m, off) in p.materials.iter().zip(p.coat_offset.iter_mut()) {
        if let Material::Plastic { ior, .. } = *m {
            *off = match at.iter().find(|(bits, _)| *bits == ior.to_bits()) {
                Some(&(_, o)) => o,
                None => {
                    let o = p.coat.len() as u32;
                    p.coat
                        .extend_from_slice(&crate::energy::coat_table_cached(ior));
                    at.push((ior.to_bits(), o));
                    o
                }
            };
        }
    }
    p
}
