//! Shading data and topology from the vertices: positions welded, vertex normals filled in,
//! closedness, degenerate triangles and the UV derivatives of a triangle.

use glam::{DVec3, Vec2, Vec3};

/// ∂p/∂u and ∂p/∂v of the plane through the triangle (pbrt's formulation), or a frame
/// around `ng` when the UVs do not span the triangle (repeated or collinear UVs).
pub(super) fn uv_derivatives(p: [Vec3; 3], uv: [Vec2; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() > 1e-12 {
        let inv = 1.0 / det;
        let dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
        let dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
        let c = dpdu.cross(dpdv);
        if c.is_finite() && c.length_squared() > 0.0 {
            return (dpdu, dpdv);
        }
    }
    let (t, b) = crate::sampling::coordinate_system(ng);
    // Keep dpdu × dpdv along ng, as a valid UV mapping of this winding would.
    if t.cross(b).dot(ng) < 0.0 {
        (b, t)
    } else {
        (t, b)
    }
}

/// `(v1 − v0) × (v2 − v0)` in f64: exact enough to tell zero area from tiny area.
#[inline]
pub(super) fn tri_normal_f64(t: &[Vec3; 3]) -> DVec3 {
    let p0 = t[0].as_dvec3();
    (t[1].as_dvec3() - p0).cross(t[2].as_dvec3() - p0)
}

/// Zero area: a repeated index, coincident positions or collinear vertices.
pub(super) fn is_degenerate(positions: &[Vec3], tri: [u32; 3]) -> bool {
    if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
        return true;
    }
    let t = tri.map(|i| positions[i as usize]);
    let n = tri_normal_f64(&t);
    // Products of f32 differences are exact in f64 unless the exponents are far apart, so a
    // zero here is a true zero (or an area no f32 ray test could resolve anyway).
    n == DVec3::ZERO || !n.is_finite()
}

/// One id per distinct position (bit-equal, with −0 = +0), so that vertices split only for
/// their attributes share normals and edges. Returns the id of each vertex and the count.
pub(super) fn weld_positions(positions: &[Vec3]) -> (Vec<u32>, usize) {
    let key = |p: Vec3| -> (u32, u32, u32) {
        let b = |x: f32| (x + 0.0).to_bits();
        (b(p.x), b(p.y), b(p.z))
    };
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(positions[i as usize]));
    let mut weld = vec![0u32; positions.len()];
    let mut next = 0u32;
    for (k, &i) in order.iter().enumerate() {
        if k > 0 && key(positions[order[k - 1] as usize]) != key(positions[i as usize]) {
            next += 1;
        }
        weld[i as usize] = next;
    }
    let count = if positions.is_empty() {
        0
    } else {
        next as usize + 1
    };
    (weld, count)
}

/// Unit vertex normals: the input's where usable, elsewhere the angle-weighted mean of the
/// face normals around the vertex's position. Returns them with the number repaired.
pub(super) fn vertex_normals(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    weld: &[u32],
    input: Option<Vec<Vec3>>,
) -> (Vec<Vec3>, usize) {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    let given = input.is_some();
    let mut missing = 0usize;
    match input {
        Some(input) => {
            for (n, g) in normals.iter_mut().zip(input) {
                match g.try_normalize() {
                    Some(u) => *n = u,
                    None => missing += 1,
                }
            }
        }
        None => missing = positions.len(),
    }
    if missing == 0 {
        return (normals, 0);
    }

    let groups = weld.iter().max().map_or(0, |&m| m as usize + 1);
    let mut sum = vec![DVec3::ZERO; groups];
    for tri in indices {
        let p = tri.map(|i| positions[i as usize].as_dvec3());
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let n = n / n.length();
        for k in 0..3 {
            let e1 = p[(k + 1) % 3] - p[k];
            let e2 = p[(k + 2) % 3] - p[k];
            // atan2 of |cross| and dot stays accurate for angles near 0 and π, unlike acos.
            let angle = e1.cross(e2).length().atan2(e1.dot(e2));
            sum[weld[tri[k] as usize] as usize] += angle * n;
        }
    }
    for (i, n) in normals.iter_mut().enumerate() {
        if *n == Vec3::ZERO {
            // A vertex no kept triangle uses, or where the faces cancel, stays zero: shading
            // then falls back to the geometric normal.
            *n = sum[weld[i] as usize]
                .try_normalize()
                .map_or(Vec3::ZERO, |d| d.as_vec3().normalize_or_zero());
        }
    }
    (normals, if given { missing } else { 0 })
}

/// Closed and consistently oriented: every directed edge occurs once and its reverse occurs
/// too, so each edge has exactly two triangles traversing it in opposite directions.
pub(super) fn is_closed_surface(indices: &[[u32; 3]], weld: &[u32]) -> bool {
    let mut edges: Vec<u64> = Vec::with_capacity(indices.len() * 3);
    for tri in indices {
        for k in 0..3 {
            let a = weld[tri[k] as usize] as u64;
            let b = weld[tri[(k + 1) % 3] as usize] as u64;
            edges.push(a << 32 | b);
        }
    }
    edges.sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    // Rotating by 32 swaps the halves: the reverse edge.
    edges
        .iter()
        .all(|&e| edges.binary_search(&e.rotate_right(32)).is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_and_closedness() {
        // A tetrahedron with one vertex duplicated (as a UV seam would do).
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::Z, // copy of 3
        ];
        let (weld, n) = weld_positions(&p);
        assert_eq!(n, 4);
        assert_eq!(weld[3], weld[4]);
        let closed = [[0, 2, 1], [0, 1, 3], [1, 2, 4], [2, 0, 3]];
        assert!(is_closed_surface(&closed, &weld));
        // One face flipped: edges no longer pair up in opposite directions.
        let flipped = [[0, 1, 2], [0, 1, 3], [1, 2, 4], [2, 0, 3]];
        assert!(!is_closed_surface(&flipped, &weld));
        assert!(!is_closed_surface(&closed[..3], &weld));
    }
}
