//! Tiles of camera rays through the flat list: rays that share an origin and axes, tested a
//! triangle at a time against eight rays at once, after a cull that drops the triangles no
//! ray of the tile can hit.
//!
//! # The same hits as one ray at a time
//!
//! Each ray's answer is what testing every triangle gives (the smallest `t`, ties to the lowest
//! index, each triangle tested with the query's `t_max`), as the per-ray query's is: the
//! ray-lane kernels run the scalar test's operations lane by lane, triangles are taken in
//! index order, and a lane keeps a new hit only when it is strictly nearer. The cull may only
//! drop a triangle the scalar test rejects for every ray of the tile, by its sign test:
//!
//! With the rays' common origin `o`, a vertex relative to it, `(a, b, z) = v − o` in the rays'
//! axis order, is the same `f32` for every ray, and only the shear `(sx, sy)` varies. In exact
//! arithmetic on those values, edge function `eᵢ = xⱼ·yₖ − yⱼ·xₖ` with `x = a + sx·z`,
//! `y = b + sy·z` is affine in `(sx, sy)` (the `sx·sy` terms cancel):
//! `eᵢ = (aⱼbₖ − bⱼaₖ) + sx·(zⱼbₖ − bⱼzₖ) + sy·(aⱼzₖ − zⱼaₖ)`, so over the box of the tile's
//! shears its extremes are at the corners. The scalar test's `eᵢ` (in `f32`, or redone in `f64`)
//! is within `EdgeErrors`' bound of that exact value; the cull uses four times that bound,
//! taken over the whole box, plus an absolute term for underflow. If some `eᵢ` is below minus
//! that margin over the whole box and some `eⱼ` above it, every ray of the tile computes mixed
//! signs, which the scalar test rejects: the triangle is dropped. Anything else (a margin that
//! is not finite, a tile whose rays do not share origin and axes) keeps the triangle or falls
//! back to one ray at a time.
//!
//! # Skipping the error bound where it provably passes
//!
//! After the sign and range tests, the scalar test accepts a hit only if its determinant's
//! sign is certain (`|det| > Σ δeᵢ`, the edges' error bounds `EdgeErrors`) and `t` is beyond
//! its error bound `Δt = 2·(2γ₃·max|zsᵢ| + γ₃·t + W)`, `W` the weights' error
//! (`t_error_bound`). [`sure`] proves, from a triangle's affine data over the tile, that both
//! pass for every ray of the tile that passes the sign and range tests; the kernel then skips
//! computing them (debug builds compute them and assert it on every such packet). With `M` the
//! sum of the edges' cull margins (each four times the bound on `|eᵢ − exact eᵢ|`, for shears
//! up to the cache's bound), `D` the least `|c + sx·p + sy·q|` of the determinant's exact
//! affine form over the shear box (0 if it changes sign), `n`, `f` the nearest and farthest
//! vertex depth along the rays (`z` in the rays' axis order, its sign flipped when `sz < 0`),
//! and `s₋`, `s₊` the least and largest `|sz|` of the tile, [`sure`] requires
//! `D ≥ 2M`, `D ≥ 2⁻⁴⁰`, `n > 0`, `s₋·n ≥ 2⁻⁵⁹`, no overflow (`M`, `M·s₊f` ≤ 2¹⁰⁰), and
//! `s₋n·(1 − 2⁻²³)(1 − 2⁻¹⁹) > 2.02·(3.01γ₃ + 9M/D)·s₊f·(1 + 2⁻²³)`. Then, for a lane that
//! passes the sign and range tests (all `eᵢ` of one sign, `u` = 2⁻²⁴):
//! - The computed `δeᵢ` are sums of non-negative terms, each within `(1 + γ₁₀)` of the cull's
//!   value at the largest `|x|`, `|y|` the shears allow: `Σ δeᵢ ≤ 0.26·M`. The computed edges
//!   are within `M/4` of exact in sum, so `|det| ≥ (D − M/4)(1 − u)² ≥ 0.87·D`: the sign is
//!   certain, and `|det| − Σ δe ≥ 0.7·D`.
//! - Every `zsᵢ = fl(sz·zᵢ) ≥ m = fl(sz·near) ≥ s₋n(1 − u) > 0`. With all `eᵢ·zsᵢ` of one sign,
//!   rounding is monotone, each product carries `(1 ± u)` and at most `2⁻¹⁵⁰` absolute (the
//!   sums add no absolute error), `det ≤ Σeᵢ(1 + u)²`, and `1/det` rounds within 2⁻²²
//!   relative (subnormal included): `t ≥ m(1 − 2.5·2⁻²²) − 3·2⁻¹⁵⁰/|det| − 2⁻¹⁵⁰`, and with
//!   `|det| ≥ 2⁻⁴¹`, `m ≥ 2⁻⁶⁰` that is `> m(1 − 2⁻²⁰)`. Likewise `t ≤ 1.01·max|zsᵢ|`.
//! - Each weight `|bᵢ| ≤ 1.01`, each spread `|zsᵢ − t| + γ₃·max|zs| ≤ 2.03·max|zs|`, so the
//!   weights' error `W ≤ 4.03·0.26M·2.03·max|zs| / (0.7·D) ≤ 3.1·M·max|zs|/D`, and
//!   `Δt ≤ 2.001·(3.01γ₃ + 3.1M/D)·max|zs|` with `max|zs| ≤ s₊f(1 + u)`: below the
//!   condition's right side, which is below `t`.
//!
//! `tests/simd_kernels.rs` (`tiles_near_the_error_bound_match_brute_force`: origins just off a
//! triangle's plane, triangles seen from close to a vertex) fails when either the determinant's
//! or `t`'s requirement is dropped.
//!
//! # Where the work goes
//!
//! Per camera ([`TileCache`]): the triangles relative to the origin, their edges' affine
//! coefficients and margins, also four triangles at a time in `f64` lanes. Per tile: the cull
//! (with AVX2 four triangles per step, the scalar cull's `f64` operations on the same values,
//! so the same triangles kept; debug builds check it), then each kept triangle's lanes are set
//! up once and tested against the tile's packets of eight rays in turn.

