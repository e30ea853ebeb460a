//! Surfaces: for the winning hit of each lane only, the full surface (normals, UV, textures,
//! normal maps) and its material, sorted into material classes for the scattering stage;
//! emitters hit by chance with their radiance and MIS weight.

use super::bsdf::LaneChannels;
use super::ctx::Ctx;
use super::state::{C, M, MAX_W, Paths, Scratch3, U, mask_from_bits, power_heuristic};
use super::transport::{ChannelArray, Transport};
use crate::components::Material;
use crate::geometry::Ray;
use crate::scene::Hit;
use crate::scene::packet::PacketHit;
use crate::scene::primitives::emitted;
use crate::simd::{Float, Mask, UInt, V3};
use glam::Vec3;

/// Per-lane material classes after the surface stage.
pub(super) const CLASS_NONE: u32 = 0;
pub(super) const CLASS_DIFFUSE: u32 = 1;
pub(super) const CLASS_MIRROR: u32 = 2;
pub(super) const CLASS_DIELECTRIC: u32 = 3;
/// MEDIA: a medium's boundary, crossed without scattering.
pub(super) const CLASS_BOUNDARY: u32 = 4;

/// What the surface stage found at each lane's hit point.
pub(super) struct Surface<F: Float, const N: usize> {
    pub(super) hit: M<F>,
    pub(super) p: V3<F>,
    /// Geometric and shading normals on the side the ray arrived from.
    pub(super) nf: V3<F>,
    pub(super) nsf: V3<F>,
    pub(super) front: M<F>,
    pub(super) class: U<F>,
    /// Albedo (Diffuse) or tint (Mirror), texture-modulated.
    pub(super) color: C<F, N>,
    /// Each lane's material index (for a dielectric's IOR model) and primitive (for the
    /// medium behind a dielectric).
    pub(super) mat: [u32; MAX_W],
    pub(super) prim: [u32; MAX_W],
    /// Lanes that hit an emitter with non-zero radiance, the radiance and its MIS weight.
    pub(super) emits: M<F>,
    pub(super) le: C<F, N>,
    pub(super) le_w: F,
}

/// The surface at `hit` with its material after textures: the albedo texture modulates the
/// material (and is returned for spectral upsampling), a normal map tilts the shading normal.
#[inline(always)]
pub(crate) fn surface_material<const MOTION: bool>(
    ctx: &Ctx,
    ray: &Ray,
    hit: &Hit,
    time: f32,
) -> (crate::geometry::SurfacePoint, Material, Option<Vec3>) {
    let prims = &ctx.scene.prims;
    let mut sp = prims.surface_at::<MOTION>(ray, hit, time);
    let mut material = prims.materials[prims.material[hit.prim as usize] as usize];
    let mut tex_albedo = None;
    if (ctx.textures || ctx.normal_maps)
        && let Some(tex) = prims.texture_of(hit.prim)
    {
        let (uv, dpdu, dpdv) = prims.uv_frame::<MOTION>(ray, hit, &sp, time);
        if ctx.textures
            && let Some(a) = tex.albedo(uv)
        {
            material = material.modulated(a);
            tex_albedo = Some(a);
        }
        if ctx.normal_maps && tex.normal_map.is_some() {
            // As pbrt does: the perturbed normal is turned to the geometric normal's side;
            // directions it would send below the geometric surface are absorbed in scattering.
            let ns = tex.shading_normal(uv, sp.ns, dpdu, dpdv);
            sp.ns = if ns.dot(sp.n) < 0.0 { -ns } else { ns };
        }
    }
    (sp, material, tex_albedo)
}

/// What lies at each lane's closest hit, one lane at a time: the surface, its textures and
/// material, and for emitters their radiance with its MIS weight.
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
    let (mut color, mut le) = (T::colours(), T::colours());
    let mut class = [CLASS_NONE; MAX_W];
    let mut mats = [0u32; MAX_W];
    let mut prim = [0u32; MAX_W];
    let mut le_w = [0.0f32; MAX_W];
    let (mut hit_bits, mut front_bits, mut emit_bits) = (0u32, 0u32, 0u32);
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
        let (sp, material, tex_albedo) = surface_material::<MOTION>(ctx, &ray, &hit, time);
        p.set(i, sp.p);
        n.set(i, sp.facing());
        ns.set(i, sp.shading_facing());
        front_bits |= (sp.front as u32) << i;
        match material {
            Material::Diffuse { albedo } => {
                class[i] = CLASS_DIFFUSE;
                T::set_reflectance(&mut color, i, ctx, mat, albedo, tex_albedo.is_some());
            }
            Material::Mirror { tint } => {
                class[i] = CLASS_MIRROR;
                T::set_reflectance(&mut color, i, ctx, mat, tint, tex_albedo.is_some());
            }
            Material::Dielectric { .. } => class[i] = CLASS_DIELECTRIC,
            Material::Light { .. } => {
                let radiance = emitted(&material, sp.n, -ray.d);
                if radiance != Vec3::ZERO {
                    emit_bits |= 1 << i;
                    T::set_emission(&mut le, i, ctx, mat, radiance, tex_albedo, &st.lam);
                    let (depth, specular) = (st.depth.lane(i), st.specular.lane(i));
                    le_w[i] = if depth == 0 || specular || !ctx.nee {
                        1.0
                    } else {
                        let pdf = scene.lights.pdf_area::<MOTION>(
                            prims,
                            hit.prim,
                            st.prev_p.lane(i),
                            sp.p,
                            sp.n,
                            time,
                        );
                        power_heuristic::<f32>(st.prev_pdf.lane(i), pdf)
                    };
                }
            }
            // Only MEDIA scenes have boundaries.
            Material::Boundary => class[i] = if MEDIA { CLASS_BOUNDARY } else { CLASS_NONE },
        }
    }
    Surface {
        hit: mask_from_bits::<F>(hit_bits),
        p: p.v3(),
        nf: n.v3(),
        nsf: ns.v3(),
        front: mask_from_bits::<F>(front_bits),
        class: U::<F>::from_fn(|i| class[i]),
        color: T::eval(&color, &st.lam),
        mat: mats,
        prim,
        emits: mask_from_bits::<F>(emit_bits),
        le: if emit_bits != 0 {
            T::eval(&le, &st.lam)
        } else {
            C::<F, N>::splat(F::zero())
        },
        le_w: F::load(&le_w),
    }
}
