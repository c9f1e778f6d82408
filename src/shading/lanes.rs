//! [`Tracer::shade_tile`] eight pixels at a time with AVX2, for scenes small enough for the
//! shadow cull ([`SHADOW_TILE_TRIANGLES`]): structure of arrays through the whole tile. The
//! hit points and their error bounds ([`crate::geometry::hit_point`]), the normals facing the
//! ray, each light's term, offset origin and direction ([`Tracer::light_term`]), the sums over
//! the lights and the colours are computed in lanes, with the scalar code's `f32` operations in
//! its order (no fused multiply-add; glam's `min`/`max` pick the operands SSE's do); the shadow
//! rays stay lanes too ([`ShadowCull::occluded8_avx2`]), grouped by axes, after the tile's cull.
//! So every colour and every ray count is the scalar path's, bit for bit.

use std::arch::x86_64::*;
use std::f32::consts::PI;

use glam::Vec3;

use super::{Mode, RayCounts, SHADOW_EPSILON, Tracer};
use crate::accel::shadow::{SHADOW_TILE_TRIANGLES, ShadowCull, ShadowRays8};
use crate::accel::{Hit, Isa, TILE_RAYS};
use crate::geometry::{Ray, RayTile, gamma};
use crate::scene::{Indirect, PointLight};

/// Most pixels in a tile.
const N: usize = TILE_RAYS;

/// One `f32` per pixel of a tile, per axis.
type Lanes = [[f32; N]; 3];

const ZERO: Lanes = [[0.0; N]; 3];

/// What [`Tracer::shade_tile_lanes`] keeps between tiles (one per band of tiles).
#[derive(Clone, Debug)]
pub(super) struct LaneScratch {
    /// Each shaded pixel's index in the tile.
    idx: [u8; N],
    /// Gathered per shaded pixel: barycentrics, the triangle's vertices, its normal, the
    /// ray's direction, the material's colour.
    bary: Lanes,
    v: [Lanes; 3],
    tri_normal: Lanes,
    ray_dir: Lanes,
    colour: Lanes,
    /// The hit point, its error bound, the normal facing the ray, the sum over the lights.
    p: Lanes,
    err: Lanes,
    normal: Lanes,
    sum: Lanes,
    /// One light's term, shadow-ray origin and direction.
    term: Lanes,
    origin: Lanes,
    dir: Lanes,
    /// One cull per light, built on first use.
    culls: Vec<Option<ShadowCull>>,
}

impl Default for LaneScratch {
    fn default() -> LaneScratch {
        LaneScratch {
            idx: [0; N],
            bary: ZERO,
            v: [ZERO; 3],
            tri_normal: ZERO,
            ray_dir: ZERO,
            colour: ZERO,
            p: ZERO,
            err: ZERO,
            normal: ZERO,
            sum: ZERO,
            term: ZERO,
            origin: ZERO,
            dir: ZERO,
            culls: vec![],
        }
    }
}

