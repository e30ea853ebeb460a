//! Surfaces of revolution against independent references: a dense tessellation, an exhaustive
//! root scan, special rays (axis, poles, horizontal, rim, joints), spawned rays and errors.
//!
//! The profile is evaluated here by de Boor's algorithm on the clamped knots, independently of
//! the module's Bézier conversion, so every comparison also checks that conversion.

use glam::{DVec3, Vec3};
use prism::geometry::revolution::{DEFAULT_TOLERANCE, Revolution, RevolutionHit, RevolutionStats};
use prism::geometry::{Ray, offset_ray_origin};

use prism::geometry::revolution::GOBLET_PROFILE as GOBLET;

/// An open sheet: neither end on the axis; it bulges, pinches and flares.
const VASE: [(f32, f32); 6] = [
    (0.3, 0.0),
    (0.6, 0.2),
    (0.5, 0.6),
    (0.15, 0.8),
    (0.3, 1.1),
    (0.45, 1.3),
];

/// A closed profile whose control polygon, closed along the axis, is convex: the solid is
/// convex, so a ray leaving it outwards never meets it again.
const EGG: [(f32, f32); 6] = [
    (0.0, -1.0),
    (0.7, -1.0),
    (1.1, -0.2),
    (1.0, 0.6),
    (0.5, 1.1),
    (0.0, 1.1),
];

#[path = "common/splitmix.rs"]
mod splitmix;
use splitmix::SplitMix as Rng;

/// A uniform direction on the unit sphere.
trait Sphere {
    fn sphere(&mut self) -> DVec3;
}

impl Sphere for Rng {
    fn sphere(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), z, s * phi.sin())
    }
}

/// The profile as a clamped uniform cubic B-spline over s ∈ [0, 1], with its derivative
/// spline, both evaluated by de Boor's algorithm.
struct Curve {
    ctrl: Vec<[f64; 2]>,
    knots: Vec<f64>,
    dctrl: Vec<[f64; 2]>,
    dknots: Vec<f64>,
    spans: usize,
    /// The profile at `SAMPLES + 1` uniform s, for scans.
    table: Vec<[f64; 2]>,
}

/// Scan resolution in s: root pairs closer than this can slip between samples.
const SAMPLES: usize = 1 << 16;

fn de_boor(p: usize, ctrl: &[[f64; 2]], knots: &[f64], x: f64) -> [f64; 2] {
    let n = ctrl.len();
    let mut l = p;
    while l < n - 1 && x >= knots[l + 1] {
        l += 1;
    }
    let mut d = [[0.0; 2]; 4];
    d[..=p].copy_from_slice(&ctrl[l - p..=l]);
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = j + l - p;
            let a = (x - knots[i]) / (knots[i + p + 1 - r] - knots[i]);
            d[j] = [
                (1.0 - a) * d[j - 1][0] + a * d[j][0],
                (1.0 - a) * d[j - 1][1] + a * d[j][1],
            ];
        }
    }
    d[p]
}

impl Curve {
    fn new(profile: &[(f32, f32)]) -> Self {
        let n = profile.len();
        let m = n - 3;
        let ctrl: Vec<[f64; 2]> = profile.iter().map(|&(r, h)| [r as f64, h as f64]).collect();
        let knots: Vec<f64> = (0..n + 4)
            .map(|i| ((i as f64 - 3.0) / m as f64).clamp(0.0, 1.0))
            .collect();
        let dctrl = (0..n - 1)
            .map(|i| {
                let w = 3.0 / (knots[i + 4] - knots[i + 1]);
                [
                    w * (ctrl[i + 1][0] - ctrl[i][0]),
                    w * (ctrl[i + 1][1] - ctrl[i][1]),
                ]
            })
            .collect();
        let dknots = knots[1..n + 3].to_vec();
        let mut c = Self {
            ctrl,
            knots,
            dctrl,
            dknots,
            spans: m,
            table: Vec::new(),
        };
        c.table = (0..=SAMPLES)
            .map(|i| c.at(i as f64 / SAMPLES as f64))
            .collect();
        c
    }
    fn at(&self, s: f64) -> [f64; 2] {
        de_boor(3, &self.ctrl, &self.knots, s.clamp(0.0, 1.0))
    }
    fn deriv(&self, s: f64) -> [f64; 2] {
        de_boor(2, &self.dctrl, &self.dknots, s.clamp(0.0, 1.0))
    }
    fn point(&self, s: f64, phi: f64) -> DVec3 {
        let [r, h] = self.at(s);
        DVec3::new(r * phi.cos(), h, r * phi.sin())
    }
    /// Unit normal (orientation not fixed) and the two unit tangents at (s, φ).
    fn frame(&self, s: f64, phi: f64) -> (DVec3, DVec3, DVec3) {
        let [dr, dh] = self.deriv(s);
        let l = dr.hypot(dh);
        let (c, sn) = (phi.cos(), phi.sin());
        let n = DVec3::new(dh * c, -dr, dh * sn) / l;
        let e1 = DVec3::new(-sn, 0.0, c);
        let e2 = DVec3::new(dr * c, dh, dr * sn) / l;
        (n, e1, e2)
    }
    /// Distance in the (r, y) half-plane from (rho, y) to the profile: a scan of every 16th
    /// table entry, then a ternary refinement over the 32 samples around the best.
    fn distance_2d(&self, rho: f64, y: f64) -> f64 {
        const STRIDE: usize = 16;
        let mut best = (f64::INFINITY, 0);
        for (i, p) in self.table.iter().enumerate().step_by(STRIDE) {
            let d = (p[0] - rho) * (p[0] - rho) + (p[1] - y) * (p[1] - y);
            if d < best.0 {
                best = (d, i);
            }
        }
        let dist = |s: f64| {
            let [r, h] = self.at(s);
            (r - rho).hypot(h - y)
        };
        let step = STRIDE as f64 / SAMPLES as f64;
        let s0 = best.1 as f64 / SAMPLES as f64;
        let (mut a, mut b) = ((s0 - step).max(0.0), (s0 + step).min(1.0));
        for _ in 0..60 {
            let m1 = a + (b - a) / 3.0;
            let m2 = b - (b - a) / 3.0;
            if dist(m1) < dist(m2) {
                b = m2;
            } else {
                a = m1;
            }
        }
        dist(0.5 * (a + b)).min(best.0.sqrt())
    }
}

