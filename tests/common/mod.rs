//! Helpers shared by the numerical-stability suite (`tests/stability_*.rs`) and the accel and
//! SIMD-kernel tests: seeded random cases and triangle soups, replayable case descriptions, the
//! exact decision of the watertight test with its f32 error bound, and an f64 reference tracer
//! of a scene with edge-distance masks.
//!
//! Every stability test draws its cases from [`Rng::seeded`] with a fixed seed per case, and
//! prints [`case`] on failure: the seed, the ray and the triangle with every `f32` in its
//! shortest round-trip form, so pasting them into a test replays the case bit for bit.
#![allow(dead_code)]

pub mod edges;
pub mod reference;

use glam::{DVec3, Vec3};
use raytty::Ray;
use raytty::geometry::t_error_bound;
pub use raytty::rng::Rng;

/// Half an ULP of 1.0 in `f32` (the unit roundoff of one `f32` operation).
pub const EPS: f64 = f32::EPSILON as f64 * 0.5;

/// Rays within this distance of a feature edge in the Cornell box (whose room is 2 wide) may
/// go either way between `f32` and `f64`: about 15 times the rounding error of a hit point or
/// an offset shadow-ray origin there (`γ₇·3 ≈ 1.3e-6`), and a 200th of a pixel's footprint on
/// the back wall at 500×500. The mask it gives is dominated by the two image diagonals, whose
/// pixel-centre rays run exactly along the room's creases (at 2e-6 it still holds 500 pixels;
/// at 0 the shadow test fails on two diagonal pixels).
pub const EDGE_TOL: f64 = 2e-5;

/// `Vec3` to `DVec3` (exact).
pub fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// The three vertices in `f64` (exact).
pub fn d3(v: &[Vec3; 3]) -> [DVec3; 3] {
    v.map(d)
}

/// A replayable description of one ray/triangle case.
pub fn case(seed: u64, origin: Vec3, dir: Vec3, tri: &[Vec3; 3]) -> String {
    format!(
        "seed {seed}: ray origin {:?} dir {:?}; triangle [{:?}, {:?}, {:?}]",
        origin.to_array(),
        dir.to_array(),
        tri[0].to_array(),
        tri[1].to_array(),
        tri[2].to_array()
    )
}

/// A uniform `f32` in `[lo, hi)`.
pub fn uniform(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.next_f32()
}

/// A point uniform in the cube `[-half, half]³`.
pub fn in_cube(rng: &mut Rng, half: f32) -> Vec3 {
    Vec3::new(
        uniform(rng, -half, half),
        uniform(rng, -half, half),
        uniform(rng, -half, half),
    )
}

/// A triangle soup: `n` non-degenerate triangles with vertices within `size` of a centre in
/// the cube of half-side `half`, all scaled by `scale`.
pub fn soup(seed: u64, n: usize, half: f32, size: f32, scale: f32) -> Vec<[Vec3; 3]> {
    let mut rng = Rng::seeded(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let c = in_cube(&mut rng, half);
        let v = [0; 3].map(|_| (c + in_cube(&mut rng, size)) * scale);
        if raytty::Triangle::new(v[0], v[1], v[2], 0).is_ok() {
            out.push(v);
        }
    }
    out
}

/// A uniformly distributed unit vector.
pub fn unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = in_cube(rng, 1.0);
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

/// `10^e` for `e` uniform in `[lo, hi)`: magnitudes spread evenly over decades.
pub fn log_uniform(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
    10f32.powf(uniform(rng, lo, hi))
}

/// Gives the `f32` computation slack for the second-order terms the bound below leaves out
/// (products of two rounding errors, the rounding of the error terms themselves): a factor of
/// two on a bound that is already worst-case.
const BOUND_SAFETY: f64 = 2.0;

/// Higham's γₙ for `f32` arithmetic, in `f64`.
pub fn gamma(n: u32) -> f64 {
    let n = n as f64 * EPS;
    n / (1.0 - n)
}

/// What the watertight test must answer for one ray and triangle, given only that its `f32`
/// arithmetic rounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Expect {
    /// The exact answer is a hit at this `t`, by more than the `f32` error on every edge, and
    /// `t` is farther from zero than the core's bound on its error allows rounding to confuse.
    Hit(f64),
    /// The exact answer is a miss, by more than the `f32` error.
    Miss,
    /// The ray passes within the `f32` error of an edge (or of the triangle's plane, for a
    /// ray lying in it): either answer is correct.
    Either,
    /// The exact answer is a hit at this `t`, clear of every edge, but `t` is below the
    /// caller's `min_t` or too close to zero for the core's bound on its error: either answer
    /// is correct (a miss here is a real hit given up to rounding, and is counted).
    Close(f64),
}

impl Expect {
    /// Whether either answer is correct.
    pub fn either(self) -> bool {
        matches!(self, Expect::Either | Expect::Close(_))
    }
}

