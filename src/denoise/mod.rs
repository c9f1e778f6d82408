//! The denoiser for path-traced indirect light: an edge-aware à-trous wavelet filter in the
//! manner of SVGF (Schied et al. 2017), run on the indirect irradiance alone.
//!
//! The direct light of a point light is exact per pixel (one shadow ray), so only the indirect
//! term is noisy, and on diffuse walls that term is smooth. In the physically based path an
//! area light's direct light is noisy too (one point on the light a sample): it goes with the
//! indirect light where the first hit is diffuse; a mirror, metal or glass first hit is not
//! filtered, nor is light focused by glass or metal after the first hit (caustics). The render splits every sample
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
//! Each pass is one kernel over a row of pixels, written once over [`Lanes`] (one pixel a
//! lane); a neighbour a pixel does not count adds a zero, which leaves a sum's bits as they
//! are (no sum here starts at or reaches −0), so every SIMD path gives the one-lane path's
//! bits, and those of the one-pixel-at-a-time loops this replaced.

mod guides;
mod planes;

pub use guides::{GuidePixel, Guides, luminance};

use glam::Vec3;
use rayon::prelude::*;

use crate::image::Image;
use crate::simd::{Isa, Kernel, Lanes, Path};
use planes::{Lane3, Planes, in_row};

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

/// The guide surface's planes (see [`Planes`]): normal, position, the key (object and
/// reflection count, as a number only equal pixels share; NaN for a pixel left out of the
/// filter, which no pixel equals), the irradiance's luminance moments, and 1 where the pixel is
/// [`GuidePixel::mixed`] (else 0).
const NX: usize = 0;
const PX: usize = 3;
const KEY: usize = 6;
const MOMENT: usize = 7;
const MIXED: usize = 9;
const SURFACE_PLANES: usize = 10;

/// The planes a pass reads and writes: the irradiance, its variance, its luminance.
const E: usize = 0;
const VAR: usize = 3;
const LUM: usize = 4;
const IRRADIANCE_PLANES: usize = 5;

/// Denoises a frame's indirect light on this CPU's widest SIMD path. The image has the
/// guides' size.
pub fn denoise(g: &Guides) -> Denoised {
    denoise_on(Isa::detect(), g)
}

/// [`denoise`] on SIMD path `isa` (a scene's, [`crate::Scene::isa`]; every path gives the
/// same bits).
///
/// # Panics
/// If this CPU does not have the path.
pub fn denoise_on(isa: Isa, g: &Guides) -> Denoised {
    let mut raw_error = 0.0;
    let (image, e) = filter(isa, g, |e| raw_error = error_estimate(g, e));
    Denoised {
        image,
        raw_error,
        error: error_estimate(g, &e),
    }
}

/// [`denoise_on`]'s image alone: a render shows no error estimate, and each is a pass over
/// the frame on one thread.
pub(crate) fn denoised_image(isa: Isa, g: &Guides) -> Image {
    filter(isa, g, |_| {}).0
}

