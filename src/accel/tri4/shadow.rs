//! Shadow rays eight at a time: one triangle against eight rays that share their axes but not
//! their origins (a tile's rays toward a point light), any hit only. Each lane runs the
//! scalar test's operations ([`crate::geometry::watertight_lanes`], the kernel of every path)
//! on its own origin and shear, so a lane is reported hit exactly when
//! [`crate::geometry::intersect_watertight`] accepts it; a lane whose edge function rounds to
//! 0 is handed back (`redo`) for the scalar test's `f64` edges.

use super::LANES;
use crate::geometry::watertight_lanes;
use crate::simd::{F8, Lanes};

/// Up to eight rays with the same axes (`kx`, `ky`, `kz`), lane by lane: each origin in that
/// axis order and each shear, as [`crate::geometry::Ray`] holds them.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub struct ShadowRays8 {
    /// Per lane: `origin[kx]`, `origin[ky]`, `origin[kz]`.
    pub origin: [[f32; 2 * LANES]; 3],
    /// Per lane: `sx`, `sy`, `sz` ([`crate::geometry::Ray::shear`]).
    pub shear: [[f32; 2 * LANES]; 3],
    /// The lanes' common axes ([`crate::geometry::Ray::axes`]).
    pub axes: [usize; 3],
}

/// Which lanes of `rays` hit the triangle of vertices `v` (each `[x, y, z, 0]`) before `t_max` (bit per lane), and which lanes the
/// scalar test must redo (an edge function rounded to 0). Lanes that hold no ray give
/// meaningless bits: callers mask them.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn any_hit8_avx2(v: &[[f32; 4]; 3], rays: &ShadowRays8, t_max: f32) -> (u32, u32) {
    // SAFETY: this function's contract.
    unsafe { any_hit8(v, rays, t_max) }
}

/// [`any_hit8_avx2`] inlined into its caller (a kernel compiled for AVX2 or AVX-512).
///
/// # Safety
/// The CPU must have AVX2.
#[inline(always)]
pub(crate) unsafe fn any_hit8(v: &[[f32; 4]; 3], rays: &ShadowRays8, t_max: f32) -> (u32, u32) {
    // (No closures: this runs inlined into kernels compiled for AVX2 or AVX-512, and a
    // closure would be compiled on its own, without those features.)
    let [kx, ky, kz] = rays.axes;
    let o = &rays.origin;
    let (ox, oy, oz) = (F8::load(&o[0]), F8::load(&o[1]), F8::load(&o[2]));
    // Each vertex relative to each lane's origin, in the axis order.
    let rel = [
        [
            F8::splat(v[0][kx]).sub(ox),
            F8::splat(v[0][ky]).sub(oy),
            F8::splat(v[0][kz]).sub(oz),
        ],
        [
            F8::splat(v[1][kx]).sub(ox),
            F8::splat(v[1][ky]).sub(oy),
            F8::splat(v[1][kz]).sub(oz),
        ],
        [
            F8::splat(v[2][kx]).sub(ox),
            F8::splat(v[2][ky]).sub(oy),
            F8::splat(v[2][kz]).sub(oz),
        ],
    ];
    let s = &rays.shear;
    let shear = [F8::load(&s[0]), F8::load(&s[1]), F8::load(&s[2])];
    let f = watertight_lanes(rel, shear, F8::splat(t_max), false);
    (f.mask, f.redo)
}
