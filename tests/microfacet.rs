//! GGX microfacets: visible-normal sampling follows its pdf (χ² at several roughnesses and
//! incidences), `sample`, `eval` and `pdf` agree, the conductor is reciprocal and its Fresnel
//! term matches complex arithmetic in f64, and every lane width gives the scalar bits.

mod common;
use common::chi2::Chi2;
use glam::{DVec2, Vec3};
use prism::integrator::bsdf::{Chan, Mode, lobe};
use prism::integrator::microfacet::{
    Conductor, ConductorFresnel, Ggx, RoughDielectric, fresnel_conductor, fresnel_schlick_r0,
    ggx_albedo, ggx_albedo_lanes, ggx_average_albedo, ggx_average_albedo_lanes,
};
use prism::simd::{self, Float, LaneKernel, Lanes, Mask, V3};
use rayon::prelude::*;

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix;

fn gold_like(ax: f32, ay: f32, smooth: bool) -> Conductor<f32, 3> {
    with_ms(ax, ay, smooth, false)
}

fn with_ms(ax: f32, ay: f32, smooth: bool, multiscatter: bool) -> Conductor<f32, 3> {
    Conductor {
        dist: Ggx { ax, ay },
        smooth,
        multiscatter,
        fresnel: ConductorFresnel {
            eta: Chan([0.18, 0.42, 1.37]),
            k: Chan([3.42, 2.35, 1.77]),
            schlick: false,
        },
    }
}

