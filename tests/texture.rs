//! Textures: filtered lookups and wrap modes, colour decoding of loaded files, normal maps and
//! tangent frames, procedural patterns, and the image cache.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::ImageEncoder;
use prism::film::{ImageMeta, PngOptions, write_image};
use prism::scene_file::schema::TextureSpec;
use prism::texture::{
    AlbedoTexture, Bricks, Checker, ColorSpace, NormalMap, TexImage, Texture, TextureCache,
    TextureError, Wood, Wrap, perturb, tangent_frame,
};

const WRAPS: [Wrap; 3] = [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror];

/// A 4×2 image whose texels are all distinct, in exactly representable values.
fn grid() -> TexImage {
    let pixels = (0..8)
        .map(|i| {
            [
                i as f32 * 0.125,
                1.0 - i as f32 * 0.0625,
                (i % 3) as f32 * 0.25,
            ]
        })
        .collect();
    TexImage::from_pixels(4, 2, pixels)
}

/// Centre of texel (x, y), y counted from the top row of the file.
fn centre(img: &TexImage, x: u32, y: u32) -> Vec2 {
    Vec2::new(
        (x as f32 + 0.5) / img.width() as f32,
        1.0 - (y as f32 + 0.5) / img.height() as f32,
    )
}

fn write_png_rgb8(path: &Path, w: u32, h: u32, raw: &[u8]) {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(raw, w, h, image::ExtendedColorType::Rgb8)
        .unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// IEC 61966-2-1 decoding, written out independently of the crate's own.
fn srgb_reference(e: f64) -> f64 {
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// Small deterministic generator (SplitMix64) so the random tests are reproducible.
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }
    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.next_f32(), self.next_f32(), self.next_f32()) * 2.0 - Vec3::ONE
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec3();
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

#[test]
fn texel_centres_return_exact_texels() {
    let img = grid();
    for wrap in WRAPS {
        for y in 0..2 {
            for x in 0..4 {
                assert_eq!(
                    img.bilinear(centre(&img, x, y), wrap),
                    img.pixel(x, y),
                    "{wrap:?} ({x}, {y})"
                );
            }
        }
    }
    // A size that is not a power of two: exact up to rounding of the centre coordinate.
    let odd = TexImage::from_pixels(3, 3, (0..9).map(|i| [i as f32, 0.0, 1.0]).collect());
    for y in 0..3 {
        for x in 0..3 {
            let got = odd.bilinear(centre(&odd, x, y), Wrap::Clamp);
            assert!(
                (got - odd.pixel(x, y)).abs().max_element() < 1e-5,
                "({x}, {y}) {got}"
            );
        }
    }
}

#[test]
fn bilinear_midpoints_are_neighbour_means() {
    let img = grid();
    let p = |x, y| img.pixel(x, y);
    for wrap in WRAPS {
        // Between horizontal neighbours, on the texel row centres.
        for y in 0..2 {
            for x in 0..3 {
                let uv = (centre(&img, x, y) + centre(&img, x + 1, y)) * 0.5;
                let want = (p(x, y) + p(x + 1, y)) * 0.5;
                assert!((img.bilinear(uv, wrap) - want).abs().max_element() < 1e-6);
            }
        }
        // Between the two rows, and at the centre of a 2×2 block.
        for x in 0..4 {
            let uv = Vec2::new(centre(&img, x, 0).x, 0.5);
            let want = (p(x, 0) + p(x, 1)) * 0.5;
            assert!((img.bilinear(uv, wrap) - want).abs().max_element() < 1e-6);
        }
        let uv = Vec2::new(0.5, 0.5);
        let want = (p(1, 0) + p(2, 0) + p(1, 1) + p(2, 1)) * 0.25;
        assert!((img.bilinear(uv, wrap) - want).abs().max_element() < 1e-6);
    }
}