use glam::Vec3;

use super::Flat;
use crate::accel::hit::Hit;
use crate::accel::tri4::{Best8, BestTile, rays};
use crate::geometry::{Ray, RayTile, TILE_RAYS, gamma, intersect_watertight};
use crate::simd::Path;

/// Flat lists of more triangles than this answer tiles one ray at a time: the cull looks at
/// every triangle once per tile, which pays while triangles are few.
const TILE_TRIANGLES: usize = 64;

const _: () = assert!(TILE_TRIANGLES <= 64, "kept triangles are bits of a u64");

/// What the flat list keeps between tiles of one camera: each triangle relative to the rays'
/// common origin, with its edge functions' affine coefficients and cull margins. Start with
/// `TileCache::default()` and pass the same one for every tile of a frame (or of a band).
#[derive(Clone, Debug, Default)]
pub struct TileCache {
    /// The origin (bits) and axes the triangles are relative to.
    key: Option<([u32; 3], [usize; 3])>,
    /// The largest |sx|, |sy| the margins hold for.
    bound: (f32, f32),
    tris: Vec<TileTri>,
    /// The triangles' edge coefficients and margins four at a time, for the SIMD cull
    /// (padding lanes: zero coefficients, NaN margins).
    quads: Vec<CullQuad>,
    /// The closest hits of the tile being traced (kept here: cleared only as far as a tile
    /// reaches).
    best: BestTile,
}

/// Four triangles' `c`, `p`, `q` and `margin` (as in [`TileTri`]), per edge, lane by lane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct CullQuad {
    c: [[f64; 4]; 3],
    p: [[f64; 4]; 3],
    q: [[f64; 4]; 3],
    margin: [[f64; 4]; 3],
}

