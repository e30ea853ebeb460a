//! Dispersion: Snell's law per wavelength, and where `scenes/prism.ron` puts each colour.

use glam::Vec3;
use prism::integrator::{RenderOptions, render};
use prism::spectrum::{
    IorModel, IorPreset, SampledSpectrum, Wavelengths, to_xyz, xyz_to_linear_srgb,
};
use std::path::Path;

/// Renders `scene` with every path carrying the single wavelength `lambda` (a monochromatic
/// image of that wavelength's radiance): the renderer's own camera, shading and transport,
/// only the wavelength sample fixed. The film receives radiance L as the colour L·v with
/// v = rgb(λ); the projection on v recovers L.
fn monochromatic(scene: &prism::scene::RenderScene, lambda: f32) -> Vec<f32> {
    let mut opts = RenderOptions::new(scene.settings.spp, prism::simd::Lanes::auto());
    opts.monochromatic = Some(lambda);
    let img = render(scene, &opts, &|_| {}).image();
    let lam = Wavelengths {
        lambda: [lambda; 4],
        pdf: [1.0, 0.0, 0.0, 0.0],
    };
    let v = xyz_to_linear_srgb(to_xyz(&SampledSpectrum([1.0, 0.0, 0.0, 0.0]), &lam));
    assert!(v.length_squared() > 0.0);
    img.pixels
        .iter()
        .map(|p| Vec3::from(*p).dot(v) / v.length_squared())
        .collect()
}

/// The prism's cross-section (x, z) from the first three vertices of `assets/prism.obj`.
fn prism_triangle() -> [(f64, f64); 3] {
    let text = std::fs::read_to_string("assets/prism.obj").unwrap();
    let v: Vec<(f64, f64)> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .take(3)
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (c[0], c[2])
        })
        .collect();
    [v[0], v[1], v[2]]
}

/// Snell's law in vector form; `n` faces the incoming ray, `eta` = n₁/n₂.
fn refract2(d: (f64, f64), n: (f64, f64), eta: f64) -> Option<(f64, f64)> {
    let c = -(d.0 * n.0 + d.1 * n.1);
    let k = 1.0 - eta * eta * (1.0 - c * c);
    (k >= 0.0).then(|| {
        let t = eta * c - k.sqrt();
        (eta * d.0 + t * n.0, eta * d.1 + t * n.1)
    })
}

/// A point or direction in the xz plane.
type P2 = (f64, f64);

/// A ray in the xz plane through the prism by Snell's law at both faces (entering, then
/// leaving): the exit point and direction, or `None` if it misses a face or is totally
/// internally reflected.
fn through_prism(n: f64, mut o: P2, mut d: P2) -> Option<(P2, P2)> {
    let p = prism_triangle();
    let mut inside = false;
    for _ in 0..2 {
        let mut best: Option<(f64, P2, P2)> = None;
        for i in 0..3 {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            let e = (b.0 - a.0, b.1 - a.1);
            let len = e.0.hypot(e.1);
            let mut nn = (e.1 / len, -e.0 / len);
            if nn.0 * (a.0 + b.0) + nn.1 * (a.1 + b.1) < 0.0 {
                nn = (-nn.0, -nn.1); // outward: the centroid is near the origin
            }
            let den = d.0 * nn.0 + d.1 * nn.1;
            if den.abs() < 1e-12 {
                continue;
            }
            let t = ((a.0 - o.0) * nn.0 + (a.1 - o.1) * nn.1) / den;
            let q = (o.0 + t * d.0, o.1 + t * d.1);
            let s = ((q.0 - a.0) * e.0 + (q.1 - a.1) * e.1) / (len * len);
            if t > 1e-9 && (0.0..=1.0).contains(&s) && best.is_none_or(|b| t < b.0) {
                best = Some((t, q, nn));
            }
        }
        let (_, q, nn) = best?;
        d = if inside {
            refract2(d, (-nn.0, -nn.1), n)
        } else {
            refract2(d, nn, 1.0 / n)
        }?;
        let l = d.0.hypot(d.1);
        d = (d.0 / l, d.1 / l);
        o = q;
        inside = !inside;
    }
    Some((o, d))
}

#[test]
fn snell_per_wavelength_with_cauchy_and_sellmeier() {
    // Schott N-BK7: n_d = 1.5168 at the helium d line.
    let bk7 = IorPreset::Bk7.model();
    assert!(
        (bk7.eta(587.56) - 1.5168).abs() < 2e-4,
        "{}",
        bk7.eta(587.56)
    );
    // Refraction from air at 45° into BK7: sin θt = sin 45° / n(λ), bluer bends more.
    let cauchy = IorModel::Cauchy {
        a: 1.5046,
        b: 0.0042,
    };
    let wi = Vec3::new(45f32.to_radians().sin(), -45f32.to_radians().cos(), 0.0);
    let mut last = f32::INFINITY;
    for lambda in [400.0, 486.1, 587.6, 656.3, 700.0] {
        for m in [cauchy, bk7] {
            let n = m.eta(lambda);
            let wt = prism::integrator::bsdf::refract(-wi, Vec3::Y, n).unwrap();
            let theta_t = (-wt.y).acos();
            let expect = (45f32.to_radians().sin() / n).asin();
            assert!(
                (theta_t - expect).abs() < 1e-5,
                "{lambda} nm: {theta_t} vs {expect}"
            );
        }
        let theta = (45f32.to_radians().sin() / cauchy.eta(lambda)).asin();
        assert!(
            theta > last || last.is_infinite(),
            "refraction angle grows with λ"
        );
        last = theta;
    }
}

