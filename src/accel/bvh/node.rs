//! The BVH's nodes: 32 bytes each as built, read by traversal as 64-byte sibling pairs (one
//! cache line) with both boxes laid out slab by slab, so the two children are slab-tested at
//! once with SSE2 (a portable twin elsewhere; both held to `Aabb::enter` bit for bit).

use glam::Vec3;

use crate::geometry::gamma;

/// The far side of a slab is widened by this factor (pbrt-v4's 1 + 2γ₃), so that rounding in
/// the two slab distances never culls a box the ray grazes.
#[inline]
pub(super) fn far_widen() -> f32 {
    1.0 + 2.0 * gamma(3)
}

/// One node as the builder makes it: a box, and either two children (adjacent: a
/// [`NodePair`]) or a run of triangles. 32 bytes; traversal reads them rearranged in [`Pair`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Node {
    pub(crate) min: Vec3,
    /// Leaf: index of its first triangle in leaf order. Interior: index of its first child
    /// (even; the second child follows it in the same pair).
    pub(crate) offset: u32,
    pub(crate) max: Vec3,
    /// Leaf: number of triangles (at least 1). Interior: 0.
    pub(crate) count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

/// Two sibling nodes, as built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct NodePair(pub(crate) [Node; 2]);

impl Node {
    /// Filler for the root's pair (never visited).
    pub(crate) const UNUSED: Node = Node {
        min: Vec3::INFINITY,
        offset: 0,
        max: Vec3::NEG_INFINITY,
        count: 0,
    };

    #[inline]
    pub(super) fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Two sibling nodes as traversal reads them, in one 64-byte cache line: the boxes laid out
/// slab by slab, so that both children's slab distances along an axis come from one 4-wide
/// operation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct Pair {
    /// Per axis: `[min of child 0, min of child 1, max of child 0, max of child 1]`.
    pub(super) slabs: [[f32; 4]; 3],
    /// Each child's [`Node::offset`].
    pub(super) offset: [u32; 2],
    /// Each child's [`Node::count`].
    pub(super) count: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<Pair>() == 64);

impl Pair {
    pub(super) fn new(NodePair(n): NodePair) -> Pair {
        Pair {
            slabs: [0, 1, 2].map(|a| [n[0].min[a], n[1].min[a], n[0].max[a], n[1].max[a]]),
            offset: [n[0].offset, n[1].offset],
            count: [n[0].count, n[1].count],
        }
    }

    /// The node in lane `lane`.
    pub(super) fn node(&self, lane: usize) -> Node {
        let s = &self.slabs;
        Node {
            min: Vec3::new(s[0][lane], s[1][lane], s[2][lane]),
            offset: self.offset[lane],
            max: Vec3::new(s[0][lane + 2], s[1][lane + 2], s[2][lane + 2]),
            count: self.count[lane],
        }
    }

