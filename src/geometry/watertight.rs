//! The watertight ray/triangle test and its bound on `t`'s rounding error, written once for
//! any number of lanes ([`watertight_lanes`]): [`intersect_watertight`] is its one-lane form,
//! the SIMD kernels (`accel::tri4`) its four-, eight- and sixteen-lane forms, so every path
//! computes the same bits by construction.

use glam::Vec3;

use super::float::gamma;
use super::ray::{Ray, RayFrame};
use crate::simd::Lanes;

/// A ray/triangle hit: distance and barycentric weights of the three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    /// Ray parameter of the hit, always `> 0` and finite.
    pub t: f32,
    /// Barycentric weights of `v0`, `v1`, `v2`; each in `[0, 1]`, summing to 1 up to rounding.
    pub b: [f32; 3],
}

/// The watertight ray/triangle test. Two-sided. Returns `None` for a miss, for a hit at or
/// beyond `t_max`, and for a hit whose `t` is within its own rounding error of zero
/// ([`t_error_bound`]). The one-lane form of [`watertight_lanes`], with its edge functions
/// redone in `f64` where one rounds to zero ([`RayFrame::edge_functions`]).
#[inline]
pub fn intersect_watertight(ray: &Ray, v: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    let [kx, ky, kz] = ray.axes();
    let rel = v.map(|v| {
        let d = v - ray.origin;
        [d[kx], d[ky], d[kz]]
    });
    // `watertight_lanes`, but for its edge functions: redone in `f64` where one rounds to 0.
    let s = Sheared::new(rel, ray.shear());
    let f = s.accept(RayFrame::from(&s).edge_functions(), false, t_max, false);
    (f.mask != 0).then_some(TriHit { t: f.t, b: f.b })
}

/// What [`watertight_lanes`] finds, lane by lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Found<L: Lanes> {
    /// Bit `i` set: lane `i` is hit, at `t` with barycentrics `b` (meaningless elsewhere).
    pub mask: u32,
    /// Bit `i` set: an edge function of lane `i` rounded to 0, so the scalar test redoes it in
    /// `f64` ([`intersect_watertight`]); nothing else is said about the lane.
    pub redo: u32,
    /// The hit lanes as a mask.
    pub accepted: L::Mask,
    /// Each hit lane's `t`.
    pub t: L,
    /// Each hit lane's barycentric weights of `v0`, `v1`, `v2`.
    pub b: [L; 3],
}

/// The watertight test lane by lane: each lane's triangle relative to its ray's origin, in the
/// ray's axis order (`rel[vertex] = [a, b, z]`), its ray's shear `[sx, sy, sz]` and `t_max`.
///
/// With `sure` true, the caller has proven that every lane which passes the sign and range
/// tests also passes [`t_error_bound`]'s two (the determinant's sign is certain, `t` is beyond
/// its error bound): they are not computed (debug builds compute them and assert it).
#[inline(always)]
pub(crate) fn watertight_lanes<L: Lanes>(
    rel: [[L; 3]; 3],
    shear: [L; 3],
    t_max: L,
    sure: bool,
) -> Found<L> {
    let s = Sheared::new(rel, shear);
    let e = [s.p[0].sub(s.p[1]), s.p[2].sub(s.p[3]), s.p[4].sub(s.p[5])];
    let zero = L::splat(0.0);
    let any_zero = L::or(L::or(e[0].eq(zero), e[1].eq(zero)), e[2].eq(zero));
    s.accept(e, any_zero, t_max, sure)
}

/// A triangle sheared into a ray's frame, lane by lane: the vertices' `x`, `y` (the ray runs
/// along `z`), the unscaled depths `z`, the edge functions' products `p` and the shear.
struct Sheared<L> {
    x: [L; 3],
    y: [L; 3],
    z: [L; 3],
    /// `x₁y₂, y₁x₂, x₂y₀, y₂x₀, x₀y₁, y₀x₁`: edge function `i` is `p[2i] − p[2i + 1]`.
    p: [L; 6],
    shear: [L; 3],
}

