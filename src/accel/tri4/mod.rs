//! Triangles four at a time: vertices as structure of arrays ([`Tri4`]), and the watertight
//! test of one ray against four (SSE2) or eight (AVX2) triangles at once.
//!
//! # Bit-identical to the scalar test, by construction
//!
//! The SIMD kernels do not replace [`intersect_watertight`]: they run its first steps lane by
//! lane — the sheared vertices, the three edge functions, the sign test, the determinant and
//! the range of `t·det` — with the same `f32` operations in the same order (no fused
//! multiply-add: the AVX2 path enables `avx2` only, not `fma`), and keep the lanes the scalar
//! test would not reject at those steps: the *candidates*. A lane whose edge function rounds to
//! exactly 0 is always a candidate, since the scalar test then redoes the edges in `f64`. Each
//! candidate is then confirmed by [`intersect_watertight`] itself, which computes the hit that is
//! reported. So a kernel can only differ from the scalar loop by rejecting a triangle the scalar
//! test accepts; `tests/simd_kernels.rs` holds every path to the scalar one over the stability
//! suite's and the accel tests' rays, and the candidates' `t` to the scalar `t` bit for bit.
//!
//! A candidate's `t` is also computed in SIMD (`t·det · (1/det)`, as the scalar test does), so
//! a closest-hit query confirms candidates nearest first and skips those that cannot beat the
//! best hit so far: one scalar confirmation per query in the common case.
//!
//! # Which path
//!
//! [`Isa::detect`] picks the widest the CPU has at run time: AVX2 (eight lanes: two blocks per
//! step), else SSE2 (four lanes; part of every x86-64), else the portable twin, which runs the
//! same operations one lane at a time. No `target-cpu` is needed or committed.

use glam::Vec3;

use super::box4::Box4;
use super::hit::{Hit, shrunk_t_max};
use super::isa::Isa;
use crate::geometry::{Ray, intersect_watertight};

mod portable;

pub use portable::{candidates_portable, candidates2_portable};

/// Triangles per [`Tri4`] block.
pub const LANES: usize = 4;

/// Four triangles' vertices, structure of arrays: `v[vertex][axis][lane]`. Unused lanes hold NaN,
/// which no test accepts (the determinant is NaN).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Tri4 {
    v: [[[f32; LANES]; 3]; 3],
}

/// Equal when every coordinate has the same bits (so the NaN padding compares equal).
impl PartialEq for Tri4 {
    fn eq(&self, o: &Tri4) -> bool {
        self.v
            .as_flattened()
            .as_flattened()
            .iter()
            .map(|x| x.to_bits())
            .eq(o
                .v
                .as_flattened()
                .as_flattened()
                .iter()
                .map(|x| x.to_bits()))
    }
}

impl Tri4 {
    /// A block with no triangle.
    pub const EMPTY: Tri4 = Tri4 {
        v: [[[f32::NAN; LANES]; 3]; 3],
    };

    /// A block of up to [`LANES`] triangles, in order.
    pub fn new(triangles: &[[Vec3; 3]]) -> Tri4 {
        assert!(triangles.len() <= LANES, "a Tri4 holds at most 4 triangles");
        let mut block = Tri4::EMPTY;
        for (lane, t) in triangles.iter().enumerate() {
            for (vertex, p) in t.iter().enumerate() {
                for axis in 0..3 {
                    block.v[vertex][axis][lane] = p[axis];
                }
            }
        }
        block
    }

    /// Blocks holding `triangles` in order, the last one padded.
    pub fn pack(triangles: impl ExactSizeIterator<Item = [Vec3; 3]>) -> Vec<Tri4> {
        let mut blocks = Vec::with_capacity(triangles.len().div_ceil(LANES));
        let mut chunk = Vec::with_capacity(LANES);
        for t in triangles {
            chunk.push(t);
            if chunk.len() == LANES {
                blocks.push(Tri4::new(&chunk));
                chunk.clear();
            }
        }
        if !chunk.is_empty() {
            blocks.push(Tri4::new(&chunk));
        }
        blocks
    }

