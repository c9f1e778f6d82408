//! The SSE2 and AVX2 kernels: one template ([`watertight_lanes`]) instantiated with four-lane
//! (`sse`) and eight-lane (`avx`) operations. Each step is [`intersect_watertight`]'s and
//! [`t_error_bound`]'s, operation for operation and in their order, so an accepted lane's `t`
//! and barycentrics are the scalar test's bits. Comparisons are ordered (false on NaN) like
//! Rust's `<`, `>`, `==`; `max` is only applied to values that are never NaN in a lane that can
//! be accepted, where it agrees with `f32::max`.
//!
//! [`intersect_watertight`]: crate::geometry::intersect_watertight
//! [`t_error_bound`]: crate::geometry::t_error_bound

use std::arch::x86_64::*;

use super::{Best8, LANES, LaneHits, RayLanes, Tri4};
use crate::geometry::{RayTile, gamma};

/// The watertight test of one ray against every lane of `$load`'s triangles, with the
/// operations of module `$o`: the ray's constants splatted, the vertices loaded.
macro_rules! triangle_lanes {
    ($o:ident, $load:expr, $r:expr, $t_max:expr) => {{
        use $o::*;
        let r: &RayLanes = $r;
        let [kx, ky, kz] = r.axes;
        let (ox, oy, oz) = (splat(r.origin[0]), splat(r.origin[1]), splat(r.origin[2]));
        // `RayFrame`: the vertices relative to the origin (then sheared in `watertight_lanes`).
        let (a0, b0, z0) = (
            sub($load(0, kx), ox),
            sub($load(0, ky), oy),
            sub($load(0, kz), oz),
        );
        let (a1, b1, z1) = (
            sub($load(1, kx), ox),
            sub($load(1, ky), oy),
            sub($load(1, kz), oz),
        );
        let (a2, b2, z2) = (
            sub($load(2, kx), ox),
            sub($load(2, ky), oy),
            sub($load(2, kz), oz),
        );
        watertight_lanes!(
            $o,
            [a0, b0, z0, a1, b1, z1, a2, b2, z2],
            [splat(r.shear[0]), splat(r.shear[1]), splat(r.shear[2])],
            splat($t_max)
        )
    }};
}