/// The denoised image, and the irradiance planes it came from; `unfiltered` sees them before
/// the first pass (their variance is the raw image's).
fn filter(isa: Isa, g: &Guides, unfiltered: impl FnOnce(&Planes)) -> (Image, Planes) {
    let (w, h) = (g.width as usize, g.height as usize);
    let surface = surface_planes(g);
    let stride = surface.stride();
    // The raw irradiance, kept for the restore, and the first pass's input.
    let mut raw = Planes::new(3, w, h);
    let mut e = Planes::new(IRRADIANCE_PLANES, w, h);
    // No firefly clamp: cutting bright pixels down to a few deviations above their
    // neighbourhood removed energy, and as the deviations shrank with more samples it cut the
    // true highlights of the light (the bias the `lights` scene showed at 1024 spp).
    let samples = g.samples.max(1) as f32;
    e.rows_mut()
        .zip(raw.rows_mut())
        .for_each(|((y, row), (_, raw_row))| {
            for (x, p) in g.pixels[y * w..(y + 1) * w].iter().enumerate() {
                let v = demodulate(p);
                for (c, v) in [v.x, v.y, v.z].into_iter().enumerate() {
                    row[in_row(stride, E + c, x)] = v;
                    raw_row[in_row(stride, c, x)] = v;
                }
                row[in_row(stride, LUM, x)] = luminance(v);
            }
            isa.run(Variance {
                s: &surface,
                y,
                samples,
                out: row,
            })
        });
    unfiltered(&e);
    let mut next = Planes::new(IRRADIANCE_PLANES, w, h);
    for i in 0..ITERATIONS {
        next.rows_mut().for_each(|(y, row)| {
            isa.run(Filter {
                s: &surface,
                e: &e,
                y,
                step: 1 << i,
                out: row,
            })
        });
        std::mem::swap(&mut e, &mut next);
    }
    restore(isa, g.samples, &surface, &raw, &mut e, next);
    // A mixed pixel takes no part in the restore; it goes back towards its raw value by its
    // samples' count: half way at RESTORE_SAMPLES, all the way in the limit.
    let back = samples / (samples + RESTORE_SAMPLES);
    let mut pixels = vec![Vec3::ZERO; w * h];
    pixels
        .par_chunks_mut(w.max(1))
        .zip(e.rows())
        .zip(raw.rows())
        .for_each(|((out, (y, row)), (_, raw_row))| {
            for (x, (o, p)) in out.iter_mut().zip(&g.pixels[y * w..]).enumerate() {
                let at = |plane: &[f32], c| plane[in_row(stride, c, x)];
                let mut f = Vec3::new(at(row, E), at(row, E + 1), at(row, E + 2));
                if p.mixed {
                    let r = Vec3::new(at(raw_row, 0), at(raw_row, 1), at(raw_row, 2));
                    f += back * (r - f);
                }
                *o = p.rest + remodulate(p, f);
            }
        });
    let image = Image {
        width: g.width,
        height: g.height,
        pixels,
    };
    (image, e)
}

/// The guides' surfaces as planes. A key is the pixel's (reflections, object) pair numbered in
/// the order the pairs first appear, as the `f32` with those bits (equal only to itself).
fn surface_planes(g: &Guides) -> Planes {
    let w = g.width as usize;
    let mut numbers = std::collections::HashMap::new();
    let mut last = None;
    let keys: Vec<f32> = g
        .pixels
        .iter()
        .map(|p| {
            let Some(guide) = p.guide.filter(|_| !left_out(p)) else {
                return f32::NAN;
            };
            let key = (guide.reflections, guide.object);
            let number = match last {
                Some((k, n)) if k == key => n,
                _ => {
                    let next = numbers.len() as u32;
                    *numbers.entry(key).or_insert(next)
                }
            };
            last = Some((key, number));
            f32::from_bits(number)
        })
        .collect();
    let mut s = Planes::new(SURFACE_PLANES, w, g.height as usize);
    s.fill(KEY, f32::NAN);
    let stride = s.stride();
    s.rows_mut().for_each(|(y, row)| {
        for x in 0..w {
            let (p, key) = (&g.pixels[y * w + x], keys[y * w + x]);
            row[in_row(stride, MOMENT, x)] = p.moments[0];
            row[in_row(stride, MOMENT + 1, x)] = p.moments[1];
            row[in_row(stride, MIXED, x)] = if p.mixed { 1.0 } else { 0.0 };
            if let Some(guide) = p.guide.filter(|_| !key.is_nan()) {
                for c in 0..3 {
                    row[in_row(stride, NX + c, x)] = guide.normal[c];
                    row[in_row(stride, PX + c, x)] = guide.position[c];
                }
                row[in_row(stride, KEY, x)] = key;
            }
        }
    });
    s
}

/// Whether the filter leaves pixel `p` raw: it saw the background, or its albedo is too small
/// to divide by.
fn left_out(p: &GuidePixel) -> bool {
    p.guide.is_none() || p.albedo.max_element() < MIN_ALBEDO
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
    if left_out(p) {
        return p.indirect;
    }
    let r = |i: f32, a: f32, f: f32| if a >= MIN_ALBEDO { a * f } else { i };
    Vec3::new(
        r(p.indirect.x, p.albedo.x, f.x),
        r(p.indirect.y, p.albedo.y, f.y),
        r(p.indirect.z, p.albedo.z, f.z),
    )
}

/// A pixel's guide surface, a pixel a lane.
#[derive(Clone, Copy)]
struct Surface<L: Lanes> {
    key: L,
    normal: Lane3<L>,
    position: Lane3<L>,
    /// 1 where the pixel is [`GuidePixel::mixed`], else 0.
    mixed: L,
}

impl<L: Lanes> Surface<L> {
    #[inline(always)]
    fn at(s: &Planes, x: isize, y: isize) -> Self {
        Surface {
            key: s.load(KEY, x, y),
            normal: s.load3(NX, x, y),
            position: s.load3(PX, x, y),
            mixed: s.load(MIXED, x, y),
        }
    }