    /// The vertices in `lane` (NaN for an unused lane).
    #[inline]
    pub fn vertices(&self, lane: usize) -> [Vec3; 3] {
        let v = &self.v;
        [0, 1, 2].map(|i| Vec3::new(v[i][0][lane], v[i][1][lane], v[i][2][lane]))
    }
}

/// A ray's constants as the kernels read them: the origin and each vertex axis in the ray's
/// permuted order (`kx`, `ky`, `kz`), and the shear.
#[derive(Clone, Copy, Debug)]
pub struct RayLanes {
    axes: [usize; 3],
    origin: [f32; 3],
    shear: [f32; 3],
}

impl RayLanes {
    /// The constants of `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> RayLanes {
        let axes = ray.axes();
        RayLanes {
            axes,
            origin: axes.map(|a| ray.origin[a]),
            shear: ray.shear(),
        }
    }
}

/// The candidates of a step: a bit per lane, and each lane's `t` (−∞ where the scalar test
/// redoes the edges in `f64` and `t` is not known yet; meaningless where the bit is clear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidates {
    /// Bit `i` set: lane `i` may hit.
    pub mask: u32,
    /// Lane `i`'s `t`, as the scalar test computes it.
    pub t: [f32; 2 * LANES],
}

impl Candidates {
    /// Sets the `t` of the candidate lanes in `mask` from their `t·det` and `det` (lanes
    /// from `first`), as the scalar test computes it; −∞ for lanes in `zero`.
    #[inline(always)]
    fn fill_t(&mut self, mask: u32, zero: u32, t_scaled: &[f32], det: &[f32], first: usize) {
        let mut m = mask;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            self.t[first + l] = if zero & (1 << l) != 0 {
                f32::NEG_INFINITY
            } else {
                t_scaled[l] * (1.0 / det[l])
            };
            m &= m - 1;
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86;

/// How a traversal tests blocks: one of the three paths, chosen by the type.
pub(crate) trait Kernel {
    /// The candidates of one block.
    fn one(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates;
    /// The candidates of two blocks (lanes 4-7 from `b`).
    fn two(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates;
    /// Which of four boxes the ray meets before `t_max`, and where it enters them.
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]);
}

/// The portable path.
pub(crate) struct Portable;

impl Kernel for Portable {
    #[inline(always)]
    fn one(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        candidates_portable(block, r, t_max)
    }
    #[inline(always)]
    fn two(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        candidates2_portable(a, b, r, t_max)
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_portable(origin, inv_dir, t_max)
    }
}

/// The SSE2 path.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Sse2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Sse2 {
    #[inline(always)]
    fn one(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        x86::candidates_sse2(block, r, t_max)
    }
    #[inline(always)]
    fn two(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        x86::candidates2_sse2(a, b, r, t_max)
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_sse2(origin, inv_dir, t_max)
    }
}

/// The AVX2 path. Only used inside functions compiled with AVX2 enabled, which are only called
/// once [`Isa::Avx2`] is known to be available.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2 {
    #[inline(always)]
    fn one(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        // SAFETY: `Avx2` is only instantiated behind a check that the CPU has AVX2.
        unsafe { x86::candidates_avx2(block, r, t_max) }
    }
    #[inline(always)]
    fn two(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        // SAFETY: as above.
        unsafe { x86::candidates2_avx2(a, b, r, t_max) }
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_sse2(origin, inv_dir, t_max)
    }
}

