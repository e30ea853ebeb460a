//! Homogeneous media: transmittance, free-flight and equiangular distance sampling,
//! the Henyey–Greenstein phase function and the survival-probability mapping.

mod common;

use std::f64::consts::PI;

use common::chi2::{Chi2, Outcome, integrate_directions, uniform_1d, uniform_2d};
use glam::{Vec2, Vec3};
use prism::medium::*;
use rand::{Rng, RngExt};
use rand_pcg::Pcg32;

/// Samples per chi-square test.
const N: usize = 1_000_000;

fn rng(seed: u64) -> Pcg32 {
    Pcg32::new(seed, 0x1405_7b7e_f767_814f)
}

fn assert_passes(result: Result<Outcome, String>) -> Outcome {
    result.unwrap_or_else(|e| panic!("{e}"))
}

/// Adaptive Simpson on [a, b] in f64, for pdfs with narrow peaks.
fn integrate_1d(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        (b - a) / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b))
    }
    fn go(f: &dyn Fn(f64) -> f64, a: f64, b: f64, whole: f64, tol: f64, depth: u32) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (simpson(f, a, m), simpson(f, m, b));
        if depth == 0 || (l + r - whole).abs() <= 15.0 * tol {
            l + r + (l + r - whole) / 15.0
        } else {
            go(f, a, m, l, 0.5 * tol, depth - 1) + go(f, m, b, r, 0.5 * tol, depth - 1)
        }
    }
    // Start from 64 pieces so a narrow peak cannot hide between the first nodes.
    let h = (b - a) / 64.0;
    (0..64)
        .map(|i| {
            let (x0, x1) = (a + h * f64::from(i), a + h * f64::from(i + 1));
            go(f, x0, x1, simpson(f, x0, x1), 1e-10, 30)
        })
        .sum()
}

// ---------------------------------------------------------- transmittance

#[test]
fn transmittance_is_beer_lambert() {
    let sigmas = [0.0f32, 1e-6, 1e-3, 1.0, 10.0, 1e3, 1e6];
    let ds = [0.0f32, 1e-7, 1e-3, 0.5, 1.0, 7.0, 1e3, 1e7, f32::INFINITY];
    for &s in &sigmas {
        // Pure absorption, pure scattering and an even split give the same σt exactly.
        let m = HomogeneousMedium::new(Vec3::new(s, 0.0, 0.5 * s), Vec3::new(0.0, s, 0.5 * s), 0.0);
        assert_eq!(m.sigma_t(), Vec3::splat(s));
        for &d in &ds {
            let want = if s == 0.0 || d == 0.0 {
                1.0
            } else {
                (-(f64::from(s) * f64::from(d))).exp()
            };
            let tr = m.transmittance(d);
            for got in tr.to_array() {
                assert!(
                    got.is_finite() && (0.0..=1.0).contains(&got),
                    "Tr = {got} for σt = {s}, d = {d}"
                );
                let err = (f64::from(got) - want).abs();
                assert!(
                    err <= 1e-6 * want + 1e-30,
                    "Tr = {got}, want {want} for σt = {s}, d = {d}"
                );
            }
        }
    }
    // The 0·∞ rule, spelled out.
    let clear = HomogeneousMedium::new(Vec3::ZERO, Vec3::ZERO, 0.0);
    assert_eq!(clear.transmittance(f32::INFINITY), Vec3::ONE);
    let thin = HomogeneousMedium::new(Vec3::splat(1e-6), Vec3::ZERO, 0.0);
    assert_eq!(thin.transmittance(f32::INFINITY), Vec3::ZERO);
    let dense = HomogeneousMedium::new(Vec3::splat(1e6), Vec3::ZERO, 0.0);
    assert_eq!(dense.transmittance(0.0), Vec3::ONE);
    // Slabs compose: Tr(a + b) = Tr(a) Tr(b).
    let m = HomogeneousMedium::new(Vec3::new(0.1, 0.5, 2.0), Vec3::new(0.3, 0.2, 1.0), 0.0);
    let (a, b) = (0.75, 1.25);
    let d = (m.transmittance(a + b) - m.transmittance(a) * m.transmittance(b)).abs();
    assert!(d.max_element() < 1e-6, "{d}");
}

