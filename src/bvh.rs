//! A bounding volume hierarchy over a scene's triangles: binned SAH, built in parallel
//! ([`build`]), stored as flat 32-byte nodes in depth-first order, traversed iteratively with a
//! fixed stack.
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
//! - A box is skipped only when the ray reaches it beyond [`cull_bound`] of the best hit so
//!   far: a triangle's computed `t` may fall a little short of the box around it, so the bound
//!   is widened by [`CULL_SLACK`].
//! - A triangle is tested with `t_max` shrunk to the best hit so far, widened by a few ULPs
//!   ([`shrunk_t_max`]), so a hit that ties the best one is still reported and the tie is
//!   broken by index.

mod build;

use glam::Vec3;

use crate::accel::Hit;
use crate::geometry::{Ray, Triangle, gamma, intersect_watertight, next_float_up};

pub use build::{LEAF_MAX, SAH_BINS};

/// Most levels a hierarchy has (root = level 1); [`build`] keeps to it by switching from SAH to
/// median splits deep down, so traversal can use a fixed stack.
pub const MAX_DEPTH: usize = 64;

/// A box is culled only if the ray enters it beyond the best hit's `t` times `1 + CULL_SLACK`.
///
/// The true hit point lies inside the triangle's box, but the watertight test's `t` carries
/// rounding error, largest for rays grazing the triangle's plane: about `u·size/θ` relative for a
/// ray at angle θ to it (u = 2⁻²⁴). 2⁻¹⁰ covers angles down to about 6e-5 rad, and costs almost
/// nothing: a box entered beyond the best hit but within a thousandth of its distance is rare.
pub const CULL_SLACK: f32 = 1.0 / 1024.0;

/// The `t` beyond which a box can hold no hit that beats `best` (or, with no hit yet, `t_max`).
#[inline]
pub fn cull_bound(bound: f32) -> f32 {
    bound * (1.0 + CULL_SLACK)
}

/// The `t_max` a triangle is tested with once a hit at `best` is known: four ULPs above it (the
/// test's own `t_max` comparisons round `t·det` and `1/det`, at most three ULPs between them), so
/// that a hit tying `best` is still reported; never above the query's `t_max`.
#[inline]
pub fn shrunk_t_max(best: f32, t_max: f32) -> f32 {
    let up = next_float_up(next_float_up(next_float_up(next_float_up(best))));
    if up < t_max { up } else { t_max }
}

/// The far side of a slab is widened by this factor (pbrt-v4's 1 + 2γ₃), so that rounding in
/// the two slab distances never culls a box the ray grazes.
#[inline]
fn far_widen() -> f32 {
    1.0 + 2.0 * gamma(3)
}

/// One node: a box, and either two children (adjacent: a [`NodePair`]) or a run of triangles.
/// 32 bytes.
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

/// Two sibling nodes, aligned to share one 64-byte cache line: traversal tests both.
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

    /// Robust slab test: where the ray enters the box, if it meets it for some `t` in
    /// `[0, t_max]`. A NaN slab distance (the origin on a slab plane of a ray parallel to it)
    /// constrains nothing, so such a box is kept.
    #[inline(always)]
    fn enter(&self, origin: Vec3, inv_dir: Vec3, t_max: f32) -> Option<f32> {
        let widen = far_widen();
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for i in 0..3 {
            let a = (self.min[i] - origin[i]) * inv_dir[i];
            let b = (self.max[i] - origin[i]) * inv_dir[i];
            let (near, far) = if a > b { (b, a) } else { (a, b) };
            let far = far * widen;
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        (t0 <= t1).then_some(t0)
    }
}

