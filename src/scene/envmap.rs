//! The environment as an image: an equirectangular (latitude–longitude) map of linear RGB
//! radiance, looked up bilinearly and importance-sampled by a piecewise-constant density over
//! the sphere.
//!
//! Convention (map space, before `rotate`): `+y` is up; texel row 0 is the top (`+y`), the
//! last row the bottom (`-y`); the map's centre column faces `-z`, the column at three
//! quarters of the width faces `+x`. In coordinates, with u = column / width and
//! v = row / height (texel centres at half-integers), θ = π·v from `+y` and φ = 2π·(u − ½):
//!
//! ```text
//! d = (sin θ · sin φ,  cos θ,  −sin θ · cos φ)
//! u = ½ + atan2(d.x, −d.z) / 2π,   v = acos(d.y) / π
//! ```
//!
//! A camera looking down `-z` sees the map's centre, with the map's right-hand side on its
//! right. `rotate` turns the map as a transform's rotation turns a shape: the world direction
//! of a map direction m is R·m, R = Rz·Ry·Rx.
//!
//! Sampling draws cells of a grid whose corners are the texel centres (columns wrap; the rows
//! nearest the poles are half cells), with probability proportional to the largest luminance
//! among the cell's corner texels times the cell's solid angle, then a point uniformly by solid
//! angle within the cell. A bilinear lookup inside a cell blends exactly those corners, so every
//! direction the map lights has a density above zero, and the density is constant per cell:
//! the cell's corner maximum over the sum of every cell's (maximum × solid angle).

use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;

/// Luminance of linear sRGB (Rec. 709 Y).
#[inline]
fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// An environment map ready to render: radiance per texel (scale applied), orientation and
/// sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: u32,
    height: u32,
    /// Linear RGB radiance, row-major, top row first.
    texels: Vec<Vec3>,
    /// Map direction → world direction.
    to_world: Mat3,
    /// World direction → map direction.
    to_local: Mat3,
    dist: SphereDistribution,
    /// Mean radiance over the sphere, linear RGB (∫ L dω / 4π).
    mean: Vec3,
    /// The file as the scene names it, with `scale` and `rotate`, for messages.
    source: String,
    scale: f32,
    rotate: Vec3,
}

/// Why a map cannot light a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvMapError {
    /// A texel holds NaN or an infinity.
    NotFinite {
        /// Column of the texel.
        x: u32,
        /// Row of the texel (0 is the top).
        y: u32,
    },
    /// The image has no texels or is larger than the bound.
    Size {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
}

impl std::fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            EnvMapError::NotFinite { x, y } => write!(
                f,
                "texel ({x}, {y}) is not a finite number (NaN or infinity); an environment map \
                 must hold finite radiance"
            ),
            EnvMapError::Size { width, height } => write!(
                f,
                "a {width}×{height} map cannot light a scene: it needs at least 1×1 texels"
            ),
        }
    }
}