fn to_f64(ray: &Ray) -> (DVec3, DVec3) {
    (ray.o.as_dvec3(), ray.d.as_dvec3())
}

/// Every crossing of the ray with the exact surface, t > 0 sorted, by an exhaustive scan in s
/// with sign changes refined by bisection. The ray is cut by its vertical plane: there the
/// surface is the pair of curves (σ S(s), h(s)), S = √(r² − ρ_c²), σ = ±1, and the ray a line
/// of direction (cos θ, sin θ), so G_σ(s) = cos θ (h − y_c) − σ sin θ S(s) is the signed
/// distance of a curve point from the line, well scaled for any slope. A vertical ray scans
/// r(s) − ρ instead.
fn reference_roots(curve: &Curve, ray: &Ray) -> Vec<f64> {
    let (o, d_raw) = to_f64(ray);
    let len = d_raw.length();
    let d = d_raw / len;
    let a = d.x * d.x + d.z * d.z;
    let mut ts = Vec::new();
    // Scans f(r, h) (None outside its domain) over the table; sign changes between
    // consecutive samples are bisected on the curve itself. Where the domain starts or ends
    // between two samples, its edge is located by bisection and scanned as a sample too.
    fn scan(curve: &Curve, f: impl Fn([f64; 2]) -> Option<f64>, out: &mut Vec<f64>) {
        let f_at = |s: f64| f(curve.at(s));
        let step = 1.0 / SAMPLES as f64;
        let mut prev: Option<(f64, f64)> = None;
        let mut prev_s = 0.0;
        let push = |prev: Option<(f64, f64)>, s: f64, v: f64, out: &mut Vec<f64>| {
            if v == 0.0 {
                out.push(s);
            } else if let Some((ps, pv)) = prev
                && pv != 0.0
                && (v < 0.0) != (pv < 0.0)
            {
                let (mut lo, mut hi) = (ps, s);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    match f_at(mid) {
                        Some(m) if (m < 0.0) == (pv < 0.0) => lo = mid,
                        Some(_) => hi = mid,
                        None => break,
                    }
                }
                out.push(0.5 * (lo + hi));
            }
        };
        for (i, &p) in curve.table.iter().enumerate() {
            let s = i as f64 * step;
            let v = f(p);
            if i > 0 && prev.is_some() != v.is_some() {
                // The domain's edge between prev_s and s.
                let (mut lo, mut hi) = (prev_s, s);
                let inside_lo = prev.is_some();
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if f_at(mid).is_some() == inside_lo {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let edge = if inside_lo { lo } else { hi };
                if let Some(ve) = f_at(edge) {
                    push(prev, edge, ve, out);
                    prev = Some((edge, ve));
                }
            }
            match v {
                Some(v) => {
                    push(prev, s, v, out);
                    prev = Some((s, v));
                }
                None => prev = None,
            }
            prev_s = s;
        }
    }
    if a < 1e-20 {
        let rho = o.x.hypot(o.z);
        let mut ss = Vec::new();
        scan(curve, |[r, _]| Some(r - rho), &mut ss);
        for s in ss {
            ts.push((curve.at(s)[1] - o.y) / d.y);
        }
    } else {
        let sa = a.sqrt();
        let tc = -(o.x * d.x + o.z * d.z) / a;
        let cross = o.x * d.z - o.z * d.x;
        let rc2 = cross * cross / a;
        let yc = o.y + d.y * tc;
        for sigma in [-1.0, 1.0] {
            let g = |[r, h]: [f64; 2]| {
                (r * r >= rc2).then(|| sa * (h - yc) - sigma * d.y * (r * r - rc2).sqrt())
            };
            let mut ss = Vec::new();
            scan(curve, g, &mut ss);
            for s in ss {
                let r = curve.at(s)[0];
                ts.push(tc + sigma * (r * r - rc2).max(0.0).sqrt() / sa);
            }
        }
    }
    let mut ts: Vec<f64> = ts
        .into_iter()
        .filter(|&t| t > 0.0)
        .map(|t| t / len)
        .collect();
    ts.sort_by(f64::total_cmp);
    ts
}

// ---------------------------------------------------------------------------------------------
// Tessellation.

struct Mesh {
    bvh: Bvh,
    /// Largest distance between the mesh and the surface (chord plus sagitta).
    deviation: f64,
}

