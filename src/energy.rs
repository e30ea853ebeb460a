//! Energy tables of rough surfaces, in f64: the directional albedo of a GGX lobe by
//! quadrature (from which `examples/ggx_tables.rs` generates the committed tables of the
//! conductor's energy compensation), and the coat tables of a plastic, built per coat IOR
//! when a scene is gathered.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The grid size of every energy table: μ and α each on `TABLE_SIZE` points of [0, 1].
pub const TABLE_SIZE: usize = 32;

/// E(μ, α), the directional albedo of a GGX lobe with F = 1 at incidence cosine μ, in f64:
/// ∫ D(h)·G2(wo, wi)·|wo·h| / μ dωh over the normals reflecting wo above the surface
/// (f = D·G2/(4 μo μi), dωi = 4|wo·h| dωh), by the midpoint rule in (cos θh = 1 − t², φ),
/// a grid dense where narrow lobes are. The generator of the committed tables.
pub fn ggx_albedo(mu: f64, alpha: f64) -> f64 {
    ggx_albedo_with(mu, alpha, |_| 1.0, (1024, 256))
}

/// The directional albedo of a GGX lobe whose microfacets reflect `fresnel(wo·h)`, by the
/// quadrature of [`ggx_albedo`] on an `nt` × `np` grid in (t, φ), cos θh = 1 − t².
pub fn ggx_albedo_with(
    mu: f64,
    alpha: f64,
    fresnel: impl Fn(f64) -> f64,
    (nt, np): (usize, usize),
) -> f64 {
    use std::f64::consts::PI;
    if alpha <= 0.0 {
        return fresnel(mu);
    }
    let mu = mu.clamp(1e-4, 1.0);
    let wo = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let a2 = alpha * alpha;
    let s = |w: [f64; 3]| (a2 * (w[0] * w[0] + w[1] * w[1]) + w[2] * w[2]).sqrt();
    let s_wo = s(wo);
    // wo lies in the xz plane: the integrand is even in φ, so half the circle, twice.
    let phis: Vec<(f64, f64)> = (0..np)
        .map(|j| {
            let phi = (j as f64 + 0.5) / np as f64 * PI;
            (phi.cos(), phi.sin())
        })
        .collect();
    let dphi = 2.0 * PI / np as f64;
    let mut e = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64;
        let cos = 1.0 - t * t;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let dcos = 2.0 * t / nt as f64;
        for &(pc, ps) in &phis {
            let h = [sin * pc, sin * ps, cos];
            let oh = wo[0] * h[0] + wo[2] * h[2];
            if oh <= 0.0 {
                continue;
            }
            let wi = [
                2.0 * oh * h[0] - wo[0],
                2.0 * oh * h[1],
                2.0 * oh * h[2] - wo[2],
            ];
            if wi[2] <= 0.0 {
                continue;
            }
            let q = (h[0] * h[0] + h[1] * h[1]) / a2 + h[2] * h[2];
            let d = 1.0 / (PI * a2 * q * q);
            let g2 = 2.0 * wo[2] * wi[2] / (s_wo * wi[2] + s(wi) * wo[2]);
            e += fresnel(oh) * d * g2 * oh / mu * dcos * dphi;
        }
    }
    e
}

/// E_avg(α) = 2∫E(μ)μ dμ (midpoint rule, 64 nodes), in f64.
pub fn ggx_average_albedo(alpha: f64) -> f64 {
    let n = 64;
    (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            2.0 * ggx_albedo(mu, alpha) * mu / n as f64
        })
        .sum()
}

/// E(μ, α) on a `TABLE_SIZE`² grid (row per α), then E_avg(α), then the smooth coat's
/// E_avg and F_in.
pub const COAT_TABLE_LEN: usize = TABLE_SIZE * TABLE_SIZE + TABLE_SIZE + 2;
pub(crate) const AVG: usize = TABLE_SIZE * TABLE_SIZE;
pub(crate) const SMOOTH_AVG: usize = AVG + TABLE_SIZE;
pub(crate) const F_IN: usize = SMOOTH_AVG + 1;

