//! A bounding volume hierarchy over a scene's triangles: binned SAH, built in parallel
//! (`bvh/build.rs`) as a binary tree, then collapsed into nodes of up to eight children
//! (`bvh/wide.rs`) whose boxes are slab-tested eight at once, visited nearest entry first with a
//! fixed stack.
//!
//! The triangles' vertices are copied in leaf order, so a leaf's triangles sit next to each
//! other in memory; each keeps its index in the scene, which is what a [`Hit`] reports.
//!
//! # The same answer as testing every triangle
//!
//! [`Bvh::intersect_isa`] returns exactly what a loop over all triangles would: the hit with the
//! smallest `t`, and among hits at the same `t` the one with the lowest scene index, each hit
//! as [`intersect_watertight`](crate::geometry::intersect_watertight) computes it for the query's `t_max`. [`Bvh::occluded_isa`] is true
//! exactly when one triangle has such a hit. Only two things could make a traversal differ:
//!
//! - A box is skipped only when the ray reaches it beyond [`cull_bound`](super::cull_bound) of the best hit so
//!   far: a triangle's computed `t` may fall a little short of the box around it, so the bound
//!   is widened by [`CULL_SLACK`](super::CULL_SLACK).
//! - A triangle is tested with `t_max` shrunk to the best hit so far, widened by a few ULPs
//!   ([`shrunk_t_max`](super::shrunk_t_max)), so a hit that ties the best one is still reported and the tie is
//!   broken by index.
//!
//! The order in which children are visited changes neither.

mod build;
mod node;
mod wide;

use std::mem::MaybeUninit;

use super::Vertices;
use super::hit::{Hit, cull_bound};
#[cfg(target_arch = "x86_64")]
use super::tri4::{Closest, LANES, RayLanes, Tri4, blocks_closest, blocks_occluded};
#[cfg(test)]
use crate::geometry::Triangle;
use crate::geometry::{Ray, RayTile};
use crate::simd::{Isa, Kernel, Path};
use node::{Node, NodePair};
use wide::{LEAF, TreeStats, WIDTH, Wide, leaf_blocks};

pub use build::LEAF_MAX;

/// Most levels the binary tree has (root = level 1); the builder keeps to it by switching from
/// SAH to median splits deep down. The wide tree has no more levels than the binary one, so
/// traversal can use a fixed stack.
pub const MAX_DEPTH: usize = 64;