fn tessellate(curve: &Curve, per_span: usize, n_phi: usize) -> Mesh {
    let ns = per_span * curve.spans;
    let dphi = std::f64::consts::TAU / n_phi as f64;
    let mut deviation: f64 = 0.0;
    for i in 0..ns {
        let (s0, s1) = (i as f64 / ns as f64, (i + 1) as f64 / ns as f64);
        let (a, b) = (curve.at(s0), curve.at(s1));
        let ab = [b[0] - a[0], b[1] - a[1]];
        let len2 = ab[0] * ab[0] + ab[1] * ab[1];
        let mut chord: f64 = 0.0;
        let mut r_max = a[0].max(b[0]);
        for j in 1..16 {
            let p = curve.at(s0 + (s1 - s0) * j as f64 / 16.0);
            r_max = r_max.max(p[0]);
            let w = if len2 > 0.0 {
                (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            chord = chord.max((p[0] - a[0] - w * ab[0]).hypot(p[1] - a[1] - w * ab[1]));
        }
        deviation = deviation.max(chord + r_max * (1.0 - (0.5 * dphi).cos()));
    }
    // The chord was sampled, not maximised: a margin for what the samples missed.
    let deviation = deviation * 1.25;
    let grid: Vec<Vec<DVec3>> = (0..=ns)
        .map(|i| {
            (0..n_phi)
                .map(|j| curve.point(i as f64 / ns as f64, j as f64 * dphi))
                .collect()
        })
        .collect();
    let mut tris = Vec::with_capacity(2 * ns * n_phi);
    for i in 0..ns {
        for j in 0..n_phi {
            let j1 = (j + 1) % n_phi;
            let (a, b, c, d) = (grid[i][j], grid[i][j1], grid[i + 1][j], grid[i + 1][j1]);
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
    }
    Mesh {
        bvh: Bvh::new(tris),
        deviation,
    }
}

/// A plain median-split BVH over the triangles, all in f64.
struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<[DVec3; 3]>,
}

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first triangle and count; interior: count 0, left child next, right at `first`.
    first: usize,
    count: usize,
}

impl Bvh {
    fn new(mut tris: Vec<[DVec3; 3]>) -> Self {
        let mut nodes = Vec::with_capacity(tris.len() / 2);
        Self::build(&mut tris, 0, &mut nodes);
        Self { nodes, tris }
    }

    fn build(tris: &mut [[DVec3; 3]], offset: usize, nodes: &mut Vec<Node>) {
        let (lo, hi) = tris
            .iter()
            .flatten()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let me = nodes.len();
        nodes.push(Node {
            lo,
            hi,
            first: offset,
            count: tris.len(),
        });
        if tris.len() <= 4 {
            return;
        }
        let axis = (hi - lo).max_position();
        let mid = tris.len() / 2;
        let key = |t: &[DVec3; 3]| t[0][axis] + t[1][axis] + t[2][axis];
        tris.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let (left, right) = tris.split_at_mut(mid);
        Self::build(left, offset, nodes);
        nodes[me].first = nodes.len();
        nodes[me].count = 0;
        Self::build(right, offset + mid, nodes);
    }

    fn slab(n: &Node, o: DVec3, inv: DVec3, t_max: f64) -> Option<f64> {
        let a = (n.lo - o) * inv;
        let b = (n.hi - o) * inv;
        // NaN (0 · ∞) from an axis-parallel ray on a slab plane is ignored by min/max.
        let t0 = a.min(b).max_element().max(0.0);
        let t1 = a.max(b).min_element().min(t_max);
        (t0 <= t1 * (1.0 + 1e-12)).then_some(t0)
    }

    fn intersect(&self, o: DVec3, d: DVec3) -> Option<f64> {
        let inv = d.recip();
        let mut best = f64::INFINITY;
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if Self::slab(n, o, inv, best).is_none() {
                continue;
            }
            if n.count > 0 {
                for t in &self.tris[n.first..n.first + n.count] {
                    if let Some(t) = ray_triangle(o, d, t) {
                        best = best.min(t);
                    }
                }
                continue;
            }
            let (l, r) = (i + 1, n.first);
            let tl = Self::slab(&self.nodes[l], o, inv, best);
            let tr = Self::slab(&self.nodes[r], o, inv, best);
            // Nearer child popped first.
            match (tl, tr) {
                (Some(a), Some(b)) if a <= b => stack.extend([r, l]),
                (Some(_), Some(_)) => stack.extend([l, r]),
                (Some(_), None) => stack.push(l),
                (None, Some(_)) => stack.push(r),
                (None, None) => {}
            }
        }
        best.is_finite().then_some(best)
    }
}

/// Möller–Trumbore in f64, edges inclusive.
fn ray_triangle(o: DVec3, d: DVec3, tri: &[DVec3; 3]) -> Option<f64> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - tri[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some(t)
}

impl Mesh {
    fn intersect(&self, ray: &Ray) -> Option<f64> {
        let (o, d) = to_f64(ray);
        self.bvh.intersect(o, d)
    }
}

fn f32_ray(o: DVec3, d: DVec3) -> Ray {
    Ray::new(o.as_vec3(), d.as_vec3())
}

/// Rays of every kind for a profile whose bounds are `lo..hi`: from far away at the bounds,
/// from inside the bounds, grazing the surface at random points (just outside and just
/// inside), and near-horizontal ones on both sides of the flat-path threshold.
fn ray_mix(curve: &Curve, lo: DVec3, hi: DVec3, n: usize, rng: &mut Rng) -> Vec<Ray> {
    let center = 0.5 * (lo + hi);
    let radius = (hi - lo).length();
    let in_box = |rng: &mut Rng| {
        DVec3::new(
            rng.range(lo.x, hi.x),
            rng.range(lo.y, hi.y),
            rng.range(lo.z, hi.z),
        )
    };
    (0..n)
        .map(|i| {
            let scale = rng.range(0.5, 2.0);
            match i % 10 {
                0..=4 => {
                    let o = center + rng.sphere() * radius * 1.5;
                    f32_ray(o, (in_box(rng) - o).normalize() * scale)
                }
                5 | 6 => f32_ray(in_box(rng), rng.sphere() * scale),
                7 | 8 => {
                    let s = rng.range(0.001, 0.999);
                    let phi = rng.range(0.0, std::f64::consts::TAU);
                    let q = curve.point(s, phi);
                    let (nrm, e1, e2) = curve.frame(s, phi);
                    let b = rng.range(0.0, std::f64::consts::TAU);
                    let dir = e1 * b.cos() + e2 * b.sin();
                    let eps = 10f64.powf(-rng.range(1.0, 5.0));
                    let side = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                    f32_ray(q - dir * radius + nrm * eps * side, dir * scale)
                }
                _ => {
                    let o = center + rng.sphere() * radius * 1.5;
                    let target = in_box(rng);
                    let slope = match i % 40 {
                        9 => 0.0,
                        19 => rng.range(-1e-5, 1e-5),
                        29 => rng.range(-2e-3, 2e-3),
                        _ => rng.range(-0.05, 0.05),
                    };
                    let flat = DVec3::new(target.x - o.x, 0.0, target.z - o.z).normalize();
                    let o = DVec3::new(o.x, target.y - slope * (target - o).length(), o.z);
                    f32_ray(o, (flat + DVec3::Y * slope) * scale)
                }
            }
        })
        .collect()
}

struct Agreement {
    rays: usize,
    both_hit: usize,
    both_miss: usize,
    excused: usize,
    /// Largest t difference beyond the tessellation's share, relative to t.
    max_excess: f64,
}

/// Distance from the ray's point at `t` to the surface.
fn distance_at(curve: &Curve, ray: &Ray, t: f64) -> f64 {
    let (o, d) = to_f64(ray);
    let p = o + d * t;
    curve.distance_2d(p.x.hypot(p.z), p.y)
}

