//! The SSE2 and AVX2 kernels: [`super::portable::candidates_portable`]'s operations, four or eight
//! lanes at a time. Comparisons are ordered (false on NaN) like Rust's `<`, `>`, `==`.

use std::arch::x86_64::*;

use super::{Candidates, LANES, RayLanes, Tri4};

/// [`super::portable::candidates_portable`] with SSE2.
#[inline(always)]
pub fn candidates_sse2(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    // SAFETY: SSE2 is part of every x86-64; the loads read whole `[f32; 4]` arrays.
    unsafe {
        let [kx, ky, kz] = r.axes;
        let (ox, oy, oz) = (
            _mm_set1_ps(r.origin[0]),
            _mm_set1_ps(r.origin[1]),
            _mm_set1_ps(r.origin[2]),
        );
        let (sx, sy, sz) = (
            _mm_set1_ps(r.shear[0]),
            _mm_set1_ps(r.shear[1]),
            _mm_set1_ps(r.shear[2]),
        );
        let v = &block.v;
        let sheared = |i: usize| {
            let a = _mm_sub_ps(_mm_load_ps(v[i][kx].as_ptr()), ox);
            let b = _mm_sub_ps(_mm_load_ps(v[i][ky].as_ptr()), oy);
            let c = _mm_sub_ps(_mm_load_ps(v[i][kz].as_ptr()), oz);
            (
                _mm_add_ps(a, _mm_mul_ps(sx, c)),
                _mm_add_ps(b, _mm_mul_ps(sy, c)),
                c,
            )
        };
        let (x0, y0, z0) = sheared(0);
        let (x1, y1, z1) = sheared(1);
        let (x2, y2, z2) = sheared(2);
        let e0 = _mm_sub_ps(_mm_mul_ps(x1, y2), _mm_mul_ps(y1, x2));
        let e1 = _mm_sub_ps(_mm_mul_ps(x2, y0), _mm_mul_ps(y2, x0));
        let e2 = _mm_sub_ps(_mm_mul_ps(x0, y1), _mm_mul_ps(y0, x1));
        let zero = _mm_setzero_ps();
        let any_zero = _mm_or_ps(
            _mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)),
            _mm_cmpeq_ps(e2, zero),
        );
        let any_neg = _mm_or_ps(
            _mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)),
            _mm_cmplt_ps(e2, zero),
        );
        let any_pos = _mm_or_ps(
            _mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)),
            _mm_cmpgt_ps(e2, zero),
        );
        let det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
        let t_scaled = _mm_add_ps(
            _mm_add_ps(
                _mm_mul_ps(e0, _mm_mul_ps(sz, z0)),
                _mm_mul_ps(e1, _mm_mul_ps(sz, z1)),
            ),
            _mm_mul_ps(e2, _mm_mul_ps(sz, z2)),
        );
        let bound = _mm_mul_ps(_mm_set1_ps(t_max), det);
        // Rejected as the scalar test rejects: mixed signs, a zero or NaN det, or t·det
        // outside (0, t_max·det] (on det's side). A NaN t·det is not rejected here.
        let reject = _mm_or_ps(
            _mm_or_ps(
                _mm_and_ps(any_neg, any_pos),
                _mm_or_ps(_mm_cmpeq_ps(det, zero), _mm_cmpunord_ps(det, det)),
            ),
            _mm_or_ps(
                _mm_and_ps(
                    _mm_cmplt_ps(det, zero),
                    _mm_or_ps(_mm_cmpge_ps(t_scaled, zero), _mm_cmplt_ps(t_scaled, bound)),
                ),
                _mm_and_ps(
                    _mm_cmpgt_ps(det, zero),
                    _mm_or_ps(_mm_cmple_ps(t_scaled, zero), _mm_cmpgt_ps(t_scaled, bound)),
                ),
            ),
        );
        let mask = (!_mm_movemask_ps(reject) as u32 & 0xf) | _mm_movemask_ps(any_zero) as u32;
        let mut out = Candidates {
            mask,
            t: [0.0; 2 * LANES],
        };
        if mask != 0 {
            let mut ts = [0f32; LANES];
            let mut d = [0f32; LANES];
            _mm_storeu_ps(ts.as_mut_ptr(), t_scaled);
            _mm_storeu_ps(d.as_mut_ptr(), det);
            let zero_mask = _mm_movemask_ps(any_zero) as u32;
            out.fill_t(mask, zero_mask, &ts, &d, 0);
        }
        out
    }
}

/// Two blocks with SSE2, one after the other.
#[inline(always)]
pub fn candidates2_sse2(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    let (ca, cb) = (candidates_sse2(a, r, t_max), candidates_sse2(b, r, t_max));
    let mut t = ca.t;
    t[LANES..].copy_from_slice(&cb.t[..LANES]);
    Candidates {
        mask: ca.mask | cb.mask << LANES,
        t,
    }
}

