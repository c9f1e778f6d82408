//! The hierarchy as traversal reads it: the binary SAH tree collapsed into nodes of up to eight
//! children, their boxes in one [`Box8`] (slab by slab, tested eight at once), 256 bytes a
//! node (four cache lines), in depth-first order; each leaf's triangles as consecutive
//! [`Tri4`] blocks, leaves in depth-first order too.

use super::node::{Node, NodePair};
use crate::accel::Vertices;
use crate::accel::box8::{BOX_LANES, Box8};
use crate::accel::tri4::{LANES, Tri4};
use crate::geometry::Aabb;

/// Children per node at most. (Four was measured too: see the issue notes.)
pub const WIDTH: usize = BOX_LANES;

/// A child reference with this bit set is a leaf: its first block is the reference's bits
/// 3..30 and its block count one more than bits 0..2. Without it, a node index.
pub(super) const LEAF: u32 = 1 << 31;

/// Most blocks a leaf reference can name: bits 0..2.
const LEAF_BLOCKS_MAX: usize = 8;

const _: () = assert!(super::LEAF_MAX.div_ceil(LANES) <= LEAF_BLOCKS_MAX);

/// One node: its children's boxes and references.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct Wide {
    /// Lane `i`: child `i`'s box.
    pub boxes: Box8,
    /// Lane `i`: child `i` (a node index, or a leaf with [`LEAF`] set).
    pub child: [u32; WIDTH],
    /// Bit `i` set: lane `i` holds a child.
    pub valid: u32,
}

const _: () = assert!(std::mem::size_of::<Wide>() == 256);

/// A leaf reference's blocks: `(first, count)`.
#[inline(always)]
pub(super) fn leaf_blocks(r: u32) -> (usize, usize) {
    (((r & !LEAF) >> 3) as usize, (r & 7) as usize + 1)
}

/// The wide hierarchy and its leaves.
pub(super) struct Collapsed {
    pub nodes: Vec<Wide>,
    /// The root: a node index, or a leaf reference when the whole tree is one leaf.
    pub root: u32,
    pub blocks: Vec<Tri4>,
    pub ids: Vec<u32>,
    /// Levels of wide nodes above the leaves (0 for a single leaf).
    pub depth: u32,
}

/// Collapses the binary tree `pairs` (the root alone in the first pair; node `i` is lane
/// `i % 2` of pair `i / 2`) whose leaves index `order`, packing each leaf's triangles into
/// blocks. A node takes its two children, then keeps replacing its interior child of largest
/// surface area (the first such on a tie) by that child's two children, up to [`WIDTH`]; the
/// children keep the binary tree's left-to-right order. Deterministic: it depends only on the
/// binary tree. (Laying out the top levels' subtrees in parallel and joining them was tried:
/// copying the joined blocks cost what the second thread saved.)
pub(super) fn collapse<V: Vertices + ?Sized>(
    pairs: &[NodePair],
    order: &[u32],
    triangles: &V,
) -> Collapsed {
    let n_blocks: usize = pairs
        .iter()
        .flat_map(|p| p.0.iter().map(|n| (n.count as usize).div_ceil(LANES)))
        .sum();
    let mut c = Collapsed {
        nodes: Vec::with_capacity(pairs.len() / 3 + 1),
        root: 0,
        blocks: Vec::with_capacity(n_blocks),
        ids: Vec::with_capacity(n_blocks * LANES),
        depth: 0,
    };
    if !pairs.is_empty() {
        let t = Tree {
            pairs,
            order,
            triangles,
        };
        c.root = t.visit(0, &mut c, 0);
    }
    c
}

/// The binary tree being collapsed.
struct Tree<'a, V: ?Sized> {
    pairs: &'a [NodePair],
    order: &'a [u32],
    triangles: &'a V,
}

