//! Distances in a homogeneous medium: transmittance, free-flight sampling with
//! single-sample MIS over channels, and equiangular sampling towards a point light.
//!
//! The channel-generic functions work on `[f32; N]` (see the parent module for why) and
//! compute in f64: the MIS weights are ratios of exponentials whose factors span hundreds
//! of orders of magnitude between a dense and a clear channel, and f64 keeps every
//! intermediate finite and accurate for the coefficients and distances f32 can express.

use glam::{DVec3, Vec3};

/// Result of free-flight sampling; `W` is the per-channel weight (`Vec3` for RGB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DistanceSample<W = Vec3> {
    /// A real scattering event at distance `t < t_max`. `weight` = σs·Tr(t) / pdf(t)
    /// already includes σs, so only the phase function remains to be applied.
    Scatter {
        /// Distance to the event along the ray.
        t: f32,
        /// σs·Tr(t) / pdf(t) per channel.
        weight: W,
    },
    /// The flight reached `t_max`; `weight` = Tr(t_max) / P(pass).
    Pass {
        /// Tr(t_max) / P(pass) per channel.
        weight: W,
    },
}

impl<W> DistanceSample<W> {
    /// The weight of either event, per channel.
    pub fn weight(&self) -> &W {
        match self {
            Self::Scatter { weight, .. } | Self::Pass { weight } => weight,
        }
    }

    /// The same event with its weight converted (e.g. from an array to a vector type).
    pub fn map<V>(self, f: impl FnOnce(W) -> V) -> DistanceSample<V> {
        match self {
            Self::Scatter { t, weight } => DistanceSample::Scatter {
                t,
                weight: f(weight),
            },
            Self::Pass { weight } => DistanceSample::Pass { weight: f(weight) },
        }
    }
}

/// `exp(−σ·d)` with `0·∞ = 0`: an empty channel transmits everything however far, and no
/// distance transmits everything however dense. `d ≤ 0` counts as no distance; NaN
/// propagates so the caller's non-finite checks see it.
#[inline]
fn tr64(sigma_t: f64, d: f64) -> f64 {
    if sigma_t == 0.0 || d <= 0.0 {
        1.0
    } else {
        (-(sigma_t * d)).exp()
    }
}

/// f64 → f32 without overflowing to ∞: a weight of f32::MAX can only come from an event
/// of (numerically) zero probability, and multiplying it by a zero throughput must give 0,
/// not NaN.
#[inline]
fn to_f32(x: f64) -> f32 {
    x.min(f64::from(f32::MAX)) as f32
}

/// Beer–Lambert transmittance `exp(−σt·d)` per channel, exact to f32 rounding for
/// σt ∈ [0, ∞) and d ∈ [0, ∞], with `0·∞ = 0` (σt = 0 → 1 for any d).
#[inline]
pub fn transmittance_channels<const N: usize>(sigma_t: [f32; N], d: f32) -> [f32; N] {
    sigma_t.map(|s| tr64(f64::from(s), f64::from(d)) as f32)
}

/// Channel-selection probabilities proportional to the path throughput `beta` (its
/// negative or non-finite entries count as 0), or uniform when that leaves nothing.
///
/// Proportional selection concentrates samples on the channels that still carry energy;
/// the free-flight estimator is unbiased in every channel whose probability is non-zero, so
/// uniform probabilities are the safe choice when the throughput says nothing.
pub fn channel_probabilities<const N: usize>(beta: [f32; N]) -> [f32; N] {
    let clean = beta.map(|b| if b.is_finite() && b > 0.0 { b } else { 0.0 });
    let sum: f32 = clean.iter().sum();
    if sum > 0.0 && sum.is_finite() {
        clean.map(|b| b / sum)
    } else {
        [1.0 / N as f32; N]
    }
}

/// [`channel_probabilities`] in f64, the form the estimators use.
fn probs64<const N: usize>(p: [f32; N]) -> [f64; N] {
    channel_probabilities(p).map(f64::from)
}