/// `wo` at `theta` degrees from the normal, azimuth 30°.
fn incident(theta: f32) -> V3<f32> {
    let (t, p) = (theta.to_radians(), 30f32.to_radians());
    V3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Reflected directions follow `pdf` at α = 0.05, 0.3 and 1 (and two anisotropic pairs), at
/// normal, oblique and grazing incidence. Samples below the horizon are failures, which the
/// test counts against the pdf's missing mass.
#[test]
fn visible_normal_sampling_follows_its_pdf() {
    let alphas = [
        (0.05, 0.05),
        (0.3, 0.3),
        (1.0, 1.0),
        (0.05, 0.3),
        (0.6, 0.15),
    ];
    let thetas = [0.0, 45.0, 85.0];
    let tests = alphas.len() * thetas.len();
    for (k, &(ax, ay)) in alphas.iter().enumerate() {
        for (j, &theta) in thetas.iter().enumerate() {
            let c = gold_like(ax, ay, false);
            let wo = incident(theta);
            let sample = |u: glam::Vec2| {
                let s = c.sample(wo, u.x, u.y);
                (s.pdf > 0.0).then(|| Vec3::from(s.wi))
            };
            let pdf = |w: Vec3| c.pdf(wo, w.into());
            let r = Chi2::new(400_000, (k * 7 + j) as u64)
                .tests(tests)
                .max_depth(7)
                .directions([0.0, 1.0], sample, pdf);
            if let Err(e) = r {
                panic!("α = ({ax}, {ay}), θ = {theta}°: {e}");
            }
        }
    }
}

/// With compensation the sampler draws a mixture of the visible normals and a cosine lobe;
/// it follows `pdf`, and each sample's weight is f·cos/pdf of the compensated f.
#[test]
fn compensated_sampling_follows_its_pdf_and_weight() {
    let cases = [(0.3, 0.0), (0.3, 70.0), (1.0, 30.0), (0.6, 85.0)];
    for (k, &(alpha, theta)) in cases.iter().enumerate() {
        let c = with_ms(alpha, alpha, false, true);
        let wo = incident(theta);
        let sample = |u: glam::Vec2| {
            let s = c.sample(wo, u.x, u.y);
            (s.pdf > 0.0).then(|| Vec3::from(s.wi))
        };
        let pdf = |w: Vec3| c.pdf(wo, w.into());
        if let Err(e) = Chi2::new(300_000, 40 + k as u64)
            .tests(cases.len())
            .directions([0.0, 1.0], sample, pdf)
        {
            panic!("α = {alpha}, θ = {theta}°: {e}");
        }
        let mut g = SplitMix(50 + k as u64);
        for _ in 0..5000 {
            let s = c.sample(wo, g.range(0.0, 1.0) as f32, g.range(0.0, 1.0) as f32);
            if s.pdf == 0.0 {
                continue;
            }
            assert!((s.pdf - c.pdf(wo, s.wi)).abs() <= 1e-4 * s.pdf);
            let f = c.eval(wo, s.wi);
            for ch in 0..3 {
                let w = f.0[ch] * s.wi.z / s.pdf;
                assert!((w - s.weight.0[ch]).abs() <= 1e-4 * w.max(1e-3));
            }
        }
    }
}

/// The committed energy tables are what the quadrature gives (a few entries recomputed).
#[test]
fn energy_tables_match_the_quadrature() {
    for (i, j) in [(0, 5), (3, 3), (10, 20), (31, 31), (16, 9), (25, 28)] {
        let (mu, alpha) = (i as f32 / 31.0, j as f32 / 31.0);
        let want = ggx_albedo(f64::from(mu), f64::from(alpha)).min(1.0);
        let got = f64::from(ggx_albedo_lanes(mu, alpha));
        assert!(
            (got - want).abs() < 2e-6,
            "E({mu}, {alpha}): {got} vs {want}"
        );
    }
    for j in [4, 17, 31] {
        let alpha = j as f32 / 31.0;
        let want = ggx_average_albedo(f64::from(alpha));
        let got = f64::from(ggx_average_albedo_lanes(alpha));
        assert!((got - want).abs() < 2e-6, "E_avg({alpha}): {got} vs {want}");
    }
}

/// Each sample reports `pdf(wo, wi)` and the weight f·cos/pdf, its lobe is glossy, and the
/// weight never exceeds the Fresnel term (G2 ≤ G1).
#[test]
fn sample_weight_is_f_cos_over_pdf() {
    let mut g = SplitMix(11);
    for &(ax, ay) in &[(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.1, 0.5)] {
        let c = gold_like(ax, ay, false);
        for _ in 0..20_000 {
            let wo = incident(g.range(0.0, 89.0) as f32);
            let (u1, u2) = (g.range(0.0, 1.0) as f32, g.range(0.0, 1.0) as f32);
            let s = c.sample(wo, u1, u2);
            if s.pdf == 0.0 {
                assert!(s.wi.z <= 0.0, "a rejected sample must point below");
                assert_eq!(s.weight.0, [0.0; 3]);
                continue;
            }
            assert_eq!(s.lobe, lobe::GLOSSY_REFLECTION);
            let pdf = c.pdf(wo, s.wi);
            assert!(
                (s.pdf - pdf).abs() <= 2e-4 * pdf,
                "α ({ax}, {ay}): {} vs {pdf}",
                s.pdf
            );
            let f = c.eval(wo, s.wi);
            let fresnel = c.fresnel.eval(wo.dot((wo + s.wi).normalize()));
            for ch in 0..3 {
                let w = f.0[ch] * s.wi.z / pdf;
                assert!(
                    (w - s.weight.0[ch]).abs() <= 2e-4 * w.max(1e-3),
                    "α ({ax}, {ay}) channel {ch}: {w} vs {}",
                    s.weight.0[ch]
                );
                assert!(s.weight.0[ch] <= fresnel.0[ch] * (1.0 + 1e-5));
            }
        }
    }
}

#[test]
fn rough_conductor_is_reciprocal_and_zero_below() {
    let mut g = SplitMix(12);
    let c = gold_like(0.2, 0.45, false);
    let up = |g: &mut SplitMix| {
        let z = g.range(0.01, 1.0) as f32;
        let phi = g.range(0.0, std::f64::consts::TAU) as f32;
        let r = (1.0 - z * z).sqrt();
        V3::<f32>::new(r * phi.cos(), r * phi.sin(), z)
    };
    for _ in 0..10_000 {
        let (a, b) = (up(&mut g), up(&mut g));
        let (fab, fba) = (c.eval(a, b), c.eval(b, a));
        for ch in 0..3 {
            assert!(
                (fab.0[ch] - fba.0[ch]).abs() <= 1e-5 * fab.0[ch].max(1.0),
                "{:?} {:?}",
                fab.0,
                fba.0
            );
        }
        let below = V3::new(b.x, b.y, -b.z);
        assert_eq!(c.eval(a, below).0, [0.0; 3]);
        assert_eq!(c.pdf(a, below), 0.0);
    }
}

/// A smooth conductor is a mirror weighted by its Fresnel term at the incidence angle, with
/// no density for light sampling.
#[test]
fn smooth_conductor_is_a_fresnel_mirror() {
    let c = gold_like(1e-4, 1e-4, true);
    for theta in [0.0, 30.0, 60.0, 89.0] {
        let wo = incident(theta);
        let s = c.sample(wo, 0.3, 0.7);
        assert_eq!(s.lobe, lobe::SPECULAR_REFLECTION);
        assert_eq!(Vec3::from(s.wi), Vec3::new(-wo.x, -wo.y, wo.z));
        assert_eq!(s.weight.0, c.fresnel.eval(wo.z).0);
        assert_eq!(c.pdf(wo, s.wi), 0.0);
        assert_eq!(c.eval(wo, s.wi).0, [0.0; 3]);
    }
}

/// D is normalised: ∫ D(h) cos θh dω = 1, by midpoint quadrature in (cos θ, φ) (f64 sums of
/// the f32 density; the grid resolves α = 0.1 to far better than the 1e-3 asked).
#[test]
fn ggx_projected_area_is_one() {
    for &(ax, ay) in &[(0.1f32, 0.1f32), (0.5, 0.5), (1.0, 1.0), (0.2, 0.7)] {
        let d = Ggx { ax, ay };
        let (nt, np) = (4000, 256);
        let mut sum = 0.0f64;
        for i in 0..nt {
            // cos θ on a grid dense near 1, where the narrow lobes are: cos = 1 − t².
            let t = (i as f64 + 0.5) / nt as f64;
            let cos = 1.0 - t * t;
            let dcos = 2.0 * t / nt as f64;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let h = V3::<f32>::new(
                    (sin * phi.cos()) as f32,
                    (sin * phi.sin()) as f32,
                    cos as f32,
                );
                sum += f64::from(d.d(h)) * cos * dcos * std::f64::consts::TAU / np as f64;
            }
        }
        assert!((sum - 1.0).abs() < 1e-3, "α ({ax}, {ay}): ∫D cos = {sum}");
    }
}

