//! Surfaces: for the winning hit of each lane only, the full surface (normals, UV, textures,
//! normal maps) and its material, sorted into material classes for the scattering stage;
//! emitters hit by chance with their radiance and MIS weight.

use super::bsdf::{Frame, LaneChannels};
use super::coat::Plastic;
use super::ctx::Ctx;
use super::microfacet::{Conductor, ConductorFresnel, Ggx, SMOOTH_ALPHA};
use super::state::{C, M, MAX_W, Paths, Scratch3, U, mask_from_bits, power_heuristic};
use super::transport::{ChannelArray, Transport};
use crate::components::Material;
use crate::geometry::Ray;
use crate::scene::Hit;
use crate::scene::packet::PacketHit;
use crate::scene::primitives::emitted;
use crate::simd::{Float, Mask, UInt, V3};
use glam::{Vec2, Vec3};

/// Per-lane material classes after the surface stage.
pub(super) const CLASS_NONE: u32 = 0;
pub(super) const CLASS_DIFFUSE: u32 = 1;
pub(super) const CLASS_MIRROR: u32 = 2;
pub(super) const CLASS_DIELECTRIC: u32 = 3;
/// MEDIA: a medium's boundary, crossed without scattering.
pub(super) const CLASS_BOUNDARY: u32 = 4;
pub(super) const CLASS_CONDUCTOR: u32 = 5;
pub(super) const CLASS_PLASTIC: u32 = 6;

/// What the surface stage found at each lane's hit point.
#[derive(Clone, Copy)]
pub(super) struct Surface<F: Float, const N: usize> {
    pub(super) hit: M<F>,
    pub(super) p: V3<F>,
    /// Geometric and shading normals on the side the ray arrived from.
    pub(super) nf: V3<F>,
    pub(super) nsf: V3<F>,
    pub(super) front: M<F>,
    pub(super) class: U<F>,
    /// Albedo (Diffuse) or tint (Mirror), texture-modulated; a Conductor's η (or Schlick's
    /// normal-incidence reflectance).
    pub(super) color: C<F, N>,
    /// A Conductor's, Dielectric's or Plastic's GGX α along the tangent and the bitangent,
    /// and the conductor lanes with Schlick's Fresnel form and with multiple-scattering
    /// compensation.
    pub(super) ax: F,
    pub(super) ay: F,
    pub(super) schlick: M<F>,
    pub(super) multiscatter: M<F>,
    /// A Plastic's coat IOR and the offset of its coat tables (1 and 0 elsewhere).
    pub(super) coat_ior: F,
    pub(super) coat: U<F>,
    /// Lanes with an anisotropic roughness, and their unit tangent ∂p/∂u (elsewhere zero).
    pub(super) aniso: M<F>,
    pub(super) tangent: V3<F>,
    /// Each lane's material index (for a dielectric's IOR model) and primitive (for the
    /// medium behind a dielectric).
    pub(super) mat: [u32; MAX_W],
    pub(super) prim: [u32; MAX_W],
    /// Lanes that hit an emitter with non-zero radiance, the radiance and its MIS weight.
    /// A lane is an emitter or a conductor, never both: `le` holds a Conductor's k.
    pub(super) emits: M<F>,
    pub(super) le: C<F, N>,
    pub(super) le_w: F,
}

impl<F: Float, const N: usize> Surface<F, N> {
    /// The lanes whose microfacet lobe is a delta: both α below [`SMOOTH_ALPHA`].
    #[inline(always)]
    pub(super) fn smooth(&self) -> M<F> {
        self.ax.max(self.ay).lt(F::splat(SMOOTH_ALPHA))
    }

    /// The GGX distribution of the rough lanes. An axis below [`SMOOTH_ALPHA`] of an
    /// anisotropic lane is held there, where D stays finite.
    #[inline(always)]
    pub(super) fn dist(&self) -> Ggx<F> {
        let floor = F::splat(SMOOTH_ALPHA);
        Ggx {
            ax: self.ax.max(floor),
            ay: self.ay.max(floor),
        }
    }

    /// The shading frame around the shading normal, its tangent along ∂p/∂u in the
    /// anisotropic lanes (an isotropic lobe is the same about any tangent).
    #[inline(always)]
    pub(super) fn frame(&self) -> Frame<F> {
        let frame = Frame::from_normal(self.nsf);
        if self.aniso.none() {
            return frame;
        }
        frame.with_tangent(self.aniso, self.tangent)
    }

