//! Eight boxes at a time: the children of one wide BVH node, or eight of the flat list's
//! objects, slab-tested eight lanes at a time (AVX2), four (SSE2) or one: [`Aabb::enter`]'s
//! operations, so every path agrees with it bit for bit (the unit test below).

use crate::geometry::{Aabb, enter_boxes};
use crate::simd::Lanes;

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
    #[cfg(test)]
    pub fn get(&self, lane: usize) -> Aabb {
        Aabb {
            min: [0, 1, 2].map(|a| self.min[a][lane]).into(),
            max: [0, 1, 2].map(|a| self.max[a][lane]).into(),
        }
    }

    /// Which boxes the ray meets for some `t` in `[0, t_max]` (bit per lane), and where it
    /// enters each: the slab test ([`Aabb::enter`]'s), `L::N` lanes at a time.
    #[inline(always)]
    pub(crate) fn enter_lanes<L: Lanes>(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        enter_boxes::<L, BOX_LANES>(&self.min, &self.max, origin, inv_dir, t_max)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::geometry::Ray;
    use crate::simd::{Isa, Kernel, Path};

    /// The slab test on path `isa`.
    fn enter(
        b: &Box8,
        isa: Isa,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; BOX_LANES]) {
        struct Enter<'a>(&'a Box8, &'a [f32; 3], &'a [f32; 3], f32);
        impl Kernel for Enter<'_> {
            type Output = (u32, [f32; BOX_LANES]);
            fn run<P: Path>(self) -> Self::Output {
                self.0.enter_lanes::<P::Eight>(self.1, self.2, self.3)
            }
        }
        isa.run(Enter(b, origin, inv_dir, t_max))
    }

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
                    let (mask, t) = enter(&b, isa, &o, &inv, t_max);
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
