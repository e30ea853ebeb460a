//! Perfect splits for the mesh's kd-tree: a triangle straddling a split plane is clipped to
//! each child's cell (Sutherland–Hodgman, in f64) and enters it with the clipped bounds.

use crate::geometry::Aabb;
use crate::kdtree::KdPrimitives;
use glam::{DVec3, Vec3};

/// Relative bounds padding: covers the rounding of the f64 clip converted back to f32, so
/// the tree never culls a point the exact triangle has.
const PAD_REL: f32 = 8.0 * f32::EPSILON;

/// Most vertices a clipped triangle can have: 3, plus one per clipping plane for a convex
/// polygon. Rounding can in principle make more; the clip then falls back to box bounds.
const CLIP_CAP: usize = 12;

/// The triangles as the kd-tree builder sees them: padded boxes, clipped for perfect splits.
pub(super) struct TriBoxes<'a>(pub(super) &'a [[Vec3; 3]]);

impl KdPrimitives for TriBoxes<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(&self.0[i as usize]).padded(PAD_REL, 0.0)
    }

    fn clipped_bounds(&self, i: u32, node: &Aabb) -> Aabb {
        clip_triangle(&self.0[i as usize], node)
    }

    fn split_bounds(&self, i: u32, node: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
        split_triangle(&self.0[i as usize], node, axis, pos)
    }
}

/// The clipped bounds of a triangle in both children of `node` split at `pos`: one clip to
/// the node, then the polygon cut by the plane (half the work of two clips to the children).
/// Each side is as `clip_triangle` on that child: inclusive, against the child grown by the
/// pad, padded.
fn split_triangle(tri: &[Vec3; 3], node: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let child = |above: bool| {
        let mut c = *node;
        if above {
            c.min[axis] = pos;
        } else {
            c.max[axis] = pos;
        }
        c
    };
    let full = Aabb::from_points(tri);
    let pad = full.min.abs().max(full.max.abs()).max_element() * PAD_REL;
    let cell = Aabb {
        min: node.min - pad,
        max: node.max + pad,
    };
    let (lo, hi) = (f64::from(pos + pad), f64::from(pos - pad));
    let (below, above) = if full.min.cmpge(cell.min).all() && full.max.cmple(cell.max).all() {
        // Most straddlers lie inside the node but for the plane: the triangle is the polygon.
        split_polygon_bounds(&tri.map(Vec3::as_dvec3), axis, lo, hi)
    } else {
        let mut poly = [DVec3::ZERO; CLIP_CAP];
        let Some(n) = clip_to_cell(tri, &full, &cell, &mut poly) else {
            return (
                clip_triangle(tri, &child(false)),
                clip_triangle(tri, &child(true)),
            );
        };
        split_polygon_bounds(&poly[..n], axis, lo, hi)
    };
    let grow = |b: Aabb| {
        if b.is_empty() {
            Aabb::EMPTY
        } else {
            Aabb {
                min: b.min - pad,
                max: b.max + pad,
            }
        }
    };
    (grow(below), grow(above))
}

/// The bounds of the parts of a polygon with `x[axis] <= below` and with `x[axis] >= above`:
/// the boxes of what two Sutherland–Hodgman steps ([`clip_polygon`]) would keep, the same
/// points computed the same way, in one pass and without building either polygon.
fn split_polygon_bounds(poly: &[DVec3], axis: usize, below: f64, above: f64) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Aabb::EMPTY, Aabb::EMPTY);
    let cross = |cur: DVec3, next: DVec3, bound: f64| {
        let s = (bound - cur[axis]) / (next[axis] - cur[axis]);
        let mut x = cur + (next - cur) * s;
        x[axis] = bound;
        x.as_vec3()
    };
    for k in 0..poly.len() {
        let cur = poly[k];
        let next = poly[(k + 1) % poly.len()];
        let (c, n) = (cur[axis], next[axis]);
        if c <= below {
            lo = lo.union_point(cur.as_vec3());
        }
        if (c <= below) != (n <= below) {
            lo = lo.union_point(cross(cur, next, below));
        }
        if c >= above {
            hi = hi.union_point(cur.as_vec3());
        }
        if (c >= above) != (n >= above) {
            hi = hi.union_point(cross(cur, next, above));
        }
    }
    (lo, hi)
}

