//! [`Tracer::shade_tile`] eight pixels at a time with AVX2, for scenes small enough for the
//! shadow cull ([`SHADOW_TILE_TRIANGLES`]): structure of arrays through the whole tile. The
//! hit points and their error bounds ([`crate::geometry::hit_point`]), the normals facing the
//! ray, each light's term, offset origin and direction ([`Tracer::light_term`]), the sums over
//! the lights and the colours are computed in lanes, with the scalar code's `f32` operations in
//! its order (no fused multiply-add; glam's `min`/`max` pick the operands SSE's do); the shadow
//! rays stay lanes too ([`ShadowCull::occluded8_avx2`]), grouped by axes, after the tile's cull.
//! So every colour and every ray count is the scalar path's, bit for bit. On AVX-512 CPUs the
//! same kernel runs compiled for AVX-512 (eight lanes still, but 32 registers and mask
//! registers): one body, two copies, each with its own inlined helpers.

use std::arch::x86_64::*;

use glam::Vec3;

use super::tile::light_lanes_avx2;
use super::{Mode, RayCounts, SHADOW_EPSILON, Tracer};
use crate::accel::shadow::{SHADOW_TILE_TRIANGLES, ShadowCull, ShadowRays8};
use crate::accel::tri4::Best8;
use crate::accel::{Hit, Isa, TILE_RAYS};
use crate::geometry::{Ray, RayTile, gamma};
use crate::scene::{Indirect, PointLight};

/// Most pixels in a tile.
const N: usize = TILE_RAYS;

/// The kernel's copy compiled for AVX2 ([`Tracer::shade_tile_lanes_in`]'s `COPY`).
const ON_AVX2: u8 = 0;
/// The kernel's copy compiled for AVX-512.
const ON_AVX512: u8 = 1;

/// One `f32` per pixel of a tile, per axis.
type Lanes = [[f32; N]; 3];

const ZERO: Lanes = [[0.0; N]; 3];

/// Per triangle of a small scene: vertices, normal, material colour, structure of arrays, for
/// gathering eight lanes at once; which triangles are shaded in lanes; each light's cull.
#[derive(Debug)]
pub(super) struct Tables {
    /// `v[vertex][axis][triangle]`.
    v: [[[f32; SHADOW_TILE_TRIANGLES]; 3]; 3],
    normal: [[f32; SHADOW_TILE_TRIANGLES]; 3],
    colour: [[f32; SHADOW_TILE_TRIANGLES]; 3],
    /// Bit `t`: triangle `t`'s hits are shaded in lanes (else one at a time, as `shade` does
    /// mirrors and black surfaces).
    own: u64,
    /// One per light, when shadows are traced.
    culls: Vec<ShadowCull>,
}

/// What [`Tracer::shade_tile_lanes`] keeps between tiles (one per band of tiles).
#[derive(Clone, Debug)]
pub(super) struct LaneScratch {
    /// Each shaded pixel's index in the tile, and its triangle.
    idx: [i32; N],
    tri: [i32; N],
    /// Gathered per shaded pixel: barycentrics.
    bary: Lanes,
    /// The hit point, its error bound, the normal facing the ray, the sum over the lights.
    p: Lanes,
    err: Lanes,
    normal: Lanes,
    sum: Lanes,
    /// One light's term, shadow-ray origin and direction.
    term: Lanes,
    origin: Lanes,
    dir: Lanes,
}

impl Default for LaneScratch {
    fn default() -> LaneScratch {
        LaneScratch {
            idx: [0; N],
            tri: [0; N],
            bary: ZERO,
            p: ZERO,
            err: ZERO,
            normal: ZERO,
            sum: ZERO,
            term: ZERO,
            origin: ZERO,
            dir: ZERO,
        }
    }
}

