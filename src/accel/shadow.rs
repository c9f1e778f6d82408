//! Shadow rays from a tile toward one point light, eight at a time against every triangle of a
//! small scene, after a cull that drops the triangles none of the tile's rays can hit.
//!
//! # The same answers as one ray at a time
//!
//! A ray's answer is whether some triangle is accepted by
//! [`crate::geometry::intersect_watertight`] before `t_max` (as [`crate::accel::Accel::occluded`]'s is, see
//! [`crate::accel`]): the kernel ([`any_hit8_avx2`]) runs that test's operations lane by lane,
//! lanes it hands back are redone by the scalar test, and the cull below only drops a triangle
//! that the scalar test rejects for every ray of the tile.
//!
//! # The cull: the planes through the light and each edge
//!
//! A shadow ray from origin `o` has direction `d = fl(L − o)` (one rounding per axis), `L`
//! the light. In the test's frame (axes `kx`, `ky`, `kz` of `d`, sheared so that `d` runs
//! along `kz`) edge function `i` of a triangle, in exact arithmetic on the exact `o`, `d` and
//! vertices, is the triple product `Eᵢ = ((vⱼ − o) × (vₖ − o))·d / |d_kz|` up to one sign
//! common to all three edges. With `d` replaced by `L − o` it is
//! `Fᵢ(o)/|d_kz|`, `Fᵢ(o) = nᵢ·(L − o)`, `nᵢ = (vⱼ − L) × (vₖ − L)`: the side of `o` of the
//! plane through the light and edge `jk` (the triangle's shadow frustum), affine in `o`. So
//! over the box `B` of a tile's origins each `Fᵢ` lies within
//! `nᵢ·(L − c) ± |nᵢ|·h` (centre `c`, half extent `h`).
//!
//! The scalar test's `eᵢ` (in `f32`, or redone in `f64`) is within `EdgeErrors`' bound of the
//! exact `Eᵢ`, taken four times and over the whole tile as `src/accel/flat/tile.rs` does: with
//! `R` a bound on `|v − o|` per axis (`v` any vertex, `o` in `B`) and `|sx|, |sy| ≤ S` (`kz` is
//! `d`'s largest axis, so `S` is 1 up to the shear's two roundings), `|x|, |y| ≤ X = R(1 + S)`,
//! each sheared coordinate's error is at most `γ₅(X + 2SR)` and
//! `δe ≤ 4·(4X·γ₅(X + 2SR) + 2γ₂X²)` (plus absolute terms for underflow). Replacing `d` by
//! `L − o` moves `Eᵢ·|d_kz|` by `((vⱼ − o) × (vₖ − o))·(d − (L − o))`, at most `6R²·ε·D` with
//! `D ≥ |L − o|` per axis and `ε = 2⁻²⁴`. And the `f64` evaluation of `Fᵢ` over the box is
//! within `2⁻⁴⁰` of its terms' magnitudes. So with
//! `M = D·δe + 6R²(εD + tiny) + 2⁻⁴⁰·(magnitudes)`, `Fᵢ < −M` over `B` means the scalar test's
//! `eᵢ` has the sign of `−1` (times the common sign) for every ray of the tile, `Fᵢ > M` the
//! other. A triangle is dropped when for every ray some edge is certainly negative and some
//! certainly positive: some `Fᵢ < −M` and some `Fⱼ > M` over `B` (so that no ray's three signs
//! agree, whatever `det`'s sign; the sums `Fⱼ + Fₖ = N·(L − o) − Fᵢ` would add a few cases,
//! about 2 % of the kept triangles in the seed frame, not worth their cost). Mixed
//! signs are rejected by the scalar test whatever else holds. A margin or bound that is not
//! finite compares false: the triangle is kept.
//!
//! # Behind the origins
//!
//! For eight rays of one packet (same axes; `d_kz > 0` say), a triangle whose vertices all have
//! `v_kz ≤ o_kz` for every origin is rejected too: each `zᵢ = fl(vᵢ,kz − o_kz) ≤ 0` and
//! `sz > 0`, so every `eᵢ·(sz·zᵢ)` has the sign opposite to `det` (or is zero), their rounded sum
//! `t·det` is `≤ 0` against a positive `det` (`≥ 0` against a negative one), and the test
//! rejects it (a NaN from `sz = ∞` fails `t < t_max`). This drops the surface the tile lies on
//! when the light is above it, which the frustum cull keeps (the origins lie in its frustum).