/// Entries a traversal stack needs: a node pushes at most all its children but one it visits
/// at once, on each of at most [`MAX_DEPTH`] levels.
const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A bounding volume hierarchy over a list of triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Wide nodes in depth-first order (the root first, unless the tree is one leaf).
    nodes: Vec<Wide>,
    /// The root: a node index, or a leaf when the tree is one leaf.
    root: u32,
    /// Each leaf's triangles in [`Tri4`] blocks (the last one padded), leaves in depth-first
    /// order.
    blocks: Vec<Tri4>,
    /// Scene index of each lane of `blocks` (`u32::MAX` for padding).
    ids: Vec<u32>,
    /// Levels of the binary tree.
    depth: u32,
    /// Levels of wide nodes.
    wide_depth: u32,
    /// The binary tree's figures.
    tree: TreeStats,
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (binned SAH, in parallel; the result does not
    /// depend on the number of threads).
    pub fn build(triangles: &(impl Vertices + ?Sized)) -> Bvh {
        Bvh::build_with(triangles, None)
    }

    /// [`Bvh::build`] for a big model, about three times as fast (the 10M-triangle torus of
    /// `examples/big_ply.rs`: 2.2 s instead of 6.3 s on one thread) for frames about 1.5 times
    /// as slow to trace (41 → 60-70 ms at 300×300): binned SAH down to nodes of a million
    /// triangles, a linear BVH (`bvh/build/morton.rs`) below.
    pub fn build_fast(triangles: &(impl Vertices + ?Sized)) -> Bvh {
        Bvh::build_with(triangles, Some(build::MORTON_NODE))
    }

    /// [`Bvh::build`] with Morton subtrees of at most `morton` triangles, or none.
    fn build_with(triangles: &(impl Vertices + ?Sized), morton: Option<usize>) -> Bvh {
        assert!(
            u32::try_from(triangles.count()).is_ok(),
            "a BVH holds at most 2³² − 1 triangles"
        );
        let built = build::build(triangles, morton);
        let tree = TreeStats::of(&built.pairs);
        let c = wide::collapse(&built.pairs, &built.order, triangles);
        Bvh {
            nodes: c.nodes,
            root: c.root,
            blocks: c.blocks,
            ids: c.ids,
            depth: built.depth,
            wide_depth: c.depth,
            tree,
        }
    }

    /// Number of nodes of the binary SAH tree it was built as (traversal reads it collapsed
    /// into [`Bvh::wide_nodes`]).
    pub fn nodes(&self) -> usize {
        self.tree.nodes
    }

    /// Number of levels of the binary SAH tree (0 when empty, 1 for a single leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Number of wide nodes (of up to eight children) traversal reads.
    #[cfg(test)]
    pub fn wide_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Levels of wide nodes above the leaves (0 for a single leaf or none).
    #[cfg(test)]
    pub fn wide_depth(&self) -> u32 {
        self.wide_depth
    }

    /// The binary tree's SAH cost: the expected number of box-pair and triangle tests for a
    /// random ray that meets the root box (each node weighted by its area over the root's).
    /// Lower is better; compare builds of one scene with it.
    #[cfg(test)]
    pub fn sah_cost(&self) -> f64 {
        self.tree.sah_cost
    }

    /// Number of leaves (the same in the binary and the wide tree).
    #[cfg(test)]
    pub fn leaves(&self) -> usize {
        self.tree.leaves
    }

    /// The closest hit with `t < t_max` (ties go to the lowest scene index), or `None`, on
    /// path `isa`, which must be available (the accelerator's path is checked where it is
    /// set).
    #[inline]
    pub(super) fn intersect_isa(&self, isa: Isa, ray: &Ray, t_max: f32) -> Option<Hit> {
        struct Q<'a>(&'a Bvh, &'a Ray, f32);
        impl Kernel for Q<'_> {
            type Output = Option<Hit>;
            #[inline(always)]
            fn run<P: Path>(self) -> Option<Hit> {
                self.0.closest::<P>(self.1, self.2)
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, ray, t_max)) }
    }

    /// Whether some triangle has a hit with `t < t_max` (stops at the first found), on path
    /// `isa`, which must be available.
    #[inline]
    pub(super) fn occluded_isa(&self, isa: Isa, ray: &Ray, t_max: f32) -> bool {
        struct Q<'a>(&'a Bvh, &'a Ray, f32);
        impl Kernel for Q<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<P: Path>(self) -> bool {
                self.0.any::<P>(self.1, self.2)
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, ray, t_max)) }
    }

    /// [`Bvh::intersect_isa`] for each of `tile`'s rays, into `hits` (as many): the path picked
    /// once for them all. `found(triangle)` is called as soon as a ray's hit is known (to
    /// prefetch what shading will read). `isa` must be available.
    pub(super) fn intersect_tile(
        &self,
        isa: Isa,
        tile: &RayTile,
        t_max: f32,
        hits: &mut [Option<Hit>],
        found: impl Fn(u32),
    ) {
        struct Q<'a, F>(&'a Bvh, &'a RayTile, f32, &'a mut [Option<Hit>], F);
        impl<F: Fn(u32)> Kernel for Q<'_, F> {
            type Output = ();
            #[inline(always)]
            fn run<P: Path>(self) {
                let Q(bvh, tile, t_max, hits, found) = self;
                for (i, h) in hits.iter_mut().enumerate() {
                    *h = bvh.closest::<P>(&tile.ray(i), t_max);
                    if let Some(h) = h {
                        found(h.triangle);
                    }
                }
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, tile, t_max, hits, found)) }
    }

    /// [`Bvh::occluded_isa`] for each of `rays`, into `out` (as many): the path picked once
    /// for them all. `isa` must be available.
    pub(super) fn occluded_each(&self, isa: Isa, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        struct Q<'a>(&'a Bvh, &'a [Ray], f32, &'a mut [bool]);
        impl Kernel for Q<'_> {
            type Output = ();
            #[inline(always)]
            fn run<P: Path>(self) {
                let Q(bvh, rays, t_max, out) = self;
                for (o, r) in out.iter_mut().zip(rays) {
                    *o = bvh.any::<P>(r, t_max);
                }
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, rays, t_max, out)) }
    }

    /// A leaf's blocks and their lanes' scene indices.
    #[inline(always)]
    fn leaf(&self, r: u32) -> (&[Tri4], &[u32]) {
        let (first, count) = leaf_blocks(r);
        let end = first + count;
        (
            &self.blocks[first..end],
            &self.ids[first * LANES..end * LANES],
        )
    }

    #[inline(always)]
    fn closest<P: Path>(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        if self.blocks.is_empty() {
            return None;
        }
        let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
        let mut bound = cull_bound(t_max);
        let r = RayLanes::new(ray);
        let mut c = Closest::new(t_max);
        // Nodes still to visit as `entry distance's bits << 32 | reference`, each node's run
        // sorted farthest at the bottom. An entry distance is `+0.0` or positive (the slab test
        // starts at 0 and only raises it), so its bits order as the distances do.
        let mut stack = [MaybeUninit::<u64>::uninit(); STACK];
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF != 0 {
                let (blocks, ids) = self.leaf(cur);
                // The scene indices are read only for a hit, after the kernel: ask for them now.
                prefetch(ids.as_ptr());
                blocks_closest::<P>(blocks, ids, ray, &r, &mut c);
                if let Some(h) = c.best {
                    bound = cull_bound(h.t);
                }
            } else {
                let node = &self.nodes[cur as usize];
                let (mask, t) = node.boxes.enter_lanes::<P::Eight>(&o, &inv, bound);
                let mut mask = mask & node.valid;
                if mask != 0 {
                    let l = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        cur = node.child[l];
                        continue;
                    }
                    // Two or more: push them sorted by entry distance, nearest on top, and
                    // take the nearest.
                    let key = |l: usize| u64::from(t[l].to_bits()) << 32 | u64::from(node.child[l]);
                    let base = sp;
                    stack[sp] = MaybeUninit::new(key(l));
                    sp += 1;
                    while mask != 0 {
                        let entry = key(mask.trailing_zeros() as usize);
                        mask &= mask - 1;
                        let mut i = sp;
                        // SAFETY: entries `base..sp` were written above.
                        while i > base && unsafe { stack[i - 1].assume_init() } < entry {
                            stack[i] = stack[i - 1];
                            i -= 1;
                        }
                        stack[i] = MaybeUninit::new(entry);
                        sp += 1;
                    }
                    sp -= 1;
                    // SAFETY: written above.
                    cur = unsafe { stack[sp].assume_init() } as u32;
                    continue;
                }
            }
            // Pop the next node the ray can still reach before the best hit.
            loop {
                if sp == 0 {
                    return c.best;
                }
                sp -= 1;
                // SAFETY: every entry below `sp` has been written.
                let e = unsafe { stack[sp].assume_init() };
                if f32::from_bits((e >> 32) as u32) <= bound {
                    cur = e as u32;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any<P: Path>(&self, ray: &Ray, t_max: f32) -> bool {
        if self.blocks.is_empty() {
            return false;
        }
        let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
        let r = RayLanes::new(ray);
        let bound = cull_bound(t_max);
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF != 0 {
                if blocks_occluded::<P>(self.leaf(cur).0, ray, &r, t_max) {
                    return true;
                }
            } else {
                let node = &self.nodes[cur as usize];
                let (mask, _) = node.boxes.enter_lanes::<P::Eight>(&o, &inv, bound);
                let mut mask = mask & node.valid;
                if mask != 0 {
                    cur = node.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        stack[sp] = MaybeUninit::new(node.child[mask.trailing_zeros() as usize]);
                        sp += 1;
                        mask &= mask - 1;
                    }
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` has been written.
            cur = unsafe { stack[sp].assume_init() };
        }
    }
}

/// Asks for the cache lines of `x` (at most two: it is at most 64 bytes). A hint: it reads
/// nothing, cannot fault and changes no result.
#[inline(always)]
pub(crate) fn prefetch_value<T>(x: &T) {
    const { assert!(std::mem::size_of::<T>() <= 64) };
    let p = (x as *const T).cast::<u8>();
    prefetch(p);
    prefetch(p.wrapping_add(std::mem::size_of::<T>() - 1));
}

/// Asks for the cache line at `p` (a hint: it reads nothing, cannot fault and changes no
/// result).
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch only hints the cache; it is defined for any address.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(p.cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::shrunk_t_max;
    use crate::scene::procedural::displaced_icosphere;

    fn triangles(mesh: Vec<[Vec3; 3]>) -> Vec<Triangle> {
        mesh.into_iter()
            .map(|v| Triangle::new(v[0], v[1], v[2], 0).unwrap())
            .collect()
    }

    #[test]
    fn the_same_tree_with_any_number_of_threads() {
        // Large enough that the top levels split, bin and bound in parallel.
        let tris = triangles(displaced_icosphere(71, 0.2));
        assert!(tris.len() > 100_000);
        let build = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Bvh::build(&tris[..]))
        };
        let one = build(1);
        assert!(one.depth() as usize <= MAX_DEPTH);
        assert!(one.nodes() > tris.len() / 8);
        for threads in [2, 3, 8] {
            assert!(
                build(threads) == one,
                "{threads} threads built another tree"
            );
        }
    }

    /// A big tree's lower levels (Morton subtrees, forced here at a small size under SAH
    /// levels built in parallel): the same tree on any number of threads, within the depth
    /// bound, and every closest hit and occlusion the brute-force loop's, on every path.
    #[test]
    fn morton_subtrees_are_deterministic_and_exact() {
        let tris = triangles(displaced_icosphere(71, 0.2));
        let build = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Bvh::build_with(&tris[..], Some(20_000)))
        };
        let one = build(1);
        assert!(one.depth() as usize <= MAX_DEPTH);
        assert!(
            one != Bvh::build(&tris[..]),
            "the Morton levels were not built"
        );
        for threads in [2, 3] {
            assert!(
                build(threads) == one,
                "{threads} threads built another tree"
            );
        }
        let mut rng = crate::rng::Rng::seeded(7);
        let mut f = || rng.next_f32() * 2.0 - 1.0;
        for i in 0..300 {
            let origin = Vec3::new(f(), f(), f()) * 3.0;
            // Half the rays aimed at a vertex, where neighbouring triangles tie.
            let target = if i % 2 == 0 {
                tris[(f().abs() * tris.len() as f32) as usize % tris.len()].v[i % 3]
            } else {
                Vec3::new(f(), f(), f()) * 0.5
            };
            let ray = Ray::new(origin, target - origin);
            let t_max = if i % 3 == 0 {
                f().abs() * 4.0
            } else {
                f32::INFINITY
            };
            let mut want: Option<Hit> = None;
            for (k, t) in tris.iter().enumerate() {
                if let Some(h) = crate::geometry::intersect_watertight(&ray, &t.v, t_max)
                    && want.is_none_or(|b| h.t < b.t)
                {
                    want = Some(Hit {
                        t: h.t,
                        b: h.b,
                        triangle: k as u32,
                    });
                }
            }
            for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                assert_eq!(
                    one.intersect_isa(isa, &ray, t_max),
                    want,
                    "ray {i} on {isa:?}"
                );
                assert_eq!(
                    one.occluded_isa(isa, &ray, t_max),
                    want.is_some(),
                    "ray {i}"
                );
            }
        }
    }

    #[test]
    fn leaves_hold_a_few_triangles() {
        let tris = triangles(displaced_icosphere(30, 0.1));
        let bvh = Bvh::build(&tris[..]);
        let per_leaf = tris.len() as f64 / bvh.leaves() as f64;
        assert!(
            (1.0..=LEAF_MAX as f64).contains(&per_leaf),
            "{per_leaf} triangles per leaf"
        );
        // A binary tree: one more leaf than interior nodes.
        assert_eq!(bvh.nodes(), 2 * bvh.leaves() - 1);
        let cost = bvh.sah_cost();
        assert!(cost.is_finite() && cost > 1.0, "SAH cost {cost}");
        // A well-balanced tree over 18000 triangles is a few dozen levels at most.
        assert!(bvh.depth() < 40, "depth {}", bvh.depth());
    }

    /// Random soups from a single leaf up to a few thousand triangles collapse into at most
    /// half as many wide nodes as binary ones, and fewer levels (`tests/accel.rs` holds their
    /// answers to brute force).
    #[test]
    fn wide_nodes_are_fewer_and_shallower() {
        let mut rng = crate::rng::Rng::seeded(40);
        let mut f = |r: f32| (rng.next_f32() * 2.0 - 1.0) * r;
        for n in [1, 2, 9, 17, 40, 64, 100, 300, 1_000, 4_000] {
            let mesh: Vec<[Vec3; 3]> = (0..n)
                .map(|_| {
                    let c = Vec3::new(f(1.0), f(1.0), f(1.0));
                    [0, 1, 2].map(|_| c + Vec3::new(f(0.3), f(0.3), f(0.3)))
                })
                .collect();
            let tris: Vec<Triangle> = mesh
                .into_iter()
                .filter_map(|v| Triangle::new(v[0], v[1], v[2], 0).ok())
                .collect();
            let bvh = Bvh::build(&tris[..]);
            assert!(
                bvh.wide_nodes() <= bvh.nodes() / 2,
                "{n} triangles: {} wide nodes for {} binary",
                bvh.wide_nodes(),
                bvh.nodes()
            );
            assert!(bvh.wide_depth() < bvh.depth().max(1), "{n} triangles");
        }
    }

    #[test]
    fn shrunk_t_max_is_above_best_and_capped() {
        assert!(shrunk_t_max(1.0, f32::INFINITY) > 1.0);
        assert_eq!(shrunk_t_max(1.0, 1.0), 1.0);
        assert!(shrunk_t_max(1.0, 2.0) < 1.0 + 1e-6);
    }
}