/// Largest distance to the surface between two crossings: how deep a ray that enters at
/// `t0` and leaves at `t1` gets (or, for a sheet, how far past it).
fn depth_between(curve: &Curve, ray: &Ray, t0: f64, t1: f64) -> f64 {
    (1..8)
        .map(|k| distance_at(curve, ray, t0 + (t1 - t0) * k as f64 / 8.0))
        .fold(0.0, f64::max)
}

/// The surface's answer must be the exhaustive scan's first crossing. Allowed differences are
/// tangencies below the scan's or the isolation's resolution: a hit nearer than the scan's
/// first root must lie on the surface, and a crossing the surface does not report must be
/// half of a pair too shallow to matter (depth below 10⁻⁶).
fn check_against_reference(curve: &Curve, ray: &Ray, a: Option<RevolutionHit>, refs: &[f64]) {
    let on_surface = |t: f64| distance_at(curve, ray, t) < 1e-5;
    match (a.map(|h| h.t as f64), refs.first()) {
        (None, None) => {}
        (Some(ta), Some(&tr)) if (ta - tr).abs() <= 1e-4 * tr => {}
        (Some(ta), first) if first.is_none_or(|&tr| ta < tr) && on_surface(ta) => {}
        (None, Some(&tr)) if refs.len() >= 2 && depth_between(curve, ray, tr, refs[1]) < 1e-6 => {}
        (ta, _) => panic!("{ray:?}: surface {ta:?} ({a:?}), exhaustive scan {refs:?}"),
    }
}

/// Compares surface and mesh on `rays`. They agree when both miss, or both hit with t within
/// 10⁻⁴ relative plus the tessellation's error along the ray (2δ / cos θ, θ the incidence
/// angle, capped at cos θ = 0.1; δ the mesh deviation). Otherwise the surface must match the
/// exhaustive scan, and the mesh's different answer must lie in the tangency band of width
/// `2δ`: the ray starts that close to the surface; or, where the surface's crossing comes
/// first, the ray gets no deeper than the band before it leaves the surface again or meets
/// the mesh (or, on a sheet, crosses that close to the edge); or, where the mesh's crossing
/// comes first (the scan having confirmed the surface has none there), the ray is within the
/// band of the surface where it meets the mesh.
fn compare(rev: &Revolution, curve: &Curve, open: bool, mesh: &Mesh, rays: &[Ray]) -> Agreement {
    let band = 2.0 * mesh.deviation;
    let mut stats = RevolutionStats::default();
    let mut out = Agreement {
        rays: rays.len(),
        both_hit: 0,
        both_miss: 0,
        excused: 0,
        max_excess: 0.0,
    };
    let ends = [curve.at(0.0), curve.at(1.0)];
    for (i, ray) in rays.iter().enumerate() {
        let a = rev.intersect(ray, f32::INFINITY, &mut stats);
        let m = mesh.intersect(ray);
        let dlen = ray.d.as_dvec3().length();
        let ok = match (a, m) {
            (None, None) => {
                out.both_miss += 1;
                true
            }
            (Some(h), Some(tm)) => {
                let ta = h.t as f64;
                let (sp, ..) = rev.surface(ray, &h);
                let cos = (sp.n.as_dvec3().dot(ray.d.as_dvec3()) / dlen).abs();
                let tess = 2.0 * mesh.deviation / cos.max(0.1);
                let err = (ta - tm).abs() * dlen;
                if err <= 1e-4 * ta * dlen + tess {
                    out.both_hit += 1;
                    out.max_excess = out.max_excess.max((err - tess).max(0.0) / (ta * dlen));
                    true
                } else {
                    false
                }
            }
            _ => false,
        };
        if ok {
            continue;
        }
        let refs = reference_roots(curve, ray);
        check_against_reference(curve, ray, a, &refs);
        let ta = a.map(|h| h.t as f64);
        let excused = if distance_at(curve, ray, 0.0) <= band {
            true
        } else if let Some(tm) = m.filter(|&tm| ta.is_none_or(|ta| tm < ta)) {
            // The scan has confirmed the surface is not crossed before `ta`: the mesh met a
            // graze here.
            distance_at(curve, ray, tm) <= band
        } else {
            let ta = ta.unwrap();
            let p = ray.at(ta as f32).as_dvec3();
            let (rho, y) = (p.x.hypot(p.z), p.y);
            let near_edge = open && ends.iter().any(|e| (e[0] - rho).hypot(e[1] - y) <= band);
            let next = refs.iter().copied().find(|&t| t > ta + 1e-9 * ta.max(1.0));
            let until = next
                .unwrap_or(f64::INFINITY)
                .min(m.unwrap_or(f64::INFINITY));
            near_edge || (until.is_finite() && depth_between(curve, ray, ta, until) <= band)
        };
        assert!(
            excused,
            "ray {i} {ray:?}: surface {a:?} vs mesh {m:?} outside the tangency band \
             {band:.3e} (scan {refs:?})"
        );
        out.excused += 1;
    }
    assert_eq!(stats.rays, rays.len() as u64);
    out
}

/// 10⁵ rays of every kind on the goblet (and 2·10⁴ on an open sheet) against a tessellation
/// of 96 rings per span × 256 around; see [`compare`] for what counts as agreement and for the
/// tangency band (twice the mesh's measured deviation from the surface).
#[test]
fn agrees_with_dense_tessellation() {
    let start = std::time::Instant::now();
    let mut rng = Rng(7);
    for (name, profile, n_rays, open) in [
        ("goblet", &GOBLET[..], 100_000, false),
        ("vase", &VASE[..], 20_000, true),
    ] {
        let rev = Revolution::new(profile, DEFAULT_TOLERANCE).unwrap();
        assert_eq!(rev.is_closed(), !open);
        let curve = Curve::new(profile);
        let mesh = tessellate(&curve, 96, 256);
        let b = rev.bounds();
        let rays = ray_mix(&curve, b.min.as_dvec3(), b.max.as_dvec3(), n_rays, &mut rng);
        let r = compare(&rev, &curve, open, &mesh, &rays);
        println!(
            "{name}: {} triangles, deviation {:.2e}; {} rays: {} both hit, {} both miss, {} \
             settled by the exhaustive scan and the tangency band; largest t difference beyond \
             the tessellation's share {:.2e} relative",
            mesh.bvh.tris.len(),
            mesh.deviation,
            r.rays,
            r.both_hit,
            r.both_miss,
            r.excused,
            r.max_excess
        );
        assert!(r.both_hit > r.rays / 3, "too few hits to mean anything");
        assert!(
            r.excused * 100 < r.rays * 3,
            "tangency band excuses {} of {} rays",
            r.excused,
            r.rays
        );
    }
    println!("tessellation comparison: {:.2?}", start.elapsed());
}

