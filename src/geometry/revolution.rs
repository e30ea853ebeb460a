//! Surfaces of revolution: a clamped uniform cubic B-spline profile `(r(s), h(s))`, s ∈ [0, 1],
//! revolved about the local y axis. Points are `(r cos φ, h, r sin φ)`.
//!
//! **Representation.** `n` control points give `n − 3` spans of equal length in s. Each span is
//! converted once to Bézier (Bernstein) form by blossoming (de Boor's algorithm with a different
//! argument per level), so the span's control hull bounds it and its endpoints are exact: joints
//! are copied from one span to the next, and a profile end on the axis has r = 0 exactly.
//!
//! **Why isolation and not plain Newton.** Newton started from one or several guesses converges
//! to *some* root, and which one depends on the basins of attraction: nothing stops it from
//! skipping the nearest crossing (the stem) and landing on a farther one (the bowl), and no
//! finite set of starts rules that out. Bernstein coefficients give a proof instead: by the
//! variation-diminishing property a polynomial on [0, 1] has at most as many roots as its
//! coefficient sequence has sign changes, and exactly one when there is one change. Subdividing
//! (de Casteljau at ½) until every interval has zero changes (no root, dropped) or one (exactly
//! one root, kept) finds every crossing. Newton then only polishes inside a bracket that holds
//! a single root, safeguarded by bisection so it cannot leave it.
//!
//! **Culling.** Each span's control hull, revolved, lies in an annular slab
//! [r_min, r_max] × [h_min, h_max]. The ray's parameter range inside it (a slab in y, a disc
//! test in xz, and a check that the ray does not stay inside the hole, using that ρ² is convex
//! along the ray) both culls the span and orders the survivors front to back, so a search
//! stops at the first span that starts beyond the best hit. Most rays search one or two spans.
//!
//! **Steep rays** (|d_y| ≥ [`FLAT_SLOPE`]·|d|). With t = (h(u) − o_y)/d_y the hit condition
//! x² + z² = r² becomes, multiplied by d_y²,
//! F(u) = (α_x + d_x h)² + (α_z + d_z h)² − (d_y r)² = 0, α = (o_x d_y − o_y d_x, o_z d_y − o_y d_z),
//! a degree-6 polynomial per span. α is a moment of the line (independent of where o sits on
//! it), so F's coefficients stay at the object's scale for distant origins; its Bernstein
//! coefficients come from pairwise products of the cubics' coefficients, so the end values are
//! exact sums of squares (≥ 0 where r = 0, so a ray through a pole meets a zero, not a rounding
//! sign flip). Intervals whose hull puts t outside (0, best) are pruned, so after the first
//! hit farther spans and sub-intervals cost a hull test. From the root u, t is taken from the
//! height, (h − o_y)/d_y, or from the radius, t_c ± S/|d_xz| (below), whichever is less
//! sensitive to the error left in u.
//!
//! **Near-horizontal rays.** As d_y → 0, F degenerates to a(h − y_c)²: the entry and exit
//! through the thin horizontal layer the ray sweeps become a near-double root in u, and
//! t = (h − o_y)/d_y amplifies every error by 1/d_y. Below the threshold the problem is solved
//! in the ray's own vertical plane instead: with τ the horizontal distance along the ray from
//! its closest approach to the axis (radius ρ_c, height y_c), the surface's section is the
//! pair of curves (±S(u), h(u)), S = √(r² − ρ_c²), and the ray the line y = y_c + k τ with
//! k = d_y/|d_xz|. Each branch σ = ±1 gives g_σ(u) = h(u) − y_c − σ k S(u), which for k = 0 is
//! exactly the cubic h(u) = o_y, and stays well conditioned for small k. Roots are isolated
//! with interval bounds (Bernstein hulls of h and r) plus a monotonicity test on the derivative
//! bounds, and t = t_c + σ S/|d_xz|, which is accurate for flat rays. The threshold 10⁻³
//! keeps the degree-6 path away from its ill-conditioned regime (pairs of roots at least
//! ~10⁻³·S apart in height) while the perturbation k·S that the flat path must bound stays
//! small, so its interval tests stay tight.
//!
//! **Precision.** Everything inside is f64: rays are converted once, direction normalised; only
//! the record handed back is f32. Polishing is Newton safeguarded by bisection (a Newton step
//! is taken only if it stays inside the shrinking bracket and at least halves the step before
//! last). It stops when the step in the curve parameter s falls to the tolerance (after a
//! Newton step the error left is then far smaller) or the bracket is that narrow (the error is
//! then within it); a bracket that reaches [`MAX_ITERATIONS`] returns its bisection midpoint
//! and is counted as non-converged. Intervals narrower than 2⁻³⁶ in span parameter, or whose
//! polynomial is zero to rounding (a ray lying in a flat ledge or along a cylinder wall), are
//! tangencies: kept only when they still show a sign change.

use super::{Aabb, Ray, SurfacePoint};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

/// Default Newton tolerance in the curve parameter s.
pub const DEFAULT_TOLERANCE: f32 = 1e-6;

/// |d_y| / |d| below which a ray takes the near-horizontal path (see the module notes).
pub const FLAT_SLOPE: f64 = 1e-3;

/// Newton/bisection steps per bracket before it counts as non-converged.
pub const MAX_ITERATIONS: u32 = 40;

/// Narrowest interval (in span parameter) the isolation subdivides to: 2⁻³⁶.
const WIDTH_FLOOR: f64 = 1.0 / 68_719_476_736.0;

/// Depth-first subdivision keeps at most one pending sibling per level.
const STACK: usize = 40;

/// Interval visits per span and branch before giving up (a safety net: degenerate inputs are
/// caught by the noise test long before).
const MAX_VISITS: u32 = 4096;