use glam::Vec3;

use crate::geometry::{Triangle, gamma};
use crate::simd::Isa;

#[cfg(target_arch = "x86_64")]
use super::tri4::shadow::any_hit8;
#[cfg(target_arch = "x86_64")]
pub use super::tri4::shadow::{ShadowRays8, any_hit8_avx2};

/// Scenes of at most this many triangles trace a tile's shadow rays together (the cull looks
/// at every triangle once per tile and light, which pays while triangles are few).
pub const SHADOW_TILE_TRIANGLES: usize = 64;

/// The triangles of a scene as the shadow rays toward one light see them: each triangle's
/// planes through the light. Build it with [`ShadowCull::new`] (once per light and frame).
#[derive(Clone, Debug)]
pub struct ShadowCull {
    /// The light's position (bits), the key.
    light: [u32; 3],
    /// The bounding box of every vertex.
    lo: [f64; 3],
    hi: [f64; 3],
    /// The largest component of any plane's rounding bound (`|a_y b_z| + |a_z b_y|`, ...).
    mag: f64,
    /// The triangles' planes, four triangles to a group.
    groups: Vec<Planes4>,
    tris: Vec<CullTri>,
}

/// Four triangles' planes through the light: per edge, per axis, per triangle: the normal `nᵢ = (vⱼ − L) × (vₖ − L)`
/// and its magnitude. Lanes without a triangle are zero (never culled).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
struct Planes4 {
    n: [[[f64; 4]; 3]; 3],
    abs: [[[f64; 4]; 3]; 3],
}

/// One triangle as the rays see it.
#[derive(Clone, Copy, Debug)]
struct CullTri {
    v: [Vec3; 3],
    /// The vertices as the kernel reads them, `[x, y, z, 0]`.
    lanes: [[f32; 4]; 3],
    /// Per axis, the least and greatest vertex coordinate.
    min: [f32; 3],
    max: [f32; 3],
}

/// Smallest positive subnormal `f32`, as `f64`: the absolute error of one underflowing
/// operation.
const TINY: f64 = 1.401298464324817e-45;

/// The relative error of the cull's own `f64` sums of products (a few roundings of 2⁻⁵³
/// each, bounded generously).
const RHO: f64 = 1.0 / (1u64 << 40) as f64;

/// A bound on `|sx|`, `|sy|`: `|d_kx|, |d_ky| ≤ |d_kz|`, and the shear rounds twice.
const SHEAR: f64 = 1.0 + 1.0 / (1u64 << 20) as f64;

impl ShadowCull {
    /// The cull of `triangles` (at most [`SHADOW_TILE_TRIANGLES`]) for a light at `light`.
    #[allow(clippy::needless_range_loop)] // per axis, in step across several arrays
    pub fn new(triangles: &[Triangle], light: Vec3) -> ShadowCull {
        assert!(triangles.len() <= SHADOW_TILE_TRIANGLES);
        let l = light.to_array().map(f64::from);
        let mut c = ShadowCull {
            light: light.to_array().map(f32::to_bits),
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
            mag: 0.0,
            groups: vec![Planes4::default(); triangles.len().div_ceil(4)],
            tris: Vec::with_capacity(triangles.len()),
        };
        for (i, t) in triangles.iter().enumerate() {
            let w = t.v.map(|v| [0, 1, 2].map(|k| v[k] as f64 - l[k]));
            let cross = |a: [f64; 3], b: [f64; 3]| {
                [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ]
            };
            let abs_cross = |a: [f64; 3], b: [f64; 3]| {
                [
                    (a[1] * b[2]).abs() + (a[2] * b[1]).abs(),
                    (a[2] * b[0]).abs() + (a[0] * b[2]).abs(),
                    (a[0] * b[1]).abs() + (a[1] * b[0]).abs(),
                ]
            };
            let edges = [(1, 2), (2, 0), (0, 1)];
            let n = edges.map(|(j, k)| cross(w[j], w[k]));
            let (g, lane) = (&mut c.groups[i / 4], i % 4);
            for e in 0..3 {
                for a in 0..3 {
                    g.n[e][a][lane] = n[e][a];
                    g.abs[e][a][lane] = n[e][a].abs();
                }
                for g in abs_cross(w[edges[e].0], w[edges[e].1]) {
                    c.mag = c.mag.max(g);
                }
            }
            let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for v in t.v {
                for k in 0..3 {
                    min[k] = min[k].min(v[k]);
                    max[k] = max[k].max(v[k]);
                    c.lo[k] = c.lo[k].min(v[k] as f64);
                    c.hi[k] = c.hi[k].max(v[k] as f64);
                }
            }
            c.tris.push(CullTri {
                v: t.v,
                lanes: t.v.map(|v| [v.x, v.y, v.z, 0.0]),
                min,
                max,
            });
        }
        c
    }