/// Decides a ray/triangle case exactly: the inside/outside question in `f64` on the exact
/// `f32` inputs, with this file's own worst-case bound on the error the test's `f32` edge
/// functions can make (an independent reference, in the sheared frame of the library's
/// [`Ray::axes`]); the distance question with the library's own [`t_error_bound`], whose
/// soundness `tests/stability_properties.rs` checks separately. Hits with `t` below `min_t`
/// are [`Expect::Close`].
pub fn expect(origin: Vec3, dir: Vec3, v: &[Vec3; 3], min_t: f64) -> Expect {
    let ray = Ray::new(origin, dir);
    let [kx, ky, kz] = ray.axes();
    let dd = d(dir);
    let (sx, sy) = (-dd[kx] / dd[kz], -dd[ky] / dd[kz]);
    // Sheared vertex coordinates (exact up to f64 rounding) and their f32 error bounds: one
    // rounding in `v − o`, two in the shear constant, one in the product, one in the sum.
    let mut p = [(0.0, 0.0, 0.0, 0.0, 0.0); 3];
    for (i, vi) in v.iter().enumerate() {
        let a = d(*vi) - d(origin);
        let x = a[kx] + sx * a[kz];
        let y = a[ky] + sy * a[kz];
        let ex = gamma(5) * (a[kx].abs() + (sx * a[kz]).abs());
        let ey = gamma(5) * (a[ky].abs() + (sy * a[kz]).abs());
        p[i] = (x, y, ex, ey, a[kz] / dd[kz]);
    }
    // e_i = x_j·y_k − y_j·x_k for (i, j, k) cyclic: error from the inputs plus two roundings.
    let mut e = [0.0f64; 3];
    let mut err = [0.0f64; 3];
    for i in 0..3 {
        let (xj, yj, exj, eyj, _) = p[(i + 1) % 3];
        let (xk, yk, exk, eyk, _) = p[(i + 2) % 3];
        e[i] = xj * yk - yj * xk;
        let input = xj.abs() * eyk + yk.abs() * exj + yj.abs() * exk + xk.abs() * eyj;
        err[i] = BOUND_SAFETY * (input + gamma(2) * ((xj * yk).abs() + (yj * xk).abs()));
    }
    let pos = (0..3).filter(|&i| e[i] > err[i]).count();
    let neg = (0..3).filter(|&i| e[i] < -err[i]).count();
    if pos > 0 && neg > 0 {
        return Expect::Miss;
    }
    if pos < 3 && neg < 3 {
        return Expect::Either;
    }
    let det: f64 = e.iter().sum();
    let t = (0..3).map(|i| e[i] * p[i].4).sum::<f64>() / det;
    if t < -min_t {
        return Expect::Miss;
    }
    if t < min_t {
        return Expect::Close(t);
    }
    match core_t_bound(&ray, v, t as f32) {
        Some(bound) if t > T_CONDITION * bound as f64 => Expect::Hit(t),
        _ => Expect::Close(t),
    }
}

/// The library's bound on the error of `t` ([`t_error_bound`]) for `ray` and triangle `v`,
/// evaluated at `t` on the library's own sheared frame and edge functions.
pub fn core_t_bound(ray: &Ray, v: &[Vec3; 3], t: f32) -> Option<f32> {
    let frame = ray.frame(v);
    t_error_bound(ray, &frame, frame.edge_functions(), t)
}

/// A hit is required only where the exact `t` exceeds the library's bound on its error by this
/// factor. The library computes `t̃` within `δ` of `t` and rejects it when `t̃ ≤ δ`; if
/// `t > 2δ` then `t̃ ≥ t − δ > δ`, so the hit must be kept (δ is evaluated at `t̃`, not `t`,
/// which moves it by far less than the margin).
pub const T_CONDITION: f64 = 2.0;

/// The exact parameter where the ray `origin + t·dir` meets the plane of `v` (all in `f64` on
/// the exact `f32` inputs), or `None` when it is parallel to it.
pub fn plane_t(origin: Vec3, dir: Vec3, v: &[Vec3; 3]) -> Option<f64> {
    let [a, b, c] = d3(v);
    let n = (b - a).cross(c - a);
    let denom = n.dot(d(dir));
    (denom != 0.0).then(|| n.dot(a - d(origin)) / denom)
}

/// Distance from `p` to the triangle `v` (zero inside), in `f64`.
pub fn point_triangle_distance(p: DVec3, v: &[DVec3; 3]) -> f64 {
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let inside = (0..3).all(|i| {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        (b - a).cross(p - a).dot(n) >= 0.0
    });
    if inside {
        return ((p - v[0]).dot(n) / n.length()).abs();
    }
    (0..3)
        .map(|i| edges::point_segment_distance(p, v[i], v[(i + 1) % 3]))
        .fold(f64::INFINITY, f64::min)
}
