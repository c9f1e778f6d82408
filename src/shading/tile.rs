//! The per-light arithmetic of [`Tracer::shade_tile`] eight pixels at a time: each pixel's
//! unshadowed term and shadow ray exactly as [`Tracer::light_term`] computes them (the same
//! `f32` operations in the same order, no fused multiply-add; the next-float steps of
//! `offset_ray_origin` as integer steps on the bits), with AVX2 on the AVX2 and AVX-512 paths.

use glam::Vec3;

use super::Tracer;
use crate::geometry::Ray;
use crate::scene::PointLight;
use crate::simd::Isa;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::__m256;

/// One pixel being shaded: hit point, its error bound, the normal facing the ray, its index.
pub(super) type At = (Vec3, Vec3, Vec3, usize);

/// What one light gives one pixel: its term and shadow ray, or nothing ([`Tracer::light_term`]).
pub(super) type Term = Option<(Vec3, Option<Ray>)>;

impl Tracer<'_> {
    /// [`Tracer::light_term`] of `light` for every pixel of `at`, appended to `out` in order.
    pub(super) fn light_terms(&self, light: &PointLight, at: &[At], out: &mut Vec<Term>) {
        #[cfg(target_arch = "x86_64")]
        if light.power != Vec3::ZERO && matches!(self.scene.isa(), Isa::Avx2 | Isa::Avx512) {
            for chunk in at.chunks(8) {
                // SAFETY: the CPU has AVX2 (the scene's path is only set where it is available).
                unsafe { self.light_terms8_avx2(light, chunk, out) };
            }
            return;
        }
        out.extend(
            at.iter()
                .map(|&(p, err, normal, _)| self.light_term(light, p, err, normal)),
        );
    }

    /// Up to eight pixels of [`Tracer::light_terms`] (the light's power is not zero).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn light_terms8_avx2(&self, light: &PointLight, at: &[At], out: &mut Vec<Term>) {
        use std::arch::x86_64::*;
        let n = at.len();
        debug_assert!((1..=8).contains(&n));
        // Lanes past the end repeat the last pixel (never used).
        let mut soa = [[0f32; 8]; 9];
        for l in 0..8 {
            let (p, e, nn, _) = at[l.min(n - 1)];
            for k in 0..3 {
                soa[k][l] = p[k];
                soa[3 + k][l] = e[k];
                soa[6 + k][l] = nn[k];
            }
        }
        // SAFETY: reads eight `f32`s.
        let ld = |a: &[f32; 8]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        let [px, py, pz, ex, ey, ez, nx, ny, nz] = soa.each_ref().map(ld);
        let LightLanes {
            term,
            origin,
            dir,
            lit,
            traced,
        } = light_lanes_avx2(light, self.min_r2, [px, py, pz], [ex, ey, ez], [nx, ny, nz]);
        let inv = dir.map(|d| _mm256_div_ps(_mm256_set1_ps(1.0), d));
        let store = |v: __m256| {
            let mut a = [0f32; 8];
            // SAFETY: writes eight `f32`s.
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
            a
        };
        let (term, origin, dir, inv) = (
            term.map(store),
            origin.map(store),
            dir.map(store),
            inv.map(store),
        );
        let v = |a: &[[f32; 8]; 3], l: usize| Vec3::new(a[0][l], a[1][l], a[2][l]);
        for l in 0..n {
            out.push((lit & 1 << l != 0).then(|| {
                let shadow = (self.settings.effects.shadows && traced & 1 << l != 0)
                    .then(|| Ray::with_inverse(v(&origin, l), v(&dir, l), v(&inv, l)));
                (v(&term, l), shadow)
            }));
        }
    }
}

/// One light's arithmetic for eight pixels ([`light_lanes_avx2`]).
#[cfg(target_arch = "x86_64")]
pub(super) struct LightLanes {
    /// The unshadowed term per channel.
    pub term: [__m256; 3],
    /// The shadow ray's origin (the offset hit point) and direction (to the light).
    pub origin: [__m256; 3],
    pub dir: [__m256; 3],
    /// The lanes lit, and the lanes with a shadow ray to trace (a bit per lane).
    pub lit: u32,
    pub traced: u32,
}

/// [`Tracer::light_term`]'s arithmetic for eight pixels (hit point `p`, its error `err`, the
/// normal `n` facing the ray, each as x, y, z lanes), the same `f32` operations in the same
/// order; `min_r2` is the tracer's. Shared by the tile's two shading paths.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn light_lanes_avx2(
    light: &PointLight,
    min_r2: f32,
    p: [__m256; 3],
    err: [__m256; 3],
    n: [__m256; 3],
) -> LightLanes {
    use std::arch::x86_64::*;
    use std::f32::consts::PI;
    let [px, py, pz] = p;
    let [ex, ey, ez] = err;
    let [nx, ny, nz] = n;
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
    let denom = mul(sp(4.0 * PI), _mm256_max_ps(dist2, sp(min_r2)));
    let pw = light.power;
    let mut term = [div(mul(sp(pw.x), cos), denom); 3];
    // A white light's three terms are one value (the same operations on the same inputs).
    if pw.y.to_bits() != pw.x.to_bits() || pw.z.to_bits() != pw.x.to_bits() {
        term[1] = div(mul(sp(pw.y), cos), denom);
        term[2] = div(mul(sp(pw.z), cos), denom);
    }
    // `offset_ray_origin(p, err, normal, to_light)`.
    let d = add(add(mul(abs(nx), ex), mul(abs(ny), ey)), mul(abs(nz), ez));
    let wn = add(add(mul(tx, nx), mul(ty, ny)), mul(tz, nz));
    let flip = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(wn, zero), sign);
    let inf = sp(f32::INFINITY);
    let mut nonzero = zero;
    let mut finite = _mm256_cmp_ps::<_CMP_EQ_OQ>(zero, zero);
    let mut origin = [zero; 3];
    let mut dir = [zero; 3];
    for (k, (p, nk)) in [(px, nx), (py, ny), (pz, nz)].into_iter().enumerate() {
        let offset = _mm256_xor_ps(mul(nk, d), flip);
        origin[k] = offset_step_avx2(add(p, offset), offset);
        dir[k] = sub(sp(lp[k]), origin[k]);
        nonzero = _mm256_or_ps(nonzero, _mm256_cmp_ps::<_CMP_NEQ_UQ>(dir[k], zero));
        finite = _mm256_and_ps(finite, _mm256_cmp_ps::<_CMP_LT_OQ>(abs(dir[k]), inf));
    }
    LightLanes {
        term,
        origin,
        dir,
        lit: _mm256_movemask_ps(lit) as u32,
        traced: _mm256_movemask_ps(_mm256_and_ps(nonzero, finite)) as u32,
    }
}