/// The candidates of one block on path `isa` (for tests and tools; traversals call the kernels
/// directly). `isa` must be available.
pub fn candidates(isa: Isa, block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    assert!(
        isa.available(),
        "{} is not available on this CPU",
        isa.name()
    );
    match isa {
        Isa::Portable => candidates_portable(block, r, t_max),
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 => x86::candidates_sse2(block, r, t_max),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: checked available above.
        Isa::Avx2 => unsafe { x86::candidates_avx2(block, r, t_max) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!(),
    }
}

/// The candidates of two blocks on path `isa` (lanes 4-7 from `b`). `isa` must be available.
pub fn candidates2(isa: Isa, a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    assert!(
        isa.available(),
        "{} is not available on this CPU",
        isa.name()
    );
    match isa {
        Isa::Portable => candidates2_portable(a, b, r, t_max),
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 => x86::candidates2_sse2(a, b, r, t_max),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: checked available above.
        Isa::Avx2 => unsafe { x86::candidates2_avx2(a, b, r, t_max) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!(),
    }
}

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

    /// Confirms `c`'s candidates nearest first with the scalar test, skipping those that cannot
    /// beat the best hit. `vertices(lane)` and `id(lane)` give a lane's triangle.
    #[inline(always)]
    pub fn take(
        &mut self,
        ray: &Ray,
        mut c: Candidates,
        vertices: impl Fn(usize) -> [Vec3; 3],
        id: impl Fn(usize) -> u32,
    ) {
        while c.mask != 0 {
            // The lowest t among the candidates (ties: the lowest lane).
            let mut lane = c.mask.trailing_zeros() as usize;
            let mut m = c.mask & (c.mask - 1);
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                if c.t[l] < c.t[lane] {
                    lane = l;
                }
                m &= m - 1;
            }
            c.mask &= !(1 << lane);
            let (t, i) = (c.t[lane], id(lane));
            // A lane whose t is known and cannot beat the best: the scalar test would give the
            // same t, so skip it.
            if let Some(b) = self.best
                && t != f32::NEG_INFINITY
                && (t > b.t || t == b.t && i > b.triangle)
            {
                continue;
            }
            let Some(h) = intersect_watertight(ray, &vertices(lane), self.tri_t_max) else {
                continue;
            };
            if self
                .best
                .is_none_or(|b| h.t < b.t || h.t == b.t && i < b.triangle)
            {
                self.best = Some(Hit {
                    t: h.t,
                    b: h.b,
                    triangle: i,
                });
                self.tri_t_max = shrunk_t_max(h.t, self.t_max);
            }
        }
    }
}

/// Whether any candidate of `c` is confirmed by the scalar test with `t_max`.
#[inline(always)]
pub(crate) fn any_confirmed(
    ray: &Ray,
    c: Candidates,
    t_max: f32,
    vertices: impl Fn(usize) -> [Vec3; 3],
) -> bool {
    let mut m = c.mask;
    while m != 0 {
        let lane = m.trailing_zeros() as usize;
        if intersect_watertight(ray, &vertices(lane), t_max).is_some() {
            return true;
        }
        m &= m - 1;
    }
    false
}

/// Folds the closest hit among consecutive `blocks` (whose lanes' scene indices are `ids`) into
/// `c`: two blocks per step where there are two.
#[inline(always)]
pub(crate) fn blocks_closest<K: Kernel>(
    blocks: &[Tri4],
    ids: &[u32],
    ray: &Ray,
    r: &RayLanes,
    c: &mut Closest,
) {
    let mut b = 0;
    while b < blocks.len() {
        let (cand, n) = if b + 1 < blocks.len() {
            (K::two(&blocks[b], &blocks[b + 1], r, c.tri_t_max), 2)
        } else {
            (K::one(&blocks[b], r, c.tri_t_max), 1)
        };
        if cand.mask != 0 {
            c.take(
                ray,
                cand,
                |l| blocks[b + l / LANES].vertices(l % LANES),
                |l| ids[b * LANES + l],
            );
        }
        b += n;
    }
}

/// Whether a triangle of `blocks` has a hit before `t_max`.
#[inline(always)]
pub(crate) fn blocks_occluded<K: Kernel>(
    blocks: &[Tri4],
    ray: &Ray,
    r: &RayLanes,
    t_max: f32,
) -> bool {
    let mut b = 0;
    while b < blocks.len() {
        let (cand, n) = if b + 1 < blocks.len() {
            (K::two(&blocks[b], &blocks[b + 1], r, t_max), 2)
        } else {
            (K::one(&blocks[b], r, t_max), 1)
        };
        if cand.mask != 0
            && any_confirmed(ray, cand, t_max, |l| {
                blocks[b + l / LANES].vertices(l % LANES)
            })
        {
            return true;
        }
        b += n;
    }
    false
}