/// Fresnel reflectance of a smooth dielectric interface in f64 (relative IOR `eta`).
fn fresnel_f64(cos_i: f64, eta: f64) -> f64 {
    let c = cos_i.clamp(0.0, 1.0);
    let cos2_t = (eta * eta - 1.0 + c * c) / (eta * eta);
    if cos2_t <= 0.0 {
        return 1.0;
    }
    let ct = cos2_t.sqrt();
    let rp = (eta * c - ct) / (eta * c + ct);
    let rs = (c - eta * ct) / (c + eta * ct);
    0.5 * (rp * rp + rs * rs)
}

/// 2∫F(μ)μ dμ for relative IOR `eta`, by the midpoint rule in x = μ² (F(√x) is smooth but
/// for the kink at a critical angle, which 4096 nodes resolve to 1e-6).
fn fresnel_average_f64(eta: f64) -> f64 {
    let n = 4096;
    (0..n)
        .map(|i| fresnel_f64(((i as f64 + 0.5) / n as f64).sqrt(), eta) / n as f64)
        .sum()
}

/// The coat tables of IOR `eta` (see [`COAT_TABLE_LEN`]).
pub fn coat_table(eta: f32) -> Vec<f32> {
    use rayon::prelude::*;
    let n = TABLE_SIZE;
    let last = (n - 1) as f64;
    let eta = f64::from(eta);
    // One work item per (α, μ) node: the rows' costs differ, the nodes' hardly.
    let nodes: Vec<f64> = (0..n * n)
        .into_par_iter()
        .map(|k| {
            let (alpha, mu) = ((k / n) as f64 / last, (k % n) as f64 / last);
            // A grid half as fine as the committed GGX tables': E enters the albedo
            // of a white plastic only as E_true − E_table (see the module's notes).
            ggx_albedo_with(mu, alpha, |c| fresnel_f64(c, eta), (512, 128)).min(1.0)
        })
        .collect();
    let rows: Vec<&[f64]> = nodes.chunks(n).collect();
    let mut t = Vec::with_capacity(COAT_TABLE_LEN);
    for row in &rows {
        t.extend(row.iter().map(|&e| e as f32));
    }
    // E_avg of the interpolated E: 2∫E(μ)μ dμ with E linear on each cell, integrated exactly
    // (and from the f32 values the lookups read).
    for row in &rows {
        let e: Vec<f64> = row.iter().map(|&e| f64::from(e as f32)).collect();
        let h = 1.0 / last;
        let avg: f64 = (0..n - 1)
            .map(|i| {
                let (m0, m1) = (i as f64 * h, (i + 1) as f64 * h);
                let (e0, e1) = (e[i], e[i + 1]);
                // ∫ (e0 + (e1 − e0)(μ − m0)/h) μ dμ over [m0, m1].
                let s = (e1 - e0) / h;
                let c = e0 - s * m0;
                c * (m1 * m1 - m0 * m0) / 2.0 + s * (m1.powi(3) - m0.powi(3)) / 3.0
            })
            .sum();
        t.push((2.0 * avg) as f32);
    }
    let f_avg = fresnel_average_f64(eta);
    t.push(f_avg as f32);
    // Light inside the coat, diffusely distributed, escapes with 1 − F_avg(1/η) =
    // (1 − F_avg(η))/η² (reciprocity of the interface).
    t.push((1.0 - (1.0 - f_avg) / (eta * eta)) as f32);
    t
}

/// The tables of `eta`, built once per process and shared.
pub fn coat_table_cached(eta: f32) -> Arc<[f32]> {
    static CACHE: OnceLock<Mutex<HashMap<u32, Arc<[f32]>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(t) = cache.lock().expect("coat cache").get(&eta.to_bits()) {
        return t.clone();
    }
    // Built outside the lock: two threads may build the same table, and both are equal.
    let t: Arc<[f32]> = coat_table(eta).into();
    cache
        .lock()
        .expect("coat cache")
        .entry(eta.to_bits())
        .or_insert(t)
        .clone()
}