/// Candidate spans sorted by entry distance; more than this are processed unsorted.
const CANDIDATES: usize = 32;

/// Squared horizontal direction length below which a unit ray counts as vertical.
const VERTICAL: f64 = 1e-24;

/// Relative padding of the f32 bounds (a few roundings of the coordinates).
const PAD_REL: f32 = 8.0 * f32::EPSILON;

/// Work counters. Plain integers in the caller's struct: each thread keeps its own and sums.
#[derive(Default, Clone, Copy, Debug, PartialEq, Eq)]
pub struct RevolutionStats {
    /// Calls to `intersect` and `occluded`.
    pub rays: u64,
    /// Spans that passed the annular-slab cull and were searched for roots.
    pub candidate_spans: u64,
    /// Single-root brackets polished.
    pub brackets: u64,
    /// Newton/bisection steps over all brackets.
    pub newton_iterations: u64,
    /// Brackets that reached the iteration cap (their bisection midpoint was used), plus
    /// searches stopped by the visit budget.
    pub non_converged: u64,
}

impl std::ops::AddAssign for RevolutionStats {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.candidate_spans += o.candidate_spans;
        self.brackets += o.brackets;
        self.newton_iterations += o.newton_iterations;
        self.non_converged += o.non_converged;
    }
}

/// The nearest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RevolutionHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Curve parameter over the whole profile, in [0, 1].
    pub s: f32,
    /// Index of the span hit.
    pub span: u32,
    /// Parameter within the span, in [0, 1]; kept beside `s` because `s` rounded to f32 and
    /// mapped back loses bits on profiles with many spans.
    pub u: f32,
}

/// One span in Bernstein form (for hulls and subdivision) and power form (for Horner).
#[derive(Clone, Copy, Debug)]
struct Span {
    r: [f64; 4],
    h: [f64; 4],
    rp: [f64; 4],
    hp: [f64; 4],
    r_lo: f64,
    r_hi: f64,
    h_lo: f64,
    h_hi: f64,
}

#[inline]
fn power(b: [f64; 4]) -> [f64; 4] {
    [
        b[0],
        3.0 * (b[1] - b[0]),
        3.0 * (b[0] - 2.0 * b[1] + b[2]),
        b[3] - b[0] + 3.0 * (b[1] - b[2]),
    ]
}