/// Clips a triangle (with box `full`) to `cell` in f64 into `poly`: the vertex count, or
/// `None` when rounding made the polygon too complex.
fn clip_to_cell(
    tri: &[Vec3; 3],
    full: &Aabb,
    cell: &Aabb,
    poly: &mut [DVec3; CLIP_CAP],
) -> Option<usize> {
    let mut scratch = [DVec3::ZERO; CLIP_CAP];
    for (k, p) in tri.iter().enumerate() {
        poly[k] = p.as_dvec3();
    }
    let mut n = 3;
    for axis in 0..3 {
        for (bound, keep_above) in [(cell.min[axis], true), (cell.max[axis], false)] {
            // Planes the triangle lies wholly inside of need no clip (nor its rounding).
            let inside = if keep_above {
                full.min[axis] >= bound
            } else {
                full.max[axis] <= bound
            };
            if inside {
                continue;
            }
            n = clip_polygon(&poly[..n], &mut scratch, axis, f64::from(bound), keep_above)?;
            std::mem::swap(poly, &mut scratch);
            if n == 0 {
                return Some(0);
            }
        }
    }
    Some(n)
}

/// Bounds of the part of a triangle inside `node`, padded. The clip is inclusive and runs
/// against the node grown by the pad, so a triangle touching or grazing a cell face stays in
/// that cell: the traversal may then reach it from either side.
fn clip_triangle(tri: &[Vec3; 3], node: &Aabb) -> Aabb {
    let full = Aabb::from_points(tri);
    let pad = full.min.abs().max(full.max.abs()).max_element() * PAD_REL;
    let cell = Aabb {
        min: node.min - pad,
        max: node.max + pad,
    };
    let grow = |b: Aabb| Aabb {
        min: b.min - pad,
        max: b.max + pad,
    };
    if full.min.cmpge(cell.min).all() && full.max.cmple(cell.max).all() {
        return grow(full);
    }

    let mut poly = [DVec3::ZERO; CLIP_CAP];
    match clip_to_cell(tri, &full, &cell, &mut poly) {
        Some(n) => {
            let mut b = Aabb::EMPTY;
            for p in &poly[..n] {
                b = b.union_point(p.as_vec3());
            }
            // Nothing left inside: an empty box, not a padded point.
            if n == 0 { b } else { grow(b) }
        }
        // Rounding made the polygon too complex: the plain box is still conservative.
        None => grow(full.intersection(&cell)),
    }
}

/// One Sutherland–Hodgman step: the part of the polygon on the kept side of the plane
/// `x[axis] = bound` (points on the plane kept). Intersections are placed exactly on the
/// plane. `None` if the result would not fit.
fn clip_polygon(
    poly: &[DVec3],
    out: &mut [DVec3; CLIP_CAP],
    axis: usize,
    bound: f64,
    keep_above: bool,
) -> Option<usize> {
    let inside = |p: &DVec3| {
        if keep_above {
            p[axis] >= bound
        } else {
            p[axis] <= bound
        }
    };
    let mut m = 0;
    let mut push = |p: DVec3| {
        if m == CLIP_CAP {
            return false;
        }
        out[m] = p;
        m += 1;
        true
    };
    for k in 0..poly.len() {
        let cur = poly[k];
        let next = poly[(k + 1) % poly.len()];
        let (cin, nin) = (inside(&cur), inside(&next));
        if cin && !push(cur) {
            return None;
        }
        if cin != nin {
            let s = (bound - cur[axis]) / (next[axis] - cur[axis]);
            let mut x = cur + (next - cur) * s;
            x[axis] = bound;
            if !push(x) {
                return None;
            }
        }
    }
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_triangle_to_a_box() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ];
        // The corner cell [1,2]² holds the part of the triangle with x + y ≤ 4: all of it.
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(1.0, 1.0, -1.0), Vec3::splat(2.0)),
        );
        assert!(
            (b.min.x - 1.0).abs() < 1e-5 && (b.max.x - 2.0).abs() < 1e-5,
            "{b:?}"
        );
        // Beyond the hypotenuse: only the part with x + y ≤ 4 in [2,3]², i.e. up to (2,2).
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(2.0, 2.0, -1.0), Vec3::splat(3.0)),
        );
        assert!(b.max.x < 2.0 + 1e-5 && b.max.y < 2.0 + 1e-5, "{b:?}");
        // Entirely beyond it.
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::new(2.5, 2.5, -1.0), Vec3::splat(3.0)),
        );
        assert!(b.is_empty());
        // Clipping the far side off keeps the part under x = 1: the box [0,1]×[0,4].
        let b = clip_triangle(
            &tri,
            &Aabb::new(Vec3::splat(-1.0), Vec3::new(1.0, 5.0, 1.0)),
        );
        assert!(
            (b.max.x - 1.0).abs() < 1e-5 && (b.max.y - 4.0).abs() < 1e-5,
            "{b:?}"
        );
    }

    #[test]
    fn a_triangle_touching_a_cell_face_stays_in_the_cell() {
        let tri = [Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)];
        let b = clip_triangle(&tri, &Aabb::new(Vec3::new(0.0, -1.0, -1.0), Vec3::ONE));
        assert!(!b.is_empty());
        assert!(b.max.x >= 1.0 && b.max.x < 1.0 + 1e-5, "{b:?}");
    }
}
