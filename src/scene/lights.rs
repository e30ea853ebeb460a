//! The light list: emitters chosen by power through an alias table (built by
//! `systems::gather_lights`), their samples as seen from a point, and the pdfs MIS needs when
//! a path finds an emitter by chance.

use super::primitives::{PrimKind, Primitives, emitted};
use crate::sampling::AliasTable;
use glam::{Vec2, Vec3};

/// One emitter of the light list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// An emissive primitive (Sphere, Rect or Disk), by primitive index.
    Area(u32),
    /// The constant environment: radiance from every direction.
    Environment(Vec3),
    /// The environment map, [`Lights::map`] (or the sky tabulated, [`Lights::sky`]).
    EnvMap,
    /// The sun's disc of [`Lights::sky`].
    Sun,
    /// A point or spot light (a delta light: never found by chance).
    Point(crate::components::PointLight),
}

/// A light sample as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// The sampled point and its normal (area lights); `None` for the environment.
    pub point: Option<(Vec3, Vec3)>,
    /// Radiance arriving along `-wi`.
    pub radiance: Vec3,
    /// Solid-angle density, including the probability of choosing this light; for a delta
    /// light, the probability of choosing it.
    pub pdf: f32,
    /// A point or spot light: no other technique can find it, so MIS gives it full weight.
    pub delta: bool,
    /// Which emitter, for spectral transport to evaluate its spectrum.
    pub source: LightSource,
}

/// The emitter a light sample came from.
#[derive(Clone, Copy, Debug)]
pub enum LightSource {
    /// Area light `prim` of material `material`, its colour modulated by the texture albedo
    /// `tex`.
    Area {
        /// Material index of the emitter.
        material: u32,
        /// Texture albedo at the sampled point, if the emitter is textured.
        tex: Option<Vec3>,
        /// Primitive index of the emitter.
        prim: u32,
    },
    /// Point or spot light `light` (light index), its intensity scaled by falloff / d².
    Point {
        /// Index in [`Lights::lights`].
        light: u32,
        /// Spot falloff over squared distance.
        scale: f32,
    },
    /// The constant environment.
    Environment,
    /// The environment map along `wi`: its radiance is the sample's linear RGB, upsampled as
    /// an illuminant in spectral transport; or the sky's spectrum along `wi`.
    EnvMap {
        /// Unit direction towards the environment.
        wi: Vec3,
    },
    /// The sun's disc: its spectrum in spectral transport.
    Sun,
}

/// The scene's emitters and the alias table that picks among them by power.
pub struct Lights {
    /// Every emitter; a light index indexes this.
    pub lights: Vec<LightKind>,
    pub(crate) table: AliasTable,
    /// Index of the environment light, if the environment emits.
    pub environment: Option<u32>,
    /// The environment map, when the environment is an image (or a sky: its tabulation,
    /// which only guides sampling).
    pub map: Option<std::sync::Arc<super::envmap::EnvMap>>,
    /// The daylight sky, when the environment is a `Sky`.
    pub sky: Option<std::sync::Arc<super::sky::Sky>>,
    /// Index of the sun's light, if the sky has a sun.
    pub sun: Option<u32>,
    /// The bounding sphere of the scene's geometry (centre, radius): light paths from the
    /// environment start on a disc of its radius facing the scene, as pbrt's do.
    pub sphere: (Vec3, f32),
}

