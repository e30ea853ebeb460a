//! The watertight ray–triangle test (Woop, Benthin and Wald 2013) and its first half run as
//! a screen over a block of leaf triangles, a lane type's width at a time.

use crate::geometry::Ray;
use crate::simd::{Float, Mask};
use glam::{Vec3, Vec4};

/// Triangles per leaf block: [`KdParams::run_align`](crate::kdtree::KdParams::run_align) of
/// mesh trees.
pub(super) const BLOCK: usize = 16;

/// pbrt's γ(n) = n u / (1 − n u), u the unit roundoff of f32.
#[inline]
const fn gamma(n: f32) -> f32 {
    let u = f32::EPSILON * 0.5;
    n * u / (1.0 - n * u)
}

/// Sixteen triangles of a leaf run, component-major: `c[corner][axis][lane]`, so that the
/// shear and the edge functions of the watertight test run on a lane type's width of them at
/// once (16 in one AVX-512 register; a typical leaf of ~10 triangles fits in one block).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct TriBlock {
    pub(super) c: [[[f32; BLOCK]; 3]; 3],
}

impl Default for TriBlock {
    fn default() -> Self {
        Self {
            c: [[[0.0; BLOCK]; 3]; 3],
        }
    }
}

impl TriBlock {
    #[inline]
    pub(super) fn corners(&self, lane: usize) -> [Vec3; 3] {
        let corner = |[x, y, z]: &[[f32; BLOCK]; 3]| Vec3::new(x[lane], y[lane], z[lane]);
        [corner(&self.c[0]), corner(&self.c[1]), corner(&self.c[2])]
    }
}

/// The constants of the watertight test for one ray: the translation to its origin and the
/// permute-and-shear rows that carry the direction onto +z (Woop et al. 2013). Public so that
/// other acceleration structures can be measured with the same triangle test.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    /// The axes that become x, y and z: z is the direction's largest component.
    k: [usize; 3],
    /// The origin's components along `k`.
    o: [f32; 3],
    /// Shear: `x' = p[kx] − Sx p[kz]`, `y' = p[ky] − Sy p[kz]`, `z' = Sz p[kz]`, with `p`
    /// relative to the origin; reading the vertices' components through `k` costs nothing
    /// more than loading them.
    sx: f32,
    sy: f32,
    sz: f32,
    /// |d[kz]|: turns the sheared z (a distance along the ray in units of t) back into the
    /// length unit of x and y for the error bounds.
    dz: f32,
}

impl RayFrame {
    /// `None` for a ray with a zero or non-finite direction or a non-finite origin.
    #[inline]
    pub fn new(ray: &Ray) -> Option<Self> {
        let usable = ray.d.is_finite() && ray.o.is_finite() && ray.d != Vec3::ZERO;
        usable.then(|| Self::build(ray))
    }

