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

/// One tile's sums of sample radiance, in f64 so that thousands of samples add without loss.
pub struct TileFilm {
    /// The part of the image this film covers.
    pub tile: Tile,
    /// The image's width: samples name their pixel by `y * width + x`.
    width: u32,
    /// Per pixel of the tile, row-major.
    pub sums: Vec<[f64; 3]>,
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
            samples: 0,
            dropped: 0,
        }
    }

    /// Adds one sample's radiance to image pixel `pixel` (which lies in the tile), or drops it
    /// if it is not finite: one bad path must not poison a pixel.
    #[inline]
    pub fn add(&mut self, pixel: u32, l: Vec3) {
        if !l.is_finite() {
            self.dropped += 1;
            return;
        }
        self.samples += 1;
        let t = &self.tile;
        let (x, y) = (pixel % self.width, pixel / self.width);
        let px = &mut self.sums[((y - t.y0) * t.w + (x - t.x0)) as usize];
        px[0] += l.x as f64;
        px[1] += l.y as f64;
        px[2] += l.z as f64;
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
}

impl Film {
    /// An empty film of `width` × `height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    /// Adds a tile's sums into the image.
    pub fn add_tile(&mut self, t: &TileFilm) {
        for (p, src) in t.sums.iter().enumerate() {
            let (x, y) = t.tile.pixel(p);
            let dst = &mut self.sums[(y * self.width + x) as usize];
            for c in 0..3 {
                dst[c] += src[c];
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