/// Index of the channel `u ∈ [0, 1)` selects; never a channel of zero probability.
fn pick_channel<const N: usize>(p: &[f64; N], u: f32) -> usize {
    let u = f64::from(u);
    let (mut acc, mut last) = (0.0, 0);
    for (c, &pc) in p.iter().enumerate() {
        if pc > 0.0 {
            acc += pc;
            last = c;
            if u < acc {
                return c;
            }
        }
    }
    // Rounding left u at or above the total: the last eligible channel owns the top end.
    last
}

/// Free-flight sampling with single-sample MIS over channels (the homogeneous special case
/// of the spectral MIS of Miller et al. 2019, as in pbrt-v4).
///
/// Channel `c` is chosen with probability `p_c` (`channel_probs`, normalized here; see
/// [`channel_probabilities`]) using `u_channel`, and `t = −ln(1 − u) / σt_c` is drawn from
/// its exponential; an empty channel (σt_c = 0) draws `t = ∞` and so never scatters. The
/// combined density over the choice is the one-sample MIS balance heuristic:
///
/// - `t < t_max`: `Scatter { t, weight = σs·Tr(t) / Σ_c p_c σt_c Tr_c(t) }`;
/// - otherwise: `Pass { weight = Tr(t_max) / Σ_c p_c Tr_c(t_max) }`.
///
/// In expectation the scatter weight integrates σs·Tr over [0, t_max) and the pass weight
/// equals Tr(t_max), in every channel with `p_c > 0`; a channel with `p_c = 0` is covered
/// too as long as `t_max` is finite and some channel with `p_c > 0` has σt > 0. Weights are
/// finite for any σt ∈ [0, ∞): the sampled channel's own term keeps each denominator away
/// from zero.
pub fn sample_free_flight<const N: usize>(
    sigma_s: [f32; N],
    sigma_t: [f32; N],
    t_max: f32,
    u_channel: f32,
    u: f32,
    channel_probs: [f32; N],
) -> DistanceSample<[f32; N]> {
    let p = probs64(channel_probs);
    let c = pick_channel(&p, u_channel);
    let st = sigma_t.map(f64::from);
    // −ln(1 − u) via ln_1p keeps precision for small u; f64 then rounds once to f32.
    let t = if st[c] > 0.0 {
        (-(-f64::from(u)).ln_1p() / st[c]) as f32
    } else {
        f32::INFINITY
    };
    if t < t_max {
        // Evaluate at the t actually returned, so weight and event agree.
        let tr = st.map(|s| tr64(s, f64::from(t)));
        let pdf: f64 = (0..N).map(|k| p[k] * st[k] * tr[k]).sum();
        let weight = std::array::from_fn(|k| {
            let num = f64::from(sigma_s[k]) * tr[k];
            if num == 0.0 { 0.0 } else { to_f32(num / pdf) }
        });
        DistanceSample::Scatter { t, weight }
    } else {
        let tr = st.map(|s| tr64(s, f64::from(t_max)));
        let pass: f64 = (0..N).map(|k| p[k] * tr[k]).sum();
        let weight = std::array::from_fn(|k| {
            if tr[k] == 0.0 {
                0.0
            } else {
                to_f32(tr[k] / pass)
            }
        });
        DistanceSample::Pass { weight }
    }
}

/// Density per unit length of [`sample_free_flight`] drawing a scattering distance `t ≥ 0`
/// (before the comparison with `t_max`): `Σ_c p_c σt_c Tr_c(t)`.
pub fn free_flight_pdf<const N: usize>(sigma_t: [f32; N], t: f32, channel_probs: [f32; N]) -> f32 {
    if t < 0.0 {
        return 0.0;
    }
    let p = probs64(channel_probs);
    let pdf: f64 = (0..N)
        .map(|k| {
            let s = f64::from(sigma_t[k]);
            p[k] * s * tr64(s, f64::from(t))
        })
        .sum();
    to_f32(pdf)
}

