//! Rays, triangles and the watertight ray/triangle test.
//!
//! The intersection follows Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection"
//! (JCGT 2013), with a conservative error bound on `t` in the spirit of pbrt-v4's but tighter
//! ([`t_error_bound`]): a ray that passes exactly through a shared edge or vertex hits at least
//! one of the triangles that share it, and a hit is never reported at a distance that rounding
//! error cannot tell from zero. New rays leave a
//! surface from an origin pushed out of the hit point's own rounding-error box
//! ([`offset_ray_origin`]), so no tuned epsilon depends on the scene's scale.

use glam::Vec3;

/// Machine epsilon for `f32` rounding: half an ULP of 1.0.
const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Bound on the relative error of `n` chained `f32` operations (Higham's γₙ, as in pbrt).
#[inline]
pub fn gamma(n: i32) -> f32 {
    let n = n as f32 * MACHINE_EPSILON;
    n / (1.0 - n)
}

/// The smallest `f32` strictly greater than `v` (identity for +∞ and NaN).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest `f32` strictly less than `v` (identity for −∞ and NaN).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// A ray `origin + t·dir`, with the per-ray constants of the watertight test precomputed.
///
/// `dir` need not be normalised: `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Its direction (any non-zero length).
    pub dir: Vec3,
    /// Component-wise `1/dir` for slab tests (±∞ where a component is zero).
    pub inv_dir: Vec3,
    /// The axis along which `dir` is largest in magnitude, and the two others.
    kx: usize,
    ky: usize,
    kz: usize,
    /// Shear that maps `dir` onto +z.
    sx: f32,
    sy: f32,
    sz: f32,
}

impl Ray {
    /// A ray from `origin` along `dir`. `dir` must be finite and non-zero.
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        debug_assert!(origin.is_finite() && dir.is_finite(), "ray {origin} {dir}");
        debug_assert!(dir != Vec3::ZERO, "zero ray direction");
        let a = dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / dir[kz];
        Ray {
            origin,
            dir,
            inv_dir: dir.recip(),
            kx,
            ky,
            kz,
            sx: -dir[kx] * sz,
            sy: -dir[ky] * sz,
            sz,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A triangle with its geometric normal and material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices in the scene's winding order.
    pub v: [Vec3; 3],
    /// `normalize(cross(v2 − v0, v1 − v0))`, the seed's convention. Never NaN: a scene only holds
    /// triangles whose normal is finite and unit length (see [`Triangle::new`]).
    pub normal: Vec3,
    /// Index into the scene's material table.
    pub material: u32,
}

/// Why a triangle cannot be part of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DegenerateTriangle {
    /// A vertex coordinate is NaN or infinite.
    NonFinite,
    /// Zero area (repeated or collinear vertices): it has no normal and can never be hit.
    ZeroArea,
}

impl std::fmt::Display for DegenerateTriangle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DegenerateTriangle::NonFinite => f.write_str("a vertex coordinate is NaN or infinite"),
            DegenerateTriangle::ZeroArea => {
                f.write_str("the triangle has zero area (repeated or collinear vertices)")
            }
        }
    }
}

impl std::error::Error for DegenerateTriangle {}

impl Triangle {
    /// Builds a triangle, rejecting the degenerate ones: non-finite vertices, or an area so small
    /// that the normal cannot be computed (the cross product computed in `f64` to avoid
    /// underflow at tiny scales).
    pub fn new(
        v0: Vec3,
        v1: Vec3,
        v2: Vec3,
        material: u32,
    ) -> Result<Triangle, DegenerateTriangle> {
        if !(v0.is_finite() && v1.is_finite() && v2.is_finite()) {
            return Err(DegenerateTriangle::NonFinite);
        }
        let c = (v2.as_dvec3() - v0.as_dvec3()).cross(v1.as_dvec3() - v0.as_dvec3());
        let len = c.length();
        if !(len > 0.0) || !len.is_finite() {
            return Err(DegenerateTriangle::ZeroArea);
        }
        let normal = (c / len).as_vec3();
        if !normal.is_finite() || normal == Vec3::ZERO {
            return Err(DegenerateTriangle::ZeroArea);
        }
        Ok(Triangle {
            v: [v0, v1, v2],
            normal: normal.normalize(),
            material,
        })
    }

    /// Intersects `ray` with this triangle (both sides), returning a hit with `0 < t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriHit> {
        intersect_watertight(ray, &self.v, t_max)
    }
}

