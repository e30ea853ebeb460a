//! Properties of the samplers, warps and alias table.

mod common;

use std::f32::consts::{FRAC_1_PI, TAU};

use common::chi2::{
    Chi2, chi2_p_value, chi2_test_directions, chi2_test_discrete, chi2_test_planar, gamma_q,
    integrate_directions, integrate_planar, ln_gamma, uniform_2d,
};
use glam::{Vec2, Vec3};
use prism::sampling::*;
use rand::Rng;
use rand_pcg::Pcg32;

/// Samples per warp chi-square test: ~500 per bin on the default 32 × 64
/// grid, enough to detect shape errors of about 1.5 %.
const N: usize = 1_000_000;

fn rng(seed: u64) -> Pcg32 {
    Pcg32::new(seed, 0xda3e_39cb_94b9_5bdb)
}

fn assert_passes(result: Result<common::chi2::Outcome, String>) {
    if let Err(e) = result {
        panic!("{e}");
    }
}

// ---------------------------------------------------------------- harness

#[test]
fn harness_incomplete_gamma_matches_closed_forms() {
    // For integer a, Q(a, x) = e^{−x} Σ_{k<a} x^k / k!.
    let closed = |a: u32, x: f64| {
        let (mut term, mut sum) = (1.0, 0.0);
        for k in 0..a {
            if k > 0 {
                term *= x / f64::from(k);
            }
            sum += term;
        }
        sum * (-x).exp()
    };
    // Points on both sides of x = a + 1, where the evaluation method switches.
    for (a, x) in [
        (1, 0.3),
        (1, 7.0),
        (3, 0.5),
        (5, 3.7),
        (5, 9.0),
        (20, 15.0),
        (50, 60.0),
        (200, 180.0),
    ] {
        let (got, want) = (gamma_q(f64::from(a), x), closed(a, x));
        assert!(
            (got - want).abs() <= 1e-10 * want.max(1e-300) + 1e-14,
            "Q({a}, {x}) = {got}, want {want}"
        );
    }
    // Textbook chi-square critical values.
    assert!((chi2_p_value(3.841_459, 1) - 0.05).abs() < 1e-6);
    assert!((chi2_p_value(23.209_251, 10) - 0.01).abs() < 1e-6);
    assert!((chi2_p_value(1.0, 2) - (-0.5f64).exp()).abs() < 1e-12);
    // Γ(n) = (n − 1)!, Γ(1/2) = √π.
    assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-11);
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-11);
    assert!((ln_gamma(1.0)).abs() < 1e-12);
}

#[test]
fn harness_rejects_wrong_pdfs() {
    // Cosine-distributed samples judged against a uniform hemisphere pdf.
    let cos_dirs = |u| Some(square_to_cosine_hemisphere(u));
    assert!(
        Chi2::new(N, 1)
            .directions([0.0, 1.0], cos_dirs, |_| uniform_hemisphere_pdf())
            .is_err()
    );
    // A subtly wrong lobe: normalized cos^1.05 instead of cos.
    let cos_pow = |d: Vec3| 2.05 / TAU * d.z.max(0.0).powf(1.05);
    assert!((integrate_directions(cos_pow, [0.0, 1.0], [64, 64]) - 1.0).abs() < 1e-4);
    assert!(
        Chi2::new(N, 2)
            .directions([0.0, 1.0], cos_dirs, cos_pow)
            .is_err()
    );
    // Right shape, wrong mass: too much is caught by the integral, too little
    // by the cell of samples the pdf cannot account for.
    let sphere = |u| Some(square_to_uniform_sphere(u));
    assert!(chi2_test_directions(sphere, |_| 1.02 * uniform_sphere_pdf(), N, 3).is_err());
    assert!(chi2_test_directions(sphere, |_| 0.98 * uniform_sphere_pdf(), N, 4).is_err());
    // Samples where the pdf is zero.
    let leaky = |u: Vec2| {
        let d = square_to_uniform_hemisphere(u);
        Some(if u.y < 0.001 { -d } else { d })
    };
    let err = Chi2::new(N, 5)
        .directions([0.0, 2.0], leaky, |d| {
            if d.z >= 0.0 {
                uniform_hemisphere_pdf()
            } else {
                0.0
            }
        })
        .unwrap_err();
    assert!(err.contains("expected count is 0"), "{err}");
    // 1-D: tent samples against a uniform density.
    assert!(
        Chi2::new(N, 6)
            .res(64, 1)
            .linear(-1.0, 1.0, |u| Some(sample_tent(u)), |_| 0.5)
            .is_err()
    );
}