impl Tracer<'_> {
    /// Whether [`Tracer::shade_tile_lanes`] shades this frame's tiles: AVX2 queries and a scene
    /// small enough for the shadow cull.
    pub(super) fn shades_in_lanes(&self) -> bool {
        self.scene.isa() == Isa::Avx2 && self.scene.triangles().len() <= SHADOW_TILE_TRIANGLES
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
        assert!(self.shades_in_lanes() && rays.len() <= N);
        // SAFETY: the scene's queries take the AVX2 path, which is only set where the CPU has it.
        unsafe { self.shade_tile_avx2(rays, hits, out, n, s) }
    }

    #[target_feature(enable = "avx2")]
    #[allow(clippy::needless_range_loop)] // lanes and axes, in step across several arrays
    unsafe fn shade_tile_avx2(
        &self,
        rays: &RayTile,
        hits: &[Option<Hit>],
        out: &mut [Vec3],
        n: &mut RayCounts,
        s: &mut LaneScratch,
    ) {
        let mode = self.settings.mode;
        let (tris, materials) = (self.scene.triangles(), self.scene.materials());
        // Gather the pixels shaded here; the others are shaded one at a time.
        let mut m = 0;
        for (i, hit) in hits.iter().enumerate() {
            let Some(hit) = hit else {
                out[i] = Vec3::ZERO;
                continue;
            };
            let tri = &tris[hit.triangle as usize];
            let material = &materials[tri.material as usize];
            // As `shade`: flat colour; a black surface or a mirror (shaded one at a time).
            let own = mode == Mode::Irradiance
                || (mode == Mode::Colour
                    && !(material.mirror > 0.0)
                    && material.colour != Vec3::ZERO);
            if !own {
                let ray = rays.ray(i);
                out[i] = self.shade_primary(&ray, Some(*hit), &mut crate::rng::Rng::seeded(0), n);
                continue;
            }
            let dir = rays.dir(i);
            for k in 0..3 {
                s.bary[k][m] = hit.b[k];
                for j in 0..3 {
                    s.v[j][k][m] = tri.v[j][k];
                }
                s.tri_normal[k][m] = tri.normal[k];
                s.ray_dir[k][m] = dir[k];
                s.colour[k][m] = material.colour[k];
            }
            s.idx[m] = i as u8;
            m += 1;
        }
        if m == 0 {
            return;
        }
        let chunks = m.div_ceil(8);
        // The lanes of chunk `c` that hold a pixel.
        let valid = |c: usize| (1u32 << (m - 8 * c).min(8)) - 1;
        let t_max = 1.0 - SHADOW_EPSILON;
        for c in 0..chunks {
            self.hit_points8(s, 8 * c);
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
                let (l, t) = self.light_terms8(light, s, 8 * c);
                lit[c] = l & valid(c);
                traced[c] = t & lit[c];
            }
            let mut blocked = [0u32; N / 8];
            if self.settings.effects.shadows {
                let count: u32 = traced.iter().map(|t| t.count_ones()).sum();
                n.shadow += count as u64;
                if count > 0 {
                    if s.culls.len() <= li {
                        s.culls.resize(li + 1, None);
                    }
                    if !s.culls[li]
                        .as_ref()
                        .is_some_and(|c| c.is_for(light.position))
                    {
                        s.culls[li] = Some(ShadowCull::new(tris, light.position));
                    }
                    let (lo, hi) = origin_box(s, &traced[..chunks]);
                    let kept = s.culls[li].as_ref().expect("built above").kept(lo, hi);
                    for c in 0..chunks {
                        if traced[c] != 0 {
                            blocked[c] = shadows8(s, li, kept, 8 * c, traced[c], t_max);
                        }
                    }
                }
            }
            for c in 0..chunks {
                add_terms8(s, 8 * c, lit[c] & !blocked[c]);
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
            for k in 0..3 {
                let sum = ld(&s.sum[k]);
                // `material.colour * (sum + indirect)`, or the irradiance alone.
                let v = match indirect {
                    Some(i) => {
                        _mm256_mul_ps(ld(&s.colour[k]), _mm256_add_ps(sum, _mm256_set1_ps(i)))
                    }
                    None => sum,
                };
                // SAFETY: writes eight `f32`s.
                unsafe { _mm256_storeu_ps(colour[k].as_mut_ptr(), v) };
            }
            for l in 0..(m - o).min(8) {
                let i = s.idx[o + l] as usize;
                out[i] = Vec3::new(colour[0][l], colour[1][l], colour[2][l]);
                debug_assert!(out[i].is_finite(), "non-finite colour {}", out[i]);
            }
        }
    }

    /// `hit_point` and the normal facing the ray for the eight pixels from `o`.
    #[target_feature(enable = "avx2")]
    fn hit_points8(&self, s: &mut LaneScratch, o: usize) {
        let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
        let st = |a: &mut [f32; N], v: __m256| unsafe { _mm256_storeu_ps(a[o..].as_mut_ptr(), v) };
        let (b0, b1, b2) = (ld(&s.bary[0]), ld(&s.bary[1]), ld(&s.bary[2]));
        let g7 = _mm256_set1_ps(gamma(7));
        let sign = _mm256_set1_ps(-0.0);
        for k in 0..3 {
            let (v0, v1, v2) = (ld(&s.v[0][k]), ld(&s.v[1][k]), ld(&s.v[2][k]));
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
        let [nx, ny, nz] = s.tri_normal.each_ref().map(ld);
        let [dx, dy, dz] = s.ray_dir.each_ref().map(ld);
        let dot = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(nx, dx), _mm256_mul_ps(ny, dy)),
            _mm256_mul_ps(nz, dz),
        );
        let flip = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(dot, _mm256_setzero_ps()), sign);
        for (k, c) in [nx, ny, nz].into_iter().enumerate() {
            st(&mut s.normal[k], _mm256_xor_ps(c, flip));
        }
    }

    /// `light_term` for the eight pixels from `o`: the term, origin and direction into `s`,
    /// and the lanes lit and the lanes with a shadow ray (bit per lane).
    #[target_feature(enable = "avx2")]
    fn light_terms8(&self, light: &PointLight, s: &mut LaneScratch, o: usize) -> (u32, u32) {
        let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
        let st = |a: &mut [f32; N], v: __m256| unsafe { _mm256_storeu_ps(a[o..].as_mut_ptr(), v) };
        let [px, py, pz] = s.p.each_ref().map(ld);
        let [ex, ey, ez] = s.err.each_ref().map(ld);
        let [nx, ny, nz] = s.normal.each_ref().map(ld);
        let sp = |v: f32| _mm256_set1_ps(v);
        let (add, sub, mul, div) = (
            |a, b| _mm256_add_ps(a, b),
            |a, b| _mm256_sub_ps(a, b),
            |a, b| _mm256_mul_ps(a, b),
            |a, b| _mm256_div_ps(a, b),
        );
        let zero = _mm256_setzero_ps();
        let sign = sp(-0.0);
        let abs = |v| _mm256_andnot_ps(sign, v);
        let lp = light.position;
        // `to_light`, `length_squared`, `cos`, the term.
        let (tx, ty, tz) = (sub(sp(lp.x), px), sub(sp(lp.y), py), sub(sp(lp.z), pz));
        let dist2 = add(add(mul(tx, tx), mul(ty, ty)), mul(tz, tz));
        let lit = _mm256_cmp_ps::<_CMP_GT_OQ>(dist2, zero);
        let cos = div(
            add(add(mul(nx, tx), mul(ny, ty)), mul(nz, tz)),
            _mm256_sqrt_ps(dist2),
        );
        let lit = _mm256_and_ps(lit, _mm256_cmp_ps::<_CMP_GT_OQ>(cos, zero));
        // `dist2.max(min_r2)`: dist2 > 0 where it matters, never NaN there.
        let denom = mul(sp(4.0 * PI), _mm256_max_ps(dist2, sp(self.min_r2)));
        let pw = light.power;
        for (k, c) in [pw.x, pw.y, pw.z].into_iter().enumerate() {
            st(&mut s.term[k], div(mul(sp(c), cos), denom));
        }
        // `offset_ray_origin(p, err, normal, to_light)`.
        let d = add(add(mul(abs(nx), ex), mul(abs(ny), ey)), mul(abs(nz), ez));
        let wn = add(add(mul(tx, nx), mul(ty, ny)), mul(tz, nz));
        let flip = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(wn, zero), sign);
        let one = _mm256_set1_epi32(1);
        let inf = sp(f32::INFINITY);
        let step = |v: __m256, off: __m256| {
            let is_zero = _mm256_cmp_ps::<_CMP_EQ_OQ>(v, zero);
            let nan = _mm256_cmp_ps::<_CMP_UNORD_Q>(v, v);
            // `next_float_up`: ±0 → +0, then one step away from −∞; +∞ and NaN stay.
            let u = _mm256_blendv_ps(v, zero, is_zero);
            let ub = _mm256_castps_si256(u);
            let up = _mm256_blendv_ps(
                _mm256_castsi256_ps(_mm256_sub_epi32(ub, one)),
                _mm256_castsi256_ps(_mm256_add_epi32(ub, one)),
                _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
            );
            let keep = _mm256_or_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(v, inf), nan);
            let up = _mm256_blendv_ps(up, v, keep);
            // `next_float_down`: ±0 → −0, then one step toward −∞; −∞ and NaN stay.
            let w = _mm256_blendv_ps(v, sign, is_zero);
            let wb = _mm256_castps_si256(w);
            let down = _mm256_blendv_ps(
                _mm256_castsi256_ps(_mm256_add_epi32(wb, one)),
                _mm256_castsi256_ps(_mm256_sub_epi32(wb, one)),
                _mm256_cmp_ps::<_CMP_GT_OQ>(w, zero),
            );
            let keep = _mm256_or_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(v, sp(f32::NEG_INFINITY)), nan);
            let down = _mm256_blendv_ps(down, v, keep);
            let v = _mm256_blendv_ps(v, down, _mm256_cmp_ps::<_CMP_LT_OQ>(off, zero));
            _mm256_blendv_ps(v, up, _mm256_cmp_ps::<_CMP_GT_OQ>(off, zero))
        };
        let mut nonzero = zero;
        let mut finite = _mm256_cmp_ps::<_CMP_EQ_OQ>(zero, zero);
        for (k, (p, nk)) in [(px, nx), (py, ny), (pz, nz)].into_iter().enumerate() {
            let offset = _mm256_xor_ps(mul(nk, d), flip);
            let origin = step(add(p, offset), offset);
            let dir = sub(sp(lp[k]), origin);
            st(&mut s.origin[k], origin);
            st(&mut s.dir[k], dir);
            nonzero = _mm256_or_ps(nonzero, _mm256_cmp_ps::<_CMP_NEQ_UQ>(dir, zero));
            finite = _mm256_and_ps(finite, _mm256_cmp_ps::<_CMP_LT_OQ>(abs(dir), inf));
        }
        let traced = _mm256_and_ps(nonzero, finite);
        (
            _mm256_movemask_ps(lit) as u32,
            _mm256_movemask_ps(traced) as u32,
        )
    }
}