/// The last step of `offset_ray_origin` in eight lanes: each lane of `v` (the point plus its
/// offset) moved one float up where `off` is positive and one float down where it is
/// negative, as `next_float_up` and `next_float_down` do it (integer steps on the bits). Only
/// callable from code compiled for AVX2, where it inlines.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
fn offset_step_avx2(
    v: std::arch::x86_64::__m256,
    off: std::arch::x86_64::__m256,
) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    let zero = _mm256_setzero_ps();
    let sign = _mm256_set1_ps(-0.0);
    let one = _mm256_set1_epi32(1);
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
    let keep = _mm256_or_ps(
        _mm256_cmp_ps::<_CMP_EQ_OQ>(v, _mm256_set1_ps(f32::INFINITY)),
        nan,
    );
    let up = _mm256_blendv_ps(up, v, keep);
    // `next_float_down`: ±0 → −0, then one step toward −∞; −∞ and NaN stay.
    let w = _mm256_blendv_ps(v, sign, is_zero);
    let wb = _mm256_castps_si256(w);
    let down = _mm256_blendv_ps(
        _mm256_castsi256_ps(_mm256_add_epi32(wb, one)),
        _mm256_castsi256_ps(_mm256_sub_epi32(wb, one)),
        _mm256_cmp_ps::<_CMP_GT_OQ>(w, zero),
    );
    let keep = _mm256_or_ps(
        _mm256_cmp_ps::<_CMP_EQ_OQ>(v, _mm256_set1_ps(f32::NEG_INFINITY)),
        nan,
    );
    let down = _mm256_blendv_ps(down, v, keep);
    let v = _mm256_blendv_ps(v, down, _mm256_cmp_ps::<_CMP_LT_OQ>(off, zero));
    _mm256_blendv_ps(v, up, _mm256_cmp_ps::<_CMP_GT_OQ>(off, zero))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::cornell::cornell_box;
    use crate::shading::Stage;

    /// A small generator for the test (xorshift).
    fn next(s: &mut u64) -> f32 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        (*s >> 40) as f32 / (1u64 << 24) as f32
    }

    #[test]
    fn eight_at_a_time_is_one_at_a_time_bit_for_bit() {
        let scene = cornell_box();
        let bits = |t: &Term| {
            t.map(|(term, ray)| {
                (
                    term.to_array().map(f32::to_bits),
                    ray.map(|r| {
                        let v =
                            [r.origin, r.dir, r.inv_dir].map(|v| v.to_array().map(f32::to_bits));
                        (v, r.axes(), r.shear().map(f32::to_bits))
                    }),
                )
            })
        };
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        for case in 0..4000 {
            let mut r = || next(&mut s) * 2.0 - 1.0;
            let scale = [1e-6f32, 1.0, 1e4][case % 3];
            let light = PointLight {
                position: Vec3::new(r(), r(), r()) * scale,
                power: Vec3::new(r().abs() * 20.0, 3.0, r().abs()),
            };
            let at: Vec<At> = (0..1 + case % 8)
                .map(|i| {
                    let mut p = Vec3::new(r(), r(), r()) * scale;
                    // Edge cases: the light itself, signed zeros, no error.
                    match (case + i) % 9 {
                        0 => p = light.position,
                        1 => p = Vec3::new(-0.0, 0.0, r()),
                        _ => {}
                    }
                    let err = if (case + i) % 7 == 0 {
                        Vec3::ZERO
                    } else {
                        (Vec3::new(r(), r(), r()).abs() + Vec3::splat(0.1)) * 1e-6 * scale
                    };
                    let n = Vec3::new(r(), r(), r()).normalize_or(Vec3::Y);
                    // A point the offset takes exactly to 0 in x (one of the two signs does).
                    if (case + i) % 5 == 0 {
                        let d = n.abs().dot(err);
                        p.x = if i % 2 == 0 { n.x * d } else { -(n.x * d) };
                    }
                    (p, err, n, i)
                })
                .collect();
            for shadows in [true, false] {
                let mut settings = Stage::Indirect.settings(scene.effects());
                settings.effects.shadows = shadows;
                let lights = [light];
                let tracer = Tracer::new(&scene, &lights, settings);
                let mut got = vec![];
                tracer.light_terms(&light, &at, &mut got);
                assert_eq!(got.len(), at.len());
                for (g, &(p, err, n, _)) in got.iter().zip(&at) {
                    let want = tracer.light_term(&light, p, err, n);
                    assert_eq!(
                        bits(g),
                        bits(&want),
                        "case {case}: p {p} err {err} n {n} light {light:?}"
                    );
                }
            }
        }
    }
}