fn area(n: &Node) -> f64 {
    let d = (n.max - n.min).as_dvec3();
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

impl<V: Vertices + ?Sized> Tree<'_, V> {
    fn node(&self, i: usize) -> Node {
        self.pairs[i / 2].0[i % 2]
    }

    /// The binary nodes that become interior node `n`'s children, in order.
    fn open(&self, n: &Node) -> ([usize; WIDTH], usize) {
        let mut kids = [0usize; WIDTH];
        kids[..2].copy_from_slice(&[n.offset as usize, n.offset as usize + 1]);
        let mut len = 2;
        while len < WIDTH {
            let mut widest: Option<(usize, f64)> = None;
            for (k, &kid) in kids[..len].iter().enumerate() {
                let kn = self.node(kid);
                if !kn.is_leaf() && widest.is_none_or(|(_, a)| area(&kn) > a) {
                    widest = Some((k, area(&kn)));
                }
            }
            let Some((k, _)) = widest else { break };
            let first = self.node(kids[k]).offset as usize;
            kids.copy_within(k + 1..len, k + 2);
            kids[k] = first;
            kids[k + 1] = first + 1;
            len += 1;
        }
        (kids, len)
    }

    /// A new node over children `kids` (their references to be filled in).
    fn wide(&self, kids: &[usize]) -> Wide {
        let mut w = Wide {
            boxes: Box8::default(),
            child: [0; WIDTH],
            valid: (1 << kids.len()) - 1,
        };
        for (lane, &kid) in kids.iter().enumerate() {
            let kn = self.node(kid);
            w.boxes.set(
                lane,
                &Aabb {
                    min: kn.min,
                    max: kn.max,
                },
            );
        }
        w
    }

    /// Lays out binary node `i`'s subtree at wide level `level` at the end of `c`; returns
    /// its reference.
    fn visit(&self, i: usize, c: &mut Collapsed, level: u32) -> u32 {
        let n = self.node(i);
        if n.is_leaf() {
            let first = c.blocks.len();
            let leaf = &self.order[n.offset as usize..(n.offset + n.count) as usize];
            for chunk in leaf.chunks(LANES) {
                let mut v = [[glam::Vec3::ZERO; 3]; LANES];
                for (v, &t) in v.iter_mut().zip(chunk) {
                    *v = self.triangles.vertices(t as usize);
                }
                c.blocks.push(Tri4::new(&v[..chunk.len()]));
            }
            c.ids.extend_from_slice(leaf);
            c.ids.resize(c.blocks.len() * LANES, u32::MAX);
            let count = c.blocks.len() - first;
            assert!(
                first < 1 << 28 && count <= LEAF_BLOCKS_MAX,
                "a BVH holds at most 2²⁸ blocks of four triangles"
            );
            return LEAF | (first as u32) << 3 | (count as u32 - 1);
        }
        c.depth = c.depth.max(level + 1);
        let (kids, len) = self.open(&n);
        let at = c.nodes.len();
        c.nodes.push(self.wide(&kids[..len]));
        for (lane, &kid) in kids[..len].iter().enumerate() {
            let r = self.visit(kid, c, level + 1);
            c.nodes[at].child[lane] = r;
        }
        at as u32
    }
}

/// The binary tree's figures, kept for [`super::Bvh::nodes`] and friends.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct TreeStats {
    pub nodes: usize,
    pub leaves: usize,
    pub sah_cost: f64,
}

impl TreeStats {
    /// The figures of the binary tree `pairs`.
    pub fn of(pairs: &[NodePair]) -> TreeStats {
        // Every node: the root, then the pairs (not the root pair's filler).
        let all = || {
            pairs
                .iter()
                .flat_map(|p| p.0)
                .enumerate()
                .filter(|&(i, _)| i != 1)
                .map(|(_, n)| n)
        };
        let Some(root) = pairs.first().map(|p| p.0[0]) else {
            return TreeStats::default();
        };
        let root_area = area(&root);
        let sah_cost = if root_area > 0.0 {
            all()
                .map(|n| {
                    let work = if n.is_leaf() { f64::from(n.count) } else { 1.0 };
                    work * area(&n) / root_area
                })
                .sum()
        } else {
            0.0
        };
        TreeStats {
            nodes: all().count(),
            leaves: all().filter(|n| n.is_leaf()).count(),
            sah_cost,
        }
    }
}
