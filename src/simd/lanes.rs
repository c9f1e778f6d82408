//! The lane type the kernels are written in: [`Lanes`], `N` `f32`s side by side, with the
//! operations the kernels need. One kernel source, generic over it, is every path's kernel:
//! `f32` itself is the one-lane form (the portable path, and the scalar tests), [`F4`] SSE2's
//! four lanes, [`F8`] AVX's eight and [`F16`] AVX-512's sixteen.
//!
//! Every operation is one IEEE operation per lane (no fused multiply-add on any path), so each
//! lane of a kernel gets the bits the one-lane form gets. The comparisons are ordered (false on
//! NaN) like Rust's `<`, `>`, `==`; `min` and `max` are SSE's (`if a < b { a } else { b }`, the
//! second operand on NaN), and the one-lane form is written the same way.
//!
//! The wide types only exist inside functions compiled for their instruction set
//! ([`super::Path`]'s dispatch), where their `inline(always)` operations become the caller's
//! own instructions.

/// `N` lanes of `f32` and the operations the kernels use.
pub(crate) trait Lanes: Copy {
    /// A mask of lanes: a `bool` at one lane, a vector of all-ones lanes on SSE and AVX, a
    /// bit per lane on AVX-512.
    type Mask: Copy;
    /// The number of lanes.
    const N: usize;

    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// Lanes `0..N` from `a` (at least `N` long).
    fn load(a: &[f32]) -> Self;
    /// Lanes `at..at + N` of the consecutive groups of four `four(0)`, `four(1)`, ...: lane
    /// `at % 4` of `four(0)` for one lane, else `N / 4` whole groups (`at` a multiple of `N`).
    fn load_fours<'a>(four: impl Fn(usize) -> &'a [f32; 4], at: usize) -> Self;
    /// Writes lanes `0..N` into `a` (at least `N` long).
    fn store(self, a: &mut [f32]);
    /// [`Lanes::store`] as one whole store, also where the value is a blend of `a`'s own lanes
    /// (see [`F8`]'s).
    #[inline(always)]
    fn store_whole(self, a: &mut [f32]) {
        self.store(a)
    }

    /// `a + b`.
    fn add(self, b: Self) -> Self;
    /// `a − b`.
    fn sub(self, b: Self) -> Self;
    /// `a · b`.
    fn mul(self, b: Self) -> Self;
    /// `a / b`.
    fn div(self, b: Self) -> Self;
    /// `|a|` (the sign bit cleared).
    fn abs(self) -> Self;
    /// `−a` (the sign bit flipped).
    fn neg(self) -> Self;
    /// `√a`.
    fn sqrt(self) -> Self;
    /// `if a < b { a } else { b }`.
    fn min(self, b: Self) -> Self;
    /// `if a > b { a } else { b }`.
    fn max(self, b: Self) -> Self;

    /// `a == b`.
    fn eq(self, b: Self) -> Self::Mask;
    /// `a < b`.
    fn lt(self, b: Self) -> Self::Mask;
    /// `a <= b`.
    fn le(self, b: Self) -> Self::Mask;
    /// `a > b`.
    fn gt(self, b: Self) -> Self::Mask;
    /// `a >= b`.
    fn ge(self, b: Self) -> Self::Mask;
    /// `a` or `b` is NaN.
    fn unord(self, b: Self) -> Self::Mask;

    /// Lanes in both.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Lanes in either.
    fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Lanes in `b` and not in `a`.
    fn andnot(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// No lane.
    fn none() -> Self::Mask;
    /// A bit per lane (bit `i`: lane `i`).
    fn bits(m: Self::Mask) -> u32;
    /// `b` where `m` is set, else `a`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
}

/// One lane: plain `f32`, the operations written as the wide ones behave.
impl Lanes for f32 {
    type Mask = bool;
    const N: usize = 1;