    /// Lanes left out of the filter (their key is NaN).
    #[inline(always)]
    fn left_out(&self) -> L::Mask {
        self.key.unord(self.key)
    }

    /// How much neighbour `q` counts, from the surfaces alone (0 to 1; 0 on another object).
    #[inline(always)]
    fn weight(&self, q: &Self) -> L {
        let mut c = self.normal.dot(q.normal).max(L::splat(0.0));
        for _ in 0..NORMAL_POWER_LOG2 {
            c = c.mul(c);
        }
        let step = q.position.sub(self.position);
        let len = step.dot(step).sqrt();
        let plane = L::splat(1.0)
            .sub(
                self.normal
                    .dot(step)
                    .abs()
                    .div(len.mul(L::splat(PLANE_COS))),
            )
            .max(L::splat(0.0));
        let plane = L::select(len.gt(L::splat(0.0)), L::splat(1.0), plane);
        L::select(self.key.eq(q.key), L::splat(0.0), c.mul(plane))
    }

    /// Whether `q` counts as this pixel's neighbour for the restore: the same object seen
    /// through the same mirrors, normals within about 17°, and each in the other's plane as
    /// far as [`Surface::weight`]'s plane term counts it at least half; neither of them
    /// mixed (a mixed pixel goes back towards its raw value on its own: see [`filter`]).
    /// Symmetric in the two pixels (what one hands to the other is what the other counts),
    /// without a square root or a division.
    #[inline(always)]
    fn shares(&self, q: &Self) -> L::Mask {
        let whole = self.mixed.add(q.mixed).eq(L::splat(0.0));
        let near = L::and(
            whole,
            L::andnot(
                self.normal.dot(q.normal).lt(L::splat(SAME_NORMAL_COS)),
                self.key.eq(q.key),
            ),
        );
        let step = q.position.sub(self.position);
        let half = 0.5 * PLANE_COS;
        let limit = L::splat(half * half).mul(step.dot(step));
        let (a, b) = (self.normal.dot(step), q.normal.dot(step));
        L::and(near, L::and(a.mul(a).le(limit), b.mul(b).le(limit)))
    }
}

/// `v` where `m` is set, else zero: a neighbour that does not count adds nothing.
#[inline(always)]
fn counted<L: Lanes>(m: L::Mask, v: L) -> L {
    L::select(m, L::splat(0.0), v)
}

/// The per-pixel variance of the mean irradiance's luminance for row `y`, estimated from the
/// moments of the neighbours on the same surface (one sample per pixel has no variance of its
/// own): `(E[l²] − E[l]²) / samples`. Written into the row's variance plane.
struct Variance<'a> {
    s: &'a Planes,
    y: usize,
    samples: f32,
    out: &'a mut [f32],
}

impl Kernel for Variance<'_> {
    type Output = ();
    // Sixteen lanes where the CPU has AVX-512: the whole filter takes about a third less
    // time than on AVX2's eight (`cargo run --release --example denoise_eval -- 200 100`,
    // stage 6 at 200×100, two threads: 3.5 against 5.1 ms, same bits).
    const SIXTEEN: bool = true;
    #[inline(always)]
    fn run<P: Path>(self) {
        type L<P> = <P as Path>::Wide;
        let (s, y) = (self.s, self.y as isize);
        for x in (0..s.width()).step_by(L::<P>::N) {
            let x = x as isize;
            let p = Surface::<L<P>>::at(s, x, y);
            let zero = L::<P>::splat(0.0);
            let (mut m1, mut m2, mut sum) = (zero, zero, zero);
            for dy in -VARIANCE_RADIUS..=VARIANCE_RADIUS {
                for dx in -VARIANCE_RADIUS..=VARIANCE_RADIUS {
                    let (qx, qy) = (x + dx as isize, y + dy as isize);
                    let wt = p.weight(&Surface::at(s, qx, qy));
                    let counts = wt.gt(zero);
                    m1 = m1.add(counted(counts, wt.mul(s.load(MOMENT, qx, qy))));
                    m2 = m2.add(counted(counts, wt.mul(s.load(MOMENT + 1, qx, qy))));
                    sum = sum.add(counted(counts, wt));
                }
            }
            let (m1, m2) = (m1.div(sum), m2.div(sum));
            let v = m2
                .sub(m1.mul(m1))
                .max(zero)
                .div(L::<P>::splat(self.samples));
            let v = L::<P>::select(p.left_out(), v, zero);
            v.store(&mut self.out[s.in_row(VAR, x)..]);
        }
    }
}

