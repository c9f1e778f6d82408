//! Where rays pass close to triangle edges: the places where `f32` and `f64` may legitimately
//! disagree, masked out of image comparisons.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use raytty::Triangle;

/// Two faces sharing an edge count as one flat quad (so the edge is not a silhouette) when
/// their unit normals agree to this: far tighter than any crease, far looser than `f64`
/// rounding of a normal computed from `f32` vertices (~1e-16).
const COPLANAR_COS: f64 = 1.0 - 1e-9;

/// Distance from `p` to the segment `a`–`b`.
pub fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let s = if l2 > 0.0 {
        ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * s - p).length()
}

/// Distance between the segments `p0`–`p1` and `q0`–`q1`: minimise |p(s) − q(t)|² over the unit
/// square, first unconstrained, then clamping one parameter and re-solving for the other.
pub fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (u, v, w) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, b, c) = (u.dot(u), u.dot(v), v.dot(v));
    let (dd, e) = (u.dot(w), v.dot(w));
    if a == 0.0 || c == 0.0 {
        return point_segment_distance(p0, q0, q1).min(point_segment_distance(q0, p0, p1));
    }
    let denom = a * c - b * b;
    // Parallel segments (relative to their lengths): any s works; start from s = 0.
    let mut s = if denom > 1e-12 * a * c {
        ((b * e - c * dd) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + e) / c;
    if t < 0.0 {
        t = 0.0;
        s = (-dd / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - dd) / a).clamp(0.0, 1.0);
    }
    (p0 + u * s - (q0 + v * t)).length()
}

/// The silhouette and boundary edges of a triangle set: every edge except those shared by two
/// coplanar faces (the diagonal of a flat quad, which no ray can tell apart from the face).
/// Vertices are matched by their exact `f32` bits.
pub fn feature_edges(triangles: &[Triangle]) -> Vec<(DVec3, DVec3)> {
    type Key = ([u32; 3], [u32; 3]);
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut faces: HashMap<Key, (DVec3, DVec3, Vec<DVec3>)> = HashMap::new();
    for t in triangles {
        let n = t.normal.as_dvec3().normalize();
        for i in 0..3 {
            let (a, b) = (t.v[i], t.v[(i + 1) % 3]);
            let key = if bits(a) < bits(b) {
                (bits(a), bits(b))
            } else {
                (bits(b), bits(a))
            };
            faces
                .entry(key)
                .or_insert_with(|| (a.as_dvec3(), b.as_dvec3(), Vec::new()))
                .2
                .push(n);
        }
    }
    let mut edges: Vec<(DVec3, DVec3)> = faces
        .into_values()
        .filter(|(_, _, n)| !(n.len() == 2 && n[0].dot(n[1]).abs() > COPLANAR_COS))
        .map(|(a, b, _)| (a, b))
        .collect();
    // HashMap order is random; sort so that every run sees the same list.
    edges.sort_by(|x, y| {
        let k = |e: &(DVec3, DVec3)| [e.0.x, e.0.y, e.0.z, e.1.x, e.1.y, e.1.z];
        k(x).partial_cmp(&k(y)).unwrap()
    });
    edges
}

/// Whether the segment `a`–`b` passes within `tol` of any edge in `edges`.
pub fn near_any(edges: &[(DVec3, DVec3)], a: DVec3, b: DVec3, tol: f64) -> bool {
    edges
        .iter()
        .any(|&(p, q)| segment_distance(a, b, p, q) < tol)
}