/// Rays through the goblet's stem and bowl, crossing the surface four times or more (three
/// when they start inside the stem): the hit must be the nearest crossing of an exhaustive
/// scan, never a farther one. Then flat rays on both sides of the flat-path threshold.
#[test]
fn never_a_farther_root() {
    let rev = Revolution::new(&GOBLET, DEFAULT_TOLERANCE).unwrap();
    let curve = Curve::new(&GOBLET);
    let mut rng = Rng(11);
    let mut stats = RevolutionStats::default();
    let (mut checked, mut many, mut ref_missed, mut inside) = (0, 0, 0, 0);
    for i in 0..400 {
        // A point inside the stem and one inside the bowl's wall.
        let ys = rng.range(0.2, 0.5);
        let stem_r = (0..64)
            .map(|j| curve.at(0.3 + 0.2 * j as f64 / 64.0))
            .min_by(|a, b| (a[1] - ys).abs().total_cmp(&(b[1] - ys).abs()))
            .unwrap()[0];
        let a = rng.range(0.0, std::f64::consts::TAU);
        let p_stem =
            DVec3::new(a.cos(), 0.0, a.sin()) * stem_r * rng.range(0.0, 0.8) + DVec3::Y * ys;
        let s_out = rng.range(0.62, 0.7);
        let s_in = 1.0 - (1.0 - s_out) * 0.9;
        let b = a + std::f64::consts::PI + rng.range(-0.6, 0.6);
        let w = rng.range(0.2, 0.8);
        let pa = curve.point(s_out, b);
        let pb = curve.point(s_in, b);
        let p_bowl = pa * (1.0 - w) + pb * w;
        let dir = (p_bowl - p_stem).normalize();
        // Half start outside, beyond the stem; half inside the stem itself.
        let o = if i % 2 == 0 {
            p_stem - dir * 2.0
        } else {
            inside += 1;
            p_stem
        };
        let ray = f32_ray(o, dir * rng.range(0.5, 2.0));
        let refs = reference_roots(&curve, &ray);
        if refs.len() >= 4 {
            many += 1;
        }
        let got = rev.intersect(&ray, f32::INFINITY, &mut stats);
        match (got, refs.first()) {
            (None, None) => {}
            (Some(h), Some(&tr)) => {
                let t = h.t as f64;
                assert!(
                    t <= tr * (1.0 + 1e-5),
                    "ray {i}: hit at t = {t} beyond the nearest root {tr} of {refs:?}"
                );
                if t < tr * (1.0 - 1e-5) {
                    // Nearer than the scan: the scan must have missed a close pair; the hit
                    // must then lie on the surface.
                    let p = ray.at(h.t).as_dvec3();
                    let off = curve.distance_2d(p.x.hypot(p.z), p.y);
                    assert!(
                        off < 1e-5,
                        "ray {i}: spurious hit {t} ({off} off the surface)"
                    );
                    ref_missed += 1;
                }
                checked += 1;
            }
            (got, r) => panic!("ray {i}: surface {got:?}, reference {r:?} of {refs:?}"),
        }
    }
    println!(
        "{checked} hits checked, {many} rays with >= 4 crossings, {inside} starting inside the \
         stem, {ref_missed} where the scan missed a root; {stats:?}"
    );
    // From outside: into and out of the stem, into and out of the bowl.
    assert!(many >= 190, "only {many} rays cross four times or more");
    assert!(ref_missed <= 4);

    // Horizontal and nearly horizontal rays through stem and bowl, on both sides of the
    // flat-path threshold, against the same scan.
    let tilts = [0.0, 1e-7, -1e-6, 5e-4, -9.99e-4, 1.001e-3, -2e-3, 1e-2];
    for i in 0..400 {
        let y = rng.range(0.02, 1.38);
        let a = rng.range(0.0, std::f64::consts::TAU);
        let dir = DVec3::new(a.cos(), tilts[i % tilts.len()], a.sin());
        let off = DVec3::new(-dir.z, 0.0, dir.x) * rng.range(-0.3, 0.3);
        let ray = f32_ray(off + DVec3::Y * y - dir * 2.0, dir);
        let refs = reference_roots(&curve, &ray);
        let got = rev.intersect(&ray, f32::INFINITY, &mut stats);
        match (got, refs.first()) {
            (None, None) => {}
            (Some(h), Some(&tr)) => assert!(
                (h.t as f64 - tr).abs() <= tr * 1e-5,
                "flat ray {i}: {} vs {tr} of {refs:?}",
                h.t
            ),
            (got, r) => panic!("flat ray {i}: surface {got:?}, reference {r:?}"),
        }
    }
    assert_eq!(stats.non_converged, 0);
}