/// Unpolarised reflectance from the complex amplitudes r_s and r_p, in f64.
fn fresnel_complex_f64(cos: f64, eta: f64, k: f64) -> f64 {
    let n = DVec2::new(eta, k);
    let mul = |a: DVec2, b: DVec2| DVec2::new(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
    let div = |a: DVec2, b: DVec2| {
        let d = b.x * b.x + b.y * b.y;
        DVec2::new(a.x * b.x + a.y * b.y, a.y * b.x - a.x * b.y) / d
    };
    let sqrt = |a: DVec2| {
        let r = a.length();
        let re = ((r + a.x) / 2.0).sqrt();
        let im = ((r - a.x) / 2.0).max(0.0).sqrt().copysign(a.y);
        DVec2::new(re, im)
    };
    let sin2 = 1.0 - cos * cos;
    // cos θt = √(1 − sin²θ/n²), n complex.
    let n2 = mul(n, n);
    let cos_t = sqrt(DVec2::new(1.0, 0.0) - div(DVec2::new(sin2, 0.0), n2));
    let ci = DVec2::new(cos, 0.0);
    let rs = div(ci - mul(n, cos_t), ci + mul(n, cos_t));
    let rp = div(mul(n, ci) - cos_t, mul(n, ci) + cos_t);
    0.5 * (rs.length_squared() + rp.length_squared())
}

#[test]
fn conductor_fresnel_matches_complex_arithmetic() {
    let metals = [
        (0.18, 3.42),
        (1.37, 1.77),
        (0.05, 4.2),
        (2.8, 3.8),
        (1.5, 0.0),
        (0.7, 0.0),
        (1.0, 0.0),
        (0.0, 2.0),
    ];
    for (eta, k) in metals {
        for i in 0..=1000 {
            let cos = i as f64 / 1000.0;
            let want = fresnel_complex_f64(cos, eta, k);
            let got = f64::from(fresnel_conductor(cos as f32, eta as f32, k as f32));
            if want.is_nan() {
                // 0/0: grazing incidence on η = 1, k = 0, no interface at all.
                assert_eq!(got, 1.0, "η {eta}, k {k}, cos {cos}");
                continue;
            }
            assert!(
                (got - want).abs() < 2e-5,
                "η {eta}, k {k}, cos {cos}: {got} vs {want}"
            );
        }
    }
    // Schlick's form is exact at both ends.
    assert_eq!(fresnel_schlick_r0(1.0f32, 0.3), 0.3);
    assert_eq!(fresnel_schlick_r0(0.0f32, 0.3), 1.0);
}

/// wo, wi, the sample's two uniforms, and (αx, αy).
type Case = ([f32; 3], [f32; 3], [f32; 2], [f32; 2]);

/// The conductor's sample, eval and pdf at one lane width, as bits.
struct Conductors<'a> {
    cases: &'a [Case],
}

