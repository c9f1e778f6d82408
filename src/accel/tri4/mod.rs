//! Triangles four at a time: vertices as structure of arrays ([`Tri4`]), and the watertight
//! test of one ray against four (SSE2) or eight (AVX2) triangles at once.
//!
//! # Bit-identical to the scalar test, by construction
//!
//! The SIMD kernels run the whole of [`intersect_watertight`] lane by lane — the sheared
//! vertices, the edge functions, the sign test, the determinant, the range of `t·det`, `t`,
//! its error bound ([`crate::geometry::t_error_bound`]) and the barycentrics — with the same
//! `f32` operations in the same order (no fused multiply-add: the AVX2 path enables `avx2`
//! only, not `fma`; IEEE division and square-free arithmetic round the same on every path).
//! So a lane the kernel accepts carries the scalar test's own `t` and barycentrics, bit for
//! bit, and a lane it rejects is one the scalar test rejects. The one exception is a lane whose
//! edge function rounds to exactly 0: the scalar test redoes its edges in `f64`, so the kernel
//! hands that lane back (`redo`) and the search runs [`intersect_watertight`] on it.
//! `tests/simd_kernels.rs` holds every path to the scalar test over the stability suite's and
//! the accel tests' rays: accepted lanes, `t` and barycentrics bit for bit.
//!
//! # Which path
//!
//! [`Isa::detect`] picks the widest the CPU has at run time: AVX2 (eight lanes: two blocks per
//! step), else SSE2 (four lanes; part of every x86-64), else the portable path, which runs the
//! scalar test one lane at a time. No `target-cpu` is needed or committed.

use glam::Vec3;

use super::box4::Box4;
use super::hit::Hit;
use crate::geometry::{Ray, RayTile};
use crate::simd::Isa;

mod portable;
mod search;
#[cfg(target_arch = "x86_64")]
pub mod shadow;
#[cfg(target_arch = "x86_64")]
mod x86;

pub(crate) use search::{Closest, blocks_closest, blocks_occluded};

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

/// What a kernel found in one or two blocks (lanes 4-7 from the second).
#[derive(Clone, Copy, Debug)]
pub struct Hits {
    /// Bit `i` set: lane `i` is hit, at `t[i]` with barycentrics `b[..][i]`, exactly as
    /// [`intersect_watertight`] computes them.
    pub mask: u32,
    /// Bit `i` set: lane `i`'s edge function rounded to 0, so the scalar test redoes it in
    /// `f64`; the kernel says nothing else about it.
    pub redo: u32,
    /// Each hit lane's `t` (meaningless elsewhere).
    pub t: [f32; 2 * LANES],
    /// Each hit lane's barycentric weights of `v0`, `v1`, `v2` (meaningless elsewhere).
    pub b: [[f32; 2 * LANES]; 3],
}

impl Hits {
    /// No lane hit, none to redo.
    pub const NONE: Hits = Hits {
        mask: 0,
        redo: 0,
        t: [0.0; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
    };

    /// The masks a kernel returned and the lanes it wrote.
    fn of((mask, redo): (u32, u32), lanes: &LaneHits) -> Hits {
        Hits {
            mask,
            redo,
            t: lanes.t,
            b: lanes.b,
        }
    }
}

/// Where a kernel writes its hit lanes' `t` and barycentrics (lanes 4-7 from a second block):
/// written only when some lane is hit, meaningful only in hit lanes. The masks themselves
/// are returned (in registers), so that a traversal that inlines the kernel tests them
/// without a round trip through memory, and an any-hit query never reads this at all.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHits {
    pub t: [f32; 2 * LANES],
    pub b: [[f32; 2 * LANES]; 3],
}

impl LaneHits {
    /// Nothing written yet.
    pub const ZERO: LaneHits = LaneHits {
        t: [0.0; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
    };
}

/// Each of eight rays' closest hit so far: `t` (∞ for none yet), barycentrics and triangle.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Best8 {
    t: [f32; 2 * LANES],
    b: [[f32; 2 * LANES]; 3],
    id: [u32; 2 * LANES],
}