/// The watertight test lane by lane, with the operations of module `$o` (`V` lanes wide,
/// `FULL` the mask of all lanes), from each lane's vertices relative to its ray's origin in the
/// ray's axis order (`a`, `b`, `z` per vertex), its shear and its `t_max`: evaluates to
/// `(mask, redo, t, b0, b1, b2, accepted)`, `accepted` the hit lanes as a vector mask.
///
/// With a fifth argument `sure` (a `bool`) true, the caller has proven that every lane which
/// passes the sign and range tests also passes `t_error_bound`'s two (the determinant's sign
/// is certain, `t` is beyond its error bound): they are not computed (debug builds compute
/// them and assert it).
macro_rules! watertight_lanes {
    ($o:ident, [$a0:expr, $b0:expr, $z0:expr, $a1:expr, $b1:expr, $z1:expr, $a2:expr, $b2:expr, $z2:expr],
     [$sx:expr, $sy:expr, $sz:expr], $t_max:expr) => {
        watertight_lanes!($o, [$a0, $b0, $z0, $a1, $b1, $z1, $a2, $b2, $z2], [$sx, $sy, $sz], $t_max, false)
    };
    ($o:ident, [$a0:expr, $b0:expr, $z0:expr, $a1:expr, $b1:expr, $z1:expr, $a2:expr, $b2:expr, $z2:expr],
     [$sx:expr, $sy:expr, $sz:expr], $t_max:expr, $sure:expr) => {{
        use $o::*;
        let sure: bool = $sure;
        let (a0, b0, z0, a1, b1, z1, a2, b2, z2) = ($a0, $b0, $z0, $a1, $b1, $z1, $a2, $b2, $z2);
        let (sx, sy, sz) = ($sx, $sy, $sz);
        let t_max = $t_max;
        let (x0, y0) = (add(a0, mul(sx, z0)), add(b0, mul(sy, z0)));
        let (x1, y1) = (add(a1, mul(sx, z1)), add(b1, mul(sy, z1)));
        let (x2, y2) = (add(a2, mul(sx, z2)), add(b2, mul(sy, z2)));
        // The edge functions (`RayFrame::edge_functions`), their products kept for the bound.
        let (p12, p21) = (mul(x1, y2), mul(y1, x2));
        let (p20, p02) = (mul(x2, y0), mul(y2, x0));
        let (p01, p10) = (mul(x0, y1), mul(y0, x1));
        let (e0, e1, e2) = (sub(p12, p21), sub(p20, p02), sub(p01, p10));
        let zero = splat(0.0);
        let any_zero = or(or(eq(e0, zero), eq(e1, zero)), eq(e2, zero));
        let any_neg = or(or(lt(e0, zero), lt(e1, zero)), lt(e2, zero));
        let any_pos = or(or(gt(e0, zero), gt(e1, zero)), gt(e2, zero));
        let det = add(add(e0, e1), e2);
        let (zs0, zs1, zs2) = (mul(sz, z0), mul(sz, z1), mul(sz, z2));
        let t_scaled = add(add(mul(e0, zs0), mul(e1, zs1)), mul(e2, zs2));
        let bound = mul(t_max, det);
        // Rejected as the scalar test rejects, in its order: mixed signs, a zero or NaN det,
        // `t·det` outside (0, t_max·det] on det's side.
        let reject = or(
            or(and(any_neg, any_pos), or(eq(det, zero), unord(det, det))),
            or(
                and(lt(det, zero), or(ge(t_scaled, zero), lt(t_scaled, bound))),
                and(gt(det, zero), or(le(t_scaled, zero), gt(t_scaled, bound))),
            ),
        );
        let redo = mask(any_zero);
        let pass = !mask(reject) & !redo & FULL;
        if pass == 0 {
            (0, redo, zero, zero, zero, zero, no_lanes())
        } else {
            let one = splat(1.0);
            let inv_det = div(one, det);
            let t = mul(t_scaled, inv_det);
            let below = lt(t, t_max);
            let fast = andnot(or(reject, any_zero), below);
            let accepted = if sure && !cfg!(debug_assertions) {
                fast
            } else {
                // `t_error_bound`.
                let (g2, g3, g5) = (splat(gamma(2)), splat(gamma(3)), splat(gamma(5)));
                let two = splat(2.0);
                let max_zt = max(max(abs(zs0), abs(zs1)), abs(zs2));
                let (az0, az1, az2) = (abs(z0), abs(z1), abs(z2));
                let (ax0, ax1, ax2) = (abs(x0), abs(x1), abs(x2));
                let (ay0, ay1, ay2) = (abs(y0), abs(y1), abs(y2));
                let dx0 = mul(g5, add(ax0, mul(two, abs(mul(sx, az0)))));
                let dx1 = mul(g5, add(ax1, mul(two, abs(mul(sx, az1)))));
                let dx2 = mul(g5, add(ax2, mul(two, abs(mul(sx, az2)))));
                let dy0 = mul(g5, add(ay0, mul(two, abs(mul(sy, az0)))));
                let dy1 = mul(g5, add(ay1, mul(two, abs(mul(sy, az1)))));
                let dy2 = mul(g5, add(ay2, mul(two, abs(mul(sy, az2)))));
                // `EdgeErrors::new`'s edge(j, k), for (1, 2), (2, 0), (0, 1).
                let ee0 = add(
                    add(add(add(mul(ax1, dy2), mul(ay2, dx1)), mul(ay1, dx2)), mul(ax2, dy1)),
                    mul(g2, add(abs(p12), abs(p21))),
                );
                let ee1 = add(
                    add(add(add(mul(ax2, dy0), mul(ay0, dx2)), mul(ay2, dx0)), mul(ax0, dy2)),
                    mul(g2, add(abs(p20), abs(p02))),
                );
                let ee2 = add(
                    add(add(add(mul(ax0, dy1), mul(ay1, dx0)), mul(ay0, dx1)), mul(ax1, dy0)),
                    mul(g2, add(abs(p01), abs(p10))),
                );
                // `EdgeErrors::weights`.
                let total = add(add(ee0, ee1), ee2);
                let adet = abs(det);
                let margin = sub(adet, total);
                let certain = gt(margin, zero);
                let inv = div(one, adet);
                let g3z = mul(g3, max_zt);
                let spread0 = add(abs(sub(zs0, t)), g3z);
                let spread1 = add(abs(sub(zs1, t)), g3z);
                let spread2 = add(abs(sub(zs2, t)), g3z);
                let w0 = mul(add(ee0, mul(abs(mul(e0, inv)), total)), spread0);
                let w1 = mul(add(ee1, mul(abs(mul(e1, inv)), total)), spread1);
                let w2 = mul(add(ee2, mul(abs(mul(e2, inv)), total)), spread2);
                let weights_error = div(add(add(w0, w1), w2), margin);
                let delta_t = mul(
                    two,
                    add(
                        add(mul(splat(2.0 * gamma(3)), max_zt), mul(g3, t)),
                        weights_error,
                    ),
                );
                let beyond = gt(t, delta_t);
                let full = andnot(
                    or(reject, any_zero),
                    and(and(below, certain), beyond),
                );
                debug_assert!(!sure || mask(full) == mask(fast), "a sure triangle failed the bound");
                full
            };
            (
                mask(accepted),
                redo,
                t,
                mul(e0, inv_det),
                mul(e1, inv_det),
                mul(e2, inv_det),
                accepted,
            )
        }
    }};
}
pub(super) use watertight_lanes;