impl EnvMap {
    /// A map from `width × height` linear RGB texels (top row first), each multiplied by
    /// `scale`, turned by `rotate` degrees about x, then y, then z (R = Rz·Ry·Rx). Negative
    /// components (ringing from resampling) are read as zero; NaN and infinities are refused.
    pub fn new(
        width: u32,
        height: u32,
        texels: &[[f32; 3]],
        scale: f32,
        rotate: Vec3,
    ) -> Result<EnvMap, EnvMapError> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(EnvMapError::Size { width, height });
        }
        let mut out = Vec::with_capacity(texels.len());
        for (i, t) in texels.iter().enumerate() {
            let v = Vec3::from_array(*t);
            if !v.is_finite() {
                return Err(EnvMapError::NotFinite {
                    x: (i % width as usize) as u32,
                    y: (i / width as usize) as u32,
                });
            }
            out.push(v.max(Vec3::ZERO) * scale);
        }
        let r = glam::Quat::from_rotation_z(rotate.z.to_radians())
            * glam::Quat::from_rotation_y(rotate.y.to_radians())
            * glam::Quat::from_rotation_x(rotate.x.to_radians());
        let to_world = Mat3::from_quat(r);
        let lum: Vec<f32> = out.iter().map(|&c| luminance(c)).collect();
        let dist = SphereDistribution::new(width, height, &lum);
        // Mean radiance: texel values weighted by their rows' solid angles.
        let mut sum = glam::DVec3::ZERO;
        for y in 0..height {
            let (c0, c1) = (
                (PI * y as f32 / height as f32).cos(),
                (PI * (y + 1) as f32 / height as f32).cos(),
            );
            let omega = f64::from(c0 - c1) * 2.0 * std::f64::consts::PI / f64::from(width);
            let row = &out[(y * width) as usize..((y + 1) * width) as usize];
            for t in row {
                sum += t.as_dvec3() * omega;
            }
        }
        let mean = (sum / (4.0 * std::f64::consts::PI)).as_vec3();
        Ok(EnvMap {
            width,
            height,
            texels: out,
            to_world,
            to_local: to_world.transpose(),
            dist,
            mean,
            source: String::new(),
            scale,
            rotate,
        })
    }

    /// The same map, labelled with the file it came from (as the scene names it).
    pub fn with_source(mut self, source: &str) -> Self {
        self.source = source.to_owned();
        self
    }

    /// The same map sampled uniformly over the sphere (density 1/4π): the baseline that
    /// importance sampling is measured against.
    pub fn with_uniform_sampling(mut self) -> Self {
        let ones = vec![1.0f32; self.texels.len()];
        self.dist = SphereDistribution::new(self.width, self.height, &ones);
        self
    }

    /// How the map is sampled, for `prism info`.
    pub fn sampling(&self) -> String {
        format!(
            "luminance × solid angle over {}×{} cells (each the maximum of its 2×2 corner texels)",
            self.width,
            self.height + 1
        )
    }

    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Mean radiance over the sphere, linear RGB.
    pub fn mean(&self) -> Vec3 {
        self.mean
    }

    /// Whether any direction receives light (a black map lights nothing and is not sampled).
    pub fn emits(&self) -> bool {
        self.dist.total > 0.0
    }

    /// The map coordinates (u, v) ∈ [0, 1]² of world direction `d` (unit length).
    #[inline]
    pub fn uv_of(&self, d: Vec3) -> Vec2 {
        uv_of_local(self.to_local * d)
    }

    /// The world direction of map coordinates `uv`.
    #[inline]
    pub fn direction_of(&self, uv: Vec2) -> Vec3 {
        self.to_world * local_of_uv(uv)
    }

    /// Radiance arriving from world direction `d` (unit length): the bilinear blend of the
    /// four texels around it (columns wrap, rows clamp at the poles).
    #[inline]
    pub fn eval(&self, d: Vec3) -> Vec3 {
        let uv = self.uv_of(d);
        self.lookup(uv)
    }

    #[inline]
    fn lookup(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (fx, fy) = (x - xf, y - yf);
        let x0 = (xf as i64).rem_euclid(w);
        let x1 = (x0 + 1) % w;
        let y0 = (yf as i64).clamp(0, h - 1);
        let y1 = (yf as i64 + 1).clamp(0, h - 1);
        let t = |x: i64, y: i64| self.texels[(y * w + x) as usize];
        let top = t(x0, y0) * (1.0 - fx) + t(x1, y0) * fx;
        let bottom = t(x0, y1) * (1.0 - fx) + t(x1, y1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Solid-angle density with which [`EnvMap::sample`] draws world direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.dist.pdf(self.uv_of(d))
    }

    /// A direction drawn from `u` ∈ [0, 1)²: (direction, radiance along it, solid-angle
    /// density). `None` when the map is black, or the draw lands on a direction of zero
    /// radiance (only possible where the corner maximum is above zero but the blend is not).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let (uv, pdf) = self.dist.sample(u)?;
        let d = self.direction_of(uv);
        let l = self.lookup(uv);
        (pdf > 0.0 && l != Vec3::ZERO).then_some((d, l, pdf))
    }
}

impl std::fmt::Display for EnvMap {
    /// The scene syntax: `Image(path: "…", scale: s, rotate: (x, y, z))`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = self.rotate;
        write!(
            f,
            "Image(path: {:?}, scale: {}, rotate: ({}, {}, {}))",
            self.source, self.scale, r.x, r.y, r.z
        )
    }
}