/// Checks the frame at a hit: finite, unit normal perpendicular to both tangents and (off the
/// axis) along the reference curve's normal, and the point on the surface.
fn check_frame(rev: &Revolution, curve: &Curve, ray: &Ray, h: &RevolutionHit, what: &str) {
    assert!(
        h.t.is_finite() && h.s.is_finite() && h.u.is_finite(),
        "{what}: {h:?}"
    );
    assert!((0.0..=1.0).contains(&h.s), "{what}: s = {}", h.s);
    let (sp, uv, dpdu, dpdv) = rev.surface(ray, h);
    for v in [sp.p, sp.n, dpdu, dpdv] {
        assert!(
            v.is_finite(),
            "{what}: non-finite frame {sp:?} {dpdu} {dpdv}"
        );
    }
    assert!(
        uv.is_finite() && (0.0..1.0).contains(&uv.x),
        "{what}: uv {uv}"
    );
    assert!(
        (sp.n.length() - 1.0).abs() < 1e-5,
        "{what}: |n| = {}",
        sp.n.length()
    );
    assert!(
        dpdu.length() > 0.0 && dpdv.length() > 0.0,
        "{what}: zero tangent"
    );
    for t in [dpdu, dpdv] {
        let c = sp.n.dot(t.normalize()).abs();
        assert!(c < 1e-5, "{what}: n·tangent = {c}");
    }
    // Against the reference: same normal line as the de Boor curve's at (s, φ).
    let s = h.s as f64;
    let [dr, dh] = curve.deriv(s);
    if dr.hypot(dh) > 1e-6 {
        let phi = (sp.p.z as f64).atan2(sp.p.x as f64);
        let (n_ref, ..) = curve.frame(s, phi);
        let r = curve.at(s)[0];
        // Off the axis the normal must match up to sign; on it φ is arbitrary only when the
        // normal is vertical, which the frame then also is.
        if r > 1e-4 || n_ref.y.abs() > 0.999 {
            let c = n_ref.dot(sp.n.as_dvec3()).abs();
            assert!(
                c > 1.0 - 1e-6,
                "{what}: normal {} vs reference {n_ref}",
                sp.n
            );
        }
    }
    let p = sp.p.as_dvec3();
    let off = curve.distance_2d(p.x.hypot(p.z), p.y);
    assert!(off < 1e-5, "{what}: point {p} is {off} off the surface");
}

#[test]
fn special_rays() {
    let rev = Revolution::new(&GOBLET, DEFAULT_TOLERANCE).unwrap();
    let curve = Curve::new(&GOBLET);
    let mut st = RevolutionStats::default();
    let hit = |ray: &Ray, st: &mut RevolutionStats| rev.intersect(ray, f32::INFINITY, st);

    // Along the axis, upwards from below: the base's pole, normal straight down.
    let up = Ray::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y);
    let h = hit(&up, &mut st).expect("axis ray from below");
    assert!((h.t - 1.0).abs() < 1e-6, "{h:?}");
    check_frame(&rev, &curve, &up, &h, "axis up");
    let (sp, ..) = rev.surface(&up, &h);
    assert!((sp.n - Vec3::NEG_Y).length() < 1e-6 && sp.front, "{sp:?}");

    // Down the axis from above: the bottom of the cup, the profile's other pole. The profile
    // meets the axis there at an angle, so the point is a cone's apex: the normal is one of the
    // cone's (any φ), which leans up into the cup; then on through the glass to the base.
    let down = Ray::new(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y);
    let h = hit(&down, &mut st).expect("axis ray from above");
    assert!((h.t - 2.3).abs() < 1e-5, "{h:?}");
    check_frame(&rev, &curve, &down, &h, "axis down");
    let (sp, ..) = rev.surface(&down, &h);
    let [dr, dh] = curve.deriv(1.0);
    let cone_ny = -dr / dr.hypot(dh);
    assert!(
        ((sp.n.y as f64) - cone_ny).abs() < 1e-6 && sp.front,
        "{sp:?} vs {cone_ny}"
    );
    let through = Ray::new(offset_ray_origin(sp.p, -sp.n), Vec3::NEG_Y);
    let h2 = hit(&through, &mut st).expect("through the stem");
    // The offset moves the origin by a few hundred ULPs along the tilted normal.
    assert!((h2.t - 0.7).abs() < 1e-4, "{h2:?}");
    let (sp2, ..) = rev.surface(&through, &h2);
    assert!(
        (sp2.n - Vec3::NEG_Y).length() < 1e-6 && !sp2.front,
        "{sp2:?}"
    );

    // Slanted rays through both poles: the hit is the pole itself.
    let mut rng = Rng(5);
    for i in 0..200 {
        let theta = rng.range(0.0, 0.35);
        let a = rng.range(0.0, std::f64::consts::TAU);
        let w = DVec3::new(theta.sin() * a.cos(), theta.cos(), theta.sin() * a.sin());
        for (pole, from) in [(DVec3::ZERO, -w), (DVec3::Y * 0.7, w)] {
            let o = pole + from * 0.6;
            let ray = f32_ray(o, (pole - o) * rng.range(0.5, 2.0));
            let h = hit(&ray, &mut st).unwrap_or_else(|| panic!("pole ray {i} missed"));
            check_frame(&rev, &curve, &ray, &h, "pole ray");
            let p = ray.at(h.t).as_dvec3();
            assert!(
                (p - pole).length() < 1e-5,
                "pole ray {i}: hit {p}, pole {pole}"
            );
        }
    }

    // Exactly horizontal rays, including at the base plane, the joints' heights and the rim.
    let m = curve.spans;
    let mut heights = vec![0.0, 0.05, 0.1, 0.3, 0.6, 0.9, 1.2, 1.39, 1.4];
    heights.extend((0..=m).map(|k| curve.at(k as f64 / m as f64)[1]));
    let rim_top = (0..20_000)
        .map(|i| curve.at(0.7 + 0.2 * i as f64 / 20_000.0)[1])
        .fold(f64::NEG_INFINITY, f64::max);
    heights.push(rim_top);
    for &y in &heights {
        for j in 0..32 {
            let a = j as f64 * 0.7;
            let dir = DVec3::new(a.cos(), 0.0, a.sin());
            let off = DVec3::new(-dir.z, 0.0, dir.x) * (j as f64 / 32.0 - 0.5);
            let ray = f32_ray(off + DVec3::Y * y - dir * 2.0, dir);
            if let Some(h) = hit(&ray, &mut st) {
                check_frame(&rev, &curve, &ray, &h, "horizontal");
            }
        }
    }

    // Grazing the rim: horizontal and barely tilted rays at the rim's top, and vertical rays
    // at the goblet's widest radius.
    let r_max = (0..20_000)
        .map(|i| curve.at(i as f64 / 20_000.0)[0])
        .fold(0.0, f64::max);
    for tilt in [0.0, 1e-7, -1e-7, 1e-5, -1e-5, 1e-3, -1e-3] {
        for j in 0..64 {
            let a = j as f64 * 0.37;
            let dir = DVec3::new(a.cos(), tilt, a.sin());
            let off = DVec3::new(-dir.z, 0.0, dir.x) * (j as f64 / 64.0 - 0.5);
            let ray = f32_ray(off + DVec3::Y * rim_top - dir * 2.0, dir);
            let h = hit(&ray, &mut st);
            if let Some(h) = h {
                check_frame(&rev, &curve, &ray, &h, "rim graze");
            }
            // Slopes at the flat-path threshold cut the rim's curl twice in quick succession:
            // the first cut, not the second.
            check_against_reference(&curve, &ray, h, &reference_roots(&curve, &ray));
            let x = DVec3::new(a.cos(), 0.0, a.sin()) * r_max;
            for eps in [0.0, 1e-6, -1e-6] {
                let ray = f32_ray(x * (1.0 + eps) + DVec3::Y * 2.0, DVec3::NEG_Y);
                if let Some(h) = hit(&ray, &mut st) {
                    check_frame(&rev, &curve, &ray, &h, "vertical graze");
                }
            }
        }
    }

    // Span joints: along the normal onto each joint (and the two ends); the hit is the joint.
    for k in 0..=m {
        let s = k as f64 / m as f64;
        for j in 0..8 {
            let phi = j as f64 * 0.8;
            let q = curve.point(s, phi);
            let (n, ..) = curve.frame(s, phi);
            // Approach from the side the normal points to, a little off the exact normal.
            let dir = -(n + DVec3::new(0.01, 0.02, -0.01)).normalize();
            let ray = f32_ray(q - dir * 0.5, dir);
            let h = hit(&ray, &mut st).unwrap_or_else(|| panic!("joint {k} missed"));
            check_frame(&rev, &curve, &ray, &h, "joint");
            let p = ray.at(h.t).as_dvec3();
            assert!((p - q).length() < 1e-5, "joint {k}: hit {p}, joint {q}");
        }
    }
    assert_eq!(st.non_converged, 0, "{st:?}");

    // Degenerate rays: zero or non-finite direction miss cleanly.
    for d in [Vec3::ZERO, Vec3::new(f32::NAN, 1.0, 0.0)] {
        let ray = Ray::new(Vec3::new(0.0, -1.0, 0.0), d);
        assert!(hit(&ray, &mut st).is_none());
        assert!(!rev.occluded(&ray, 10.0, &mut st));
    }
}

