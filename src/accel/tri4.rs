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

/// The candidates among `block`'s lanes, one lane at a time: the portable twin of the SIMD
/// kernels and the statement of what they compute.
pub fn candidates_portable(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    let [kx, ky, kz] = r.axes;
    let [ox, oy, oz] = r.origin;
    let [sx, sy, sz] = r.shear;
    let mut out = Candidates {
        mask: 0,
        t: [0.0; 2 * LANES],
    };
    for lane in 0..LANES {
        let v = &block.v;
        let mut x = [0f32; 3];
        let mut y = [0f32; 3];
        let mut z = [0f32; 3];
        for i in 0..3 {
            let (a, b, c) = (
                v[i][kx][lane] - ox,
                v[i][ky][lane] - oy,
                v[i][kz][lane] - oz,
            );
            x[i] = a + sx * c;
            y[i] = b + sy * c;
            z[i] = c;
        }
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        if e[0] == 0.0 || e[1] == 0.0 || e[2] == 0.0 {
            out.mask |= 1 << lane;
            out.t[lane] = f32::NEG_INFINITY;
            continue;
        }
        if (e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0) && (e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0) {
            continue;
        }
        let det = e[0] + e[1] + e[2];
        if det == 0.0 || det.is_nan() {
            continue;
        }
        let z = z.map(|z| sz * z);
        let t_scaled = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
        let bound = t_max * det;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < bound) {
            continue;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > bound) {
            continue;
        }
        out.mask |= 1 << lane;
        out.t[lane] = t_scaled * (1.0 / det);
    }
    out
}