    #[inline(always)]
    fn splat(x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn load(a: &[f32]) -> f32 {
        a[0]
    }
    #[inline(always)]
    fn load_fours<'a>(four: impl Fn(usize) -> &'a [f32; 4], at: usize) -> f32 {
        four(0)[at % 4]
    }
    #[inline(always)]
    fn store(self, a: &mut [f32]) {
        a[0] = self;
    }
    #[inline(always)]
    fn add(self, b: f32) -> f32 {
        self + b
    }
    #[inline(always)]
    fn sub(self, b: f32) -> f32 {
        self - b
    }
    #[inline(always)]
    fn mul(self, b: f32) -> f32 {
        self * b
    }
    #[inline(always)]
    fn div(self, b: f32) -> f32 {
        self / b
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn neg(self) -> f32 {
        -self
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn min(self, b: f32) -> f32 {
        if self < b { self } else { b }
    }
    #[inline(always)]
    fn max(self, b: f32) -> f32 {
        if self > b { self } else { b }
    }
    #[inline(always)]
    fn eq(self, b: f32) -> bool {
        self == b
    }
    #[inline(always)]
    fn lt(self, b: f32) -> bool {
        self < b
    }
    #[inline(always)]
    fn le(self, b: f32) -> bool {
        self <= b
    }
    #[inline(always)]
    fn gt(self, b: f32) -> bool {
        self > b
    }
    #[inline(always)]
    fn ge(self, b: f32) -> bool {
        self >= b
    }
    #[inline(always)]
    fn unord(self, b: f32) -> bool {
        self.is_nan() || b.is_nan()
    }
    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    fn or(a: bool, b: bool) -> bool {
        a | b
    }
    #[inline(always)]
    fn andnot(a: bool, b: bool) -> bool {
        !a & b
    }
    #[inline(always)]
    fn none() -> bool {
        false
    }
    #[inline(always)]
    fn bits(m: bool) -> u32 {
        m as u32
    }
    #[inline(always)]
    fn select(m: bool, a: f32, b: f32) -> f32 {
        if m { b } else { a }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{F4, F8, F16};

/// The wide lanes. SAFETY (of every `unsafe` in this module): the intrinsics take and return
/// registers, and loads and stores read or write `N` `f32`s of slices checked to hold them.
/// SSE2 is part of every x86-64; an `F8` or `F16` is only ever made inside a function
/// compiled for AVX2 or AVX-512 ([`super::Path`]), which is only called where the CPU has it,
/// and there these `inline(always)` operations become that function's own instructions.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::undocumented_unsafe_blocks)]
mod x86 {
    use std::arch::x86_64::*;

    use super::Lanes;

    /// Four lanes of SSE2.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F4(__m128);

    /// Eight lanes of AVX.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F8(__m256);

    /// Sixteen lanes of AVX-512 (masks are a bit per lane).
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F16(__m512);

    impl Lanes for F4 {
        type Mask = F4;
        const N: usize = 4;

        #[inline(always)]
        fn splat(x: f32) -> F4 {
            F4(unsafe { _mm_set1_ps(x) })
        }
        #[inline(always)]
        fn load(a: &[f32]) -> F4 {
            F4(unsafe { _mm_loadu_ps(a[..F4::N].as_ptr()) })
        }
        #[inline(always)]
        fn load_fours<'a>(four: impl Fn(usize) -> &'a [f32; 4], _: usize) -> F4 {
            F4(unsafe { _mm_loadu_ps(four(0).as_ptr()) })
        }
        #[inline(always)]
        fn store(self, a: &mut [f32]) {
            unsafe { _mm_storeu_ps(a[..F4::N].as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, b: F4) -> F4 {
            F4(unsafe { _mm_add_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn sub(self, b: F4) -> F4 {
            F4(unsafe { _mm_sub_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn mul(self, b: F4) -> F4 {
            F4(unsafe { _mm_mul_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn div(self, b: F4) -> F4 {
            F4(unsafe { _mm_div_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn abs(self) -> F4 {
            F4(unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn neg(self) -> F4 {
            F4(unsafe { _mm_xor_ps(_mm_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn sqrt(self) -> F4 {
            F4(unsafe { _mm_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn min(self, b: F4) -> F4 {
            F4(unsafe { _mm_min_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn max(self, b: F4) -> F4 {
            F4(unsafe { _mm_max_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn eq(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmpeq_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn lt(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmplt_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn le(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmple_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn gt(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmpgt_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn ge(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmpge_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn unord(self, b: F4) -> F4 {
            F4(unsafe { _mm_cmpunord_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn and(a: F4, b: F4) -> F4 {
            F4(unsafe { _mm_and_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn or(a: F4, b: F4) -> F4 {
            F4(unsafe { _mm_or_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn andnot(a: F4, b: F4) -> F4 {
            F4(unsafe { _mm_andnot_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn none() -> F4 {
            F4(unsafe { _mm_setzero_ps() })
        }
        #[inline(always)]
        fn bits(m: F4) -> u32 {
            unsafe { _mm_movemask_ps(m.0) as u32 }
        }
        #[inline(always)]
        fn select(m: F4, a: F4, b: F4) -> F4 {
            F4(unsafe { _mm_or_ps(_mm_and_ps(m.0, b.0), _mm_andnot_ps(m.0, a.0)) })
        }
    }

    impl Lanes for F8 {
        type Mask = F8;
        const N: usize = 8;

        #[inline(always)]
        fn splat(x: f32) -> F8 {
            F8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn load(a: &[f32]) -> F8 {
            F8(unsafe { _mm256_loadu_ps(a[..F8::N].as_ptr()) })
        }
        #[inline(always)]
        fn load_fours<'a>(four: impl Fn(usize) -> &'a [f32; 4], _: usize) -> F8 {
            F8(unsafe {
                let lo = _mm256_castps128_ps256(_mm_loadu_ps(four(0).as_ptr()));
                _mm256_insertf128_ps::<1>(lo, _mm_loadu_ps(four(1).as_ptr()))
            })
        }
        #[inline(always)]
        fn store(self, a: &mut [f32]) {
            unsafe { _mm256_storeu_ps(a[..F8::N].as_mut_ptr(), self.0) }
        }
        /// From LLVM 21 on, storing `select(m, load(a), v)` back to `a` is compiled to a
        /// masked store (`vmaskmovps`), which AMD's Zen CPUs run as microcode and which a
        /// later load of the same lanes cannot take its data from. The fold into the nearest
        /// hit does exactly that, per triangle. The address passed through an empty `asm`
        /// block (no instruction) is one the compiler cannot match with the load's, so the
        /// blend stays a blend and the store one whole `vmovups`. On a Zen 3 EPYC (one
        /// thread, `perf record` over 30 renders of the 500×500 seed frame) the frame's own
        /// code took 17 % fewer samples; `raytty bench`'s seed row, 2 threads, medians of 5
        /// interleaved rounds: 6.10 → 4.94 ms. Same frames.
        // The block reads and writes no memory: it only hides where the pointer came from.
        #[allow(clippy::pointers_in_nomem_asm_block)]
        #[inline(always)]
        fn store_whole(self, a: &mut [f32]) {
            let mut to = a[..F8::N].as_mut_ptr();
            unsafe {
                std::arch::asm!(
                    "/* {0} */",
                    inout(reg) to,
                    options(pure, nomem, nostack, preserves_flags)
                );
                _mm256_storeu_ps(to, self.0)
            }
        }
        #[inline(always)]
        fn add(self, b: F8) -> F8 {
            F8(unsafe { _mm256_add_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn sub(self, b: F8) -> F8 {
            F8(unsafe { _mm256_sub_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn mul(self, b: F8) -> F8 {
            F8(unsafe { _mm256_mul_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn div(self, b: F8) -> F8 {
            F8(unsafe { _mm256_div_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn abs(self) -> F8 {
            F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn neg(self) -> F8 {
            F8(unsafe { _mm256_xor_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn sqrt(self) -> F8 {
            F8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn min(self, b: F8) -> F8 {
            F8(unsafe { _mm256_min_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn max(self, b: F8) -> F8 {
            F8(unsafe { _mm256_max_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn eq(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, b.0) })
        }
        #[inline(always)]
        fn lt(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, b.0) })
        }
        #[inline(always)]
        fn le(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, b.0) })
        }
        #[inline(always)]
        fn gt(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, b.0) })
        }
        #[inline(always)]
        fn ge(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, b.0) })
        }
        #[inline(always)]
        fn unord(self, b: F8) -> F8 {
            F8(unsafe { _mm256_cmp_ps::<_CMP_UNORD_Q>(self.0, b.0) })
        }
        #[inline(always)]
        fn and(a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_and_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn or(a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_or_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn andnot(a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_andnot_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn none() -> F8 {
            F8(unsafe { _mm256_setzero_ps() })
        }
        #[inline(always)]
        fn bits(m: F8) -> u32 {
            unsafe { _mm256_movemask_ps(m.0) as u32 }
        }
        #[inline(always)]
        fn select(m: F8, a: F8, b: F8) -> F8 {
            F8(unsafe { _mm256_blendv_ps(a.0, b.0, m.0) })
        }
    }

    impl Lanes for F16 {
        type Mask = __mmask16;
        const N: usize = 16;

        #[inline(always)]
        fn splat(x: f32) -> F16 {
            F16(unsafe { _mm512_set1_ps(x) })
        }
        #[inline(always)]
        fn load(a: &[f32]) -> F16 {
            F16(unsafe { _mm512_loadu_ps(a[..F16::N].as_ptr()) })
        }
        #[inline(always)]
        fn load_fours<'a>(four: impl Fn(usize) -> &'a [f32; 4], _: usize) -> F16 {
            F16(unsafe {
                let lo = F8::load_fours(&four, 0).0;
                let hi = F8::load_fours(|k| four(k + 2), 0).0;
                _mm512_insertf32x8::<1>(_mm512_castps256_ps512(lo), hi)
            })
        }
        #[inline(always)]
        fn store(self, a: &mut [f32]) {
            unsafe { _mm512_storeu_ps(a[..F16::N].as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, b: F16) -> F16 {
            F16(unsafe { _mm512_add_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn sub(self, b: F16) -> F16 {
            F16(unsafe { _mm512_sub_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn mul(self, b: F16) -> F16 {
            F16(unsafe { _mm512_mul_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn div(self, b: F16) -> F16 {
            F16(unsafe { _mm512_div_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn abs(self) -> F16 {
            F16(unsafe { _mm512_andnot_ps(_mm512_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn neg(self) -> F16 {
            F16(unsafe { _mm512_xor_ps(_mm512_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn sqrt(self) -> F16 {
            F16(unsafe { _mm512_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn min(self, b: F16) -> F16 {
            F16(unsafe { _mm512_min_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn max(self, b: F16) -> F16 {
            F16(unsafe { _mm512_max_ps(self.0, b.0) })
        }
        #[inline(always)]
        fn eq(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, b.0) }
        }
        #[inline(always)]
        fn lt(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, b.0) }
        }
        #[inline(always)]
        fn le(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, b.0) }
        }
        #[inline(always)]
        fn gt(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, b.0) }
        }
        #[inline(always)]
        fn ge(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_GE_OQ>(self.0, b.0) }
        }
        #[inline(always)]
        fn unord(self, b: F16) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(self.0, b.0) }
        }
        #[inline(always)]
        fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & b
        }
        #[inline(always)]
        fn or(a: __mmask16, b: __mmask16) -> __mmask16 {
            a | b
        }
        #[inline(always)]
        fn andnot(a: __mmask16, b: __mmask16) -> __mmask16 {
            !a & b
        }
        #[inline(always)]
        fn none() -> __mmask16 {
            0
        }
        #[inline(always)]
        fn bits(m: __mmask16) -> u32 {
            m as u32
        }
        #[inline(always)]
        fn select(m: __mmask16, a: F16, b: F16) -> F16 {
            F16(unsafe { _mm512_mask_blend_ps(m, a.0, b.0) })
        }
    }
}