#[test]
fn open_sheet_normal_is_the_left_side() {
    // Profile going up at radius ~0.5: its left side (radius right, height up) faces the axis.
    let rev = Revolution::new(&[(0.5, 0.0), (0.5, 0.3), (0.5, 0.6), (0.5, 1.0)], 1e-6).unwrap();
    assert!(!rev.is_closed());
    let mut st = RevolutionStats::default();
    let ray = Ray::new(Vec3::new(2.0, 0.5, 0.0), Vec3::NEG_X);
    let h = rev.intersect(&ray, f32::INFINITY, &mut st).unwrap();
    assert!((h.t - 1.5).abs() < 1e-6);
    let (sp, _, dpdu, dpdv) = rev.surface(&ray, &h);
    assert!((sp.n - Vec3::NEG_X).length() < 1e-6, "{sp:?}");
    assert!(!sp.front);
    assert!(dpdu.cross(dpdv).normalize().dot(sp.n) > 0.999);
    // From inside the cylinder the ray meets the side the normal points to.
    let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::X);
    let h = rev.intersect(&ray, f32::INFINITY, &mut st).unwrap();
    assert!(rev.surface(&ray, &h).0.front);
}

/// Spawned rays: reflected ones leave on the facing side, transmitted ones go through. On a
/// convex solid the reflected ray never returns and the transmitted one runs the full chord to
/// the exit the exhaustive scan finds; on the goblet the topology alone decides which side the
/// next hit must be met from. Profiles are scaled from 10⁻² to 10² to exercise the offset.
#[test]
fn spawned_rays_do_not_reintersect() {
    let mut rng = Rng(3);
    let mut stats = RevolutionStats::default();
    for scale in [0.01f32, 1.0, 100.0] {
        let egg: Vec<(f32, f32)> = EGG.iter().map(|&(r, h)| (r * scale, h * scale)).collect();
        let rev = Revolution::new(&egg, DEFAULT_TOLERANCE).unwrap();
        let curve = Curve::new(&egg);
        let size = 2.1 * scale as f64;
        let (mut reflected, mut transmitted) = (0, 0);
        for i in 0..3000 {
            let o = DVec3::new(0.0, 0.05, 0.0) * scale as f64 + rng.sphere() * size * 2.0;
            let target = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ) * 1.1
                * scale as f64;
            let ray = f32_ray(o, target - o);
            let Some(h) = rev.intersect(&ray, f32::INFINITY, &mut stats) else {
                continue;
            };
            let (sp, ..) = rev.surface(&ray, &h);
            assert!(
                sp.front,
                "scale {scale} ray {i}: outside ray met the inner side"
            );
            let n = sp.facing();
            let d = ray.d.normalize();
            let r = Ray::new(offset_ray_origin(sp.p, n), d - 2.0 * d.dot(n) * n);
            let back = rev.intersect(&r, f32::INFINITY, &mut stats);
            assert!(
                back.is_none(),
                "scale {scale} ray {i}: reflected ray re-hit at {back:?}"
            );
            reflected += 1;

            // Through the surface: inside a convex solid the only crossing left is the exit,
            // met from inside, on the surface and a chord away. Only rays meeting the surface
            // at least 0.1 off tangent, whose chords are long; every eighth is also checked
            // against the exhaustive scan's last root.
            if n.dot(d).abs() < 0.1 {
                continue;
            }
            let t_ray = Ray::new(offset_ray_origin(sp.p, -n), d);
            let exit = rev
                .intersect(&t_ray, f32::INFINITY, &mut stats)
                .unwrap_or_else(|| panic!("scale {scale} ray {i}: transmitted ray escaped"));
            let (ep, ..) = rev.surface(&t_ray, &exit);
            let off = distance_at(&curve, &t_ray, exit.t as f64);
            assert!(
                exit.t as f64 > 1e-3 * size && !ep.front && off < 1e-5 * size,
                "scale {scale} ray {i}: transmitted ray hit at {exit:?} (size {size}, {off} \
                 off the surface)"
            );
            if transmitted % 8 == 0 {
                let chord = *reference_roots(&curve, &t_ray).last().unwrap();
                assert!(
                    (exit.t as f64 - chord).abs() < 1e-4 * size,
                    "scale {scale} ray {i}: exit at {} but the chord is {chord}",
                    exit.t
                );
            }
            transmitted += 1;
        }
        assert!(
            reflected > 1000 && transmitted > 500,
            "{reflected} {transmitted}"
        );
    }

    // The goblet: after entering (front) the next hit is an exit; a reflected ray that comes
    // back must meet the outer side again, and not at its own starting point.
    let rev = Revolution::new(&GOBLET, DEFAULT_TOLERANCE).unwrap();
    let mut checked = 0;
    for i in 0..20_000 {
        let o = DVec3::new(0.0, 0.7, 0.0) + rng.sphere() * 3.0;
        let target = DVec3::new(
            rng.range(-0.5, 0.5),
            rng.range(0.0, 1.4),
            rng.range(-0.5, 0.5),
        );
        let ray = f32_ray(o, target - o);
        let Some(h) = rev.intersect(&ray, f32::INFINITY, &mut stats) else {
            continue;
        };
        let (sp, ..) = rev.surface(&ray, &h);
        assert!(sp.front, "goblet ray {i}: outside ray met the inner side");
        let n = sp.n;
        let d = ray.d.normalize();
        let r = Ray::new(offset_ray_origin(sp.p, n), d - 2.0 * d.dot(n) * n);
        if let Some(b) = rev.intersect(&r, f32::INFINITY, &mut stats) {
            let (bp, ..) = rev.surface(&r, &b);
            assert!(
                bp.front && b.t > 1e-4,
                "goblet ray {i}: reflected ray re-hit {b:?}"
            );
        }
        let t_ray = Ray::new(offset_ray_origin(sp.p, -n), d);
        let e = rev
            .intersect(&t_ray, f32::INFINITY, &mut stats)
            .unwrap_or_else(|| panic!("goblet ray {i}: transmitted ray never left the glass"));
        assert!(
            !rev.surface(&t_ray, &e).0.front && e.t > 1e-4,
            "goblet ray {i}: transmitted ray re-hit {e:?}"
        );
        checked += 1;
    }
    assert!(checked > 5000);
    println!("{stats:?}");
}

