//! Building the hierarchy: binned SAH, top levels in parallel.
//!
//! Deterministic for any number of threads: a node's split depends only on the triangles it
//! holds (bounds are min/max and counts integer sums, both exact in any order), partitioning is
//! sequential within a node, and the two halves of a split are built independently and laid
//! out left then right.

use glam::Vec3;
use rayon::prelude::*;

use super::{MAX_DEPTH, Node};
use crate::geometry::Triangle;

/// Number of SAH bins per axis.
pub const SAH_BINS: usize = 16;

/// Most triangles in a leaf: larger nodes are always split.
pub const LEAF_MAX: usize = 8;

/// Cost of visiting a node (two slab tests) relative to one triangle test, for the SAH.
const TRAVERSAL_COST: f64 = 1.0;

/// Below this depth nodes split by SAH; deeper ones split at the median, which halves the count
/// each level, so no tree is deeper than this plus log₂(2³²): within [`MAX_DEPTH`].
const SAH_DEPTH: u32 = 30;

/// Nodes with at least this many triangles build their two halves in parallel.
const PARALLEL_NODE: usize = 8 * 1024;

/// Nodes with at least this many triangles also compute their bounds and bins in parallel.
const PARALLEL_PASS: usize = 64 * 1024;

/// Chunk size for the parallel passes.
const CHUNK: usize = 16 * 1024;

/// A triangle's box and its scene index, the unit the builder sorts.
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    min: Vec3,
    max: Vec3,
    id: u32,
}

impl PrimRef {
    /// The box's centre along `axis` (each term halved first, so huge coordinates cannot
    /// overflow).
    #[inline]
    fn centroid(&self, axis: usize) -> f32 {
        self.min[axis] * 0.5 + self.max[axis] * 0.5
    }
}