#[test]
fn harness_accepts_failed_samples_the_pdf_accounts_for() {
    // Half the samples fail; the pdf integrates to 1/2 accordingly.
    let half = |u: Vec2| (u.x < 0.5).then(|| square_to_uniform_sphere(Vec2::new(2.0 * u.x, u.y)));
    assert_passes(Chi2::new(N, 7).directions([0.0, 2.0], half, |_| 0.5 * uniform_sphere_pdf()));
}

// ------------------------------------------------------------------ warps

#[test]
fn cosine_hemisphere_matches_pdf() {
    let sample = |u| Some(square_to_cosine_hemisphere(u));
    let pdf = |d: Vec3| cosine_hemisphere_pdf(d.z);
    assert_passes(
        Chi2::new(N, 10)
            .tests(2)
            .directions([0.0, 1.0], sample, pdf),
    );
    // Over the whole sphere too (the pdf is continuous at the horizon), which
    // also checks nothing lands below it.
    assert_passes(
        Chi2::new(N, 11)
            .tests(2)
            .directions([0.0, 2.0], sample, pdf),
    );
}

#[test]
fn uniform_sphere_matches_pdf() {
    chi2_test_directions(
        |u| Some(square_to_uniform_sphere(u)),
        |_| uniform_sphere_pdf(),
        N,
        12,
    )
    .unwrap();
}

#[test]
fn uniform_hemisphere_matches_pdf() {
    let sample = |u| Some(square_to_uniform_hemisphere(u));
    assert_passes(
        Chi2::new(N, 13)
            .tests(2)
            .directions([0.0, 1.0], sample, |_| uniform_hemisphere_pdf()),
    );
    // Whole sphere: the pdf's jump at the horizon falls on a bin edge.
    assert_passes(
        Chi2::new(N, 14)
            .tests(2)
            .directions([0.0, 2.0], sample, |d| {
                if d.z >= 0.0 {
                    uniform_hemisphere_pdf()
                } else {
                    0.0
                }
            }),
    );
}

#[test]
fn uniform_cones_match_pdf() {
    let cones = [0.2f32, 0.9, 0.9999];
    for (k, &cos_max) in cones.iter().enumerate() {
        // The domain is exactly the cone: any sample outside it is an error.
        let omc = 1.0 - f64::from(cos_max);
        assert_passes(
            Chi2::new(N, 20 + k as u64)
                .tests(cones.len() + 1)
                .directions(
                    [0.0, omc],
                    |u| Some(square_to_uniform_cone(u, cos_max)),
                    |_| uniform_cone_pdf(cos_max),
                ),
        );
    }
    // A cone so narrow that cos_max rounds to 1 in f32: only the
    // 1 − cos form can describe it, and it must still be exact.
    let omc = 1e-9f32;
    assert_passes(Chi2::new(N, 30).tests(cones.len() + 1).directions(
        [0.0, f64::from(omc)],
        |u| Some(square_to_uniform_cone_one_minus_cos(u, omc)),
        |_| uniform_cone_pdf_one_minus_cos(omc),
    ));
}

