//! Eight boxes at a time: the children of one wide BVH node, slab-tested with AVX2 (one 8-lane
//! step per axis), SSE2 (two 4-lane halves) or the portable twin (one lane at a time). All three
//! run [`Aabb::enter`]'s operations in its order, so they agree with it bit for bit
//! (`tests/simd_kernels.rs`, and the unit test below).

use crate::geometry::{Aabb, gamma};

/// Boxes per [`Box8`].
pub const BOX_LANES: usize = 8;

/// Eight boxes, slab by slab: `min[axis][lane]`, `max[axis][lane]` (three 64-byte cache lines).
/// Unused lanes hold empty boxes (min +∞, max −∞); the slab test does *not* reject those (its
/// swap of near and far turns them into everything), so a user masks them out.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Box8 {
    min: [[f32; BOX_LANES]; 3],
    max: [[f32; BOX_LANES]; 3],
}

impl Default for Box8 {
    fn default() -> Box8 {
        Box8::new(&[])
    }
}

impl Box8 {
    /// Up to eight boxes, in lanes from 0.
    pub fn new(boxes: &[Aabb]) -> Box8 {
        assert!(boxes.len() <= BOX_LANES, "a Box8 holds at most 8 boxes");
        let mut b = Box8 {
            min: [[f32::INFINITY; BOX_LANES]; 3],
            max: [[f32::NEG_INFINITY; BOX_LANES]; 3],
        };
        for (lane, bx) in boxes.iter().enumerate() {
            b.set(lane, bx);
        }
        b
    }

    /// Puts `bx` in `lane`.
    pub fn set(&mut self, lane: usize, bx: &Aabb) {
        for axis in 0..3 {
            self.min[axis][lane] = bx.min[axis];
            self.max[axis][lane] = bx.max[axis];
        }
    }

    /// The box in `lane`.
    pub fn get(&self, lane: usize) -> Aabb {
        Aabb {
            min: [0, 1, 2].map(|a| self.min[a][lane]).into(),
            max: [0, 1, 2].map(|a| self.max[a][lane]).into(),
        }
    }

    /// Where the ray enters each box, if it meets it for some `t` in `[0, t_max]`: a bit per
    /// lane and the entry distances. [`Aabb::enter`]'s robust slab test (the far side widened by
    /// 1 + 2γ₃; a NaN slab distance constrains nothing), one lane at a time.
    #[inline(always)]
    pub fn enter_portable(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        super::box4::enter_lanes(&self.min, &self.max, origin, inv_dir, t_max)
    }

