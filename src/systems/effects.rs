//! `detect_effects`: which optional parts of light transport a scene needs.

use crate::components::camera::CameraPath;
use crate::components::{Camera, Material, Motion, Name, Texture};
use crate::scene::{Effect, Effects};
use crate::spectrum::{EmitterSpectrum, IorModel};

/// Decides the effect set from the world and the camera, for the shutter interval `shutter`.
pub fn detect_effects(
    world: &hecs::World,
    camera: &Camera,
    path: Option<&CameraPath>,
    shutter: (f32, f32),
    environment: &EmitterSpectrum,
    sky: Option<&crate::scene::sky::Sky>,
) -> Effects {
    let mut fx = Effects::default();
    if camera.aperture_radius > 0.0 {
        fx.set(
            Effect::Lens,
            true,
            format!("camera aperture radius {}", camera.aperture_radius),
        );
    } else {
        fx.set(Effect::Lens, false, "pinhole camera (aperture radius 0)");
    }
    let moving: Vec<String> = world
        .query::<(&Name, &Motion)>()
        .iter()
        .filter(|(_, m)| !m.is_static())
        .map(|(n, _)| crate::components::quoted(&n.0))
        .collect();
    let camera_moves = path.is_some_and(|p| p.moves_within(shutter.0, shutter.1));
    let shutter_open = shutter.1 > shutter.0;
    if !moving.is_empty() && shutter_open {
        let more = if moving.len() > 3 {
            format!(" and {} more", moving.len() - 3)
        } else {
            String::new()
        };
        fx.set(
            Effect::Motion,
            true,
            format!(
                "Motion on entity {}{}{}",
                moving[..moving.len().min(3)].join(", "),
                more,
                if camera_moves {
                    "; camera keyframes move within the shutter"
                } else {
                    ""
                }
            ),
        );
    } else if camera_moves && shutter_open {
        fx.set(
            Effect::Motion,
            true,
            "camera keyframes move within the shutter",
        );
    } else if !moving.is_empty() {
        fx.set(
            Effect::Motion,
            false,
            "the shutter is closed (open = close)",
        );
    } else {
        let entities = world.query::<&Name>().iter().count();
        fx.set(
            Effect::Motion,
            false,
            format!("no Motion component on any of {entities} entities and a static camera"),
        );
    }
    let mut spectral: Vec<String> = Vec::new();
    let mut emitters: Vec<(hecs::Entity, String)> = world
        .query::<(hecs::Entity, &Name, &Material)>()
        .iter()
        .filter_map(|(e, n, m)| match m {
            Material::Dielectric { ior, .. } if ior.is_dispersive() => Some((
                e,
                format!(
                    "entity {}: {}",
                    crate::components::quoted(&n.0),
                    describe_ior(ior)
                ),
            )),
            Material::Light { spectrum, .. } if spectrum.is_spectral() => Some((
                e,
                format!(
                    "entity {}: {}",
                    crate::components::quoted(&n.0),
                    spectrum.describe()
                ),
            )),
            _ => None,
        })
        .collect();
    emitters.extend(
        world
            .query::<(hecs::Entity, &Name, &crate::components::PointLight)>()
            .iter()
            .filter(|(_, _, l)| l.spectrum.is_spectral())
            .map(|(e, n, l)| {
                (
                    e,
                    format!(
                        "entity {}: {}",
                        crate::components::quoted(&n.0),
                        l.spectrum.describe()
                    ),
                )
            }),
    );
    // Entities in file order, so the reason names the first one the user wrote.
    emitters.sort_by_key(|(e, _)| e.id());
    spectral.extend(emitters.into_iter().map(|(_, s)| s));
    if environment.is_spectral() {
        spectral.push(format!("environment: {}", environment.describe()));
    }
    if sky.is_some() {
        spectral.push("environment: Sky (the Hosek–Wilkie spectral daylight model)".into());
    }
    if spectral.is_empty() {
        fx.set(
            Effect::Spectral,
            false,
            "no dispersive IOR and no spectral emitter",
        );
    } else {
        fx.set(Effect::Spectral, true, list_reasons(&spectral));
    }
    let named = |f: &dyn Fn(&Texture) -> bool| -> Vec<String> {
        world
            .query::<(&Name, &Texture)>()
            .iter()
            .filter(|(_, t)| f(t))
            .map(|(n, _)| crate::components::quoted(&n.0))
            .collect()
    };
    let list = |v: &[String]| {
        if v.len() > 3 {
            format!("{} and {} more", v[..3].join(", "), v.len() - 3)
        } else {
            v.join(", ")
        }
    };
    let albedo = named(&|t| t.albedo.is_some());
    let roughness = named(&|t| t.roughness.is_some());
    if albedo.is_empty() && roughness.is_empty() {
        fx.set(Effect::Textures, false, "no texture with an albedo");
    } else if albedo.is_empty() {
        fx.set(
            Effect::Textures,
            true,
            format!("roughness texture on entity {}", list(&roughness)),
        );
    } else {
        fx.set(
            Effect::Textures,
            true,
            format!("albedo texture on entity {}", list(&albedo)),
        );
    }
    let normals = named(&|t| t.normal_map.is_some());
    if normals.is_empty() {
        fx.set(Effect::NormalMaps, false, "no normal map");
    } else {
        fx.set(
            Effect::NormalMaps,
            true,
            format!("normal map on entity {}", list(&normals)),
        );
    }
    let media: Vec<String> = world
        .query::<(&Name, &crate::components::Medium)>()
        .iter()
        .map(|(n, _)| crate::components::quoted(&n.0))
        .collect();
    if media.is_empty() {
        fx.set(Effect::Media, false, "no Medium component");
    } else {
        fx.set(
            Effect::Media,
            true,
            format!("Medium on entity {}", list(&media)),
        );
    }
    fx
}

/// The first few reasons, and how many more.
fn list_reasons(v: &[String]) -> String {
    if v.len() > 3 {
        format!("{} and {} more", v[..3].join("; "), v.len() - 3)
    } else {
        v.join("; ")
    }
}

/// A dispersive IOR as the manifest shows it, e.g. `Cauchy b = 0.0137 µm²`.
fn describe_ior(ior: &IorModel) -> String {
    match ior {
        IorModel::Constant(n) => format!("Constant {n}"),
        IorModel::Cauchy { b, .. } => format!("Cauchy b = {b} µm²"),
        IorModel::Sellmeier { .. } | IorModel::Sellmeier4 { .. } => {
            format!("Sellmeier, n_d = {:.4}", ior.eta(crate::spectrum::LAMBDA_D))
        }
    }
}