/// Four lanes of SSE2, under the names [`watertight_lanes`] uses. SAFETY (of every `unsafe`
/// here): SSE2 is part of every x86-64 CPU; these take and return registers only.
mod sse {
    use std::arch::x86_64::*;

    pub type V = __m128;
    pub const FULL: u32 = 0xf;

    #[inline(always)]
    pub fn splat(x: f32) -> V {
        unsafe { _mm_set1_ps(x) }
    }
    #[inline(always)]
    pub fn add(a: V, b: V) -> V {
        unsafe { _mm_add_ps(a, b) }
    }
    #[inline(always)]
    pub fn sub(a: V, b: V) -> V {
        unsafe { _mm_sub_ps(a, b) }
    }
    #[inline(always)]
    pub fn mul(a: V, b: V) -> V {
        unsafe { _mm_mul_ps(a, b) }
    }
    #[inline(always)]
    pub fn div(a: V, b: V) -> V {
        unsafe { _mm_div_ps(a, b) }
    }
    #[inline(always)]
    pub fn abs(a: V) -> V {
        unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), a) }
    }
    /// `f32::max` where neither is NaN.
    #[inline(always)]
    pub fn max(a: V, b: V) -> V {
        unsafe { _mm_max_ps(a, b) }
    }
    #[inline(always)]
    pub fn and(a: V, b: V) -> V {
        unsafe { _mm_and_ps(a, b) }
    }
    #[inline(always)]
    pub fn or(a: V, b: V) -> V {
        unsafe { _mm_or_ps(a, b) }
    }
    /// `b` where `a` is clear.
    #[inline(always)]
    pub fn andnot(a: V, b: V) -> V {
        unsafe { _mm_andnot_ps(a, b) }
    }
    /// `b` where `m` is set, else `a`.
    #[inline(always)]
    pub fn select(m: V, a: V, b: V) -> V {
        unsafe { _mm_or_ps(_mm_and_ps(m, b), _mm_andnot_ps(m, a)) }
    }
    #[inline(always)]
    pub fn eq(a: V, b: V) -> V {
        unsafe { _mm_cmpeq_ps(a, b) }
    }
    #[inline(always)]
    pub fn lt(a: V, b: V) -> V {
        unsafe { _mm_cmplt_ps(a, b) }
    }
    #[inline(always)]
    pub fn le(a: V, b: V) -> V {
        unsafe { _mm_cmple_ps(a, b) }
    }
    #[inline(always)]
    pub fn gt(a: V, b: V) -> V {
        unsafe { _mm_cmpgt_ps(a, b) }
    }
    #[inline(always)]
    pub fn ge(a: V, b: V) -> V {
        unsafe { _mm_cmpge_ps(a, b) }
    }
    #[inline(always)]
    pub fn unord(a: V, b: V) -> V {
        unsafe { _mm_cmpunord_ps(a, b) }
    }
    #[inline(always)]
    pub fn mask(a: V) -> u32 {
        unsafe { _mm_movemask_ps(a) as u32 }
    }
    /// The mask of no lane.
    #[inline(always)]
    pub fn no_lanes() -> V {
        unsafe { _mm_setzero_ps() }
    }
}