    /// Whether this cull was built for a light at `light`.
    pub fn is_for(&self, light: Vec3) -> bool {
        self.light == light.to_array().map(f32::to_bits)
    }

    /// The triangles some ray from an origin in the box `lo`..`hi` toward the light may hit,
    /// as a bit per triangle (bit `i`: the scene's triangle `i`), the plane tests on path `isa`
    /// (which must be available).
    pub fn kept(&self, isa: Isa, lo: Vec3, hi: Vec3) -> u64 {
        self.kept_with_margin(isa, lo, hi, 1.0)
    }

    /// [`ShadowCull::kept`] with the margin scaled by `scale` (1 in use; the tests show that
    /// 0 drops triangles the scalar test hits).
    pub(crate) fn kept_with_margin(&self, isa: Isa, lo: Vec3, hi: Vec3, scale: f64) -> u64 {
        assert!(isa.available(), "{} is not available", isa.name());
        #[cfg(target_arch = "x86_64")]
        if matches!(isa, Isa::Avx2 | Isa::Avx512) {
            // SAFETY: the CPU has AVX2 (and so AVX).
            return unsafe { self.kept_avx2(lo, hi, scale) };
        }
        self.kept_on(lo, hi, scale, false)
    }

    /// [`ShadowCull::kept_with_margin`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn kept_avx2(&self, lo: Vec3, hi: Vec3, scale: f64) -> u64 {
        self.kept_on(lo, hi, scale, true)
    }

    /// [`ShadowCull::kept`] with AVX, inlined into its caller (a kernel compiled for AVX2 or
    /// AVX-512).
    ///
    /// # Safety
    /// The CPU must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn kept_avx(&self, lo: Vec3, hi: Vec3) -> u64 {
        self.kept_on(lo, hi, 1.0, true)
    }

    /// [`ShadowCull::kept_with_margin`], the plane tests with AVX (which the CPU must have) or
    /// portably: the same answer.
    #[inline(always)]
    fn kept_on(&self, lo: Vec3, hi: Vec3, scale: f64, avx: bool) -> u64 {
        let l = self.light.map(f32::from_bits).map(f64::from);
        let (lo, hi) = (lo.to_array().map(f64::from), hi.to_array().map(f64::from));
        // `L − o` over the box: centre and half extent (widened for their rounding), and
        // the magnitudes the rounding terms scale with.
        let u_lo = [0, 1, 2].map(|k| l[k] - hi[k]);
        let u_hi = [0, 1, 2].map(|k| l[k] - lo[k]);
        let cu = [0, 1, 2].map(|k| 0.5 * (u_lo[k] + u_hi[k]));
        let ru =
            [0, 1, 2].map(|k| 0.5 * (u_hi[k] - u_lo[k]) + RHO * (u_lo[k].abs() + u_hi[k].abs()));
        let um: f64 = (0..3).map(|k| cu[k].abs() + ru[k]).sum();
        // R: |v − o| per axis; D: |L − o| per axis (and |d|, one rounding more).
        let r = (0..3)
            .map(|k| (self.hi[k] - lo[k]).max(hi[k] - self.lo[k]))
            .fold(0.0, f64::max)
            * (1.0 + RHO);
        let d = (0..3)
            .map(|k| u_lo[k].abs().max(u_hi[k].abs()))
            .fold(0.0, f64::max)
            * (1.0 + 4.0 * f32::EPSILON as f64);
        let (g2, g5) = (gamma(2) as f64, gamma(5) as f64);
        let x = r * (1.0 + SHEAR);
        let dx = g5 * (x + 2.0 * SHEAR * r) + 2.0 * TINY;
        let de = 4.0 * (4.0 * x * dx + g2 * 2.0 * x * x) + 4.0 * TINY;
        let eps = f32::EPSILON as f64 * 0.5;
        // The margin of one edge.
        let m = scale * (d * de + 6.0 * r * r * (eps * d + TINY) + RHO * self.mag * um);
        let mut neg = [0u64; 3];
        let mut pos = [0u64; 3];
        #[cfg(target_arch = "x86_64")]
        if avx {
            // SAFETY: the caller passes `avx` only where the CPU has it.
            unsafe { planes_avx(&self.groups, &cu, &ru, m, &mut neg, &mut pos) };
        }
        for (gi, g) in self.groups.iter().enumerate() {
            if avx {
                break;
            }
            for p in 0..3 {
                let margin = m;
                for lane in 0..4 {
                    let n = [0, 1, 2].map(|a| g.n[p][a][lane]);
                    let s = [0, 1, 2].map(|a| g.abs[p][a][lane]);
                    let f = n[0] * cu[0] + n[1] * cu[1] + n[2] * cu[2];
                    let s = s[0] * ru[0] + s[1] * ru[1] + s[2] * ru[2];
                    // A NaN compares false: kept.
                    neg[p] |= ((f + s < -margin) as u64) << (4 * gi + lane);
                    pos[p] |= ((f - s > margin) as u64) << (4 * gi + lane);
                }
            }
        }
        let culled = (neg[0] | neg[1] | neg[2]) & (pos[0] | pos[1] | pos[2]);
        let all = if self.tris.len() == 64 {
            u64::MAX
        } else {
            (1 << self.tris.len()) - 1
        };
        all & !culled
    }
}