// ------------------------------------------------------------ free flight

/// Monte Carlo means of the pass and scatter weights.
fn free_flight_means(
    m: &HomogeneousMedium,
    t_max: f32,
    probs: Vec3,
    n: usize,
    seed: u64,
) -> [Vec3; 2] {
    let mut r = rng(seed);
    let (mut pass, mut scatter) = ([0f64; 3], [0f64; 3]);
    for _ in 0..n {
        let uc = uniform_1d(&mut r);
        let u = uniform_1d(&mut r);
        let (acc, w) = match m.sample_distance(t_max, uc, u, probs) {
            DistanceSample::Pass { weight } => (&mut pass, weight),
            DistanceSample::Scatter { t, weight } => {
                assert!(
                    (0.0..t_max).contains(&t),
                    "scatter at {t} outside [0, {t_max})"
                );
                (&mut scatter, weight)
            }
        };
        assert!(w.is_finite() && w.min_element() >= 0.0, "weight {w}");
        for k in 0..3 {
            acc[k] += f64::from(w[k]);
        }
    }
    let mean = |a: [f64; 3]| Vec3::from_array(a.map(|x| (x / n as f64) as f32));
    [mean(pass), mean(scatter)]
}

#[test]
fn free_flight_estimators_are_unbiased() {
    let t_max = 1.5;
    let cases = [
        // Chromatic, uniform channel choice.
        (
            Vec3::new(0.05, 0.3, 1.2),
            Vec3::new(0.05, 0.5, 0.8),
            Vec3::splat(1.0 / 3.0),
        ),
        // Channel choice from a throughput.
        (
            Vec3::new(0.05, 0.3, 1.2),
            Vec3::new(0.05, 0.5, 0.8),
            channel_probabilities_rgb(Vec3::new(0.7, 0.2, 0.1)),
        ),
        // A channel never chosen is still covered by the others.
        (
            Vec3::new(0.05, 0.3, 1.2),
            Vec3::new(0.05, 0.5, 0.8),
            Vec3::new(0.5, 0.5, 0.0),
        ),
        // Dense, ordinary and empty channels side by side.
        (
            Vec3::new(5e5, 0.2, 0.0),
            Vec3::new(5e5, 0.3, 0.0),
            Vec3::splat(1.0 / 3.0),
        ),
    ];
    for (i, &(sa, ss, probs)) in cases.iter().enumerate() {
        let m = HomogeneousMedium::new(sa, ss, 0.0);
        let st = m.sigma_t();
        let [pass, scatter] = free_flight_means(&m, t_max, probs, N, 100 + i as u64);
        for k in 0..3 {
            let (s_t, s_s) = (f64::from(st[k]), f64::from(ss[k]));
            let tr = (-s_t * f64::from(t_max)).exp();
            // ∫₀^t_max σs e^{−σt t} dt = σs/σt (1 − Tr(t_max)).
            let in_scatter = if s_t == 0.0 {
                0.0
            } else {
                s_s / s_t * (1.0 - tr)
            };
            let close = |got: f32, want: f64| (f64::from(got) - want).abs() <= 0.01 * want + 1e-9;
            assert!(
                close(pass[k], tr),
                "case {i} channel {k}: pass mean {} vs Tr {tr}",
                pass[k]
            );
            assert!(
                close(scatter[k], in_scatter),
                "case {i} channel {k}: scatter mean {} vs {in_scatter}",
                scatter[k]
            );
        }
    }
}

fn channel_probabilities_rgb(beta: Vec3) -> Vec3 {
    Vec3::from_array(channel_probabilities(beta.to_array()))
}

/// Uniform numbers at both ends of [0, 1) and between.
const U_EXTREMES: [f32; 5] = [
    0.0,
    1e-7,
    0.5,
    1.0 - 1.0 / 16_777_216.0,
    1.0 - f32::EPSILON / 2.0,
];