#[test]
fn occluded_matches_intersect() {
    let rev = Revolution::new(&GOBLET, DEFAULT_TOLERANCE).unwrap();
    let curve = Curve::new(&GOBLET);
    let mut rng = Rng(13);
    let b = rev.bounds();
    let rays = ray_mix(&curve, b.min.as_dvec3(), b.max.as_dvec3(), 20_000, &mut rng);
    let mut st = RevolutionStats::default();
    for ray in &rays {
        let t_max = rng.range(0.1, 6.0) as f32;
        let h = rev.intersect(ray, t_max, &mut st);
        if let Some(h) = h {
            assert!(h.t > 0.0 && h.t < t_max);
        }
        assert_eq!(
            rev.occluded(ray, t_max, &mut st),
            h.is_some(),
            "{ray:?} {t_max}"
        );
    }
    assert_eq!(st.rays, 40_000);
}

#[test]
fn tolerance_trades_iterations_for_accuracy() {
    let curve = Curve::new(&GOBLET);
    let mut rng = Rng(17);
    let rays: Vec<Ray> = (0..2000)
        .map(|_| {
            let o = DVec3::new(0.0, 0.7, 0.0) + rng.sphere() * 3.0;
            let target = DVec3::new(rng.range(-0.4, 0.4), rng.range(0.0, 1.4), 0.0);
            f32_ray(o, target - o)
        })
        .collect();
    let mut per_hit = Vec::new();
    for tol in [1e-3f32, 1e-5, 1e-7] {
        let rev = Revolution::new(&GOBLET, tol).unwrap();
        let mut st = RevolutionStats::default();
        let mut worst: f64 = 0.0;
        for ray in &rays {
            if let Some(h) = rev.intersect(ray, f32::INFINITY, &mut st) {
                let p = ray.at(h.t).as_dvec3();
                worst = worst.max(curve.distance_2d(p.x.hypot(p.z), p.y));
            }
        }
        let it = st.newton_iterations as f64 / st.brackets as f64;
        println!(
            "tolerance {tol:e}: {it:.2} iterations per bracket, worst distance {worst:.2e}, \
             {st:?}"
        );
        assert_eq!(st.non_converged, 0);
        // The step in s bounds the error in s; the goblet's |dP/ds| stays below 10.
        assert!(worst < 10.0 * tol as f64 + 1e-6, "tolerance {tol}: {worst}");
        per_hit.push((it, worst));
    }
    assert!(
        per_hit[0].0 <= per_hit[2].0 && per_hit[2].1 < 1e-5,
        "{per_hit:?}"
    );
}

#[test]
fn rejects_bad_profiles() {
    let err = |p: &[(f32, f32)]| Revolution::new(p, DEFAULT_TOLERANCE).err().unwrap();
    let e = err(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]);
    assert!(
        e.contains("at least 4 control points") && e.contains("got 3"),
        "{e}"
    );
    assert!(err(&[]).contains("at least 4"));
    let e = err(&[(0.0, 0.0), (1.0, 0.0), (-0.5, 1.0), (0.0, 1.0)]);
    assert!(
        e.contains("point 2") && e.contains("negative radius -0.5"),
        "{e}"
    );
    let e = err(&[(0.0, 0.0), (f32::NAN, 0.0), (1.0, 1.0), (0.0, 1.0)]);
    assert!(e.contains("point 1") && e.contains("not finite"), "{e}");
    let e = err(&[(0.0, 0.0), (1.0, f32::INFINITY), (1.0, 1.0), (0.0, 1.0)]);
    assert!(e.contains("not finite"), "{e}");
    let e = err(&[(0.0, 0.0), (0.0, 1.0), (0.0, 2.0), (0.0, 3.0)]);
    assert!(e.contains("every radius is 0"), "{e}");
    for tol in [0.0, -1.0, f32::NAN] {
        let e = Revolution::new(&GOBLET, tol).err().unwrap();
        assert!(e.contains("tolerance"), "{e}");
    }
    // -0.0 is a radius of zero, not a negative one.
    assert!(Revolution::new(&[(-0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)], 1e-6).is_ok());
}