#[test]
fn wrap_modes_at_the_edges() {
    const EPS: f32 = 1e-4;
    // Along u: a 4×1 row; along v: a 1×4 column whose file's top row is v ≈ 1.
    let row = TexImage::from_pixels(4, 1, (0..4).map(|i| [i as f32 * 0.25, 0.0, 0.0]).collect());
    let col = TexImage::from_pixels(1, 4, (0..4).map(|i| [0.0, i as f32 * 0.25, 0.0]).collect());
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() <= 1e-3;
    for (img, along_u) in [(&row, true), (&col, false)] {
        // Texels from the start of the axis: u = 0 is column 0, v = 0 the bottom file row.
        let first = if along_u {
            img.pixel(0, 0)
        } else {
            img.pixel(0, 3)
        };
        let last = if along_u {
            img.pixel(3, 0)
        } else {
            img.pixel(0, 0)
        };
        let at = |t: f32, wrap| {
            let uv = if along_u {
                Vec2::new(t, 0.5)
            } else {
                Vec2::new(0.5, t)
            };
            img.bilinear(uv, wrap)
        };
        let seam = (first + last) * 0.5;
        for t in [-EPS, 0.0, 1.0, 1.0 + EPS] {
            assert!(close(at(t, Wrap::Repeat), seam), "repeat {t} {along_u}");
        }
        for (t, want) in [(-EPS, first), (0.0, first), (1.0, last), (1.0 + EPS, last)] {
            assert_eq!(at(t, Wrap::Clamp), want, "clamp {t} {along_u}");
            assert_eq!(at(t, Wrap::Mirror), want, "mirror {t} {along_u}");
        }
        // Far outside: clamp holds the edge, repeat and mirror keep their periods.
        assert_eq!(at(-7.3, Wrap::Clamp), first);
        assert_eq!(at(9.9, Wrap::Clamp), last);
        assert!(close(at(2.375, Wrap::Repeat), at(0.375, Wrap::Repeat)));
        assert!(close(at(1.375, Wrap::Mirror), at(0.625, Wrap::Mirror)));
        assert!(close(at(-0.375, Wrap::Mirror), at(0.375, Wrap::Mirror)));
    }
}