/// One triangle as the cull sees it.
#[derive(Clone, Copy, Debug)]
struct TileTri {
    /// Vertices relative to the origin, in the rays' axis order.
    rel: [[f32; 3]; 3],
    v: [Vec3; 3],
    id: u32,
    /// Per edge: `e = c + sx·p + sy·q` in exact arithmetic.
    c: [f64; 3],
    p: [f64; 3],
    q: [f64; 3],
    /// Per edge: the bound on the scalar test's error in `e` for any shear within `bound`
    /// (times four); NaN when not finite (then the triangle is never culled).
    margin: [f64; 3],
    /// The determinant `Σeᵢ` as `c + sx·p + sy·q` (the edges' coefficients summed), and the
    /// sum of the edges' margins.
    det: [f64; 3],
    det_margin: f64,
    /// The smallest and largest vertex depth along the rays' main axis (`z`).
    z_range: (f32, f32),
}

/// The smallest power of two ≥ `x` (for `x` ≥ 0, finite), so that the margins are rebuilt
/// only a few times per frame.
fn power_of_two_above(x: f32) -> f32 {
    let x = x.max(f32::MIN_POSITIVE);
    f32::from_bits((x.to_bits() + 0x7f_ffff) & 0xff80_0000)
}

impl TileCache {
    /// Makes the cache hold `f`'s triangles relative to `origin` with `axes`, with margins for
    /// shears up to at least (`smx`, `smy`).
    fn prepare(&mut self, f: &Flat, origin: Vec3, axes: [usize; 3], smx: f32, smy: f32) {
        let key = Some((origin.to_array().map(f32::to_bits), axes));
        if self.key == key && smx <= self.bound.0 && smy <= self.bound.1 {
            return;
        }
        if self.key != key {
            self.bound = (0.0, 0.0);
        }
        self.key = key;
        self.bound = (
            power_of_two_above(smx.max(self.bound.0)),
            power_of_two_above(smy.max(self.bound.1)),
        );
        let [kx, ky, kz] = axes;
        let (smx, smy) = (self.bound.0 as f64, self.bound.1 as f64);
        self.tris.clear();
        self.tris.extend(f.tris.iter().map(|&(v, id)| {
            let rel = [0, 1, 2].map(|j| {
                let d = v[j] - origin;
                [d[kx], d[ky], d[kz]]
            });
            let mut t = TileTri {
                rel,
                v,
                id,
                c: [0.0; 3],
                p: [0.0; 3],
                q: [0.0; 3],
                margin: [0.0; 3],
                det: [0.0; 3],
                det_margin: 0.0,
                z_range: (0.0, 0.0),
            };
            edges(&rel, smx, smy, &mut t);
            t.det = [t.c, t.p, t.q].map(|e| e[0] + e[1] + e[2]);
            t.det_margin = t.margin[0] + t.margin[1] + t.margin[2];
            let z = rel.map(|v| v[2]);
            t.z_range = (z[0].min(z[1]).min(z[2]), z[0].max(z[1]).max(z[2]));
            t
        }));
        self.quads.clear();
        self.quads.extend(self.tris.chunks(4).map(|tris| {
            let mut quad = CullQuad {
                c: [[0.0; 4]; 3],
                p: [[0.0; 4]; 3],
                q: [[0.0; 4]; 3],
                margin: [[f64::NAN; 4]; 3],
            };
            for (l, t) in tris.iter().enumerate() {
                for e in 0..3 {
                    quad.c[e][l] = t.c[e];
                    quad.p[e][l] = t.p[e];
                    quad.q[e][l] = t.q[e];
                    quad.margin[e][l] = t.margin[e];
                }
            }
            quad
        }));
    }

    /// The triangles [`may_hit`] keeps for the shear box `sx` × `sy`, as bits in index order.
    fn kept(&self, sx: (f64, f64), sy: (f64, f64)) -> u64 {
        let mut kept = 0;
        for (i, t) in self.tris.iter().enumerate() {
            kept |= (may_hit(t, sx, sy) as u64) << i;
        }
        kept
    }

