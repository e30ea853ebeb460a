//! Procedural albedos: colour and a height field, both evaluated directly from (u, v).
//!
//! Heights are in uv units (a groove 0.01 deep is as deep as 0.01 of the texture is wide),
//! so [`NormalMap::FromHeight`](super::NormalMap::FromHeight) with strength 1 tilts normals
//! as a real relief of that shape would on a surface mapped without stretching. Every
//! function is total: NaN or infinite coordinates are treated as 0, and nothing allocates.

use super::image_tex::rem_euclid_lanes;
use crate::simd::{Float, V3};
use glam::{Vec2, Vec3};

/// Replaces non-finite coordinates by 0 so patterns never see NaN.
#[inline]
pub(crate) fn sanitize(uv: Vec2) -> Vec2 {
    Vec2::new(
        if uv.x.is_finite() { uv.x } else { 0.0 },
        if uv.y.is_finite() { uv.y } else { 0.0 },
    )
}

#[inline]
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Squares of side `size`; the square touching the origin from above-right is `a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checker {
    /// Colour of the square touching the origin from above-right, linear RGB.
    pub a: Vec3,
    /// Colour of the other squares, linear RGB.
    pub b: Vec3,
    /// Side of a square, uv units.
    pub size: f32,
}

impl Checker {
    /// True where the colour is `a`.
    #[inline]
    pub fn is_a(&self, uv: Vec2) -> bool {
        let uv = sanitize(uv) / self.size;
        // Parity of floor(u) + floor(v) in floating point: exact for any magnitude, where an
        // integer cast would saturate.
        let sum = uv.x.floor().rem_euclid(2.0) + uv.y.floor().rem_euclid(2.0);
        sum != 1.0
    }

    /// Linear RGB at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        if self.is_a(uv) { self.a } else { self.b }
    }

    /// [`eval`](Self::eval) for every lane at once, bit for bit.
    #[inline(always)]
    pub fn eval_lanes<F: Float>(&self, u: F, v: F) -> V3<F> {
        let sum = self.parity_lanes(u) + self.parity_lanes(v);
        V3::select(sum.ne(F::one()), V3::splat(self.a), V3::splat(self.b))
    }

    /// `floor(x / size) mod 2` as [`is_a`](Self::is_a) computes it, in lanes.
    #[inline(always)]
    fn parity_lanes<F: Float>(&self, x: F) -> F {
        let x = F::select(x.is_finite(), x, F::zero());
        rem_euclid_lanes((x / F::splat(self.size)).floor(), 2.0)
    }

    /// A checkerboard is a flat print: constant height.
    #[inline]
    pub fn height(&self, _uv: Vec2) -> f32 {
        0.0
    }

    /// A finite-difference step far below the square size.
    pub fn height_step(&self) -> f32 {
        self.size / 64.0
    }
}

/// Running-bond brickwork: rows of height `size.y`, bricks `size.x` wide, every odd row
/// shifted by half a brick. `size` is the pitch (brick plus one joint); the mortar joint of
/// width `joint` (uv units) is centred on the lines u = k·size.x (shifted in odd rows) and
/// v = k·size.y, so the origin lies in mortar and (size.x/2, size.y/2) is a brick centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bricks {
    /// Brick colour, linear RGB.
    pub brick: Vec3,
    /// Mortar colour, linear RGB.
    pub mortar: Vec3,
    /// Pitch of the pattern (brick plus one joint) along u and v, uv units.
    pub size: Vec2,
    /// Width of the mortar joints, uv units.
    pub joint: f32,
}

impl Bricks {
    /// Distance from `uv` to the nearest joint centre line, in uv units.
    #[inline]
    pub fn joint_distance(&self, uv: Vec2) -> f32 {
        let uv = sanitize(uv);
        let (w, h) = (self.size.x, self.size.y);
        let row = (uv.y / h).floor();
        let shift = if row.rem_euclid(2.0) >= 1.0 {
            0.5 * w
        } else {
            0.0
        };
        let fu = ((uv.x + shift) / w).fract_gl() * w;
        let fv = (uv.y / h).fract_gl() * h;
        fu.min(w - fu).min(fv.min(h - fv))
    }

    /// True where `uv` lies in a mortar joint.
    #[inline]
    pub fn is_mortar(&self, uv: Vec2) -> bool {
        self.joint_distance(uv) < 0.5 * self.joint
    }

    /// Linear RGB at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        if self.is_mortar(uv) {
            self.mortar
        } else {
            self.brick
        }
    }

    /// Brick faces at 0, mortar recessed by half a joint width; brick edges round off over
    /// half a joint width so the slope is finite and central differences see it.
    #[inline]
    pub fn height(&self, uv: Vec2) -> f32 {
        let d = self.joint_distance(uv);
        let half = 0.5 * self.joint;
        let (depth, bevel) = (half, half);
        let h = -depth * (1.0 - smoothstep(half, half + bevel, d));
        if h.is_finite() { h } else { 0.0 }
    }

    /// Several steps across the bevel.
    pub fn height_step(&self) -> f32 {
        self.joint / 16.0
    }
}

/// Plank grain: growth rings of a log whose axis runs along u through the tile centre,
/// seen as long ellipses and distorted by smooth noise. Latewood (the dark band at the end
/// of each ring) is harder and stands slightly proud of the softer earlywood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wood {
    /// Earlywood colour, linear RGB.
    pub light: Vec3,
    /// Latewood colour, linear RGB.
    pub dark: Vec3,
    /// Rings per uv unit across the grain (along v).
    pub rings: f32,
    /// Distortion of the rings, in ring widths.
    pub noise: f32,
}

/// Squeezes u so the rings stretch along it: the grain runs along u.
const GRAIN_STRETCH: f32 = 0.15;
/// Latewood ridge height as a fraction of the ring width.
const RIDGE: f32 = 0.05;

impl Wood {
    /// 0 in earlywood, rising to 1 in the latewood band at the end of each ring; continuous
    /// across ring boundaries so the height has no cliffs.
    #[inline]
    pub fn latewood(&self, uv: Vec2) -> f32 {
        let uv = sanitize(uv);
        let p = uv - Vec2::splat(0.5);
        let r = Vec2::new(p.x * GRAIN_STRETCH, p.y).length();
        let t = self.rings * r + self.noise * fbm(uv * Vec2::new(2.0, 6.0));
        let s = t.fract_gl();
        let l = smoothstep(0.55, 0.85, s) * (1.0 - smoothstep(0.9, 1.0, s));
        if l.is_finite() { l } else { 0.0 }
    }

    /// Linear RGB at `uv`: earlywood blended towards latewood.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        self.light.lerp(self.dark, self.latewood(uv))
    }

    /// Relief in uv units: latewood ridges stand proud of earlywood.
    #[inline]
    pub fn height(&self, uv: Vec2) -> f32 {
        self.latewood(uv) * RIDGE / self.rings
    }

    /// A small fraction of one ring width.
    pub fn height_step(&self) -> f32 {
        1.0 / (64.0 * self.rings)
    }
}

/// `x − floor(x)`, in [0, 1) (0 for non-finite input, unlike `f32::fract`, which is signed).
trait FractGl {
    fn fract_gl(self) -> f32;
}

impl FractGl for f32 {
    #[inline]
    fn fract_gl(self) -> f32 {
        let f = self - self.floor();
        // `-tiny - floor(-tiny)` rounds to 1.0; keep the documented range.
        if f < 1.0 { f } else { 0.0 }
    }
}

/// Integer lattice hash to [−1, 1] (a 32-bit avalanche mix; quality is ample for grain).
#[inline]
fn lattice(x: i32, y: i32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343) ^ (y as u32).wrapping_mul(0xd816_3841);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
}

/// Smooth value noise in [−1, 1]: C² (quintic) blend of hashed lattice values.
#[inline]
fn value_noise(p: Vec2) -> f32 {
    let base = p.floor();
    let f = p - base;
    let fade = f * f * f * (f * (f * 6.0 - Vec2::splat(15.0)) + Vec2::splat(10.0));
    // Saturating casts keep huge inputs total; the noise there is just constant.
    let (x, y) = (base.x as i32, base.y as i32);
    let a = lattice(x, y);
    let b = lattice(x.wrapping_add(1), y);
    let c = lattice(x, y.wrapping_add(1));
    let d = lattice(x.wrapping_add(1), y.wrapping_add(1));
    let bottom = a + (b - a) * fade.x;
    let top = c + (d - c) * fade.x;
    bottom + (top - bottom) * fade.y
}

/// Four octaves of value noise, normalised back to [−1, 1].
#[inline]
fn fbm(p: Vec2) -> f32 {
    let mut sum = 0.0;
    let mut amp = 0.5;
    let mut q = p;
    for _ in 0..4 {
        sum += amp * value_noise(q);
        // Shift each octave so the lattices of successive octaves do not line up.
        q = q * 2.0 + Vec2::new(17.3, 5.9);
        amp *= 0.5;
    }
    sum / 0.9375
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_bounded_and_deterministic() {
        for i in 0..2000 {
            let p = Vec2::new(i as f32 * 0.37 - 300.0, i as f32 * 0.11 + 7.0);
            let n = fbm(p);
            assert!((-1.0..=1.0).contains(&n), "{p} {n}");
            assert_eq!(n, fbm(p));
        }
        // Lattice values are reproduced exactly at integer points.
        assert_eq!(value_noise(Vec2::new(3.0, -4.0)), lattice(3, -4));
    }

    #[test]
    fn noise_is_continuous() {
        let mut worst = 0.0f32;
        for i in 0..5000 {
            let p = Vec2::new(i as f32 * 0.013, 1.0 + i as f32 * 0.007);
            worst = worst.max((value_noise(p + Vec2::splat(1e-3)) - value_noise(p)).abs());
        }
        assert!(worst < 0.02, "{worst}");
    }

    #[test]
    fn wood_latewood_is_bounded_and_continuous() {
        let w = Wood {
            light: Vec3::ONE,
            dark: Vec3::ZERO,
            rings: 8.0,
            noise: 0.5,
        };
        let mut seen_dark = false;
        for i in 0..4000 {
            let uv = Vec2::new(0.3, i as f32 / 4000.0);
            let l = w.latewood(uv);
            assert!((0.0..=1.0).contains(&l));
            seen_dark |= l > 0.9;
            let step = (w.latewood(uv + Vec2::new(0.0, 1e-4)) - l).abs();
            assert!(step < 0.05, "jump {step} at {uv}");
        }
        assert!(seen_dark, "rings must reach the latewood colour");
    }

    #[test]
    fn fract_gl_stays_below_one() {
        assert_eq!((-1e-30f32).fract_gl(), 0.0);
        assert_eq!(2.25f32.fract_gl(), 0.25);
        assert_eq!((-0.25f32).fract_gl(), 0.75);
    }
}
