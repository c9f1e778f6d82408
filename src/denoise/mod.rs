//! The denoiser for path-traced indirect light: an edge-aware à-trous wavelet filter in the
//! manner of SVGF (Schied et al. 2017), run on the indirect irradiance alone.
//!
//! The direct light of a point light is exact per pixel (one shadow ray), so only the indirect
//! term is noisy, and on diffuse walls that term is smooth. The render splits every sample
//! ([`crate::shading::SplitSample`]) and sums the parts into [`Guides`]; the filter divides the
//! indirect light by the albedo (so texture and colour edges are not blurred), smooths that
//! irradiance over neighbours on the same surface, and multiplies the albedo back. Neighbours
//! count only if they lie on the same object (seen through the same number of mirrors), face
//! the same way, lie in the same plane, and, as the variance shrinks, have a similar colour:
//! so the filter does not bleed across silhouettes, creases or mirrors.
//!
//! An edge-stopping filter is biased by as much as the noise it stops at: where the light
//! changes (a corner, a coloured light's pool), it pulls each pixel towards neighbours within a
//! few standard deviations of it, always from the same side, and that does not average away
//! over a region as noise does. So after filtering, what the filter took from each pixel (the
//! raw value minus the filtered one) is handed back to its neighbourhood on the same surface
//! ([`restore`]): a pixel's local mean is the raw image's again, and as samples accumulate the
//! denoised image converges to the raw (unbiased) one, blocks of pixels included. Where the
//! difference is mostly noise (few samples), it is shrunk away instead of handed back.
//!
//! Everything here is per-pixel arithmetic on fixed neighbourhoods (no fused multiply-add, no
//! platform `exp`): the same guides give the same bits on any thread count and any x86-64.

mod guides;

pub use guides::{GuidePixel, Guides, luminance};

use glam::Vec3;
use rayon::prelude::*;

use crate::image::Image;

/// À-trous passes: the taps of pass `i` are `2^i` pixels apart, so four passes of a 3×3 kernel
/// reach 15 pixels out. Measured at 200×100 against the 4096-spp reference (`cargo run
/// --release --example denoise_eval`): RMSE 0.0248 / 0.0136 / 0.0087 at 1 / 4 / 16 spp with
/// four passes and a 3×3 variance window, 0.0244 / 0.0142 / 0.0098 with five and 5×5, for
/// 28 % fewer instructions.
pub const ITERATIONS: u32 = 4;

/// Normal weight: `(n_p·n_q)^(2^NORMAL_POWER_LOG2)` = `(n_p·n_q)^16`: half weight at about
/// 20°, so the facets of the procedural sphere blend and the faces of a block (90°) do not.
const NORMAL_POWER_LOG2: u32 = 4;

/// Plane weight: a neighbour counts fully when the step to it lies in the pixel's tangent
/// plane, and not at all when the step's cosine with the normal exceeds this (about 17°): a
/// silhouette in front of a parallel surface is a step along the view, far out of the plane,
/// while a curved surface's neighbours stay close to it. Measured with `denoise_sheet` on the
/// sphere (1 spp against 64): RMSE 0.0510 at 0.1 and 32nd-power normals, 0.0457 at 0.3 and
/// 16th; the Cornell box is the same either way (0.0248).
const PLANE_COS: f32 = 0.3;

/// Luminance weight: a difference of this many standard deviations of the noise halves a
/// neighbour's weight (roughly; SVGF's σ_l = 4).
const SIGMA_LUMINANCE: f32 = 4.0;

/// Colour weight: a difference of this many standard deviations in any one channel halves a
/// neighbour's weight too, each channel's deviation being the luminance's scaled by the
/// channel's share of the local mean. A difference the luminance does not see (a red pool
/// beside a blue one) is fixed while the noise shrinks, so this stops the filter once samples
/// are many; looser than the luminance's, so that at few samples, where one channel's
/// difference is mostly noise, it hardly adds to it. Measured (160×100, `denoise_bias`,
/// cornell/mirror/lights): with the luminance alone the frames kept up to 1.25–1.5× the raw
/// block error at 256–1024 spp; with 6, at most 1.18× (1 spp: 0.029 on the box); with 8,
/// 1.22× (0.028); both with a 7×7 restore window.
const SIGMA_COLOUR: f32 = 6.0;