impl Best8 {
    /// No hit yet.
    pub const NONE: Best8 = Best8 {
        t: [f32::INFINITY; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
        id: [u32::MAX; 2 * LANES],
    };

    /// Takes `(t, b)` on triangle `id` for lane `l` if it is nearer than the lane's best.
    /// Triangles are offered in increasing order, so a tie keeps the lower index.
    #[inline]
    pub fn offer(&mut self, l: usize, t: f32, b: [f32; 3], id: u32) {
        if t < self.t[l] {
            self.t[l] = t;
            for (row, w) in self.b.iter_mut().zip(b) {
                row[l] = w;
            }
            self.id[l] = id;
        }
    }

    /// The first `out.len()` (at most 8) lanes' closest hits into `out`: each [`Best8::hit`],
    /// with AVX2 (where `avx2`) gathered lane by lane by a transposition.
    #[inline(always)]
    pub(crate) fn hits_into(&self, out: &mut [Option<Hit>], avx2: bool) {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: the caller passes `avx2` only where the CPU has AVX2.
            let q = unsafe { x86::best_lanes_avx2(self) };
            for ((h, &id), &[t, b0, b1, b2]) in out.iter_mut().zip(&self.id).zip(&q) {
                *h = if id == u32::MAX {
                    None
                } else {
                    Some(Hit {
                        t,
                        b: [b0, b1, b2],
                        triangle: id,
                    })
                };
            }
            return;
        }
        let _ = avx2;
        for (l, h) in out.iter_mut().enumerate() {
            *h = self.hit(l);
        }
    }

    /// Makes lane `l`'s closest hit `hit` (none: no hit).
    #[inline]
    pub fn set(&mut self, l: usize, hit: Option<Hit>) {
        match hit {
            Some(h) => {
                self.t[l] = h.t;
                for (row, w) in self.b.iter_mut().zip(h.b) {
                    row[l] = w;
                }
                self.id[l] = h.triangle;
            }
            None => {
                self.t[l] = f32::INFINITY;
                for row in &mut self.b {
                    row[l] = 0.0;
                }
                self.id[l] = u32::MAX;
            }
        }
    }

    /// Each lane's triangle, `u32::MAX` for none.
    #[inline]
    pub fn ids(&self) -> &[u32; 2 * LANES] {
        &self.id
    }

    /// Each lane's barycentric weights, by vertex (0 where there is no hit).
    #[inline]
    pub fn barycentrics(&self) -> &[[f32; 2 * LANES]; 3] {
        &self.b
    }

    /// Lane `l`'s closest hit.
    #[inline]
    pub fn hit(&self, l: usize) -> Option<Hit> {
        (self.id[l] != u32::MAX).then(|| Hit {
            t: self.t[l],
            b: [self.b[0][l], self.b[1][l], self.b[2][l]],
            triangle: self.id[l],
        })
    }
}

/// How a traversal tests blocks: one of the three paths, chosen by the type.
pub(crate) trait Kernel {
    /// Whether this is the AVX2 path (its helpers may use AVX2).
    const AVX2: bool = false;
    /// The hits in one block: `(mask, redo)` as in [`Hits`]; the hit lanes' `t` and
    /// barycentrics into `out` (lanes 0-3).
    fn one(block: &Tri4, ray: &Ray, r: &RayLanes, t_max: f32, out: &mut LaneHits) -> (u32, u32);
    /// The hits in two blocks (lanes 4-7 from `b`), as [`Kernel::one`].
    fn two(
        a: &Tri4,
        b: &Tri4,
        ray: &Ray,
        r: &RayLanes,
        t_max: f32,
        out: &mut LaneHits,
    ) -> (u32, u32);
    /// Which of four boxes the ray meets before `t_max`, and where it enters them.
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]);
    /// Triangle `id` (vertices `v`; `rel` relative to the rays' common origin in their axis
    /// order) against the rays of `tile` (which share their axes) eight at a time, folded into
    /// `best` (eight rays each, as many as the tile has packets of eight). Returns the rays
    /// the caller must test with the scalar test (its `f64` redo); bits from `tile.len()` on
    /// are meaningless.
    ///
    /// `sure`: the caller has proven that every ray of the tile that passes the test's sign
    /// and range checks also passes its error-bound checks (`flat/tile.rs`), which the SIMD
    /// paths then skip.
    fn rays(
        v: &[Vec3; 3],
        rel: &[[f32; 3]; 3],
        tile: &RayTile,
        t_max: f32,
        id: u32,
        sure: bool,
        best: &mut [Best8],
    ) -> u64;
}