#[test]
fn free_flight_is_finite_in_extreme_media() {
    let mut r = rng(200);
    let probs = Vec3::splat(1.0 / 3.0);
    // σt = 0: every flight passes with weight 1, however long.
    let clear = HomogeneousMedium::new(Vec3::ZERO, Vec3::ZERO, 0.3);
    for t_max in [0.0, 1.0, 1e30, f32::INFINITY] {
        for _ in 0..1000 {
            let s = clear.sample_distance(t_max, uniform_1d(&mut r), uniform_1d(&mut r), probs);
            assert_eq!(s, DistanceSample::Pass { weight: Vec3::ONE });
        }
        assert_eq!(clear.pass_probability(t_max, probs), 1.0);
        assert_eq!(clear.distance_pdf(0.5, probs), 0.0);
    }
    // σt = 1e6, mixed with thin and empty channels, at the extremes of u.
    let us = U_EXTREMES;
    let media = [
        HomogeneousMedium::new(Vec3::splat(5e5), Vec3::splat(5e5), 0.0),
        HomogeneousMedium::new(Vec3::new(1e6, 1e-3, 0.0), Vec3::new(0.0, 1e-3, 0.0), 0.0),
        HomogeneousMedium::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1e6, 0.0, 0.0), 0.0),
    ];
    let prob_sets = [
        probs,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1e-7, 1.0),
        Vec3::ZERO,
    ];
    for m in &media {
        for &p in &prob_sets {
            for t_max in [0.0, 1e-7, 1.0, 1e4, f32::INFINITY] {
                for &uc in &us {
                    for &u in &us {
                        let s = m.sample_distance(t_max, uc, u, p);
                        assert!(
                            s.weight().is_finite() && s.weight().min_element() >= 0.0,
                            "{s:?} for {m:?}, probs {p}, t_max {t_max}, u ({uc}, {u})"
                        );
                        if let DistanceSample::Scatter { t, .. } = s {
                            assert!(t.is_finite() && (0.0..t_max).contains(&t));
                        }
                    }
                }
                let pp = m.pass_probability(t_max, p);
                assert!((0.0..=1.0).contains(&pp), "pass probability {pp}");
                assert!(m.distance_pdf(t_max.min(1.0), p).is_finite());
            }
        }
    }
}

#[test]
fn free_flight_distances_match_pdf() {
    // Scatter events are histogrammed over [0, t_max]; passes land in the harness's extra
    // cell, whose expected count is 1 − ∫pdf = the pass probability.
    let cases = [
        (Vec3::new(0.1, 0.8, 2.0), Vec3::splat(1.0 / 3.0), 2.0),
        (Vec3::new(0.1, 0.8, 2.0), Vec3::new(0.6, 0.1, 0.3), 2.0),
        (Vec3::new(40.0, 0.0, 0.5), Vec3::new(0.4, 0.3, 0.3), 3.0),
    ];
    for (i, &(st, probs, t_max)) in cases.iter().enumerate() {
        let m = HomogeneousMedium::new(0.25 * st, 0.75 * st, 0.0);
        let mut channel_rng = rng(300 + i as u64);
        let outcome = assert_passes(
            Chi2::new(N, 310 + i as u64)
                .res(64, 1)
                .tests(cases.len())
                .linear(
                    0.0,
                    t_max,
                    |u| match m.sample_distance(t_max, uniform_1d(&mut channel_rng), u, probs) {
                        DistanceSample::Scatter { t, .. } => Some(t),
                        DistanceSample::Pass { .. } => None,
                    },
                    |t| m.distance_pdf(t, probs),
                ),
        );
        let pass = f64::from(m.pass_probability(t_max, probs));
        assert!(
            (outcome.integral + pass - 1.0).abs() < 1e-5,
            "∫pdf = {} but pass probability {pass}",
            outcome.integral
        );
    }
}