/// One à-trous pass over row `y`: each pixel's irradiance becomes the weighted mean of its
/// 3×3 neighbours `step` pixels apart, and its variance that mean's variance.
struct Filter<'a> {
    s: &'a Planes,
    e: &'a Planes,
    y: usize,
    step: usize,
    out: &'a mut [f32],
}

impl Kernel for Filter<'_> {
    type Output = ();
    const SIXTEEN: bool = true;
    #[inline(always)]
    fn run<P: Path>(self) {
        type L<P> = <P as Path>::Wide;
        const KERNEL: [f32; 3] = [0.25, 0.5, 0.25];
        let (s, e, y, step) = (self.s, self.e, self.y as isize, self.step as isize);
        for x in (0..s.width()).step_by(L::<P>::N) {
            let x = x as isize;
            let p = Surface::<L<P>>::at(s, x, y);
            let (ep, var_p, lp) = (e.load3(E, x, y), e.load(VAR, x, y), e.load(LUM, x, y));
            let scale = channel_scale(s, e, &p, var_p, x, y);
            let lum_scale = L::<P>::splat(1.0).div(
                L::<P>::splat(SIGMA_LUMINANCE)
                    .mul(var_p.sqrt())
                    .add(L::<P>::splat(VARIANCE_EPSILON)),
            );
            let zero = L::<P>::splat(0.0);
            let (mut sum_e, mut sum_v, mut sum_w) = (Lane3::splat(zero), zero, zero);
            for (ky, &hy) in KERNEL.iter().enumerate() {
                for (kx, &hx) in KERNEL.iter().enumerate() {
                    let (qx, qy) = (x + (kx as isize - 1) * step, y + (ky as isize - 1) * step);
                    let (g, counts) = if (kx, ky) == (1, 1) {
                        (L::<P>::splat(1.0), L::<P>::eq(zero, zero))
                    } else {
                        let g = p.weight(&Surface::at(s, qx, qy));
                        let same = p.key.eq(s.load(KEY, qx, qy));
                        (g, L::<P>::andnot(g.le(zero), same))
                    };
                    let eq = e.load3(E, qx, qy);
                    let d = e
                        .load::<L<P>>(LUM, qx, qy)
                        .sub(lp)
                        .abs()
                        .mul(lum_scale)
                        .max(eq.sub(ep).abs().mul(scale).max_element());
                    // exp(−d) without the platform's exp (whose rounding may vary by CPU): a
                    // rational with the same start and a tail as long.
                    let wl = L::<P>::splat(1.0).div(
                        L::<P>::splat(1.0)
                            .add(d)
                            .add(L::<P>::splat(0.5).mul(d).mul(d)),
                    );
                    let wt = L::<P>::splat(hx * hy).mul(g).mul(wl);
                    sum_e = sum_e.add(eq.scale(wt).counted(counts));
                    sum_v = sum_v.add(counted(counts, wt.mul(wt).mul(e.load(VAR, qx, qy))));
                    sum_w = sum_w.add(counted(counts, wt));
                }
            }
            let left_out = p.left_out();
            let out_e = Lane3::select(left_out, sum_e.div(sum_w), ep);
            let out_v = L::<P>::select(left_out, sum_v.div(sum_w.mul(sum_w)), var_p);
            out_e.store(self.out, s.in_row(E, x), s.stride());
            out_v.store(&mut self.out[s.in_row(VAR, x)..]);
            out_e.luminance().store(&mut self.out[s.in_row(LUM, x)..]);
        }
    }
}

/// The reciprocal of `SIGMA_COLOUR` standard deviations of each channel of pixel `p`'s
/// irradiance: the luminance's deviation (from its variance `var_p`) times the channel's share
/// of the mean of the irradiance over the 3×3 neighbours on the same surface, so that the
/// colour weight compares each channel with its own noise (and no other surface's light
/// sways it).
#[inline(always)]
fn channel_scale<L: Lanes>(
    s: &Planes,
    e: &Planes,
    p: &Surface<L>,
    var_p: L,
    x: isize,
    y: isize,
) -> Lane3<L> {
    /// Keeps the shares finite where the light is black.
    const TINY: f32 = 1e-6;
    let zero = L::splat(0.0);
    let (mut sum, mut count) = (Lane3::splat(zero), zero);
    for qy in y - 1..=y + 1 {
        for qx in x - 1..=x + 1 {
            let same = p.key.eq(s.load(KEY, qx, qy));
            sum = sum.add(e.load3(E, qx, qy).counted(same));
            count = count.add(counted(same, L::splat(1.0)));
        }
    }
    let mean = sum.div(count);
    let share = mean
        .max(L::splat(TINY))
        .div(mean.luminance().max(L::splat(TINY)));
    let sigma = share.scale(L::splat(SIGMA_COLOUR).mul(var_p.sqrt()));
    Lane3::splat(L::splat(1.0)).div3(sigma.add(Lane3::splat(L::splat(VARIANCE_EPSILON))))
}