#[test]
fn non_finite_and_huge_uv_give_finite_output() {
    let img = Arc::new(grid());
    let albedos = [
        AlbedoTexture::Image {
            image: img.clone(),
            wrap: Wrap::Repeat,
        },
        AlbedoTexture::Image {
            image: img.clone(),
            wrap: Wrap::Clamp,
        },
        AlbedoTexture::Image {
            image: img.clone(),
            wrap: Wrap::Mirror,
        },
        AlbedoTexture::Checker(Checker {
            a: Vec3::ONE,
            b: Vec3::ZERO,
            size: 0.1,
        }),
        AlbedoTexture::Bricks(bricks()),
        AlbedoTexture::Wood(wood()),
    ];
    let normals = [
        NormalMap::Image {
            image: img,
            flip_y: true,
            wrap: Wrap::Mirror,
        },
        NormalMap::FromHeight { strength: 1e30 },
        NormalMap::FromHeight { strength: -3.0 },
    ];
    let bad = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MAX,
        f32::MIN,
        1e30,
        -1e-45,
        0.0,
    ];
    for &u in &bad {
        for &v in &bad {
            let uv = Vec2::new(u, v);
            for a in &albedos {
                assert!(a.eval(uv).is_finite(), "{a:?} {uv}");
                assert!(a.height(uv).is_finite(), "{a:?} {uv}");
                for n in &normals {
                    for duv in [0.0, -1.0, f32::NAN, 1e-3] {
                        let t = n.tangent_normal(uv, a, duv);
                        assert!(
                            t.is_finite() && (t.length() - 1.0).abs() < 1e-5,
                            "{n:?} {uv}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn loaded_8bit_png_is_srgb_decoded_or_kept_linear() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ramp.png");
    // Every 8-bit code once: 16×16 grey ramp, code = y·16 + x (top row first).
    let raw: Vec<u8> = (0..=255u8).flat_map(|c| [c, c, 255 - c]).collect();
    write_png_rgb8(&path, 16, 16, &raw);
    let srgb = TexImage::load(&path, ColorSpace::Srgb).unwrap();
    let linear = TexImage::load(&path, ColorSpace::Linear).unwrap();
    assert_eq!((srgb.width(), srgb.height()), (16, 16));
    for code in 0..=255u32 {
        let (x, y) = (code % 16, code / 16);
        let e = code as f64 / 255.0;
        let want = srgb_reference(e) as f32;
        let want_b = srgb_reference(1.0 - e) as f32;
        let got = srgb.pixel(x, y);
        assert!(
            (got.x - want).abs() <= 1e-6 && (got.y - want).abs() <= 1e-6,
            "{code}: {got}"
        );
        assert!((got.z - want_b).abs() <= 1e-6, "{code}: {got}");
        let got = linear.pixel(x, y);
        assert!((got.x - e as f32).abs() <= 1e-7, "{code}: {got}");
        // Lookups at texel centres see the same decoded values.
        assert_eq!(
            srgb.bilinear(centre(&srgb, x, y), Wrap::Clamp),
            srgb.pixel(x, y)
        );
    }
}

#[test]
fn loaded_16bit_png_is_srgb_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("deep.png");
    let codes = [0u16, 1000, 2651, 30000, 65535];
    let raw: Vec<u8> = codes
        .iter()
        .flat_map(|c| c.to_ne_bytes().repeat(3))
        .collect();
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&raw, codes.len() as u32, 1, image::ExtendedColorType::Rgb16)
        .unwrap();
    std::fs::write(&path, bytes).unwrap();
    let img = TexImage::load(&path, ColorSpace::Srgb).unwrap();
    for (x, &c) in codes.iter().enumerate() {
        let want = srgb_reference(c as f64 / 65535.0) as f32;
        assert!((img.pixel(x as u32, 0).x - want).abs() <= 1e-6, "{c}");
    }
}

#[test]
fn float_sources_are_linear_in_either_space() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("t.exr");
    let film = prism::film::Image {
        width: 2,
        height: 1,
        pixels: vec![[2.0, 0.5, 0.25], [0.0, 7.5, 0.125]],
    };
    let meta = ImageMeta {
        spp: 1,
        sample_offset: 0,
        scene_hash: 0,
        simd: None,
        complete: true,
        settings: None,
    };
    write_image(&exr, &film, &meta, &PngOptions::default()).unwrap();
    let hdr = dir.path().join("t.hdr");
    let mut bytes = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut bytes)
        .encode(&[image::Rgb([2.0f32, 0.5, 0.25]); 2], 2, 1)
        .unwrap();
    std::fs::write(&hdr, bytes).unwrap();
    for space in [ColorSpace::Srgb, ColorSpace::Linear] {
        let img = TexImage::load(&exr, space).unwrap();
        assert_eq!(img.pixel(0, 0), Vec3::new(2.0, 0.5, 0.25));
        assert_eq!(img.pixel(1, 0), Vec3::new(0.0, 7.5, 0.125));
        // Powers of two are exact in RGBE.
        let img = TexImage::load(&hdr, space).unwrap();
        assert_eq!(img.pixel(1, 0), Vec3::new(2.0, 0.5, 0.25));
    }
}