/// A ray/triangle hit: distance and barycentric weights of the three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    /// Ray parameter of the hit, always `> 0` and finite.
    pub t: f32,
    /// Barycentric weights of `v0`, `v1`, `v2`; each in `[0, 1]`, summing to 1 up to rounding.
    pub b: [f32; 3],
}

/// A triangle seen from a ray, as the watertight test sees it: the vertices translated to the
/// ray's origin, their axes permuted so that the ray's largest component is the third
/// ([`Ray::axes`]), and sheared so that the ray runs along that axis. The ray passes through
/// the triangle where the origin of the (x, y) plane lies inside the sheared triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayFrame {
    /// Sheared x of each vertex: `(v − o)[kx] + sx·(v − o)[kz]`.
    pub x: [f32; 3],
    /// Sheared y of each vertex: `(v − o)[ky] + sy·(v − o)[kz]`.
    pub y: [f32; 3],
    /// Each vertex's offset along the ray's main axis, `(v − o)[kz]`, not yet scaled by `sz`
    /// into units of `t`.
    pub z: [f32; 3],
}

impl Ray {
    /// The axes `[kx, ky, kz]` of the watertight test: `kz` is the axis along which `dir` is
    /// largest in magnitude (the first one on ties), `kx` and `ky` follow it cyclically, swapped
    /// when `dir[kz] < 0` so that the triangle's winding is kept.
    pub fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    /// The shear constants `[sx, sy, sz]`: `sx = −dir[kx]/dir[kz]`, `sy = −dir[ky]/dir[kz]`,
    /// `sz = 1/dir[kz]`, each as rounded in `f32`.
    pub fn shear(&self) -> [f32; 3] {
        [self.sx, self.sy, self.sz]
    }

    /// The triangle `v` in this ray's frame.
    #[inline]
    pub fn frame(&self, v: &[Vec3; 3]) -> RayFrame {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = v[0] - self.origin;
        let b = v[1] - self.origin;
        let c = v[2] - self.origin;
        let (az, bz, cz) = (a[kz], b[kz], c[kz]);
        RayFrame {
            x: [
                a[kx] + self.sx * az,
                b[kx] + self.sx * bz,
                c[kx] + self.sx * cz,
            ],
            y: [
                a[ky] + self.sy * az,
                b[ky] + self.sy * bz,
                c[ky] + self.sy * cz,
            ],
            z: [az, bz, cz],
        }
    }
}

impl RayFrame {
    /// The three edge functions; `e[i]` is the (unnormalised) weight of vertex `i`, the signed
    /// doubled area of the sheared triangle formed by the other two vertices and the ray. When
    /// one rounds to exactly zero in `f32`, all three are recomputed in `f64`, where the products
    /// of `f32` values are exact, so that a ray exactly on an edge gets its sign right.
    #[inline]
    pub fn edge_functions(&self) -> [f32; 3] {
        let (x, y) = (self.x, self.y);
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        if e[0] != 0.0 && e[1] != 0.0 && e[2] != 0.0 {
            return e;
        }
        let (x, y) = (x.map(f64::from), y.map(f64::from));
        [
            (x[1] * y[2] - y[1] * x[2]) as f32,
            (x[2] * y[0] - y[2] * x[0]) as f32,
            (x[0] * y[1] - y[0] * x[1]) as f32,
        ]
    }
}

/// The watertight ray/triangle test. Two-sided. Returns `None` for a miss, for a hit at or
/// beyond `t_max`, and for a hit whose `t` is within its own rounding error of zero
/// ([`t_error_bound`]).
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
        let dx = [0, 1, 2].map(|i| gamma(5) * (x[i].abs() + 2.0 * (sx * z[i]).abs()));
        let dy = [0, 1, 2].map(|i| gamma(5) * (y[i].abs() + 2.0 * (sy * z[i]).abs()));
        let e = [0, 1, 2].map(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            x[j].abs() * dy[k]
                + y[k].abs() * dx[j]
                + y[j].abs() * dx[k]
                + x[k].abs() * dy[j]
                + gamma(2) * ((x[j] * y[k]).abs() + (y[j] * x[k]).abs())
        });
        EdgeErrors { e }
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