/// Two blocks at once with AVX2: lanes 0-3 from `a`, 4-7 from `b`.
///
/// # Safety
/// The CPU must have AVX2 ([`super::Isa::Avx2`] available).
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn candidates2_avx2(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    // SAFETY (of the loads): each reads a whole `[f32; 4]`, 16-byte aligned.
    unsafe {
        let [kx, ky, kz] = r.axes;
        let load = |i: usize, axis: usize| {
            _mm256_insertf128_ps(
                _mm256_castps128_ps256(_mm_load_ps(a.v[i][axis].as_ptr())),
                _mm_load_ps(b.v[i][axis].as_ptr()),
                1,
            )
        };
        let (ox, oy, oz) = (
            _mm256_set1_ps(r.origin[0]),
            _mm256_set1_ps(r.origin[1]),
            _mm256_set1_ps(r.origin[2]),
        );
        let (sx, sy, sz) = (
            _mm256_set1_ps(r.shear[0]),
            _mm256_set1_ps(r.shear[1]),
            _mm256_set1_ps(r.shear[2]),
        );
        let sheared = |i: usize| {
            let p = _mm256_sub_ps(load(i, kx), ox);
            let q = _mm256_sub_ps(load(i, ky), oy);
            let c = _mm256_sub_ps(load(i, kz), oz);
            (
                _mm256_add_ps(p, _mm256_mul_ps(sx, c)),
                _mm256_add_ps(q, _mm256_mul_ps(sy, c)),
                c,
            )
        };
        let (x0, y0, z0) = sheared(0);
        let (x1, y1, z1) = sheared(1);
        let (x2, y2, z2) = sheared(2);
        let e0 = _mm256_sub_ps(_mm256_mul_ps(x1, y2), _mm256_mul_ps(y1, x2));
        let e1 = _mm256_sub_ps(_mm256_mul_ps(x2, y0), _mm256_mul_ps(y2, x0));
        let e2 = _mm256_sub_ps(_mm256_mul_ps(x0, y1), _mm256_mul_ps(y0, x1));
        let zero = _mm256_setzero_ps();
        let cmp3 = |f: fn(__m256, __m256) -> __m256| {
            _mm256_or_ps(_mm256_or_ps(f(e0, zero), f(e1, zero)), f(e2, zero))
        };
        let any_zero = cmp3(|a, b| _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b));
        let any_neg = cmp3(|a, b| _mm256_cmp_ps::<_CMP_LT_OQ>(a, b));
        let any_pos = cmp3(|a, b| _mm256_cmp_ps::<_CMP_GT_OQ>(a, b));
        let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
        let t_scaled = _mm256_add_ps(
            _mm256_add_ps(
                _mm256_mul_ps(e0, _mm256_mul_ps(sz, z0)),
                _mm256_mul_ps(e1, _mm256_mul_ps(sz, z1)),
            ),
            _mm256_mul_ps(e2, _mm256_mul_ps(sz, z2)),
        );
        let bound = _mm256_mul_ps(_mm256_set1_ps(t_max), det);
        let reject = _mm256_or_ps(
            _mm256_or_ps(
                _mm256_and_ps(any_neg, any_pos),
                _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_EQ_OQ>(det, zero),
                    _mm256_cmp_ps::<_CMP_UNORD_Q>(det, det),
                ),
            ),
            _mm256_or_ps(
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(det, zero),
                    _mm256_or_ps(
                        _mm256_cmp_ps::<_CMP_GE_OQ>(t_scaled, zero),
                        _mm256_cmp_ps::<_CMP_LT_OQ>(t_scaled, bound),
                    ),
                ),
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GT_OQ>(det, zero),
                    _mm256_or_ps(
                        _mm256_cmp_ps::<_CMP_LE_OQ>(t_scaled, zero),
                        _mm256_cmp_ps::<_CMP_GT_OQ>(t_scaled, bound),
                    ),
                ),
            ),
        );
        let mask =
            (!_mm256_movemask_ps(reject) as u32 & 0xff) | _mm256_movemask_ps(any_zero) as u32;
        let mut out = Candidates {
            mask,
            t: [0.0; 2 * LANES],
        };
        if mask != 0 {
            let mut ts = [0f32; 2 * LANES];
            let mut d = [0f32; 2 * LANES];
            _mm256_storeu_ps(ts.as_mut_ptr(), t_scaled);
            _mm256_storeu_ps(d.as_mut_ptr(), det);
            let zero_mask = _mm256_movemask_ps(any_zero) as u32;
            out.fill_t(mask, zero_mask, &ts, &d, 0);
        }
        out
    }
}

/// One block on the AVX2 path: the SSE2 kernel (VEX-encoded in this context).
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn candidates_avx2(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    candidates_sse2(block, r, t_max)
}