    /// Robust slab test of both boxes: where the ray enters each, if it meets it for some `t`
    /// in `[0, t_max]`. The far distance is widened by 1 + 2γ₃; a NaN slab distance (the
    /// origin on a slab plane of a ray parallel to it) constrains nothing, so such a box is
    /// kept. This is the portable form; x86-64 runs the same operations four lanes at a time.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub(super) fn enter(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> [Option<f32>; 2] {
        self.enter_portable(origin, inv_dir, t_max)
    }

    /// [`Pair::enter`] one box and one slab at a time.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    #[inline(always)]
    pub(super) fn enter_portable(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> [Option<f32>; 2] {
        let widen = far_widen();
        let mut t0 = [0.0f32; 2];
        let mut t1 = [t_max; 2];
        for axis in 0..3 {
            let s = &self.slabs[axis];
            let t: [f32; 4] = std::array::from_fn(|j| (s[j] - origin[axis]) * inv_dir[axis]);
            for c in 0..2 {
                let (a, b) = (t[c], t[c + 2]);
                let (near, far) = if a > b { (b, a) } else { (a, b) };
                let far = far * widen;
                if near > t0[c] {
                    t0[c] = near;
                }
                if far < t1[c] {
                    t1[c] = far;
                }
            }
        }
        [0, 1].map(|c| (t0[c] <= t1[c]).then_some(t0[c]))
    }

    /// The slab test above with SSE2 (part of every x86-64), both boxes' two slabs along an
    /// axis in one register: the same `f32` operations, and SSE's min/max pick the same operand
    /// as the portable form's comparisons, NaN included (`minps(x, y)` is `x < y ? x : y`).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn enter(
        &self,
        origin: &[f32; 3],
        inv_dir: &[f32; 3],
        t_max: f32,
    ) -> [Option<f32>; 2] {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is baseline on x86-64; the loads read `[f32; 4]` arrays in full.
        unsafe {
            let widen = _mm_set1_ps(far_widen());
            let mut t0 = _mm_setzero_ps();
            let mut t1 = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let s = _mm_loadu_ps(self.slabs[axis].as_ptr());
                // Lanes: min 0, min 1, max 0, max 1.
                let t = _mm_mul_ps(
                    _mm_sub_ps(s, _mm_set1_ps(origin[axis])),
                    _mm_set1_ps(inv_dir[axis]),
                );
                let a = t;
                let b = _mm_movehl_ps(t, t);
                // near = a > b ? b : a; far = a > b ? a : b.
                let near = _mm_min_ps(b, a);
                let far = _mm_mul_ps(_mm_max_ps(a, b), widen);
                // t0 = near > t0 ? near : t0; t1 = far < t1 ? far : t1.
                t0 = _mm_max_ps(near, t0);
                t1 = _mm_min_ps(far, t1);
            }
            let hit = _mm_movemask_ps(_mm_cmple_ps(t0, t1));
            let mut t = [0f32; 4];
            _mm_storeu_ps(t.as_mut_ptr(), t0);
            [
                (hit & 1 != 0).then_some(t[0]),
                (hit & 2 != 0).then_some(t[1]),
            ]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Aabb, Ray};

    #[test]
    fn every_slab_test_agrees_bit_for_bit() {
        // Random boxes and rays, with axis-parallel rays and origins on slab planes mixed in
        // (the NaN cases), compared bit for bit.
        let mut rng = crate::rng::Rng::seeded(5);
        let mut f = |scale: f32| (rng.next_f32() * 2.0 - 1.0) * scale;
        for i in 0..20_000 {
            let lo = [0, 1].map(|_| Vec3::new(f(1.0), f(1.0), f(1.0)));
            let hi = lo.map(|l| l + Vec3::new(f(1.0).abs(), f(1.0).abs(), f(1.0).abs()));
            let node = |k: usize| Node {
                min: lo[k],
                offset: 0,
                max: hi[k],
                count: 1,
            };
            let pair = Pair::new(NodePair([node(0), node(1)]));
            let mut origin = Vec3::new(f(2.0), f(2.0), f(2.0));
            let mut dir = Vec3::new(f(1.0), f(1.0), f(1.0));
            if i % 3 == 0 {
                dir[i % 9 / 3] = 0.0;
                origin[i % 9 / 3] = if i % 2 == 0 {
                    lo[0][i % 9 / 3]
                } else {
                    hi[1][i % 9 / 3]
                };
            }
            if dir == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(origin, dir);
            let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
            for t_max in [f32::INFINITY, f(3.0).abs()] {
                let a = pair.enter(&o, &inv, t_max).map(|t| t.map(f32::to_bits));
                let b = pair
                    .enter_portable(&o, &inv, t_max)
                    .map(|t| t.map(f32::to_bits));
                assert_eq!(a, b, "{ray:?} {t_max} {pair:?}");
                // Both are held to the one slab test, `Aabb::enter`.
                let c = [0, 1].map(|k| {
                    Aabb {
                        min: lo[k],
                        max: hi[k],
                    }
                    .enter(&ray, t_max)
                    .map(f32::to_bits)
                });
                assert_eq!(a, c, "{ray:?} {t_max} {pair:?}");
            }
        }
    }

    #[test]
    fn nan_slab_distances_keep_the_box() {
        let node = Node {
            min: Vec3::new(0.0, -1.0, 1.0),
            offset: 0,
            max: Vec3::new(1.0, 1.0, 2.0),
            count: 1,
        };
        // Both lanes hold the box: they must agree.
        let pair = Pair::new(NodePair([node; 2]));
        assert_eq!(pair.node(1), node);
        let node = |o: Vec3, inv: Vec3, t_max| {
            let [a, b] = pair.enter(&o.to_array(), &inv.to_array(), t_max);
            assert_eq!(a, b);
            a
        };
        // Origin on the x = 0 face, ray along +z: (0 − 0)·∞ is NaN.
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert_eq!(node(ray.origin, ray.inv_dir, f32::INFINITY), Some(1.0));
        // Beside the box and parallel to its faces: missed.
        let ray = Ray::new(Vec3::new(-0.5, 0.0, 0.0), Vec3::Z);
        assert_eq!(node(ray.origin, ray.inv_dir, f32::INFINITY), None);
        // Beyond t_max: missed.
        let ray = Ray::new(Vec3::new(0.5, 0.0, 0.0), Vec3::Z);
        assert_eq!(node(ray.origin, ray.inv_dir, 0.5), None);
    }
}