/// The portable path.
pub(crate) struct Portable;

impl Kernel for Portable {
    #[inline(always)]
    fn one(block: &Tri4, ray: &Ray, _: &RayLanes, t_max: f32, out: &mut LaneHits) -> (u32, u32) {
        portable::hits(block, ray, t_max, out, 0)
    }
    #[inline(always)]
    fn two(
        a: &Tri4,
        b: &Tri4,
        ray: &Ray,
        _: &RayLanes,
        t_max: f32,
        out: &mut LaneHits,
    ) -> (u32, u32) {
        let (m0, r0) = portable::hits(a, ray, t_max, out, 0);
        let (m1, r1) = portable::hits(b, ray, t_max, out, LANES);
        (m0 | m1 << LANES, r0 | r1 << LANES)
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_portable(origin, inv_dir, t_max)
    }
    #[inline(always)]
    fn rays(
        v: &[Vec3; 3],
        _: &[[f32; 3]; 3],
        tile: &RayTile,
        t_max: f32,
        id: u32,
        _: bool,
        best: &mut [Best8],
    ) -> u64 {
        for l in 0..tile.len() {
            if let Some(h) = crate::geometry::intersect_watertight(&tile.ray(l), v, t_max) {
                best[l / 8].offer(l % 8, h.t, h.b, id);
            }
        }
        0
    }
}

/// The SSE2 path.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Sse2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Sse2 {
    #[inline(always)]
    fn one(block: &Tri4, _: &Ray, r: &RayLanes, t_max: f32, out: &mut LaneHits) -> (u32, u32) {
        x86::hits_sse2(block, r, t_max, out, 0)
    }
    #[inline(always)]
    fn two(
        a: &Tri4,
        b: &Tri4,
        _: &Ray,
        r: &RayLanes,
        t_max: f32,
        out: &mut LaneHits,
    ) -> (u32, u32) {
        let (m0, r0) = x86::hits_sse2(a, r, t_max, out, 0);
        let (m1, r1) = x86::hits_sse2(b, r, t_max, out, LANES);
        (m0 | m1 << LANES, r0 | r1 << LANES)
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_sse2(origin, inv_dir, t_max)
    }
    #[inline(always)]
    fn rays(
        _: &[Vec3; 3],
        rel: &[[f32; 3]; 3],
        tile: &RayTile,
        t_max: f32,
        id: u32,
        sure: bool,
        best: &mut [Best8],
    ) -> u64 {
        x86::rays_sse2(rel, tile, t_max, id, sure, best)
    }
}