impl Tracer<'_> {
    /// Whether [`Tracer::shade_tile_lanes`] shades this frame's tiles: AVX2 or AVX-512 queries
    /// and a scene small enough for the shadow cull.
    pub(super) fn shades_in_lanes(&self) -> bool {
        matches!(self.scene.isa(), Isa::Avx2 | Isa::Avx512)
            && self.scene.triangles().len() <= SHADOW_TILE_TRIANGLES
    }

    /// [`Tracer::shade_tile`] in lanes (see the module's doc). Only when
    /// [`Tracer::shades_in_lanes`].
    pub(super) fn shade_tile_lanes(
        &self,
        rays: &RayTile,
        hits: &[Option<Hit>],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        let mut best = [Best8::NONE; N / 8];
        for (i, &h) in hits.iter().enumerate() {
            best[i / 8].set(i % 8, h);
        }
        self.shade_tile_best_lanes(rays, &best, out, n, s);
    }

    /// [`Tracer::shade_tile_lanes`] of hits in lanes as [`crate::Scene::intersect_tile_best`]
    /// leaves them (ray `i`'s in lane `i % 8` of `best[i / 8]`).
    pub(super) fn shade_tile_best_lanes(
        &self,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        assert!(self.shades_in_lanes() && rays.len() <= N && out.len() == rays.len());
        // SAFETY: the scene's queries take the AVX2 or the AVX-512 path, which is only set
        // where the CPU has it.
        unsafe {
            if self.scene.isa() == Isa::Avx512 {
                self.shade_tile_avx512(rays, best, out, n, s)
            } else {
                self.shade_tile_avx2(rays, best, out, n, s)
            }
        }
    }

    /// [`Tracer::shade_tile_lanes_in`] compiled for AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn shade_tile_avx2(
        &self,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        self.shade_tile_lanes_in::<ON_AVX2>(rays, best, out, n, s)
    }

    /// [`Tracer::shade_tile_lanes_in`] compiled for AVX-512: the same operations (eight
    /// lanes), with 32 registers instead of 16 and comparisons into mask registers.
    #[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
    unsafe fn shade_tile_avx512(
        &self,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        self.shade_tile_lanes_in::<ON_AVX512>(rays, best, out, n, s)
    }

    /// The kernel of [`Tracer::shade_tile_best_lanes`]. `COPY` ([`ON_AVX2`] or [`ON_AVX512`])
    /// names the compilation it belongs to: each helper below is generic over it too, so that
    /// every copy has a single caller, is inlined into it and compiled with its features.
    #[target_feature(enable = "avx2")]
    #[allow(clippy::needless_range_loop)] // lanes and axes, in step across several arrays
    fn shade_tile_lanes_in<const COPY: u8>(
        &self,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        let mode = self.settings.mode;
        let tables = &**self.tables.get_or_init(|| Box::new(self.tables()));
        // Gather the pixels shaded here (packed, in order); the others are shaded one at a
        // time, after.
        let k = rays.len().min(N);
        let mut m = 0;
        let mut others = 0u64;
        // `tables.own`'s two halves, and what picks a lane's bit out of them.
        let own_lo = _mm256_set1_epi32(tables.own as u32 as i32);
        let own_hi = _mm256_set1_epi32((tables.own >> 32) as u32 as i32);
        let (one, thirty_two) = (_mm256_set1_epi32(1), _mm256_set1_epi32(32));
        let iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        for (c, b) in best.iter().enumerate().take(k.div_ceil(8)) {
            let (ids, bary) = (b.ids(), b.barycentrics());
            let lanes = (k - 8 * c).min(8);
            // SAFETY: reads eight `u32`s.
            let id8 = unsafe { _mm256_loadu_si256(ids.as_ptr().cast()) };
            // Each lane's bit of `own` (0 for a miss, `u32::MAX`): shifts by 32 or more give 0,
            // so ids below 32 take their bit from the low half, 32..64 from the high one.
            let bit = _mm256_and_si256(
                _mm256_or_si256(
                    _mm256_srlv_epi32(own_lo, id8),
                    _mm256_srlv_epi32(own_hi, _mm256_sub_epi32(id8, thirty_two)),
                ),
                one,
            );
            let all_own = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(bit, one)));
            // Eight hits, all on triangles shaded here (most packets): copied as they are.
            if lanes == 8 && all_own == 0xff {
                for a in 0..3 {
                    s.bary[a][m..m + 8].copy_from_slice(&bary[a]);
                }
                let (tri, idx) = (&mut s.tri[m..m + 8], &mut s.idx[m..m + 8]);
                // SAFETY: each writes eight `i32`s into a slice of eight.
                unsafe {
                    _mm256_storeu_si256(tri.as_mut_ptr().cast(), id8);
                    let at = _mm256_add_epi32(_mm256_set1_epi32(8 * c as i32), iota);
                    _mm256_storeu_si256(idx.as_mut_ptr().cast(), at);
                }
                m += 8;
                continue;
            }
            for l in 0..lanes {
                let (i, id) = (8 * c + l, ids[l]);
                if id == u32::MAX {
                    out[i] = Vec3::ZERO;
                    continue;
                }
                let own = tables.own >> id & 1;
                others |= (own ^ 1) << i;
                // (`m < N`: the mask only tells the compiler so.)
                let j = m & (N - 1);
                s.bary[0][j] = bary[0][l];
                s.bary[1][j] = bary[1][l];
                s.bary[2][j] = bary[2][l];
                s.tri[j] = id as i32;
                s.idx[j] = i as i32;
                m += own as usize;
            }
        }
        while others != 0 {
            let i = others.trailing_zeros() as usize;
            others &= others - 1;
            let mut rng = crate::rng::Rng::seeded(0);
            out[i] = self.shade_primary(&rays.ray(i), best[i / 8].hit(i % 8), &mut rng, n);
        }
        if m == 0 {
            return;
        }
        let chunks = m.div_ceil(8);
        // The lanes of chunk `c` that hold a pixel.
        let valid = |c: usize| (1u32 << (m - 8 * c).min(8)) - 1;
        let t_max = 1.0 - SHADOW_EPSILON;
        for c in 0..chunks {
            hit_points8::<COPY>(tables, s, rays.dir_lanes(), 8 * c, (m - 8 * c).min(8));
        }
        s.sum = ZERO;
        for (li, light) in self.lights.iter().enumerate() {
            // A dark light adds nothing and traces nothing.
            if light.power == Vec3::ZERO {
                continue;
            }
            let mut lit = [0u32; N / 8];
            let mut traced = [0u32; N / 8];
            for c in 0..chunks {
                let (l, t) = self.light_terms8::<COPY>(light, s, 8 * c);
                lit[c] = l & valid(c);
                traced[c] = t & lit[c];
            }
            let mut blocked = [0u32; N / 8];
            if self.settings.effects.shadows {
                let count: u32 = traced.iter().map(|t| t.count_ones()).sum();
                n.shadow += count as u64;
                if count > 0 {
                    let cull = &tables.culls[li];
                    let (lo, hi) = origin_box::<COPY>(s, &traced[..chunks]);
                    let kept = cull.kept_in::<COPY>(self.scene.isa(), lo, hi, 1.0);
                    for c in 0..chunks {
                        if traced[c] != 0 {
                            blocked[c] = shadows8::<COPY>(s, cull, kept, 8 * c, traced[c], t_max);
                        }
                    }
                }
            }
            for c in 0..chunks {
                add_terms8::<COPY>(s, 8 * c, lit[c] & !blocked[c]);
            }
        }
        let indirect = match self.settings.effects.indirect {
            Indirect::Constant(k) if mode == Mode::Colour => Some(k),
            _ if mode == Mode::Colour => Some(0.0),
            _ => None,
        };
        for c in 0..chunks {
            let o = 8 * c;
            // SAFETY: reads eight `f32`s.
            let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
            let mut colour = [[0f32; 8]; 3];
            // SAFETY: reads eight `i32`s.
            let ids = unsafe { _mm256_loadu_si256(s.tri[o..].as_ptr().cast()) };
            for k in 0..3 {
                let sum = ld(&s.sum[k]);
                // `material.colour * (sum + indirect)`, or the irradiance alone.
                let v = match indirect {
                    Some(i) => _mm256_mul_ps(
                        gather(&tables.colour[k], ids),
                        _mm256_add_ps(sum, _mm256_set1_ps(i)),
                    ),
                    None => sum,
                };
                // SAFETY: writes eight `f32`s.
                unsafe { _mm256_storeu_ps(colour[k].as_mut_ptr(), v) };
            }
            let colour = |l: usize| Vec3::new(colour[0][l], colour[1][l], colour[2][l]);
            if m - o >= 8 && s.idx[o + 7] == (o + 7) as i32 {
                // Eight pixels in place (indices only grow): written in a row.
                for (l, c) in out[o..o + 8].iter_mut().enumerate() {
                    *c = colour(l);
                }
            } else {
                for l in 0..(m - o).min(8) {
                    out[s.idx[o + l] as usize] = colour(l);
                }
            }
        }
        debug_assert!(out[..k].iter().all(|c| c.is_finite()), "non-finite colour");
    }

    /// The tables of [`Tracer::shade_tile_lanes`] for this frame (a small scene).
    fn tables(&self) -> Tables {
        let mut t = Tables {
            v: [[[0.0; SHADOW_TILE_TRIANGLES]; 3]; 3],
            normal: [[0.0; SHADOW_TILE_TRIANGLES]; 3],
            colour: [[0.0; SHADOW_TILE_TRIANGLES]; 3],
            own: 0,
            culls: vec![],
        };
        let mode = self.settings.mode;
        let materials = self.scene.materials();
        for (i, tri) in self.scene.triangles().iter().enumerate() {
            let material = &materials[tri.material as usize];
            for k in 0..3 {
                for j in 0..3 {
                    t.v[j][k][i] = tri.v[j][k];
                }
                t.normal[k][i] = tri.normal[k];
                t.colour[k][i] = material.colour[k];
            }
            // As `shade`: flat colour; a black surface or a mirror (shaded one at a time).
            let own = mode == Mode::Irradiance
                || (mode == Mode::Colour
                    && !(material.mirror > 0.0)
                    && material.colour != Vec3::ZERO);
            t.own |= (own as u64) << i;
        }
        if self.settings.effects.shadows {
            t.culls = self
                .lights
                .iter()
                .map(|l| ShadowCull::new(self.scene.triangles(), l.position))
                .collect();
        }
        t
    }

    /// `light_term` for the eight pixels from `o`: the term, origin and direction into `s`,
    /// and the lanes lit and the lanes with a shadow ray (bit per lane).
    #[target_feature(enable = "avx2")]
    fn light_terms8<const COPY: u8>(
        &self,
        light: &PointLight,
        s: &mut LaneScratch,
        o: usize,
    ) -> (u32, u32) {
        let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
        let st = |a: &mut [f32; N], v: __m256| unsafe { _mm256_storeu_ps(a[o..].as_mut_ptr(), v) };
        let lanes = light_lanes_avx2(
            light,
            self.min_r2,
            s.p.each_ref().map(ld),
            s.err.each_ref().map(ld),
            s.normal.each_ref().map(ld),
        );
        for k in 0..3 {
            st(&mut s.term[k], lanes.term[k]);
            st(&mut s.origin[k], lanes.origin[k]);
            st(&mut s.dir[k], lanes.dir[k]);
        }
        (lanes.lit, lanes.traced)
    }
}

