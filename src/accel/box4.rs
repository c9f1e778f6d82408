//! Four boxes at a time: the flat list's object boxes, slab by slab for the slab test
//! ([`crate::geometry::Aabb::enter`]'s operations, four lanes or one at a time).

use crate::geometry::{Aabb, enter_boxes};
use crate::simd::Lanes;

/// Four boxes, slab by slab: `min[axis][lane]`, `max[axis][lane]`. Unused lanes are empty
/// boxes (min +∞, max −∞); the slab test does not reject those (its near/far swap makes them
/// everything), so callers mask them out (`Flat::lanes`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct Box4 {
    min: [[f32; 4]; 3],
    max: [[f32; 4]; 3],
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
    /// enters each: the slab test, `L::N` lanes at a time.
    #[inline(always)]
    pub(crate) fn enter<L: Lanes>(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> (u32, [f32; 4]) {
        enter_boxes::<L, 4>(&self.min, &self.max, origin, inv_dir, t_max)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::geometry::Ray;
    use crate::simd::{Isa, Kernel, Path};

    /// [`Box4::enter`] on path `isa`.
    fn enter(isa: Isa, b: &Box4, o: &[f32; 3], inv: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        struct Enter<'a>(&'a Box4, &'a [f32; 3], &'a [f32; 3], f32);
        impl Kernel for Enter<'_> {
            type Output = (u32, [f32; 4]);
            fn run<P: Path>(self) -> Self::Output {
                self.0.enter::<P::Four>(self.1, self.2, self.3)
            }
        }
        isa.run(Enter(b, o, inv, t_max))
    }

    /// Random boxes and rays, with axis-parallel rays and origins on slab planes mixed in (the
    /// NaN cases): every path against `Aabb::enter`, hit and entry `t` bit for bit.
    #[test]
    fn every_path_is_the_slab_test() {
        let mut rng = crate::rng::Rng::seeded(5);
        let mut f = |scale: f32| (rng.next_f32() * 2.0 - 1.0) * scale;
        for i in 0..20_000 {
            let boxes: Vec<Aabb> = (0..4)
                .map(|_| {
                    let lo = Vec3::new(f(1.0), f(1.0), f(1.0));
                    let size = Vec3::new(f(1.0), f(1.0), f(1.0)).abs();
                    Aabb {
                        min: lo,
                        max: lo + size,
                    }
                })
                .collect();
            let b = Box4::new(&boxes);
            let mut origin = Vec3::new(f(2.0), f(2.0), f(2.0));
            let mut dir = Vec3::new(f(1.0), f(1.0), f(1.0));
            if i % 3 == 0 {
                let axis = i % 9 / 3;
                dir[axis] = 0.0;
                origin[axis] = if i % 2 == 0 {
                    boxes[0].min[axis]
                } else {
                    boxes[1].max[axis]
                };
            }
            if dir == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(origin, dir);
            let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
            for t_max in [f32::INFINITY, f(3.0).abs()] {
                let want: Vec<_> = boxes
                    .iter()
                    .map(|bx| bx.enter(&ray, t_max).map(f32::to_bits))
                    .collect();
                for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                    let (mask, t) = enter(isa, &b, &o, &inv, t_max);
                    let got: Vec<_> = (0..4)
                        .map(|l| (mask & 1 << l != 0).then_some(t[l].to_bits()))
                        .collect();
                    assert_eq!(got, want, "{isa:?} {ray:?} {t_max} {boxes:?}");
                }
            }
        }
    }
}