impl LaneKernel for Conductors<'_> {
    type Output = Vec<Vec<u32>>;
    #[inline(always)]
    fn run<F: Float>(self) -> Vec<Vec<u32>> {
        let c = self.cases;
        let w = F::WIDTH;
        let mut out = vec![Vec::new(); c.len()];
        for base in (0..c.len()).step_by(w) {
            let at = |l: usize| &c[(base + l).min(c.len() - 1)];
            let wo = V3::<F>::from_fn(|l| Vec3::from(at(l).0)).normalize();
            let wi = V3::<F>::from_fn(|l| Vec3::from(at(l).1)).normalize();
            let (u1, u2) = (F::from_fn(|l| at(l).2[0]), F::from_fn(|l| at(l).2[1]));
            let (ax, ay) = (F::from_fn(|l| at(l).3[0]), F::from_fn(|l| at(l).3[1]));
            let mut vals: Vec<F> = Vec::new();
            for (schlick, smooth, ms) in [
                (false, false, false),
                (true, false, false),
                (false, true, false),
                (false, false, true),
                (true, true, true),
            ] {
                let cd = Conductor {
                    dist: Ggx { ax, ay },
                    smooth: F::Mask::splat(smooth),
                    multiscatter: F::Mask::splat(ms),
                    fresnel: ConductorFresnel {
                        eta: Chan([0.18, 0.42, 0.9].map(F::splat)),
                        k: Chan([3.42, 2.35, 1.77].map(F::splat)),
                        schlick: F::Mask::splat(schlick),
                    },
                };
                let s = cd.sample(wo, u1, u2);
                vals.extend([s.wi.x, s.wi.y, s.wi.z, s.pdf, cd.pdf(wo, wi)]);
                vals.extend(s.weight.0);
                vals.extend(cd.eval(wo, wi).0);
            }
            let uc = F::from_fn(|l| (at(l).2[0] + at(l).2[1]).fract());
            for (eta, schlick, ms) in [
                (1.5, false, false),
                (1.0 / 1.5, false, false),
                (1.33, true, false),
                (1.5, false, true),
                (1.0 / 2.2, false, true),
            ] {
                let d = RoughDielectric {
                    dist: Ggx { ax, ay },
                    eta: F::splat(eta),
                    schlick,
                    multiscatter: F::Mask::splat(ms),
                };
                let s = d.sample::<Chan<F, 1>>(wo, uc, u1, u2, Mode::Radiance);
                vals.extend([s.wi.x, s.wi.y, s.wi.z, s.pdf, s.weight.0[0], d.pdf(wo, wi)]);
                vals.extend([
                    d.eval(wo, wi, Mode::Radiance),
                    d.eval(wo, wi, Mode::Importance),
                ]);
            }
            for l in 0..w {
                if base + l < c.len() {
                    out[base + l] = vals.iter().map(|x| x.lane(l).to_bits()).collect();
                }
            }
        }
        out
    }
}