#[test]
fn narrow_cone_directions_are_unit_and_inside() {
    let mut r = rng(31);
    for &omc in &[1e-3f32, 1e-6, 1e-9, 1e-12] {
        for _ in 0..10_000 {
            let d = square_to_uniform_cone_one_minus_cos(uniform_2d(&mut r), omc);
            assert!((d.length() - 1.0).abs() < 1e-6);
            // sin²θ ≤ (1 − cos_max)(1 + cos_max) to f32 precision.
            let sin2 = d.x * d.x + d.y * d.y;
            assert!(
                sin2 <= omc * (2.0 - omc) * (1.0 + 1e-5),
                "{d} outside cone {omc}"
            );
        }
    }
}

#[test]
fn concentric_disk_matches_pdf() {
    // Uniform on the disk is uniform in (r², φ) with density pdf · ½ there
    // (dA = ½ d(r²) dφ); unlike a Cartesian grid, no bin straddles the rim.
    let polar = |u| {
        let p = square_to_uniform_disk_concentric(u);
        let phi = p.y.atan2(p.x);
        Some(Vec2::new(
            p.length_squared(),
            if phi < 0.0 { phi + TAU } else { phi },
        ))
    };
    assert_passes(Chi2::new(N, 40).tests(2).res(32, 64).planar(
        Vec2::ZERO,
        Vec2::new(1.0, TAU),
        polar,
        |_| 0.5 * uniform_disk_pdf(),
    ));
    // Cartesian too: the rim cuts through bins, exercising the adaptive
    // integration.
    assert_passes(Chi2::new(N / 4, 41).tests(2).res(16, 16).planar(
        Vec2::splat(-1.0),
        Vec2::ONE,
        |u| Some(square_to_uniform_disk_concentric(u)),
        |p| {
            if p.length_squared() <= 1.0 {
                uniform_disk_pdf()
            } else {
                0.0
            }
        },
    ));
}

#[test]
fn triangle_matches_pdf() {
    // (b0, b1 / (1 − b0)) spans the unit square, where the density becomes
    // pdf · (1 − b0), smooth with no edge inside any bin.
    let square = |u| {
        let b = square_to_uniform_triangle(u);
        assert!(
            b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0,
            "{b} outside the triangle"
        );
        Some(Vec2::new(b.x, b.y / (1.0 - b.x)))
    };
    chi2_test_planar(
        square,
        |q| uniform_triangle_pdf() * (1.0 - q.x),
        Vec2::ZERO,
        Vec2::ONE,
        N,
        50,
    )
    .unwrap();
}

#[test]
fn tent_matches_pdf() {
    assert_passes(Chi2::new(N, 60).res(64, 1).linear(
        -1.0,
        1.0,
        |u| Some(sample_tent(u)),
        tent_pdf,
    ));
    assert_eq!(sample_tent(0.0), -1.0);
    assert_eq!(sample_tent(0.5), 0.0);
    assert!(sample_tent(1.0 - f32::EPSILON / 2.0) < 1.0);
}

#[test]
fn pdfs_integrate_to_one() {
    let res = [64, 64];
    let close = |x: f64, what: &str| assert!((x - 1.0).abs() < 1e-6, "{what} integrates to {x}");
    close(
        integrate_directions(|d| cosine_hemisphere_pdf(d.z), [0.0, 2.0], res),
        "cosine hemisphere",
    );
    close(
        integrate_directions(|_| uniform_sphere_pdf(), [0.0, 2.0], res),
        "sphere",
    );
    close(
        integrate_directions(|_| uniform_hemisphere_pdf(), [0.0, 1.0], res),
        "hemisphere",
    );
    for cos_max in [-0.5f32, 0.2, 0.9, 0.9999] {
        let omc = 1.0 - f64::from(cos_max);
        close(
            integrate_directions(|_| uniform_cone_pdf(cos_max), [0.0, omc], res),
            "cone",
        );
    }
    // Disk in polar coordinates: ∫∫ pdf r dr dφ.
    close(
        integrate_planar(
            |p| uniform_disk_pdf() * p.x,
            Vec2::ZERO,
            Vec2::new(1.0, TAU),
            res,
        ),
        "disk",
    );
    // Triangle over the (b0, b1) square, b1 ≤ 1 − b0, via the same
    // substitution as its chi-square test.
    close(
        integrate_planar(
            |q| uniform_triangle_pdf() * (1.0 - q.x),
            Vec2::ZERO,
            Vec2::ONE,
            res,
        ),
        "triangle",
    );
    close(
        integrate_planar(|p| tent_pdf(p.x), Vec2::new(-1.0, 0.0), Vec2::ONE, res),
        "tent",
    );
}