/// What the filter took from a pixel is handed back over this radius (a 5×5 window on the
/// same surface). Smaller windows put back more noise; larger ones carry a pixel's light
/// further from it. Measured (160×100, `denoise_bias`, cornell/mirror/lights): block error
/// from 256 spp at most 1.11× raw's with 2, 1.18× with 3; 1 spp on the box 0.030 and 0.029.
const RESTORE_RADIUS: i32 = 2;

/// Below this many samples a difference is handed back only where it stands out from the
/// noise (the variance of the window's mean difference counts `RESTORE_SAMPLES / samples`
/// times), so the first frames keep the filter's smoothing; above it, ever more of the
/// difference comes back, all of it in the limit. Measured (160×100, `denoise_bias`, a 7×7
/// window, colour σ 8): 1 spp RMSE 0.028 on the Cornell box and block error from 256 spp at
/// most 1.22× raw's; with 4 here, 0.029 and 1.22×.
const RESTORE_SAMPLES: f32 = 16.0;

/// Albedo channels below this are not demodulated (a division by almost nothing would blow
/// the noise up); such a channel keeps its raw indirect light.
const MIN_ALBEDO: f32 = 1e-3;

/// Keeps the luminance weight finite where the variance is zero.
const VARIANCE_EPSILON: f32 = 1e-10;

/// The spatial variance estimate averages moments over this radius (a 3×3 window).
const VARIANCE_RADIUS: i32 = 1;

/// A denoised frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Denoised {
    /// The filtered image: `rest + albedo·filtered irradiance`.
    pub image: Image,
    /// Estimated RMSE of the raw image from its per-pixel variance (noise only).
    pub raw_error: f32,
    /// The same estimate for the filtered image, the variance carried through the filter
    /// (noise only: the filter's own bias is not in it).
    pub error: f32,
}

/// The guide data one pass reads, laid out for the loop (structure of arrays).
struct Surface {
    normal: Vec<Vec3>,
    position: Vec<Vec3>,
    /// Object and reflection count; `u64::MAX` for a pixel left out of the filter.
    key: Vec<u64>,
}

/// Denoises a frame's indirect light. The image has the guides' size.
pub fn denoise(g: &Guides) -> Denoised {
    let (w, h) = (g.width as usize, g.height as usize);
    let n = w * h;
    let surface = Surface {
        normal: g
            .pixels
            .iter()
            .map(|p| p.guide.map_or(Vec3::ZERO, |s| s.normal))
            .collect(),
        position: g
            .pixels
            .iter()
            .map(|p| p.guide.map_or(Vec3::ZERO, |s| s.position))
            .collect(),
        key: g
            .pixels
            .iter()
            .map(|p| match p.guide {
                Some(s) if p.albedo.max_element() >= MIN_ALBEDO => {
                    (u64::from(s.reflections) << 32) | u64::from(s.object)
                }
                _ => u64::MAX,
            })
            .collect(),
    };
    let mut var = spatial_variance(g, &surface);
    let raw_error = error_estimate(g, &var);
    // No firefly clamp: cutting bright pixels down to a few deviations above their
    // neighbourhood removed energy, and as the deviations shrank with more samples it cut the
    // true highlights of the light (the bias the `lights` scene showed at 1024 spp).
    let raw: Vec<Vec3> = g.pixels.iter().map(demodulate).collect();
    let mut e = raw.clone();
    if n > 0 {
        let mut e_next = vec![Vec3::ZERO; n];
        let mut var_next = vec![0.0; n];
        let mut scale = vec![Vec3::ZERO; n];
        for i in 0..ITERATIONS {
            let step = 1usize << i;
            channel_scales(w, h, &surface, &e, &var, &mut scale);
            e_next
                .par_chunks_mut(w)
                .zip(var_next.par_chunks_mut(w))
                .enumerate()
                .for_each(|(y, (e_row, v_row))| {
                    for x in 0..w {
                        (e_row[x], v_row[x]) =
                            filter_pixel(x, y, w, h, step, &surface, &e, &var, &scale);
                    }
                });
            std::mem::swap(&mut e, &mut e_next);
            std::mem::swap(&mut var, &mut var_next);
        }
        e = restore(w, h, g.samples, &surface, &raw, &e);
    }
    let error = error_estimate(g, &var);
    let pixels = g
        .pixels
        .iter()
        .zip(&e)
        .map(|(p, &f)| p.rest + remodulate(p, f))
        .collect();
    Denoised {
        image: Image {
            width: g.width,
            height: g.height,
            pixels,
        },
        raw_error,
        error,
    }
}