/// (u, v) of a map-space unit direction.
#[inline]
pub fn uv_of_local(d: Vec3) -> Vec2 {
    let u = 0.5 + d.x.atan2(-d.z) * (0.5 / PI);
    let v = d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI);
    // atan2 returns π for −0.0 as well as 0.0: keep u in [0, 1).
    Vec2::new(if u >= 1.0 { u - 1.0 } else { u }, v)
}

/// Map-space unit direction of (u, v).
#[inline]
pub fn local_of_uv(uv: Vec2) -> Vec3 {
    let (sin_t, cos_t) = (PI * uv.y).sin_cos();
    let (sin_p, cos_p) = (2.0 * PI * (uv.x - 0.5)).sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

/// A piecewise-constant solid-angle density over the sphere on the cells whose corners are
/// the texel centres of a `width × height` latitude–longitude grid: `width` columns (cell j
/// spans u ∈ [(j + ½)/W, (j + 1½)/W), wrapping), `height + 1` rows (row i spans
/// v ∈ [(i − ½)/H, (i + ½)/H] clamped to [0, 1], so the first and last are half rows).
#[derive(Clone, Debug)]
pub struct SphereDistribution {
    width: u32,
    height: u32,
    /// Per cell, row-major: the largest luminance among its corners.
    max: Vec<f32>,
    /// cos θ at each row edge, `height + 2` values from +1 down to −1.
    cos_edge: Vec<f32>,
    /// Cumulative row weights, `height + 2` values from 0 to 1.
    row_cdf: Vec<f32>,
    /// Per row, cumulative column weights, `width + 1` values from 0 to 1.
    col_cdf: Vec<f32>,
    /// Σ max × solid angle over every cell.
    total: f32,
}

impl SphereDistribution {
    /// The distribution of a `width × height` grid of luminances (row-major, top row first).
    pub fn new(width: u32, height: u32, lum: &[f32]) -> Self {
        let (w, h) = (width as usize, height as usize);
        let rows = h + 1;
        let mut max = vec![0.0f32; rows * w];
        for i in 0..rows {
            let (r0, r1) = (i.saturating_sub(1), i.min(h - 1));
            for j in 0..w {
                let j1 = (j + 1) % w;
                max[i * w + j] = lum[r0 * w + j]
                    .max(lum[r0 * w + j1])
                    .max(lum[r1 * w + j])
                    .max(lum[r1 * w + j1]);
            }
        }
        let cos_edge: Vec<f32> = (0..=rows)
            .map(|i| match i {
                0 => 1.0,
                i if i == rows => -1.0,
                i => (PI * (i as f32 - 0.5) / h as f32).cos(),
            })
            .collect();
        // Sums in f64: a 16k-wide row of small values would lose its tail in f32.
        let mut row_w = vec![0.0f64; rows];
        let mut col_cdf = vec![0.0f32; rows * (w + 1)];
        for i in 0..rows {
            let mut acc = 0.0f64;
            let cdf = &mut col_cdf[i * (w + 1)..(i + 1) * (w + 1)];
            for j in 0..w {
                acc += f64::from(max[i * w + j]);
                cdf[j + 1] = acc as f32;
            }
            if acc > 0.0 {
                for c in cdf.iter_mut() {
                    *c = (f64::from(*c) / acc) as f32;
                }
            }
            cdf[w] = 1.0;
            let omega =
                f64::from(cos_edge[i] - cos_edge[i + 1]) * 2.0 * std::f64::consts::PI / w as f64;
            row_w[i] = acc * omega;
        }
        let total: f64 = row_w.iter().sum();
        let mut row_cdf = vec![0.0f32; rows + 1];
        let mut acc = 0.0f64;
        for i in 0..rows {
            acc += row_w[i];
            row_cdf[i + 1] = if total > 0.0 {
                (acc / total) as f32
            } else {
                0.0
            };
        }
        row_cdf[rows] = 1.0;
        SphereDistribution {
            width,
            height,
            max,
            cos_edge,
            row_cdf,
            col_cdf,
            total: total as f32,
        }
    }

    /// The cell (row, column) holding map coordinates `uv`.
    #[inline]
    fn cell(&self, uv: Vec2) -> (usize, usize) {
        let (w, h) = (self.width as usize, self.height as usize);
        let i = ((uv.y * h as f32 + 0.5).floor().max(0.0) as usize).min(h);
        let s = uv.x * w as f32 - 0.5;
        let j = (s.floor() as i64).rem_euclid(w as i64) as usize;
        (i, j)
    }

    /// Solid-angle density at map coordinates `uv`.
    #[inline]
    pub fn pdf(&self, uv: Vec2) -> f32 {
        if self.total <= 0.0 {
            return 0.0;
        }
        let (i, j) = self.cell(uv);
        self.max[i * self.width as usize + j] / self.total
    }

    /// Map coordinates drawn from `u` ∈ [0, 1)², with their solid-angle density; `None` when
    /// every weight is zero.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        if self.total <= 0.0 {
            return None;
        }
        let w = self.width as usize;
        let (i, fy) = pick(&self.row_cdf, u.y);
        let (j, fx) = pick(&self.col_cdf[i * (w + 1)..(i + 1) * (w + 1)], u.x);
        // Uniform by solid angle within the cell: linear in cos θ and in φ.
        let cos_t = self.cos_edge[i] + (self.cos_edge[i + 1] - self.cos_edge[i]) * fy;
        let v = cos_t.clamp(-1.0, 1.0).acos() * (1.0 / PI);
        let mut uu = (j as f32 + fx + 0.5) / w as f32;
        if uu >= 1.0 {
            uu -= 1.0;
        }
        let pdf = self.max[i * w + j] / self.total;
        Some((Vec2::new(uu, v), pdf))
    }
}

