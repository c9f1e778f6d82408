//! Building the hierarchy: binned SAH, top levels in parallel.
//!
//! Deterministic for any number of threads: a node's split depends only on the triangles it
//! holds (bounds are min/max and counts integer sums, both exact in any order), partitioning is
//! sequential within a node, and the two halves of a split are built independently and laid
//! out left then right.

use rayon::prelude::*;

mod bins;
mod morton;

use bins::{Binning, Bounds, Grow, NodeBounds, PrimRef, bin_all};

use super::{MAX_DEPTH, Node, NodePair};
use crate::accel::Vertices;

/// Number of SAH bins per axis.
pub const SAH_BINS: usize = 16;

/// Most triangles in a leaf: larger nodes are always split. 16 (four blocks) traced the 1M
/// sphere's camera and shadow rays 13-18 % faster through the wide tree than 8, and 24 or 32
/// no faster (the issue 11 notes).
pub const LEAF_MAX: usize = 16;

/// A leaf whose box has more than this fraction of the root box's area holds at most
/// [`BIG_LEAF_MAX`] triangles (see `choose_split`).
const BIG_LEAF_AREA: f64 = 1.0 / 16.0;

/// Most triangles of a leaf whose box is big: a quad.
const BIG_LEAF_MAX: usize = 2;

/// Cost of visiting a node (two slab tests) relative to one triangle test, for the SAH.
const TRAVERSAL_COST: f64 = 1.0;

/// Cost of a leaf of `n` triangles, in triangle tests: the SIMD kernel tests a block of four
/// for about the price of one scalar test (`tri4`), so a leaf costs its blocks.
fn leaf_cost(n: usize) -> f64 {
    n.div_ceil(4) as f64
}

/// Below this depth nodes split by SAH; deeper ones split at the median, which halves the count
/// each level, so no tree is deeper than this plus log₂(2³²): within [`MAX_DEPTH`].
const SAH_DEPTH: u32 = 30;

/// Nodes with at least this many triangles build their two halves in parallel.
const PARALLEL_NODE: usize = 8 * 1024;

/// Nodes with at most this many triangles are split by the exact SAH (every cut between sorted
/// centroids) rather than by bins.
const SMALL_NODE: usize = 16;

/// Nodes with at least this many triangles also compute their bounds and bins in parallel.
const PARALLEL_PASS: usize = 64 * 1024;

/// Chunk size for the parallel passes.
const CHUNK: usize = 16 * 1024;

/// In a fast build, nodes of at most this many triangles are built by `morton.rs`. The 10M-triangle
/// torus of `examples/big_ply.rs` (`render --pixels 1x1`, one thread): its binary tree built in
/// 6.3 s by SAH alone, 2.7 s with Morton subtrees of up to 64K, 2.2 s up to 1M; its 300×300
/// frame traced in 41 ms through the SAH tree, 60-70 ms through these (a machine under load).
pub(super) const MORTON_NODE: usize = 1 << 20;

const _: () = assert!(MORTON_NODE >= PARALLEL_NODE && MORTON_NODE <= morton::MORTON_MAX);

/// How a node is split.
enum Split {
    /// Make a leaf.
    Leaf,
    /// Triangles whose centroid falls in a bin below `bin` go left.
    Binned(Binning, usize),
    /// Sort by centroid along the axis (ties by scene index) and cut at this many.
    Sorted(usize, usize),
    /// Put the entries in this order (a small node's, sorted along the chosen axis) and cut at
    /// this many.
    Ordered([u8; SMALL_NODE], usize),
    /// All centroids coincide: cut the list in two as it is.
    Halve,
}

/// The built hierarchy: sibling pairs (the root alone in the first), and the scene indices in
/// leaf order.
pub(super) struct Built {
    pub pairs: Vec<NodePair>,
    pub order: Vec<u32>,
    pub depth: u32,
}

/// Builds the hierarchy over `triangles`: binned SAH, or with `morton` nodes of at most that
/// many triangles built as a linear BVH.
pub(super) fn build(triangles: &(impl Vertices + ?Sized), morton: Option<usize>) -> Built {
    if triangles.count() == 0 {
        return Built {
            pairs: Vec::new(),
            order: Vec::new(),
            depth: 0,
        };
    }
    let mut refs: Vec<PrimRef> = (0..triangles.count())
        .into_par_iter()
        .map(|i| {
            let v = triangles.vertices(i);
            PrimRef::new(v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]), i as u32)
        })
        .collect();
    let nb = NodeBounds::of(&refs);
    let (mut root, below, depth) = subtree(&mut refs, nb, 0, 1, f64::NAN, morton);
    debug_assert!(depth as usize <= MAX_DEPTH);
    if !root.is_leaf() {
        // The root's children are the next pair: flat index 2.
        root.offset = 2;
    }
    let mut pairs = Vec::with_capacity(1 + below.len());
    pairs.push(NodePair([root, Node::UNUSED]));
    below.flatten(&mut pairs);
    Built {
        pairs,
        order: refs.par_iter().map(PrimRef::id).collect(),
        depth,
    }
}