/// Probability that [`sample_free_flight`] passes `t_max`: `Σ_c p_c Tr_c(t_max)`.
pub fn free_flight_pass_probability<const N: usize>(
    sigma_t: [f32; N],
    t_max: f32,
    channel_probs: [f32; N],
) -> f32 {
    let p = probs64(channel_probs);
    (0..N)
        .map(|k| p[k] * tr64(f64::from(sigma_t[k]), f64::from(t_max)))
        .sum::<f64>() as f32
}

// ------------------------------------------------------------------ equiangular

/// Largest u used, so `t1 = ∞` never yields an infinite distance.
const U_MAX: f32 = 1.0 - f32::EPSILON / 2.0;

/// Equiangular sampling (Kulla & Fajardo 2012) of a distance along a ray segment
/// `[t0, t1]` towards a point light: the density is proportional to `1 / (D² + (t − Δ)²)`,
/// the inverse squared distance to the light, where `Δ` is the parameter of the light's
/// foot on the ray and `D` its distance from the ray line. Equivalently, the angle
/// subtended at the light is uniform.
///
/// `t1` may be `+∞` (a ray leaving into an unbounded medium). With the light exactly on the
/// ray line (D = 0) the density becomes `∝ 1 / (t − Δ)²`, still proper when the light is
/// outside the segment; with it on the segment itself there is no density and construction
/// fails.
///
/// Numerics: everything is f64, and sampling uses
/// `t = t0 + r0 sin(uΘ) / sin ψ(u)` (Θ the subtended angle, r0 the distance from the light
/// to the segment start, ψ the angle between the ray and the light-to-point direction),
/// which has no `tan` near ±π/2 and no difference of nearly equal angles, so it keeps its
/// accuracy as D → 0, where the textbook `Δ + D tan θ` collapses onto Δ.
#[derive(Clone, Copy, Debug)]
pub struct Equiangular {
    t0: f64,
    t1: f64,
    delta: f64,
    kind: Kind,
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    /// D > 0: uniform in the angle at the light.
    Angular {
        d_perp: f64,
        /// Angle the segment subtends at the light.
        theta: f64,
        /// Angle between +ray_d and the light-to-point direction at t1 (0 for t1 = ∞).
        psi1: f64,
        /// Same angle measured from −ray_d, at t0.
        chi0: f64,
        /// Distance from the light to the point at t0.
        r0: f64,
    },
    /// D = 0, light outside the segment: density `k / (t − Δ)²`.
    InverseSquare { k: f64 },
}

impl Equiangular {
    /// Set-up for the segment `[t0, t1]` of the ray `ray_o + t ray_d` (`ray_d` unit) and the
    /// light at `light_p`; `None` if the segment is empty or not finite at t0, or if the light
    /// lies on the segment itself.
    pub fn new(ray_o: Vec3, ray_d: Vec3, t0: f32, t1: f32, light_p: Vec3) -> Option<Self> {
        debug_assert!(
            (ray_d.length() - 1.0).abs() < 1e-3,
            "ray direction {ray_d} must be unit"
        );
        let (t0, t1) = (f64::from(t0), f64::from(t1));
        if !(t0.is_finite() && t1 > t0) {
            return None;
        }
        let v: DVec3 = light_p.as_dvec3() - ray_o.as_dvec3();
        let d = ray_d.as_dvec3();
        if !(v.is_finite() && d.is_finite()) {
            return None;
        }
        let delta = v.dot(d);
        // |v × d| is the perpendicular distance without the cancellation of |v − Δd|.
        let d_perp = v.cross(d).length();
        let (s0, s1) = (t0 - delta, t1 - delta);
        // Angle between (s0, D) and (s1, D) as one atan2: no difference of two angles that
        // are both near ±π/2 when D is small.
        let theta = if t1.is_infinite() {
            d_perp.atan2(s0)
        } else {
            (d_perp * (t1 - t0)).atan2(d_perp * d_perp + s0 * s1)
        };
        let kind = if d_perp > 0.0 && theta > 0.0 {
            Kind::Angular {
                d_perp,
                theta,
                psi1: if t1.is_infinite() {
                    0.0
                } else {
                    d_perp.atan2(s1)
                },
                chi0: d_perp.atan2(-s0),
                r0: d_perp.hypot(s0),
            }
        } else if s0 * s1 > 0.0 {
            // On the line, outside the segment (both ends on one side; s1 = ∞ needs s0 > 0).
            // The limit D/Θ → s0 s1 / (t1 − t0) (or s0 for t1 = ∞) normalizes k / s².
            let k = if t1.is_infinite() {
                s0
            } else {
                s0 * s1 / (t1 - t0)
            };
            Kind::InverseSquare { k }
        } else {
            return None;
        };
        Some(Self {
            t0,
            t1,
            delta,
            kind,
        })
    }