/// Eight lanes of `table` at triangles `ids` (all in the table).
#[target_feature(enable = "avx2")]
fn gather(table: &[f32; SHADOW_TILE_TRIANGLES], ids: __m256i) -> __m256 {
    // SAFETY: every id indexes the table (the scene's triangles, at most its length).
    unsafe { _mm256_i32gather_ps::<4>(table.as_ptr(), ids) }
}

/// `hit_point` and the normal facing the ray for the `count` (1 to 8) pixels from `o`
/// (`dirs`: the tile's ray directions).
#[target_feature(enable = "avx2")]
fn hit_points8<const COPY: u8>(
    t: &Tables,
    s: &mut LaneScratch,
    dirs: &Lanes,
    o: usize,
    count: usize,
) {
    let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
    let st = |a: &mut [f32; N], v: __m256| unsafe { _mm256_storeu_ps(a[o..].as_mut_ptr(), v) };
    // SAFETY: reads eight `i32`s.
    let ids = unsafe { _mm256_loadu_si256(s.tri[o..].as_ptr().cast()) };
    // Eight hits on one triangle (the common case): its values splatted, else gathered.
    let first = s.tri[o];
    let same = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
        ids,
        _mm256_set1_epi32(first),
    ))) == 0xff;
    let get = |a: &[f32; SHADOW_TILE_TRIANGLES]| {
        if same {
            _mm256_set1_ps(a[first as usize])
        } else {
            gather(a, ids)
        }
    };
    let (b0, b1, b2) = (ld(&s.bary[0]), ld(&s.bary[1]), ld(&s.bary[2]));
    let g7 = _mm256_set1_ps(gamma(7));
    let sign = _mm256_set1_ps(-0.0);
    for k in 0..3 {
        let (v0, v1, v2) = (get(&t.v[0][k]), get(&t.v[1][k]), get(&t.v[2][k]));
        let (p0, p1, p2) = (
            _mm256_mul_ps(v0, b0),
            _mm256_mul_ps(v1, b1),
            _mm256_mul_ps(v2, b2),
        );
        // glam's `min`/`max`: `a < b ? a : b`, `a > b ? a : b`, as SSE's.
        let lo = _mm256_min_ps(_mm256_min_ps(v0, v1), v2);
        let hi = _mm256_max_ps(_mm256_max_ps(v0, v1), v2);
        let sum = _mm256_add_ps(_mm256_add_ps(p0, p1), p2);
        st(&mut s.p[k], _mm256_min_ps(_mm256_max_ps(sum, lo), hi));
        let abs = |v| _mm256_andnot_ps(sign, v);
        let e = _mm256_add_ps(_mm256_add_ps(abs(p0), abs(p1)), abs(p2));
        st(&mut s.err[k], _mm256_mul_ps(e, g7));
    }
    // Two-sided shading: the normal on the side the ray came from.
    let (nx, ny, nz) = (get(&t.normal[0]), get(&t.normal[1]), get(&t.normal[2]));
    // The rays' directions: the tile's own lanes when these `count` pixels are the tile's
    // pixels `o..` (indices only grow, so the last one tells), else gathered.
    let last = o + count - 1;
    let in_place = s.idx[last] == last as i32;
    let dir = |k: usize| {
        if in_place {
            ld(&dirs[k])
        } else {
            // SAFETY: every index is a pixel of the tile (at most `N`; stale lanes past the
            // last pixel hold indices of earlier tiles, also below `N`).
            unsafe {
                let idx = _mm256_loadu_si256(s.idx[o..].as_ptr().cast());
                _mm256_i32gather_ps::<4>(dirs[k].as_ptr(), idx)
            }
        }
    };
    let (dx, dy, dz) = (dir(0), dir(1), dir(2));
    let dot = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(nx, dx), _mm256_mul_ps(ny, dy)),
        _mm256_mul_ps(nz, dz),
    );
    let flip = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(dot, _mm256_setzero_ps()), sign);
    for (k, c) in [nx, ny, nz].into_iter().enumerate() {
        st(&mut s.normal[k], _mm256_xor_ps(c, flip));
    }
}