/// What lies below a subtree's root, as built: sibling pairs, the first one the root's
/// children. Flattened once at the end, so no node is copied twice.
enum Part {
    /// Built in one go. An interior node's `offset` is the index in this list of its
    /// children's pair.
    Pairs(Vec<NodePair>),
    /// The root's two children, whose subtrees were built in parallel, and what lies below
    /// each; with the total number of pairs.
    Join([Node; 2], Box<[Part; 2]>, usize),
}

impl Part {
    /// Number of pairs.
    fn len(&self) -> usize {
        match self {
            Part::Pairs(v) => v.len(),
            Part::Join(_, _, len) => *len,
        }
    }

    /// Appends the pairs to `out`, every interior node's `offset` becoming the flat index of
    /// its first child (its pair's index times two).
    fn flatten(self, out: &mut Vec<NodePair>) {
        match self {
            Part::Pairs(v) => {
                let base = out.len();
                out.extend(v.into_iter().map(|mut pair| {
                    for node in &mut pair.0 {
                        if !node.is_leaf() {
                            node.offset = (2 * (base + node.offset as usize)) as u32;
                        }
                    }
                    pair
                }));
            }
            Part::Join(mut children, below, _) => {
                let at = out.len();
                out.push(NodePair([Node::UNUSED; 2]));
                for (child, below) in children.iter_mut().zip(*below) {
                    if !child.is_leaf() {
                        child.offset = (2 * out.len()) as u32;
                    }
                    below.flatten(out);
                }
                out[at] = NodePair(children);
            }
        }
    }
}

/// Builds the subtree over `refs` (whose bounds are `nb`; whose first entry is at `first` in
/// leaf order) at level `depth`: its root (an interior root's `offset` is set by the caller),
/// what lies below it, and the deepest level reached. Halves of large nodes are built in
/// parallel; with `morton`, nodes of at most that many triangles by `morton.rs`.
fn subtree(
    refs: &mut [PrimRef],
    nb: NodeBounds,
    first: usize,
    depth: u32,
    root_area: f64,
    morton: Option<usize>,
) -> (Node, Part, u32) {
    if morton.is_some_and(|m| refs.len() <= m) {
        let mut pairs = Vec::with_capacity(refs.len() / 4);
        let (root, d) = morton::build(refs, &nb, first, depth, &mut pairs);
        return (root, Part::Pairs(pairs), d);
    }
    if refs.len() < PARALLEL_NODE {
        let mut pairs = Vec::with_capacity(refs.len() / 2);
        let (root, d) = build_node(refs, nb, first, depth, root_area, &mut pairs);
        return (root, Part::Pairs(pairs), d);
    }
    let root_area = if depth == 1 {
        nb.bounds.area()
    } else {
        root_area
    };
    let Some((mid, lb, rb)) = split(refs, &nb, depth, root_area) else {
        // (Only nodes of at most LEAF_MAX triangles become leaves.)
        return (leaf(&nb, first, refs.len()), Part::Pairs(Vec::new()), depth);
    };
    let (left, right) = refs.split_at_mut(mid);
    let ((l, l_below, l_depth), (r, r_below, r_depth)) = rayon::join(
        || subtree(left, lb, first, depth + 1, root_area, morton),
        || subtree(right, rb, first + mid, depth + 1, root_area, morton),
    );
    let len = 1 + l_below.len() + r_below.len();
    (
        interior(&nb, 0),
        Part::Join([l, r], Box::new([l_below, r_below]), len),
        l_depth.max(r_depth),
    )
}

/// A leaf over the `n` triangles from `first` in leaf order.
fn leaf(nb: &NodeBounds, first: usize, n: usize) -> Node {
    Node {
        min: nb.bounds.min,
        offset: first as u32,
        max: nb.bounds.max,
        count: n as u32,
    }
}

/// An interior node whose children are at `offset`.
fn interior(nb: &NodeBounds, offset: usize) -> Node {
    Node {
        min: nb.bounds.min,
        offset: offset as u32,
        max: nb.bounds.max,
        count: 0,
    }
}

