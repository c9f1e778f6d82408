//! Sixteen lanes of AVX-512, under the names [`watertight_lanes`] uses: the same IEEE
//! operations on wider registers, so each lane's result is AVX2's bits. Comparisons give masks
//! (`M`, a bit per lane) rather than vectors; `and`, `or`, `andnot` and `select` take those.
//! Compiled for the path's features, so they inline into its kernels.

use std::arch::x86_64::*;

pub type V = __m512;
pub type M = __mmask16;
pub const FULL: u32 = 0xffff;

#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn splat(x: f32) -> V {
    _mm512_set1_ps(x)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn add(a: V, b: V) -> V {
    _mm512_add_ps(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn sub(a: V, b: V) -> V {
    _mm512_sub_ps(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn mul(a: V, b: V) -> V {
    _mm512_mul_ps(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn div(a: V, b: V) -> V {
    _mm512_div_ps(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn abs(a: V) -> V {
    _mm512_andnot_ps(_mm512_set1_ps(-0.0), a)
}
/// `f32::max` where neither is NaN.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn max(a: V, b: V) -> V {
    _mm512_max_ps(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn and(a: M, b: M) -> M {
    a & b
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn or(a: M, b: M) -> M {
    a | b
}
/// `b` where `a` is clear.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn andnot(a: M, b: M) -> M {
    !a & b
}
/// `b` where `m` is set, else `a`.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn select(m: M, a: V, b: V) -> V {
    _mm512_mask_blend_ps(m, a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn eq(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn lt(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_LT_OQ>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn le(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_LE_OQ>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn gt(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_GT_OQ>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn ge(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn unord(a: V, b: V) -> M {
    _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(a, b)
}
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn mask(a: M) -> u32 {
    a as u32
}
/// The mask of no lane.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn no_lanes() -> M {
    0
}
/// Eight lanes of `lo` and eight of `hi`, as one vector.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn join(lo: __m256, hi: __m256) -> V {
    _mm512_insertf32x8::<1>(_mm512_castps256_ps512(lo), hi)
}
/// The two halves of `v`.
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
#[inline]
pub fn halves(v: V) -> (__m256, __m256) {
    (_mm512_castps512_ps256(v), _mm512_extractf32x8_ps::<1>(v))
}