/// The restore's neighbours share a surface when their normals are within the angle at which
/// [`Surface::weight`]'s normal term halves: `2^(−1/16)`, about 17°.
const SAME_NORMAL_COS: f32 = 0.957_603_3;

/// Hands what the filter took from each pixel back to its neighbourhood on the same surface:
/// `f_p + Σ_q k_q·(raw_q − f_q)/n_q` over the pixels q whose windows hold p, `n_q` the number
/// of pixels of q's window on its surface ([`Surface::shares`]), so that each pixel's
/// difference is shared out whole (the local mean is kept, unlike a plain average of the
/// differences, which over-counts the pixels at a surface's edge, where the bias is). `k` per
/// channel is a Wiener factor `b²/(b² + var b·RESTORE_SAMPLES/samples)` of the window's mean
/// difference `b`: about 1 where the difference is systematic (the filter's bias), about 0
/// where it is noise (few samples, where handing it back would undo the filter).
fn restore(isa: Isa, samples: u32, s: &Planes, raw: &Planes, f: &mut Planes, mut share: Planes) {
    let noise_weight = RESTORE_SAMPLES / samples.max(1) as f32;
    // What each pixel hands to each pixel of its window.
    share.rows_mut().for_each(|(y, row)| {
        isa.run(Share {
            s,
            raw,
            f,
            noise_weight,
            y,
            out: row,
        })
    });
    f.rows_mut().for_each(|(y, row)| {
        isa.run(Gather {
            s,
            share: &share,
            y,
            out: row,
        })
    });
}

/// The window of pixels the restore shares over: `RESTORE_RADIUS` each way.
const RESTORE_WINDOW: std::ops::RangeInclusive<isize> =
    -(RESTORE_RADIUS as isize)..=RESTORE_RADIUS as isize;

/// What each pixel of row `y` hands to each pixel of its window (see [`restore`]), from what
/// the filter took from each pixel: its raw irradiance (`raw`) minus the filtered one (`f`).
/// (Outside the frame that difference is not zero, but no pixel counts a neighbour there.)
struct Share<'a> {
    s: &'a Planes,
    raw: &'a Planes,
    f: &'a Planes,
    noise_weight: f32,
    y: usize,
    out: &'a mut [f32],
}

impl Share<'_> {
    /// What the filter took from pixels (`x`, `y`) on.
    #[inline(always)]
    fn taken<L: Lanes>(&self, x: isize, y: isize) -> Lane3<L> {
        self.raw.load3(0, x, y).sub(self.f.load3(E, x, y))
    }
}

impl Kernel for Share<'_> {
    type Output = ();
    const SIXTEEN: bool = true;
    #[inline(always)]
    fn run<P: Path>(self) {
        type L<P> = <P as Path>::Wide;
        let (s, y) = (self.s, self.y as isize);
        for x in (0..s.width()).step_by(L::<P>::N) {
            let x = x as isize;
            let q = Surface::<L<P>>::at(s, x, y);
            let zero = L::<P>::splat(0.0);
            let (mut m1, mut m2, mut n) = (Lane3::splat(zero), Lane3::splat(zero), zero);
            for dy in RESTORE_WINDOW {
                for dx in RESTORE_WINDOW {
                    let shares = q.shares(&Surface::at(s, x + dx, y + dy));
                    let d = self.taken::<L<P>>(x + dx, y + dy);
                    m1 = m1.add(d.counted(shares));
                    m2 = m2.add(d.mul(d).counted(shares));
                    n = n.add(counted(shares, L::<P>::splat(1.0)));
                }
            }
            let b = m1.div(n);
            let var_b = m2
                .div(n)
                .sub(b.mul(b))
                .max(L::<P>::splat(0.0))
                .scale(L::<P>::splat(self.noise_weight).div(n));
            let b2 = b.mul(b);
            let total = b2.add(var_b);
            let k = total.zip(b2, |t, b2| L::<P>::select(t.gt(zero), zero, b2.div(t)));
            let share = self.taken::<L<P>>(x, y).mul(k).div(n);
            // A pixel is in its own window unless it is left out of the filter.
            share
                .counted(n.gt(zero))
                .store(self.out, s.in_row(E, x), s.stride());
        }
    }
}