#[test]
fn warps_hit_their_domains() {
    let mut r = rng(70);
    for _ in 0..100_000 {
        let u = uniform_2d(&mut r);
        assert!(square_to_uniform_disk_concentric(u).length() <= 1.0 + 1e-6);
        let c = square_to_cosine_hemisphere(u);
        assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
        let s = square_to_uniform_sphere(u);
        assert!((s.length() - 1.0).abs() < 1e-5);
        let h = square_to_uniform_hemisphere(u);
        assert!(h.z >= 0.0 && (h.length() - 1.0).abs() < 1e-5);
        let t = sample_tent(u.x);
        assert!((-1.0..=1.0).contains(&t));
    }
    assert_eq!(
        square_to_uniform_disk_concentric(Vec2::splat(0.5)),
        Vec2::ZERO
    );
    assert_eq!(cosine_hemisphere_pdf(-0.3), 0.0);
    assert!((cosine_hemisphere_pdf(1.0) - FRAC_1_PI).abs() < 1e-7);
}

#[test]
fn coordinate_system_is_orthonormal_and_right_handed() {
    let mut r = rng(80);
    let check = |n: Vec3| {
        let (t, b) = coordinate_system(n);
        let tol = 2e-6;
        assert!(
            (t.length() - 1.0).abs() < tol && (b.length() - 1.0).abs() < tol,
            "{n}: {t} {b}"
        );
        assert!(
            t.dot(b).abs() < tol && t.dot(n).abs() < tol && b.dot(n).abs() < tol,
            "{n}: {t} {b}"
        );
        assert!(
            (t.cross(b) - n).abs().max_element() < tol,
            "{n}: t × b = {}",
            t.cross(b)
        );
    };
    for _ in 0..100_000 {
        check(square_to_uniform_sphere(uniform_2d(&mut r)));
    }
    // Near the z = 0 switch and the poles.
    for n in [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::new(1.0, 0.0, -0.0),
        Vec3::new(0.6, 0.8, 1e-7),
        Vec3::new(0.6, 0.8, -1e-7),
        Vec3::new(1e-4, 0.0, 1.0 - 5e-9).normalize(),
        Vec3::new(0.0, 1e-4, -1.0).normalize(),
    ] {
        check(n);
    }
    // Exactly at ±z the basis is exact.
    assert_eq!(coordinate_system(Vec3::Z), (Vec3::X, Vec3::Y));
    assert_eq!(coordinate_system(Vec3::NEG_Z), (Vec3::X, Vec3::NEG_Y));
    assert_eq!(Vec3::X.cross(Vec3::NEG_Y), Vec3::NEG_Z);
}

// ------------------------------------------------------------ alias table

fn test_weights() -> Vec<f32> {
    let mut r = rng(90);
    let mut w: Vec<f32> = (0..200)
        .map(|_| (r.next_u32() >> 8) as f32 / 16_777_216.0)
        .collect();
    // Zeros (including runs), a dominant entry and tiny ones.
    for i in [0, 1, 2, 17, 50, 51, 199] {
        w[i] = 0.0;
    }
    w[100] = 40.0;
    w[101] = 1e-4;
    w
}

