//! Binning for the SAH: triangle references, their bounds, and the per-axis bins that
//! a node's split is chosen from (counts and boxes gathered in parallel for big nodes).

use glam::Vec3;
use rayon::prelude::*;

use super::{CHUNK, PARALLEL_PASS, SAH_BINS};

/// A triangle's box and its scene index, the unit the builder sorts.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRef {
    pub(super) min: Vec3,
    pub(super) max: Vec3,
    pub(super) id: u32,
}

impl PrimRef {
    /// The box's centre along `axis` (each term halved first, so huge coordinates cannot
    /// overflow).
    #[inline]
    pub(super) fn centroid(&self, axis: usize) -> f32 {
        let (min, max): (&[f32; 3], &[f32; 3]) = (self.min.as_ref(), self.max.as_ref());
        min[axis] * 0.5 + max[axis] * 0.5
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

/// One axis's bins: boxes and counts.
#[derive(Clone, Copy, Debug)]
pub(super) struct AxisBins {
    pub(super) min: [Vec3; SAH_BINS],
    pub(super) max: [Vec3; SAH_BINS],
    pub(super) count: [u32; SAH_BINS],
}

impl AxisBins {
    pub(super) const EMPTY: AxisBins = AxisBins {
        min: [Vec3::INFINITY; SAH_BINS],
        max: [Vec3::NEG_INFINITY; SAH_BINS],
        count: [0; SAH_BINS],
    };

    pub(super) fn bounds(&self, k: usize) -> Bounds {
        Bounds {
            min: self.min[k],
            max: self.max[k],
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
    // its bins are never read.
    let lo = Vec3::from_array(binnings.map(|b| b.map_or(0.0, |b| b.lo)));
    let scale = Vec3::from_array(binnings.map(|b| b.map_or(0.0, |b| b.scale)));
    let last = Vec3::splat((SAH_BINS - 1) as f32);
    let fold = |refs: &[PrimRef]| {
        let mut bins = [AxisBins::EMPTY; 3];
        for r in refs {
            let c = r.min * 0.5 + r.max * 0.5;
            // Vec3::max/min are `if a > b { a } else { b }` per lane, as in `bin_index`.
            let k = ((c - lo) * scale).max(Vec3::ZERO).min(last);
            for (bins, k) in bins.iter_mut().zip(k.to_array()) {
                // In [0, 15]: the 32-bit conversion is one instruction, the 64-bit one several.
                let k = k as i32 as usize;
                bins.min[k] = bins.min[k].min(r.min);
                bins.max[k] = bins.max[k].max(r.max);
                bins.count[k] += 1;
            }
        }
        bins
    };
    if refs.len() >= PARALLEL_PASS {
        refs.par_chunks(CHUNK)
            .map(fold)
            .reduce(|| [AxisBins::EMPTY; 3], union_bins)
    } else {
        fold(refs)
    }
}