    /// [`TileCache::kept`] four triangles at a time with AVX2: the same operations on the same
    /// values (in `f64`), so the same bits.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn kept_avx2(&self, sx: (f64, f64), sy: (f64, f64)) -> u64 {
        use std::arch::x86_64::*;
        let (sx0, sx1) = (_mm256_set1_pd(sx.0), _mm256_set1_pd(sx.1));
        let (sy0, sy1) = (_mm256_set1_pd(sy.0), _mm256_set1_pd(sy.1));
        let sign = _mm256_set1_pd(-0.0);
        // SAFETY: reads four `f64`s, 32-byte aligned.
        let load = |v: &[f64; 4]| unsafe { _mm256_load_pd(v.as_ptr()) };
        let mut kept = 0;
        for (k, quad) in self.quads.iter().enumerate() {
            let (mut neg, mut pos) = (_mm256_setzero_pd(), _mm256_setzero_pd());
            for e in 0..3 {
                let (c, p, q) = (load(&quad.c[e]), load(&quad.p[e]), load(&quad.q[e]));
                let margin = load(&quad.margin[e]);
                let (px0, px1) = (_mm256_mul_pd(sx0, p), _mm256_mul_pd(sx1, p));
                let (qy0, qy1) = (_mm256_mul_pd(sy0, q), _mm256_mul_pd(sy1, q));
                let lo = _mm256_add_pd(
                    _mm256_add_pd(c, _mm256_min_pd(px0, px1)),
                    _mm256_min_pd(qy0, qy1),
                );
                let hi = _mm256_add_pd(
                    _mm256_add_pd(c, _mm256_max_pd(px0, px1)),
                    _mm256_max_pd(qy0, qy1),
                );
                let below = _mm256_cmp_pd::<_CMP_LT_OQ>(hi, _mm256_xor_pd(margin, sign));
                neg = _mm256_or_pd(neg, below);
                pos = _mm256_or_pd(pos, _mm256_cmp_pd::<_CMP_GT_OQ>(lo, margin));
            }
            let culled = _mm256_movemask_pd(_mm256_and_pd(neg, pos)) as u64;
            kept |= (!culled & 0xf) << (4 * k);
        }
        kept & (u64::MAX >> (64 - self.tris.len().max(1)))
    }
}

/// Fills `t`'s edge coefficients and margins for shears up to (`smx`, `smy`) in magnitude.
fn edges(rel: &[[f32; 3]; 3], smx: f64, smy: f64, t: &mut TileTri) {
    let (g2, g5) = (gamma(2) as f64, gamma(5) as f64);
    // The smallest subnormal `f32`: the absolute error of an operation that underflows.
    let tiny = f32::from_bits(1) as f64;
    let a = rel.map(|v| v[0] as f64);
    let b = rel.map(|v| v[1] as f64);
    let z = rel.map(|v| v[2] as f64);
    // Bounds on |x|, |y| over the shears and on their rounding errors.
    let xm = [0, 1, 2].map(|j| a[j].abs() + smx * z[j].abs());
    let ym = [0, 1, 2].map(|j| b[j].abs() + smy * z[j].abs());
    let dx = [0, 1, 2].map(|j| g5 * (xm[j] + 2.0 * smx * z[j].abs()) + 2.0 * tiny);
    let dy = [0, 1, 2].map(|j| g5 * (ym[j] + 2.0 * smy * z[j].abs()) + 2.0 * tiny);
    for (i, (j, k)) in [(1, 2), (2, 0), (0, 1)].into_iter().enumerate() {
        t.c[i] = a[j] * b[k] - b[j] * a[k];
        t.p[i] = z[j] * b[k] - b[j] * z[k];
        t.q[i] = a[j] * z[k] - z[j] * a[k];
        let margin = 4.0
            * (xm[j] * dy[k]
                + ym[k] * dx[j]
                + ym[j] * dx[k]
                + xm[k] * dy[j]
                + g2 * (xm[j] * ym[k] + ym[j] * xm[k]))
            + 4.0 * tiny;
        let finite =
            margin.is_finite() && t.c[i].is_finite() && t.p[i].is_finite() && t.q[i].is_finite();
        t.margin[i] = if finite { margin } else { f64::NAN };
    }
}

