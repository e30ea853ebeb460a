//! Three-component vectors of lanes: x, y and z each a [`Float`], so W vectors are three
//! registers (structure of arrays), not W packed triples.

use super::Float;
use glam::Vec3;
use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// A vector per lane, stored as one lane value per component.
#[derive(Clone, Copy, Debug)]
pub struct V3<F> {
    /// x component of every lane.
    pub x: F,
    /// y component of every lane.
    pub y: F,
    /// z component of every lane.
    pub z: F,
}

impl<F: Float> V3<F> {
    /// From its three components.
    #[inline(always)]
    pub fn new(x: F, y: F, z: F) -> Self {
        V3 { x, y, z }
    }
    /// The same vector in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3::new(F::splat(v.x), F::splat(v.y), F::splat(v.z))
    }
    /// The zero vector in every lane.
    #[inline(always)]
    pub fn zero() -> Self {
        Self::splat(Vec3::ZERO)
    }
    /// Lane `i` set to `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> Self {
        let mut x = [0.0f32; 16];
        let mut y = [0.0f32; 16];
        let mut z = [0.0f32; 16];
        for i in 0..F::WIDTH {
            let v = f(i);
            (x[i], y[i], z[i]) = (v.x, v.y, v.z);
        }
        V3::new(F::load(&x), F::load(&y), F::load(&z))
    }
    /// The vector in lane `i`.
    #[inline(always)]
    pub fn lane(self, i: usize) -> Vec3 {
        Vec3::new(self.x.lane(i), self.y.lane(i), self.z.lane(i))
    }
    /// Dot product per lane (fused).
    #[inline(always)]
    pub fn dot(self, o: Self) -> F {
        self.x.mul_add(o.x, self.y.mul_add(o.y, self.z * o.z))
    }
    /// Cross product per lane.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    /// Squared length per lane.
    #[inline(always)]
    pub fn length_squared(self) -> F {
        self.dot(self)
    }
    /// Length per lane.
    #[inline(always)]
    pub fn length(self) -> F {
        self.dot(self).sqrt()
    }
    /// Unit length; a zero vector gives NaN lanes, as glam's `normalize` does.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * self.length().recip()
    }
    /// Componentwise product.
    #[inline(always)]
    pub fn mul_elem(self, o: Self) -> Self {
        V3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
    /// `self * s + o`, fused per component.
    #[inline(always)]
    pub fn mul_add(self, s: F, o: Self) -> Self {
        V3::new(
            self.x.mul_add(s, o.x),
            self.y.mul_add(s, o.y),
            self.z.mul_add(s, o.z),
        )
    }
    /// `a` in lanes where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: F::Mask, a: Self, b: Self) -> Self {
        V3::new(
            F::select(m, a.x, b.x),
            F::select(m, a.y, b.y),
            F::select(m, a.z, b.z),
        )
    }
    /// Largest component per lane.
    #[inline(always)]
    pub fn max_element(self) -> F {
        self.x.max(self.y).max(self.z)
    }
}

impl<F: Float> Add for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<F: Float> Sub for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<F: Float> Mul<F> for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F) -> Self {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<F: Float> Neg for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3::new(-self.x, -self.y, -self.z)
    }
}

impl<F: Float> AddAssign for V3<F> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<F: Float> SubAssign for V3<F> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

impl<F: Float> MulAssign<F> for V3<F> {
    #[inline(always)]
    fn mul_assign(&mut self, s: F) {
        *self = *self * s;
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Vec3 {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> V3<f32> {
        V3::new(v.x, v.y, v.z)
    }
}
