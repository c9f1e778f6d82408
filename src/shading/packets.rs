//! A tile's shadow rays toward one point light in packets of eight with AVX2, for scenes small
//! enough for the light's cull
//! ([`crate::accel::shadow::SHADOW_TILE_TRIANGLES`]): the box of the rays' origins, the
//! triangles the cull keeps for it, then per packet of rays sharing their axes
//! ([`crate::geometry::Ray::new`]'s choice) [`ShadowCull::occluded8`]. The answers are the
//! scalar test's, ray by ray (`accel/shadow.rs`).
//!
//! Every function here is `#[inline(always)]`: it runs inside the tile kernel's entries,
//! compiled for AVX2 or AVX-512.

use std::arch::x86_64::*;

use glam::Vec3;

use super::lane::{Avx2, Lanes, each3};
use super::tile::Points;
use crate::accel::shadow::{ShadowCull, ShadowRays8};
use crate::geometry::Ray;

// SAFETY (every `unsafe` block below): an `Avx2` token exists only where the CPU has AVX2, and
// each load or store reads or writes eight `f32`s of an array that holds them.

/// Which of the `traced` pixels (bit per pixel, the first `m` of `p`) some triangle blocks
/// before `t_max` on the way to the light of `cull` (a small scene's).
#[inline(always)]
pub(super) fn blocked<const C: usize>(
    avx: Avx2,
    cull: &ShadowCull,
    p: &Points<C>,
    m: usize,
    traced: u64,
    t_max: f32,
) -> u64 {
    let (lo, hi) = origin_box(avx, p, m, traced);
    // SAFETY: the CPU has AVX2.
    let kept = unsafe { cull.kept_avx(lo, hi) };
    let mut blocked = 0;
    for c in 0..m.div_ceil(8) {
        let t = (traced >> (8 * c)) as u32 & 0xff;
        if t != 0 {
            blocked |= (packets8(avx, p, cull, kept, c, t, t_max) as u64) << (8 * c);
        }
    }
    blocked
}

/// The least and greatest of `v` over the lanes of `on` (a vector mask with a lane set).
#[inline(always)]
fn min_max8(_: Avx2, v: __m256, on: __m256) -> (f32, f32) {
    unsafe {
        let lo = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), v, on);
        let hi = _mm256_blendv_ps(_mm256_set1_ps(f32::NEG_INFINITY), v, on);
        // Halves, then pairs, then neighbours (no lane is NaN: origins are finite).
        let l = _mm_min_ps(_mm256_castps256_ps128(lo), _mm256_extractf128_ps::<1>(lo));
        let l = _mm_min_ps(l, _mm_movehl_ps(l, l));
        let l = _mm_min_ps(l, _mm_shuffle_ps::<1>(l, l));
        let h = _mm_max_ps(_mm256_castps256_ps128(hi), _mm256_extractf128_ps::<1>(hi));
        let h = _mm_max_ps(h, _mm_movehl_ps(h, h));
        let h = _mm_max_ps(h, _mm_shuffle_ps::<1>(h, h));
        (_mm_cvtss_f32(l), _mm_cvtss_f32(h))
    }
}

/// The box of the origins of the `traced` pixels.
#[inline(always)]
fn origin_box<const C: usize>(s: Avx2, p: &Points<C>, m: usize, traced: u64) -> (Vec3, Vec3) {
    let mut lo = [s.splat(f32::INFINITY); 3];
    let mut hi = [s.splat(f32::NEG_INFINITY); 3];
    for c in 0..m.div_ceil(8) {
        let t = (traced >> (8 * c)) as u32 & 0xff;
        if t == 0 {
            continue;
        }
        let on = s.lanes(t);
        let origin = &p.origin[c];
        each3!(|k| {
            let v = s.load(&origin[k]);
            lo[k] = s.select(on, s.min(lo[k], v), lo[k]);
            hi[k] = s.select(on, s.max(hi[k], v), hi[k]);
        });
    }
    let all = s.lanes(0xff);
    let lo = each3!(|k| min_max8(s, lo[k], all).0);
    let hi = each3!(|k| min_max8(s, hi[k], all).1);
    (Vec3::from_array(lo), Vec3::from_array(hi))
}

/// The shadow rays of the `traced` lanes of block `c` (eight pixels) against the `kept`
/// triangles of `cull`, in packets of one axis order: the lanes blocked.
#[inline(always)]
fn packets8<const C: usize>(
    s: Avx2,
    p: &Points<C>,
    cull: &ShadowCull,
    kept: u64,
    c: usize,
    traced: u32,
    t_max: f32,
) -> u32 {
    let (origin, dir) = (&p.origin[c], &p.dir[c]);
    let dirs = each3!(|k| s.load(&dir[k]));
    let a = each3!(|k| s.abs(dirs[k]));
    let (x_y, x_z, y_z) = (
        s.bits(s.gt(a[0], a[1])),
        s.bits(s.gt(a[0], a[2])),
        s.bits(s.gt(a[1], a[2])),
    );
    // `Ray::new`'s axis: x if |x| > |y| and |x| > |z|, else y if |y| > |z|, else z.
    let (on_x, on_y) = (x_y & x_z, !x_y & y_z);
    let by_axis = [on_x, on_y, !(on_x | on_y)];
    let zero = s.splat(0.0);
    let negative = each3!(|k| s.bits(s.lt(dirs[k], zero)));
    // Each lane's class: its axis and the sign along it (`Ray::new`'s axes and swap).
    let class = |l: usize| {
        let kz = if on_x >> l & 1 == 1 {
            0
        } else if on_y >> l & 1 == 1 {
            1
        } else {
            2
        };
        (kz, negative[kz] >> l & 1 == 1)
    };
    let all = s.lanes(0xff);
    let mut blocked = 0;
    let mut left = traced;
    while left != 0 {
        let (kz, neg) = class(left.trailing_zeros() as usize);
        let side = if neg { negative[kz] } else { !negative[kz] };
        let lanes = left & by_axis[kz] & side;
        left &= !lanes;
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if neg {
            std::mem::swap(&mut kx, &mut ky);
        }
        let mut rays = ShadowRays8 {
            axes: [kx, ky, kz],
            ..ShadowRays8::default()
        };
        // The shear, as `Ray::with_inverse` computes it: `sz = 1/d_kz`, `sx = −d_kx·sz`.
        let sz = s.div(s.splat(1.0), dirs[kz]);
        s.store(&mut rays.shear[0], s.mul(s.neg_where(all, dirs[kx]), sz));
        s.store(&mut rays.shear[1], s.mul(s.neg_where(all, dirs[ky]), sz));
        s.store(&mut rays.shear[2], sz);
        rays.origin = [origin[kx], origin[ky], origin[kz]];
        let oz = min_max8(s, s.load(&origin[kz]), s.lanes(lanes));
        let ray = |l: usize| {
            let at = |v| Points::at(v, 8 * c + l);
            Ray::new(at(&p.origin), at(&p.dir))
        };
        // SAFETY: the CPU has AVX2.
        blocked |= unsafe { cull.occluded8(kept, &rays, lanes, oz, t_max, ray) };
    }
    blocked
}