/// The bin of a cumulative table `cdf` (first 0, last 1) that `u` falls in, skipping empty
/// bins, and where in the bin it falls, in [0, 1).
#[inline]
fn pick(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    // The last bin whose start is <= u; a zero-width bin is never chosen.
    let k = cdf[1..n].partition_point(|&c| c <= u);
    let (a, b) = (cdf[k], cdf[k + 1]);
    let f = if b > a {
        ((u - a) / (b - a)).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
    } else {
        0.0
    };
    (k, f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_round_trip() {
        for &(u, v) in &[(0.5, 0.5), (0.75, 0.25), (0.1, 0.9), (0.999, 0.01)] {
            let d = local_of_uv(Vec2::new(u, v));
            let back = uv_of_local(d);
            assert!(
                (back.x - u).abs() < 1e-5 && (back.y - v).abs() < 1e-5,
                "{u} {v} {back}"
            );
        }
        // The centre column faces −z, three quarters faces +x, the top row +y.
        assert!(local_of_uv(Vec2::new(0.5, 0.5)).abs_diff_eq(Vec3::NEG_Z, 1e-6));
        assert!(local_of_uv(Vec2::new(0.75, 0.5)).abs_diff_eq(Vec3::X, 1e-6));
        assert!(local_of_uv(Vec2::new(0.3, 0.0)).abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn pick_skips_empty_bins() {
        let cdf = [0.0, 0.0, 0.5, 0.5, 1.0];
        assert_eq!(pick(&cdf, 0.0).0, 1);
        assert_eq!(pick(&cdf, 0.49).0, 1);
        assert_eq!(pick(&cdf, 0.5).0, 3);
        assert_eq!(pick(&cdf, 0.999).0, 3);
    }

    #[test]
    fn bilinear_lookup_wraps_and_clamps() {
        // Two columns: 0 and 1. Halfway between texel centres is the mean; at u = 0 (the
        // seam) the blend wraps.
        let m = EnvMap::new(2, 1, &[[0.0; 3], [1.0; 3]], 1.0, Vec3::ZERO).unwrap();
        assert!((m.lookup(Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((m.lookup(Vec2::new(0.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((m.lookup(Vec2::new(0.75, 0.0)).x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn refuses_non_finite_texels() {
        let e = EnvMap::new(2, 1, &[[0.0; 3], [f32::NAN, 0.0, 0.0]], 1.0, Vec3::ZERO);
        assert_eq!(e.unwrap_err(), EnvMapError::NotFinite { x: 1, y: 0 });
    }
}
