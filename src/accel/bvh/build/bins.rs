//! Binning for the SAH: triangle references, their bounds, and the per-axis bins that
//! a node's split is chosen from (counts and boxes gathered in parallel for big nodes).

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::{CHUNK, PARALLEL_PASS, SAH_BINS};

/// A triangle's box and its scene index, the unit the builder sorts: two 16-byte lanes of
/// four, so that a box is binned and grown with one SIMD operation a corner (glam's `Vec4`
/// on SSE2: `min`/`max` are `a < b ? a : b` per lane, as `Vec3`'s scalar ones, so the boxes,
/// centroids and bins are bit for bit those of three scalar lanes, and the tree the same).
/// With the two sets of bins in [`bin_all`] and the children's bounds gathered while
/// partitioning, a 10M-triangle PLY's load took 6.0-6.5 s of CPU time instead of 7.4-8.5 s
/// (`/usr/bin/time`, one sitting).
///
/// The fourth lanes hold the index, split so that both are normal floats in [2²³, 2²⁴) (a
/// denormal would slow every operation on it): `lo.w` the low 23 bits, `hi.w` the rest. Their
/// sums and products with 0.5 stay normal and are never read.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRef {
    lo: Vec4,
    hi: Vec4,
}

/// The exponent bits of 2²³: a float with them and 23 mantissa bits is 2²³ + those bits.
const TAG: u32 = 0x4b00_0000;
const LOW: u32 = (1 << 23) - 1;

impl PrimRef {
    #[inline]
    pub(super) fn new(min: Vec3, max: Vec3, id: u32) -> PrimRef {
        PrimRef {
            lo: min.extend(f32::from_bits(TAG | (id & LOW))),
            hi: max.extend(f32::from_bits(TAG | (id >> 23))),
        }
    }

    #[inline]
    pub(super) fn min(&self) -> Vec3 {
        self.lo.truncate()
    }

    #[inline]
    pub(super) fn max(&self) -> Vec3 {
        self.hi.truncate()
    }

    /// The triangle's scene index.
    #[inline]
    pub(super) fn id(&self) -> u32 {
        (self.lo.w.to_bits() & LOW) | ((self.hi.w.to_bits() & LOW) << 23)
    }

    /// The box's centre (each term halved first, so huge coordinates cannot overflow); the
    /// fourth lane is not a coordinate.
    #[inline]
    fn centre4(&self) -> Vec4 {
        self.lo * 0.5 + self.hi * 0.5
    }

    /// The box's centre.
    #[inline]
    pub(super) fn centre(&self) -> Vec3 {
        self.centre4().truncate()
    }

    /// The box's centre along `axis`.
    #[inline]
    pub(super) fn centroid(&self, axis: usize) -> f32 {
        self.lo[axis] * 0.5 + self.hi[axis] * 0.5
    }
}

/// Box bounds as plain min/max; `EMPTY` is the identity of `union`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Bounds {
    pub(super) min: Vec3,
    pub(super) max: Vec3,
}

impl Bounds {
    pub(super) const EMPTY: Bounds = Bounds {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    #[inline]
    pub(super) fn grow(&mut self, min: Vec3, max: Vec3) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline]
    pub(super) fn union(mut self, o: Bounds) -> Bounds {
        self.grow(o.min, o.max);
        self
    }

