//! Accumulation: the image is split into tiles, each rendered into a film of its own by one
//! worker (tiles never share pixels, so workers need no locks and the sum does not depend on
//! which thread rendered which tile), then added into the image's sums in tile order.

use super::Image;
use glam::Vec3;

/// Square tiles of this many pixels a side: the unit of parallel work.
pub const TILE: u32 = 16;

/// A rectangle of the image, in pixels.
#[derive(Clone, Copy, Debug)]
pub struct Tile {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Width in pixels (at most [`TILE`]).
    pub w: u32,
    /// Height in pixels (at most [`TILE`]).
    pub h: u32,
}

impl Tile {
    /// Number of pixels in the tile.
    #[inline]
    pub fn pixels(&self) -> usize {
        (self.w * self.h) as usize
    }

    /// Image coordinates of the tile's `p`-th pixel (row-major).
    #[inline]
    pub fn pixel(&self, p: usize) -> (u32, u32) {
        let p = p as u32;
        (self.x0 + p % self.w, self.y0 + p / self.w)
    }
}

/// The tiles of a `width`×`height` image, row by row.
pub fn tiles(width: u32, height: u32) -> Vec<Tile> {
    let mut t = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            t.push(Tile {
                x0,
                y0,
                w: TILE.min(width - x0),
                h: TILE.min(height - y0),
            });
        }
    }
    t
}

/// The bit of a sample's pixel key that puts it in the second of two independent halves
/// (`crate::film::estimate`): pixel numbers stay below 2²⁸, so it is free, and the sampler
/// keys its scrambles by the whole key, so the two halves draw unrelated sequences.
pub const HALF_B: u32 = 1 << 31;

/// Which samples of a tile's pixels one pass renders: the tile's pixel `p` renders its
/// samples `j` in `first .. first + count`, pixel after pixel in the tile's order.
#[derive(Clone, Copy, Debug)]
pub struct TileWork<'a> {
    /// The sample index of every pixel's sample 0.
    pub offset: u32,
    /// `(first, count)` of every pixel, unless `per_pixel` is given.
    pub uniform: (u32, u32),
    /// `(first, count)` per tile pixel (row-major), for adaptive passes.
    pub per_pixel: Option<&'a [(u32, u32)]>,
    /// Samples alternate between two independent halves: sample `j` is index `offset + j/2`
    /// of half `j mod 2` (keyed with [`HALF_B`] when odd); otherwise it is index `offset + j`.
    pub split: bool,
}

impl TileWork<'_> {
    /// `(first, count)` of the tile's pixel `p`.
    #[inline]
    pub fn range(&self, p: usize) -> (u32, u32) {
        match self.per_pixel {
            Some(r) => r[p],
            None => self.uniform,
        }
    }

    /// The sample index and the half bit of a pixel's sample `j`.
    #[inline]
    pub fn index(&self, j: u32) -> (u32, u32) {
        if self.split {
            (self.offset + (j >> 1), (j & 1) << 31)
        } else {
            (self.offset + j, 0)
        }
    }

    /// Samples in the whole tile.
    pub fn total(&self, pixels: usize) -> u64 {
        match self.per_pixel {
            Some(r) => r.iter().map(|&(_, n)| u64::from(n)).sum(),
            None => pixels as u64 * u64::from(self.uniform.1),
        }
    }
}

/// One tile's sums of sample radiance, in f64 so that thousands of samples add without loss.
pub struct TileFilm {
    /// The part of the image this film covers.
    pub tile: Tile,
    /// The image's width: samples name their pixel by `y * width + x`.
    width: u32,
    /// Per pixel of the tile, row-major.
    pub sums: Vec<[f64; 3]>,
    /// Per pixel, the sums of the samples of half B alone (those keyed with [`HALF_B`]);
    /// empty unless the render estimates its error.
    pub half: Vec<[f64; 3]>,
    /// Samples added.
    pub samples: u64,
    /// Samples dropped because their radiance was not finite.
    pub dropped: u64,
}

impl TileFilm {
    /// An empty film for `tile` of an image `width` pixels wide.
    pub fn new(tile: Tile, width: u32) -> Self {
        TileFilm {
            tile,
            width,
            sums: vec![[0.0; 3]; tile.pixels()],
            half: Vec::new(),
            samples: 0,
            dropped: 0,
        }
    }

    /// An empty film that also keeps the sums of half B.
    pub fn with_halves(tile: Tile, width: u32) -> Self {
        let mut f = Self::new(tile, width);
        f.half = vec![[0.0; 3]; tile.pixels()];
        f
    }

    /// Adds one sample's radiance to image pixel `pixel` (which lies in the tile; with
    /// [`HALF_B`] set, to half B too), or drops it if it is not finite: one bad path must not
    /// poison a pixel.
    #[inline]
    pub fn add(&mut self, key: u32, l: Vec3) {
        if !l.is_finite() {
            self.dropped += 1;
            return;
        }
        self.samples += 1;
        let t = &self.tile;
        let pixel = key & !HALF_B;
        let (x, y) = (pixel % self.width, pixel / self.width);
        let i = ((y - t.y0) * t.w + (x - t.x0)) as usize;
        let l = [l.x as f64, l.y as f64, l.z as f64];
        let px = &mut self.sums[i];
        for c in 0..3 {
            px[c] += l[c];
        }
        if key & HALF_B != 0 {
            let h = &mut self.half[i];
            for c in 0..3 {
                h[c] += l[c];
            }
        }
    }
}

/// A whole image's sums of sample radiance.
pub struct Film {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Per pixel, row-major, top row first.
    pub sums: Vec<[f64; 3]>,
    /// Per pixel, the sums of half B (empty unless the render estimates its error).
    pub half: Vec<[f64; 3]>,
}

impl Film {
    /// An empty film of `width` × `height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; width as usize * height as usize],
            half: Vec::new(),
        }
    }

    /// An empty film that also keeps the sums of half B.
    pub fn with_halves(width: u32, height: u32) -> Self {
        let mut f = Self::new(width, height);
        f.half = vec![[0.0; 3]; f.sums.len()];
        f
    }

    /// Adds a tile's sums (and those of its half B) into the image.
    pub fn add_tile(&mut self, t: &TileFilm) {
        for (p, src) in t.sums.iter().enumerate() {
            let (x, y) = t.tile.pixel(p);
            let i = (y * self.width + x) as usize;
            for (d, s) in self.sums[i].iter_mut().zip(src) {
                *d += s;
            }
            if let Some(h) = t.half.get(p) {
                for (d, s) in self.half[i].iter_mut().zip(h) {
                    *d += s;
                }
            }
        }
    }
}

/// The image of `sums`: each pixel's sum divided by the sample count.
pub fn mean_image(width: u32, height: u32, sums: &[[f64; 3]], spp: u32) -> Image {
    let k = 1.0 / spp.max(1) as f64;
    Image {
        width,
        height,
        pixels: sums
            .iter()
            .map(|s| [(s[0] * k) as f32, (s[1] * k) as f32, (s[2] * k) as f32])
            .collect(),
    }
}