/// Builds the subtree over `refs` (whose bounds are `nb`) sequentially, appending the pairs
/// below its root to `out`; returns the root (an interior root's `offset` is its children's
/// index in `out`) and the deepest level reached. `root_area` is the whole tree's box's area
/// (any value at depth 1).
fn build_node(
    refs: &mut [PrimRef],
    nb: NodeBounds,
    first: usize,
    depth: u32,
    root_area: f64,
    out: &mut Vec<NodePair>,
) -> (Node, u32) {
    let n = refs.len();
    let root_area = if depth == 1 {
        nb.bounds.area()
    } else {
        root_area
    };
    let Some((mid, lb, rb)) = split(refs, &nb, depth, root_area) else {
        return (leaf(&nb, first, n), depth);
    };
    let at = out.len();
    out.push(NodePair([Node::UNUSED; 2]));
    let (left, right) = refs.split_at_mut(mid);
    let (l, l_depth) = build_node(left, lb, first, depth + 1, root_area, out);
    let (r, r_depth) = build_node(right, rb, first + mid, depth + 1, root_area, out);
    out[at] = NodePair([l, r]);
    (interior(&nb, at), l_depth.max(r_depth))
}

/// Decides how to split the node and reorders `refs` so that the left half comes first;
/// returns the left half's size and both halves' bounds, or `None` for a leaf.
fn split(
    refs: &mut [PrimRef],
    nb: &NodeBounds,
    depth: u32,
    root_area: f64,
) -> Option<(usize, NodeBounds, NodeBounds)> {
    let n = refs.len();
    let mid = match choose_split(refs, nb, depth, root_area) {
        Split::Leaf => return None,
        Split::Binned(binning, bin) => {
            let (mid, l, r) = partition(refs, |r| binning.bin(r.centroid(binning.axis)) < bin);
            debug_assert!(0 < mid && mid < n);
            return Some((mid, l, r));
        }
        Split::Sorted(axis, mid) => {
            refs.select_nth_unstable_by(mid, |a, b| {
                a.centroid(axis)
                    .total_cmp(&b.centroid(axis))
                    .then(a.id().cmp(&b.id()))
            });
            mid
        }
        Split::Ordered(order, mid) => {
            let old: [PrimRef; SMALL_NODE] = std::array::from_fn(|i| refs[i.min(n - 1)]);
            for (r, &o) in refs.iter_mut().zip(&order[..n]) {
                *r = old[o as usize];
            }
            mid
        }
        Split::Halve => n / 2,
    };
    debug_assert!(0 < mid && mid < n);
    Some((
        mid,
        NodeBounds::of(&refs[..mid]),
        NodeBounds::of(&refs[mid..]),
    ))
}

/// Picks how to split a node of `refs.len()` triangles with bounds `nb`, in a tree whose root
/// box has area `root_area`.
fn choose_split(refs: &[PrimRef], nb: &NodeBounds, depth: u32, root_area: f64) -> Split {
    let n = refs.len();
    if n == 1 {
        return Split::Leaf;
    }
    let c = &nb.centroids;
    if c.min == c.max {
        return if n <= LEAF_MAX {
            Split::Leaf
        } else {
            Split::Halve
        };
    }
    let widest = {
        let d = c.max.as_dvec3() - c.min.as_dvec3();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    };
    if depth >= SAH_DEPTH {
        return if n <= LEAF_MAX {
            Split::Leaf
        } else {
            Split::Sorted(widest, n / 2)
        };
    }
    let area = nb.bounds.area();
    let (best, split) = if n <= SMALL_NODE {
        small_sah(refs, c)
    } else {
        binned_sah(refs, c)
    };
    match (best, split) {
        (Some(cost), Some(split)) if cost.is_finite() && area.is_finite() && area > 0.0 => {
            let split_cost = TRAVERSAL_COST + cost / area;
            // A big box is entered by most rays, before what they hit inside it (the SAH's
            // estimate, that a ray meeting a box passes through it, misses that), so a leaf
            // there holds at most a quad: e.g. a room's walls, each its own thin slab that
            // rays meet only beyond their hit, not one leaf the size of the room.
            let big = area > BIG_LEAF_AREA * root_area && n > BIG_LEAF_MAX;
            if n <= LEAF_MAX && leaf_cost(n) <= split_cost && !big {
                Split::Leaf
            } else {
                split
            }
        }
        // No split separates the centroids, or the areas overflowed: cut at the median.
        _ if n <= LEAF_MAX => Split::Leaf,
        _ => Split::Sorted(widest, n / 2),
    }
}

