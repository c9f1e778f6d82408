//! The watertight ray/triangle test and its bound on `t`'s rounding error.

use glam::Vec3;

use super::float::gamma;
use super::ray::{Ray, RayFrame};

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
/// ([`t_error_bound`]).
///
/// The SIMD kernels (`accel/tri4/x86.rs`) repeat this test and [`t_error_bound`] operation for
/// operation, in this order: a change here must be made there too (`tests/simd_kernels.rs`
/// holds them to each other bit for bit).
#[inline]
pub fn intersect_watertight(ray: &Ray, v: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    let frame = ray.frame(v);
    let e = frame.edge_functions();
    if (e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0) && (e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0) {
        return None;
    }
    let det = e[0] + e[1] + e[2];
    if det == 0.0 || det.is_nan() {
        return None;
    }
    let z = frame.z.map(|z| ray.sz * z);
    let t_scaled = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    if !(t < t_max) {
        return None;
    }
    // A `None` bound: the determinant's sign is not certain (the ray lies nearly in the plane).
    let delta_t = t_error_bound(ray, &frame, e, t)?;
    if !(t > delta_t) {
        return None;
    }
    Some(TriHit {
        t,
        b: [e[0] * inv_det, e[1] * inv_det, e[2] * inv_det],
    })
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
#[inline]
pub fn t_error_bound(ray: &Ray, frame: &RayFrame, e: [f32; 3], t: f32) -> Option<f32> {
    let z = frame.z.map(|z| ray.sz * z);
    let max_zt = z[0].abs().max(z[1].abs()).max(z[2].abs());
    let det = e[0] + e[1] + e[2];
    let edge = EdgeErrors::new(frame.x, frame.y, frame.z.map(f32::abs), (ray.sx, ray.sy));
    let weights_error = edge.weights(e, det, z.map(|z| (z - t).abs() + gamma(3) * max_zt))?;
    Some(2.0 * (2.0 * gamma(3) * max_zt + gamma(3) * t + weights_error))
}

/// Bounds on the rounding error of the watertight test's three edge functions, each from its
/// own operands (steps 1 and 2 of [`t_error_bound`]'s derivation).
struct EdgeErrors {
    e: [f32; 3],
}

impl EdgeErrors {
    /// From the sheared vertex coordinates `x`, `y`, the unscaled `|z|` and the shear.
    #[inline]
    fn new(x: [f32; 3], y: [f32; 3], z: [f32; 3], (sx, sy): (f32, f32)) -> EdgeErrors {
        // Written out per index rather than `[0, 1, 2].map(..)`: the same arithmetic, but the
        // compiler unrolls it (through `map` it kept a loop with `% 3` divisions).
        let dx = |i: usize| gamma(5) * (x[i].abs() + 2.0 * (sx * z[i]).abs());
        let dy = |i: usize| gamma(5) * (y[i].abs() + 2.0 * (sy * z[i]).abs());
        let (dx, dy) = ([dx(0), dx(1), dx(2)], [dy(0), dy(1), dy(2)]);
        let edge = |j: usize, k: usize| {
            x[j].abs() * dy[k]
                + y[k].abs() * dx[j]
                + y[j].abs() * dx[k]
                + x[k].abs() * dy[j]
                + gamma(2) * ((x[j] * y[k]).abs() + (y[j] * x[k]).abs())
        };
        EdgeErrors {
            e: [edge(1, 2), edge(2, 0), edge(0, 1)],
        }
    }

    /// How far errors in the weights `eᵢ/det` can move a weighted mean whose terms lie within
    /// `spread[i]` of it: Σ (δeᵢ + |wᵢ|·Σδe)·spreadᵢ / (|det| − Σδe) (step 3). `None` when the
    /// determinant is not certain to be non-zero.
    #[inline]
    fn weights(&self, e: [f32; 3], det: f32, spread: [f32; 3]) -> Option<f32> {
        let total = self.e[0] + self.e[1] + self.e[2];
        let margin = det.abs() - total;
        if !(margin > 0.0) {
            return None;
        }
        let inv = 1.0 / det.abs();
        let sum: f32 = (0..3)
            .map(|i| (self.e[i] + (e[i] * inv).abs() * total) * spread[i])
            .sum();
        Some(sum / margin)
    }
}