#[inline]
fn hull<const N: usize>(c: &[f64; N]) -> (f64, f64) {
    c.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// Both halves of a Bernstein polynomial split at ½ (de Casteljau).
#[inline]
fn split<const N: usize>(c: &[f64; N]) -> ([f64; N], [f64; N]) {
    let mut tmp = *c;
    let mut left = *c;
    let mut right = *c;
    for j in 1..N {
        for i in 0..N - j {
            tmp[i] = 0.5 * (tmp[i] + tmp[i + 1]);
        }
        left[j] = tmp[0];
        right[N - 1 - j] = tmp[N - 1 - j];
    }
    (left, right)
}

/// Sign changes of a coefficient sequence (zeros skipped), and the signs of its first and last
/// non-zero coefficients (true = negative): the sign of the polynomial just inside each end.
#[inline]
fn variations<const N: usize>(c: &[f64; N]) -> (u32, bool, bool) {
    let mut count = 0;
    let mut first = None;
    let mut last = None;
    for &v in c {
        if v == 0.0 {
            continue;
        }
        let neg = v < 0.0;
        if let Some(l) = last
            && l != neg
        {
            count += 1;
        }
        if first.is_none() {
            first = Some(neg);
        }
        last = Some(neg);
    }
    (count, first.unwrap_or(false), last.unwrap_or(false))
}

impl Span {
    fn new(r: [f64; 4], h: [f64; 4]) -> Self {
        let (r_lo, r_hi) = hull(&r);
        let (h_lo, h_hi) = hull(&h);
        Self {
            r,
            h,
            rp: power(r),
            hp: power(h),
            r_lo,
            r_hi,
            h_lo,
            h_hi,
        }
    }

    /// r, h, dr/du, dh/du.
    #[inline]
    fn eval(&self, u: f64) -> (f64, f64, f64, f64) {
        let (r, h) = (&self.rp, &self.hp);
        (
            r[0] + u * (r[1] + u * (r[2] + u * r[3])),
            h[0] + u * (h[1] + u * (h[2] + u * h[3])),
            r[1] + u * (2.0 * r[2] + 3.0 * u * r[3]),
            h[1] + u * (2.0 * h[2] + 3.0 * u * h[3]),
        )
    }

    /// Direction of increasing u in the (r, h) plane, never zero: where the first derivative
    /// vanishes (coincident control points) the curve still moves along the first non-zero
    /// higher derivative, with the sign it has on the side the point is approached from.
    fn tangent(&self, u: f64, eps: f64) -> (f64, f64) {
        let (_, _, dr, dh) = self.eval(u);
        if dr.hypot(dh) > eps {
            return (dr, dh);
        }
        let (r, h) = (&self.rp, &self.hp);
        let side = if u < 0.5 { 1.0 } else { -1.0 };
        let (ddr, ddh) = (2.0 * r[2] + 6.0 * u * r[3], 2.0 * h[2] + 6.0 * u * h[3]);
        if ddr.hypot(ddh) > eps {
            return (side * ddr, side * ddh);
        }
        if r[3].hypot(h[3]) > 0.0 {
            return (r[3], h[3]);
        }
        (0.0, 1.0)
    }
}

/// One blossom value b(x₁, x₂, x₃) of the span starting at knot `k + 3`: de Boor's algorithm
/// with argument xᵢ at level i. Equal arguments give curve points, mixed ones the Bézier
/// control points.
fn blossom(pts: &[[f64; 2]], knots: &[f64], k: usize, x: [f64; 3]) -> [f64; 2] {
    let mut d = [pts[k], pts[k + 1], pts[k + 2], pts[k + 3]];
    for lvl in 1..=3 {
        // Downwards, so d[j - 1] still holds the previous level.
        for j in (lvl..=3).rev() {
            let i = k + j;
            let (lo, hi) = (knots[i], knots[i + 4 - lvl]);
            let a = if hi > lo {
                (x[lvl - 1] - lo) / (hi - lo)
            } else {
                0.0
            };
            d[j] = [
                d[j - 1][0] + a * (d[j][0] - d[j - 1][0]),
                d[j - 1][1] + a * (d[j][1] - d[j - 1][1]),
            ];
        }
    }
    d[3]
}

/// The ray in f64, direction normalised, with the quantities both paths share.
struct Local {
    o: DVec3,
    d: DVec3,
    /// |ray.d|: unit-direction distances divide by it to give the caller's t.
    len: f64,
    /// Moment terms of the steep path.
    ax: f64,
    az: f64,
    /// d_x² + d_z², its root, and the closest approach to the axis in xz: parameter, squared
    /// radius and height there. Meaningful when `a > VERTICAL`.
    a: f64,
    sqrt_a: f64,
    t_c: f64,
    rho_c2: f64,
    y_c: f64,
    /// Slope d_y / |d_xz| of the ray in its vertical plane.
    k: f64,
    flat: bool,
}

impl Local {
    fn new(ray: &Ray) -> Option<Self> {
        let o = ray.o.as_dvec3();
        let d_raw = ray.d.as_dvec3();
        let len = d_raw.length();
        if !(len > 0.0 && len.is_finite() && o.is_finite()) {
            return None;
        }
        let d = d_raw / len;
        let a = d.x * d.x + d.z * d.z;
        let (sqrt_a, t_c, rho_c2, y_c, k) = if a > VERTICAL {
            let sqrt_a = a.sqrt();
            let t_c = -(o.x * d.x + o.z * d.z) / a;
            // From the cross product, not |o|² − (o·d)²/a, which cancels for far origins.
            let cross = o.x * d.z - o.z * d.x;
            (
                sqrt_a,
                t_c,
                cross * cross / a,
                o.y + d.y * t_c,
                d.y / sqrt_a,
            )
        } else {
            (0.0, 0.0, o.x * o.x + o.z * o.z, o.y, f64::INFINITY)
        };
        Some(Self {
            o,
            d,
            len,
            ax: o.x * d.y - o.y * d.x,
            az: o.z * d.y - o.y * d.z,
            a,
            sqrt_a,
            t_c,
            rho_c2,
            y_c,
            k,
            flat: d.y.abs() < FLAT_SLOPE,
        })
    }

    #[inline]
    fn rho2(&self, t: f64) -> f64 {
        let x = self.o.x + t * self.d.x;
        let z = self.o.z + t * self.d.z;
        x * x + z * z
    }
}

/// The best hit so far (unit-direction t) and what the search may still accept.
struct Best {
    t: f64,
    u: f64,
    span: u32,
    found: bool,
    /// Stop at the first hit (shadow rays).
    any: bool,
}

impl Best {
    #[inline]
    fn offer(&mut self, t: f64, u: f64, span: usize) -> bool {
        if t > 0.0 && t < self.t {
            self.t = t;
            self.u = u;
            self.span = span as u32;
            self.found = true;
            true
        } else {
            false
        }
    }
}

/// Bisection-safeguarded Newton on a bracket `[lo, hi]` holding one root (`neg_lo`: the
/// function is negative just right of `lo`). Newton is taken only while it stays inside the
/// shrinking bracket and at least halves the step before last (as in Numerical Recipes'
/// `rtsafe`); otherwise the bracket is bisected, so progress is guaranteed.
fn polish(
    mut f: impl FnMut(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    neg_lo: bool,
    guess: f64,
    tol: f64,
    stats: &mut RevolutionStats,
) -> f64 {
    stats.brackets += 1;
    let mut u = if guess > lo && guess < hi {
        guess
    } else {
        0.5 * (lo + hi)
    };
    let mut step_old = hi - lo;
    let mut step = step_old;
    for _ in 0..MAX_ITERATIONS {
        stats.newton_iterations += 1;
        let (v, dv) = f(u);
        if v == 0.0 {
            return u;
        }
        if (v < 0.0) == neg_lo {
            lo = u;
        } else {
            hi = u;
        }
        let newton = u - v / dv;
        let next = if newton > lo && newton < hi && 2.0 * (newton - u).abs() <= step_old.abs() {
            newton
        } else {
            0.5 * (lo + hi)
        };
        step_old = step;
        step = next - u;
        u = next;
        if step.abs() <= tol || hi - lo <= tol {
            return u;
        }
    }
    stats.non_converged += 1;
    0.5 * (lo + hi)
}

/// An interval of the steep path: F and h on it, and the range of t its hull allows.
#[derive(Clone, Copy, Default)]
struct SteepIv {
    u0: f64,
    u1: f64,
    f: [f64; 7],
    h: [f64; 4],
    t_lo: f64,
    t_hi: f64,
}

/// An interval of the flat path: h − y_c and r on it.
#[derive(Clone, Copy, Default)]
struct FlatIv {
    u0: f64,
    u1: f64,
    c: [f64; 4],
    r: [f64; 4],
}

/// The seed's goblet: a thick, closed profile (outer wall up, rim, inner wall down), as in
/// `scenes/goblet.ron`; shared by the tests and benches.
pub const GOBLET_PROFILE: [(f32, f32); 10] = [
    (0.0, 0.0),
    (0.45, 0.0),
    (0.45, 0.05),
    (0.06, 0.1),
    (0.05, 0.6),
    (0.4, 0.9),
    (0.5, 1.4),
    (0.47, 1.4),
    (0.37, 0.95),
    (0.0, 0.7),
];

/// A surface of revolution in object space (the profile revolved about y).
#[derive(Clone, Debug)]
pub struct Revolution {
    spans: Vec<Span>,
    closed: bool,
    /// Sign turning (dh, −dr) into the outward normal of a closed profile: +1 when the
    /// profile runs counter-clockwise around its region in the (r, y) half-plane.
    orientation: f64,
    /// Newton tolerance in the span parameter (tolerance in s times the span count).
    tol_u: f64,
    tolerance: f32,
    r_max: f64,
    h_min: f64,
    h_max: f64,
    /// Largest coordinate magnitude of the control points.
    scale: f64,
    /// Absolute slack of the span culls.
    pad: f64,
}

impl Revolution {
    /// Builds the surface from a clamped uniform cubic B-spline control polygon of
    /// `(radius, height)` points. `tolerance` is the Newton convergence threshold in the curve
    /// parameter s ([`DEFAULT_TOLERANCE`] is a good default).
    pub fn new(profile: &[(f32, f32)], tolerance: f32) -> Result<Self, String> {
        let n = profile.len();
        if n < 4 {
            return Err(format!(
                "Revolution profile needs at least 4 control points (it is a cubic B-spline), \
                 got {n}"
            ));
        }
        for (i, &(r, h)) in profile.iter().enumerate() {
            if !r.is_finite() || !h.is_finite() {
                return Err(format!(
                    "Revolution profile point {i} ({r}, {h}) is not finite: radius and height \
                     must be finite numbers"
                ));
            }
            if r < 0.0 {
                return Err(format!(
                    "Revolution profile point {i} has negative radius {r}: radii must be >= 0 \
                     (the profile is revolved about the y axis)"
                ));
            }
        }
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(format!(
                "Revolution tolerance must be finite and positive, got {tolerance}"
            ));
        }
        if profile.iter().all(|p| p.0 == 0.0) {
            return Err(
                "Revolution profile lies on the axis (every radius is 0): the surface has no area"
                    .to_string(),
            );
        }
        if profile.iter().all(|&p| p == profile[0]) {
            return Err("Revolution profile control points all coincide".to_string());
        }

        let pts: Vec<[f64; 2]> = profile.iter().map(|&(r, h)| [r as f64, h as f64]).collect();
        let m = n - 3;
        // Clamped uniform knots in span units: four zeros, 1 … m − 1, four m's.
        let knots: Vec<f64> = (0..n + 4)
            .map(|i| (i as f64 - 3.0).clamp(0.0, m as f64))
            .collect();
        let mut spans = Vec::with_capacity(m);
        let mut prev_end = pts[0];
        for k in 0..m {
            let (a, b) = (k as f64, k as f64 + 1.0);
            let mut c = [
                blossom(&pts, &knots, k, [a, a, a]),
                blossom(&pts, &knots, k, [a, a, b]),
                blossom(&pts, &knots, k, [a, b, b]),
                blossom(&pts, &knots, k, [b, b, b]),
            ];
            // Joints shared bit for bit, and the curve's ends exactly the end points (a pole
            // keeps r = 0 exactly).
            c[0] = prev_end;
            if k == m - 1 {
                c[3] = pts[n - 1];
            }
            prev_end = c[3];
            spans.push(Span::new(c.map(|p| p[0]), c.map(|p| p[1])));
        }

        let closed = profile[0].0 == 0.0 && profile[n - 1].0 == 0.0;
        // Green's theorem: ∮ r dh over the profile and back along the axis (where r = 0) is the
        // signed area; positive means counter-clockwise, whose outward side is the right one.
        // r·h' has degree 5, so 3-point Gauss–Legendre is exact.
        let gauss = [
            (0.5 - 0.5 * 0.6f64.sqrt(), 5.0 / 18.0),
            (0.5, 8.0 / 18.0),
            (0.5 + 0.5 * 0.6f64.sqrt(), 5.0 / 18.0),
        ];
        let area: f64 = spans
            .iter()
            .flat_map(|sp| {
                gauss.iter().map(move |&(x, w)| {
                    let (r, _, _, dh) = sp.eval(x);
                    w * r * dh
                })
            })
            .sum();
        let orientation = if area < 0.0 { -1.0 } else { 1.0 };

        let r_max = spans.iter().map(|s| s.r_hi).fold(0.0, f64::max);
        let h_min = spans.iter().map(|s| s.h_lo).fold(f64::INFINITY, f64::min);
        let h_max = spans
            .iter()
            .map(|s| s.h_hi)
            .fold(f64::NEG_INFINITY, f64::max);
        let scale = r_max.max(h_min.abs()).max(h_max.abs());
        Ok(Self {
            spans,
            closed,
            orientation,
            tol_u: tolerance as f64 * m as f64,
            tolerance,
            r_max,
            h_min,
            h_max,
            scale,
            pad: scale * 1e-9,
        })
    }

    /// A profile that starts and ends on the axis encloses a solid.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Newton convergence threshold in the curve parameter s.
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// Number of polynomial spans in the profile (control points − 3).
    pub fn span_count(&self) -> usize {
        self.spans.len()
    }

    /// Object-space bounds of the revolved control hull, padded for rounding.
    pub fn bounds(&self) -> Aabb {
        let r = self.r_max as f32;
        Aabb::new(
            Vec3::new(-r, self.h_min as f32, -r),
            Vec3::new(r, self.h_max as f32, r),
        )
        .padded(PAD_REL, 0.0)
    }

    /// The part `[t0, t1]` of (0, limit) where the ray lies in the annular slab
    /// [r_lo, r_hi] × [h_lo, h_hi]: the revolved control hull of a span, or of the whole
    /// profile. Conservative: slack `pad` on every side.
    #[inline]
    fn slab(&self, l: &Local, r: (f64, f64), h: (f64, f64), limit: f64) -> Option<(f64, f64)> {
        let (h_lo, h_hi) = (h.0 - self.pad, h.1 + self.pad);
        let (r_lo, r_hi) = (r.0 - self.pad, r.1 + self.pad);
        let (mut t0, mut t1) = if l.d.y != 0.0 {
            let a = (h_lo - l.o.y) / l.d.y;
            let b = (h_hi - l.o.y) / l.d.y;
            (a.min(b), a.max(b))
        } else if l.o.y >= h_lo && l.o.y <= h_hi {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return None;
        };
        if l.a > VERTICAL {
            let q = (r_hi * r_hi - l.rho_c2) / l.a;
            if q < 0.0 {
                return None;
            }
            let half = q.sqrt();
            t0 = t0.max(l.t_c - half);
            t1 = t1.min(l.t_c + half);
        } else if l.rho_c2 > r_hi * r_hi {
            return None;
        }
        t0 = t0.max(0.0);
        t1 = t1.min(limit);
        if t0 > t1 {
            return None;
        }
        // ρ² is convex along the ray, so its maximum over [t0, t1] sits at an end: if both
        // ends are inside the inner radius, the ray stays in the hole.
        if r_lo > 0.0 && l.rho2(t0).max(l.rho2(t1)) < r_lo * r_lo {
            return None;
        }
        Some((t0, t1))
    }

    /// Nearest hit in (0, t_max), object space.
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        stats: &mut RevolutionStats,
    ) -> Option<RevolutionHit> {
        stats.rays += 1;
        let l = Local::new(ray)?;
        let mut best = Best {
            t: t_max as f64 * l.len,
            u: 0.0,
            span: 0,
            found: false,
            any: false,
        };
        self.search(&l, &mut best, stats);
        if !best.found {
            return None;
        }
        let m = self.spans.len() as f64;
        let t = (best.t / l.len) as f32;
        // Rounding to f32 must not push the hit onto t_max (the float just below it: t_max is
        // positive and finite here, or no hit could be below it) or onto 0.
        let t = if t >= t_max {
            f32::from_bits(t_max.to_bits() - 1)
        } else {
            t.max(f32::MIN_POSITIVE)
        };
        Some(RevolutionHit {
            t,
            s: ((best.span as f64 + best.u) / m) as f32,
            span: best.span,
            u: best.u as f32,
        })
    }

    /// Whether anything is hit in (0, t_max).
    pub fn occluded(&self, ray: &Ray, t_max: f32, stats: &mut RevolutionStats) -> bool {
        stats.rays += 1;
        let Some(l) = Local::new(ray) else {
            return false;
        };
        let mut best = Best {
            t: t_max as f64 * l.len,
            u: 0.0,
            span: 0,
            found: false,
            any: true,
        };
        self.search(&l, &mut best, stats);
        best.found
    }

    fn search(&self, l: &Local, best: &mut Best, stats: &mut RevolutionStats) {
        if self
            .slab(l, (0.0, self.r_max), (self.h_min, self.h_max), best.t)
            .is_none()
        {
            return;
        }
        // Spans front to back by where the ray enters their slab, so the first hit usually
        // rules out the rest.
        let mut cand = [(0.0f64, 0u32); CANDIDATES];
        let mut n = 0;
        for (i, sp) in self.spans.iter().enumerate() {
            let Some((t0, _)) = self.slab(l, (sp.r_lo, sp.r_hi), (sp.h_lo, sp.h_hi), best.t) else {
                continue;
            };
            if n < CANDIDATES {
                cand[n] = (t0, i as u32);
                n += 1;
            } else if t0 < best.t {
                // More candidates than the buffer holds: correct unsorted, only slower.
                stats.candidate_spans += 1;
                if self.span_roots(i, l, best, stats) && best.any {
                    return;
                }
            }
        }
        let cand = &mut cand[..n];
        cand.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for &(t0, i) in cand.iter() {
            if t0 >= best.t {
                break;
            }
            stats.candidate_spans += 1;
            if self.span_roots(i as usize, l, best, stats) && best.any {
                return;
            }
        }
    }

    /// Offers every root of span `i` with t in (0, best.t) to `best`; true if any was taken.
    fn span_roots(
        &self,
        i: usize,
        l: &Local,
        best: &mut Best,
        stats: &mut RevolutionStats,
    ) -> bool {
        if l.flat {
            let mut found = false;
            // The σ = −1 branch lies before the closest approach, so it goes first.
            for sigma in [-1.0, 1.0] {
                found |= self.flat_branch(i, sigma, l, best, stats);
                if found && best.any {
                    break;
                }
            }
            found
        } else {
            self.steep_roots(i, l, best, stats)
        }
    }

    /// t of a steep-path root: from the height, t = (h − o_y)/d_y, or from the radius,
    /// t = t_c ± S/|d_xz|, whichever is less sensitive to the remaining error in u.
    #[inline]
    fn steep_t(&self, sp: &Span, l: &Local, u: f64) -> f64 {
        let (r, h, dr, dh) = sp.eval(u);
        let t_h = (h - l.o.y) / l.d.y;
        if l.a > VERTICAL {
            let s2 = r * r - l.rho_c2;
            if s2 > 0.0 {
                let s = s2.sqrt();
                if (r * dr).abs() * l.d.y.abs() < dh.abs() * s * l.sqrt_a {
                    let sigma = if (h - l.y_c) * l.d.y >= 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    return l.t_c + sigma * s / l.sqrt_a;
                }
            }
        }
        t_h
    }

    fn steep_roots(
        &self,
        i: usize,
        l: &Local,
        best: &mut Best,
        stats: &mut RevolutionStats,
    ) -> bool {
        let sp = &self.spans[i];
        let (dx, dy, dz) = (l.d.x, l.d.y, l.d.z);
        let ca: [f64; 4] = sp.h.map(|h| l.ax + dx * h);
        let cb: [f64; 4] = sp.h.map(|h| l.az + dz * h);
        let cr: [f64; 4] = sp.r.map(|r| dy * r);
        let p = |i: usize, j: usize| ca[i] * ca[j] + cb[i] * cb[j] - cr[i] * cr[j];
        // Bernstein product of the cubics: c_k = Σ_{i+j=k} C(3,i) C(3,j) / C(6,k) · P_ij.
        let f = [
            p(0, 0),
            p(0, 1),
            (2.0 * p(0, 2) + 3.0 * p(1, 1)) / 5.0,
            (p(0, 3) + 9.0 * p(1, 2)) / 10.0,
            (2.0 * p(1, 3) + 3.0 * p(2, 2)) / 5.0,
            p(2, 3),
            p(3, 3),
        ];
        let noise = 64.0
            * f64::EPSILON
            * (0..4)
                .map(|i| ca[i] * ca[i] + cb[i] * cb[i] + cr[i] * cr[i])
                .fold(0.0, f64::max);
        let inv_dy = 1.0 / dy;
        let t_pad = 1e-9 * (self.scale + l.o.abs().max_element());
        let t_range = |h: &[f64; 4]| {
            let (lo, hi) = hull(h);
            let (a, b) = ((lo - l.o.y) * inv_dy, (hi - l.o.y) * inv_dy);
            (a.min(b) - t_pad, a.max(b) + t_pad)
        };
        let eval = |u: f64| {
            let (r, h, dr, dh) = sp.eval(u);
            let a = l.ax + dx * h;
            let b = l.az + dz * h;
            let rr = dy * r;
            (
                a * a + b * b - rr * rr,
                2.0 * (dh * (a * dx + b * dz) - dy * rr * dr),
            )
        };

        let mut found = false;
        // Roots exactly at the span's ends: each span owns u = 0, the last one also u = 1.
        // These matter at poles, where F touches zero without changing sign.
        let last = i + 1 == self.spans.len();
        for (u, v) in [(0.0, f[0]), (1.0, if last { f[6] } else { 1.0 })] {
            if v == 0.0 && best.offer(self.steep_t(sp, l, u), u, i) {
                found = true;
                if best.any {
                    return true;
                }
            }
        }

        let mut stack = [SteepIv::default(); STACK];
        let (t_lo, t_hi) = t_range(&sp.h);
        stack[0] = SteepIv {
            u0: 0.0,
            u1: 1.0,
            f,
            h: sp.h,
            t_lo,
            t_hi,
        };
        let mut top = 1;
        let mut visits = 0;
        while top > 0 {
            top -= 1;
            let iv = stack[top];
            if iv.t_hi <= 0.0 || iv.t_lo >= best.t {
                continue;
            }
            visits += 1;
            if visits > MAX_VISITS {
                stats.non_converged += 1;
                break;
            }
            let (v, neg_lo, neg_hi) = variations(&iv.f);
            if v == 0 {
                continue;
            }
            let width = iv.u1 - iv.u0;
            let at_floor =
                width <= WIDTH_FLOOR || iv.f.iter().all(|c| c.abs() <= noise) || top + 2 > STACK;
            if v == 1 || at_floor {
                // An even count at the floor is a tangency (a double root or a pair closer
                // than the floor): no crossing to report.
                if neg_lo == neg_hi {
                    continue;
                }
                let guess = iv.u0 + width * control_crossing(&iv.f);
                let u = polish(eval, iv.u0, iv.u1, neg_lo, guess, self.tol_u, stats);
                if best.offer(self.steep_t(sp, l, u), u, i) {
                    found = true;
                    if best.any {
                        return true;
                    }
                }
                continue;
            }
            let (fl, fr) = split(&iv.f);
            let (hl, hr) = split(&iv.h);
            let mid = 0.5 * (iv.u0 + iv.u1);
            let (al, bl) = t_range(&hl);
            let (ar, br) = t_range(&hr);
            let left = SteepIv {
                u0: iv.u0,
                u1: mid,
                f: fl,
                h: hl,
                t_lo: al,
                t_hi: bl,
            };
            let right = SteepIv {
                u0: mid,
                u1: iv.u1,
                f: fr,
                h: hr,
                t_lo: ar,
                t_hi: br,
            };
            // The half that may hold the nearer hit is searched first.
            let (first, second) = if al <= ar {
                (left, right)
            } else {
                (right, left)
            };
            stack[top] = second;
            stack[top + 1] = first;
            top += 2;
        }
        found
    }

    /// Roots of the branch g_σ(u) = h(u) − y_c − σ k S(u) of span `i` (near-horizontal rays).
    fn flat_branch(
        &self,
        i: usize,
        sigma: f64,
        l: &Local,
        best: &mut Best,
        stats: &mut RevolutionStats,
    ) -> bool {
        let sp = &self.spans[i];
        let k = l.k;
        let rho_c2 = l.rho_c2;
        let s_of = |r: f64| (r * r - rho_c2).max(0.0).sqrt();
        let g_of = |c: f64, r: f64| c - sigma * k * s_of(r);
        let t_of = |s: f64| l.t_c + sigma * s / l.sqrt_a;
        let eval = |u: f64| {
            let (r, h, dr, dh) = sp.eval(u);
            let s = s_of(r);
            let ds = if s > 0.0 { r * dr / s } else { 0.0 };
            (h - l.y_c - sigma * k * s, dh - sigma * k * ds)
        };
        let noise = 64.0 * f64::EPSILON * (l.y_c.abs() + sp.h_lo.abs().max(sp.h_hi.abs()));
        let t_pad = 1e-9 * (self.scale + l.o.abs().max_element());
        let mut found = false;
        let mut stack = [FlatIv::default(); STACK];
        stack[0] = FlatIv {
            u0: 0.0,
            u1: 1.0,
            c: sp.h.map(|h| h - l.y_c),
            r: sp.r,
        };
        let mut top = 1;
        let mut visits = 0;
        while top > 0 {
            top -= 1;
            let iv = stack[top];
            let (r_lo, r_hi) = hull(&iv.r);
            if r_hi * r_hi < rho_c2 {
                // The ray never comes this close to the axis.
                continue;
            }
            let s_hi = s_of(r_hi);
            let in_domain = r_lo * r_lo >= rho_c2;
            let s_lo = if in_domain { s_of(r_lo) } else { 0.0 };
            let (ta, tb) = if sigma > 0.0 {
                (t_of(s_lo), t_of(s_hi))
            } else {
                (t_of(s_hi), t_of(s_lo))
            };
            if tb + t_pad <= 0.0 || ta - t_pad >= best.t {
                continue;
            }
            let (c_lo, c_hi) = hull(&iv.c);
            // Interval bounds of g = c − (σk) S.
            let ks = sigma * k;
            let (g_lo, g_hi) = if ks >= 0.0 {
                (c_lo - ks * s_hi, c_hi - ks * s_lo)
            } else {
                (c_lo - ks * s_lo, c_hi - ks * s_hi)
            };
            if g_lo > 0.0 || g_hi < 0.0 {
                continue;
            }
            visits += 1;
            if visits > MAX_VISITS {
                stats.non_converged += 1;
                break;
            }
            let g0 = g_of(iv.c[0], iv.r[0]);
            let g1 = g_of(iv.c[3], iv.r[3]);
            let width = iv.u1 - iv.u0;
            let mut bracket = false;
            let mut decided = false;
            if in_domain && (k == 0.0 || s_lo > 0.0) {
                // g' = c' − σk r r'/S by interval arithmetic on the hulls (derivatives with
                // respect to this interval's own parameter). Bounding the two terms together,
                // not |c'| against |kS'|, matters where c' vanishes (the top of a rim) while
                // the whole g' does not: there a comparison of magnitudes never succeeds and
                // a whole neighbourhood would be subdivided to the floor.
                let dc = [
                    3.0 * (iv.c[1] - iv.c[0]),
                    3.0 * (iv.c[2] - iv.c[1]),
                    3.0 * (iv.c[3] - iv.c[2]),
                ];
                let dr = [
                    3.0 * (iv.r[1] - iv.r[0]),
                    3.0 * (iv.r[2] - iv.r[1]),
                    3.0 * (iv.r[3] - iv.r[2]),
                ];
                let (dc_lo, dc_hi) = hull(&dc);
                let (d_lo, d_hi) = if ks == 0.0 {
                    (dc_lo, dc_hi)
                } else {
                    let (dr_lo, dr_hi) = hull(&dr);
                    let p = [r_lo * dr_lo, r_lo * dr_hi, r_hi * dr_lo, r_hi * dr_hi];
                    let (p_lo, p_hi) = hull(&p);
                    let q = [p_lo / s_lo, p_lo / s_hi, p_hi / s_lo, p_hi / s_hi];
                    let (q_lo, q_hi) = hull(&q);
                    if ks > 0.0 {
                        (dc_lo - ks * q_hi, dc_hi - ks * q_lo)
                    } else {
                        (dc_lo - ks * q_lo, dc_hi - ks * q_hi)
                    }
                };
                if d_lo > 0.0 || d_hi < 0.0 {
                    decided = true;
                    bracket = g0 == 0.0 || g1 == 0.0 || (g0 < 0.0) != (g1 < 0.0);
                }
            }
            if !decided {
                let flat = g_lo.abs().max(g_hi.abs()) <= noise;
                if width <= WIDTH_FLOOR || flat || top + 2 > STACK {
                    // Tangent (the silhouette, where both branches meet) or lying in a flat
                    // ledge: only a clean sign change inside the domain counts.
                    decided = true;
                    bracket = !flat && in_domain && (g0 < 0.0) != (g1 < 0.0);
                }
            }
            if decided {
                if bracket {
                    let u = if g0 == 0.0 {
                        iv.u0
                    } else if g1 == 0.0 {
                        iv.u1
                    } else {
                        let guess = iv.u0 + width * g0 / (g0 - g1);
                        polish(eval, iv.u0, iv.u1, g0 < 0.0, guess, self.tol_u, stats)
                    };
                    let (r, ..) = sp.eval(u);
                    if best.offer(t_of(s_of(r)), u, i) {
                        found = true;
                        if best.any {
                            return true;
                        }
                    }
                }
                continue;
            }
            let (cl, cr) = split(&iv.c);
            let (rl, rr) = split(&iv.r);
            let mid = 0.5 * (iv.u0 + iv.u1);
            stack[top] = FlatIv {
                u0: mid,
                u1: iv.u1,
                c: cr,
                r: rr,
            };
            stack[top + 1] = FlatIv {
                u0: iv.u0,
                u1: mid,
                c: cl,
                r: rl,
            };
            top += 2;
        }
        found
    }

    /// Point, outward unit normal, UV = (φ / 2π, s) and the derivatives of the point with
    /// respect to u and v.
    ///
    /// The normal is outward for a closed profile. For an open sheet it points to the left of
    /// the profile as s increases, drawn with radius to the right and height up, which equals
    /// `normalize(dpdu × dpdv)`.
    ///
    /// On the axis (r = 0) the exact dp/du vanishes; the circle's direction is kept there with
    /// a length floor so that a frame built from it is never degenerate. Where the profile's
    /// derivative vanishes (coincident control points) dpdv follows the limiting tangent.
    pub fn surface(&self, ray: &Ray, hit: &RevolutionHit) -> (SurfacePoint, Vec2, Vec3, Vec3) {
        let i = (hit.span as usize).min(self.spans.len() - 1);
        let sp = &self.spans[i];
        let u = (hit.u as f64).clamp(0.0, 1.0);
        let m = self.spans.len() as f64;
        let (r, h, _, _) = sp.eval(u);
        let eps = self.scale * 1e-12;
        let (tr, th) = sp.tangent(u, eps);

        // The angle from the ray's point; where the point is on the axis any angle serves.
        let o = ray.o.as_dvec3();
        let d = ray.d.as_dvec3();
        let q = o + d * hit.t as f64;
        let phi = if q.x == 0.0 && q.z == 0.0 {
            0.0
        } else {
            q.z.atan2(q.x)
        };
        let (sin, cos) = phi.sin_cos();
        let r = r.max(0.0);
        let p = DVec3::new(r * cos, h, r * sin);

        let (nr, nh) = if self.closed {
            (self.orientation * th, -self.orientation * tr)
        } else {
            (-th, tr)
        };
        let len = nr.hypot(nh);
        let (nr, nh) = (nr / len, nh / len);
        let n = DVec3::new(nr * cos, nh, nr * sin);

        let dpdu = DVec3::new(-sin, 0.0, cos) * (TAU * r.max(self.scale * 1e-6));
        let (_, _, dr, dh) = sp.eval(u);
        let dpdv = if dr.hypot(dh) > eps {
            DVec3::new(dr * cos, dh, dr * sin) * m
        } else {
            let tl = tr.hypot(th);
            DVec3::new(tr * cos, th, tr * sin) * (m * eps / tl)
        };
        let uv_u = if phi < 0.0 {
            phi / TAU + 1.0
        } else {
            phi / TAU
        };
        let uv = Vec2::new((uv_u as f32).min(1.0 - f32::EPSILON / 2.0), hit.s);
        // In f64 with the exact normal: only a ray within ~1e-15 of tangent can come out on
        // the wrong side, where either answer is a graze.
        let front = d.dot(n) < 0.0;
        let n = n.as_vec3().normalize_or(Vec3::Y);
        (
            SurfacePoint {
                p: p.as_vec3(),
                n,
                // The surface is smooth and its normal exact: nothing to interpolate.
                ns: n,
                front,
            },
            uv,
            dpdu.as_vec3(),
            dpdv.as_vec3(),
        )
    }
}