#[test]
fn flat_normal_map_leaves_the_shading_normal_alone() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flat_n.png");
    write_png_rgb8(&path, 4, 4, &[128, 128, 255].repeat(16));
    let mut cache = TextureCache::new();
    let image = cache.get(&path, ColorSpace::Linear).unwrap();
    let bound = 1.0 / 255.0 + 1e-6;
    let dummy = AlbedoTexture::Checker(Checker {
        a: Vec3::ONE,
        b: Vec3::ONE,
        size: 1.0,
    });
    let mut rng = Rng(7);
    for flip_y in [false, true] {
        let map = NormalMap::Image {
            image: image.clone(),
            flip_y,
            wrap: Wrap::Repeat,
        };
        for i in 0..200 {
            let uv = Vec2::new(rng.next_f32(), rng.next_f32()) * 3.0 - Vec2::ONE;
            let tn = map.tangent_normal(uv, &dummy, 0.0);
            assert!((tn - Vec3::Z).abs().max_element() <= bound, "{tn}");
            // The frame is orthonormal, so the world normal is exactly as far from ns as the
            // tangent normal is from +z: within 1/255 on each tangent axis, √2/255 in all.
            let off = (tn - Vec3::Z).length();
            assert!(off <= std::f32::consts::SQRT_2 * bound, "{tn}");
            let ns = rng.unit();
            let (dpdu, dpdv) = (rng.vec3() * 4.0, rng.vec3() * 0.1);
            let n = perturb(ns, dpdu, dpdv, tn);
            assert!((n - ns).length() <= off + 1e-6, "{i}: {n} vs {ns}");
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
    }
    // Read as sRGB the same file would tilt every normal far beyond that bound.
    let wrong = TexImage::load(&path, ColorSpace::Srgb).unwrap();
    let c = wrong.pixel(0, 0) * 2.0 - Vec3::ONE;
    assert!((c.normalize() - Vec3::Z).length() > 0.5);
}

#[test]
fn normal_map_follows_opengl_green_up() {
    // Encoded (0.5, 1.0, 0.5) would be +y; (0.5, 0.75, ~0.933) is a 30° tilt towards +v.
    let tilt = [0.5, 0.75, 0.5 + 0.5 * 0.866_025_4];
    let image = Arc::new(TexImage::from_pixels(1, 1, vec![tilt]));
    let dummy = AlbedoTexture::Checker(Checker {
        a: Vec3::ONE,
        b: Vec3::ONE,
        size: 1.0,
    });
    for (flip_y, sign) in [(false, 1.0), (true, -1.0)] {
        let map = NormalMap::Image {
            image: image.clone(),
            flip_y,
            wrap: Wrap::Clamp,
        };
        let tn = map.tangent_normal(Vec2::splat(0.5), &dummy, 0.0);
        // A surface in the xz plane facing +y with u along +x and v along −z.
        let n = perturb(Vec3::Y, Vec3::X, -Vec3::Z, tn);
        assert!(
            (n - Vec3::new(0.0, 0.866_025_4, -0.5 * sign)).length() < 1e-5,
            "{n}"
        );
    }
}

#[test]
fn tangent_frames_are_orthonormal_for_random_and_degenerate_inputs() {
    let mut rng = Rng(42);
    let check = |ns: Vec3, dpdu: Vec3, dpdv: Vec3| {
        let n = ns.normalize();
        let (t, b) = tangent_frame(ns, dpdu, dpdv);
        let msg = format!("ns {ns} dpdu {dpdu} dpdv {dpdv} -> t {t} b {b}");
        assert!(t.is_finite() && b.is_finite(), "{msg}");
        assert!((t.length() - 1.0).abs() < 1e-5, "{msg}");
        assert!((b.length() - 1.0).abs() < 1e-5, "{msg}");
        assert!(t.dot(b).abs() < 1e-5, "{msg}");
        assert!(t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5, "{msg}");
        assert!((t.cross(b).dot(n).abs() - 1.0).abs() < 1e-5, "{msg}");
        // A usable dpdu fixes the tangent direction, whatever its magnitude.
        let m = dpdu.abs().max_element();
        if m.is_finite() && m > 0.0 {
            let d = dpdu / m;
            let perp = d - n * n.dot(d);
            if perp.length() > 1e-3 * d.length() {
                assert!(t.dot(perp.normalize()) > 1.0 - 1e-4, "{msg}");
            }
        }
        let p = perturb(ns, dpdu, dpdv, tilt_for(dpdu));
        assert!((p.length() - 1.0).abs() < 1e-5, "{msg}");
    };
    for _ in 0..5000 {
        let ns = rng.unit();
        check(ns, rng.vec3() * 10.0, rng.vec3());
    }
    // Degenerate dpdu: zero, along ±ns, nearly along ns, tiny, huge, non-finite; with and
    // without a usable dpdv.
    for _ in 0..500 {
        let ns = rng.unit();
        let dpdv = rng.vec3();
        let degenerate = [
            Vec3::ZERO,
            ns * 3.0,
            -ns,
            ns + rng.vec3() * 1e-7,
            rng.vec3() * 1e-30,
            rng.vec3() * 1e30,
            Vec3::NAN,
            Vec3::new(f32::INFINITY, 0.0, 0.0),
        ];
        for dpdu in degenerate {
            check(ns, dpdu, dpdv);
            check(ns, dpdu, Vec3::ZERO);
            check(ns, dpdu, ns);
        }
    }
    // Normals along the axes (the fallback frame's branch points).
    for ns in [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y] {
        check(ns, Vec3::ZERO, Vec3::ZERO);
    }
}

