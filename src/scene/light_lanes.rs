//! Light samples from a packet of reference points, one per lane.
//!
//! The light is chosen per lane by the alias table; lanes that chose the same light are then
//! sampled together, in lanes, with the scalar sample's bits: the environment, point and spot
//! lights, and Rect, Disk and Sphere emitters. Emitters that move or carry a texture take
//! [`Lights::sample`] one lane at a time.

use super::lights::{LightKind, LightSource, Lights};
use super::primitives::{NO_MOTION, PrimKind, Primitives};
use crate::components::Material;
use crate::simd::{Float, Mask, V3};

type M<F> = <F as Float>::Mask;

/// The widest packet.
const MAX_W: usize = 16;

/// [`super::LightSample`] of each lane; lanes outside `has` hold no sample.
#[derive(Clone, Copy)]
pub struct LaneLightSample<F: Float> {
    /// Lanes that hold a sample.
    pub has: M<F>,
    /// Unit direction towards the light.
    pub wi: V3<F>,
    /// Radiance arriving along `-wi`, linear sRGB.
    pub radiance: V3<F>,
    /// Solid-angle density including the choice of the light; for a delta light, the choice
    /// probability.
    pub pdf: F,
    /// Lanes whose light is a point or spot light.
    pub delta: M<F>,
    /// Lanes whose sample is a point (area, point and spot lights), held in `q` and `nq`.
    pub at_point: M<F>,
    /// The sampled point, world space.
    pub q: V3<F>,
    /// Unit normal at `q` (zero for point and spot lights).
    pub nq: V3<F>,
}

impl<F: Float> LaneLightSample<F> {
    #[inline(always)]
    fn none() -> Self {
        let no = M::<F>::splat(false);
        LaneLightSample {
            has: no,
            wi: V3::zero(),
            radiance: V3::zero(),
            pdf: F::one(),
            delta: no,
            at_point: no,
            q: V3::zero(),
            nq: V3::zero(),
        }
    }

    /// Takes the lanes of `m` from `o`.
    #[inline(always)]
    fn blend(&mut self, m: M<F>, o: &Self) {
        self.has = (self.has.and_not(m)) | (o.has & m);
        self.wi = V3::select(m, o.wi, self.wi);
        self.radiance = V3::select(m, o.radiance, self.radiance);
        self.pdf = F::select(m, o.pdf, self.pdf);
        self.delta = (self.delta.and_not(m)) | (o.delta & m);
        self.at_point = (self.at_point.and_not(m)) | (o.at_point & m);
        self.q = V3::select(m, o.q, self.q);
        self.nq = V3::select(m, o.nq, self.nq);
    }
}

#[inline(always)]
fn nonzero<F: Float>(v: V3<F>) -> M<F> {
    !(v.x.eq(F::zero()) & v.y.eq(F::zero()) & v.z.eq(F::zero()))
}