/// The lanes of a mask (bit per lane) as a vector mask.
#[target_feature(enable = "avx2")]
fn lane_mask(lanes: u32) -> __m256 {
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits),
        bits,
    ))
}

/// The least and greatest of `v` over the lanes of `on` (a vector mask with a lane set).
#[target_feature(enable = "avx2")]
fn min_max8(v: __m256, on: __m256) -> (f32, f32) {
    let lo = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), v, on);
    let hi = _mm256_blendv_ps(_mm256_set1_ps(f32::NEG_INFINITY), v, on);
    // Halves, then pairs, then neighbours (no lane is NaN: origins are finite).
    let l = _mm_min_ps(_mm256_castps256_ps128(lo), _mm256_extractf128_ps::<1>(lo));
    let l = _mm_min_ps(l, _mm_movehl_ps(l, l));
    let l = _mm_min_ps(l, _mm_shuffle_ps::<1>(l, l));
    let h = _mm_max_ps(_mm256_castps256_ps128(hi), _mm256_extractf128_ps::<1>(hi));
    let h = _mm_max_ps(h, _mm_movehl_ps(h, h));
    let h = _mm_max_ps(h, _mm_shuffle_ps::<1>(h, h));
    (_mm_cvtss_f32(l), _mm_cvtss_f32(h))
}