impl<L: Lanes> Sheared<L> {
    #[inline(always)]
    fn new(rel: [[L; 3]; 3], shear: [L; 3]) -> Sheared<L> {
        let [sx, sy, _] = shear;
        let [[a0, b0, z0], [a1, b1, z1], [a2, b2, z2]] = rel;
        let x = [a0.add(sx.mul(z0)), a1.add(sx.mul(z1)), a2.add(sx.mul(z2))];
        let y = [b0.add(sy.mul(z0)), b1.add(sy.mul(z1)), b2.add(sy.mul(z2))];
        Sheared::of(x, y, [z0, z1, z2], shear)
    }

    /// From the sheared coordinates.
    #[inline(always)]
    fn of(x: [L; 3], y: [L; 3], z: [L; 3], shear: [L; 3]) -> Sheared<L> {
        Sheared {
            x,
            y,
            z,
            p: [
                x[1].mul(y[2]),
                y[1].mul(x[2]),
                x[2].mul(y[0]),
                y[2].mul(x[0]),
                x[0].mul(y[1]),
                y[0].mul(x[1]),
            ],
            shear,
        }
    }

    /// The test from the edge functions `e` on: the sign test, the determinant, the range of
    /// `t·det`, `t` and (unless `sure`) its error bound. Lanes in `redo` are not accepted.
    #[inline(always)]
    fn accept(&self, e: [L; 3], redo: L::Mask, t_max: L, sure: bool) -> Found<L> {
        let zero = L::splat(0.0);
        let any_neg = L::or(L::or(e[0].lt(zero), e[1].lt(zero)), e[2].lt(zero));
        let any_pos = L::or(L::or(e[0].gt(zero), e[1].gt(zero)), e[2].gt(zero));
        // Edge functions of both signs: the ray passes beside the triangle, as it does for
        // most lanes a traversal tests; when every lane does (or is to be redone), the rest
        // of the test is skipped.
        let beside = L::and(any_neg, any_pos);
        let redo_bits = L::bits(redo);
        let full = (1u32 << L::N).wrapping_sub(1);
        let none = Found {
            mask: 0,
            redo: redo_bits,
            accepted: L::none(),
            t: zero,
            b: [zero; 3],
        };
        if !L::bits(beside) & !redo_bits & full == 0 {
            return none;
        }
        let det = e[0].add(e[1]).add(e[2]);
        let sz = self.shear[2];
        let zs = [sz.mul(self.z[0]), sz.mul(self.z[1]), sz.mul(self.z[2])];
        let t_scaled = e[0].mul(zs[0]).add(e[1].mul(zs[1])).add(e[2].mul(zs[2]));
        let bound = t_max.mul(det);
        // Rejected in the scalar order: mixed signs, a zero or NaN det, `t·det` outside
        // (0, t_max·det] on det's side.
        let reject = L::or(
            L::or(beside, L::or(det.eq(zero), det.unord(det))),
            L::or(
                L::and(det.lt(zero), L::or(t_scaled.ge(zero), t_scaled.lt(bound))),
                L::and(det.gt(zero), L::or(t_scaled.le(zero), t_scaled.gt(bound))),
            ),
        );
        if !L::bits(reject) & !redo_bits & full == 0 {
            return none;
        }
        let inv_det = L::splat(1.0).div(det);
        let t = t_scaled.mul(inv_det);
        let fast = L::andnot(L::or(reject, redo), t.lt(t_max));
        let accepted = if sure && !cfg!(debug_assertions) {
            fast
        } else {
            let (certain, delta_t) = self.error_bound(e, det, zs, t);
            let full = L::and(fast, L::and(certain, t.gt(delta_t)));
            debug_assert!(
                !sure || L::bits(full) == L::bits(fast),
                "a sure triangle failed the bound"
            );
            full
        };
        Found {
            mask: L::bits(accepted),
            redo: redo_bits,
            accepted,
            t,
            b: [e[0].mul(inv_det), e[1].mul(inv_det), e[2].mul(inv_det)],
        }
    }