/// Box bounds as plain min/max; `EMPTY` is the identity of `union`.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: Vec3,
    max: Vec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    #[inline]
    fn grow(&mut self, min: Vec3, max: Vec3) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline]
    fn union(mut self, o: Bounds) -> Bounds {
        self.grow(o.min, o.max);
        self
    }

    /// Surface area in `f64` (f32 extents of huge boxes would overflow when multiplied).
    fn area(&self) -> f64 {
        if !(self.min.x <= self.max.x) {
            return 0.0;
        }
        let d = self.max.as_dvec3() - self.min.as_dvec3();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

/// A node's box and the box of its triangles' centroids.
#[derive(Clone, Copy, Debug)]
struct NodeBounds {
    bounds: Bounds,
    centroids: Bounds,
}

impl NodeBounds {
    const EMPTY: NodeBounds = NodeBounds {
        bounds: Bounds::EMPTY,
        centroids: Bounds::EMPTY,
    };

    fn union(self, o: NodeBounds) -> NodeBounds {
        NodeBounds {
            bounds: self.bounds.union(o.bounds),
            centroids: self.centroids.union(o.centroids),
        }
    }

    fn of(refs: &[PrimRef]) -> NodeBounds {
        let fold = |refs: &[PrimRef]| {
            let mut b = NodeBounds::EMPTY;
            for r in refs {
                b.bounds.grow(r.min, r.max);
                let c = r.min * 0.5 + r.max * 0.5;
                b.centroids.grow(c, c);
            }
            b
        };
        if refs.len() >= PARALLEL_PASS {
            refs.par_chunks(CHUNK)
                .map(fold)
                .reduce(|| NodeBounds::EMPTY, NodeBounds::union)
        } else {
            fold(refs)
        }
    }
}

/// The mapping of centroids to bins along one axis.
#[derive(Clone, Copy, Debug)]
struct Binning {
    axis: usize,
    lo: f64,
    scale: f64,
}

impl Binning {
    /// `None` when the centroids do not spread along `axis`.
    fn new(centroids: &Bounds, axis: usize) -> Option<Binning> {
        let lo = f64::from(centroids.min[axis]);
        let extent = f64::from(centroids.max[axis]) - lo;
        (extent > 0.0).then(|| Binning {
            axis,
            lo,
            scale: SAH_BINS as f64 / extent,
        })
    }

    #[inline]
    fn bin(&self, r: &PrimRef) -> usize {
        let k = (f64::from(r.centroid(self.axis)) - self.lo) * self.scale;
        (k as usize).min(SAH_BINS - 1)
    }
}

/// Per-axis bins: box and count.
#[derive(Clone, Copy, Debug)]
struct Bins {
    bounds: [[Bounds; SAH_BINS]; 3],
    counts: [[u32; SAH_BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        bounds: [[Bounds::EMPTY; SAH_BINS]; 3],
        counts: [[0; SAH_BINS]; 3],
    };

    fn union(mut self, o: Bins) -> Bins {
        for a in 0..3 {
            for k in 0..SAH_BINS {
                self.bounds[a][k] = self.bounds[a][k].union(o.bounds[a][k]);
                self.counts[a][k] += o.counts[a][k];
            }
        }
        self
    }

    fn of(refs: &[PrimRef], binnings: &[Option<Binning>; 3]) -> Bins {
        let fold = |refs: &[PrimRef]| {
            let mut bins = Bins::EMPTY;
            for r in refs {
                for b in binnings.iter().flatten() {
                    let k = b.bin(r);
                    bins.bounds[b.axis][k].grow(r.min, r.max);
                    bins.counts[b.axis][k] += 1;
                }
            }
            bins
        };
        if refs.len() >= PARALLEL_PASS {
            refs.par_chunks(CHUNK)
                .map(fold)
                .reduce(|| Bins::EMPTY, Bins::union)
        } else {
            fold(refs)
        }
    }
}

/// How a node is split.
enum Split {
    /// Make a leaf.
    Leaf,
    /// Triangles whose centroid falls in a bin below `bin` go left.
    Sah(Binning, usize),
    /// Sort by centroid along the axis (ties by scene index) and cut at the middle.
    Median(usize),
    /// All centroids coincide: cut the list in two as it is.
    Halve,
}

/// The built hierarchy: nodes in depth-first order, and the scene indices in leaf order.
pub(super) struct Built {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
    pub depth: u32,
}

/// Builds the hierarchy over `triangles`.
pub(super) fn build(triangles: &[Triangle]) -> Built {
    if triangles.is_empty() {
        return Built {
            nodes: Vec::new(),
            order: Vec::new(),
            depth: 0,
        };
    }
    let mut refs: Vec<PrimRef> = triangles
        .par_iter()
        .enumerate()
        .map(|(i, t)| PrimRef {
            min: t.v[0].min(t.v[1]).min(t.v[2]),
            max: t.v[0].max(t.v[1]).max(t.v[2]),
            id: i as u32,
        })
        .collect();
    let mut nodes = Vec::with_capacity(triangles.len());
    let depth = build_node(&mut refs, 0, 1, &mut nodes);
    debug_assert!(depth as usize <= MAX_DEPTH);
    Built {
        nodes,
        order: refs.par_iter().map(|r| r.id).collect(),
        depth,
    }
}

/// Builds the subtree over `refs` (whose first entry is at `first` in leaf order) at level
/// `depth`, appending its nodes to `out`. Returns the deepest level reached.
fn build_node(refs: &mut [PrimRef], first: usize, depth: u32, out: &mut Vec<Node>) -> u32 {
    let n = refs.len();
    let nb = NodeBounds::of(refs);
    let me = out.len();
    let split = choose_split(refs, &nb, depth);
    let mid = match split {
        Split::Leaf => {
            out.push(Node {
                min: nb.bounds.min,
                offset: first as u32,
                max: nb.bounds.max,
                count: n as u32,
            });
            return depth;
        }
        Split::Sah(binning, bin) => partition(refs, |r| binning.bin(r) < bin),
        Split::Median(axis) => {
            let mid = n / 2;
            refs.select_nth_unstable_by(mid, |a, b| {
                a.centroid(axis)
                    .total_cmp(&b.centroid(axis))
                    .then(a.id.cmp(&b.id))
            });
            mid
        }
        Split::Halve => n / 2,
    };
    debug_assert!(0 < mid && mid < n);
    out.push(Node {
        min: nb.bounds.min,
        offset: 0,
        max: nb.bounds.max,
        count: 0,
    });
    let (left, right) = refs.split_at_mut(mid);
    if n >= PARALLEL_NODE {
        let ((l_nodes, l_depth), (r_nodes, r_depth)) = rayon::join(
            || subtree(left, first, depth + 1),
            || subtree(right, first + mid, depth + 1),
        );
        out[me].offset = (1 + l_nodes.len()) as u32;
        out.extend_from_slice(&l_nodes);
        out.extend_from_slice(&r_nodes);
        l_depth.max(r_depth)
    } else {
        let l_depth = build_node(left, first, depth + 1, out);
        out[me].offset = (out.len() - me) as u32;
        let r_depth = build_node(right, first + mid, depth + 1, out);
        l_depth.max(r_depth)
    }
}

/// A subtree built into its own node list (offsets are relative, so it can be appended as is).
fn subtree(refs: &mut [PrimRef], first: usize, depth: u32) -> (Vec<Node>, u32) {
    let mut nodes = Vec::with_capacity(refs.len() / 2 + 1);
    let d = build_node(refs, first, depth, &mut nodes);
    (nodes, d)
}

/// Picks how to split a node of `refs.len()` triangles with bounds `nb`.
fn choose_split(refs: &[PrimRef], nb: &NodeBounds, depth: u32) -> Split {
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
            Split::Median(widest)
        };
    }
    let binnings = [0, 1, 2].map(|a| Binning::new(c, a));
    let bins = Bins::of(refs, &binnings);
    // Sweep each axis: cost of cutting before bin k is A_L·N_L + A_R·N_R.
    let mut best: Option<(f64, Binning, usize)> = None;
    for b in binnings.iter().flatten() {
        let (boxes, counts) = (&bins.bounds[b.axis], &bins.counts[b.axis]);
        let mut right_cost = [0f64; SAH_BINS];
        let mut acc = Bounds::EMPTY;
        let mut count = 0u64;
        for k in (1..SAH_BINS).rev() {
            acc = acc.union(boxes[k]);
            count += u64::from(counts[k]);
            right_cost[k] = acc.area() * count as f64;
        }
        let mut acc = Bounds::EMPTY;
        let mut count = 0u64;
        for k in 1..SAH_BINS {
            acc = acc.union(boxes[k - 1]);
            count += u64::from(counts[k - 1]);
            if count == 0 || count == n as u64 {
                continue;
            }
            let cost = acc.area() * count as f64 + right_cost[k];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, *b, k));
            }
        }
    }
    let area = nb.bounds.area();
    match best {
        Some((cost, b, k)) if cost.is_finite() && area.is_finite() && area > 0.0 => {
            let split_cost = TRAVERSAL_COST + cost / area;
            if n <= LEAF_MAX && n as f64 <= split_cost {
                Split::Leaf
            } else {
                Split::Sah(b, k)
            }
        }
        // Every centroid fell in one bin, or the areas overflowed: split at the median.
        _ if n <= LEAF_MAX => Split::Leaf,
        _ => Split::Median(widest),
    }
}

/// Moves the entries for which `left` holds to the front (in a fixed order: the result depends
/// only on the input) and returns how many there are.
fn partition(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut i = 0;
    let mut j = refs.len();
    loop {
        while i < j && left(&refs[i]) {
            i += 1;
        }
        while i < j && !left(&refs[j - 1]) {
            j -= 1;
        }
        if i >= j {
            return i;
        }
        refs.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}