/// The box of the origins of the `traced` lanes (bit per lane, a word per chunk of eight).
#[target_feature(enable = "avx2")]
fn origin_box<const COPY: u8>(s: &LaneScratch, traced: &[u32]) -> (Vec3, Vec3) {
    let mut lo = [_mm256_set1_ps(f32::INFINITY); 3];
    let mut hi = [_mm256_set1_ps(f32::NEG_INFINITY); 3];
    for (c, &t) in traced.iter().enumerate() {
        if t == 0 {
            continue;
        }
        let on = lane_mask(t);
        for k in 0..3 {
            // SAFETY: reads eight `f32`s.
            let v = unsafe { _mm256_loadu_ps(s.origin[k][8 * c..].as_ptr()) };
            lo[k] = _mm256_blendv_ps(lo[k], _mm256_min_ps(lo[k], v), on);
            hi[k] = _mm256_blendv_ps(hi[k], _mm256_max_ps(hi[k], v), on);
        }
    }
    let all = lane_mask(0xff);
    let (x, y, z) = (
        min_max8(lo[0], all),
        min_max8(lo[1], all),
        min_max8(lo[2], all),
    );
    let (lo, _) = ((x.0, y.0, z.0), ());
    let (x, y, z) = (
        min_max8(hi[0], all),
        min_max8(hi[1], all),
        min_max8(hi[2], all),
    );
    (Vec3::new(lo.0, lo.1, lo.2), Vec3::new(x.1, y.1, z.1))
}

