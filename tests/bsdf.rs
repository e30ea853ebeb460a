//! The BSDF interface: sampling agrees with `eval` and `pdf`, the physics holds (reciprocity,
//! Fresnel-weighted lobe choice, Snell, the radiance/importance asymmetry of refraction), and
//! every lane width and form gives the scalar bits.

mod common;
use common::chi2::Chi2;
use glam::Vec3;
use prism::integrator::bsdf::{
    BsdfSample, Chan, Dielectric, Diffuse, Mirror, Mode, fresnel_dielectric, lobe,
};
use prism::simd::{self, Float, LaneKernel, Lanes, UInt, V3};

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix;

/// A unit direction in the upper hemisphere, uniform in solid angle.
fn upper(g: &mut SplitMix) -> Vec3 {
    let z = g.range(0.0, 1.0) as f32;
    let phi = g.range(0.0, std::f64::consts::TAU) as f32;
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn diffuse_sampling_matches_its_pdf_and_weight() {
    let d = Diffuse {
        albedo: Vec3::new(0.2, 0.5, 0.9),
    };
    let wo = V3::<f32>::new(0.3, -0.2, 0.933);
    // The sampled directions follow pdf() (chi-square over the sphere: none below the horizon).
    let sample = |u: glam::Vec2| Some(Vec3::from(d.sample(wo, u.x, u.y).wi));
    let pdf = |w: Vec3| d.pdf(wo, w.into());
    Chi2::new(200_000, 3)
        .directions([0.0, 2.0], sample, pdf)
        .unwrap();
    // Each sample reports that density and the weight f·cos/pdf.
    let mut g = SplitMix(4);
    for _ in 0..10_000 {
        let (ux, uy) = (g.range(0.0, 1.0) as f32, g.range(0.0, 1.0) as f32);
        let s = d.sample(wo, ux, uy);
        let (pdf, f) = (d.pdf(wo, s.wi), d.eval(wo, s.wi));
        assert!((s.pdf - pdf).abs() <= 1e-6 * pdf.max(1.0));
        if pdf > 1e-3 {
            let w = f * s.wi.z / pdf;
            assert!(
                (w - s.weight).abs().max_element() < 1e-5,
                "{w} vs {}",
                s.weight
            );
        }
        assert_eq!(s.lobe, lobe::DIFFUSE_REFLECTION);
    }
}

#[test]
fn diffuse_is_reciprocal_and_zero_below() {
    let d = Diffuse { albedo: Vec3::ONE };
    let mut g = SplitMix(5);
    for _ in 0..1000 {
        let (a, b) = (upper(&mut g), upper(&mut g));
        assert_eq!(d.eval(a.into(), b.into()), d.eval(b.into(), a.into()));
        let below = Vec3::new(b.x, b.y, -b.z);
        assert_eq!(d.eval(a.into(), below.into()), Vec3::ZERO);
        assert_eq!(d.pdf(a.into(), below.into()), 0.0);
    }
}

#[test]
fn mirror_reflects_about_the_normal_with_its_tint() {
    let m = Mirror {
        tint: Vec3::new(0.9, 0.8, 0.7),
    };
    let mut g = SplitMix(6);
    for _ in 0..1000 {
        let wo = upper(&mut g);
        let s: BsdfSample<f32, Vec3> = m.sample(wo.into());
        assert_eq!(Vec3::from(s.wi), Vec3::new(-wo.x, -wo.y, wo.z));
        assert_eq!(s.weight, m.tint);
        assert!(s.is_specular() && !s.is_transmission());
        assert_eq!(m.eval(wo.into(), s.wi), Vec3::ZERO);
        assert_eq!(m.pdf(wo.into(), s.wi), 0.0);
    }
}

#[test]
fn dielectric_chooses_reflection_with_the_fresnel_probability() {
    // The reflected fraction of N uniform u is binomial(N, R): within 5σ of R.
    let n = 100_000;
    for (eta, schlick) in [
        (1.5, false),
        (1.0 / 1.5, false),
        (2.42, true),
        (1.0 / 1.33, true),
    ] {
        let d = Dielectric { eta, schlick };
        for deg in [0.0f32, 30.0, 45.0, 60.0, 75.0, 85.0] {
            let th = deg.to_radians();
            let wo = V3::<f32>::new(th.sin(), 0.0, th.cos());
            let r = d.reflectance(wo);
            let mut g = SplitMix(7);
            let mut reflected = 0;
            for _ in 0..n {
                let s = d.sample::<Vec3>(wo, g.range(0.0, 1.0) as f32, Mode::Radiance);
                if s.is_transmission() {
                    // Snell, and the transmitted side.
                    let sin_t = (s.wi.x * s.wi.x + s.wi.y * s.wi.y).sqrt();
                    assert!((th.sin() - eta * sin_t).abs() < 1e-5, "{eta} {deg}");
                    assert!(s.wi.z < 0.0);
                    assert_eq!(s.eta, eta);
                    assert!((s.pdf - (1.0 - r)).abs() < 1e-6);
                } else {
                    reflected += 1;
                    assert_eq!(Vec3::from(s.wi), Vec3::new(-wo.x, -wo.y, wo.z));
                    assert_eq!(s.weight, Vec3::ONE);
                    assert_eq!((s.pdf, s.eta), (r, 1.0));
                }
                assert!(s.is_specular());
            }
            let p = reflected as f64 / n as f64;
            let sigma = (f64::from(r) * (1.0 - f64::from(r)) / n as f64).sqrt();
            assert!(
                (p - f64::from(r)).abs() <= 5.0 * sigma + 1e-9,
                "eta {eta} {deg}°: reflected {p}, Fresnel {r}"
            );
        }
    }
}

#[test]
fn total_internal_reflection_always_reflects() {
    let eta = 1.0f32 / 1.5;
    let critical = eta.asin();
    let d = Dielectric {
        eta,
        schlick: false,
    };
    let mut g = SplitMix(8);
    for k in 1..50 {
        let th = critical + (std::f32::consts::FRAC_PI_2 - critical) * k as f32 / 50.0;
        let wo = V3::<f32>::new(th.sin(), 0.0, th.cos());
        assert_eq!(fresnel_dielectric(wo.z, eta), 1.0);
        for _ in 0..100 {
            let s = d.sample::<Vec3>(wo, g.range(0.0, 1.0) as f32, Mode::Radiance);
            assert!(
                !s.is_transmission(),
                "refracted beyond the critical angle at {th}"
            );
        }
    }
}

#[test]
fn refraction_scales_radiance_by_one_over_eta_squared_and_importance_not() {
    // Radiance L/η² is what keeps L/n² invariant along a ray; importance (the adjoint) is
    // not compressed, so light and camera paths weight the same path consistently.
    for eta in [1.5f32, 1.0 / 1.5, 2.42] {
        let d = Dielectric {
            eta,
            schlick: false,
        };
        let wo = V3::<f32>::new(0.1, 0.0, 0.995);
        // u close to 1 refracts (R is small at near-normal incidence).
        let rad = d.sample::<Vec3>(wo, 0.999, Mode::Radiance);
        let imp = d.sample::<Vec3>(wo, 0.999, Mode::Importance);
        assert!(rad.is_transmission() && imp.is_transmission());
        assert_eq!(Vec3::from(rad.wi), Vec3::from(imp.wi));
        assert!((rad.weight.x * eta * eta - 1.0).abs() < 1e-6);
        assert_eq!(imp.weight, Vec3::ONE);
    }
}

/// Every BSDF's sample, eval and pdf for a list of inputs, as bits, at one lane width.
struct Bsdfs<'a> {
    cases: &'a [([f32; 3], [f32; 3], [f32; 3])],
}

