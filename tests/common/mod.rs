//! Helpers shared by the numerical-stability suite (`tests/stability_*.rs`): seeded random
//! cases, replayable case descriptions, the exact decision of the watertight test with its f32
//! error bound, and an f64 reference tracer of a scene with edge-distance masks.
//!
//! Every stability test draws its cases from [`Rng::seeded`] with a fixed seed per case, and
//! prints [`case`] on failure: the seed, the ray and the triangle with every `f32` in its
//! shortest round-trip form, so pasting them into a test replays the case bit for bit.
#![allow(dead_code)]

pub mod edges;
pub mod reference;

use glam::{DVec3, Vec3};
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

/// The ray axes the watertight test picks: `kz` is the largest component of `dir` in
/// magnitude (first one on ties), `kx`, `ky` follow it cyclically, swapped when `dir[kz] < 0`.
/// A copy of the rule in `Ray::new`, needed to reproduce the test's rounding exactly.
fn ray_axes(dir: Vec3) -> (usize, usize, usize) {
    let a = dir.abs();
    let kz = if a.x > a.y {
        if a.x > a.z { 0 } else { 2 }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if dir[kz] < 0.0 {
        (ky, kx, kz)
    } else {
        (kx, ky, kz)
    }
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
    /// The exact answer is a hit at this `t`, by more than the `f32` error on every edge.
    Hit(f64),
    /// The exact answer is a miss, by more than the `f32` error.
    Miss,
    /// The ray passes within the `f32` error of an edge (or of the triangle's plane, for a
    /// ray lying in it): either answer is correct.
    Either,
}

/// Decides a ray/triangle case exactly (in `f64` on the exact `f32` inputs) and compares each
/// of the watertight test's three edge functions with a worst-case bound on the error the
/// test's own `f32` arithmetic makes in it. Hits with `t` below `min_t` count as [`Expect::Either`]
/// (the test rejects hits within their rounding error of the origin).
pub fn expect(origin: Vec3, dir: Vec3, v: &[Vec3; 3], min_t: f64) -> Expect {
    let (kx, ky, kz) = ray_axes(dir);
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
    // How far the edge functions' errors can move t: t is a weighted mean of the vertices'
    // depths zᵢ, and each weight eᵢ/det may be off by (errᵢ + |wᵢ|·Σerr)/(|det| − Σerr).
    let total: f64 = err.iter().sum();
    let dt: f64 = (0..3)
        .map(|i| (err[i] + (e[i] / det).abs() * total) * (p[i].4 - t).abs())
        .sum::<f64>()
        / (det.abs() - total);
    if t < min_t || !(dt * T_CONDITION < t) {
        Expect::Either
    } else {
        Expect::Hit(t)
    }
}

/// A hit is required only where `t` is certain to be positive by this factor, given the
/// edge functions' `f32` errors (see [`expect`]). The watertight test rejects any hit whose
/// `t` its own error bound cannot separate from zero; that bound is the same analysis with
/// a safety factor of 2 and slightly looser per-vertex terms, so 4 covers it. Only grazing
/// rays (or rays nearly along an edge) are affected: elsewhere `t` is known to ~1e-6.
pub const T_CONDITION: f64 = 4.0;

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