impl Lights {
    /// [`Lights::sample`] for the reference points of lanes `m`, with the same bits; with
    /// `sources`, each lane's [`LightSource`] too.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn sample_lanes<F: Float, const MOTION: bool>(
        &self,
        prims: &Primitives,
        p: V3<F>,
        m: M<F>,
        u_select: F,
        ux: F,
        uy: F,
        time: F,
        textures: bool,
        mut sources: Option<&mut [LightSource; MAX_W]>,
    ) -> LaneLightSample<F> {
        let mut out = LaneLightSample::none();
        if self.lights.is_empty() || m.none() {
            return out;
        }
        let mut which = [0u32; MAX_W];
        let mut pmf = [0.0f32; MAX_W];
        let bits = m.bits();
        for i in 0..F::WIDTH {
            if bits >> i & 1 != 0 {
                let (k, pm) = self.table.sample(u_select.lane(i));
                (which[i], pmf[i]) = (k as u32, pm);
            }
        }
        let pmf = F::load(&pmf);
        let mut todo = bits;
        while todo != 0 {
            let k = which[todo.trailing_zeros() as usize];
            let mut group = 0u32;
            for (i, &w) in which.iter().enumerate().take(F::WIDTH) {
                if todo >> i & 1 != 0 && w == k {
                    group |= 1 << i;
                }
            }
            todo &= !group;
            let gm = M::<F>::from_fn(|i| group >> i & 1 != 0);
            if let Some((s, scale)) =
                self.light_lanes::<F, MOTION>(prims, k, p, gm, pmf, ux, uy, textures)
            {
                out.blend(gm, &s);
                if let Some(sources) = sources.as_deref_mut() {
                    let source = match self.lights[k as usize] {
                        LightKind::Area(prim) => LightSource::Area {
                            material: prims.material[prim as usize],
                            tex: None,
                            prim,
                        },
                        LightKind::Point(_) => LightSource::Point {
                            light: k,
                            scale: 0.0,
                        },
                        LightKind::Environment(_) => LightSource::Environment,
                        // Sampled one lane at a time (`light_lanes` gives `None`).
                        LightKind::EnvMap | LightKind::Sun => continue,
                    };
                    for (i, s) in sources.iter_mut().enumerate().take(F::WIDTH) {
                        if group >> i & 1 != 0 {
                            *s = match source {
                                LightSource::Point { light, .. } => LightSource::Point {
                                    light,
                                    scale: scale.lane(i),
                                },
                                s => s,
                            };
                        }
                    }
                }
                continue;
            }
            for i in 0..F::WIDTH {
                if group >> i & 1 == 0 {
                    continue;
                }
                let u = glam::Vec2::new(ux.lane(i), uy.lane(i));
                let s = self.sample::<MOTION>(
                    prims,
                    p.lane(i),
                    u_select.lane(i),
                    u,
                    time.lane(i),
                    textures,
                );
                let lane = M::<F>::from_fn(|l| l == i);
                let Some(s) = s else {
                    out.has = out.has.and_not(lane);
                    continue;
                };
                let (q, nq) = s.point.unwrap_or_default();
                let one = LaneLightSample {
                    has: M::<F>::splat(true),
                    wi: V3::splat(s.wi),
                    radiance: V3::splat(s.radiance),
                    pdf: F::splat(s.pdf),
                    delta: M::<F>::splat(s.delta),
                    at_point: M::<F>::splat(s.point.is_some()),
                    q: V3::splat(q),
                    nq: V3::splat(nq),
                };
                out.blend(lane, &one);
                if let Some(sources) = sources.as_deref_mut() {
                    sources[i] = s.source;
                }
            }
        }
        out
    }

    /// Light `k` sampled in lanes `m`, with the scalar sample's bits: the environment, a
    /// point or spot light (with each lane's falloff / d², its source's scale), or a still,
    /// untextured Rect, Disk or Sphere. `None` for the rest (moving or textured emitters),
    /// which the caller samples one lane at a time.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn light_lanes<F: Float, const MOTION: bool>(
        &self,
        prims: &Primitives,
        k: u32,
        p: V3<F>,
        m: M<F>,
        pmf: F,
        ux: F,
        uy: F,
        textures: bool,
    ) -> Option<(LaneLightSample<F>, F)> {
        let no = M::<F>::splat(false);
        let prim = match self.lights[k as usize] {
            LightKind::Environment(l) => {
                let wi = crate::sampling::warp::lanes::square_to_uniform_sphere(ux, uy);
                let s = LaneLightSample {
                    has: m,
                    wi,
                    radiance: V3::splat(l),
                    pdf: pmf * F::splat(crate::sampling::uniform_sphere_pdf()),
                    delta: no,
                    at_point: no,
                    q: V3::zero(),
                    nq: V3::zero(),
                };
                return Some((s, F::zero()));
            }
            // Each lane walks the map's tables on its own.
            LightKind::EnvMap | LightKind::Sun => return None,
            LightKind::Point(pl) => {
                let q = V3::<F>::splat(pl.position);
                let d = q - p;
                let d2 = d.x * d.x + d.y * d.y + d.z * d.z;
                let r = d2.sqrt();
                let wi = V3::new(d.x / r, d.y / r, d.z / r);
                let scale = pl.falloff_lanes(-wi) / d2;
                let radiance = V3::<F>::splat(pl.intensity) * scale;
                let finite =
                    radiance.x.is_finite() & radiance.y.is_finite() & radiance.z.is_finite();
                let s = LaneLightSample {
                    has: m & nonzero(radiance) & finite,
                    wi,
                    radiance,
                    pdf: pmf,
                    delta: M::<F>::splat(true),
                    at_point: M::<F>::splat(true),
                    q,
                    nq: V3::zero(),
                };
                return Some((s, scale));
            }
            LightKind::Area(prim) => prim,
        };
        let i = prim as usize;
        if (MOTION && prims.motion[i] != NO_MOTION)
            || (textures && prims.texture_of(prim).is_some())
        {
            return None;
        }
        let Material::Light {
            emission,
            two_sided,
            ..
        } = prims.materials[prims.material[i] as usize]
        else {
            return None;
        };
        let l = prims.local[i] as usize;
        let (q, nq, pdf, ok) = match prims.kind[i] {
            PrimKind::Rect | PrimKind::Disk => {
                let planar = &prims.planars[l];
                let (q, pdf) = planar.sample_lanes(p, ux, uy, prims.kind[i] == PrimKind::Disk);
                (q, V3::splat(planar.n), pdf, pdf.gt(F::zero()))
            }
            PrimKind::Sphere => prims.spheres[l].sample_lanes(p, ux, uy),
            PrimKind::Box | PrimKind::Revolution | PrimKind::Mesh => return None,
        };
        let d = q - p;
        // glam's `normalize_or_zero`.
        let rcp = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt().recip();
        let unit = rcp.is_finite() & rcp.gt(F::zero());
        let wi = V3::select(unit, d * rcp, V3::zero());
        let facing = if two_sided {
            M::<F>::splat(true)
        } else {
            let wo = -wi;
            (nq.x * wo.x + nq.y * wo.y + nq.z * wo.z).gt(F::zero())
        };
        let lit = M::<F>::splat(emission != glam::Vec3::ZERO) & facing;
        let s = LaneLightSample {
            has: m & ok & nonzero(wi) & lit,
            wi,
            radiance: V3::splat(emission),
            pdf: pmf * pdf,
            delta: no,
            at_point: M::<F>::splat(true),
            q,
            nq,
        };
        Some((s, F::zero()))
    }
}