/// The AVX2 path. Only used inside functions compiled with AVX2 enabled, which are only called
/// once [`Isa::Avx2`] is known to be available.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2 {
    const AVX2: bool = true;
    #[inline(always)]
    fn one(block: &Tri4, _: &Ray, r: &RayLanes, t_max: f32, out: &mut LaneHits) -> (u32, u32) {
        // The SSE2 kernel, VEX-encoded where it inlines (functions compiled for AVX2).
        x86::hits_sse2(block, r, t_max, out, 0)
    }
    #[inline(always)]
    fn two(
        a: &Tri4,
        b: &Tri4,
        _: &Ray,
        r: &RayLanes,
        t_max: f32,
        out: &mut LaneHits,
    ) -> (u32, u32) {
        // SAFETY: `Avx2` is only instantiated behind a check that the CPU has AVX2, inside
        // functions compiled for it (so the kernel inlines).
        unsafe { x86::hits2_avx2(a, b, r, t_max, out) }
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        b.enter_sse2(origin, inv_dir, t_max)
    }
    #[inline(always)]
    fn rays(
        _: &[Vec3; 3],
        rel: &[[f32; 3]; 3],
        tile: &RayTile,
        t_max: f32,
        id: u32,
        sure: bool,
        best: &mut [Best8],
    ) -> u64 {
        // SAFETY: `Avx2` is only instantiated behind a check that the CPU has AVX2.
        unsafe { x86::rays_avx2(rel, tile, t_max, id, sure, best) }
    }
}

/// The AVX-512 path: AVX2's kernels but for a tile's rays, sixteen lanes at a time. Only used
/// inside functions compiled with AVX-512 enabled, which are only called once [`Isa::Avx512`]
/// is known to be available.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx512;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx512 {
    const AVX2: bool = true;
    #[inline(always)]
    fn one(block: &Tri4, ray: &Ray, r: &RayLanes, t_max: f32, out: &mut LaneHits) -> (u32, u32) {
        Avx2::one(block, ray, r, t_max, out)
    }
    #[inline(always)]
    fn two(
        a: &Tri4,
        b: &Tri4,
        ray: &Ray,
        r: &RayLanes,
        t_max: f32,
        out: &mut LaneHits,
    ) -> (u32, u32) {
        Avx2::two(a, b, ray, r, t_max, out)
    }
    #[inline(always)]
    fn boxes(b: &Box4, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        Avx2::boxes(b, origin, inv_dir, t_max)
    }
    #[inline(always)]
    fn rays(
        _: &[Vec3; 3],
        rel: &[[f32; 3]; 3],
        tile: &RayTile,
        t_max: f32,
        id: u32,
        sure: bool,
        best: &mut [Best8],
    ) -> u64 {
        // SAFETY: `Avx512` is only instantiated behind a check that the CPU has AVX-512.
        unsafe { x86::rays_avx512(rel, tile, t_max, id, sure, best) }
    }
}

/// The hits of `ray` in one block on path `isa` (for tests and tools; traversals call the
/// kernels directly). `isa` must be available.
pub fn hits(isa: Isa, block: &Tri4, ray: &Ray, t_max: f32) -> Hits {
    assert!(
        isa.available(),
        "{} is not available on this CPU",
        isa.name()
    );
    let r = RayLanes::new(ray);
    let mut out = LaneHits::ZERO;
    let masks = match isa {
        Isa::Portable => Portable::one(block, ray, &r, t_max, &mut out),
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 => Sse2::one(block, ray, &r, t_max, &mut out),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: checked available above.
        Isa::Avx2 | Isa::Avx512 => unsafe { x86::hits_avx2_call(block, &r, t_max, &mut out) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!(),
    };
    Hits::of(masks, &out)
}

/// The hits of `ray` in two blocks on path `isa` (lanes 4-7 from `b`). `isa` must be available.
pub fn hits2(isa: Isa, a: &Tri4, b: &Tri4, ray: &Ray, t_max: f32) -> Hits {
    assert!(
        isa.available(),
        "{} is not available on this CPU",
        isa.name()
    );
    let r = RayLanes::new(ray);
    let mut out = LaneHits::ZERO;
    let masks = match isa {
        Isa::Portable => Portable::two(a, b, ray, &r, t_max, &mut out),
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 => Sse2::two(a, b, ray, &r, t_max, &mut out),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: checked available above.
        Isa::Avx2 | Isa::Avx512 => unsafe { x86::hits2_avx2_call(a, b, &r, t_max, &mut out) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!(),
    };
    Hits::of(masks, &out)
}