/// A fixed tilted tangent normal (varied by input so the check is not trivially +z).
fn tilt_for(seed: Vec3) -> Vec3 {
    let s = if seed.x.is_finite() {
        seed.x.sin()
    } else {
        0.3
    };
    Vec3::new(s * 0.5, 0.4, 0.7).normalize()
}

#[test]
fn checker_alternates() {
    let c = Checker {
        a: Vec3::new(0.9, 0.8, 0.7),
        b: Vec3::new(0.1, 0.2, 0.3),
        size: 0.1,
    };
    for j in -12i32..12 {
        for i in -12..12 {
            let uv = (Vec2::new(i as f32, j as f32) + Vec2::splat(0.5)) * 0.1;
            let want = if (i + j).rem_euclid(2) == 0 { c.a } else { c.b };
            assert_eq!(c.eval(uv), want, "({i}, {j})");
        }
    }
    // Neighbours across each edge differ.
    let p = Vec2::new(0.35, 0.45);
    assert_ne!(c.eval(p), c.eval(p + Vec2::new(0.1, 0.0)));
    assert_ne!(c.eval(p), c.eval(p + Vec2::new(0.0, 0.1)));
    assert_eq!(c.eval(p), c.eval(p + Vec2::new(0.1, 0.1)));
}

fn bricks() -> Bricks {
    Bricks {
        brick: Vec3::new(0.5, 0.15, 0.1),
        mortar: Vec3::new(0.8, 0.8, 0.75),
        size: Vec2::new(0.4, 0.2),
        joint: 0.02,
    }
}

fn wood() -> Wood {
    Wood {
        light: Vec3::new(0.75, 0.52, 0.3),
        dark: Vec3::new(0.45, 0.25, 0.12),
        rings: 8.0,
        noise: 0.5,
    }
}

#[test]
fn bricks_have_mortar_where_expected_and_below_the_bricks() {
    let b = bricks();
    // Even rows (v in [0, 0.2)): vertical joints at u = 0, 0.4, …; odd rows shifted by 0.2.
    let mortar = [
        (0.0, 0.1),
        (0.4, 0.1),
        (-0.4, 0.05),
        (0.2, 0.3),
        (0.6, 0.35),
        (0.2, 0.0),
        (0.13, 0.2),
        (0.31, 0.4),
        (0.1, 0.2 + 0.009),
        (0.009, 0.1),
    ];
    let brick = [
        (0.2, 0.1),
        (0.0, 0.3),
        (0.4, 0.3),
        (0.6, 0.1),
        (0.0, 0.3 - 0.08),
        (0.02, 0.1),
        (0.1, 0.2 + 0.011),
    ];
    for (u, v) in mortar {
        let uv = Vec2::new(u, v);
        assert!(b.is_mortar(uv), "{uv}");
        assert_eq!(b.eval(uv), b.mortar, "{uv}");
    }
    for (u, v) in brick {
        let uv = Vec2::new(u, v);
        assert!(!b.is_mortar(uv), "{uv}");
        assert_eq!(b.eval(uv), b.brick, "{uv}");
    }
    // Heights: joint centres lowest, brick faces highest.
    let brick_h = b.height(Vec2::new(0.2, 0.1));
    let mortar_h = b.height(Vec2::new(0.0, 0.1));
    assert_eq!(brick_h, 0.0);
    assert!(mortar_h < brick_h - 0.005, "{mortar_h}");
    for (u, v) in mortar {
        assert!(b.height(Vec2::new(u, v)) <= mortar_h + 1e-6);
    }
    // Mortar covers 1 − (w − j)(h − j)/(w h) of the wall.
    let n = 400;
    let hits = (0..n * n)
        .filter(|i| {
            let uv = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) / n as f32 * 0.8;
            b.is_mortar(uv)
        })
        .count();
    let want = 1.0 - (0.38 * 0.18) / (0.4 * 0.2);
    let got = hits as f32 / (n * n) as f32;
    assert!((got - want).abs() < 0.01, "{got} vs {want}");
}

