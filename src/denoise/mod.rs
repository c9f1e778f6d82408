//! The denoiser for path-traced indirect light: an edge-aware à-trous wavelet filter in the
//! manner of SVGF (Schied et al. 2017), run on the indirect irradiance alone.
//!
//! The direct light of a point light is exact per pixel (one shadow ray), so only the indirect
//! term is noisy, and on diffuse walls that term is smooth. The render splits every sample
//! ([`crate::shading::SplitSample`]) and sums the parts into [`Guides`]; the filter divides the
//! indirect light by the albedo (so texture and colour edges are not blurred), smooths that
//! irradiance over neighbours on the same surface, and multiplies the albedo back. Neighbours
//! count only if they lie on the same object (seen through the same number of mirrors), face
//! the same way, lie in the same plane, and, as the variance shrinks, have a similar
//! luminance: so the filter does not bleed across silhouettes, creases or mirrors, and its
//! strength falls as samples accumulate, down to the raw (unbiased) image.
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

/// A pixel's irradiance is clamped to this many standard deviations (of a pixel's mean) above
/// its neighbourhood's mean luminance. As samples accumulate the deviation of a mean shrinks
/// and so does what lies beyond it: the clamp fades with the noise.
const FIREFLY_SIGMAS: f32 = 3.0;

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
    let moments = spatial_variance(g, &surface);
    let mut var: Vec<f32> = moments.iter().map(|m| m.0).collect();
    let raw_error = error_estimate(g, &var);
    // Outliers (a bounce that found the light from close by) are pulled down to
    // FIREFLY_SIGMAS standard deviations above their surface's mean before filtering: a
    // filter that stops at luminance edges would otherwise keep them as bright dots.
    let mut e: Vec<Vec3> = g
        .pixels
        .iter()
        .zip(&moments)
        .map(|(p, &(v, mean))| {
            let e = demodulate(p);
            let cap = mean + FIREFLY_SIGMAS * v.sqrt();
            let l = luminance(e);
            if l > cap && l > 0.0 { e * (cap / l) } else { e }
        })
        .collect();
    if n > 0 {
        let mut e_next = vec![Vec3::ZERO; n];
        let mut var_next = vec![0.0; n];
        for i in 0..ITERATIONS {
            let step = 1usize << i;
            e_next
                .par_chunks_mut(w)
                .zip(var_next.par_chunks_mut(w))
                .enumerate()
                .for_each(|(y, (e_row, v_row))| {
                    for x in 0..w {
                        (e_row[x], v_row[x]) = filter_pixel(x, y, w, h, step, &surface, &e, &var);
                    }
                });
            std::mem::swap(&mut e, &mut e_next);
            std::mem::swap(&mut var, &mut var_next);
        }
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
/// `(E[l²] − E[l]²) / samples`; and the neighbours' mean luminance `E[l]`.
fn spatial_variance(g: &Guides, s: &Surface) -> Vec<(f32, f32)> {
    let (w, h) = (g.width as usize, g.height as usize);
    let mut out = vec![(0.0, 0.0); w * h];
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
                *v = ((m2 - m1 * m1).max(0.0) / samples, m1);
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
) -> (Vec3, f32) {
    const KERNEL: [f32; 3] = [0.25, 0.5, 0.25];
    let p = y * w + x;
    if s.key[p] == u64::MAX {
        return (e[p], var[p]);
    }
    let lp = luminance(e[p]);
    let scale = 1.0 / (SIGMA_LUMINANCE * var[p].sqrt() + VARIANCE_EPSILON);
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
            let d = (luminance(e[q]) - lp).abs() * scale;
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
