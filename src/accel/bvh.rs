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
mod node;

use rayon::prelude::*;

use super::hit::{Hit, cull_bound};
use super::isa::Isa;
#[cfg(target_arch = "x86_64")]
use super::tri4::{Avx2, Sse2};
use super::tri4::{
    Closest, Kernel, LANES, Portable, RayLanes, Tri4, blocks_closest, blocks_occluded,
};
use crate::geometry::{Ray, Triangle};
use node::{Node, NodePair, Pair};

pub use build::{LEAF_MAX, SAH_BINS};

/// Most levels a hierarchy has (root = level 1); the builder keeps to it by switching from SAH to
/// median splits deep down, so traversal can use a fixed stack.
pub const MAX_DEPTH: usize = 64;

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
    use crate::accel::shrunk_t_max;

    #[test]
    fn shrunk_t_max_is_above_best_and_capped() {
        assert!(shrunk_t_max(1.0, f32::INFINITY) > 1.0);
        assert_eq!(shrunk_t_max(1.0, 1.0), 1.0);
        assert!(shrunk_t_max(1.0, 2.0) < 1.0 + 1e-6);
    }
}