#[test]
fn alias_table_frequencies_match_weights() {
    let w = test_weights();
    let table = AliasTable::new(&w);
    let total: f64 = w.iter().map(|&x| f64::from(x)).sum();
    let mut counts = vec![0u64; w.len()];
    let mut r = rng(91);
    for _ in 0..N {
        let (i, p) = table.sample((r.next_u32() >> 8) as f32 / 16_777_216.0);
        assert_eq!(p, table.pmf(i));
        counts[i] += 1;
    }
    for (i, &wi) in w.iter().enumerate() {
        if wi == 0.0 {
            assert_eq!(counts[i], 0, "zero-weight entry {i} was drawn");
        }
    }
    let pmf: Vec<f64> = w.iter().map(|&x| f64::from(x) / total).collect();
    assert_passes(chi2_test_discrete(&counts, &pmf, 1));
}

#[test]
fn alias_table_is_exact_over_all_24_bit_inputs() {
    // Every f32 a sampler can return (k · 2⁻²⁴) once: the frequencies are the
    // table's exact probabilities, up to one 2⁻²⁴ step per bin boundary.
    let w = test_weights();
    let table = AliasTable::new(&w);
    let mut counts = vec![0u64; w.len()];
    for k in 0..1u32 << 24 {
        counts[table.sample(k as f32 / 16_777_216.0).0] += 1;
    }
    for i in 0..w.len() {
        let freq = counts[i] as f64 / f64::from(1u32 << 24);
        let tol = 2.0 * w.len() as f64 / f64::from(1u32 << 24) + 1e-7;
        assert!(
            (freq - f64::from(table.pmf(i))).abs() < tol,
            "entry {i}: {freq} vs {}",
            table.pmf(i)
        );
        if w[i] == 0.0 {
            assert_eq!(counts[i], 0);
        }
    }
}

#[test]
fn alias_table_pmf_is_normalized() {
    let mut r = rng(92);
    for len in [1usize, 2, 3, 7, 64, 1000, 4097] {
        let w: Vec<f32> = (0..len)
            .map(|_| {
                let x = r.next_u32();
                // Mix of zeros and values spanning many orders of magnitude.
                if x.is_multiple_of(5) {
                    0.0
                } else {
                    2f32.powi((x >> 16) as i32 % 40 - 20)
                }
            })
            .collect();
        let t = AliasTable::new(&w);
        assert_eq!(t.len(), len);
        let sum: f64 = (0..len).map(|i| f64::from(t.pmf(i))).sum();
        assert!((sum - 1.0).abs() < 1e-5, "len {len}: pmf sums to {sum}");
        for (i, &wi) in w.iter().enumerate() {
            if wi == 0.0 {
                assert_eq!(t.pmf(i), 0.0);
            }
        }
        for u in [0.0, 0.5, 1.0 - f32::EPSILON / 2.0] {
            let (i, p) = t.sample(u);
            assert!(
                i < len && w[i] > 0.0 && p > 0.0,
                "len {len}, u {u}: drew {i}"
            );
        }
    }
}

#[test]
fn alias_table_edge_cases() {
    let empty = AliasTable::new(&[]);
    assert!(empty.is_empty());
    assert_eq!(empty.len(), 0);
    assert_eq!(empty.pmf(0), 0.0);

    // All-zero (and invalid) weights fall back to uniform.
    let zero = AliasTable::new(&[0.0, 0.0, -1.0, f32::NAN]);
    assert_eq!(zero.len(), 4);
    for i in 0..4 {
        assert_eq!(zero.pmf(i), 0.25);
    }
    assert_eq!(zero.sample(0.6).0, 2);

    // Invalid weights alongside valid ones count as zero.
    let mixed = AliasTable::new(&[f32::NAN, 1.0, -3.0, f32::INFINITY, 3.0]);
    assert_eq!(
        (0..5).map(|i| mixed.pmf(i)).collect::<Vec<_>>(),
        [0.0, 0.25, 0.0, 0.0, 0.75]
    );
    for k in 0..1000 {
        let (i, _) = mixed.sample(k as f32 / 1000.0);
        assert!(i == 1 || i == 4);
    }

    let single = AliasTable::new(&[2.5]);
    assert_eq!(single.sample(0.999), (0, 1.0));
    assert_eq!(single.pmf(1), 0.0);
}