/// The shadow rays of the `traced` lanes of the eight pixels from `o` against the `kept`
/// triangles of light `li`'s cull, in packets of one axis order: the lanes blocked.
#[target_feature(enable = "avx2")]
fn shadows8<const COPY: u8>(
    s: &LaneScratch,
    cull: &ShadowCull,
    kept: u64,
    o: usize,
    traced: u32,
    t_max: f32,
) -> u32 {
    let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
    let (dx, dy, dz) = (ld(&s.dir[0]), ld(&s.dir[1]), ld(&s.dir[2]));
    let sign = _mm256_set1_ps(-0.0);
    let abs = |v| _mm256_andnot_ps(sign, v);
    let (ax, ay, az) = (abs(dx), abs(dy), abs(dz));
    let gt = |a, b| _mm256_cmp_ps::<_CMP_GT_OQ>(a, b);
    let mask = |v| _mm256_movemask_ps(v) as u32;
    let (x_y, x_z, y_z) = (gt(ax, ay), gt(ax, az), gt(ay, az));
    // `Ray::new`'s axis: x if |x| > |y| and |x| > |z|, else y if |y| > |z|, else z.
    let on_x = mask(_mm256_and_ps(x_y, x_z));
    let on_y = mask(_mm256_andnot_ps(x_y, y_z));
    let by_axis = [on_x, on_y, !(on_x | on_y)];
    let zero = _mm256_setzero_ps();
    let dirs = [dx, dy, dz];
    let negative = dirs.map(|d| mask(_mm256_cmp_ps::<_CMP_LT_OQ>(d, zero)));
    // Each lane's class: its axis and the sign along it (`Ray::new`'s axes and swap).
    let class = |l: usize| {
        let kz = if on_x >> l & 1 == 1 {
            0
        } else if on_y >> l & 1 == 1 {
            1
        } else {
            2
        };
        (kz, negative[kz] >> l & 1 == 1)
    };
    let mut blocked = 0;
    let mut left = traced;
    while left != 0 {
        let (kz, neg) = class(left.trailing_zeros() as usize);
        let side = if neg { negative[kz] } else { !negative[kz] };
        let lanes = left & by_axis[kz] & side;
        left &= !lanes;
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if neg {
            std::mem::swap(&mut kx, &mut ky);
        }
        let mut rays = ShadowRays8 {
            axes: [kx, ky, kz],
            ..ShadowRays8::default()
        };
        // The shear, as `Ray::with_inverse` computes it: `sz = 1/d_kz`, `sx = −d_kx·sz`.
        let sz = _mm256_div_ps(_mm256_set1_ps(1.0), dirs[kz]);
        let sx = _mm256_mul_ps(_mm256_xor_ps(dirs[kx], sign), sz);
        let sy = _mm256_mul_ps(_mm256_xor_ps(dirs[ky], sign), sz);
        // SAFETY: each writes or reads eight `f32`s.
        unsafe {
            _mm256_store_ps(rays.shear[0].as_mut_ptr(), sx);
            _mm256_store_ps(rays.shear[1].as_mut_ptr(), sy);
            _mm256_store_ps(rays.shear[2].as_mut_ptr(), sz);
            for (row, k) in rays.origin.iter_mut().zip([kx, ky, kz]) {
                _mm256_store_ps(row.as_mut_ptr(), ld(&s.origin[k]));
            }
        }
        let oz = min_max8(ld(&s.origin[kz]), lane_mask(lanes));
        let ray = |l: usize| {
            let v = |a: &Lanes| Vec3::new(a[0][o + l], a[1][o + l], a[2][o + l]);
            Ray::new(v(&s.origin), v(&s.dir))
        };
        // SAFETY: this function runs with AVX2.
        blocked |= unsafe { cull.occluded8_in::<COPY>(kept, &rays, lanes, oz, t_max, ray) };
    }
    blocked
}

/// `sum += term` in the `lanes` (bit per lane) of the eight pixels from `o`.
#[target_feature(enable = "avx2")]
fn add_terms8<const COPY: u8>(s: &mut LaneScratch, o: usize, lanes: u32) {
    if lanes == 0 {
        return;
    }
    let on = lane_mask(lanes);
    for k in 0..3 {
        // SAFETY: reads and writes eight `f32`s.
        unsafe {
            let sum = _mm256_loadu_ps(s.sum[k][o..].as_ptr());
            let term = _mm256_loadu_ps(s.term[k][o..].as_ptr());
            let new = _mm256_blendv_ps(sum, _mm256_add_ps(sum, term), on);
            _mm256_storeu_ps(s.sum[k][o..].as_mut_ptr(), new);
        }
    }
}