impl Lights {
    /// Whether the scene has no emitter at all.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Chooses a light by power and samples a direction to it from `p`. A moving emitter is
    /// sampled in its rest pose at `time` (a rigid map keeps solid-angle densities).
    #[inline]
    pub fn sample<const MOTION: bool>(
        &self,
        prims: &Primitives,
        p: Vec3,
        u_select: f32,
        u: Vec2,
        time: f32,
        textures: bool,
    ) -> Option<LightSample> {
        if self.lights.is_empty() {
            return None;
        }
        let (i, pmf) = self.table.sample(u_select);
        match self.lights[i] {
            LightKind::Environment(l) => {
                let wi = crate::sampling::square_to_uniform_sphere(u);
                Some(LightSample {
                    wi,
                    point: None,
                    radiance: l,
                    pdf: pmf * crate::sampling::uniform_sphere_pdf(),
                    delta: false,
                    source: LightSource::Environment,
                })
            }
            LightKind::EnvMap => {
                let map = self.map.as_deref()?;
                let (wi, radiance, pdf) = map.sample(u)?;
                // A sky's radiance is the model's, not its tabulation's.
                let radiance = self.sky.as_deref().map_or(radiance, |sky| sky.rgb(wi));
                Some(LightSample {
                    wi,
                    point: None,
                    radiance,
                    pdf: pmf * pdf,
                    delta: false,
                    source: LightSource::EnvMap { wi },
                })
            }
            LightKind::Sun => {
                let sky = self.sky.as_deref()?;
                Some(LightSample {
                    wi: sky.sample_sun(u),
                    point: None,
                    radiance: sky.sun_rgb(),
                    pdf: pmf / sky.sun_solid_angle(),
                    delta: false,
                    source: LightSource::Sun,
                })
            }
            LightKind::Point(pl) => {
                let d = pl.position - p;
                let d2 = d.length_squared();
                let wi = d / d2.sqrt();
                let scale = pl.falloff(-wi) / d2;
                let radiance = pl.intensity * scale;
                (radiance != Vec3::ZERO && radiance.is_finite()).then_some(LightSample {
                    wi,
                    point: Some((pl.position, Vec3::ZERO)),
                    radiance,
                    pdf: pmf,
                    delta: true,
                    source: LightSource::Point {
                        light: i as u32,
                        scale,
                    },
                })
            }
            LightKind::Area(prim) => {
                let l = prims.local[prim as usize] as usize;
                let motion = if MOTION { prims.motion_of(prim) } else { None };
                let p_rest = motion.map_or(p, |m| m.point_to_rest(p, time));
                let mut s = match prims.kind[prim as usize] {
                    PrimKind::Sphere => prims.spheres[l].sample(p_rest, u),
                    PrimKind::Rect => prims.planars[l].sample(p_rest, u, false),
                    PrimKind::Disk => prims.planars[l].sample(p_rest, u, true),
                    PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => None,
                }?;
                if let Some(m) = motion {
                    s.p = m.point_to_world(s.p, time);
                    s.n = m.vector_to_world(s.n, time);
                }
                let d = s.p - p;
                let wi = d.normalize_or_zero();
                let material = prims.material[prim as usize];
                let mut m = prims.materials[material as usize];
                let mut tex = None;
                if textures && let Some(t) = prims.texture_of(prim) {
                    let q = motion.map_or(s.p, |mo| mo.point_to_rest(s.p, time));
                    if let Some(a) = t.albedo(prims.uv_at(prim, q)) {
                        m = m.modulated(a);
                        tex = Some(a);
                    }
                }
                let radiance = emitted(&m, s.n, -wi);
                (wi != Vec3::ZERO && radiance != Vec3::ZERO).then_some(LightSample {
                    wi,
                    point: Some((s.p, s.n)),
                    radiance,
                    pdf: pmf * s.pdf,
                    delta: false,
                    source: LightSource::Area {
                        material,
                        tex,
                        prim,
                    },
                })
            }
        }
    }

    /// Density with which `sample` from `p` would have produced the point `q` (normal `n`)
    /// on emissive primitive `prim`: needed to weight emitters found by chance.
    #[inline]
    pub fn pdf_area<const MOTION: bool>(
        &self,
        prims: &Primitives,
        prim: u32,
        p: Vec3,
        q: Vec3,
        n: Vec3,
        time: f32,
    ) -> f32 {
        let (p, q, n) = match prims.motion_of(prim) {
            Some(m) if MOTION => (
                m.point_to_rest(p, time),
                m.point_to_rest(q, time),
                m.vector_to_rest(n, time),
            ),
            _ => (p, q, n),
        };
        let li = prims.light[prim as usize];
        let pmf = self.table.pmf(li as usize);
        let l = prims.local[prim as usize] as usize;
        pmf * match prims.kind[prim as usize] {
            PrimKind::Sphere => prims.spheres[l].pdf(p, q, n),
            PrimKind::Rect | PrimKind::Disk => prims.planars[l].pdf(p, q),
            PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => 0.0,
        }
    }

