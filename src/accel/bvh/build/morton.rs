//! The big trees' lower levels: a linear BVH. A subtree's triangles are sorted along a Morton
//! curve through their centroids' box, then split where the highest differing bit of the codes
//! changes (Lauterbach et al., "Fast BVH Construction on GPUs", 2009): one sort instead of a
//! binned SAH pass at every level.
//!
//! Deterministic: the codes depend only on the triangles' boxes and the subtree's centroid
//! box, ties are broken by position in the (already deterministic) input order, and the
//! splits only by the sorted codes.

use super::bins::{Grow, NodeBounds, PrimRef};
use super::{LEAF_MAX, Node, NodePair, SAH_DEPTH, interior, leaf};

/// Bits of each axis in a Morton code: three make the code's 30 bits.
const AXIS_BITS: u32 = 10;

/// A Morton subtree's leaves hold this many triangles (four full blocks of four), all but its
/// last one: each split is rounded to a multiple of it. Splitting at any count left most
/// leaves' last block part empty; leaves of 8 made twice the nodes (10M-triangle torus: 88 →
/// 98 bytes a triangle at the peak) for frames no faster (300×300: 47-53 ms either way).
pub(super) const MORTON_LEAF: usize = 16;

const _: () = assert!(MORTON_LEAF <= LEAF_MAX);

/// Most triangles a Morton subtree sorts at once: each one's position in it fits the bits a
/// sort key has below its code.
pub(super) const MORTON_MAX: usize = 1 << (64 - 3 * AXIS_BITS);

/// Spreads the low 10 bits of `x` three apart (bit `i` to bit `3i`).
fn spread(x: u32) -> u64 {
    let mut x = u64::from(x) & 0x3ff;
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    x = (x | x << 2) & 0x0924_9249;
    x
}

/// Builds the subtree over `refs` (whose bounds are `nb`; its first entry at `first` in leaf
/// order) at level `depth` sequentially, reordering `refs` along the curve and appending the
/// pairs below its root to `out`, as `build_node` does; returns its root and deepest level.
pub(super) fn build(
    refs: &mut [PrimRef],
    nb: &NodeBounds,
    first: usize,
    depth: u32,
    out: &mut Vec<NodePair>,
) -> (Node, u32) {
    let n = refs.len();
    assert!(
        n <= MORTON_MAX,
        "a Morton subtree sorts at most 2³⁴ triangles"
    );
    let c = &nb.centroids;
    let extent = c.max - c.min;
    let cells = (1u32 << AXIS_BITS) as f32;
    // An axis the centroids do not spread along gets scale 0 (every code's bits 0 there).
    let scale = extent.map(|e| {
        let s = cells / e;
        if e > 0.0 && s.is_finite() { s } else { 0.0 }
    });
    let last = (cells - 1.0) as u32;
    let mut keys: Vec<u64> = refs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let q = ((r.centre() - c.min) * scale).to_array().map(|x| {
                // Clamped into the cells (NaN to 0); in range, the 32-bit conversion is exact.
                let x = if x > 0.0 { x } else { 0.0 };
                (x as u32).min(last)
            });
            let code = spread(q[0]) << 2 | spread(q[1]) << 1 | spread(q[2]);
            code << (64 - 3 * AXIS_BITS) | i as u64
        })
        .collect();
    keys.sort_unstable();
    let old = refs.to_vec();
    for (r, k) in refs.iter_mut().zip(&keys) {
        *r = old[(k & (MORTON_MAX as u64 - 1)) as usize];
    }
    drop(old);
    for k in &mut keys {
        *k >>= 64 - 3 * AXIS_BITS;
    }
    let mut b = Builder {
        refs,
        codes: &keys,
        first,
        out,
    };
    let (node, _, d) = b.node(0, n, depth);
    (node, d)
}

/// The sorted triangles and their codes, and where pairs go.
struct Builder<'a> {
    refs: &'a [PrimRef],
    codes: &'a [u64],
    first: usize,
    out: &'a mut Vec<NodePair>,
}

impl Builder<'_> {
    /// The node over `lo..hi` at level `depth`: the node, its bounds and its deepest level.
    fn node(&mut self, lo: usize, hi: usize, depth: u32) -> (Node, NodeBounds, u32) {
        let n = hi - lo;
        if n <= MORTON_LEAF {
            let mut g = Grow::EMPTY;
            for r in &self.refs[lo..hi] {
                g.add(r);
            }
            let nb = g.bounds();
            return (leaf(&nb, self.first + lo, n), nb, depth);
        }
        let (a, b) = (self.codes[lo], self.codes[hi - 1]);
        // Below SAH_DEPTH, at the highest bit where the first and last code differ (the codes
        // are sorted: those with it clear come first); deeper, or when all codes are equal,
        // at the middle, which keeps the tree within MAX_DEPTH as the SAH builder does (rounding
        // keeps at least a quarter of a node of more than 2·MORTON_LEAF on either side).
        let cut = if a != b && depth < SAH_DEPTH {
            let bit = 63 - (a ^ b).leading_zeros();
            self.codes[lo..hi].partition_point(|c| c >> bit & 1 == 0)
        } else {
            n / 2
        };
        // To the nearest multiple of MORTON_LEAF, leaving at least one entry on the right.
        let last = (n - 1) / MORTON_LEAF * MORTON_LEAF;
        let mid =
            lo + ((cut + MORTON_LEAF / 2) / MORTON_LEAF * MORTON_LEAF).clamp(MORTON_LEAF, last);
        debug_assert!(lo < mid && mid < hi);
        let at = self.out.len();
        self.out.push(NodePair([Node::UNUSED; 2]));
        let (l, lb, l_depth) = self.node(lo, mid, depth + 1);
        let (r, rb, r_depth) = self.node(mid, hi, depth + 1);
        self.out[at] = NodePair([l, r]);
        let nb = lb.union(rb);
        (interior(&nb, at), nb, l_depth.max(r_depth))
    }
}