    /// Edge function `i`'s error (`(j, k)` its other two vertices), from the coordinates'
    /// errors `dx`, `dy` (step 2 of [`t_error_bound`]'s derivation).
    #[inline(always)]
    fn edge_error(&self, i: usize, (j, k): (usize, usize), dx: [L; 3], dy: [L; 3], g2: L) -> L {
        let (x, y) = (&self.x, &self.y);
        x[j].abs()
            .mul(dy[k])
            .add(y[k].abs().mul(dx[j]))
            .add(y[j].abs().mul(dx[k]))
            .add(x[k].abs().mul(dy[j]))
            .add(g2.mul(self.p[2 * i].abs().add(self.p[2 * i + 1].abs())))
    }

    /// [`t_error_bound`] lane by lane: whether the determinant's sign is certain, and the
    /// bound on `t`'s error (meaningful where it is). `zs` are the depths scaled by `sz`.
    #[inline(always)]
    fn error_bound(&self, e: [L; 3], det: L, zs: [L; 3], t: L) -> (L::Mask, L) {
        let (x, y, z) = (&self.x, &self.y, &self.z);
        let [sx, sy, _] = self.shear;
        let (g2, g3, g5) = (L::splat(gamma(2)), L::splat(gamma(3)), L::splat(gamma(5)));
        let two = L::splat(2.0);
        let max_zt = zs[0].abs().max(zs[1].abs()).max(zs[2].abs());
        // Step 1: each sheared coordinate's error.
        let coord = |c: L, s: L, z: L| coord_error(c, s, z, g5);
        let dx = [
            coord(x[0], sx, z[0]),
            coord(x[1], sx, z[1]),
            coord(x[2], sx, z[2]),
        ];
        let dy = [
            coord(y[0], sy, z[0]),
            coord(y[1], sy, z[1]),
            coord(y[2], sy, z[2]),
        ];
        // Step 2: each edge function's, for (j, k) = (1, 2), (2, 0), (0, 1).
        let ee = [
            self.edge_error(0, (1, 2), dx, dy, g2),
            self.edge_error(1, (2, 0), dx, dy, g2),
            self.edge_error(2, (0, 1), dx, dy, g2),
        ];
        // Step 3: the weights' error, over the depths' spread about `t`.
        let total = ee[0].add(ee[1]).add(ee[2]);
        let margin = det.abs().sub(total);
        let certain = margin.gt(L::splat(0.0));
        let inv = L::splat(1.0).div(det.abs());
        let g3z = g3.mul(max_zt);
        let w = [
            weight_error(ee[0], e[0].mul(inv), total, zs[0].sub(t).abs().add(g3z)),
            weight_error(ee[1], e[1].mul(inv), total, zs[1].sub(t).abs().add(g3z)),
            weight_error(ee[2], e[2].mul(inv), total, zs[2].sub(t).abs().add(g3z)),
        ];
        let weights_error = w[0].add(w[1]).add(w[2]).div(margin);
        // Step 4, and the doubling.
        let delta_t = two.mul(
            L::splat(2.0 * gamma(3))
                .mul(max_zt)
                .add(g3.mul(t))
                .add(weights_error),
        );
        (certain, delta_t)
    }
}

/// A sheared coordinate's error, `γ₅·(|c| + 2|s·|z||)` (step 1 of [`t_error_bound`]'s
/// derivation). The kernels' helpers are functions, not closures, so that they are sure to
/// inline: code left out of line would lose the path's target features.
#[inline(always)]
fn coord_error<L: Lanes>(c: L, s: L, z: L, g5: L) -> L {
    g5.mul(c.abs().add(L::splat(2.0).mul(s.mul(z.abs()).abs())))
}

/// A weight's error times its depth's spread about `t`: `(δeᵢ + |wᵢ|·Σδe)·spreadᵢ` (step 3),
/// `w` the weight `eᵢ/|det|`.
#[inline(always)]
fn weight_error<L: Lanes>(ee: L, w: L, total: L, spread: L) -> L {
    ee.add(w.abs().mul(total)).mul(spread)
}

impl From<&Sheared<f32>> for RayFrame {
    fn from(s: &Sheared<f32>) -> RayFrame {
        RayFrame {
            x: s.x,
            y: s.y,
            z: s.z,
        }
    }
}