/// The single-scattering albedo of a rough dielectric interface (GGX α, relative IOR `eta`
/// transmitted over incident) lit at incidence cosine `mu`: the reflected and the
/// transmitted shares of the flux, by the quadrature of [`ggx_albedo_with`]. Per microfacet
/// normal h visible from wo, the flux D(h)·(wo·h)/μ dωh leaves reflected with F(wo·h) and
/// refracted with 1 − F, each masked by G2; both terms share the normal's measure, since
/// f_t·|μi| dωi = (1 − F)·D·G2·(wo·h)/μ dωh (Walter et al. 2007).
pub fn dielectric_albedo(mu: f64, alpha: f64, eta: f64, (nt, np): (usize, usize)) -> (f64, f64) {
    use std::f64::consts::PI;
    if alpha <= 0.0 {
        let f = fresnel_f64(mu, eta);
        return (f, 1.0 - f);
    }
    let mu = mu.clamp(1e-4, 1.0);
    let wo = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let a2 = alpha * alpha;
    let s = |w: [f64; 3]| (a2 * (w[0] * w[0] + w[1] * w[1]) + w[2] * w[2]).sqrt();
    let g2 = |wi: [f64; 3]| {
        let zi = wi[2].abs();
        2.0 * wo[2] * zi / (s(wo) * zi + s(wi) * wo[2])
    };
    let (mut r, mut t) = (0.0, 0.0);
    for i in 0..nt {
        let tt = (i as f64 + 0.5) / nt as f64;
        let cos = 1.0 - tt * tt;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let dcos = 2.0 * tt / nt as f64;
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * PI;
            let h = [sin * phi.cos(), sin * phi.sin(), cos];
            let oh = wo[0] * h[0] + wo[2] * h[2];
            if oh <= 0.0 {
                continue;
            }
            let q = (h[0] * h[0] + h[1] * h[1]) / a2 + h[2] * h[2];
            let d = 1.0 / (PI * a2 * q * q);
            let measure = d * oh / mu * dcos * (2.0 * PI / np as f64);
            let f = fresnel_f64(oh, eta);
            let wr = [
                2.0 * oh * h[0] - wo[0],
                2.0 * oh * h[1],
                2.0 * oh * h[2] - wo[2],
            ];
            if wr[2] > 0.0 {
                r += f * g2(wr) * measure;
            }
            let cos2_t = 1.0 - (1.0 - oh * oh) / (eta * eta);
            if f < 1.0 && cos2_t > 0.0 {
                let k = oh / eta - cos2_t.sqrt();
                let wt = [-wo[0] / eta + k * h[0], k * h[1], -wo[2] / eta + k * h[2]];
                if wt[2] < 0.0 {
                    t += (1.0 - f) * g2(wt) * measure;
                }
            }
        }
    }
    (r, t)
}

/// The relative IORs of the rough dielectric's energy tables: η = 1 + k/10, k < 21, from
/// the side light enters (η ≥ 1) and, as 1/η, from the side it leaves.
pub const DIELECTRIC_ETAS: usize = 21;
/// Where the tables of [`dielectric_energy_table`] start: E(μ, α) per side and η on a
/// `TABLE_SIZE`² grid (row per α), then E_avg(α) per side and η, then the share of the
/// compensation lobe that is transmitted, per side and η.
pub const DIELECTRIC_AVG: usize = 2 * DIELECTRIC_ETAS * TABLE_SIZE * TABLE_SIZE;
/// See [`DIELECTRIC_AVG`].
pub const DIELECTRIC_SPLIT: usize = DIELECTRIC_AVG + 2 * DIELECTRIC_ETAS * TABLE_SIZE;
/// The length of [`dielectric_energy_table`].
pub const DIELECTRIC_TABLE_LEN: usize = DIELECTRIC_SPLIT + 2 * DIELECTRIC_ETAS * TABLE_SIZE;
/// The quadrature grid of the committed dielectric tables.
pub const DIELECTRIC_GRID: (usize, usize) = (512, 128);

/// The relative IOR of slice `k` seen from `side` (0: entering, 1: leaving).
pub fn dielectric_table_eta(side: usize, k: usize) -> f64 {
    let eta = 1.0 + k as f64 / 10.0;
    if side == 0 { eta } else { 1.0 / eta }
}

/// 2∫E(μ)μ dμ of `e` on the `TABLE_SIZE` grid of μ, linear on each cell, integrated
/// exactly: the average a lookup's interpolant has.
fn linear_average(e: &[f64]) -> f64 {
    let last = (e.len() - 1) as f64;
    let h = 1.0 / last;
    let s: f64 = (0..e.len() - 1)
        .map(|i| {
            let (m0, m1) = (i as f64 * h, (i + 1) as f64 * h);
            let s = (e[i + 1] - e[i]) / h;
            let c = e[i] - s * m0;
            c * (m1 * m1 - m0 * m0) / 2.0 + s * (m1.powi(3) - m0.powi(3)) / 3.0
        })
        .sum();
    2.0 * s
}