/// The pixel's indirect irradiance: its indirect light divided by its albedo, per channel
/// (0 where the albedo is too small to divide by).
fn demodulate(p: &GuidePixel) -> Vec3 {
    let d = |i: f32, a: f32| if a >= MIN_ALBEDO { i / a } else { 0.0 };
    Vec3::new(
        d(p.indirect.x, p.albedo.x),
        d(p.indirect.y, p.albedo.y),
        d(p.indirect.z, p.albedo.z),
    )
}

/// The indirect light from a filtered irradiance `f`: `albedo·f`, with the raw indirect
/// light kept in channels that were not demodulated.
fn remodulate(p: &GuidePixel, f: Vec3) -> Vec3 {
    if p.guide.is_none() || p.albedo.max_element() < MIN_ALBEDO {
        return p.indirect;
    }
    let r = |i: f32, a: f32, f: f32| if a >= MIN_ALBEDO { a * f } else { i };
    Vec3::new(
        r(p.indirect.x, p.albedo.x, f.x),
        r(p.indirect.y, p.albedo.y, f.y),
        r(p.indirect.z, p.albedo.z, f.z),
    )
}

/// How much neighbour `q` of pixel `p` counts, from the surfaces alone (0 to 1).
#[inline]
fn geometric_weight(s: &Surface, p: usize, q: usize) -> f32 {
    if s.key[q] != s.key[p] {
        return 0.0;
    }
    let mut c = s.normal[p].dot(s.normal[q]).max(0.0);
    for _ in 0..NORMAL_POWER_LOG2 {
        c *= c;
    }
    let step = s.position[q] - s.position[p];
    let len = step.length();
    let plane = if len > 0.0 {
        (1.0 - s.normal[p].dot(step).abs() / (len * PLANE_COS)).max(0.0)
    } else {
        1.0
    };
    c * plane
}

/// The per-pixel variance of the mean irradiance's luminance, estimated from the moments of
/// the neighbours on the same surface (one sample per pixel has no variance of its own):
/// `(E[l²] − E[l]²) / samples`.
fn spatial_variance(g: &Guides, s: &Surface) -> Vec<f32> {
    let (w, h) = (g.width as usize, g.height as usize);
    let mut out = vec![0.0; w * h];
    let samples = g.samples.max(1) as f32;
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let p = y * w + x;
                if s.key[p] == u64::MAX {
                    continue;
                }
                let (mut m1, mut m2, mut sum) = (0.0f32, 0.0f32, 0.0f32);
                for dy in -VARIANCE_RADIUS..=VARIANCE_RADIUS {
                    for dx in -VARIANCE_RADIUS..=VARIANCE_RADIUS {
                        let (qx, qy) = (x as i32 + dx, y as i32 + dy);
                        if qx < 0 || qy < 0 || qx >= w as i32 || qy >= h as i32 {
                            continue;
                        }
                        let q = qy as usize * w + qx as usize;
                        let wt = geometric_weight(s, p, q);
                        if wt > 0.0 {
                            m1 += wt * g.pixels[q].moments[0];
                            m2 += wt * g.pixels[q].moments[1];
                            sum += wt;
                        }
                    }
                }
                let (m1, m2) = (m1 / sum, m2 / sum);
                *v = (m2 - m1 * m1).max(0.0) / samples;
            }
        });
    out
}

