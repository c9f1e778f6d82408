//! Where a ray hit, in lanes: the hit point and its error bound, the normals on the side the
//! ray came from (the triangle's, and the shading normal), and the origin of a ray leaving it. Written once over [`Lanes`]: one ray at
//! a time is width 1.

use super::lane::{Lanes, each3};
use crate::geometry::gamma;

/// Hit points, one per lane, each coordinate `[x, y, z]` as lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Surface<F> {
    /// The hit point ([`crate::geometry::hit_point`]).
    pub p: [F; 3],
    /// Its error bound per axis.
    pub err: [F; 3],
    /// The triangle's unit normal on the side the ray came from (two-sided shading): where
    /// rays leave from ([`offset_origin`]) and which side a direction is on.
    pub normal: [F; 3],
    /// The unit shading normal on the same side: the interpolated vertex normal where the
    /// scene has vertex normals ([`with_shading`]), else `normal`. Cosines and BSDF frames.
    pub shading: [F; 3],
}

/// `a·b`, summed x, y, z in that order (glam's `dot`).
#[inline(always)]
pub(crate) fn dot<S: Lanes>(s: S, a: [S::F; 3], b: [S::F; 3]) -> S::F {
    s.add(
        s.add(s.mul(a[0], b[0]), s.mul(a[1], b[1])),
        s.mul(a[2], b[2]),
    )
}

/// The hit points at barycentrics `b` of triangles with vertices `v` (`v[vertex][axis]`) and
/// normal `normal`, of rays with directions `dir`: [`crate::geometry::hit_point`]'s operations
/// lane by lane (the point clamped to the triangle's box, its error `γ₇·Σ|vᵢbᵢ|`).
#[inline(always)]
pub(crate) fn surface<S: Lanes>(
    s: S,
    v: [[S::F; 3]; 3],
    normal: [S::F; 3],
    b: [S::F; 3],
    dir: [S::F; 3],
) -> Surface<S::F> {
    let g7 = s.splat(gamma(7));
    let mut p = [s.splat(0.0); 3];
    let mut err = p;
    for k in 0..3 {
        let (v0, v1, v2) = (v[0][k], v[1][k], v[2][k]);
        let (p0, p1, p2) = (s.mul(v0, b[0]), s.mul(v1, b[1]), s.mul(v2, b[2]));
        let lo = s.min(s.min(v0, v1), v2);
        let hi = s.max(s.max(v0, v1), v2);
        p[k] = s.min(s.max(s.add(s.add(p0, p1), p2), lo), hi);
        let e = s.add(s.add(s.abs(p0), s.abs(p1)), s.abs(p2));
        err[k] = s.mul(e, g7);
    }
    // Two-sided shading: the normal on the side the ray came from.
    let away = s.gt(dot(s, normal, dir), s.splat(0.0));
    let normal = each3!(|k| s.neg_where(away, normal[k]));
    Surface {
        p,
        err,
        normal,
        shading: normal,
    }
}

/// `at` with shading normal `n` (unit), turned to the side of `at`'s normal: a vertex normal
/// that points away from the face the ray sees (the back of a two-sided surface, or a normal
/// against the winding) is flipped with it.
#[inline(always)]
pub(crate) fn with_shading<S: Lanes>(s: S, at: &mut Surface<S::F>, n: [S::F; 3]) {
    let back = s.lt(dot(s, n, at.normal), s.splat(0.0));
    at.shading = each3!(|k| s.neg_where(back, n[k]));
}

/// The origins of rays leaving `at` toward `w`: [`crate::geometry::offset_ray_origin`]'s
/// operations lane by lane (the point moved off its surface by its error bound, to `w`'s
/// side, then one float further away).
#[inline(always)]
pub(crate) fn offset_origin<S: Lanes>(s: S, at: &Surface<S::F>, w: [S::F; 3]) -> [S::F; 3] {
    let n = at.normal;
    let d = dot(s, each3!(|k| s.abs(n[k])), at.err);
    let behind = s.lt(dot(s, w, n), s.splat(0.0));
    each3!(|k| {
        let offset = s.neg_where(behind, s.mul(n[k], d));
        s.step_along(s.add(at.p[k], offset), offset)
    })
}