    /// The frame of a ray that [`RayFrame::new`] accepts.
    #[inline]
    fn build(ray: &Ray) -> Self {
        let d = ray.d.to_array();
        let o = ray.o.to_array();
        let a = ray.d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Swapping x and y for a negative z keeps the triangles' winding, and so the sign
        // convention of the edge functions, the same for every ray.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            k: [kx, ky, kz],
            o: [o[kx], o[ky], o[kz]],
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
            dz: d[kz].abs(),
        }
    }

    /// A vertex relative to the origin, permuted and sheared: (x', y', z before scaling).
    #[inline]
    fn shear(&self, v: &Vec3) -> (f32, f32, f32) {
        let v: &[f32; 3] = v.as_ref();
        let [kx, ky, kz] = self.k;
        let z = v[kz] - self.o[2];
        (
            v[kx] - self.o[0] - self.sx * z,
            v[ky] - self.o[1] - self.sy * z,
            z,
        )
    }

    /// Bit per lane of the first `n` of the block: set where the triangle may be hit, clear
    /// where the edge functions have mixed signs (all nonzero), which [`RayFrame::hit`]
    /// rejects. Lane for lane the same operations as `hit`, so the same roundings. Width 1
    /// screens four at a time in SSE registers.
    #[inline(always)]
    pub(super) fn screen<F: Float>(&self, b: &TriBlock, n: usize) -> u32 {
        let mut bits = 0;
        let mut at = 0;
        while at < n {
            bits |= if F::WIDTH == 1 {
                self.screen4(b, at)
            } else {
                self.screen_lanes::<F>(b, at)
            } << at;
            at += F::WIDTH.max(4);
        }
        // Padding lanes (all-zero triangles) pass the screen; they are not the leaf's.
        bits & (u32::MAX >> (32 - n))
    }

    /// The screen of lanes `at..at + F::WIDTH`.
    #[inline(always)]
    fn screen_lanes<F: Float>(&self, b: &TriBlock, at: usize) -> u32 {
        // Clamped so the compiler sees the rows are in range (they are: k permutes 0..3).
        let (kx, ky, kz) = (self.k[0].min(2), self.k[1].min(2), self.k[2].min(2));
        let (ox, oy, oz) = (
            F::splat(self.o[0]),
            F::splat(self.o[1]),
            F::splat(self.o[2]),
        );
        let (sx, sy) = (F::splat(self.sx), F::splat(self.sy));
        let load = |c: &[[f32; BLOCK]; 3], axis: usize| F::load(&c[axis][at..]);
        // No closures or array maps over lane values here: those were left uninlined.
        let (ax, ay) = {
            let z = load(&b.c[0], kz) - oz;
            (
                load(&b.c[0], kx) - ox - sx * z,
                load(&b.c[0], ky) - oy - sy * z,
            )
        };
        let (bx, by) = {
            let z = load(&b.c[1], kz) - oz;
            (
                load(&b.c[1], kx) - ox - sx * z,
                load(&b.c[1], ky) - oy - sy * z,
            )
        };
        let (cx, cy) = {
            let z = load(&b.c[2], kz) - oz;
            (
                load(&b.c[2], kx) - ox - sx * z,
                load(&b.c[2], ky) - oy - sy * z,
            )
        };
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = F::zero();
        let is_zero = u.eq(zero) | v.eq(zero) | w.eq(zero);
        let neg = u.lt(zero) | v.lt(zero) | w.lt(zero);
        let pos = u.gt(zero) | v.gt(zero) | w.gt(zero);
        (is_zero | !(neg & pos)).bits()
    }

    /// The screen of lanes `at..at + 4` in SSE registers.
    #[inline(always)]
    fn screen4(&self, b: &TriBlock, at: usize) -> u32 {
        let (kx, ky, kz) = (self.k[0].min(2), self.k[1].min(2), self.k[2].min(2));
        let (ox, oy, oz) = (
            Vec4::splat(self.o[0]),
            Vec4::splat(self.o[1]),
            Vec4::splat(self.o[2]),
        );
        let (sx, sy) = (Vec4::splat(self.sx), Vec4::splat(self.sy));
        let shear = |c: &[[f32; BLOCK]; 3]| {
            let get = |axis: usize| Vec4::from_slice(&c[axis][at..at + 4]);
            let z = get(kz) - oz;
            (get(kx) - ox - sx * z, get(ky) - oy - sy * z)
        };
        let (ax, ay) = shear(&b.c[0]);
        let (bx, by) = shear(&b.c[1]);
        let (cx, cy) = shear(&b.c[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = u.cmpeq(Vec4::ZERO) | v.cmpeq(Vec4::ZERO) | w.cmpeq(Vec4::ZERO);
        let neg = u.cmplt(Vec4::ZERO) | v.cmplt(Vec4::ZERO) | w.cmplt(Vec4::ZERO);
        let pos = u.cmpgt(Vec4::ZERO) | v.cmpgt(Vec4::ZERO) | w.cmpgt(Vec4::ZERO);
        (zero | !(neg & pos)).bitmask()
    }

    /// `(t, b1, b2)` of a hit with `t` in (0, t_max).
    #[inline]
    pub fn hit(&self, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let (ax, ay, az) = self.shear(&tri[0]);
        let (bx, by, bz) = self.shear(&tri[1]);
        let (cx, cy, cz) = self.shear(&tri[2]);

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // On an edge to f32 precision: the f64 products are exact, so the sign is right
            // and both triangles of the edge agree on it.
            let e = |px: f32, py: f32, qx: f32, qy: f32| {
                (f64::from(px) * f64::from(qy) - f64::from(py) * f64::from(qx)) as f32
            };
            u = e(cx, cy, bx, by);
            v = e(ax, ay, cx, cy);
            w = e(bx, by, ax, ay);
        }
        // Both orientations count (no back-face culling); a mix of signs is a miss.
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }

        let (az, bz, cz) = (self.sz * az, self.sz * bz, self.sz * cz);
        let t_scaled = u * az + v * bz + w * cz;
        // The range test before dividing, with det's sign folded in.
        if det < 0.0 {
            if t_scaled >= 0.0 || t_scaled < t_max * det {
                return None;
            }
        } else if t_scaled <= 0.0 || t_scaled > t_max * det {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // NaN only from overflow in extreme coordinates: not a hit either.
        if t >= t_max || t.is_nan() {
            return None;
        }

        // Conservative: t must exceed the bound on its rounding error (pbrt-v3, 3.9.6), or
        // a hit at or just behind the origin could be reported in front of it. The x and y
        // bounds take z before the 1/d_z scaling (pbrt's form assumes |d| ≈ 1; for a short or
        // long direction the scaled z is in other units and the bound would reject real hits).
        let max_zt = az.abs().max(bz.abs()).max(cz.abs());
        let max_z_len = max_zt * self.dz;
        let max_xt = ax.abs().max(bx.abs()).max(cx.abs());
        let max_yt = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = gamma(3.0) * max_zt;
        let delta_x = gamma(5.0) * (max_xt + max_z_len);
        let delta_y = gamma(5.0) * (max_yt + max_z_len);
        let delta_e = 2.0 * (gamma(2.0) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = 3.0
            * (gamma(3.0) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some((t, v * inv_det, w * inv_det))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_screen_keeps_every_triangle_the_scalar_test_hits() {
        use crate::simd::PortableF32;
        use rand::{RngExt, SeedableRng};
        // Triangles of a small grid, so that rays aimed at its vertices and edge midpoints
        // make edge functions exactly zero, and random ones elsewhere; each block is screened
        // at every width and every lane checked against the scalar test.
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut rnd = |lo: f32, hi: f32| lo + (hi - lo) * rng.random::<f32>();
        let mut tris = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let p = |a: u32, b: u32| Vec3::new(a as f32, b as f32, 0.0);
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        while tris.len() < 64 {
            let mut v = || Vec3::new(rnd(-1.0, 5.0), rnd(-1.0, 5.0), rnd(-2.0, 2.0));
            tris.push([v(), v(), v()]);
        }
        let blocks: Vec<TriBlock> = tris
            .chunks(BLOCK)
            .map(|some| {
                let mut b = TriBlock::default();
                for (lane, t) in some.iter().enumerate() {
                    for (j, v) in t.iter().enumerate() {
                        for a in 0..3 {
                            b.c[j][a][lane] = v[a];
                        }
                    }
                }
                b
            })
            .collect();
        let (mut hits, mut rejected, mut lanes) = (0, 0, 0);
        for k in 0..4000 {
            let target = if k % 2 == 0 {
                // A grid vertex or an edge midpoint.
                let (a, b) = ((k / 2 % 9) as f32 * 0.5, (k / 18 % 9) as f32 * 0.5);
                Vec3::new(a, b, 0.0)
            } else {
                Vec3::new(rnd(-1.0, 5.0), rnd(-1.0, 5.0), rnd(-1.0, 1.0))
            };
            let o = Vec3::new(rnd(-3.0, 7.0), rnd(-3.0, 7.0), rnd(-4.0, 4.0));
            let ray = Ray::new(o, target - o);
            let Some(frame) = RayFrame::new(&ray) else {
                continue;
            };
            for (b, block) in blocks.iter().enumerate() {
                // Every width screens with the same roundings; a short run masks its padding.
                let n = 1 + (k + b) % BLOCK;
                let mask = frame.screen::<f32>(block, n);
                assert_eq!(frame.screen::<PortableF32<8>>(block, n), mask);
                assert_eq!(frame.screen::<PortableF32<16>>(block, n), mask);
                assert_eq!(mask >> n, 0, "padding lanes are never candidates");
                for lane in 0..n {
                    let tri = &tris[BLOCK * b + lane];
                    assert_eq!(block.corners(lane), *tri);
                    let hit = frame.hit(tri, f32::INFINITY);
                    lanes += 1;
                    hits += usize::from(hit.is_some());
                    if mask >> lane & 1 == 0 {
                        rejected += 1;
                        assert!(hit.is_none(), "{ray:?} lane {lane} of block {b}");
                    }
                }
            }
        }
        // The screen must do its job too: it rejects most of the misses.
        assert!(hits > 500, "{hits} hits");
        assert!(rejected > (lanes - hits) / 2, "{rejected} of {lanes}");
    }
}