/// Slit plane and the slit's centre line in `scenes/prism.ron`.
const SLIT_X: f64 = -1.6;
const SLIT_Z: f64 = -0.13;

#[test]
fn prism_spreads_the_spectrum_in_order_at_the_predicted_places() {
    // Where the spectrum lands on the screen, seen from the screen: a pinhole camera at the
    // spot where the 550 nm central ray meets the screen, looking back into the prism. By
    // reciprocity each wavelength's light reaches that spot from the direction in which the
    // camera sees the slit through the prism at that wavelength; the camera's rays are
    // specular chains, so a monochromatic image converges in a few samples where the
    // screen's diffuse paths would need millions.
    let n550 = IorModel::Cauchy {
        a: 1.739,
        b: 0.0159,
    }
    .eta(550.0) as f64;
    let (x, d) = through_prism(n550, (-2.0, SLIT_Z), (1.0, 0.0)).unwrap();
    // The screen in prism.ron stands 0.55 beyond the exit point, square to this ray; stand
    // a centimetre in front of it.
    let eye = (x.0 + 0.54 * d.0, x.1 + 0.54 * d.1);
    let look = (x.0, x.1);
    let text = std::fs::read_to_string("scenes/prism.ron").unwrap();
    let cam_start = text.find("camera: (").unwrap();
    let cam_end = cam_start + text[cam_start..].find("),\n    entities").unwrap() + 3;
    let text = format!(
        "{}camera: (position: ({}, 0.4, {}), look_at: ({}, 0.4, {}), fov_y: 6.0),{}",
        &text[..cam_start],
        eye.0,
        eye.1,
        look.0,
        look.1,
        &text[cam_end..]
    )
    .replace(
        "render: (width: 480, height: 300, spp: 4096,",
        "render: (width: 320, height: 32, spp: 16,",
    );
    let loaded =
        prism::scene_file::load_str(&text, Path::new("scenes/prism.ron"), &[]).expect("parses");
    let scene = prism::systems::prepare(&loaded, &prism::kdtree::KdParams::default());
    let ior = loaded
        .world
        .query::<(&prism::components::Name, &prism::components::Material)>()
        .iter()
        .find_map(|(n, m)| match m {
            prism::components::Material::Dielectric { ior, .. } if n.0 == "prism" => Some(*ior),
            _ => None,
        })
        .expect("prism.ron has a dielectric called \"prism\"");
    let cam = &scene.camera;
    let (w, h) = (scene.settings.width, scene.settings.height);
    // Horizontal image position (in pixels) of a direction in the xz plane.
    let column = |d: (f64, f64)| -> f64 {
        let v = Vec3::new(d.0 as f32, 0.0, d.1 as f32);
        let sx = v.dot(cam.right) / v.dot(cam.forward) / cam.half.x;
        ((sx as f64) + 1.0) * 0.5 * w as f64
    };
    let mut measured = Vec::new();
    for lambda in [450.0f32, 550.0, 650.0] {
        let n = ior.eta(lambda) as f64;
        // Prediction: the direction from the eye whose ray, refracted by Snell's law at
        // both faces, crosses the slit plane at the slit's centre (bisection on the angle).
        let slit_z = |a: f64| -> Option<f64> {
            let (o, d) = through_prism(n, eye, (a.cos(), a.sin()))?;
            (d.0 < 0.0).then(|| o.1 + (SLIT_X - o.0) / d.0 * d.1)
        };
        let a0 = (look.1 - eye.1).atan2(look.0 - eye.0);
        let (mut lo, mut hi) = (a0 - 0.1, a0 + 0.1);
        let f_lo = slit_z(lo).unwrap() - SLIT_Z;
        assert!(
            f_lo * (slit_z(hi).unwrap() - SLIT_Z) < 0.0,
            "bracket at {lambda} nm"
        );
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if (slit_z(mid).unwrap() - SLIT_Z) * f_lo > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let a = 0.5 * (lo + hi);
        let predicted = column((a.cos(), a.sin()));
        // Measured: the centroid of the slit's image along the middle rows.
        let img = monochromatic(&scene, lambda);
        let (mut sw, mut sx) = (0.0f64, 0.0f64);
        for y in h / 2 - 4..h / 2 + 4 {
            for x in 0..w {
                let v = img[(y * w + x) as usize] as f64;
                sw += v;
                sx += v * (x as f64 + 0.5);
            }
        }
        assert!(sw > 0.0, "the slit is not seen at {lambda} nm");
        let centroid = sx / sw;
        eprintln!(
            "{lambda} nm: n = {n:.4}, slit image at x = {centroid:.2} px, Snell {predicted:.2} px"
        );
        assert!(
            (centroid - predicted).abs() < 1.0,
            "{lambda} nm: slit image at {centroid:.2} px, Snell predicts {predicted:.2} px"
        );
        measured.push(centroid);
    }
    // Violet is deviated most: its light comes from furthest round, and the three are
    // well separated (one degree is about 53 px here).
    assert!(
        (measured[0] - measured[1]) * (measured[1] - measured[2]) > 0.0,
        "{measured:?}"
    );
    assert!((measured[0] - measured[2]).abs() > 20.0, "{measured:?}");
}