/// Whether a ray whose shear lies in the box `sx` × `sy` may pass the sign test of `t`. `false`
/// only when the scalar test computes mixed signs for every such ray (see the module's doc).
#[inline(always)]
fn may_hit(t: &TileTri, sx: (f64, f64), sy: (f64, f64)) -> bool {
    let (mut neg, mut pos) = (false, false);
    for i in 0..3 {
        let (p, q) = (t.p[i], t.q[i]);
        let (px0, px1, qy0, qy1) = (sx.0 * p, sx.1 * p, sy.0 * q, sy.1 * q);
        let lo = t.c[i] + px0.min(px1) + qy0.min(qy1);
        let hi = t.c[i] + px0.max(px1) + qy0.max(qy1);
        // A NaN margin (or bound) makes both false: kept.
        neg |= hi < -t.margin[i];
        pos |= lo > t.margin[i];
    }
    !(neg && pos)
}

/// The least `|det|` (over the tile's shears) [`sure`] accepts: keeps underflow out of the
/// bound on `t` (see the module's doc).
const DET_MIN: f64 = 1.0 / (1u64 << 40) as f64;

/// The least depth `sz·z` [`sure`] accepts, for the same reason.
const DEPTH_MIN: f64 = 1.0 / (1u64 << 59) as f64;

/// The largest `Σ margin` and `Σ margin·|sz·z|` [`sure`] accepts: no `f32` overflow in the
/// error bound's terms.
const TERM_MAX: f64 = (1u128 << 100) as f64;

/// Whether every ray of a tile (shears in the box `sx` × `sy`, `sz` in `sz`, all of one sign:
/// positive when `ahead`) that passes triangle `t`'s sign and range tests also passes the
/// error bound's two (see the module's doc), so that the kernel may skip them.
#[inline(always)]
fn sure(t: &TileTri, sx: (f64, f64), sy: (f64, f64), sz: (f32, f32), ahead: bool) -> bool {
    let (zlo, zhi) = (t.z_range.0 as f64, t.z_range.1 as f64);
    // Depths along the rays, as positive numbers when in front.
    let (near, far) = if ahead { (zlo, zhi) } else { (-zhi, -zlo) };
    let (s_lo, s_hi) = (
        sz.0.abs().min(sz.1.abs()) as f64,
        sz.0.abs().max(sz.1.abs()) as f64,
    );
    let [c, p, q] = t.det;
    let (px0, px1, qy0, qy1) = (sx.0 * p, sx.1 * p, sy.0 * q, sy.1 * q);
    let lo = c + px0.min(px1) + qy0.min(qy1);
    let hi = c + px0.max(px1) + qy0.max(qy1);
    let det = if lo > 0.0 {
        lo
    } else if hi < 0.0 {
        -hi
    } else {
        0.0
    };
    let m = t.det_margin;
    let (depth_lo, depth_hi) = (s_lo * near * (1.0 - ULP), s_hi * far * (1.0 + ULP));
    // Every comparison is false on NaN: not sure.
    let bounded = det >= 2.0 * m
        && det >= DET_MIN
        && depth_lo >= DEPTH_MIN
        && m <= TERM_MAX
        && m * depth_hi <= TERM_MAX;
    let delta_t = 2.02 * (3.01 * gamma(3) as f64 + 9.0 * m / det) * depth_hi;
    bounded && near > 0.0 && depth_lo * (1.0 - T_SHRINK) > delta_t
}