#[test]
fn channel_probabilities_follow_throughput() {
    let p = channel_probabilities([2.0f32, 1.0, 1.0]);
    assert_eq!(p, [0.5, 0.25, 0.25]);
    assert_eq!(channel_probabilities([0.0f32; 3]), [1.0 / 3.0; 3]);
    assert_eq!(
        channel_probabilities([f32::NAN, -1.0, 4.0]),
        [0.0, 0.0, 1.0]
    );
    assert_eq!(channel_probabilities([0.0f32; 4]), [0.25; 4]);
    // Four channels run through the same estimator: u_channel = 0.99 picks the empty
    // channel 3, which never scatters, so the flight passes.
    let st = [1.0f32, 2.0, 3.0, 0.0];
    let DistanceSample::Pass { weight } =
        sample_free_flight([0.5; 4], st, 10.0, 0.99, 0.3, [0.25; 4])
    else {
        panic!("the empty channel cannot scatter");
    };
    let tr = st.map(|s| (-10.0 * f64::from(s)).exp());
    let pass: f64 = tr.iter().sum::<f64>() / 4.0;
    for k in 0..4 {
        let want = tr[k] / pass;
        assert!(
            (f64::from(weight[k]) - want).abs() <= 1e-6 * want,
            "{weight:?}"
        );
    }
}

// ---------------------------------------------------------- Henyey–Greenstein

const GS: [f32; 5] = [-0.9, -0.3, 0.0, 0.3, 0.9];

/// Outgoing directions for the tests: the lobe's peak on +z for |g| = 0.9 (where the
/// harness bins 1 − cos θ finely), oblique otherwise to exercise the frame.
fn wo_for(g: f32) -> Vec3 {
    if g >= 0.9 {
        -Vec3::Z
    } else if g <= -0.9 {
        Vec3::Z
    } else {
        Vec3::new(0.3, -0.5, 0.8).normalize()
    }
}

#[test]
fn hg_sampling_matches_pdf() {
    for (i, &g) in GS.iter().enumerate() {
        let wo = wo_for(g);
        assert_passes(Chi2::new(N, 400 + i as u64).tests(GS.len()).directions(
            [0.0, 2.0],
            |u| {
                let (wi, pdf) = sample_hg(wo, g, u);
                let want = hg_phase_dirs(wo, wi, g);
                assert!(
                    (pdf - want).abs() <= 1e-4 * want,
                    "pdf {pdf} vs phase {want} at g = {g}"
                );
                Some(wi)
            },
            |wi| hg_phase_dirs(wo, wi, g),
        ));
    }
}

#[test]
fn hg_mean_cosine_is_g() {
    let n = 1_000_000;
    for (i, &g) in GS.iter().chain(&[0.99, -0.99, 1e-4]).enumerate() {
        let wo = Vec3::new(-0.6, 0.0, 0.8);
        let mut r = rng(500 + i as u64);
        let sum: f64 = (0..n)
            .map(|_| f64::from(-wo.dot(sample_hg(wo, g, uniform_2d(&mut r)).0)))
            .sum();
        let mean = sum / n as f64;
        // Var(cos θ) = (1 − g²)/3 for HG (its second Legendre moment is g²).
        let sigma = ((1.0 - f64::from(g).powi(2)) / 3.0 / n as f64).sqrt();
        assert!(
            (mean - f64::from(g)).abs() <= 3.0 * sigma + 1e-6,
            "g = {g}: mean cos θ = {mean} ± {sigma}"
        );
    }
}

