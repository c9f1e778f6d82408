//! Four boxes at a time: the flat list's object boxes, slab-tested with SSE2 (or the portable
//! twin, one lane at a time, which `tests/simd_kernels.rs` holds it to bit for bit).

use crate::geometry::{Aabb, gamma};

/// Four boxes, slab by slab: `min[axis][lane]`, `max[axis][lane]`. Unused lanes are empty
/// boxes (min +∞, max −∞); the slab test does not reject those (its near/far swap makes them
/// everything), so callers mask them out (`Flat::lanes`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct Box4 {
    min: [[f32; 4]; 3],
    max: [[f32; 4]; 3],
}

/// The portable slab test of `N` boxes held slab by slab (`min[axis][lane]`), one lane at a
/// time: which the ray meets for some `t` in `[0, t_max]` (bit per lane) and where it enters
/// each, [`Aabb::enter`]'s operations in its order (the far side widened by 1 + 2γ₃; a NaN
/// slab distance constrains nothing). [`Box4`] and `Box8` share it.
#[inline(always)]
pub(crate) fn enter_lanes<const N: usize>(
    min: &[[f32; N]; 3],
    max: &[[f32; N]; 3],
    origin: &[f32; 3],
    inv_dir: &[f32; 3],
    t_max: f32,
) -> (u32, [f32; N]) {
    let widen = 1.0 + 2.0 * gamma(3);
    let mut t0 = [0.0f32; N];
    let mut t1 = [t_max; N];
    for axis in 0..3 {
        for l in 0..N {
            let a = (min[axis][l] - origin[axis]) * inv_dir[axis];
            let b = (max[axis][l] - origin[axis]) * inv_dir[axis];
            let (near, far) = if a > b { (b, a) } else { (a, b) };
            let far = far * widen;
            if near > t0[l] {
                t0[l] = near;
            }
            if far < t1[l] {
                t1[l] = far;
            }
        }
    }
    let mut mask = 0;
    for l in 0..N {
        if t0[l] <= t1[l] {
            mask |= 1 << l;
        }
    }
    (mask, t0)
}

impl Box4 {
    /// Up to four boxes.
    pub fn new(boxes: &[Aabb]) -> Box4 {
        assert!(boxes.len() <= 4);
        let mut b = Box4 {
            min: [[f32::INFINITY; 4]; 3],
            max: [[f32::NEG_INFINITY; 4]; 3],
        };
        for (lane, bx) in boxes.iter().enumerate() {
            for axis in 0..3 {
                b.min[axis][lane] = bx.min[axis];
                b.max[axis][lane] = bx.max[axis];
            }
        }
        b
    }

    /// Which boxes the ray meets for some `t` in `[0, t_max]` (bit per lane), and where it
    /// enters each: [`Aabb::hit`]'s robust slab test (the far side widened by 1 + 2γ₃; a NaN
    /// slab distance constrains nothing), one lane at a time.
    #[inline(always)]
    pub fn enter_portable(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; 4]) {
        enter_lanes(&self.min, &self.max, origin, inv_dir, t_max)
    }

    /// [`Box4::enter_portable`] with SSE2: the same operations four lanes at a time (SSE's
    /// min/max pick the same operand as the portable comparisons, NaN included).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn enter_sse2(&self, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of every x86-64; the loads read whole aligned `[f32; 4]`s.
        unsafe {
            let widen = _mm_set1_ps(1.0 + 2.0 * gamma(3));
            let mut t0 = _mm_setzero_ps();
            let mut t1 = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let o = _mm_set1_ps(origin[axis]);
                let inv = _mm_set1_ps(inv_dir[axis]);
                let a = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(self.min[axis].as_ptr()), o), inv);
                let b = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(self.max[axis].as_ptr()), o), inv);
                let near = _mm_min_ps(b, a);
                let far = _mm_mul_ps(_mm_max_ps(a, b), widen);
                t0 = _mm_max_ps(near, t0);
                t1 = _mm_min_ps(far, t1);
            }
            let mask = _mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u32;
            let mut t = [0f32; 4];
            _mm_storeu_ps(t.as_mut_ptr(), t0);
            (mask, t)
        }
    }
}