/// The box of the origins of the `traced` lanes (bit per lane, a word per chunk of eight).
#[target_feature(enable = "avx2")]
fn origin_box(s: &LaneScratch, traced: &[u32]) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (c, &t) in traced.iter().enumerate() {
        let mut t = t;
        while t != 0 {
            let l = 8 * c + t.trailing_zeros() as usize;
            t &= t - 1;
            for k in 0..3 {
                lo[k] = lo[k].min(s.origin[k][l]);
                hi[k] = hi[k].max(s.origin[k][l]);
            }
        }
    }
    (Vec3::from_array(lo), Vec3::from_array(hi))
}

/// The shadow rays of the `traced` lanes of the eight pixels from `o` against the `kept`
/// triangles of light `li`'s cull, in packets of one axis order: the lanes blocked.
#[target_feature(enable = "avx2")]
fn shadows8(s: &LaneScratch, li: usize, kept: u64, o: usize, traced: u32, t_max: f32) -> u32 {
    let ld = |a: &[f32; N]| unsafe { _mm256_loadu_ps(a[o..].as_ptr()) };
    let [dx, dy, dz] = s.dir.each_ref().map(ld);
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
    let mut blocked = 0;
    for kz in 0..3 {
        for neg in [false, true] {
            let side = if neg { negative[kz] } else { !negative[kz] };
            let lanes = traced & by_axis[kz] & side;
            if lanes == 0 {
                continue;
            }
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
            for (row, v) in rays.shear.iter_mut().zip([sx, sy, sz]) {
                // SAFETY: writes eight `f32`s.
                unsafe { _mm256_store_ps(row.as_mut_ptr(), v) };
            }
            for (row, k) in rays.origin.iter_mut().zip([kx, ky, kz]) {
                row.copy_from_slice(&s.origin[k][o..o + 8]);
            }
            let mut oz = (f32::INFINITY, f32::NEG_INFINITY);
            let mut m = lanes;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                let z = rays.origin[2][l];
                oz = (oz.0.min(z), oz.1.max(z));
            }
            let ray = |l: usize| {
                let v = |a: &Lanes| Vec3::new(a[0][o + l], a[1][o + l], a[2][o + l]);
                Ray::new(v(&s.origin), v(&s.dir))
            };
            // SAFETY: this function runs with AVX2.
            let cull = s.culls[li].as_ref().expect("built by the caller");
            blocked |= unsafe { cull.occluded8_avx2(kept, &rays, lanes, oz, t_max, ray) };
        }
    }
    blocked
}

/// `sum += term` in the `lanes` (bit per lane) of the eight pixels from `o`.
#[target_feature(enable = "avx2")]
fn add_terms8(s: &mut LaneScratch, o: usize, lanes: u32) {
    if lanes == 0 {
        return;
    }
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let on = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits),
        bits,
    ));
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