#[test]
fn from_height_on_flat_height_is_exactly_up() {
    let flat = AlbedoTexture::Checker(Checker {
        a: Vec3::ONE,
        b: Vec3::ZERO,
        size: 0.1,
    });
    for strength in [1.0, 25.0, -3.0, 0.0] {
        let map = NormalMap::FromHeight { strength };
        for uv in [Vec2::ZERO, Vec2::new(0.05, 0.1), Vec2::new(0.37, -2.0)] {
            for duv in [1e-3, 0.01, 0.0] {
                let n = map.tangent_normal(uv, &flat, duv);
                assert_eq!(
                    n.to_array().map(f32::to_bits),
                    Vec3::Z.to_array().map(f32::to_bits)
                );
            }
        }
    }
    // Inside a brick face, away from the bevel, the bricks are flat too.
    let b = AlbedoTexture::Bricks(bricks());
    let n = NormalMap::FromHeight { strength: 1.0 }.tangent_normal(Vec2::new(0.2, 0.1), &b, 1e-3);
    assert_eq!(n, Vec3::Z);
}

#[test]
fn brick_bevels_tilt_towards_the_joint() {
    let b = AlbedoTexture::Bricks(bricks());
    let map = NormalMap::FromHeight { strength: 1.0 };
    // Just right of the joint at u = 0.4 the face rises with u, so the normal leans to −u;
    // just above the joint at v = 0.2 it leans to −v.
    let right = map.tangent_normal(Vec2::new(0.4 + 0.015, 0.1), &b, 1e-3);
    assert!(right.x < -0.1 && right.y.abs() < 1e-6, "{right}");
    let left = map.tangent_normal(Vec2::new(0.4 - 0.015, 0.1), &b, 1e-3);
    assert!(left.x > 0.1, "{left}");
    let above = map.tangent_normal(Vec2::new(0.1, 0.2 + 0.015), &b, 1e-3);
    assert!(above.y < -0.1 && above.x.abs() < 1e-6, "{above}");
    // Negative strength inverts the relief.
    let inv =
        NormalMap::FromHeight { strength: -1.0 }.tangent_normal(Vec2::new(0.415, 0.1), &b, 1e-3);
    assert!((inv.x + right.x).abs() < 1e-6);
}

#[test]
fn wood_mixes_its_two_colours_with_ridged_latewood() {
    let w = wood();
    let mut lightest = f32::MAX;
    let mut darkest = f32::MIN;
    for i in 0..2000 {
        let uv = Vec2::new(0.37, i as f32 / 2000.0);
        let t = w.latewood(uv);
        let c = w.eval(uv);
        assert!((c - w.light.lerp(w.dark, t)).abs().max_element() < 1e-6);
        // Dark latewood stands proud of the light earlywood.
        assert!((w.height(uv) - t * 0.05 / 8.0).abs() < 1e-7);
        lightest = lightest.min(t);
        darkest = darkest.max(t);
    }
    assert!(lightest < 0.01 && darkest > 0.95, "{lightest} {darkest}");
}

