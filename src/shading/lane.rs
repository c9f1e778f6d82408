//! The lanes the shading kernel computes in: one trait, [`Lanes`], with a width-1 form
//! ([`Scalar`], plain `f32`) and an eight-lane form ([`Avx2`]). The kernel is written once
//! against the trait, so one ray at a time and eight at a time run the same operations in the
//! same order (no fused multiply-add; `min` and `max` pick the operands SSE's do), and give
//! the same bits.
//!
//! A value of [`Avx2`] is a token: it exists only where the CPU has AVX2 ([`Avx2::of`]), so
//! its operations are safe to call. Every operation is `#[inline(always)]`: the kernel is
//! inlined into an entry compiled for the path's target features (AVX2, or AVX-512 for its
//! 32 registers and mask compares), and so are the intrinsics.

use crate::geometry::{next_float_down, next_float_up};

/// `[e(0), e(1), e(2)]` for an expression `e` of `k`, written out: the kernel uses no closure
/// around lane operations, because a closure is a function of its own, compiled without the
/// target features of the entry its kernel is inlined into, and its operations would not
/// inline (the frame took four times as long).
macro_rules! each3 {
    (|$k:ident| $e:expr) => {
        [
            {
                let $k = 0;
                $e
            },
            {
                let $k = 1;
                $e
            },
            {
                let $k = 2;
                $e
            },
        ]
    };
}
pub(crate) use each3;

/// `f32` lanes of one width and their operations (`Self` is the path's token).
pub(crate) trait Lanes: Copy {
    /// Lanes per value.
    const WIDTH: usize;
    /// `WIDTH` `f32`s.
    type F: Copy;
    /// `WIDTH` booleans.
    type M: Copy;