/// One à-trous tap set for pixel (x, y): the weighted mean of the irradiance of its 3×3
/// neighbours `step` pixels apart, and the variance of that mean.
#[allow(clippy::too_many_arguments)]
#[inline]
fn filter_pixel(
    x: usize,
    y: usize,
    w: usize,
    h: usize,
    step: usize,
    s: &Surface,
    e: &[Vec3],
    var: &[f32],
    scale: &[Vec3],
) -> (Vec3, f32) {
    const KERNEL: [f32; 3] = [0.25, 0.5, 0.25];
    let p = y * w + x;
    if s.key[p] == u64::MAX {
        return (e[p], var[p]);
    }
    let (ep, scale) = (e[p], scale[p]);
    let lp = luminance(ep);
    let lum_scale = 1.0 / (SIGMA_LUMINANCE * var[p].sqrt() + VARIANCE_EPSILON);
    let (mut sum_e, mut sum_v, mut sum_w) = (Vec3::ZERO, 0.0f32, 0.0f32);
    for (ky, &hy) in KERNEL.iter().enumerate() {
        let qy = y as isize + (ky as isize - 1) * step as isize;
        if qy < 0 || qy >= h as isize {
            continue;
        }
        for (kx, &hx) in KERNEL.iter().enumerate() {
            let qx = x as isize + (kx as isize - 1) * step as isize;
            if qx < 0 || qx >= w as isize {
                continue;
            }
            let q = qy as usize * w + qx as usize;
            let g = if q == p {
                1.0
            } else {
                geometric_weight(s, p, q)
            };
            if g <= 0.0 {
                continue;
            }
            let d = ((luminance(e[q]) - lp).abs() * lum_scale)
                .max(((e[q] - ep).abs() * scale).max_element());
            // exp(−d) without the platform's exp (whose rounding may vary by CPU): a rational
            // with the same start and a tail as long.
            let wl = 1.0 / (1.0 + d + 0.5 * d * d);
            let wt = hx * hy * g * wl;
            sum_e += e[q] * wt;
            sum_v += wt * wt * var[q];
            sum_w += wt;
        }
    }
    (sum_e / sum_w, sum_v / (sum_w * sum_w))
}

/// Per pixel, the reciprocal of `SIGMA_COLOUR` standard deviations of each channel of the
/// irradiance: the luminance's deviation (from `var`) times the channel's share of the mean of
/// `e` over the 3×3 neighbours on the same surface, so that the colour weight compares each
/// channel with its own noise (and no other surface's light sways it).
fn channel_scales(w: usize, h: usize, s: &Surface, e: &[Vec3], var: &[f32], out: &mut [Vec3]) {
    /// Keeps the shares finite where the light is black.
    const TINY: f32 = 1e-6;
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let p = y * w + x;
            if s.key[p] == u64::MAX {
                continue;
            }
            let mut sum = Vec3::ZERO;
            let mut count = 0.0f32;
            for qy in y.saturating_sub(1)..(y + 2).min(h) {
                for qx in x.saturating_sub(1)..(x + 2).min(w) {
                    let q = qy * w + qx;
                    if s.key[q] == s.key[p] {
                        sum += e[q];
                        count += 1.0;
                    }
                }
            }
            let mean = sum / count;
            let share = mean.max(Vec3::splat(TINY)) / luminance(mean).max(TINY);
            let sigma = share * (SIGMA_COLOUR * var[p].sqrt());
            *o = Vec3::ONE / (sigma + Vec3::splat(VARIANCE_EPSILON));
        }
    });
}

/// The restore's neighbours share a surface when their normals are within the angle at which
/// `geometric_weight`'s normal term halves: `2^(−1/16)`, about 17°.
const SAME_NORMAL_COS: f32 = 0.957_603_3;

/// Whether pixel `q` counts as `p`'s neighbour for the restore: the same object seen through
/// the same mirrors, normals within about 17°, and each in the other's plane as far as
/// `geometric_weight`'s plane term counts it at least half. Symmetric in `p` and `q` (what one
/// hands to the other is what the other counts) and all-or-nothing, so a window is a bit mask
/// worked out once, without a square root or a division.
#[inline]
fn shares_surface(s: &Surface, p: usize, q: usize) -> bool {
    if s.key[p] != s.key[q] || s.key[p] == u64::MAX {
        return false;
    }
    let (np, nq) = (s.normal[p], s.normal[q]);
    if np.dot(nq) < SAME_NORMAL_COS {
        return false;
    }
    let step = s.position[q] - s.position[p];
    let limit = (0.5 * PLANE_COS) * (0.5 * PLANE_COS) * step.length_squared();
    let (a, b) = (np.dot(step), nq.dot(step));
    a * a <= limit && b * b <= limit
}