/// A conservative bound on the rounding error of the `t` that [`intersect_watertight`] computes
/// for `ray` and a triangle whose [`RayFrame`] is `frame`, edge functions `e` and computed
/// distance `t`, measured against the exact intersection of the same `f32` ray and triangle.
/// `None` when the edge functions' errors could flip the sign of their sum, the determinant:
/// the ray lies within rounding of the triangle's plane and no bound on `t` exists.
///
/// # Derivation
///
/// With γₙ = nε/(1 − nε) bounding the relative error of n roundings (ε = 2⁻²⁴):
///
/// 1. Each sheared coordinate `x = (v − o)ₓ + sx·(v − o)_z` carries one rounding from `v − o`,
///    two from `sx = −dₓ·(1/d_z)`, one from the product and one from the sum, on terms of at
///    most `|x| + |sx·z|` (z unscaled): δx ≤ γ₅·(|x| + 2|sx·z|), the factor 2 because `|x|` is
///    the computed sum, not the larger of its terms. The same for y.
/// 2. Edge function `eᵢ = xⱼ·yₖ − yⱼ·xₖ` inherits its inputs' errors, each times the other
///    factor, and adds two roundings of its own: δeᵢ ≤ |xⱼ|δyₖ + |yₖ|δxⱼ + |yⱼ|δxₖ + |xₖ|δyⱼ
///    + γ₂·(|xⱼyₖ| + |yⱼxₖ|).
/// 3. `t = Σ wᵢ·zᵢ` with weights `wᵢ = eᵢ/det` that sum to 1 (zᵢ now scaled into units of t).
///    Perturbed weights still sum to 1, so `Σ δwᵢ = 0` and a weight error moves t by
///    `Σ δwᵢ·(zᵢ − t)`: only the spread of the depths about t matters, not their size. Each
///    weight is off by at most `(δeᵢ + |wᵢ|·Σδe)/(|det| − Σδe)`, which needs `|det| > Σδe`.
///    The spread is widened by the depths' own error, γ₃·max|z|.
/// 4. Rounding after the weights: the scaled depths (γ₃·max|z|, one rounding in `v − o`, two in
///    `sz·z`), their weighted sum (γ₃·max|z| again: Σ|eᵢ||zᵢ|/|det| ≤ max|z| for a hit, where the
///    weights are all of one sign) and the division by det (γ₃·t, with the reciprocal).
///
/// The sum of 3 and 4, doubled for the second-order terms the first-order analysis leaves out
/// (products of two errors, the rounding of the bound itself), is the bound.
///
/// # Where this departs from pbrt-v4
///
/// pbrt-v4 (section 6.8.4 of the book, `IntersectTriangle`) bounds all three edge functions by
/// one error built from the largest |x|, |y| and the largest *scaled* |z|, and multiplies it by
/// the largest |z|. Two consequences reject real hits, as `tests/stability_properties.rs` found:
/// - the sheared x and y carry error in proportion to the *unscaled* z (|sx|, |sy| ≤ 1); using
///   the scaled z, which is z/d_z, overstates it by 1/|d_z| or more: a ray whose direction is
///   much shorter than 1 (a shadow ray towards a close light, `dir = light − p`) gets a bound
///   larger than its t;
/// - multiplying the weights' error by the largest depth instead of the depths' spread about t
///   overstates it by t/(depth extent): a small, distant triangle seen nearly edge-on has a
///   small det and a large t, and pbrt's bound exceeds t.
///
/// Here each edge gets its own error from its own operands, in the units the arithmetic really
/// uses, and the weight error is multiplied by the spread. All of it is `f32` and only runs for
/// rays that pass the edge tests, so the kernel's cost is unchanged for misses.
pub fn t_error_bound(ray: &Ray, frame: &RayFrame, e: [f32; 3], t: f32) -> Option<f32> {
    let s = Sheared::of(frame.x, frame.y, frame.z, ray.shear());
    let det = e[0] + e[1] + e[2];
    let sz = ray.shear()[2];
    let (certain, delta_t) = s.error_bound(e, det, frame.z.map(|z| sz * z), t);
    certain.then_some(delta_t)
}
