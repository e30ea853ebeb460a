//! Homogeneous participating media: coefficients, transmittance, free-flight and
//! equiangular distance sampling, and the Henyey–Greenstein phase function.
//!
//! This module holds only the math; it knows nothing of rays, scenes or integrators.
//!
//! # Units and conventions
//!
//! - Coefficients σa (absorption), σs (scattering) and σt = σa + σs are per scene unit of
//!   length, one value per colour channel. Distances `t` are ray parameters along unit
//!   directions, so they are lengths too.
//! - Transmittance is Beer–Lambert, `Tr(d) = exp(−σt·d)`, with the product `σt·d` taken as 0
//!   whenever either factor is 0: a channel with σt = 0 transmits everything over any distance
//!   (even an infinite one), and a zero distance transmits everything.
//! - Directions at a scattering point both point *away* from it: `wo` back along the ray that
//!   arrived, `wi` along the ray that leaves. The scattering angle θ is the deflection of the
//!   propagation direction, so `cos θ = −wo·wi`; forward scattering (g > 0) sends `wi ≈ −wo`.
//!   Henyey–Greenstein's mean `cos θ` is `g` in this convention.
//!
//! # Channels
//!
//! [`HomogeneousMedium`] stores RGB coefficients as `glam::Vec3`, the type the path
//! throughput already has, so the integrator multiplies weights without conversions. The
//! arithmetic underneath ([`transmittance_channels`], [`sample_free_flight`], …) is generic
//! over the channel count `N` on plain `[f32; N]` arrays. With sampled wavelengths the
//! coefficients have to be evaluated at each path's own wavelengths, so a spectral integrator
//! will build `[f32; 4]` coefficient arrays per path and call those functions directly; a
//! struct fixed to RGB would not serve it, and a trait over vector types would tie the math
//! to whatever spectrum type that integrator adopts.
//!
//! # Fog described by survival probabilities
//!
//! The seed renderer described fog by three numbers: the probability `p_a` that light
//! survives absorption over one unit of length, the probability `p_s` that it travels one unit
//! without being scattered, and a back-scatter strength `b ∈ [0, 1]`. [`from_survival`] maps
//! them onto the physical parameters:
//!
//! - Survival over a unit length in a homogeneous medium is `exp(−σ·1)`, so
//!   `σa = −ln p_a` and `σs = −ln p_s`; the two processes are independent, so the unit-length
//!   transmittance is `p_a · p_s`. Probabilities are clamped to `[f32::MIN_POSITIVE, 1]`:
//!   `p = 1` is a clear channel (σ = 0), and `p = 0` becomes σ ≈ 87 per unit (transmittance
//!   about 1e-38 per unit length), opaque for rendering but still a finite coefficient.
//! - The back-scatter strength becomes the Henyey–Greenstein asymmetry `g = −b`: `b` is the
//!   mean cosine of the deflection *towards* the direction the light came from. `b = 0` is
//!   isotropic fog and `b → 1` approaches a retro-reflector. The mean cosine is the one number
//!   similarity theory keeps (the reduced coefficient `σs (1 − g)` governs multiple
//!   scattering), so it is the natural reading of a single "strength" parameter; HG clamps
//!   `|g|` to [`HG_G_MAX`] so `b = 1` stays finite.

mod distance;
pub mod lanes;
mod phase;

pub use distance::*;
pub use phase::*;

use glam::{Vec2, Vec3};

/// Homogeneous medium coefficients per channel (1/scene unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomogeneousMedium {
    /// Absorption coefficient σa per channel (1/scene unit).
    pub sigma_a: Vec3,
    /// Scattering coefficient σs per channel (1/scene unit).
    pub sigma_s: Vec3,
    /// Henyey–Greenstein asymmetry in [−1, 1] (see [`hg_phase`] for the convention).
    pub g: f32,
}