/// The hit point from barycentrics, and a conservative bound on its absolute error per axis.
///
/// The point is clamped into the triangle's bounding box: the exact point lies in it, so the
/// clamp only moves the computed one closer on each axis and the bound still holds. Without
/// it, a hit exactly on a crease (a ray along the line where a wall meets the floor) can round
/// to one ulp behind the neighbouring wall, and a shadow ray from there, offset along its own
/// normal only, is blocked by that wall.
#[inline]
pub fn hit_point(v: &[Vec3; 3], b: [f32; 3]) -> (Vec3, Vec3) {
    let p0 = v[0] * b[0];
    let p1 = v[1] * b[1];
    let p2 = v[2] * b[2];
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let p = (p0 + p1 + p2).max(lo).min(hi);
    let err = (p0.abs() + p1.abs() + p2.abs()) * gamma(7);
    (p, err)
}

/// Moves `p` (with per-axis error bound `err`) off its surface with normal `n`, to the side that
/// `w` points to, far enough that a ray from the result cannot re-hit that surface (pbrt-v4's
/// `OffsetRayOrigin`). The offset is rounded away from `p` so it survives the addition.
#[inline]
pub fn offset_ray_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(err);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_float_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_float_down(po[i]);
        }
    }
    po
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +∞, max = −∞), the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The box around a triangle.
    pub fn of_triangle(t: &Triangle) -> Aabb {
        Aabb {
            min: t.v[0].min(t.v[1]).min(t.v[2]),
            max: t.v[0].max(t.v[1]).max(t.v[2]),
        }
    }

    /// The smallest box holding both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The box's centre.
    pub fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Robust slab test (pbrt-v4): does the ray meet the box for some `t` in `[0, t_max)`?
    /// The far distance is widened by 2γ₃ so rounding never culls a box the ray grazes.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f32) -> bool {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for i in 0..3 {
            let inv = ray.inv_dir[i];
            let mut near = (self.min[i] - ray.origin[i]) * inv;
            let mut far = (self.max[i] - ray.origin[i]) * inv;
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= 1.0 + 2.0 * gamma(3);
            // NaN (origin on a slab plane of a parallel ray) leaves the interval unchanged.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
            if t0 > t1 {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        assert!(next_float_up(1.0) > 1.0);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert_eq!(next_float_down(next_float_up(2.5)), 2.5);
    }

    #[test]
    fn hits_inside_and_misses_outside() {
        let v = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let hit = intersect_watertight(&ray, &v, f32::INFINITY).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-6);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(5.0, 0.0, 1.0));
        assert!(intersect_watertight(&ray, &v, f32::INFINITY).is_none());
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        assert!(intersect_watertight(&ray, &v, f32::INFINITY).is_none());
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!(intersect_watertight(&ray, &v, 0.5).is_none());
    }

    #[test]
    fn t_error_bound_is_small_head_on_and_none_in_the_plane() {
        let v = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        // A direction far from unit length, as a shadow ray's `light − p` can be: the bound
        // stays a few ulps of t (pbrt-v4's grows with t², see `t_error_bound`).
        let ray = Ray::new(Vec3::ZERO, Vec3::Z * 1e-3);
        let frame = ray.frame(&v);
        let e = frame.edge_functions();
        let hit = intersect_watertight(&ray, &v, f32::INFINITY).expect("head-on hit");
        let bound = t_error_bound(&ray, &frame, e, hit.t).expect("a bound exists");
        assert!((hit.t - 1000.0).abs() <= bound, "{hit:?} {bound}");
        assert!(
            bound > 0.0 && bound < hit.t * 1e-5,
            "{bound} for t = {}",
            hit.t
        );
        // In the triangle's plane the determinant is zero: no bound, no hit.
        let ray = Ray::new(Vec3::new(-2.0, 0.0, 1.0), Vec3::X);
        let frame = ray.frame(&v);
        assert_eq!(
            t_error_bound(&ray, &frame, frame.edge_functions(), 2.0),
            None
        );
        assert_eq!(intersect_watertight(&ray, &v, f32::INFINITY), None);
    }

    #[test]
    fn degenerate_triangles_are_rejected() {
        let a = Vec3::ZERO;
        let b = Vec3::X;
        assert_eq!(Triangle::new(a, a, b, 0), Err(DegenerateTriangle::ZeroArea));
        assert_eq!(
            Triangle::new(a, b, 2.0 * b, 0),
            Err(DegenerateTriangle::ZeroArea)
        );
        assert_eq!(
            Triangle::new(a, b, Vec3::NAN, 0),
            Err(DegenerateTriangle::NonFinite)
        );
        assert!(Triangle::new(a, b, Vec3::Y, 0).is_ok());
    }
}