/// The side of the restore's window.
const RESTORE_SIDE: usize = 2 * RESTORE_RADIUS as usize + 1;
const _: () = assert!(
    RESTORE_SIDE * RESTORE_SIDE <= 64,
    "a window's mask is one u64"
);

/// Per pixel, which pixels of its window share its surface: bit `(dy + r)·side + (dx + r)`.
fn restore_masks(w: usize, h: usize, s: &Surface) -> Vec<u64> {
    let r = RESTORE_RADIUS as isize;
    let mut masks = vec![0u64; w * h];
    masks.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, m) in row.iter_mut().enumerate() {
            let p = y * w + x;
            if s.key[p] == u64::MAX {
                continue;
            }
            for dy in -r..=r {
                for dx in -r..=r {
                    let (qx, qy) = (x as isize + dx, y as isize + dy);
                    if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                        continue;
                    }
                    if shares_surface(s, p, qy as usize * w + qx as usize) {
                        *m |= 1 << ((dy + r) as usize * RESTORE_SIDE + (dx + r) as usize);
                    }
                }
            }
        }
    });
    masks
}

/// The pixels a window's mask names, in bit order.
fn window(p: usize, w: usize, mut mask: u64) -> impl Iterator<Item = usize> {
    let r = RESTORE_RADIUS as isize;
    std::iter::from_fn(move || {
        if mask == 0 {
            return None;
        }
        let bit = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        let (dy, dx) = (
            (bit / RESTORE_SIDE) as isize - r,
            (bit % RESTORE_SIDE) as isize - r,
        );
        Some((p as isize + dy * w as isize + dx) as usize)
    })
}

/// Hands what the filter took from each pixel back to its neighbourhood on the same surface:
/// `f_p + Σ_q k_q·(raw_q − f_q)/n_q` over the pixels q whose windows hold p, `n_q` the size of
/// q's window, so that each pixel's difference is shared out whole (the local mean is kept,
/// unlike a plain average of the differences, which over-counts the pixels at a surface's
/// edge, where the bias is). `k` per channel is a Wiener factor
/// `b²/(b² + var b·RESTORE_SAMPLES/samples)` of the window's mean difference `b`: about 1
/// where the difference is systematic (the filter's bias), about 0 where it is noise (few
/// samples, where handing it back would undo the filter).
fn restore(w: usize, h: usize, samples: u32, s: &Surface, raw: &[Vec3], f: &[Vec3]) -> Vec<Vec3> {
    let noise_weight = RESTORE_SAMPLES / samples.max(1) as f32;
    let masks = restore_masks(w, h, s);
    // What each pixel hands to each pixel of its window.
    let mut share = vec![Vec3::ZERO; w * h];
    share.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let q = y * w + x;
            if masks[q] == 0 {
                continue;
            }
            let (mut m1, mut m2) = (Vec3::ZERO, Vec3::ZERO);
            for p in window(q, w, masks[q]) {
                let d = raw[p] - f[p];
                m1 += d;
                m2 += d * d;
            }
            // The pixel itself is always in its window.
            let n = masks[q].count_ones() as f32;
            let b = m1 / n;
            let var_b = (m2 / n - b * b).max(Vec3::ZERO) * (noise_weight / n);
            let b2 = b * b;
            let total = b2 + var_b;
            let k = Vec3::select(total.cmpgt(Vec3::ZERO), b2 / total, Vec3::ZERO);
            *o = (raw[q] - f[q]) * k / n;
        }
    });
    let mut out = f.to_vec();
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let p = y * w + x;
            for q in window(p, w, masks[p]) {
                *o += share[q];
            }
        }
    });
    out
}

/// An RMSE estimate from per-pixel luminance variances: `sqrt(mean(lum(albedo)²·var))` over
/// the filtered pixels, counted over all pixels.
fn error_estimate(g: &Guides, var: &[f32]) -> f32 {
    if g.pixels.is_empty() {
        return 0.0;
    }
    let sum: f64 = g
        .pixels
        .iter()
        .zip(var)
        .map(|(p, &v)| {
            let a = f64::from(luminance(p.albedo));
            a * a * f64::from(v)
        })
        .sum();
    (sum / g.pixels.len() as f64).sqrt() as f32
}