/// Eight lanes of AVX, under the names [`watertight_lanes`] uses. Compiled for AVX2 (the path's
/// feature), so they inline into the AVX2 kernels.
pub(super) mod avx {
    use std::arch::x86_64::*;

    pub type V = __m256;
    pub const FULL: u32 = 0xff;

    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn splat(x: f32) -> V {
        _mm256_set1_ps(x)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn add(a: V, b: V) -> V {
        _mm256_add_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn sub(a: V, b: V) -> V {
        _mm256_sub_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn mul(a: V, b: V) -> V {
        _mm256_mul_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn div(a: V, b: V) -> V {
        _mm256_div_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn abs(a: V) -> V {
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), a)
    }
    /// `f32::max` where neither is NaN.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn max(a: V, b: V) -> V {
        _mm256_max_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn and(a: V, b: V) -> V {
        _mm256_and_ps(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn or(a: V, b: V) -> V {
        _mm256_or_ps(a, b)
    }
    /// `b` where `a` is clear.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn andnot(a: V, b: V) -> V {
        _mm256_andnot_ps(a, b)
    }
    /// `b` where `m` is set, else `a`.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn select(m: V, a: V, b: V) -> V {
        _mm256_blendv_ps(a, b, m)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn eq(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn lt(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_LT_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn le(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_LE_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn gt(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_GT_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn ge(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_GE_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn unord(a: V, b: V) -> V {
        _mm256_cmp_ps::<_CMP_UNORD_Q>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn mask(a: V) -> u32 {
        _mm256_movemask_ps(a) as u32
    }
    /// The mask of no lane.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn no_lanes() -> V {
        _mm256_setzero_ps()
    }
}

// Sixteen lanes of AVX-512 under the same names (its own file: comparisons give masks).
pub(super) mod avx512;

/// The hits of one block with SSE2 (four lanes): `(mask, redo)` as in [`super::Hits`], and, when
/// some lane is hit, their `t` and barycentrics into lanes `half..half + 4` of `out`.
#[inline(always)]
pub fn hits_sse2(
    block: &Tri4,
    r: &RayLanes,
    t_max: f32,
    out: &mut LaneHits,
    half: usize,
) -> (u32, u32) {
    let v = &block.v;
    // SAFETY: SSE2 is part of every x86-64; each load reads a whole aligned `[f32; 4]`.
    let load = |i: usize, axis: usize| unsafe { _mm_load_ps(v[i][axis].as_ptr()) };
    let (mask, redo, t, b0, b1, b2, _) = triangle_lanes!(sse, load, r, t_max);
    if mask != 0 {
        // SAFETY: each store writes four of eight `f32`s (`half` is 0 or 4).
        unsafe {
            _mm_storeu_ps(out.t[half..].as_mut_ptr(), t);
            _mm_storeu_ps(out.b[0][half..].as_mut_ptr(), b0);
            _mm_storeu_ps(out.b[1][half..].as_mut_ptr(), b1);
            _mm_storeu_ps(out.b[2][half..].as_mut_ptr(), b2);
        }
    }
    (mask, redo)
}

/// The hits of two blocks at once with AVX2 (lanes 0-3 from `a`, 4-7 from `b`): `(mask,
/// redo)` as in [`super::Hits`], and, when some lane is hit, their `t` and barycentrics into `out`.
///
/// Always inlined, and without a `target_feature` of its own (a function with one cannot be
/// `inline(always)`, and LLVM declines to inline one this large): it is only called from
/// functions compiled with AVX2 enabled, where its operations (AVX2 functions themselves,
/// which do inline there) become the caller's own instructions, the masks stay in registers
/// and a caller that reads only the masks (an any-hit query) drops the rest. Called from
/// anywhere else it would still be right, only slow.
///
/// # Safety
/// The CPU must have AVX2 ([`super::Isa::Avx2`] available).
#[inline(always)]
pub unsafe fn hits2_avx2(
    a: &Tri4,
    b: &Tri4,
    r: &RayLanes,
    t_max: f32,
    out: &mut LaneHits,
) -> (u32, u32) {
    #[target_feature(enable = "avx2")]
    #[inline]
    fn load2(a: &Tri4, b: &Tri4, i: usize, axis: usize) -> __m256 {
        // SAFETY: each load reads a whole `[f32; 4]`, 16-byte aligned.
        unsafe {
            _mm256_insertf128_ps(
                _mm256_castps128_ps256(_mm_load_ps(a.v[i][axis].as_ptr())),
                _mm_load_ps(b.v[i][axis].as_ptr()),
                1,
            )
        }
    }
    // SAFETY: the caller guarantees AVX2, which every operation here needs and no more.
    unsafe {
        let load = |i: usize, axis: usize| load2(a, b, i, axis);
        let (mask, redo, t, b0, b1, b2, _) = triangle_lanes!(avx, load, r, t_max);
        if mask != 0 {
            // Each store writes eight `f32`s.
            _mm256_storeu_ps(out.t.as_mut_ptr(), t);
            _mm256_storeu_ps(out.b[0].as_mut_ptr(), b0);
            _mm256_storeu_ps(out.b[1].as_mut_ptr(), b1);
            _mm256_storeu_ps(out.b[2].as_mut_ptr(), b2);
        }
        (mask, redo)
    }
}

/// [`hits2_avx2`] compiled as a function of its own with AVX2 (for [`super::hits2`]: tests
/// and tools).
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
pub unsafe fn hits2_avx2_call(
    a: &Tri4,
    b: &Tri4,
    r: &RayLanes,
    t_max: f32,
    out: &mut LaneHits,
) -> (u32, u32) {
    // SAFETY: as the caller guarantees.
    unsafe { hits2_avx2(a, b, r, t_max, out) }
}

/// [`hits_sse2`] compiled with AVX2 (VEX-encoded): the one-block kernel of the AVX2 path, as
/// traversals inline it (for [`super::hits`]: tests and tools).
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
pub unsafe fn hits_avx2_call(
    block: &Tri4,
    r: &RayLanes,
    t_max: f32,
    out: &mut LaneHits,
) -> (u32, u32) {
    hits_sse2(block, r, t_max, out, 0)
}

const _: () = assert!(LANES == 4);

/// One triangle (`rel`: its vertices relative to the rays' common origin, in their axis
/// order) against `tile`'s rays eight at a time with AVX2, folded into `best` (one per packet
/// of eight rays: lanes that hit it nearer than their best so far take it, as `id`). Returns
/// the rays to redo with the scalar test (bits from `tile.len()` on are meaningless). The
/// triangle's lanes are set up once for all packets. `sure`: see [`super::Kernel::rays`].
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn rays_avx2(
    rel: &[[f32; 3]; 3],
    tile: &RayTile,
    t_max: f32,
    id: u32,
    sure: bool,
    best: &mut [Best8],
) -> u64 {
    // SAFETY: this function's contract.
    unsafe { rays_avx2_from(rel, tile, t_max, id, sure, best, 0) }
}

/// [`rays_avx2`] for the packets of `best`, which are the tile's from packet `first` on.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn rays_avx2_from(
    rel: &[[f32; 3]; 3],
    tile: &RayTile,
    t_max: f32,
    id: u32,
    sure: bool,
    best: &mut [Best8],
    first: usize,
) -> u64 {
    use avx::*;
    let [[a0, b0, z0], [a1, b1, z1], [a2, b2, z2]] = rel;
    let (a0, b0, z0) = (splat(*a0), splat(*b0), splat(*z0));
    let (a1, b1, z1) = (splat(*a1), splat(*b1), splat(*z1));
    let (a2, b2, z2) = (splat(*a2), splat(*b2), splat(*z2));
    let t_max = splat(t_max);
    let id = _mm256_castsi256_ps(_mm256_set1_epi32(id as i32));
    let mut redo_all = 0;
    for (p, best) in best.iter_mut().enumerate() {
        let at = 8 * (first + p);
        // SAFETY: every load and store reads or writes eight `f32`s, 32-byte aligned (the
        // tile's lanes are aligned and `at` is a multiple of 8 below `TILE_RAYS`).
        let load = |p: &[f32]| unsafe { _mm256_load_ps(p[..8].as_ptr()) };
        let s = &tile.shear;
        let (mask, redo, t, w0, w1, w2, accepted) = watertight_lanes!(
            avx,
            [a0, b0, z0, a1, b1, z1, a2, b2, z2],
            [load(&s[0][at..]), load(&s[1][at..]), load(&s[2][at..])],
            t_max,
            sure
        );
        redo_all |= (redo as u64) << at;
        if mask != 0 {
            let best_t = load(&best.t);
            let take = and(accepted, lt(t, best_t));
            // SAFETY: as above; the ids are moved as bits.
            unsafe {
                let ids = _mm256_castsi256_ps(_mm256_load_si256(best.id.as_ptr().cast()));
                _mm256_store_ps(best.t.as_mut_ptr(), select(take, best_t, t));
                for (b, w) in best.b.iter_mut().zip([w0, w1, w2]) {
                    _mm256_store_ps(b.as_mut_ptr(), select(take, load(b), w));
                }
                let ids = _mm256_castps_si256(select(take, ids, id));
                _mm256_store_si256(best.id.as_mut_ptr().cast(), ids);
            }
        }
    }
    redo_all
}

/// [`rays_avx2`] with AVX-512, sixteen lanes (two packets) at a time; an odd last packet
/// with AVX2. The same operations lane by lane, so the same `best` and redo bits.
///
/// # Safety
/// The CPU must have AVX-512 F, DQ, VL and BW ([`super::Isa::Avx512`] available).
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub unsafe fn rays_avx512(
    rel: &[[f32; 3]; 3],
    tile: &RayTile,
    t_max: f32,
    id: u32,
    sure: bool,
    best: &mut [Best8],
) -> u64 {
    use avx512::*;
    let [[a0, b0, z0], [a1, b1, z1], [a2, b2, z2]] = rel;
    let (a0, b0, z0) = (splat(*a0), splat(*b0), splat(*z0));
    let (a1, b1, z1) = (splat(*a1), splat(*b1), splat(*z1));
    let (a2, b2, z2) = (splat(*a2), splat(*b2), splat(*z2));
    let t_max_v = splat(t_max);
    let id_v = _mm512_castsi512_ps(_mm512_set1_epi32(id as i32));
    let mut redo_all = 0;
    let pairs = best.len() / 2;
    for (q, pair) in best.chunks_exact_mut(2).enumerate() {
        let at = 16 * q;
        // SAFETY: each load reads sixteen `f32`s of a tile row of `TILE_RAYS` (`at + 16` is at
        // most `TILE_RAYS`: `best` holds at most `TILE_RAYS / 8` packets).
        let load = |p: &[f32]| unsafe { _mm512_loadu_ps(p[..16].as_ptr()) };
        let s = &tile.shear;
        let (mask, redo, t, w0, w1, w2, accepted) = watertight_lanes!(
            avx512,
            [a0, b0, z0, a1, b1, z1, a2, b2, z2],
            [load(&s[0][at..]), load(&s[1][at..]), load(&s[2][at..])],
            t_max_v,
            sure
        );
        redo_all |= (redo as u64) << at;
        if mask != 0 {
            let (lo, hi) = pair.split_at_mut(1);
            let (lo, hi) = (&mut lo[0], &mut hi[0]);
            // SAFETY: every load and store reads or writes a whole 32-byte-aligned `[f32; 8]`
            // or `[u32; 8]` of the two packets; the ids are moved as bits.
            unsafe {
                let ld = |a: &[f32; 8], b: &[f32; 8]| {
                    join(_mm256_load_ps(a.as_ptr()), _mm256_load_ps(b.as_ptr()))
                };
                let st = |a: &mut [f32; 8], b: &mut [f32; 8], v| {
                    let (l, h) = halves(v);
                    _mm256_store_ps(a.as_mut_ptr(), l);
                    _mm256_store_ps(b.as_mut_ptr(), h);
                };
                let best_t = ld(&lo.t, &hi.t);
                let take = and(accepted, lt(t, best_t));
                st(&mut lo.t, &mut hi.t, select(take, best_t, t));
                for (k, w) in [w0, w1, w2].into_iter().enumerate() {
                    let old = ld(&lo.b[k], &hi.b[k]);
                    st(&mut lo.b[k], &mut hi.b[k], select(take, old, w));
                }
                let ids = join(
                    _mm256_castsi256_ps(_mm256_load_si256(lo.id.as_ptr().cast())),
                    _mm256_castsi256_ps(_mm256_load_si256(hi.id.as_ptr().cast())),
                );
                let (l, h) = halves(select(take, ids, id_v));
                _mm256_store_si256(lo.id.as_mut_ptr().cast(), _mm256_castps_si256(l));
                _mm256_store_si256(hi.id.as_mut_ptr().cast(), _mm256_castps_si256(h));
            }
        }
    }
    if best.len() % 2 == 1 {
        // SAFETY: the CPU has AVX2 (this function's contract).
        redo_all |= unsafe {
            rays_avx2_from(
                rel,
                tile,
                t_max,
                id,
                sure,
                &mut best[2 * pairs..],
                2 * pairs,
            )
        };
    }
    redo_all
}

/// [`rays_avx2`] with SSE2, four lanes at a time.
#[inline(always)]
pub fn rays_sse2(
    rel: &[[f32; 3]; 3],
    tile: &RayTile,
    t_max: f32,
    id: u32,
    sure: bool,
    best: &mut [Best8],
) -> u64 {
    use sse::*;
    let [[a0, b0, z0], [a1, b1, z1], [a2, b2, z2]] = rel.map(|v| v.map(splat));
    let t_max = splat(t_max);
    let mut redo_all = 0;
    for (p, best) in best.iter_mut().enumerate() {
        for half in [0, LANES] {
            let at = 8 * p + half;
            // SAFETY: every load and store reads or writes four `f32`s, 16-byte aligned.
            let load = |p: &[f32]| unsafe { _mm_load_ps(p[..4].as_ptr()) };
            let s = &tile.shear;
            let (mask, redo, t, w0, w1, w2, accepted) = watertight_lanes!(
                sse,
                [a0, b0, z0, a1, b1, z1, a2, b2, z2],
                [load(&s[0][at..]), load(&s[1][at..]), load(&s[2][at..])],
                t_max,
                sure
            );
            redo_all |= (redo as u64) << at;
            if mask != 0 {
                let best_t = load(&best.t[half..]);
                let take = and(accepted, lt(t, best_t));
                // SAFETY: as above; the ids are moved as bits.
                unsafe {
                    let ids = _mm_castsi128_ps(_mm_load_si128(best.id[half..].as_ptr().cast()));
                    _mm_store_ps(best.t[half..].as_mut_ptr(), select(take, best_t, t));
                    for (b, w) in best.b.iter_mut().zip([w0, w1, w2]) {
                        let old = _mm_load_ps(b[half..].as_ptr());
                        _mm_store_ps(b[half..].as_mut_ptr(), select(take, old, w));
                    }
                    let id = _mm_castsi128_ps(_mm_set1_epi32(id as i32));
                    let ids = _mm_castps_si128(select(take, ids, id));
                    _mm_store_si128(best.id[half..].as_mut_ptr().cast(), ids);
                }
            }
        }
    }
    redo_all
}

/// Each lane of `best` as `[t, b0, b1, b2]`, by a 4×8 transposition with AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn best_lanes_avx2(best: &Best8) -> [[f32; 4]; 8] {
    // SAFETY: every load reads a whole 32-byte-aligned `[f32; 8]`; every store writes a whole
    // `[f32; 4]`.
    unsafe {
        let t = _mm256_load_ps(best.t.as_ptr());
        let [b0, b1, b2] = best.b.each_ref().map(|b| _mm256_load_ps(b.as_ptr()));
        // Lanes (i, i + 4) of each pair of rows side by side, then in fours.
        let (tb_lo, tb_hi) = (_mm256_unpacklo_ps(t, b0), _mm256_unpackhi_ps(t, b0));
        let (bb_lo, bb_hi) = (_mm256_unpacklo_ps(b1, b2), _mm256_unpackhi_ps(b1, b2));
        let q = [
            _mm256_shuffle_ps::<0x44>(tb_lo, bb_lo),
            _mm256_shuffle_ps::<0xee>(tb_lo, bb_lo),
            _mm256_shuffle_ps::<0x44>(tb_hi, bb_hi),
            _mm256_shuffle_ps::<0xee>(tb_hi, bb_hi),
        ];
        // `q[i]` holds lane i in its low half and lane i + 4 in its high half.
        let mut out = [[0f32; 4]; 8];
        for (i, q) in q.into_iter().enumerate() {
            _mm_storeu_ps(out[i].as_mut_ptr(), _mm256_castps256_ps128(q));
            _mm_storeu_ps(out[i + 4].as_mut_ptr(), _mm256_extractf128_ps::<1>(q));
        }
        out
    }
}
