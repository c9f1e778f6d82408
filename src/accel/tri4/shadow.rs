//! Shadow rays eight at a time: one triangle against eight rays that share their axes but not
//! their origins (a tile's rays toward a point light), any hit only. Each lane runs the
//! scalar test's operations (`x86.rs`'s `watertight_lanes`, the kernel of every path)
//! on its own origin and shear, so a lane is reported hit exactly when
//! [`crate::geometry::intersect_watertight`] accepts it; a lane whose edge function rounds to
//! 0 is handed back (`redo`) for the scalar test's `f64` edges.

use super::LANES;
use super::x86::{avx, watertight_lanes};
use crate::geometry::gamma;

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
    use avx::*;
    use std::arch::x86_64::*;
    // SAFETY: the CPU has AVX2 (this function's contract); every load reads a whole
    // 32-byte-aligned `[f32; 8]`.
    // (No closures: this runs inlined into kernels compiled for AVX2 or AVX-512, and a
    // closure would be compiled on its own, without those features.)
    unsafe {
        let [kx, ky, kz] = rays.axes;
        let ox = _mm256_load_ps(rays.origin[0].as_ptr());
        let oy = _mm256_load_ps(rays.origin[1].as_ptr());
        let oz = _mm256_load_ps(rays.origin[2].as_ptr());
        // `RayFrame`: each vertex relative to each lane's origin, in the axis order.
        let (a0, b0, z0) = (
            sub(splat(v[0][kx]), ox),
            sub(splat(v[0][ky]), oy),
            sub(splat(v[0][kz]), oz),
        );
        let (a1, b1, z1) = (
            sub(splat(v[1][kx]), ox),
            sub(splat(v[1][ky]), oy),
            sub(splat(v[1][kz]), oz),
        );
        let (a2, b2, z2) = (
            sub(splat(v[2][kx]), ox),
            sub(splat(v[2][ky]), oy),
            sub(splat(v[2][kz]), oz),
        );
        let sx = _mm256_load_ps(rays.shear[0].as_ptr());
        let sy = _mm256_load_ps(rays.shear[1].as_ptr());
        let sz = _mm256_load_ps(rays.shear[2].as_ptr());
        let (hit, redo, ..) = watertight_lanes!(
            avx,
            [a0, b0, z0, a1, b1, z1, a2, b2, z2],
            [sx, sy, sz],
            splat(t_max)
        );
        (hit, redo)
    }
}