    /// The plastic BSDF of the plastic lanes (meaningless in others), its coat tables in
    /// `tables`.
    #[inline(always)]
    pub(super) fn plastic<'a>(&self, tables: &'a [f32]) -> Plastic<'a, F, N> {
        Plastic {
            dist: self.dist(),
            smooth: self.smooth(),
            eta: self.coat_ior,
            albedo: self.color,
            tables,
            base: self.coat,
        }
    }

    /// The conductor BSDF of the conductor lanes (meaningless in others).
    #[inline(always)]
    pub(super) fn conductor(&self) -> Conductor<F, N> {
        Conductor {
            dist: self.dist(),
            smooth: self.smooth(),
            multiscatter: self.multiscatter,
            fresnel: ConductorFresnel {
                eta: self.color,
                k: self.le,
                schlick: self.schlick,
            },
        }
    }
}

/// Where a hit's albedo texture stands after [`surface_material`].
pub(crate) enum Albedo {
    /// No albedo texture (or textures off).
    None,
    /// Looked up already (patterns without a lane form).
    Now(Vec3),
    /// To be looked up in lanes: the texture's index and the surface uv.
    Later(u32, Vec2),
}

/// The surface at `hit` with its untextured material; a normal map tilts the shading normal.
/// Albedo textures with a lane form (images, checkerboards) are left to the caller, which
/// looks them up for a packet's lanes at once; other patterns are evaluated here.
#[inline(always)]
pub(crate) fn surface_material<const MOTION: bool>(
    ctx: &Ctx,
    ray: &Ray,
    hit: &Hit,
    time: f32,
) -> (crate::geometry::SurfacePoint, Material, Albedo) {
    let prims = &ctx.scene.prims;
    let mut sp = prims.surface_at::<MOTION>(ray, hit, time);
    let mut material = prims.materials[prims.material[hit.prim as usize] as usize];
    let mut albedo = Albedo::None;
    if (ctx.textures || ctx.normal_maps)
        && let Some(tex) = prims.texture_of(hit.prim)
    {
        let (uv, dpdu, dpdv) = prims.uv_frame::<MOTION>(ray, hit, &sp, time);
        if ctx.textures
            && let Some(r) = tex.roughness(uv)
        {
            material = material.roughened(r);
        }
        if ctx.textures
            && let Some(a) = &tex.albedo
        {
            albedo = if a.has_lane_form() {
                Albedo::Later(prims.texture[hit.prim as usize], uv)
            } else {
                Albedo::Now(a.eval(tex.map_uv(uv)))
            };
        }
        if ctx.normal_maps && tex.normal_map.is_some() {
            // As pbrt does: the perturbed normal is turned to the geometric normal's side;
            // directions it would send below the geometric surface are absorbed in scattering.
            let ns = tex.shading_normal(uv, sp.ns, dpdu, dpdv);
            sp.ns = if ns.dot(sp.n) < 0.0 { -ns } else { ns };
        }
    }
    (sp, material, albedo)
}

/// One lane's hit as the material stage needs it.
#[derive(Clone, Copy)]
struct LaneHit {
    mat: u32,
    prim: u32,
    /// The geometric normal (not turned to the ray) and the point, for an emitter.
    n: Vec3,
    p: Vec3,
}

/// Per-lane results of the material stage, filled one lane at a time.
struct Shading<T: Transport> {
    color: T::Colours,
    /// Emitters' radiance, conductors' k.
    le: T::Colours,
    class: [u32; MAX_W],
    le_w: [f32; MAX_W],
    ax: [f32; MAX_W],
    ay: [f32; MAX_W],
    coat_ior: [f32; MAX_W],
    coat: [u32; MAX_W],
    emit_bits: u32,
    /// Conductor lanes, and those among them with Schlick's Fresnel form.
    conductor_bits: u32,
    schlick_bits: u32,
    multiscatter_bits: u32,
}