fn glass(alpha: f32, eta: f32) -> RoughDielectric<f32> {
    compensated_glass(alpha, eta, false)
}

fn compensated_glass(alpha: f32, eta: f32, multiscatter: bool) -> RoughDielectric<f32> {
    RoughDielectric {
        dist: Ggx::isotropic(alpha),
        eta,
        schlick: false,
        multiscatter,
    }
}

/// Reflected and refracted directions together follow `pdf` over the whole sphere, at α =
/// 0.05, 0.3 and 1, at normal, oblique and grazing incidence, entering glass and leaving it
/// (where total internal reflection takes every microfacet beyond the critical angle).
#[test]
fn rough_dielectric_sampling_follows_its_pdf() {
    let alphas = [0.05f32, 0.3, 1.0];
    let thetas = [0.0f32, 45.0, 85.0];
    let etas = [1.5f32, 1.0 / 1.5];
    let tests = alphas.len() * thetas.len() * etas.len();
    let mut cases = Vec::new();
    for (k, &alpha) in alphas.iter().enumerate() {
        for (j, &theta) in thetas.iter().enumerate() {
            for (e, &eta) in etas.iter().enumerate() {
                cases.push((k, j, e, alpha, theta, eta));
            }
        }
    }
    // The pdf's quadrature dominates: the cases run on every core.
    let failures: Vec<String> = cases
        .par_iter()
        .filter_map(|&(k, j, e, alpha, theta, eta)| {
            let b = glass(alpha, eta);
            let wo = incident(theta);
            // The lobe's uniform from its own stream: the χ² harness draws two.
            let mut g = SplitMix((k * 100 + j * 10 + e) as u64);
            let sample = |u: glam::Vec2| {
                let uc = g.range(0.0, 1.0) as f32;
                let s = b.sample::<Chan<f32, 1>>(wo, uc, u.x, u.y, Mode::Radiance);
                (s.pdf > 0.0).then(|| Vec3::from(s.wi))
            };
            let pdf = |w: Vec3| b.pdf(wo, w.into());
            Chi2::new(400_000, (k * 31 + j * 7 + e) as u64)
                .tests(tests)
                .max_depth(7)
                .directions([0.0, 2.0], sample, pdf)
                .err()
                .map(|err| format!("α = {alpha}, θ = {theta}°, η = {eta}: {err}"))
        })
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Each sample's pdf is `pdf(wo, wi)` and its weight f·|cos|/pdf; reflected weights are
/// G2/G1 ≤ 1, refracted radiance is scaled by 1/η² and importance is not.
#[test]
fn rough_dielectric_weight_is_f_cos_over_pdf() {
    let mut g = SplitMix(21);
    for &alpha in &[0.05f32, 0.3, 1.0] {
        for &eta in &[1.5f32, 1.0 / 1.5, 2.4] {
            let b = glass(alpha, eta);
            for _ in 0..20_000 {
                let wo = incident(g.range(0.0, 89.0) as f32);
                let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
                for mode in [Mode::Radiance, Mode::Importance] {
                    let s = b.sample::<Chan<f32, 1>>(wo, u[0], u[1], u[2], mode);
                    let weight = s.weight.0[0];
                    if s.pdf == 0.0 {
                        assert_eq!(weight, 0.0);
                        continue;
                    }
                    let t = s.wi.z < 0.0;
                    let want = if t {
                        lobe::GLOSSY_TRANSMISSION
                    } else {
                        lobe::GLOSSY_REFLECTION
                    };
                    assert_eq!(s.lobe, want);
                    assert_eq!(s.eta, if t { eta } else { 1.0 });
                    let pdf = b.pdf(wo, s.wi);
                    let ctx = format!("α {alpha}, η {eta}, wo {wo:?}, wi {:?}", s.wi);
                    assert!(
                        (s.pdf - pdf).abs() <= 2e-3 * pdf,
                        "{ctx}: {} vs {pdf}",
                        s.pdf
                    );
                    let w = b.eval(wo, s.wi, mode) * s.wi.z.abs() / pdf;
                    assert!(
                        (w - weight).abs() <= 2e-3 * w.max(1e-3),
                        "{ctx}: {w} vs {weight}"
                    );
                    let scale = if t && mode == Mode::Radiance {
                        1.0 / (eta * eta)
                    } else {
                        1.0
                    };
                    assert!(weight <= scale * (1.0 + 1e-5), "{ctx}: {weight}");
                }
            }
        }
    }
}

/// A random direction above the surface, at least 0.02 from grazing.
fn up(g: &mut SplitMix) -> V3<f32> {
    let z = g.range(0.02, 1.0) as f32;
    let phi = g.range(0.0, std::f64::consts::TAU) as f32;
    let r = (1.0 - z * z).sqrt();
    V3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `w` mirrored through the surface plane.
fn flip(w: V3<f32>) -> V3<f32> {
    V3::new(w.x, w.y, -w.z)
}

/// Reflection is reciprocal; refraction is adjoint: importance from wo to wi equals radiance
/// from wi to wo through the same interface seen from the other side (η → 1/η), which is
/// f_t(wo, wi)/η_o² = f_t(wi, wo)/η_i² of the physical BTDF.
#[test]
fn rough_dielectric_is_reciprocal_and_adjoint() {
    let mut g = SplitMix(22);
    let (mut transmitted, mut reflected) = (0, 0);
    for &eta in &[1.5f32, 1.0 / 1.33] {
        let (b, back) = (glass(0.35, eta), glass(0.35, 1.0 / eta));
        for _ in 0..20_000 {
            let (a, c) = (up(&mut g), up(&mut g));
            let (fac, fca) = (b.eval(a, c, Mode::Radiance), b.eval(c, a, Mode::Radiance));
            assert!((fac - fca).abs() <= 1e-4 * fac.max(1.0), "{fac} vs {fca}");
            reflected += usize::from(fac > 0.0);
            // a above, c below: the reverse path leaves c on the far side.
            let wi = flip(c);
            let imp = b.eval(a, wi, Mode::Importance);
            let rad = back.eval(c, flip(a), Mode::Radiance);
            // Near the critical angle 1 − F, seen from the dense side, is ill-conditioned in
            // f32: its cosine on the thin side comes from cos² = (η² − 1 + cos²θi)/η², a
            // cancellation. Pairs whose facet cosine on the thin side is under 0.05 are
            // compared more loosely.
            let h = (wi * eta + a).normalize();
            let thin = if eta > 1.0 { a.dot(h) } else { wi.dot(h) }.abs();
            let tol = if thin < 0.05 { 2e-2 } else { 1e-3 };
            assert!(
                (imp - rad).abs() <= tol * imp.max(1e-2),
                "η {eta}: {imp} vs {rad}, a {a:?} c {c:?}"
            );
            transmitted += usize::from(imp > 0.0);
        }
    }
    // Every reflected pair has a facet between its directions; a refraction needs one facing
    // both, which a fair share of random pairs have.
    assert!(
        reflected > 30_000 && transmitted > 5_000,
        "{reflected} {transmitted}"
    );
}

/// Energy: ∫ f |cos| dω over the sphere, by the sampled weights' mean, is at most 1 (single
/// scattering only loses energy), and at normal incidence on a nearly smooth interface all
/// but 1 % survives (the smooth limit loses nothing).
#[test]
fn rough_dielectric_conserves_energy() {
    let mut g = SplitMix(23);
    for &alpha in &[0.05f32, 0.3, 1.0] {
        for &eta in &[1.5f32, 1.0 / 1.5] {
            let b = glass(alpha, eta);
            for theta in [0.0f32, 40.0, 75.0] {
                let wo = incident(theta);
                let n = 200_000;
                let sum: f64 = (0..n)
                    .map(|_| {
                        let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
                        let s = b.sample::<Chan<f32, 1>>(wo, u[0], u[1], u[2], Mode::Importance);
                        f64::from(s.weight.0[0])
                    })
                    .sum();
                let e = sum / f64::from(n);
                assert!(e <= 1.0 + 1e-6, "α {alpha}, η {eta}, θ {theta}: {e}");
                if alpha <= 0.05 && theta == 0.0 {
                    assert!(e >= 0.99, "α {alpha}, η {eta}, θ {theta}: {e}");
                }
            }
        }
    }
}

/// With compensation the sampler mixes single scattering with a cosine lobe on each side;
/// the mixture follows `pdf` over the whole sphere (χ², entering and leaving glass, normal
/// and grazing incidence) and each sample's weight is f·|cos|/pdf of the compensated f.
#[test]
fn compensated_rough_dielectric_sampling_follows_its_pdf_and_weight() {
    let cases = [
        (0.3f32, 0.0f32, 1.5f32),
        (1.0, 85.0, 1.5),
        (0.3, 30.0, 1.0 / 1.5),
        (1.0, 70.0, 1.0 / 1.5),
        (0.6, 45.0, 2.4),
    ];
    // The pdf's quadrature dominates: the cases run on every core.
    cases
        .par_iter()
        .enumerate()
        .for_each(|(k, &(alpha, theta, eta))| {
            let b = compensated_glass(alpha, eta, true);
            let wo = incident(theta);
            let mut g = SplitMix(70 + k as u64);
            let sample = |u: glam::Vec2| {
                let uc = g.range(0.0, 1.0) as f32;
                let s = b.sample::<Chan<f32, 1>>(wo, uc, u.x, u.y, Mode::Radiance);
                (s.pdf > 0.0).then(|| Vec3::from(s.wi))
            };
            let pdf = |w: Vec3| b.pdf(wo, w.into());
            if let Err(err) = Chi2::new(400_000, 80 + k as u64)
                .tests(cases.len())
                .max_depth(7)
                .directions([0.0, 2.0], sample, pdf)
            {
                panic!("α = {alpha}, θ = {theta}°, η = {eta}: {err}");
            }
            let mut g = SplitMix(90 + k as u64);
            for _ in 0..5000 {
                let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
                for mode in [Mode::Radiance, Mode::Importance] {
                    let s = b.sample::<Chan<f32, 1>>(wo, u[0], u[1], u[2], mode);
                    if s.pdf == 0.0 {
                        assert_eq!(s.weight.0[0], 0.0);
                        continue;
                    }
                    let t = s.wi.z < 0.0;
                    assert_eq!(s.is_transmission(), t);
                    let pdf = b.pdf(wo, s.wi);
                    assert!((s.pdf - pdf).abs() <= 1e-3 * pdf, "{} vs {pdf}", s.pdf);
                    let w = b.eval(wo, s.wi, mode) * s.wi.z.abs() / pdf;
                    assert!((w - s.weight.0[0]).abs() <= 1e-3 * w.max(1e-3));
                }
            }
        });
}

/// The compensation lobe keeps refraction adjoint: importance from wo to wi equals radiance
/// from wi to wo through the interface seen from the other side, which holds only because
/// the two sides' transmitted shares are tied by x₋(1 − E₋avg)η² = x₊(1 − E₊avg).
#[test]
fn compensated_rough_dielectric_is_reciprocal_and_adjoint() {
    let mut g = SplitMix(24);
    for &(alpha, eta) in &[(0.35f32, 1.5f32), (0.9, 1.0 / 1.33), (0.6, 2.2)] {
        let b = compensated_glass(alpha, eta, true);
        let back = compensated_glass(alpha, 1.0 / eta, true);
        for _ in 0..20_000 {
            let (a, c) = (up(&mut g), up(&mut g));
            let (fac, fca) = (b.eval(a, c, Mode::Radiance), b.eval(c, a, Mode::Radiance));
            assert!((fac - fca).abs() <= 1e-4 * fac.max(1.0), "{fac} vs {fca}");
            let wi = flip(c);
            let imp = b.eval(a, wi, Mode::Importance);
            let rad = back.eval(c, flip(a), Mode::Radiance);
            let h = (wi * eta + a).normalize();
            let thin = if eta > 1.0 { a.dot(h) } else { wi.dot(h) }.abs();
            let tol = if thin < 0.05 { 2e-2 } else { 2e-3 };
            // The lobe alone is never zero between two directions: every pair transmits.
            assert!(imp > 0.0, "α {alpha} η {eta}: a {a:?} c {c:?}");
            assert!(
                (imp - rad).abs() <= tol * imp.max(1e-2),
                "α {alpha} η {eta}: {imp} vs {rad}, a {a:?} c {c:?}"
            );
        }
    }
}

/// With compensation the interface neither absorbs nor creates light: ∫ f |cos| dω over the
/// sphere (the mean sampled weight in importance form) is 1 within the tables' accuracy and
/// the estimate's noise (200 000 samples) at every roughness, incidence and side.
#[test]
fn compensated_rough_dielectric_keeps_all_the_energy() {
    let mut g = SplitMix(25);
    for &alpha in &[0.1f32, 0.3, 0.6, 1.0] {
        for &eta in &[1.5f32, 1.0 / 1.5, 1.33, 2.4] {
            let b = compensated_glass(alpha, eta, true);
            for theta in [0.0f32, 40.0, 75.0, 88.0] {
                let wo = incident(theta);
                let n = 200_000;
                let (mut sum, mut sq) = (0.0f64, 0.0f64);
                for _ in 0..n {
                    let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
                    let s = b.sample::<Chan<f32, 1>>(wo, u[0], u[1], u[2], Mode::Importance);
                    let w = f64::from(s.weight.0[0]);
                    sum += w;
                    sq += w * w;
                }
                let e = sum / f64::from(n);
                let sd = ((sq / f64::from(n) - e * e).max(0.0) / f64::from(n)).sqrt();
                assert!(
                    (e - 1.0).abs() <= 4.0 * sd + 5e-3,
                    "α {alpha}, η {eta}, θ {theta}: {e} ± {sd}"
                );
            }
        }
    }
}

/// The committed dielectric tables are what the quadrature gives (a few entries recomputed
/// at grid points, where the lookup returns the stored value).
#[test]
fn dielectric_energy_tables_match_the_quadrature() {
    use prism::energy::{DIELECTRIC_GRID, dielectric_albedo};
    use prism::integrator::dielectric_energy::Slices;
    for (i, j, k, leaving) in [
        (0, 5, 5, false),
        (3, 3, 5, true),
        (10, 20, 0, false),
        (31, 31, 20, true),
        (16, 9, 3, false),
        (25, 28, 14, true),
    ] {
        let (mu, alpha) = (i as f32 / 31.0, j as f32 / 31.0);
        let eta = 1.0 + k as f64 / 10.0;
        let eta = if leaving { 1.0 / eta } else { eta };
        let (r, t) = dielectric_albedo(f64::from(mu), f64::from(alpha), eta, DIELECTRIC_GRID);
        let want = (r + t).min(1.0);
        let got = f64::from(Slices::<f32>::new(eta as f32).albedo(false, mu, alpha));
        assert!(
            (got - want).abs() < 3e-5,
            "E({mu}, {alpha}, η {eta}): {got} vs {want}"
        );
    }
}

#[test]
fn every_lane_form_gives_the_scalar_conductor_bits() {
    let mut g = SplitMix(13);
    let dir = |g: &mut SplitMix| {
        let z = g.range(-0.2, 1.0) as f32;
        let phi = g.range(0.0, std::f64::consts::TAU) as f32;
        let r = (1.0 - z * z).max(0.0).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    };
    let cases: Vec<Case> = (0..4000)
        .map(|_| {
            let (wo, wi) = (dir(&mut g), dir(&mut g));
            let u = [g.range(0.0, 1.0) as f32, g.range(0.0, 1.0) as f32];
            let a = [g.range(0.002, 1.0) as f32, g.range(0.002, 1.0) as f32];
            (wo, wi, u, a)
        })
        .collect();
    let want = Conductors { cases: &cases }.run::<f32>();
    for lanes in Lanes::all_available() {
        let got = simd::dispatch(lanes, Conductors { cases: &cases });
        for (k, (a, b)) in got.iter().zip(&want).enumerate() {
            assert_eq!(a, b, "{} case {k}: {:?}", lanes.describe(), cases[k]);
        }
    }
}