/// The binned SAH: the cheapest cut between bins on any axis, as `(A_L·N_L + A_R·N_R, split)`.
fn binned_sah(refs: &[PrimRef], c: &Bounds) -> (Option<f64>, Option<Split>) {
    let n = refs.len() as u64;
    let binnings = [0, 1, 2].map(|a| Binning::new(c, a));
    let bins = bin_all(refs, &binnings);
    let mut best: Option<(f64, Binning, usize)> = None;
    for (b, bins) in binnings.iter().zip(&bins) {
        let Some(b) = b else { continue };
        let mut right_cost = [0f64; SAH_BINS];
        let mut acc = Bounds::EMPTY;
        let mut count = 0u64;
        for k in (1..SAH_BINS).rev() {
            acc = acc.union(bins.bounds(k));
            count += u64::from(bins.count[k]);
            right_cost[k] = acc.area() * count as f64;
        }
        let mut acc = Bounds::EMPTY;
        let mut count = 0u64;
        for (k, right) in right_cost.iter().enumerate().skip(1) {
            acc = acc.union(bins.bounds(k - 1));
            count += u64::from(bins.count[k - 1]);
            if count == 0 || count == n {
                continue;
            }
            let cost = acc.area() * count as f64 + right;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, *b, k));
            }
        }
    }
    match best {
        Some((cost, b, k)) => (Some(cost), Some(Split::Binned(b, k))),
        None => (None, None),
    }
}

/// The exact SAH for a small node: every cut between centroids sorted along each axis (ties
/// by scene index).
#[allow(clippy::needless_range_loop)] // `axis` picks a coordinate of several arrays' entries
fn small_sah(refs: &[PrimRef], c: &Bounds) -> (Option<f64>, Option<Split>) {
    let n = refs.len();
    debug_assert!(n <= SMALL_NODE);
    let centroids: [[f32; 3]; SMALL_NODE] =
        std::array::from_fn(|i| refs.get(i).map_or([0.0; 3], |r| r.centre().to_array()));
    let mut best: Option<(f64, [u8; SMALL_NODE], usize)> = None;
    let mut right_cost = [0f64; SMALL_NODE];
    for axis in 0..3 {
        if !(c.max[axis] > c.min[axis]) {
            continue;
        }
        // Sort by (centroid, scene index) as one integer key: the centroid's bits mapped to
        // an unsigned integer in `total_cmp` order, then the index.
        let mut keys = [(u64::MAX, 0u8); SMALL_NODE];
        for (i, key) in keys[..n].iter_mut().enumerate() {
            let bits = centroids[i][axis].to_bits();
            let ordered = if bits >> 31 == 1 {
                !bits
            } else {
                bits | 1 << 31
            };
            *key = (
                (u64::from(ordered) << 32) | u64::from(refs[i].id()),
                i as u8,
            );
        }
        keys[..n].sort_unstable_by_key(|k| k.0);
        let order: [u8; SMALL_NODE] = keys.map(|k| k.1);
        let mut acc = Bounds::EMPTY;
        for k in (1..n).rev() {
            let r = &refs[order[k] as usize];
            acc.grow(r.min(), r.max());
            right_cost[k] = acc.area() * (n - k) as f64;
        }
        let mut acc = Bounds::EMPTY;
        for k in 1..n {
            let (prev, next) = (order[k - 1] as usize, order[k] as usize);
            acc.grow(refs[prev].min(), refs[prev].max());
            // Cut only between distinct centroids, so each half's centroid box shrinks.
            if centroids[prev][axis] == centroids[next][axis] {
                continue;
            }
            let cost = acc.area() * k as f64 + right_cost[k];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, order, k));
            }
        }
    }
    match best {
        Some((cost, order, k)) => (Some(cost), Some(Split::Ordered(order, k))),
        None => (None, None),
    }
}

/// Moves the entries for which `left` holds to the front (in a fixed order: the result depends
/// only on the input) and returns how many there are, with the bounds of both parts (gathered
/// on the way: min and max, the same in any order).
fn partition(
    refs: &mut [PrimRef],
    left: impl Fn(&PrimRef) -> bool,
) -> (usize, NodeBounds, NodeBounds) {
    let (mut lb, mut rb) = (Grow::EMPTY, Grow::EMPTY);
    let mut i = 0;
    let mut j = refs.len();
    loop {
        while i < j && left(&refs[i]) {
            lb.add(&refs[i]);
            i += 1;
        }
        while i < j && !left(&refs[j - 1]) {
            rb.add(&refs[j - 1]);
            j -= 1;
        }
        if i >= j {
            return (i, lb.bounds(), rb.bounds());
        }
        refs.swap(i, j - 1);
        lb.add(&refs[i]);
        rb.add(&refs[j - 1]);
        i += 1;
        j -= 1;
    }
}