#[test]
fn texture_applies_scale_and_offset_before_lookup() {
    let img = Arc::new(grid());
    let t = Texture {
        albedo: Some(AlbedoTexture::Image {
            image: img.clone(),
            wrap: Wrap::Repeat,
        }),
        normal_map: None,
        roughness: None,
        scale: Vec2::new(2.0, 1.0),
        offset: Vec2::new(0.125, 0.0),
    };
    // uv' = (0.5·2 + 0.125, 0.75) = (1.125, 0.75): texel 0 of the top row, second tile.
    assert_eq!(t.albedo(Vec2::new(0.5, 0.75)), Some(img.pixel(0, 0)));
}

#[test]
fn cache_shares_images_and_separates_colour_spaces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    write_png_rgb8(&path, 2, 1, &[10, 20, 30, 200, 210, 220]);
    let mut cache = TextureCache::new();
    let a = cache.get(&path, ColorSpace::Srgb).unwrap();
    let b = cache.get(&path, ColorSpace::Srgb).unwrap();
    assert!(Arc::ptr_eq(&a, &b));
    // Another spelling of the same file.
    let other: PathBuf = dir.path().join(".").join("a.png");
    assert!(Arc::ptr_eq(
        &a,
        &cache.get(&other, ColorSpace::Srgb).unwrap()
    ));
    let lin = cache.get(&path, ColorSpace::Linear).unwrap();
    assert!(!Arc::ptr_eq(&a, &lin));
    assert_eq!(cache.len(), 2);
    assert!((lin.pixel(0, 0).x - 10.0 / 255.0).abs() < 1e-7);

    // Many entities built from specs share the one image.
    let spec: TextureSpec = prism::scene_file::load::ron_options()
        .from_str(r#"(albedo: Image(path: "a.png", wrap: Mirror))"#)
        .unwrap();
    for _ in 0..3 {
        let built = spec.build(dir.path(), &mut cache).unwrap();
        let Some(AlbedoTexture::Image { image, wrap }) = &built.albedo else {
            panic!("{built:?}")
        };
        assert!(Arc::ptr_eq(image, &a) && *wrap == Wrap::Mirror);
    }
    assert_eq!(cache.len(), 2);
}

#[test]
fn load_errors_name_the_file_and_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let mut cache = TextureCache::new();

    let missing = dir.path().join("missing.png");
    let err = cache.get(&missing, ColorSpace::Srgb).unwrap_err();
    assert!(matches!(err, TextureError::Missing { .. }), "{err:?}");
    assert_eq!(err.path(), missing);
    assert_eq!(
        err.to_string(),
        format!("texture '{}' not found", missing.display())
    );

    let tiff = dir.path().join("photo.tiff");
    std::fs::write(&tiff, b"II*\0").unwrap();
    let msg = cache.get(&tiff, ColorSpace::Srgb).unwrap_err().to_string();
    assert!(
        msg.contains("photo.tiff") && msg.contains("'.tiff'") && msg.contains(".png"),
        "{msg}"
    );

    let corrupt = dir.path().join("corrupt.png");
    std::fs::write(&corrupt, b"definitely not a png").unwrap();
    let err = cache.get(&corrupt, ColorSpace::Linear).unwrap_err();
    assert!(matches!(err, TextureError::Decode { .. }), "{err:?}");
    assert!(
        err.to_string().starts_with("cannot decode texture '")
            && err.to_string().contains("corrupt.png")
    );

    let bad_exr = dir.path().join("bad.exr");
    std::fs::write(&bad_exr, b"nope").unwrap();
    let msg = cache
        .get(&bad_exr, ColorSpace::Srgb)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("cannot decode texture '") && msg.contains("bad.exr"),
        "{msg}"
    );

    let missing_exr = dir.path().join("gone.exr");
    let err = cache.get(&missing_exr, ColorSpace::Srgb).unwrap_err();
    assert!(matches!(err, TextureError::Missing { .. }), "{err:?}");

    // A directory with an image's name cannot be read.
    let as_dir = dir.path().join("dir.png");
    std::fs::create_dir(&as_dir).unwrap();
    let msg = cache
        .get(&as_dir, ColorSpace::Srgb)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("cannot read texture '") && msg.contains("dir.png"),
        "{msg}"
    );
    assert!(cache.is_empty());
}