    /// Samples `t ∈ [t0, t1]` from `u ∈ [0, 1)`; returns `(t, pdf)` with the pdf per unit
    /// length at the returned (rounded) `t`.
    pub fn sample(&self, u: f32) -> (f32, f32) {
        let u = f64::from(u.clamp(0.0, U_MAX));
        let (t0, t1) = (self.t0, self.t1);
        let t = match self.kind {
            Kind::Angular {
                theta,
                psi1,
                chi0,
                r0,
                ..
            } => {
                let phi = u * theta;
                // ψ(u) two ways, each a sum of non-negative terms: from the t1 end and,
                // as π − ψ, from the t0 end. Both have the same sine; the smaller angle
                // gives it with full relative precision.
                let psi = psi1 + (1.0 - u) * theta;
                let chi = chi0 + phi;
                t0 + r0 * phi.sin() / psi.min(chi).sin()
            }
            Kind::InverseSquare { .. } => {
                // 1/(t − Δ) is uniform in u between its end values.
                let s0 = t0 - self.delta;
                if t1.is_infinite() {
                    t0 + u * s0 / (1.0 - u)
                } else {
                    let s1 = t1 - self.delta;
                    t0 + u * s0 * (t1 - t0) / ((1.0 - u) * s1 + u * s0)
                }
            }
        };
        // Rounding may step a hair outside; t1 is an f32, so clamping in f64 keeps the
        // rounded result inside too.
        let t = t.clamp(t0, t1) as f32;
        (t, self.pdf(t))
    }

    /// Density per unit length at `t` (0 outside `[t0, t1]`).
    pub fn pdf(&self, t: f32) -> f32 {
        let t = f64::from(t);
        if !(t >= self.t0 && t <= self.t1) {
            return 0.0;
        }
        let s = t - self.delta;
        let pdf = match self.kind {
            Kind::Angular { d_perp, theta, .. } => d_perp / (theta * (d_perp * d_perp + s * s)),
            Kind::InverseSquare { k } => k / (s * s),
        };
        to_f32(pdf)
    }
}

/// Equiangular sample of a distance in `[t0, t1]` along the ray towards the point light at
/// `light_p`; `(t, pdf per unit length)`, or `None` when the light lies on the segment
/// itself (no density exists) or the segment is empty. See [`Equiangular`].
pub fn sample_equiangular(
    ray_o: Vec3,
    ray_d: Vec3,
    t0: f32,
    t1: f32,
    light_p: Vec3,
    u: f32,
) -> Option<(f32, f32)> {
    Equiangular::new(ray_o, ray_d, t0, t1, light_p).map(|e| e.sample(u))
}

/// Density per unit length of [`sample_equiangular`] producing `t` (0 where it cannot).
pub fn equiangular_pdf(ray_o: Vec3, ray_d: Vec3, t0: f32, t1: f32, light_p: Vec3, t: f32) -> f32 {
    Equiangular::new(ray_o, ray_d, t0, t1, light_p).map_or(0.0, |e| e.pdf(t))
}