// --------------------------------------------------------------- samplers

const KINDS: [SamplerKind; 2] = [SamplerKind::Sobol, SamplerKind::Independent];

#[test]
fn samples_lie_in_unit_interval() {
    for kind in KINDS {
        let s = Sampler::new(kind, 7);
        for pixel in [0, 1, 99, u32::MAX] {
            for index in (0..4096).chain([u32::MAX - 1, u32::MAX]) {
                for dim in [0, 1, 5, 64, u32::MAX - 1] {
                    let x = s.get_1d(pixel, index, dim);
                    let p = s.get_2d(pixel, index, dim);
                    assert!((0.0..1.0).contains(&x), "{kind:?}: {x}");
                    assert!(
                        (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                        "{kind:?}: {p}"
                    );
                }
            }
        }
    }
    assert!(u32_to_unit_f32(u32::MAX) < 1.0);
    assert_eq!(u32_to_unit_f32(0), 0.0);
    assert_eq!(u32_to_unit_f32(1 << 31), 0.5);
}

#[test]
fn samplers_are_pure_functions() {
    for kind in KINDS {
        let (a, b) = (Sampler::new(kind, 42), Sampler::new(kind, 42));
        let args: Vec<(u32, u32, u32)> =
            (0..2000).map(|k| (k % 13 * 7919, k / 13, k % 9)).collect();
        let forward: Vec<Vec2> = args.iter().map(|&(p, i, d)| a.get_2d(p, i, d)).collect();
        // A second sampler, in reverse order, interleaved with other calls.
        for (k, &(p, i, d)) in args.iter().enumerate().rev() {
            let _ = b.get_1d(p ^ 5, i + 1, d + 3);
            assert_eq!(b.get_2d(p, i, d), forward[k], "{kind:?}");
            assert_eq!(b.get_1d(p, i, d), a.get_1d(p, i, d), "{kind:?}");
        }
        // Another seed gives other samples.
        let c = Sampler::new(kind, 43);
        let same = args
            .iter()
            .filter(|&&(p, i, d)| c.get_2d(p, i, d) == a.get_2d(p, i, d))
            .count();
        assert!(same == 0, "{kind:?}: {same} samples unchanged by the seed");
    }
}

#[test]
fn dimension_conventions() {
    let sobol = Sampler::new(SamplerKind::Sobol, 3);
    let indep = Sampler::new(SamplerKind::Independent, 3);
    for (p, i, d) in [(0, 0, 0), (5, 17, 3), (1000, 255, 40)] {
        // Sobol: the 1-D sample is the first coordinate of the 2-D one.
        assert_eq!(sobol.get_1d(p, i, d), sobol.get_2d(p, i, d).x);
        // Independent: a 2-D sample is two consecutive dimensions.
        assert_eq!(
            indep.get_2d(p, i, d),
            Vec2::new(indep.get_1d(p, i, d), indep.get_1d(p, i, d + 1))
        );
    }
}

/// Chi-square of `get_2d` over a 16 × 16 grid, pooled over pixels, dims and
/// a non-power-of-two run of indices not starting at 0, so per-pixel
/// stratification alone cannot make it pass.
fn sampler_uniformity_2d(kind: SamplerKind, tests: usize) -> Result<common::chi2::Outcome, String> {
    let s = Sampler::new(kind, 11);
    let (pixels, dims, spp) = (512u32, 6u32, 37u32);
    let mut k = 0u32;
    let sample = move |_| {
        let (p, rest) = (k % pixels, k / pixels);
        let (i, d) = (5 + rest % spp, rest / spp);
        k += 1;
        Some(s.get_2d(p * 7 + 3, i, 2 * d + 1))
    };
    Chi2::new((pixels * dims * spp) as usize, 0)
        .res(16, 16)
        .tests(tests)
        .planar(Vec2::ZERO, Vec2::ONE, sample, |_| 1.0)
}

fn sampler_uniformity_1d(kind: SamplerKind, tests: usize) -> Result<common::chi2::Outcome, String> {
    let s = Sampler::new(kind, 12);
    let (pixels, dims, spp) = (512u32, 6u32, 37u32);
    let mut k = 0u32;
    let sample = move |_| {
        let (p, rest) = (k % pixels, k / pixels);
        let (i, d) = (3 + rest % spp, rest / spp);
        k += 1;
        Some(s.get_1d(p, i, d * 3))
    };
    Chi2::new((pixels * dims * spp) as usize, 0)
        .res(64, 1)
        .tests(tests)
        .linear(0.0, 1.0, sample, |_| 1.0)
}

#[test]
fn samplers_are_uniform() {
    for kind in KINDS {
        assert_passes(sampler_uniformity_2d(kind, 4));
        assert_passes(sampler_uniformity_1d(kind, 4));
    }
}

#[test]
fn sobol_is_uniform_across_pixels_at_a_fixed_index() {
    // Nothing stratifies sample i of different pixels: this isolates the
    // quality of the per-pixel shuffle and scramble hashes.
    let s = Sampler::new(SamplerKind::Sobol, 13);
    let cases = [(0u32, 0u32), (1, 0), (7, 2), (64, 9), (1000, 1)];
    for &(index, dim) in &cases {
        let mut pixel = 0;
        let sample = |_| {
            pixel += 1;
            Some(s.get_2d(pixel, index, dim))
        };
        assert_passes(Chi2::new(200_000, 0).res(16, 16).tests(cases.len()).planar(
            Vec2::ZERO,
            Vec2::ONE,
            sample,
            |_| 1.0,
        ));
    }
}

/// Whether points `block·2^k .. (block+1)·2^k` put exactly one point in each
/// elementary interval of shape 2^-a × 2^-b for every a + b = k.
fn is_0k2_net(s: &Sampler, pixel: u32, dim: u32, k: u32, block: u32) -> bool {
    let n = 1u32 << k;
    let pts: Vec<Vec2> = (0..n)
        .map(|i| s.get_2d(pixel, block * n + i, dim))
        .collect();
    (0..=k).all(|a| {
        let b = k - a;
        let mut seen = vec![false; n as usize];
        pts.iter().all(|p| {
            // Exact: scaling by a power of two and flooring lose nothing.
            let cx = (p.x * (1u32 << a) as f32) as u32;
            let cy = (p.y * (1u32 << b) as f32) as u32;
            !std::mem::replace(&mut seen[(cy << a | cx) as usize], true)
        })
    })
}

#[test]
fn sobol_prefixes_are_0k2_nets() {
    let s = Sampler::new(SamplerKind::Sobol, 21);
    for pixel in [0, 1, 12_345, u32::MAX] {
        for dim in [0, 1, 2, 7, 100] {
            for k in 0..=8 {
                for block in [0, 1, 5] {
                    assert!(
                        is_0k2_net(&s, pixel, dim, k, block),
                        "pixel {pixel} dim {dim} k {k} block {block}"
                    );
                }
            }
        }
    }
    // The check has teeth: independent samples are not nets.
    let indep = Sampler::new(SamplerKind::Independent, 21);
    assert!(!(0..4).any(|p| is_0k2_net(&indep, p, 0, 6, 0)));
}

#[test]
fn sobol_1d_prefixes_are_stratified() {
    let s = Sampler::new(SamplerKind::Sobol, 22);
    for pixel in [0, 3, 77_777] {
        for dim in [0, 1, 9] {
            for k in 0..=12 {
                let n = 1u32 << k;
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let cell = (s.get_1d(pixel, i, dim) * n as f32) as usize;
                    assert!(
                        !std::mem::replace(&mut seen[cell], true),
                        "pixel {pixel} dim {dim} k {k}"
                    );
                }
            }
        }
    }
}