/// A value of [0, 1] as the committed tables store it, 16 bits fixed point.
pub fn quantize_unit(v: f64) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// The value a stored 16-bit entry stands for.
pub fn dequantize_unit(q: u16) -> f64 {
    f64::from(q) / 65535.0
}

/// The energy tables of the rough dielectric's multiple-scattering compensation, quantized
/// (layout at [`DIELECTRIC_AVG`]), by `grid` quadrature per entry.
///
/// Kulla & Conty 2017 restore the energy 1 − E(μo) single scattering loses with a lobe
/// (1 − E(μo))(1 − E'(μi)) / (π(1 − E'_avg)) on each side, E' the table of the side wi is
/// on, reflected with share 1 − x and transmitted with share x. Reciprocity across the
/// interface (f(o, i)/η_i² = f(i, o)/η_o²) ties the two sides' transmitted shares:
/// x₋ = x₊ (1 − E₊avg) / ((1 − E₋avg) η²), with x₊ the transmitted share of single
/// scattering from outside, lowered where x₋ would exceed 1.
pub fn dielectric_energy_table(grid: (usize, usize)) -> Vec<u16> {
    use rayon::prelude::*;
    let n = TABLE_SIZE;
    let last = (n - 1) as f64;
    let slices: Vec<(usize, usize)> = (0..2)
        .flat_map(|s| (0..DIELECTRIC_ETAS).map(move |k| (s, k)))
        .collect();
    // Per slice: E rows (quantized), E_avg per α (of the dequantized rows), T_avg per α.
    let built: Vec<(Vec<u16>, Vec<f64>, Vec<f64>)> = slices
        .par_iter()
        .map(|&(side, k)| {
            let eta = dielectric_table_eta(side, k);
            let mut e = Vec::with_capacity(n * n);
            let (mut avg, mut t_avg) = (Vec::new(), Vec::new());
            for j in 0..n {
                let alpha = j as f64 / last;
                let rows: Vec<(f64, f64)> = (0..n)
                    .map(|i| dielectric_albedo(i as f64 / last, alpha, eta, grid))
                    .collect();
                let q: Vec<u16> = rows.iter().map(|&(r, t)| quantize_unit(r + t)).collect();
                let deq: Vec<f64> = q.iter().map(|&v| dequantize_unit(v)).collect();
                let tr: Vec<f64> = rows.iter().map(|&(_, t)| t).collect();
                avg.push(linear_average(&deq));
                t_avg.push(linear_average(&tr));
                e.extend(q);
            }
            (e, avg, t_avg)
        })
        .collect();
    let mut out = Vec::with_capacity(DIELECTRIC_TABLE_LEN);
    for (e, _, _) in &built {
        out.extend_from_slice(e);
    }
    let avg_q: Vec<Vec<u16>> = built
        .iter()
        .map(|(_, a, _)| a.iter().map(|&v| quantize_unit(v)).collect())
        .collect();
    for a in &avg_q {
        out.extend_from_slice(a);
    }
    let mut split = vec![0u16; 2 * DIELECTRIC_ETAS * n];
    for k in 0..DIELECTRIC_ETAS {
        let eta = dielectric_table_eta(0, k);
        let (enter, leave) = (k, DIELECTRIC_ETAS + k);
        for j in 0..n {
            let ea = dequantize_unit(avg_q[enter][j]);
            let eb = dequantize_unit(avg_q[leave][j]);
            let (t_in, e_in) = (built[enter].2[j], built[enter].1[j]);
            let mut x_in = if e_in > 0.0 { t_in / e_in } else { 1.0 };
            let (la, lb) = (1.0 - ea, (1.0 - eb) * eta * eta);
            let mut x_out = if lb > 1e-9 { x_in * la / lb } else { 0.0 };
            if x_out > 1.0 {
                x_out = 1.0;
                x_in = if la > 1e-9 { lb / la } else { x_in };
            }
            split[enter * n + j] = quantize_unit(x_in);
            split[leave * n + j] = quantize_unit(x_out);
        }
    }
    out.extend(split);
    debug_assert_eq!(out.len(), DIELECTRIC_TABLE_LEN);
    out
}