    /// Chooses a light exactly as `sample` does (same `u_select`) and returns what
    /// equiangular sampling along the segment `ray` (unit direction) up to `t_max` aims at: a
    /// point or spot light, or a point on an area light drawn from `u` before any distance
    /// along the ray is known (so it cannot depend on the scattering point). Planar emitters
    /// are sampled uniformly by area; spheres uniformly by area over the half facing the
    /// segment (see [`sphere_facing_axis`]). The environment gives `None`.
    #[inline]
    pub fn pick_equiangular<const MOTION: bool>(
        &self,
        prims: &Primitives,
        ray: &crate::geometry::Ray,
        t_max: f32,
        (u_select, u): (f32, Vec2),
        time: f32,
    ) -> Option<EquiangularTarget> {
        if self.lights.is_empty() {
            return None;
        }
        let (i, pmf) = self.table.sample(u_select);
        match self.lights[i] {
            LightKind::Point(light) => Some(EquiangularTarget::Point {
                index: i as u32,
                light,
                pmf,
            }),
            LightKind::Area(prim) => {
                let l = prims.local[prim as usize] as usize;
                // A moving emitter is sampled in its rest pose; a rigid map keeps areas.
                let motion = if MOTION { prims.motion_of(prim) } else { None };
                let (p, n, density) = match prims.kind[prim as usize] {
                    PrimKind::Sphere => {
                        let s = &prims.spheres[l];
                        let mut n = crate::sampling::square_to_uniform_sphere(u);
                        let axis = sphere_facing_axis(s, &rest_ray(motion, ray, time), t_max);
                        let share = match axis {
                            Some(a) => {
                                if n.dot(a) < 0.0 {
                                    n = -n;
                                }
                                0.5
                            }
                            None => 1.0,
                        };
                        (s.center + n * s.radius, n, pmf / (share * s.area()))
                    }
                    PrimKind::Rect | PrimKind::Disk => {
                        let q = &prims.planars[l];
                        let (a, b) = if prims.kind[prim as usize] == PrimKind::Disk {
                            let d = crate::sampling::square_to_uniform_disk_concentric(u);
                            (d.x, d.y)
                        } else {
                            (2.0 * u.x - 1.0, 2.0 * u.y - 1.0)
                        };
                        (q.center + a * q.u + b * q.v, q.n, pmf / q.area())
                    }
                    PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => return None,
                };
                let (p, n) = match motion {
                    Some(m) => (m.point_to_world(p, time), m.vector_to_world(n, time)),
                    None => (p, n),
                };
                Some(EquiangularTarget::Area {
                    prim,
                    p,
                    n,
                    density,
                })
            }
            LightKind::Environment(_) | LightKind::EnvMap | LightKind::Sun => None,
        }
    }

    /// Density per unit area, with the selection probability, with which
    /// [`Self::pick_equiangular`] for the segment `ray` up to `t_max` picks the point of
    /// normal `n` on area light `prim`.
    #[inline]
    pub fn equiangular_area_density<const MOTION: bool>(
        &self,
        prims: &Primitives,
        prim: u32,
        n: Vec3,
        ray: &crate::geometry::Ray,
        t_max: f32,
        time: f32,
    ) -> f32 {
        let pmf = self.table.pmf(prims.light[prim as usize] as usize);
        let l = prims.local[prim as usize] as usize;
        match prims.kind[prim as usize] {
            PrimKind::Sphere => {
                let s = &prims.spheres[l];
                let motion = if MOTION { prims.motion_of(prim) } else { None };
                match sphere_facing_axis(s, &rest_ray(motion, ray, time), t_max) {
                    Some(a) => {
                        let n = motion.map_or(n, |m| m.vector_to_rest(n, time));
                        if n.dot(a) >= 0.0 {
                            pmf / (0.5 * s.area())
                        } else {
                            0.0
                        }
                    }
                    None => pmf / s.area(),
                }
            }
            _ => pmf / emitter_area(prims, prim),
        }
    }

    /// The light sample that the point `(q, n)` (position, normal) on area light `prim` makes as seen
    /// from `p`: radiance emitted towards `p` and, as `pdf`, the solid-angle density with which
    /// `sample` from `p` would have chosen it. `None` when nothing is emitted towards `p`.
    #[inline]
    pub fn area_seen_from<const MOTION: bool>(
        &self,
        prims: &Primitives,
        prim: u32,
        (q, n): (Vec3, Vec3),
        p: Vec3,
        time: f32,
        textures: bool,
    ) -> Option<LightSample> {
        let wi = (q - p).normalize_or_zero();
        let material = prims.material[prim as usize];
        let mut m = prims.materials[material as usize];
        let mut tex = None;
        if textures && let Some(t) = prims.texture_of(prim) {
            let motion = if MOTION { prims.motion_of(prim) } else { None };
            let qr = motion.map_or(q, |mo| mo.point_to_rest(q, time));
            if let Some(a) = t.albedo(prims.uv_at(prim, qr)) {
                m = m.modulated(a);
                tex = Some(a);
            }
        }
        let radiance = emitted(&m, n, -wi);
        (wi != Vec3::ZERO && radiance != Vec3::ZERO).then(|| LightSample {
            wi,
            point: Some((q, n)),
            radiance,
            pdf: self.pdf_area::<MOTION>(prims, prim, p, q, n, time),
            delta: false,
            source: LightSource::Area {
                material,
                tex,
                prim,
            },
        })
    }