/// The candidates of two blocks (lanes 0-3 from `a`, 4-7 from `b`), one lane at a time.
pub fn candidates2_portable(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    let (ca, cb) = (
        candidates_portable(a, r, t_max),
        candidates_portable(b, r, t_max),
    );
    let mut t = ca.t;
    t[LANES..].copy_from_slice(&cb.t[..LANES]);
    Candidates {
        mask: ca.mask | cb.mask << LANES,
        t,
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    //! The SSE2 and AVX2 kernels: [`super::candidates_portable`]'s operations, four or eight
    //! lanes at a time. Comparisons are ordered (false on NaN) like Rust's `<`, `>`, `==`.

    use std::arch::x86_64::*;

    use super::{Candidates, LANES, RayLanes, Tri4};

    /// [`super::candidates_portable`] with SSE2.
    #[inline(always)]
    pub fn candidates_sse2(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        // SAFETY: SSE2 is part of every x86-64; the loads read whole `[f32; 4]` arrays.
        unsafe {
            let [kx, ky, kz] = r.axes;
            let (ox, oy, oz) = (
                _mm_set1_ps(r.origin[0]),
                _mm_set1_ps(r.origin[1]),
                _mm_set1_ps(r.origin[2]),
            );
            let (sx, sy, sz) = (
                _mm_set1_ps(r.shear[0]),
                _mm_set1_ps(r.shear[1]),
                _mm_set1_ps(r.shear[2]),
            );
            let v = &block.v;
            let sheared = |i: usize| {
                let a = _mm_sub_ps(_mm_load_ps(v[i][kx].as_ptr()), ox);
                let b = _mm_sub_ps(_mm_load_ps(v[i][ky].as_ptr()), oy);
                let c = _mm_sub_ps(_mm_load_ps(v[i][kz].as_ptr()), oz);
                (
                    _mm_add_ps(a, _mm_mul_ps(sx, c)),
                    _mm_add_ps(b, _mm_mul_ps(sy, c)),
                    c,
                )
            };
            let (x0, y0, z0) = sheared(0);
            let (x1, y1, z1) = sheared(1);
            let (x2, y2, z2) = sheared(2);
            let e0 = _mm_sub_ps(_mm_mul_ps(x1, y2), _mm_mul_ps(y1, x2));
            let e1 = _mm_sub_ps(_mm_mul_ps(x2, y0), _mm_mul_ps(y2, x0));
            let e2 = _mm_sub_ps(_mm_mul_ps(x0, y1), _mm_mul_ps(y0, x1));
            let zero = _mm_setzero_ps();
            let any_zero = _mm_or_ps(
                _mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)),
                _mm_cmpeq_ps(e2, zero),
            );
            let any_neg = _mm_or_ps(
                _mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)),
                _mm_cmplt_ps(e2, zero),
            );
            let any_pos = _mm_or_ps(
                _mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)),
                _mm_cmpgt_ps(e2, zero),
            );
            let det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
            let t_scaled = _mm_add_ps(
                _mm_add_ps(
                    _mm_mul_ps(e0, _mm_mul_ps(sz, z0)),
                    _mm_mul_ps(e1, _mm_mul_ps(sz, z1)),
                ),
                _mm_mul_ps(e2, _mm_mul_ps(sz, z2)),
            );
            let bound = _mm_mul_ps(_mm_set1_ps(t_max), det);
            // Rejected as the scalar test rejects: mixed signs, a zero or NaN det, or t·det
            // outside (0, t_max·det] (on det's side). A NaN t·det is not rejected here.
            let reject = _mm_or_ps(
                _mm_or_ps(
                    _mm_and_ps(any_neg, any_pos),
                    _mm_or_ps(_mm_cmpeq_ps(det, zero), _mm_cmpunord_ps(det, det)),
                ),
                _mm_or_ps(
                    _mm_and_ps(
                        _mm_cmplt_ps(det, zero),
                        _mm_or_ps(_mm_cmpge_ps(t_scaled, zero), _mm_cmplt_ps(t_scaled, bound)),
                    ),
                    _mm_and_ps(
                        _mm_cmpgt_ps(det, zero),
                        _mm_or_ps(_mm_cmple_ps(t_scaled, zero), _mm_cmpgt_ps(t_scaled, bound)),
                    ),
                ),
            );
            let mask = (!_mm_movemask_ps(reject) as u32 & 0xf) | _mm_movemask_ps(any_zero) as u32;
            let mut out = Candidates {
                mask,
                t: [0.0; 2 * LANES],
            };
            if mask != 0 {
                let mut ts = [0f32; LANES];
                let mut d = [0f32; LANES];
                _mm_storeu_ps(ts.as_mut_ptr(), t_scaled);
                _mm_storeu_ps(d.as_mut_ptr(), det);
                let zero_mask = _mm_movemask_ps(any_zero) as u32;
                out.fill_t(mask, zero_mask, &ts, &d, 0);
            }
            out
        }
    }

    /// Two blocks with SSE2, one after the other.
    #[inline(always)]
    pub fn candidates2_sse2(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        let (ca, cb) = (candidates_sse2(a, r, t_max), candidates_sse2(b, r, t_max));
        let mut t = ca.t;
        t[LANES..].copy_from_slice(&cb.t[..LANES]);
        Candidates {
            mask: ca.mask | cb.mask << LANES,
            t,
        }
    }

    /// Two blocks at once with AVX2: lanes 0-3 from `a`, 4-7 from `b`.
    ///
    /// # Safety
    /// The CPU must have AVX2 ([`super::Isa::Avx2`] available).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub unsafe fn candidates2_avx2(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        // SAFETY (of the loads): each reads a whole `[f32; 4]`, 16-byte aligned.
        unsafe {
            let [kx, ky, kz] = r.axes;
            let load = |i: usize, axis: usize| {
                _mm256_insertf128_ps(
                    _mm256_castps128_ps256(_mm_load_ps(a.v[i][axis].as_ptr())),
                    _mm_load_ps(b.v[i][axis].as_ptr()),
                    1,
                )
            };
            let (ox, oy, oz) = (
                _mm256_set1_ps(r.origin[0]),
                _mm256_set1_ps(r.origin[1]),
                _mm256_set1_ps(r.origin[2]),
            );
            let (sx, sy, sz) = (
                _mm256_set1_ps(r.shear[0]),
                _mm256_set1_ps(r.shear[1]),
                _mm256_set1_ps(r.shear[2]),
            );
            let sheared = |i: usize| {
                let p = _mm256_sub_ps(load(i, kx), ox);
                let q = _mm256_sub_ps(load(i, ky), oy);
                let c = _mm256_sub_ps(load(i, kz), oz);
                (
                    _mm256_add_ps(p, _mm256_mul_ps(sx, c)),
                    _mm256_add_ps(q, _mm256_mul_ps(sy, c)),
                    c,
                )
            };
            let (x0, y0, z0) = sheared(0);
            let (x1, y1, z1) = sheared(1);
            let (x2, y2, z2) = sheared(2);
            let e0 = _mm256_sub_ps(_mm256_mul_ps(x1, y2), _mm256_mul_ps(y1, x2));
            let e1 = _mm256_sub_ps(_mm256_mul_ps(x2, y0), _mm256_mul_ps(y2, x0));
            let e2 = _mm256_sub_ps(_mm256_mul_ps(x0, y1), _mm256_mul_ps(y0, x1));
            let zero = _mm256_setzero_ps();
            let cmp3 = |f: fn(__m256, __m256) -> __m256| {
                _mm256_or_ps(_mm256_or_ps(f(e0, zero), f(e1, zero)), f(e2, zero))
            };
            let any_zero = cmp3(|a, b| _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b));
            let any_neg = cmp3(|a, b| _mm256_cmp_ps::<_CMP_LT_OQ>(a, b));
            let any_pos = cmp3(|a, b| _mm256_cmp_ps::<_CMP_GT_OQ>(a, b));
            let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
            let t_scaled = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(e0, _mm256_mul_ps(sz, z0)),
                    _mm256_mul_ps(e1, _mm256_mul_ps(sz, z1)),
                ),
                _mm256_mul_ps(e2, _mm256_mul_ps(sz, z2)),
            );
            let bound = _mm256_mul_ps(_mm256_set1_ps(t_max), det);
            let reject = _mm256_or_ps(
                _mm256_or_ps(
                    _mm256_and_ps(any_neg, any_pos),
                    _mm256_or_ps(
                        _mm256_cmp_ps::<_CMP_EQ_OQ>(det, zero),
                        _mm256_cmp_ps::<_CMP_UNORD_Q>(det, det),
                    ),
                ),
                _mm256_or_ps(
                    _mm256_and_ps(
                        _mm256_cmp_ps::<_CMP_LT_OQ>(det, zero),
                        _mm256_or_ps(
                            _mm256_cmp_ps::<_CMP_GE_OQ>(t_scaled, zero),
                            _mm256_cmp_ps::<_CMP_LT_OQ>(t_scaled, bound),
                        ),
                    ),
                    _mm256_and_ps(
                        _mm256_cmp_ps::<_CMP_GT_OQ>(det, zero),
                        _mm256_or_ps(
                            _mm256_cmp_ps::<_CMP_LE_OQ>(t_scaled, zero),
                            _mm256_cmp_ps::<_CMP_GT_OQ>(t_scaled, bound),
                        ),
                    ),
                ),
            );
            let mask =
                (!_mm256_movemask_ps(reject) as u32 & 0xff) | _mm256_movemask_ps(any_zero) as u32;
            let mut out = Candidates {
                mask,
                t: [0.0; 2 * LANES],
            };
            if mask != 0 {
                let mut ts = [0f32; 2 * LANES];
                let mut d = [0f32; 2 * LANES];
                _mm256_storeu_ps(ts.as_mut_ptr(), t_scaled);
                _mm256_storeu_ps(d.as_mut_ptr(), det);
                let zero_mask = _mm256_movemask_ps(any_zero) as u32;
                out.fill_t(mask, zero_mask, &ts, &d, 0);
            }
            out
        }
    }

    /// One block on the AVX2 path: the SSE2 kernel (VEX-encoded in this context).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub unsafe fn candidates_avx2(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
        candidates_sse2(block, r, t_max)
    }
}

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
