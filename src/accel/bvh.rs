//! A bounding volume hierarchy over a scene's triangles: binned SAH, built in parallel
//! (`bvh/build.rs`), stored as 32-byte nodes in sibling pairs (one 64-byte cache line, boxes laid out
//! slab by slab so both children are tested at once) in depth-first order, traversed
//! iteratively with a fixed stack.
//!
//! The triangles' vertices are copied in leaf order, so a leaf's triangles sit next to each
//! other in memory; each keeps its index in the scene, which is what a [`Hit`] reports.
//!
//! # The same answer as testing every triangle
//!
//! [`Bvh::intersect`] returns exactly what a loop over all triangles would: the hit with the
//! smallest `t`, and among hits at the same `t` the one with the lowest scene index, each hit
//! as [`intersect_watertight`] computes it for the query's `t_max`. [`Bvh::occluded`] is true
//! exactly when one triangle has such a hit. Only two things could make a traversal differ:
//!
//! - A box is skipped only when the ray reaches it beyond [`cull_bound`](super::cull_bound) of the best hit so
//!   far: a triangle's computed `t` may fall a little short of the box around it, so the bound
//!   is widened by [`CULL_SLACK`](super::CULL_SLACK).
//! - A triangle is tested with `t_max` shrunk to the best hit so far, widened by a few ULPs
//!   ([`shrunk_t_max`](super::shrunk_t_max)), so a hit that ties the best one is still reported and the tie is
//!   broken by index.

mod build;

use glam::Vec3;
use rayon::prelude::*;

use super::hit::{Hit, cull_bound};
use super::isa::Isa;
#[cfg(target_arch = "x86_64")]
use super::tri4::{Avx2, Sse2};
use super::tri4::{
    Closest, Kernel, LANES, Portable, RayLanes, Tri4, blocks_closest, blocks_occluded,
};
use crate::geometry::{Ray, Triangle, gamma};

pub use build::{LEAF_MAX, SAH_BINS};

/// Most levels a hierarchy has (root = level 1); the builder keeps to it by switching from SAH to
/// median splits deep down, so traversal can use a fixed stack.
pub const MAX_DEPTH: usize = 64;

/// The far side of a slab is widened by this factor (pbrt-v4's 1 + 2γ₃), so that rounding in
/// the two slab distances never culls a box the ray grazes.
#[inline]
fn far_widen() -> f32 {
    1.0 + 2.0 * gamma(3)
}

/// One node as the builder makes it: a box, and either two children (adjacent: a
/// [`NodePair`]) or a run of triangles. 32 bytes; traversal reads them rearranged in [`Pair`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Node {
    min: Vec3,
    /// Leaf: index of its first triangle in leaf order. Interior: index of its first child
    /// (even; the second child follows it in the same pair).
    offset: u32,
    max: Vec3,
    /// Leaf: number of triangles (at least 1). Interior: 0.
    count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

/// Two sibling nodes, as built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct NodePair(pub(crate) [Node; 2]);

impl Node {
    /// Filler for the root's pair (never visited).
    const UNUSED: Node = Node {
        min: Vec3::INFINITY,
        offset: 0,
        max: Vec3::NEG_INFINITY,
        count: 0,
    };

    #[inline]
    fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Two sibling nodes as traversal reads them, in one 64-byte cache line: the boxes laid out
/// slab by slab, so that both children's slab distances along an axis come from one 4-wide
/// operation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Pair {
    /// Per axis: `[min of child 0, min of child 1, max of child 0, max of child 1]`.
    slabs: [[f32; 4]; 3],
    /// Each child's [`Node::offset`].
    offset: [u32; 2],
    /// Each child's [`Node::count`].
    count: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<Pair>() == 64);

impl Pair {
    fn new(NodePair(n): NodePair) -> Pair {
        Pair {
            slabs: [0, 1, 2].map(|a| [n[0].min[a], n[1].min[a], n[0].max[a], n[1].max[a]]),
            offset: [n[0].offset, n[1].offset],
            count: [n[0].count, n[1].count],
        }
    }