impl<T: Transport> Shading<T> {
    /// Lane i's class and colours from its material, texture-modulated by `albedo`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn finish<F: Float, const N: usize, const MOTION: bool, const MEDIA: bool>(
        &mut self,
        ctx: &Ctx,
        st: &Paths<F, T, N>,
        i: usize,
        h: LaneHit,
        material: Material,
        albedo: Option<Vec3>,
    ) where
        T: Transport<S: ChannelArray<N>>,
    {
        let textured = albedo.is_some();
        match material {
            Material::Diffuse { albedo } => {
                self.class[i] = CLASS_DIFFUSE;
                T::set_reflectance(&mut self.color, i, ctx, h.mat, albedo, textured);
            }
            Material::Mirror { tint } => {
                self.class[i] = CLASS_MIRROR;
                T::set_reflectance(&mut self.color, i, ctx, h.mat, tint, textured);
            }
            Material::Plastic { albedo, ior, alpha } => {
                self.class[i] = CLASS_PLASTIC;
                (self.ax[i], self.ay[i]) = (alpha.x, alpha.y);
                self.coat_ior[i] = ior;
                self.coat[i] = ctx.scene.prims.coat_offset[h.mat as usize];
                T::set_reflectance(&mut self.color, i, ctx, h.mat, albedo, textured);
            }
            Material::Dielectric {
                alpha,
                multiscatter,
                ..
            } => {
                self.class[i] = CLASS_DIELECTRIC;
                (self.ax[i], self.ay[i]) = (alpha.x, alpha.y);
                self.multiscatter_bits |= u32::from(multiscatter) << i;
            }
            Material::Conductor {
                ior,
                alpha,
                multiscatter,
            } => {
                self.class[i] = CLASS_CONDUCTOR;
                (self.ax[i], self.ay[i]) = (alpha.x, alpha.y);
                self.conductor_bits |= 1 << i;
                self.multiscatter_bits |= u32::from(multiscatter) << i;
                let schlick = T::set_conductor(
                    &mut self.color,
                    &mut self.le,
                    i,
                    ctx,
                    h.mat,
                    &ior,
                    textured,
                    &st.lam,
                );
                self.schlick_bits |= u32::from(schlick) << i;
            }
            Material::Light { .. } => {
                let radiance = emitted(&material, h.n, -st.d.lane(i));
                if radiance != Vec3::ZERO {
                    self.emit_bits |= 1 << i;
                    T::set_emission(&mut self.le, i, ctx, h.mat, radiance, albedo, &st.lam);
                    let (depth, specular) = (st.depth.lane(i), st.specular.lane(i));
                    self.le_w[i] = if depth == 0 || specular || !ctx.nee {
                        1.0
                    } else {
                        let pdf = ctx.scene.lights.pdf_area::<MOTION>(
                            &ctx.scene.prims,
                            h.prim,
                            st.prev_p.lane(i),
                            h.p,
                            h.n,
                            st.time.lane(i),
                        );
                        power_heuristic::<f32>(st.prev_pdf.lane(i), pdf)
                    };
                }
            }
            // Only MEDIA scenes have boundaries.
            Material::Boundary => self.class[i] = if MEDIA { CLASS_BOUNDARY } else { CLASS_NONE },
        }
    }
}

/// What lies at each lane's closest hit: the surface one lane at a time, then the albedo
/// textures for all lanes that share one at once (an image gathers its texels), then each
/// lane's material, and for emitters their radiance with its MIS weight.
#[inline(always)]
pub(super) fn surfaces<
    F: Float,
    T: Transport<S: ChannelArray<N>>,
    const N: usize,
    const MOTION: bool,
    const MEDIA: bool,