impl LaneKernel for Bsdfs<'_> {
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
            let u = [0, 1, 2].map(|k| F::from_fn(|l| at(l).2[k]));
            let albedo = Chan([0.3f32, 0.6, 0.9].map(F::splat));
            let d = Diffuse { albedo };
            let ds = d.sample(wo, u[0], u[1]);
            let de = d.eval(wo, wi);
            let dp = d.pdf(wo, wi);
            let ms = Mirror { tint: albedo }.sample(wo);
            let mut vals: Vec<F> = vec![ds.wi.x, ds.wi.y, ds.wi.z, ds.pdf, dp, ms.wi.x, ms.wi.z];
            vals.extend(ds.weight.0);
            vals.extend(de.0);
            let mut lobes = vec![ds.lobe, ms.lobe];
            for (eta, schlick) in [(1.5, false), (1.0 / 1.5, false), (1.33, true), (0.7, true)] {
                let g = Dielectric {
                    eta: F::splat(eta),
                    schlick,
                };
                for mode in [Mode::Radiance, Mode::Importance] {
                    let s = g.sample::<Chan<F, 4>>(wo, u[2], mode);
                    vals.extend([s.wi.x, s.wi.y, s.wi.z, s.pdf, s.eta, s.weight.0[0]]);
                    lobes.push(s.lobe);
                }
            }
            for l in 0..w {
                if base + l < c.len() {
                    let mut v: Vec<u32> = vals.iter().map(|x| x.lane(l).to_bits()).collect();
                    v.extend(lobes.iter().map(|x| x.lane(l)));
                    out[base + l] = v;
                }
            }
        }
        out
    }
}

#[test]
fn every_lane_form_gives_the_scalar_bsdf_bits() {
    let mut g = SplitMix(9);
    let cases: Vec<([f32; 3], [f32; 3], [f32; 3])> = (0..5000)
        .map(|k| {
            let wo = upper(&mut g);
            // Some below the horizon, for eval's zero and the tilted-normal case.
            let wi = if k % 5 == 0 {
                -upper(&mut g)
            } else {
                upper(&mut g)
            };
            let u = [0; 3].map(|_| g.range(0.0, 1.0) as f32);
            (wo.to_array(), wi.to_array(), u)
        })
        .collect();
    let want = Bsdfs { cases: &cases }.run::<f32>();
    for lanes in Lanes::all_available() {
        let got = simd::dispatch(lanes, Bsdfs { cases: &cases });
        for (k, (a, b)) in got.iter().zip(&want).enumerate() {
            assert_eq!(a, b, "{} case {k}: {:?}", lanes.describe(), cases[k]);
        }
    }
}