    /// The node in lane `lane`.
    fn node(&self, lane: usize) -> Node {
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
    fn enter(&self, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> [Option<f32>; 2] {
        self.enter_portable(origin, inv_dir, t_max)
    }

    /// [`Pair::enter`] one box and one slab at a time.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    #[inline(always)]
    fn enter_portable(
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
    fn enter(&self, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> [Option<f32>; 2] {
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

/// A bounding volume hierarchy over a list of triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Sibling pairs in depth-first order; the root alone in the first. Node `i` is lane
    /// `i % 2` of pair `i / 2`.
    nodes: Vec<Pair>,
    /// Each leaf's triangles in [`Tri4`] blocks (the last one padded), leaves in depth-first
    /// order; a leaf's [`Node::offset`] is its first block.
    blocks: Vec<Tri4>,
    /// Scene index of each lane of `blocks` (`u32::MAX` for padding).
    ids: Vec<u32>,
    depth: u32,
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (binned SAH, in parallel; the result does not
    /// depend on the number of threads).
    pub fn build(triangles: &[Triangle]) -> Bvh {
        assert!(
            u32::try_from(triangles.len()).is_ok(),
            "a BVH holds at most 2³² − 1 triangles"
        );
        let built = build::build(triangles);
        let mut nodes: Vec<Pair> = built.pairs.into_par_iter().map(Pair::new).collect();
        let leaves = |p: &Pair| (0..2).filter(|&l| p.count[l] > 0).count();
        let n_blocks: usize = nodes
            .iter()
            .flat_map(|p| (0..2).map(|l| (p.count[l] as usize).div_ceil(LANES)))
            .sum();
        let mut blocks = Vec::with_capacity(n_blocks);
        let mut ids = Vec::with_capacity(n_blocks * LANES);
        for p in nodes.iter_mut().filter(|p| leaves(p) > 0) {
            for lane in 0..2 {
                let (offset, count) = (p.offset[lane] as usize, p.count[lane] as usize);
                if count == 0 {
                    continue;
                }
                let leaf = &built.order[offset..offset + count];
                p.offset[lane] = u32::try_from(blocks.len()).expect("fewer than 2³² blocks");
                blocks.extend(Tri4::pack(leaf.iter().map(|&i| triangles[i as usize].v)));
                ids.extend_from_slice(leaf);
                ids.resize(blocks.len() * LANES, u32::MAX);
            }
        }
        Bvh {
            nodes,
            blocks,
            ids,
            depth: built.depth,
        }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        (2 * self.nodes.len()).saturating_sub(1)
    }

    /// Every node (the root, then the pairs; not the root pair's filler).
    fn all_nodes(&self) -> impl Iterator<Item = Node> {
        self.nodes
            .iter()
            .flat_map(|p| [p.node(0), p.node(1)])
            .enumerate()
            .filter(|&(i, _)| i != 1)
            .map(|(_, n)| n)
    }

    /// Number of levels (0 when empty, 1 for a single leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The tree's SAH cost: the expected number of box-pair and triangle tests for a random
    /// ray that meets the root box (each node weighted by its area over the root's). Lower is
    /// better; compare builds of one scene with it.
    pub fn sah_cost(&self) -> f64 {
        let area = |n: &Node| {
            let d = (n.max - n.min).as_dvec3();
            2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
        };
        let Some(root) = self.nodes.first().map(|p| p.node(0)) else {
            return 0.0;
        };
        let root_area = area(&root);
        if !(root_area > 0.0) {
            return 0.0;
        }
        self.all_nodes()
            .map(|n| {
                let work = if n.is_leaf() { f64::from(n.count) } else { 1.0 };
                work * area(&n) / root_area
            })
            .sum()
    }

    /// Number of leaves.
    pub fn leaves(&self) -> usize {
        self.all_nodes().filter(|n| n.is_leaf()).count()
    }

    /// The closest hit with `t < t_max` (ties go to the lowest scene index), or `None`, on
    /// the widest SIMD path this CPU has.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.intersect_on(Isa::detect(), ray, t_max)
    }

    /// Whether some triangle has a hit with `t < t_max` (stops at the first found), on the
    /// widest SIMD path this CPU has.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.occluded_on(Isa::detect(), ray, t_max)
    }

    /// [`Bvh::intersect`] on path `isa`, which must be available.
    pub fn intersect_on(&self, isa: Isa, ray: &Ray, t_max: f32) -> Option<Hit> {
        assert!(isa.available(), "{} is not available", isa.name());
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: checked available above.
            Isa::Avx2 => unsafe { closest_avx2(self, ray, t_max) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => self.closest::<Sse2>(ray, t_max),
            _ => self.closest::<Portable>(ray, t_max),
        }
    }

    /// [`Bvh::occluded`] on path `isa`, which must be available.
    pub fn occluded_on(&self, isa: Isa, ray: &Ray, t_max: f32) -> bool {
        assert!(isa.available(), "{} is not available", isa.name());
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: checked available above.
            Isa::Avx2 => unsafe { occluded_avx2(self, ray, t_max) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => self.any::<Sse2>(ray, t_max),
            _ => self.any::<Portable>(ray, t_max),
        }
    }

    /// A leaf's blocks and their lanes' scene indices.
    #[inline(always)]
    fn leaf(&self, offset: usize, count: usize) -> (&[Tri4], &[u32]) {
        let end = offset + count.div_ceil(LANES);
        (
            &self.blocks[offset..end],
            &self.ids[offset * LANES..end * LANES],
        )
    }

    #[inline(always)]
    fn closest<K: Kernel>(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let root = self.nodes.first()?;
        let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
        let mut bound = cull_bound(t_max);
        root.enter(&o, &inv, bound)[0]?;
        let r = RayLanes::new(ray);
        let mut c = Closest::new(t_max);
        let mut stack = [(0u32, 0f32); MAX_DEPTH];
        let mut sp = 0;
        let mut i = 0usize;
        loop {
            let (pair, lane) = (&self.nodes[i >> 1], i & 1);
            let (offset, count) = (pair.offset[lane] as usize, pair.count[lane] as usize);
            if count > 0 {
                let (blocks, ids) = self.leaf(offset, count);
                blocks_closest::<K>(blocks, ids, ray, &r, &mut c);
                if let Some(h) = c.best {
                    bound = cull_bound(h.t);
                }
            } else {
                let (a, b) = (offset, offset + 1);
                let [ta, tb] = self.nodes[a >> 1].enter(&o, &inv, bound);
                match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        // Nearer child first; the other waits with its entry distance.
                        let (near, far, t_far) = if tb < ta { (b, a, ta) } else { (a, b, tb) };
                        stack[sp] = (far as u32, t_far);
                        sp += 1;
                        i = near;
                        continue;
                    }
                    (Some(_), None) => {
                        i = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        i = b;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next node the ray can still reach before the best hit.
            loop {
                if sp == 0 {
                    return c.best;
                }
                sp -= 1;
                let (n, t_enter) = stack[sp];
                if t_enter <= bound {
                    i = n as usize;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any<K: Kernel>(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(root) = self.nodes.first() else {
            return false;
        };
        let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
        let r = RayLanes::new(ray);
        let bound = cull_bound(t_max);
        if root.enter(&o, &inv, bound)[0].is_none() {
            return false;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0;
        let mut i = 0usize;
        loop {
            let (pair, lane) = (&self.nodes[i >> 1], i & 1);
            let (offset, count) = (pair.offset[lane] as usize, pair.count[lane] as usize);
            if count > 0 {
                if blocks_occluded::<K>(self.leaf(offset, count).0, ray, &r, t_max) {
                    return true;
                }
            } else {
                let (a, b) = (offset, offset + 1);
                let [ta, tb] = self.nodes[a >> 1].enter(&o, &inv, bound);
                let (ha, hb) = (ta.is_some(), tb.is_some());
                if ha {
                    if hb {
                        stack[sp] = b as u32;
                        sp += 1;
                    }
                    i = a;
                    continue;
                }
                if hb {
                    i = b;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            i = stack[sp] as usize;
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn closest_avx2(bvh: &Bvh, ray: &Ray, t_max: f32) -> Option<Hit> {
    bvh.closest::<Avx2>(ray, t_max)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn occluded_avx2(bvh: &Bvh, ray: &Ray, t_max: f32) -> bool {
    bvh.any::<Avx2>(ray, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::shrunk_t_max;
    use crate::geometry::Aabb;

    #[test]
    fn shrunk_t_max_is_above_best_and_capped() {
        assert!(shrunk_t_max(1.0, f32::INFINITY) > 1.0);
        assert_eq!(shrunk_t_max(1.0, 1.0), 1.0);
        assert!(shrunk_t_max(1.0, 2.0) < 1.0 + 1e-6);
    }

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