    /// Surface area: in `f32`, or in `f64` when that overflows (huge boxes).
    #[inline]
    pub(super) fn area(&self) -> f64 {
        if !(self.min.x <= self.max.x) {
            return 0.0;
        }
        let d = self.max - self.min;
        let a = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        if a.is_finite() {
            return f64::from(a);
        }
        let d = self.max.as_dvec3() - self.min.as_dvec3();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

/// A node's box and the box of its triangles' centroids.
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeBounds {
    pub(super) bounds: Bounds,
    pub(super) centroids: Bounds,
}

impl NodeBounds {
    pub(super) const EMPTY: NodeBounds = NodeBounds {
        bounds: Bounds::EMPTY,
        centroids: Bounds::EMPTY,
    };

    pub(super) fn union(self, o: NodeBounds) -> NodeBounds {
        NodeBounds {
            bounds: self.bounds.union(o.bounds),
            centroids: self.centroids.union(o.centroids),
        }
    }

    pub(super) fn of(refs: &[PrimRef]) -> NodeBounds {
        let fold = |refs: &[PrimRef]| {
            let mut b = Grow::EMPTY;
            for r in refs {
                b.add(r);
            }
            b.bounds()
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

/// [`NodeBounds`] being gathered, four lanes a corner.
#[derive(Clone, Copy, Debug)]
pub(super) struct Grow {
    min: Vec4,
    max: Vec4,
    cmin: Vec4,
    cmax: Vec4,
}

impl Grow {
    pub(super) const EMPTY: Grow = Grow {
        min: Vec4::INFINITY,
        max: Vec4::NEG_INFINITY,
        cmin: Vec4::INFINITY,
        cmax: Vec4::NEG_INFINITY,
    };

    #[inline]
    pub(super) fn add(&mut self, r: &PrimRef) {
        self.min = self.min.min(r.lo);
        self.max = self.max.max(r.hi);
        let c = r.centre4();
        self.cmin = self.cmin.min(c);
        self.cmax = self.cmax.max(c);
    }

    pub(super) fn bounds(&self) -> NodeBounds {
        NodeBounds {
            bounds: Bounds {
                min: self.min.truncate(),
                max: self.max.truncate(),
            },
            centroids: Bounds {
                min: self.cmin.truncate(),
                max: self.cmax.truncate(),
            },
        }
    }
}

/// The mapping of centroids to bins along one axis.
#[derive(Clone, Copy, Debug)]
pub(super) struct Binning {
    pub(super) axis: usize,
    pub(super) lo: f32,
    pub(super) scale: f32,
}

impl Binning {
    /// `None` when the centroids do not spread along `axis`. The scale is computed in `f64`
    /// (the extent may overflow `f32`); a centroid distance that overflows lands in the last bin,
    /// on both the binning and the partitioning pass alike.
    pub(super) fn new(centroids: &Bounds, axis: usize) -> Option<Binning> {
        let lo = centroids.min[axis];
        let extent = f64::from(centroids.max[axis]) - f64::from(lo);
        let scale = (SAH_BINS as f64 / extent) as f32;
        (extent > 0.0 && scale.is_finite() && scale > 0.0).then_some(Binning { axis, lo, scale })
    }

    /// The bin of a triangle whose centroid is `c` along this axis.
    #[inline]
    pub(super) fn bin(&self, c: f32) -> usize {
        bin_index((c - self.lo) * self.scale)
    }
}

/// Bin of a scaled centroid distance, clamped to the bins (NaN to bin 0). The same operations as
/// [`bin_all`]'s three-axes-at-once form, so both passes agree on every triangle.
#[inline]
pub(super) fn bin_index(k: f32) -> usize {
    let k = if k > 0.0 { k } else { 0.0 };
    let last = (SAH_BINS - 1) as f32;
    (if k < last { k } else { last }) as i32 as usize
}

/// One axis's bins: boxes (the fourth lane is not a coordinate) and counts.
#[derive(Clone, Copy, Debug)]
pub(super) struct AxisBins {
    min: [Vec4; SAH_BINS],
    max: [Vec4; SAH_BINS],
    pub(super) count: [u32; SAH_BINS],
}

impl AxisBins {
    pub(super) const EMPTY: AxisBins = AxisBins {
        min: [Vec4::INFINITY; SAH_BINS],
        max: [Vec4::NEG_INFINITY; SAH_BINS],
        count: [0; SAH_BINS],
    };

    pub(super) fn bounds(&self, k: usize) -> Bounds {
        Bounds {
            min: self.min[k].truncate(),
            max: self.max[k].truncate(),
        }
    }
}

pub(super) type Bins = [AxisBins; 3];

pub(super) fn union_bins(mut a: Bins, b: Bins) -> Bins {
    for (x, y) in a.iter_mut().zip(&b) {
        for k in 0..SAH_BINS {
            x.min[k] = x.min[k].min(y.min[k]);
            x.max[k] = x.max[k].max(y.max[k]);
            x.count[k] += y.count[k];
        }
    }
    a
}

pub(super) fn bin_all(refs: &[PrimRef], binnings: &[Option<Binning>; 3]) -> Bins {
    // All three axes at once: an axis without bins gets scale 0 (every triangle in bin 0) and
    // its bins are never read; the fourth lane is scaled by 0 too.
    let lo = Vec3::from_array(binnings.map(|b| b.map_or(0.0, |b| b.lo))).extend(0.0);
    let scale = Vec3::from_array(binnings.map(|b| b.map_or(0.0, |b| b.scale))).extend(0.0);
    let last = Vec4::splat((SAH_BINS - 1) as f32);
    let add = |bins: &mut Bins, r: &PrimRef| {
        // Vec4::max/min are `if a > b { a } else { b }` per lane, as in `bin_index`.
        let k = ((r.centre4() - lo) * scale).max(Vec4::ZERO).min(last);
        for (bins, k) in bins.iter_mut().zip(k.truncate().to_array()) {
            // In [0, 15]: the 32-bit conversion is one instruction, the 64-bit one several.
            let k = k as i32 as usize;
            bins.min[k] = bins.min[k].min(r.lo);
            bins.max[k] = bins.max[k].max(r.hi);
            bins.count[k] += 1;
        }
    };
    // Two sets of bins, even and odd entries: neighbours often fall in one bin, and with one
    // set each would wait for the other's update of it.
    let fold = |refs: &[PrimRef]| {
        let mut even = [AxisBins::EMPTY; 3];
        let mut odd = [AxisBins::EMPTY; 3];
        let mut pairs = refs.chunks_exact(2);
        for pair in &mut pairs {
            add(&mut even, &pair[0]);
            add(&mut odd, &pair[1]);
        }
        for r in pairs.remainder() {
            add(&mut even, r);
        }
        union_bins(even, odd)
    };
    if refs.len() >= PARALLEL_PASS {
        refs.par_chunks(CHUNK)
            .map(fold)
            .reduce(|| [AxisBins::EMPTY; 3], union_bins)
    } else {
        fold(refs)
    }
}
