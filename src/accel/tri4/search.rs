//! The block loops every structure shares: the closest hit among blocks, and whether any block
//! is hit.

use glam::Vec3;

use super::{LANES, LaneHits, RayLanes, Tri4, block_hits};
use crate::accel::hit::{Hit, shrunk_t_max};
use crate::geometry::{Ray, intersect_watertight};
use crate::simd::Path;

/// The closest-hit search's state: the best hit so far and the `t_max` a triangle is tested
/// with (four ULPs above it, see [`shrunk_t_max`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Closest {
    pub best: Option<Hit>,
    pub tri_t_max: f32,
    pub t_max: f32,
}

impl Closest {
    #[inline(always)]
    pub fn new(t_max: f32) -> Closest {
        Closest {
            best: None,
            tri_t_max: t_max,
            t_max,
        }
    }

    /// Keeps the hit `(t, b)` on triangle `i` if it beats the best: a smaller `t`, or the same
    /// `t` on a lower index.
    #[inline(always)]
    fn offer(&mut self, t: f32, b: [f32; 3], i: u32) {
        if self
            .best
            .is_none_or(|h| t < h.t || t == h.t && i < h.triangle)
        {
            self.best = Some(Hit { t, b, triangle: i });
            self.tri_t_max = shrunk_t_max(t, self.t_max);
        }
    }

    /// Folds a kernel's hits into the best: its hit lanes (`mask`, values in `h`) as they are,
    /// its `redo` lanes through the scalar test. `vertices(lane)` and `id(lane)` give a lane's
    /// triangle.
    #[inline(always)]
    pub fn take(
        &mut self,
        ray: &Ray,
        (mask, redo): (u32, u32),
        h: &LaneHits,
        vertices: impl Fn(usize) -> [Vec3; 3],
        id: impl Fn(usize) -> u32,
    ) {
        let mut m = mask;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            self.offer(h.t[l], [h.b[0][l], h.b[1][l], h.b[2][l]], id(l));
        }
        let mut m = redo;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if let Some(s) = intersect_watertight(ray, &vertices(l), self.tri_t_max) {
                self.offer(s.t, s.b, id(l));
            }
        }
    }
}

/// Folds the closest hit among consecutive `blocks` (whose lanes' scene indices are `ids`) into
/// `c`: two blocks per step where there are two.
#[inline(always)]
pub(crate) fn blocks_closest<P: Path>(
    blocks: &[Tri4],
    ids: &[u32],
    ray: &Ray,
    r: &RayLanes,
    c: &mut Closest,
) {
    let mut h = LaneHits::ZERO;
    let mut b = 0;
    while b < blocks.len() {
        let (masks, n) = if b + 1 < blocks.len() {
            let two = &blocks[b..b + 2];
            (block_hits::<P::Eight>(two, r, c.tri_t_max, &mut h), 2)
        } else {
            let one = &blocks[b..b + 1];
            (block_hits::<P::Four>(one, r, c.tri_t_max, &mut h), 1)
        };
        if (masks.0 | masks.1) != 0 {
            c.take(
                ray,
                masks,
                &h,
                |l| blocks[b + l / LANES].vertices(l % LANES),
                |l| ids[b * LANES + l],
            );
        }
        b += n;
    }
}

/// Whether a triangle of `blocks` has a hit before `t_max`.
#[inline(always)]
pub(crate) fn blocks_occluded<P: Path>(
    blocks: &[Tri4],
    ray: &Ray,
    r: &RayLanes,
    t_max: f32,
) -> bool {
    // Written by the kernels, never read: an any-hit query needs only the masks (where the
    // kernels inline, the stores and the barycentrics they would need are dropped).
    let mut unused = LaneHits::ZERO;
    let mut b = 0;
    while b < blocks.len() {
        let ((mask, redo), n) = if b + 1 < blocks.len() {
            let two = &blocks[b..b + 2];
            (block_hits::<P::Eight>(two, r, t_max, &mut unused), 2)
        } else {
            let one = &blocks[b..b + 1];
            (block_hits::<P::Four>(one, r, t_max, &mut unused), 1)
        };
        if mask != 0 {
            return true;
        }
        let mut m = redo;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let v = blocks[b + l / LANES].vertices(l % LANES);
            if intersect_watertight(ray, &v, t_max).is_some() {
                return true;
            }
        }
        b += n;
    }
    false
}