    /// [`Box8::enter_portable`] with SSE2, four lanes at a time: the same operations (SSE's
    /// min/max pick the same operand as the portable comparisons, NaN included: `minps(x, y)`
    /// is `x < y ? x : y`).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn enter_sse2(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        use std::arch::x86_64::*;
        let mut t = [0f32; BOX_LANES];
        let mut mask = 0;
        // SAFETY: SSE2 is part of every x86-64; the loads read four floats inside aligned
        // `[f32; 8]` rows (offsets 0 and 4: 16-byte aligned), the store writes four into `t`.
        unsafe {
            let widen = _mm_set1_ps(1.0 + 2.0 * gamma(3));
            for half in 0..2 {
                let mut t0 = _mm_setzero_ps();
                let mut t1 = _mm_set1_ps(t_max);
                for axis in 0..3 {
                    let o = _mm_set1_ps(origin[axis]);
                    let inv = _mm_set1_ps(inv_dir[axis]);
                    let lo = _mm_load_ps(self.min[axis].as_ptr().add(4 * half));
                    let hi = _mm_load_ps(self.max[axis].as_ptr().add(4 * half));
                    let a = _mm_mul_ps(_mm_sub_ps(lo, o), inv);
                    let b = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
                    // near = a > b ? b : a; far = a > b ? a : b.
                    let near = _mm_min_ps(b, a);
                    let far = _mm_mul_ps(_mm_max_ps(a, b), widen);
                    // t0 = near > t0 ? near : t0; t1 = far < t1 ? far : t1.
                    t0 = _mm_max_ps(near, t0);
                    t1 = _mm_min_ps(far, t1);
                }
                mask |= (_mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u32) << (4 * half);
                _mm_storeu_ps(t.as_mut_ptr().add(4 * half), t0);
            }
        }
        (mask, t)
    }

    /// [`Box8::enter_portable`] with AVX, all eight lanes in one step per axis: the same
    /// operations as the SSE2 form, on 256-bit registers.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 ([`crate::accel::Isa::Avx2`] available).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    pub unsafe fn enter_avx2(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        use std::arch::x86_64::*;
        let mut t = [0f32; BOX_LANES];
        // SAFETY: the caller guarantees AVX2; the loads read whole 32-byte-aligned `[f32; 8]`
        // rows, the store writes all of `t`.
        unsafe {
            let widen = _mm256_set1_ps(1.0 + 2.0 * gamma(3));
            let mut t0 = _mm256_setzero_ps();
            let mut t1 = _mm256_set1_ps(t_max);
            for axis in 0..3 {
                let o = _mm256_set1_ps(origin[axis]);
                let inv = _mm256_set1_ps(inv_dir[axis]);
                let lo = _mm256_load_ps(self.min[axis].as_ptr());
                let hi = _mm256_load_ps(self.max[axis].as_ptr());
                let a = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
                let b = _mm256_mul_ps(_mm256_sub_ps(hi, o), inv);
                let near = _mm256_min_ps(b, a);
                let far = _mm256_mul_ps(_mm256_max_ps(a, b), widen);
                t0 = _mm256_max_ps(near, t0);
                t1 = _mm256_min_ps(far, t1);
            }
            let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32;
            _mm256_storeu_ps(t.as_mut_ptr(), t0);
            (mask, t)
        }
    }

    /// The slab test on path `isa` (for tests and tools; the BVH calls the forms directly).
    /// `isa` must be available.
    pub fn enter(
        &self,
        isa: crate::accel::Isa,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        use crate::accel::Isa;
        assert!(isa.available(), "{} is not available", isa.name());
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: checked available above.
            Isa::Avx2 | Isa::Avx512 => unsafe { self.enter_avx2(origin, inv_dir, t_max) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => self.enter_sse2(origin, inv_dir, t_max),
            _ => self.enter_portable(origin, inv_dir, t_max),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::Isa;
    use crate::geometry::Ray;

    #[test]
    fn every_slab_test_agrees_bit_for_bit() {
        // Random boxes and rays, with axis-parallel rays and origins on slab planes mixed in
        // (the NaN cases), every path against `Aabb::enter`, the one slab test, bit for bit.
        let mut rng = crate::rng::Rng::seeded(5);
        let mut f = |scale: f32| (rng.next_f32() * 2.0 - 1.0) * scale;
        for i in 0..20_000 {
            let boxes: Vec<Aabb> = (0..BOX_LANES)
                .map(|_| {
                    let lo = Vec3::new(f(1.0), f(1.0), f(1.0));
                    let size = Vec3::new(f(1.0).abs(), f(1.0).abs(), f(1.0).abs());
                    Aabb {
                        min: lo,
                        max: lo + size,
                    }
                })
                .collect();
            let b = Box8::new(&boxes);
            let mut origin = Vec3::new(f(2.0), f(2.0), f(2.0));
            let mut dir = Vec3::new(f(1.0), f(1.0), f(1.0));
            if i % 3 == 0 {
                let axis = i % 9 / 3;
                dir[axis] = 0.0;
                origin[axis] = if i % 2 == 0 {
                    boxes[i % 8].min[axis]
                } else {
                    boxes[(i + 3) % 8].max[axis]
                };
            }
            if dir == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(origin, dir);
            let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
            for t_max in [f32::INFINITY, f(3.0).abs()] {
                let want: Vec<Option<u32>> = boxes
                    .iter()
                    .map(|bx| bx.enter(&ray, t_max).map(f32::to_bits))
                    .collect();
                for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                    let (mask, t) = b.enter(isa, &o, &inv, t_max);
                    let got: Vec<Option<u32>> = (0..BOX_LANES)
                        .map(|l| (mask & 1 << l != 0).then_some(t[l].to_bits()))
                        .collect();
                    assert_eq!(got, want, "{isa:?} {ray:?} {t_max} {boxes:?}");
                }
            }
        }
    }

    #[test]
    fn lanes_round_trip() {
        let bx = Aabb {
            min: Vec3::new(-1.0, 0.0, 2.0),
            max: Vec3::new(1.0, 0.5, 3.0),
        };
        let mut b = Box8::default();
        b.set(5, &bx);
        assert_eq!(b.get(5), bx);
        assert_eq!(b.get(0).min, Vec3::INFINITY);
    }
}