/// A bounding volume hierarchy over a list of triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Sibling pairs in depth-first order; the root alone in the first. Node `i` is
    /// `nodes[i / 2].0[i % 2]`.
    nodes: Vec<NodePair>,
    /// Vertices in leaf order.
    vertices: Vec<[Vec3; 3]>,
    /// Scene index of each entry of `vertices`.
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
        let vertices = built
            .order
            .iter()
            .map(|&i| triangles[i as usize].v)
            .collect();
        Bvh {
            nodes: built.pairs,
            vertices,
            ids: built.order,
            depth: built.depth,
        }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        (2 * self.nodes.len()).saturating_sub(1)
    }

    #[inline(always)]
    fn node(&self, i: usize) -> &Node {
        &self.nodes[i >> 1].0[i & 1]
    }

    /// Every node (the root, then the pairs; not the root pair's filler).
    fn all_nodes(&self) -> impl Iterator<Item = &Node> {
        self.nodes
            .iter()
            .flat_map(|p| &p.0)
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
        let Some(NodePair([root, _])) = self.nodes.first() else {
            return 0.0;
        };
        let root_area = area(root);
        if !(root_area > 0.0) {
            return 0.0;
        }
        self.all_nodes()
            .map(|n| {
                let work = if n.is_leaf() { f64::from(n.count) } else { 1.0 };
                work * area(n) / root_area
            })
            .sum()
    }

    /// Number of leaves.
    pub fn leaves(&self) -> usize {
        self.all_nodes().filter(|n| n.is_leaf()).count()
    }

    /// The closest hit with `t < t_max` (ties go to the lowest scene index), or `None`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let root = &self.nodes.first()?.0[0];
        let (o, inv) = (ray.origin, ray.inv_dir);
        let mut bound = cull_bound(t_max);
        root.enter(o, inv, bound)?;
        let mut best: Option<Hit> = None;
        let mut tri_t_max = t_max;
        let mut stack = [(0u32, 0f32); MAX_DEPTH];
        let mut sp = 0;
        let mut i = 0usize;
        loop {
            let node = self.node(i);
            if node.is_leaf() {
                let first = node.offset as usize;
                for k in first..first + node.count as usize {
                    let Some(h) = intersect_watertight(ray, &self.vertices[k], tri_t_max) else {
                        continue;
                    };
                    let id = self.ids[k];
                    if best.is_none_or(|b| h.t < b.t || h.t == b.t && id < b.triangle) {
                        best = Some(Hit {
                            t: h.t,
                            b: h.b,
                            triangle: id,
                        });
                        tri_t_max = shrunk_t_max(h.t, t_max);
                        bound = cull_bound(h.t);
                    }
                }
            } else {
                let a = node.offset as usize;
                let b = a + 1;
                let pair = &self.nodes[a >> 1].0;
                let ta = pair[0].enter(o, inv, bound);
                let tb = pair[1].enter(o, inv, bound);
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
                    return best;
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

    /// Whether some triangle has a hit with `t < t_max` (stops at the first found).
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(NodePair([root, _])) = self.nodes.first() else {
            return false;
        };
        let (o, inv) = (ray.origin, ray.inv_dir);
        let bound = cull_bound(t_max);
        if root.enter(o, inv, bound).is_none() {
            return false;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0;
        let mut i = 0usize;
        loop {
            let node = self.node(i);
            if node.is_leaf() {
                let first = node.offset as usize;
                if self.vertices[first..first + node.count as usize]
                    .iter()
                    .any(|v| intersect_watertight(ray, v, t_max).is_some())
                {
                    return true;
                }
            } else {
                let a = node.offset as usize;
                let b = a + 1;
                let pair = &self.nodes[a >> 1].0;
                let ha = pair[0].enter(o, inv, bound).is_some();
                let hb = pair[1].enter(o, inv, bound).is_some();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrunk_t_max_is_above_best_and_capped() {
        assert!(shrunk_t_max(1.0, f32::INFINITY) > 1.0);
        assert_eq!(shrunk_t_max(1.0, 1.0), 1.0);
        assert!(shrunk_t_max(1.0, 2.0) < 1.0 + 1e-6);
    }

    #[test]
    fn nan_slab_distances_keep_the_box() {
        let node = Node {
            min: Vec3::new(0.0, -1.0, 1.0),
            offset: 0,
            max: Vec3::new(1.0, 1.0, 2.0),
            count: 1,
        };
        // Origin on the x = 0 face, ray along +z: (0 − 0)·∞ is NaN.
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert_eq!(
            node.enter(ray.origin, ray.inv_dir, f32::INFINITY),
            Some(1.0)
        );
        // Beside the box and parallel to its faces: missed.
        let ray = Ray::new(Vec3::new(-0.5, 0.0, 0.0), Vec3::Z);
        assert_eq!(node.enter(ray.origin, ray.inv_dir, f32::INFINITY), None);
        // Beyond t_max: missed.
        let ray = Ray::new(Vec3::new(0.5, 0.0, 0.0), Vec3::Z);
        assert_eq!(node.enter(ray.origin, ray.inv_dir, 0.5), None);
    }
}