/// 2⁻²³: more than one rounding of an `f32`, relative.
const ULP: f64 = 1.0 / (1u64 << 23) as f64;

/// 2⁻¹⁹: how far below the nearest depth a hit's computed `t` can be, relative, with room.
const T_SHRINK: f64 = 1.0 / (1u64 << 19) as f64;

/// The closest hits of `tile`'s rays into `hits` (as many), each as [`Flat::intersect`] gives
/// it; a tile whose rays do not share their axes, or a list of too many triangles, is
/// answered one ray at a time by `one`.
#[inline(always)]
pub(super) fn intersect_tile<P: Path>(
    f: &Flat,
    tile: &RayTile,
    t_max: f32,
    hits: &mut [Option<Hit>],
    cache: &mut TileCache,
    one: impl Fn(&Ray) -> Option<Hit>,
) {
    debug_assert_eq!(tile.len(), hits.len());
    let mut best = [Best8::NONE; TILE_RAYS / 8];
    intersect_tile_best::<P>(f, tile, t_max, &mut best, cache, one);
    for (i, h) in hits.iter_mut().enumerate() {
        *h = best[i / 8].hit(i % 8);
    }
}

/// [`intersect_tile`], the hits left in `best` as the kernels make them: ray `i` is lane
/// `i % 8` of `best[i / 8]` (the rest of `best` is left as it was).
#[inline(always)]
pub(super) fn intersect_tile_best<P: Path>(
    f: &Flat,
    tile: &RayTile,
    t_max: f32,
    best: &mut [Best8; TILE_RAYS / 8],
    cache: &mut TileCache,
    one: impl Fn(&Ray) -> Option<Hit>,
) {
    let n = tile.len();
    let axes = match tile.axes() {
        Some(axes) if f.tris.len() <= TILE_TRIANGLES && n > 0 => axes,
        _ => {
            for i in 0..n {
                best[i / 8].set(i % 8, one(&tile.ray(i)));
            }
            return;
        }
    };
    // The box of the tile's shears.
    let [sx0, sx1, sy0, sy1, sz0, sz1] = tile.shear_box();
    cache.prepare(
        f,
        tile.origin(),
        axes,
        sx0.abs().max(sx1.abs()),
        sy0.abs().max(sy1.abs()),
    );
    let (sx, sy) = ((sx0 as f64, sx1 as f64), (sy0 as f64, sy1 as f64));
    let packets = n.div_ceil(8);
    let lanes = if n == TILE_RAYS {
        u64::MAX
    } else {
        (1 << n) - 1
    };
    // The triangles that survive the cull, in index order.
    #[cfg(target_arch = "x86_64")]
    let mut kept = if P::AVX {
        // SAFETY: a path with AVX only runs where the CPU has AVX2 (`Path::AVX`).
        unsafe { cache.kept_avx2(sx, sy) }
    } else {
        cache.kept(sx, sy)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let mut kept = cache.kept(sx, sy);
    debug_assert_eq!(kept, cache.kept(sx, sy), "the SIMD cull is the scalar one");
    // The rays run along +kz when `sz > 0` (one sign for the whole tile: its axes are shared).
    let ahead = sz0 > 0.0;
    let TileCache {
        tris, best: all, ..
    } = cache;
    all.clear();
    while kept != 0 {
        let t = &tris[kept.trailing_zeros() as usize];
        kept &= kept - 1;
        let sure = sure(t, sx, sy, (sz0, sz1), ahead);
        let mut redo = rays::<P::Wide>(&t.rel, tile, t_max, t.id, sure, all) & lanes;
        while redo != 0 {
            let l = redo.trailing_zeros() as usize;
            redo &= redo - 1;
            if let Some(h) = intersect_watertight(&tile.ray(l), &t.v, t_max) {
                all.offer(l, h.t, h.b, t.id);
            }
        }
    }
    for (p, best) in best[..packets].iter_mut().enumerate() {
        all.packet_into(p, best);
    }
}