    /// Density of sampling direction `wi` (unit length) towards the environment.
    #[inline]
    pub fn pdf_environment(&self, wi: Vec3) -> f32 {
        self.environment.map_or(0.0, |i| {
            let pmf = self.table.pmf(i as usize);
            match &self.map {
                Some(map) => pmf * map.pdf(wi),
                None => pmf * crate::sampling::uniform_sphere_pdf(),
            }
        })
    }

    /// Whether the environment (or the sun) emits.
    pub fn has_infinite(&self) -> bool {
        self.environment.is_some() || self.sun.is_some()
    }

    /// The density of a light path's origin on the disc at infinity, per unit area of the
    /// disc (planar: the rays are parallel).
    pub fn disc_density(&self) -> f32 {
        1.0 / (std::f32::consts::PI * self.sphere.1 * self.sphere.1)
    }

    /// Density of sampling direction `wi` (unit length) towards the sun (zero off its disc).
    #[inline]
    pub fn pdf_sun(&self, wi: Vec3) -> f32 {
        match (self.sun, self.sky.as_deref()) {
            (Some(i), Some(sky)) if sky.on_sun(wi) => {
                self.table.pmf(i as usize) / sky.sun_solid_angle()
            }
            _ => 0.0,
        }
    }
}

/// What equiangular distance sampling aims at, chosen by [`Lights::pick_equiangular`].
#[derive(Clone, Copy, Debug)]
pub enum EquiangularTarget {
    /// Point or spot light `index`, chosen with probability `pmf`.
    Point {
        /// Index in [`Lights::lights`].
        index: u32,
        /// The light itself.
        light: crate::components::PointLight,
        /// Probability of having chosen it.
        pmf: f32,
    },
    /// Point `p` (normal `n`) on area light `prim`, drawn with `density` per unit area
    /// (including the light's selection probability).
    Area {
        /// Primitive index of the emitter.
        prim: u32,
        /// The point, world space.
        p: Vec3,
        /// Unit surface normal at `p`.
        n: Vec3,
        /// Density per unit area, including the light's selection probability.
        density: f32,
    },
}

/// The ray in the rest pose of a moving primitive (itself when it does not move).
#[inline]
fn rest_ray(
    motion: Option<&crate::geometry::RigidMotion>,
    ray: &crate::geometry::Ray,
    time: f32,
) -> crate::geometry::Ray {
    motion.map_or(*ray, |m| {
        crate::geometry::Ray::new(m.point_to_rest(ray.o, time), m.vector_to_rest(ray.d, time))
    })
}

/// The half of sphere `s` that equiangular sampling draws light points from for the segment
/// `ray` (unit direction) up to `t_max`: the hemisphere facing the segment's point nearest
/// the centre, where equiangular sampling puts most scattering points and whose visible cap
/// is nearly that hemisphere (uniform points over the whole sphere would waste half on its
/// far side). `None`, the whole sphere, when that point is not outside the sphere.
#[inline]
pub fn sphere_facing_axis(
    s: &crate::geometry::Sphere,
    ray: &crate::geometry::Ray,
    t_max: f32,
) -> Option<Vec3> {
    let t = (s.center - ray.o).dot(ray.d).clamp(0.0, t_max);
    let a = ray.at(t) - s.center;
    (a.length_squared() > s.radius * s.radius && a.is_finite()).then_some(a)
}

/// World-space area of an emissive primitive (a rigid motion keeps it); infinite for the
/// shapes lights are not sampled on.
#[inline]
pub(crate) fn emitter_area(prims: &Primitives, prim: u32) -> f32 {
    let l = prims.local[prim as usize] as usize;
    match prims.kind[prim as usize] {
        PrimKind::Sphere => prims.spheres[l].area(),
        PrimKind::Rect | PrimKind::Disk => prims.planars[l].area(),
        PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => f32::INFINITY,
    }
}

pub(crate) fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