/// Pearson correlation of two equally long sequences.
fn correlation(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        let (dx, dy) = (f64::from(x) - ma, f64::from(y) - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    sab / (saa * sbb).sqrt()
}

#[test]
fn different_pixels_and_dimensions_are_decorrelated() {
    // For independent sequences the sample correlation has variance ≈ 1/n:
    // each pair must stay within 6σ, and the mean square over all pairs
    // within twice its expectation.
    let n = 1024u32;
    for kind in KINDS {
        let s = Sampler::new(kind, 23);
        let seq = |pixel: u32, dim: u32, second: bool| -> Vec<f32> {
            (0..n)
                .map(|i| {
                    let p = s.get_2d(pixel, i, dim);
                    if second { p.y } else { p.x }
                })
                .collect()
        };
        let mut pairs = Vec::new();
        for p in 0..16 {
            let base = seq(p, 0, false);
            pairs.push((base.clone(), seq(p + 1, 0, false))); // neighbour pixel
            pairs.push((base.clone(), seq(p + 1000, 0, false))); // far pixel
            pairs.push((base.clone(), seq(p, 2, false))); // next 2-D dimension
            pairs.push((base.clone(), seq(p, 1, false))); // overlapping dimension
            pairs.push((base.clone(), seq(p, 0, true))); // the other coordinate
            pairs.push((seq(p, 0, true), seq(p, 2, true)));
        }
        let bound = 6.0 / f64::from(n).sqrt();
        let mut mean_sq = 0.0;
        for (a, b) in &pairs {
            let r = correlation(a, b);
            assert!(r.abs() < bound, "{kind:?}: correlation {r}");
            assert!(a != b, "{kind:?}: identical sequences");
            mean_sq += r * r / pairs.len() as f64;
        }
        assert!(mean_sq < 2.0 / f64::from(n), "{kind:?}: mean r² {mean_sq}");
    }
}

#[test]
fn independent_dimensions_differ() {
    let s = Sampler::new(SamplerKind::Independent, 24);
    let (mut equal, mut total) = (0, 0);
    for pixel in 0..64 {
        for index in 0..64 {
            let v: Vec<f32> = (0..16).map(|d| s.get_1d(pixel, index, d)).collect();
            for w in v.windows(2) {
                equal += usize::from(w[0] == w[1]);
                total += 1;
            }
        }
    }
    // Two independent 24-bit values coincide with probability 2⁻²⁴.
    assert!(
        equal <= 1,
        "{equal} of {total} consecutive dimensions equal"
    );
}

#[test]
fn sobol_converges_faster_than_independent() {
    // Mean of a smooth integrand over [0,1)² with 256 samples per pixel:
    // scrambled Sobol is unbiased with error falling ~N^-1.5 versus N^-0.5.
    let f = |p: Vec2| f64::from((3.0 * p.x).sin() * (-p.y * p.y).exp() + p.x * p.y);
    // ∫₀¹ sin 3x dx · ∫₀¹ e^{-y²} dy + 1/4.
    let exact = (1.0 - 3f64.cos()) / 3.0 * 0.746_824_132_812_427 + 0.25;
    let rmse = |kind| {
        let s = Sampler::new(kind, 25);
        let (pixels, spp) = (256u32, 256u32);
        let mut sq = 0.0;
        let mut bias = 0.0;
        for pixel in 0..pixels {
            let est = (0..spp).map(|i| f(s.get_2d(pixel, i, 4))).sum::<f64>() / f64::from(spp);
            sq += (est - exact).powi(2);
            bias += (est - exact) / f64::from(pixels);
        }
        ((sq / f64::from(pixels)).sqrt(), bias)
    };
    let (sobol, sobol_bias) = rmse(SamplerKind::Sobol);
    let (indep, _) = rmse(SamplerKind::Independent);
    assert!(
        sobol < 0.1 * indep,
        "Sobol RMSE {sobol} vs independent {indep}"
    );
    // Mean over 256 pixels is within 5 standard errors of the truth.
    assert!(
        sobol_bias.abs() < 5.0 * sobol / 16.0,
        "Sobol bias {sobol_bias}"
    );
}