/// [`ShadowCull::kept_with_margin`]'s plane tests for one group, four triangles at a time: per
/// plane, the lanes certainly negative and certainly positive over the box (bit per lane). The
/// same `f64` operations in the same order as the portable loop.
///
/// # Safety
/// The CPU must have AVX.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn planes4_avx(g: &Planes4, cu: &[f64; 3], ru: &[f64; 3], m: f64) -> ([u32; 3], [u32; 3]) {
    use std::arch::x86_64::*;
    // SAFETY: the CPU has AVX (this function's contract); each load reads a whole
    // 32-byte-aligned `[f64; 4]`. (No closure around the loads: this runs inlined into
    // kernels compiled for AVX2 or AVX-512, and a closure is compiled without them.)
    unsafe {
        macro_rules! ld {
            ($a:expr) => {
                _mm256_load_pd($a.as_ptr())
            };
        }
        let (c0, c1, c2) = (
            _mm256_set1_pd(cu[0]),
            _mm256_set1_pd(cu[1]),
            _mm256_set1_pd(cu[2]),
        );
        let (r0, r1, r2) = (
            _mm256_set1_pd(ru[0]),
            _mm256_set1_pd(ru[1]),
            _mm256_set1_pd(ru[2]),
        );
        let (mut neg, mut pos) = ([0; 3], [0; 3]);
        let margin = _mm256_set1_pd(m);
        let below = _mm256_sub_pd(_mm256_setzero_pd(), margin);
        for p in 0..3 {
            let n = &g.n[p];
            let a = &g.abs[p];
            let f = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(ld!(n[0]), c0), _mm256_mul_pd(ld!(n[1]), c1)),
                _mm256_mul_pd(ld!(n[2]), c2),
            );
            let s = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(ld!(a[0]), r0), _mm256_mul_pd(ld!(a[1]), r1)),
                _mm256_mul_pd(ld!(a[2]), r2),
            );
            neg[p] =
                _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_add_pd(f, s), below)) as u32;
            pos[p] =
                _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(_mm256_sub_pd(f, s), margin)) as u32;
        }
        (neg, pos)
    }
}