/// Where the control polygon of a Bernstein polynomial first crosses zero, in [0, 1]: a cheap
/// first guess for the root of a single-root interval.
#[inline]
fn control_crossing<const N: usize>(c: &[f64; N]) -> f64 {
    let deg = (N - 1) as f64;
    let mut prev: Option<(usize, f64)> = None;
    for (j, &v) in c.iter().enumerate() {
        if v == 0.0 {
            continue;
        }
        if let Some((i, pv)) = prev
            && (pv < 0.0) != (v < 0.0)
        {
            let x = i as f64 + (j - i) as f64 * pv / (pv - v);
            return x / deg;
        }
        prev = Some((j, v));
    }
    0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_join_and_interpolate_the_ends() {
        let prof = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 2.0), (0.0, 2.5)];
        let rev = Revolution::new(&prof, DEFAULT_TOLERANCE).unwrap();
        assert_eq!(rev.spans.len(), 2);
        assert_eq!((rev.spans[0].r[0], rev.spans[0].h[0]), (0.0, 0.0));
        assert_eq!((rev.spans[1].r[3], rev.spans[1].h[3]), (0.0, 2.5));
        assert_eq!(rev.spans[0].r[3], rev.spans[1].r[0]);
        // C² at the joint: equal first derivatives of the two spans.
        let (_, _, dr0, dh0) = rev.spans[0].eval(1.0);
        let (_, _, dr1, dh1) = rev.spans[1].eval(0.0);
        assert!((dr0 - dr1).abs() < 1e-12 && (dh0 - dh1).abs() < 1e-12);
        assert!(rev.is_closed());
    }

    #[test]
    fn split_matches_evaluation() {
        let c = [1.0, -2.0, 0.5, 3.0, -1.0, 2.0, 0.25];
        let (l, r) = split(&c);
        let bern = |c: &[f64; 7], x: f64| {
            let mut t = *c;
            for j in 1..7 {
                for i in 0..7 - j {
                    t[i] = t[i] * (1.0 - x) + t[i + 1] * x;
                }
            }
            t[0]
        };
        for x in [0.0, 0.3, 0.7, 1.0] {
            assert!((bern(&l, x) - bern(&c, 0.5 * x)).abs() < 1e-12);
            assert!((bern(&r, x) - bern(&c, 0.5 + 0.5 * x)).abs() < 1e-12);
        }
        assert_eq!(variations(&c).0, 4);
    }
}