    /// Every lane `v`.
    fn splat(self, v: f32) -> Self::F;
    /// `a[at..at + WIDTH]` (`at` is 0 on eight lanes).
    fn load_at(self, a: &[f32; 8], at: usize) -> Self::F;
    /// `a[0..WIDTH]`.
    #[inline(always)]
    fn load(self, a: &[f32; 8]) -> Self::F {
        self.load_at(a, 0)
    }
    /// Lane `l` is `f(l)`.
    fn gather(self, f: impl FnMut(usize) -> f32) -> Self::F;
    /// `v` into `a[at..at + WIDTH]` (`at` is 0 on eight lanes).
    fn store_at(self, a: &mut [f32; 8], at: usize, v: Self::F);
    /// `v` into `a[0..WIDTH]`.
    #[inline(always)]
    fn store(self, a: &mut [f32; 8], v: Self::F) {
        self.store_at(a, 0, v)
    }
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    fn sqrt(self, a: Self::F) -> Self::F;
    /// `a < b ? a : b` (SSE's `min`, glam's).
    fn min(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a > b ? a : b` (SSE's `max`, glam's).
    fn max(self, a: Self::F, b: Self::F) -> Self::F;
    /// `|a|` (the sign bit cleared).
    fn abs(self, a: Self::F) -> Self::F;
    /// `-a` in the lanes of `m`, `a` elsewhere (the sign bit flipped).
    fn neg_where(self, m: Self::M, a: Self::F) -> Self::F;
    /// `a > b` (false if either is NaN).
    fn gt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a < b` (false if either is NaN).
    fn lt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a != b` (true if either is NaN).
    fn ne(self, a: Self::F, b: Self::F) -> Self::M;
    fn and(self, a: Self::M, b: Self::M) -> Self::M;
    fn or(self, a: Self::M, b: Self::M) -> Self::M;
    /// `m ? a : b` lane by lane.
    fn select(self, m: Self::M, a: Self::F, b: Self::F) -> Self::F;
    /// A bit per lane (bit `l`: lane `l`).
    fn bits(self, m: Self::M) -> u32;
    /// The lanes of `bits` (bit `l`: lane `l`) as a mask.
    fn lanes(self, bits: u32) -> Self::M;
    /// `v` one float further along the sign of `off`: [`next_float_up`] where `off > 0`,
    /// [`next_float_down`] where `off < 0`, `v` elsewhere.
    fn step_along(self, v: Self::F, off: Self::F) -> Self::F;
    /// The AVX2 token, on AVX2's lanes (for kernels that have an AVX2-only step).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        None
    }
}

/// One lane: plain `f32`, any target.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scalar;

impl Lanes for Scalar {
    const WIDTH: usize = 1;
    type F = f32;
    type M = bool;

    #[inline(always)]
    fn splat(self, v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn load_at(self, a: &[f32; 8], at: usize) -> f32 {
        a[at]
    }
    #[inline(always)]
    fn gather(self, mut f: impl FnMut(usize) -> f32) -> f32 {
        f(0)
    }
    #[inline(always)]
    fn store_at(self, a: &mut [f32; 8], at: usize, v: f32) {
        a[at] = v;
    }
    #[inline(always)]
    fn add(self, a: f32, b: f32) -> f32 {
        a + b
    }
    #[inline(always)]
    fn sub(self, a: f32, b: f32) -> f32 {
        a - b
    }
    #[inline(always)]
    fn mul(self, a: f32, b: f32) -> f32 {
        a * b
    }
    #[inline(always)]
    fn div(self, a: f32, b: f32) -> f32 {
        a / b
    }
    #[inline(always)]
    fn sqrt(self, a: f32) -> f32 {
        a.sqrt()
    }
    #[inline(always)]
    fn min(self, a: f32, b: f32) -> f32 {
        if a < b { a } else { b }
    }
    #[inline(always)]
    fn max(self, a: f32, b: f32) -> f32 {
        if a > b { a } else { b }
    }
    #[inline(always)]
    fn abs(self, a: f32) -> f32 {
        a.abs()
    }
    #[inline(always)]
    fn neg_where(self, m: bool, a: f32) -> f32 {
        if m { -a } else { a }
    }
    #[inline(always)]
    fn gt(self, a: f32, b: f32) -> bool {
        a > b
    }
    #[inline(always)]
    fn lt(self, a: f32, b: f32) -> bool {
        a < b
    }
    #[inline(always)]
    fn ne(self, a: f32, b: f32) -> bool {
        a != b
    }
    #[inline(always)]
    fn and(self, a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    fn or(self, a: bool, b: bool) -> bool {
        a | b
    }
    #[inline(always)]
    fn select(self, m: bool, a: f32, b: f32) -> f32 {
        if m { a } else { b }
    }
    #[inline(always)]
    fn bits(self, m: bool) -> u32 {
        m as u32
    }
    #[inline(always)]
    fn lanes(self, bits: u32) -> bool {
        bits & 1 != 0
    }
    #[inline(always)]
    fn step_along(self, v: f32, off: f32) -> f32 {
        if off > 0.0 {
            next_float_up(v)
        } else if off < 0.0 {
            next_float_down(v)
        } else {
            v
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::Avx2;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::Lanes;
    use crate::simd::Isa;

    /// Eight lanes with AVX2 (a token: only made where the CPU has it: [`Avx2::of`]).
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx2(());

    impl Avx2 {
        /// The token, for a path with AVX2 (AVX2's and AVX-512's) that this CPU runs.
        pub(crate) fn of(isa: Isa) -> Option<Avx2> {
            (matches!(isa, Isa::Avx2 | Isa::Avx512) && isa.available()).then_some(Avx2(()))
        }
    }

    // SAFETY (every `unsafe` block below): an `Avx2` exists only where the CPU has AVX2, and
    // the loads and stores read or write an `[f32; 8]`.
    impl Lanes for Avx2 {
        const WIDTH: usize = 8;
        type F = __m256;
        type M = __m256;

        #[inline(always)]
        fn splat(self, v: f32) -> __m256 {
            unsafe { _mm256_set1_ps(v) }
        }
        #[inline(always)]
        fn load_at(self, a: &[f32; 8], at: usize) -> __m256 {
            debug_assert_eq!(at, 0);
            unsafe { _mm256_loadu_ps(a.as_ptr()) }
        }
        #[inline(always)]
        fn gather(self, mut f: impl FnMut(usize) -> f32) -> __m256 {
            let mut a = [0.0; 8];
            for (l, a) in a.iter_mut().enumerate() {
                *a = f(l);
            }
            self.load(&a)
        }
        #[inline(always)]
        fn store_at(self, a: &mut [f32; 8], at: usize, v: __m256) {
            debug_assert_eq!(at, 0);
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) }
        }
        #[inline(always)]
        fn add(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_add_ps(a, b) }
        }
        #[inline(always)]
        fn sub(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_sub_ps(a, b) }
        }
        #[inline(always)]
        fn mul(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_mul_ps(a, b) }
        }
        #[inline(always)]
        fn div(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_div_ps(a, b) }
        }
        #[inline(always)]
        fn sqrt(self, a: __m256) -> __m256 {
            unsafe { _mm256_sqrt_ps(a) }
        }
        #[inline(always)]
        fn min(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_min_ps(a, b) }
        }
        #[inline(always)]
        fn max(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_max_ps(a, b) }
        }
        #[inline(always)]
        fn abs(self, a: __m256) -> __m256 {
            unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a) }
        }
        #[inline(always)]
        fn neg_where(self, m: __m256, a: __m256) -> __m256 {
            unsafe { _mm256_xor_ps(a, _mm256_and_ps(m, _mm256_set1_ps(-0.0))) }
        }
        #[inline(always)]
        fn gt(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(a, b) }
        }
        #[inline(always)]
        fn lt(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(a, b) }
        }
        #[inline(always)]
        fn ne(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_cmp_ps::<_CMP_NEQ_UQ>(a, b) }
        }
        #[inline(always)]
        fn and(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_and_ps(a, b) }
        }
        #[inline(always)]
        fn or(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_or_ps(a, b) }
        }
        #[inline(always)]
        fn select(self, m: __m256, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_blendv_ps(b, a, m) }
        }
        #[inline(always)]
        fn bits(self, m: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(m) as u32 }
        }
        #[inline(always)]
        fn lanes(self, bits: u32) -> __m256 {
            unsafe {
                let each = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let on = _mm256_and_si256(_mm256_set1_epi32(bits as i32), each);
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(on, each))
            }
        }
        #[inline(always)]
        fn avx2(self) -> Option<Avx2> {
            Some(self)
        }
        #[inline(always)]
        fn step_along(self, v: __m256, off: __m256) -> __m256 {
            // `next_float_up` and `next_float_down` as one step on the bits: a zero takes
            // `off`'s sign (+0 up, −0 down), then the bits move one away from zero where its
            // sign is `off`'s, one toward it elsewhere. A step that leaves the floats (from
            // the infinity it moves toward, or from NaN) gives NaN or starts from it: those
            // lanes keep `v`, as do the lanes where `off` is zero or NaN. (11 instructions;
            // the two steps computed apart and blended took 29.)
            unsafe {
                let zero = _mm256_setzero_ps();
                let z = _mm256_blendv_ps(
                    v,
                    _mm256_and_ps(off, _mm256_set1_ps(-0.0)),
                    _mm256_cmp_ps::<_CMP_EQ_OQ>(v, zero),
                );
                let away = _mm256_srai_epi32::<31>(_mm256_castps_si256(_mm256_xor_ps(z, off)));
                let step = _mm256_or_si256(away, _mm256_set1_epi32(1));
                let r = _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(z), step));
                let moves = _mm256_andnot_ps(
                    _mm256_cmp_ps::<_CMP_UNORD_Q>(r, v),
                    _mm256_cmp_ps::<_CMP_NEQ_OQ>(off, zero),
                );
                _mm256_blendv_ps(v, r, moves)
            }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::simd::Isa;

    /// [`Avx2::step_along`] is [`Scalar`]'s, bit for bit: at zeros, the extremes, infinities,
    /// NaN and random floats of every magnitude, for offsets of either sign, zero and NaN.
    #[test]
    fn avx2_step_along_is_the_scalar_step() {
        let Some(s) = Avx2::of(Isa::Avx2) else {
            return;
        };
        let mut values = vec![
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            f32::from_bits(0x8000_0001),
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1.0,
            -1.0,
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..4000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(f32::from_bits(x as u32));
        }
        let offsets = [
            1e-3,
            -1e-3,
            0.0,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for chunk in values.chunks(8) {
            for k in 0..offsets.len() {
                let mut v = [0.0; 8];
                let mut o = [0.0; 8];
                for l in 0..8 {
                    v[l] = chunk[l % chunk.len()];
                    // Offsets of each kind in each lane.
                    o[l] = offsets[(k + l) % offsets.len()];
                }
                let mut out = [0.0; 8];
                s.store(&mut out, s.step_along(s.load(&v), s.load(&o)));
                for l in 0..8 {
                    let want = Scalar.step_along(v[l], o[l]);
                    assert_eq!(
                        out[l].to_bits(),
                        want.to_bits(),
                        "{:e} along {:e}: {:e}, not {:e}",
                        v[l],
                        o[l],
                        out[l],
                        want
                    );
                }
            }
        }
    }
}