#[test]
fn hg_pdf_integrates_to_one() {
    // Pieces in 1 − cos θ refine where strongly peaked lobes put their mass.
    let pieces = [
        0.0, 1e-6, 1e-4, 1e-2, 0.1, 0.5, 1.0, 1.5, 1.9, 1.99, 1.9999, 2.0,
    ];
    for &g in GS.iter().chain(&[0.99, -0.99, 0.999, -0.999, 1e-5]) {
        let wo = -Vec3::Z;
        let total: f64 = pieces
            .windows(2)
            .map(|w| integrate_directions(|wi| hg_phase_dirs(wo, wi, g), [w[0], w[1]], [16, 4]))
            .sum();
        assert!((total - 1.0).abs() < 1e-4, "g = {g}: ∫p = {total}");
        // And against the textbook formula away from the peak.
        for c in [-0.7f32, 0.0, 0.4] {
            let (gd, cd) = (f64::from(g), f64::from(c));
            let want = (1.0 - gd * gd) / (4.0 * PI * (1.0 + gd * gd - 2.0 * gd * cd).powf(1.5));
            let got = f64::from(hg_phase(c, g));
            assert!(
                (got - want).abs() <= 1e-5 * want,
                "g = {g}, cos = {c}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn hg_extreme_g_is_finite() {
    let wos = [Vec3::Z, -Vec3::Z, Vec3::new(0.48, -0.6, 0.64)];
    let us = [
        0.0,
        1e-7,
        0.25,
        0.5,
        0.999,
        1.0 - 2f32.powi(-24),
        1.0 - f32::EPSILON / 2.0,
    ];
    for g in [0.999f32, -0.999, 1e-5, -1e-5, 0.0, 1.0, -1.0] {
        for wo in wos {
            for &ux in &us {
                for &uy in &us {
                    let (wi, pdf) = sample_hg(wo, g, Vec2::new(ux, uy));
                    assert!(
                        wi.is_finite() && (wi.length() - 1.0).abs() < 1e-5,
                        "g = {g}: wi = {wi}"
                    );
                    assert!(pdf.is_finite() && pdf > 0.0, "g = {g}: pdf {pdf}");
                    // At |g| = 1 (clamped to HG_G_MAX) the lobe is ~1e-6 rad wide, below
                    // what f32 directions resolve, so only finiteness is checked there.
                    if g.abs() < 1.0 {
                        let p = hg_phase_dirs(wo, wi, g);
                        assert!(
                            (pdf - p).abs() <= 1e-3 * p,
                            "g = {g}: pdf {pdf} vs phase {p}"
                        );
                    }
                }
            }
        }
        for c in [-1.0f32, -0.5, 0.0, 0.5, 1.0] {
            let p = hg_phase(c, g);
            assert!(p.is_finite() && p > 0.0, "g = {g}, cos = {c}: {p}");
        }
    }
    // The convention: forward scattering sends wi along −wo.
    let wo = Vec3::new(0.0, 0.6, 0.8);
    assert!(hg_phase_dirs(wo, -wo, 0.8) > 100.0 * hg_phase_dirs(wo, wo, 0.8));
    assert_eq!(hg_phase(0.3, 0.0), hg_phase(-0.9, 0.0));
}

// ----------------------------------------------------------------- equiangular

struct EquiCase {
    name: &'static str,
    o: Vec3,
    d: Vec3,
    t0: f32,
    t1: f32,
    light: Vec3,
}

fn equi_cases() -> Vec<EquiCase> {
    let diag = Vec3::new(1.0, 2.0, -0.5).normalize();
    let o = Vec3::new(1.0, -2.0, 0.5);
    let side = diag.cross(Vec3::Z).normalize();
    let case = |name, o, d, t0, t1, light| EquiCase {
        name,
        o,
        d,
        t0,
        t1,
        light,
    };
    vec![
        case(
            "beside",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            10.0,
            Vec3::new(3.0, 1.0, 0.0),
        ),
        case(
            "beside, oblique ray",
            o,
            diag,
            0.5,
            8.0,
            o + 4.0 * diag + 0.3 * side,
        ),
        case(
            "in front",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            10.0,
            Vec3::new(14.0, 0.5, 0.0),
        ),
        case(
            "behind",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            10.0,
            Vec3::new(-4.0, 0.7, 0.2),
        ),
        case(
            "in front, near the line",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            10.0,
            Vec3::new(12.0, 1e-6, 0.0),
        ),
        case(
            "behind, on the line",
            Vec3::ZERO,
            Vec3::X,
            1.0,
            10.0,
            Vec3::new(-2.0, 0.0, 0.0),
        ),
        case(
            "beside, infinite segment",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            f32::INFINITY,
            Vec3::new(3.0, 1.0, 0.0),
        ),
        case(
            "behind, infinite segment",
            Vec3::ZERO,
            Vec3::X,
            0.0,
            f32::INFINITY,
            Vec3::new(-1.0, 0.5, 0.0),
        ),
    ]
}

#[test]
fn equiangular_matches_pdf() {
    let cases = equi_cases();
    for (i, c) in cases.iter().enumerate() {
        // Infinite segments are histogrammed over a finite stretch; the tail goes to the
        // harness's extra cell.
        let hi = if c.t1.is_finite() { c.t1 } else { 60.0 };
        let outcome = Chi2::new(N / 2, 600 + i as u64)
            .res(64, 1)
            .tests(cases.len())
            .linear(
                c.t0,
                hi,
                |u| {
                    let (t, pdf) = sample_equiangular(c.o, c.d, c.t0, c.t1, c.light, u)?;
                    assert!(t >= c.t0 && t <= c.t1, "{}: t = {t}", c.name);
                    let want = equiangular_pdf(c.o, c.d, c.t0, c.t1, c.light, t);
                    assert_eq!(pdf, want, "{}", c.name);
                    Some(t)
                },
                |t| equiangular_pdf(c.o, c.d, c.t0, c.t1, c.light, t),
            );
        if let Err(e) = outcome {
            panic!("{}: {e}", c.name);
        }
    }
}

#[test]
fn equiangular_pdf_integrates_to_one() {
    for c in equi_cases() {
        let pdf = |t: f64| f64::from(equiangular_pdf(c.o, c.d, c.t0, c.t1, c.light, t as f32));
        let total = if c.t1.is_finite() {
            integrate_1d(&pdf, c.t0.into(), c.t1.into())
        } else {
            // Substitute t = t0 + x / (1 − x) to fold [t0, ∞) onto [0, 1).
            let t0 = f64::from(c.t0);
            integrate_1d(
                &|x: f64| {
                    let w = 1.0 - x;
                    if w <= 0.0 {
                        0.0
                    } else {
                        pdf(t0 + x / w) / (w * w)
                    }
                },
                0.0,
                1.0,
            )
        };
        assert!((total - 1.0).abs() < 1e-4, "{}: ∫pdf = {total}", c.name);
    }
}

#[test]
fn equiangular_near_the_line() {
    // The light a hair off the segment: the density is a spike of width D at the foot, but
    // every sample stays finite and inside, and the angle at the light stays uniform. The
    // foot sits at t = 0, where f32 resolves even D = 1e-7; elsewhere the returned t is
    // quantized to its f32 spacing, which says nothing about the sampler.
    for (i, d_perp) in [1e-3f32, 1e-5, 1e-7].into_iter().enumerate() {
        let (t0, t1) = (-4.0f32, 6.0f32);
        let light = Vec3::new(0.0, d_perp, 0.0);
        let e = Equiangular::new(Vec3::ZERO, Vec3::X, t0, t1, light).expect("proper density");
        // CDF in closed form (f64): the fraction of the subtended angle swept.
        let d = f64::from(d_perp);
        let angle = |t: f64| (t / d).atan();
        let cdf = |t: f32| {
            (angle(f64::from(t)) - angle(t0.into())) / (angle(t1.into()) - angle(t0.into()))
        };
        assert_passes(Chi2::new(N / 4, 700 + i as u64).res(64, 1).tests(3).linear(
            0.0,
            1.0,
            |u| {
                let (t, pdf) = e.sample(u);
                assert!(
                    t >= t0 && t <= t1 && pdf.is_finite() && pdf > 0.0,
                    "t {t} pdf {pdf}"
                );
                Some(cdf(t) as f32)
            },
            |_| 1.0,
        ));
        let peak = e.pdf(0.0);
        assert!(peak.is_finite() && (f64::from(peak) * PI * d - 1.0).abs() < 1e-3);
        let pdf = |t: f64| f64::from(e.pdf(t as f32));
        let total = integrate_1d(&pdf, t0.into(), 0.0) + integrate_1d(&pdf, 0.0, t1.into());
        assert!((total - 1.0).abs() < 1e-4, "D = {d_perp}: ∫pdf = {total}");
        // Away from t = 0 the spike is narrower than the f32 grid, yet stays finite.
        let light = Vec3::new(4.0, d_perp, 0.0);
        let e = Equiangular::new(Vec3::ZERO, Vec3::X, 0.0, 10.0, light).unwrap();
        for k in 0..=1000 {
            let (t, pdf) = e.sample(k as f32 / 1000.0);
            assert!((0.0..=10.0).contains(&t) && pdf.is_finite() && pdf > 0.0);
        }
    }
    // Exactly on the segment there is no density.
    let on = Vec3::new(4.0, 0.0, 0.0);
    assert!(sample_equiangular(Vec3::ZERO, Vec3::X, 0.0, 10.0, on, 0.5).is_none());
    assert!(sample_equiangular(Vec3::ZERO, Vec3::X, 4.0, 10.0, on, 0.5).is_none());
    assert_eq!(
        equiangular_pdf(Vec3::ZERO, Vec3::X, 0.0, 10.0, on, 3.0),
        0.0
    );
    // Empty segments.
    assert!(sample_equiangular(Vec3::ZERO, Vec3::X, 2.0, 2.0, Vec3::Y, 0.5).is_none());
    // Extreme u on a far, nearly collinear light still lands inside.
    let far = Vec3::new(-1e4, 1e-4, 0.0);
    let mut r = rng(710);
    for u in [0.0, 1e-7, 0.5, 1.0 - f32::EPSILON / 2.0, 1.0]
        .into_iter()
        .chain((0..1000).map(|_| r.next_u32() as f32 / 4_294_967_296.0))
    {
        for t1 in [10.0, f32::INFINITY] {
            let (t, pdf) = sample_equiangular(Vec3::ZERO, Vec3::X, 0.0, t1, far, u).unwrap();
            assert!(t.is_finite() && (0.0..=t1).contains(&t), "u {u}: t {t}");
            assert!(pdf.is_finite() && pdf > 0.0, "u {u}: pdf {pdf}");
        }
    }
}

// ------------------------------------------------------------------ survival

#[test]
fn survival_mapping_reproduces_probabilities() {
    let pa = Vec3::new(0.9, 0.5, 1.0);
    let ps = Vec3::new(0.99, 0.7, 0.2);
    let m = from_survival(pa, ps, 0.4);
    assert_eq!(m.g, -0.4);
    assert_eq!(m.sigma_a.z, 0.0);
    assert!(m.is_valid());
    let want = pa * ps;
    let per_unit = m.transmittance(1.0);
    assert!(
        (per_unit - want).abs().max_element() < 1e-6,
        "{per_unit} vs {want}"
    );
    // Absorption and scattering survive separately.
    let only_abs = HomogeneousMedium::new(m.sigma_a, Vec3::ZERO, 0.0);
    assert!((only_abs.transmittance(1.0) - pa).abs().max_element() < 1e-6);
    // Over three units, the probabilities compound.
    assert!((m.transmittance(3.0) - want.powf(3.0)).abs().max_element() < 1e-6);
    // Strength limits: no back-scatter is isotropic, full back-scatter retro-reflects.
    assert_eq!(from_survival(pa, ps, 0.0).g, 0.0);
    let retro = from_survival(pa, ps, 1.0);
    let wo = Vec3::Z;
    assert!(retro.phase(wo, wo) > 1e6 * retro.phase(wo, -wo));
    // A zero survival probability is opaque but finite.
    let opaque = from_survival(Vec3::ZERO, Vec3::ONE, 0.0);
    assert!(opaque.is_valid() && opaque.transmittance(1.0).max_element() < 1e-30);
}

/// The integrators' f32 lane estimators against the f64 ones: the same decision, distance
/// and weights to f32 accuracy, over random media and the extremes above.
#[test]
fn lane_free_flight_matches_the_f64_estimator() {
    let mut r = rng(201);
    // (σa, σs, β, t_max, u_channel, u)
    type Case = ([f32; 3], [f32; 3], [f32; 3], f32, f32, f32);
    let mut cases: Vec<Case> = Vec::new();
    let us = U_EXTREMES;
    let extremes = [
        ([5e5; 3], [5e5; 3]),
        ([1e6, 1e-3, 0.0], [0.0, 1e-3, 0.0]),
        ([0.0, 0.0, 1.0], [1e6, 0.0, 0.0]),
        ([0.0; 3], [0.0; 3]),
    ];
    let betas = [
        [1.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1e-7, 1.0],
        [0.0; 3],
        [f32::NAN, 1.0, -1.0],
    ];
    for (sa, ss) in extremes {
        for beta in betas {
            for t_max in [0.0, 1e-7, 1.0, 1e4, f32::INFINITY] {
                for &uc in &us {
                    for &u in &us {
                        cases.push((sa, ss, beta, t_max, uc, u));
                    }
                }
            }
        }
    }
    for _ in 0..200_000 {
        // Coefficients over twelve decades, some channels empty.
        let mut coef = || {
            if r.random::<f32>() < 0.15 {
                0.0
            } else {
                10f32.powf(r.random_range(-6.0..6.0))
            }
        };
        let sa = [coef(), coef(), coef()];
        let ss = [coef(), coef(), coef()];
        let beta = [
            r.random::<f32>(),
            r.random::<f32>(),
            r.random::<f32>() * 0.01,
        ];
        let t_max = if r.random::<f32>() < 0.1 {
            f32::INFINITY
        } else {
            10f32.powf(r.random_range(-4.0..4.0))
        };
        cases.push((sa, ss, beta, t_max, r.random(), r.random()));
    }
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-4 * b.abs() + 1e-30;
    let mut flips = 0usize;
    for (sa, ss, beta, t_max, uc, u) in cases {
        let st: [f32; 3] = std::array::from_fn(|k| sa[k] + ss[k]);
        let want = sample_free_flight(ss, st, t_max, uc, u, beta);
        let got = lanes::sample_free_flight::<f32, 3>(&ss, &st, t_max, uc, u, &beta);
        let what = format!("σs {ss:?} σt {st:?} β {beta:?} t_max {t_max} u ({uc}, {u})");
        assert!(
            got.weight.iter().all(|w| w.is_finite() && *w >= 0.0),
            "{got:?} for {what}"
        );
        match want {
            DistanceSample::Scatter { t, weight } if got.scatter => {
                assert!(close(got.t, t), "t {} vs {t} for {what}", got.t);
                for (g, w) in got.weight.iter().zip(weight) {
                    assert!(close(*g, w), "{got:?} vs {want:?} for {what}");
                }
                let pdf = free_flight_pdf(st, t, beta);
                let lane_pdf = lanes::free_flight_pdf::<f32, 3>(&st, t, &beta);
                assert!(close(lane_pdf, pdf), "pdf {lane_pdf} vs {pdf} for {what}");
            }
            DistanceSample::Pass { weight } if !got.scatter => {
                for (g, w) in got.weight.iter().zip(weight) {
                    assert!(close(*g, w), "{got:?} vs {want:?} for {what}");
                }
            }
            // The distance rounded to the other side of t_max.
            _ => {
                assert!(close(got.t, t_max), "{got:?} vs {want:?} for {what}");
                flips += 1;
            }
        }
    }
    assert!(flips <= 20, "{flips} decisions differ from f64's");
}

/// The lane Henyey–Greenstein phase function and its sampling against the scalar ones.
#[test]
fn lane_hg_matches_the_scalar_one() {
    let mut r = rng(202);
    for _ in 0..100_000 {
        let g = r.random_range(-1.0..1.0f32);
        let wo = wo_for(g * 0.37 + 0.1);
        let u = uniform_2d(&mut r);
        let (wi, pdf) = lanes::sample_hg::<f32>(wo.into(), g, u.x, u.y);
        let wi: Vec3 = wi.into();
        let (want_wi, want_pdf) = sample_hg(wo, g, u);
        // Different azimuth frames: compare the scattering angle and the densities.
        let (c, want_c) = (-wo.dot(wi), -wo.dot(want_wi));
        assert!(
            (c - want_c).abs() <= 2e-6,
            "g {g} u {u}: cos {c} vs {want_c}"
        );
        assert!(
            (pdf / want_pdf - 1.0).abs() <= 1e-5,
            "g {g}: pdf {pdf} vs {want_pdf}"
        );
        let phase = lanes::hg_phase_dirs::<f32>(wo.into(), wi.into(), g);
        let want = hg_phase_dirs(wo, wi, g);
        assert!(
            (phase / want - 1.0).abs() <= 1e-5,
            "g {g}: {phase} vs {want}"
        );
        // The density at the rounded direction: a unit vector's rounding moves 1 − cos θ by
        // ~2.4e-7, against a denominator ≥ (1 − |g|)² (≥ 0.01 here), times 3/2 from its power.
        if g.abs() <= 0.9 {
            assert!(
                (phase / pdf - 1.0).abs() <= 1e-3,
                "g {g}: phase {phase} vs pdf {pdf}"
            );
        }
    }
}