/// Row `y` of the restored irradiance: each pixel's filtered value plus the shares of the
/// pixels whose windows hold it (see [`restore`]).
struct Gather<'a> {
    s: &'a Planes,
    share: &'a Planes,
    y: usize,
    out: &'a mut [f32],
}

impl Kernel for Gather<'_> {
    type Output = ();
    const SIXTEEN: bool = true;
    #[inline(always)]
    fn run<P: Path>(self) {
        type L<P> = <P as Path>::Wide;
        let (s, y) = (self.s, self.y as isize);
        for x in (0..s.width()).step_by(L::<P>::N) {
            let x = x as isize;
            let p = Surface::<L<P>>::at(s, x, y);
            let at = s.in_row(E, x);
            let mut sum = Lane3::<L<P>>::load_row(self.out, at, s.stride());
            for dy in RESTORE_WINDOW {
                for dx in RESTORE_WINDOW {
                    let q = Surface::at(s, x + dx, y + dy);
                    sum = sum.add(self.share.load3(E, x + dx, y + dy).counted(p.shares(&q)));
                }
            }
            sum.store(self.out, at, s.stride());
        }
    }
}

/// An RMSE estimate from per-pixel luminance variances: `sqrt(mean(lum(albedo)²·var))` over
/// the filtered pixels, counted over all pixels.
fn error_estimate(g: &Guides, e: &Planes) -> f32 {
    if g.pixels.is_empty() {
        return 0.0;
    }
    let w = g.width as usize;
    let sum: f64 = g
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let a = f64::from(luminance(p.albedo));
            a * a * f64::from(e.get(VAR, i % w, i / w))
        })
        .sum();
    (sum / g.pixels.len() as f64).sqrt() as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;
    use crate::{HitCache, Options, Output, Stage};

    /// Stage 6 guides of a built-in scene.
    fn guides(name: &str, w: u32, h: u32, samples: u32) -> Guides {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let mut settings = Stage::Gi.settings(scene.effects());
        settings.effects.samples = samples;
        let options = Options {
            width: w,
            height: h,
            settings: Some(settings),
            output: Output::Guides,
            ..Options::default()
        };
        HitCache::new().render(&scene, &options).guides.unwrap()
    }

    fn bits(d: &Denoised) -> Vec<[u32; 3]> {
        let b = |v: Vec3| v.to_array().map(f32::to_bits);
        d.image.pixels.iter().map(|&p| b(p)).collect()
    }

    /// The kernels' lanes run past the frame's edge and skip neighbours by adding zeros: every
    /// path must still give the one-lane path's bits, at widths that end mid-lane, on scenes
    /// with mirrors (other keys), the background (pixels left out) and a curved surface.
    #[test]
    fn every_simd_path_gives_the_same_bits() {
        for (name, w, h, samples) in [
            ("cornell", 37, 23, 1),
            ("mirror", 45, 19, 4),
            ("lights", 21, 17, 16),
            ("sphere", 33, 20, 2),
            ("cornell", 1, 1, 1),
            ("cornell", 3, 40, 2),
        ] {
            let g = guides(name, w, h, samples);
            let one = denoise_on(Isa::Portable, &g);
            for isa in [Isa::Sse2, Isa::Avx2, Isa::Avx512] {
                if !isa.available() {
                    continue;
                }
                let d = denoise_on(isa, &g);
                assert_eq!(bits(&d), bits(&one), "{name} {w}x{h} on {}", isa.name());
                assert_eq!(d.error.to_bits(), one.error.to_bits());
                assert_eq!(d.raw_error.to_bits(), one.raw_error.to_bits());
            }
            assert!(one.image.pixels.iter().all(|p| p.is_finite()), "{name}");
        }
    }

    #[test]
    fn an_empty_frame_denoises_to_an_empty_image() {
        let g = Guides {
            width: 0,
            height: 0,
            samples: 1,
            pixels: Vec::new(),
        };
        let d = denoise(&g);
        assert!(d.image.pixels.is_empty());
        assert_eq!(d.error, 0.0);
    }
}