/// [`planes4_avx`] for every group, into `neg` and `pos` (bit per triangle).
///
/// # Safety
/// The CPU must have AVX.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn planes_avx(
    groups: &[Planes4],
    cu: &[f64; 3],
    ru: &[f64; 3],
    m: f64,
    neg: &mut [u64; 3],
    pos: &mut [u64; 3],
) {
    for (gi, g) in groups.iter().enumerate() {
        // SAFETY: the CPU has AVX (this function's contract).
        let (n4, p4) = unsafe { planes4_avx(g, cu, ru, m) };
        for p in 0..3 {
            neg[p] |= (n4[p] as u64) << (4 * gi);
            pos[p] |= (p4[p] as u64) << (4 * gi);
        }
    }
}

impl ShadowCull {
    /// Which of `lanes` of `rays` (origins with `o_kz` in `oz`, least and greatest) some kept
    /// triangle blocks before `t_max`, as [`crate::geometry::intersect_watertight`] decides; `ray(l)` is lane
    /// `l`'s ray, for the lanes the scalar test redoes.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub unsafe fn occluded8_avx2(
        &self,
        kept: u64,
        rays: &ShadowRays8,
        lanes: u32,
        oz: (f32, f32),
        t_max: f32,
        ray: impl Fn(usize) -> crate::geometry::Ray,
    ) -> u32 {
        // SAFETY: this function's contract.
        unsafe { self.occluded8(kept, rays, lanes, oz, t_max, ray) }
    }

    /// [`ShadowCull::occluded8_avx2`] inlined into its caller (the shading kernel, compiled
    /// for AVX2 or AVX-512).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn occluded8(
        &self,
        kept: u64,
        rays: &ShadowRays8,
        lanes: u32,
        oz: (f32, f32),
        t_max: f32,
        ray: impl Fn(usize) -> crate::geometry::Ray,
    ) -> u32 {
        let [kx, _, kz] = rays.axes;
        // `d_kz < 0` exactly when the axes are swapped.
        let forward = kx == (kz + 1) % 3;
        let mut blocked = 0;
        let mut kept = kept;
        while kept != 0 {
            let i = kept.trailing_zeros() as usize;
            kept &= kept - 1;
            let t = &self.tris[i];
            // Behind every origin along the packet's direction: rejected (module doc).
            if (forward && t.max[kz] <= oz.0) || (!forward && t.min[kz] >= oz.1) {
                continue;
            }
            // SAFETY: the CPU has AVX2 (this function's contract).
            let (hit, redo) = unsafe { any_hit8(&t.lanes, rays, t_max) };
            blocked |= hit & lanes;
            let mut redo = redo & lanes & !blocked;
            while redo != 0 {
                let l = redo.trailing_zeros() as usize;
                redo &= redo - 1;
                if crate::geometry::intersect_watertight(&ray(l), &t.v, t_max).is_some() {
                    blocked |= 1 << l;
                }
            }
            if blocked == lanes {
                break;
            }
        }
        blocked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Ray, intersect_watertight};
    use crate::rng::Rng;
    use crate::shading::SHADOW_EPSILON;

    fn uniform(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn point(rng: &mut Rng, r: f32) -> Vec3 {
        Vec3::new(
            uniform(rng, -r, r),
            uniform(rng, -r, r),
            uniform(rng, -r, r),
        )
    }

    /// Whether the scalar test accepts triangle `v` for the shadow ray from `o` to `light`.
    fn hits(v: &[Vec3; 3], o: Vec3, light: Vec3) -> bool {
        let d = light - o;
        d != Vec3::ZERO && intersect_watertight(&Ray::new(o, d), v, 1.0 - SHADOW_EPSILON).is_some()
    }

    /// Adversarial cases: origins whose shadow ray passes within rounding of an edge of the
    /// triangle (on the plane through the light and that edge), alone (a box of one point) or
    /// at a corner of a small box. Returns how many the cull with margin `scale` dropped
    /// although the scalar test hits them, and how many the scalar test hits at all.
    fn wrong_drops(scale: f64) -> (usize, usize) {
        let mut rng = Rng::seeded(11);
        let (mut wrong, mut hit) = (0, 0);
        for case in 0..20_000 {
            let scale_of_scene = [1.0, 1e-3, 300.0][case % 3];
            let v = [0, 1, 2].map(|_| point(&mut rng, scale_of_scene));
            let Ok(tri) = Triangle::new(v[0], v[1], v[2], 0) else {
                continue;
            };
            let light = point(&mut rng, scale_of_scene) * 2.0;
            // A point on edge `jk`, and an origin beyond it from the light.
            let e = case % 3;
            let (j, k) = ((e + 1) % 3, (e + 2) % 3);
            let a = uniform(&mut rng, 0.05, 0.95);
            let x = v[j] * a + v[k] * (1.0 - a);
            let o = light + (x - light) * uniform(&mut rng, 1.05, 3.0);
            let (lo, hi) = if case % 2 == 0 {
                (o, o)
            } else {
                let h = Vec3::splat(scale_of_scene * 1e-3) * Vec3::new(1.0, 0.5, 2.0);
                (o - h * uniform(&mut rng, 0.0, 1.0), o)
            };
            let cull = ShadowCull::new(&[tri], light);
            let h = hits(&v, o, light);
            hit += h as usize;
            if h && cull.kept_with_margin(Isa::detect(), lo, hi, scale) & 1 == 0 {
                wrong += 1;
            }
        }
        (wrong, hit)
    }

    #[test]
    fn the_cull_never_drops_a_triangle_the_scalar_test_hits() {
        let (wrong, hit) = wrong_drops(1.0);
        assert!(hit > 1000, "too few hits to test anything: {hit}");
        assert_eq!(wrong, 0, "{wrong} of {hit} hits dropped");
    }

    /// The margin is needed: without it, the same cases drop triangles that rays graze and hit.
    #[test]
    fn without_its_margin_the_cull_drops_hits() {
        let (wrong, hit) = wrong_drops(0.0);
        assert!(
            wrong > 0,
            "no hit dropped of {hit}: the cases are not adversarial"
        );
    }

    /// Random boxes of origins and triangles: whatever the cull drops, no ray from a corner, the
    /// centre or a random point of the box hits; and it does drop most of what lies aside.
    #[test]
    fn the_cull_is_sound_and_drops_what_lies_aside() {
        let mut rng = Rng::seeded(12);
        let (mut dropped, mut total) = (0, 0);
        for case in 0..5000 {
            let tris: Vec<Triangle> = (0..1 + case % 40)
                .filter_map(|_| {
                    let c = point(&mut rng, 1.0);
                    {
                        let [a, b, d] = [0, 1, 2].map(|_| c + point(&mut rng, 0.3));
                        Triangle::new(a, b, d, 0).ok()
                    }
                })
                .collect();
            let light = point(&mut rng, 1.0);
            let c = point(&mut rng, 1.0);
            let h = point(&mut rng, [0.0, 0.01, 0.1][case % 3]).abs();
            let (lo, hi) = (c - h, c + h);
            let cull = ShadowCull::new(&tris, light);
            let kept = cull.kept(Isa::detect(), lo, hi);
            if Isa::Avx2.available() {
                assert_eq!(
                    cull.kept_on(lo, hi, 1.0, true),
                    cull.kept_on(lo, hi, 1.0, false)
                );
            }
            for (i, t) in tris.iter().enumerate() {
                total += 1;
                if kept >> i & 1 == 1 {
                    continue;
                }
                dropped += 1;
                for o in (0..12).map(|k| match k {
                    0..8 => Vec3::new(
                        [lo.x, hi.x][k & 1],
                        [lo.y, hi.y][k >> 1 & 1],
                        [lo.z, hi.z][k >> 2 & 1],
                    ),
                    8 => c,
                    _ => lo + (hi - lo) * Vec3::new(uniform(&mut rng, 0.0, 1.0), 0.5, 0.3),
                }) {
                    assert!(
                        !hits(&t.v, o, light),
                        "case {case}: dropped triangle {i} hit from {o}"
                    );
                }
            }
        }
        assert!(dropped * 2 > total, "dropped only {dropped} of {total}");
    }
}