impl HomogeneousMedium {
    /// From σa, σs and the Henyey–Greenstein asymmetry `g`.
    pub fn new(sigma_a: Vec3, sigma_s: Vec3, g: f32) -> Self {
        Self {
            sigma_a,
            sigma_s,
            g,
        }
    }

    /// Whether every coefficient is finite and non-negative and `g` lies in [−1, 1]: the
    /// domain on which the methods promise finite results.
    pub fn is_valid(&self) -> bool {
        let ok = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
        ok(self.sigma_a) && ok(self.sigma_s) && (-1.0..=1.0).contains(&self.g)
    }

    /// Extinction σt = σa + σs.
    #[inline]
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }

    /// Single-scattering albedo σs / σt per channel, 0 where the channel is empty.
    pub fn albedo(&self) -> Vec3 {
        let st = self.sigma_t();
        Vec3::select(st.cmpgt(Vec3::ZERO), self.sigma_s / st, Vec3::ZERO)
    }

    /// Beer–Lambert transmittance `exp(−σt·d)` per channel for `d ∈ [0, ∞]`, with
    /// `0·∞ = 0`: a channel with σt = 0 gives 1 for any `d`, and `d = ∞` with σt > 0 gives 0.
    #[inline]
    pub fn transmittance(&self, d: f32) -> Vec3 {
        Vec3::from_array(transmittance_channels(self.sigma_t().to_array(), d))
    }

    /// Free-flight distance sampling with single-sample MIS over channels; see
    /// [`sample_free_flight`] for the estimator. `channel_probs` need not be normalized
    /// (use [`channel_probabilities`] of the path throughput).
    #[inline]
    pub fn sample_distance(
        &self,
        t_max: f32,
        u_channel: f32,
        u: f32,
        channel_probs: Vec3,
    ) -> DistanceSample {
        debug_assert!(self.is_valid(), "invalid medium {self:?}");
        sample_free_flight(
            self.sigma_s.to_array(),
            self.sigma_t().to_array(),
            t_max,
            u_channel,
            u,
            channel_probs.to_array(),
        )
        .map(Vec3::from_array)
    }

    /// Density per unit length of [`Self::sample_distance`] producing a scattering event at
    /// `t` (before it is compared with `t_max`), averaged over channels with `channel_probs`.
    #[inline]
    pub fn distance_pdf(&self, t: f32, channel_probs: Vec3) -> f32 {
        free_flight_pdf(self.sigma_t().to_array(), t, channel_probs.to_array())
    }

    /// Probability that [`Self::sample_distance`] passes `t_max`.
    #[inline]
    pub fn pass_probability(&self, t_max: f32, channel_probs: Vec3) -> f32 {
        free_flight_pass_probability(self.sigma_t().to_array(), t_max, channel_probs.to_array())
    }

    /// Phase function value for the pair (`wo`, `wi`), both pointing away from the point.
    #[inline]
    pub fn phase(&self, wo: Vec3, wi: Vec3) -> f32 {
        hg_phase_dirs(wo, wi, self.g)
    }

    /// Samples `wi` from the phase function; returns it with its pdf (= phase value).
    #[inline]
    pub fn sample_phase(&self, wo: Vec3, u: Vec2) -> (Vec3, f32) {
        sample_hg(wo, self.g, u)
    }
}

/// Builds a medium from per-unit-length survival probabilities against absorption and
/// against scattering, and a back-scatter strength in [0, 1] (see the module docs for the
/// mapping and its justification).
pub fn from_survival(
    p_absorb_survive: Vec3,
    p_scatter_survive: Vec3,
    back_scatter: f32,
) -> HomogeneousMedium {
    // −ln p; `0 − ln 1` is +0, so a clear channel gets an exact positive zero.
    let sigma = |p: Vec3| p.map(|p| 0.0 - p.clamp(f32::MIN_POSITIVE, 1.0).ln());
    HomogeneousMedium {
        sigma_a: sigma(p_absorb_survive),
        sigma_s: sigma(p_scatter_survive),
        g: -back_scatter.clamp(0.0, 1.0),
    }
}