>(
    ctx: &Ctx,
    st: &Paths<F, T, N>,
    hits: &PacketHit<F>,
    at: M<F>,
) -> Surface<F, N> {
    let scene = ctx.scene;
    let prims = &scene.prims;
    let (mut p, mut n, mut ns) = (Scratch3::new(), Scratch3::new(), Scratch3::new());
    let (mut tangent, mut aniso_bits) = (Scratch3::new(), 0u32);
    let mut shade = Shading::<T> {
        color: T::colours(),
        le: T::colours(),
        class: [CLASS_NONE; MAX_W],
        le_w: [0.0; MAX_W],
        ax: [0.0; MAX_W],
        ay: [0.0; MAX_W],
        coat_ior: [1.0; MAX_W],
        coat: [0; MAX_W],
        emit_bits: 0,
        conductor_bits: 0,
        schlick_bits: 0,
        multiscatter_bits: 0,
    };
    let mut mats = [0u32; MAX_W];
    let mut prim = [0u32; MAX_W];
    let (mut hit_bits, mut front_bits) = (0u32, 0u32);
    // Lanes whose albedo is looked up in lanes after this loop: their texture and uv.
    let mut later = 0u32;
    let mut tex = [0u32; MAX_W];
    let (mut tu, mut tv) = ([0.0f32; MAX_W], [0.0f32; MAX_W]);
    let found = (hits.hit & at).bits();
    for i in 0..F::WIDTH {
        if found >> i & 1 == 0 {
            continue;
        }
        let ray = Ray::new(st.o.lane(i), st.d.lane(i));
        let time = st.time.lane(i);
        let Some(hit) = hits.lane(i) else {
            continue;
        };
        let mat = prims.material[hit.prim as usize];
        hit_bits |= 1 << i;
        mats[i] = mat;
        prim[i] = hit.prim;
        let (sp, material, albedo) = surface_material::<MOTION>(ctx, &ray, &hit, time);
        p.set(i, sp.p);
        n.set(i, sp.facing());
        ns.set(i, sp.shading_facing());
        front_bits |= (sp.front as u32) << i;
        if material.alpha().is_some_and(|a| a.is_anisotropic()) {
            // The loader refuses anisotropy on meshes without UVs, so ∂p/∂u exists.
            let (_, dpdu, _) = prims.uv_frame::<MOTION>(&ray, &hit, &sp, time);
            tangent.set(i, dpdu.normalize_or_zero());
            aniso_bits |= 1 << i;
        }
        let h = LaneHit {
            mat,
            prim: hit.prim,
            n: sp.n,
            p: sp.p,
        };
        match albedo {
            Albedo::None => shade.finish::<F, N, MOTION, MEDIA>(ctx, st, i, h, material, None),
            Albedo::Now(a) => {
                let m = material.modulated(a);
                shade.finish::<F, N, MOTION, MEDIA>(ctx, st, i, h, m, Some(a));
            }
            Albedo::Later(t, uv) => {
                later |= 1 << i;
                (tex[i], tu[i], tv[i]) = (t, uv.x, uv.y);
            }
        }
    }
    // One lane lookup per texture among the packet's hits (usually one or two).
    let (u, v) = (F::load(&tu), F::load(&tv));
    while later != 0 {
        let t = tex[later.trailing_zeros() as usize];
        let mut same = 0u32;
        for (i, &ti) in tex.iter().enumerate().take(F::WIDTH) {
            same |= u32::from(later >> i & 1 != 0 && ti == t) << i;
        }
        later &= !same;
        let Some(a) = prims.textures[t as usize].albedo_lanes(u, v, mask_from_bits::<F>(same))
        else {
            continue;
        };
        for i in 0..F::WIDTH {
            if same >> i & 1 == 0 {
                continue;
            }
            let ai = a.lane(i);
            // The surface as the loop above left it: the geometric normal from the facing
            // one and the side.
            let facing = Vec3::new(n.x[i], n.y[i], n.z[i]);
            let h = LaneHit {
                mat: mats[i],
                prim: prim[i],
                n: if front_bits >> i & 1 != 0 {
                    facing
                } else {
                    -facing
                },
                p: Vec3::new(p.x[i], p.y[i], p.z[i]),
            };
            let mut m = prims.materials[mats[i] as usize].modulated(ai);
            if let Some(r) = prims.textures[t as usize].roughness(Vec2::new(tu[i], tv[i])) {
                m = m.roughened(r);
            }
            shade.finish::<F, N, MOTION, MEDIA>(ctx, st, i, h, m, Some(ai));
        }
    }
    Surface {
        hit: mask_from_bits::<F>(hit_bits),
        p: p.v3(),
        nf: n.v3(),
        nsf: ns.v3(),
        front: mask_from_bits::<F>(front_bits),
        class: U::<F>::from_fn(|i| shade.class[i]),
        color: T::eval(&shade.color, &st.lam),
        ax: F::load(&shade.ax),
        ay: F::load(&shade.ay),
        schlick: mask_from_bits::<F>(shade.schlick_bits),
        multiscatter: mask_from_bits::<F>(shade.multiscatter_bits),
        coat_ior: F::load(&shade.coat_ior),
        coat: U::<F>::from_fn(|i| shade.coat[i]),
        aniso: mask_from_bits::<F>(aniso_bits),
        tangent: tangent.v3(),
        mat: mats,
        prim,
        emits: mask_from_bits::<F>(shade.emit_bits),
        le: if shade.emit_bits | shade.conductor_bits != 0 {
            T::eval(&shade.le, &st.lam)
        } else {
            C::<F, N>::splat(F::zero())
        },
        le_w: F::load(&shade.le_w),
    }
}
