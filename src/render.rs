//! The render loop: primary rays for every pixel, rows in parallel, shaded by [`Tracer`].
//!
//! A frame's pixels depend only on (scene, camera, lights, settings, size): each sample's random
//! numbers are seeded from (pixel, sample, frame), and the ray counts are integer sums, so the
//! image and the stats are the same with one thread or many.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

mod samples;
mod threads;

use threads::{next_band, on_every_thread};

use crate::accel::tri4::Best8;
use crate::accel::{Hit, TILE_RAYS, TileCache};
use crate::camera::Camera;
use crate::denoise::{GuidePixel, Guides, denoise};
use crate::geometry::RayTile;
use crate::image::Image;
use crate::rng::Rng;
use crate::sampler::{Sampler, Stream};
use crate::scene::{PointLight, Scene};
use crate::shading::{RayCounts, Settings, TileScratch, Tracer};

/// The side of a tile of camera rays traced together (`TILE`² = [`TILE_RAYS`]).
const TILE: usize = 8;

/// What a frame cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Rays traced by kind.
    pub rays: RayCounts,
    /// Samples per pixel.
    pub samples: u32,
    /// Wall-clock time of the render.
    pub elapsed: Duration,
}

/// A rendered frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The linear image.
    pub image: Image,
    /// What it cost.
    pub stats: FrameStats,
    /// The denoiser's guide buffers: only from [`render_guided`] with path-traced indirect
    /// light.
    pub guides: Option<Guides>,
}

/// The primary hits of the last frame, reused while the camera, size and geometry stay the
/// same: a frame where only the light (or the stage) changed traces no primary ray.
#[derive(Clone, Debug, Default)]
pub struct HitCache {
    key: Option<(CameraKey, u32, u32)>,
    hits: Vec<Option<Hit>>,
}

type CameraKey = [u32; 15];

fn camera_key(c: &Camera) -> CameraKey {
    c.key()
}

impl HitCache {
    /// An empty cache.
    pub fn new() -> HitCache {
        HitCache::default()
    }

    /// Forgets the cached hits (call when the scene's geometry changes).
    pub fn clear(&mut self) {
        self.key = None;
        self.hits.clear();
    }
}

/// Renders a `width`×`height` frame.
pub fn render(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
) -> Frame {
    render_impl(
        scene, camera, lights, settings, width, height, None, false, None,
    )
}

/// What [`render_streamed`] hands each band of finished rows to: `(y0, pixels)`, the image's
/// rows from `y0` down, `pixels.len()` a whole number of rows.
pub type BandDone<'a> = &'a (dyn Fn(u32, &[Vec3]) + Sync);

/// [`render`]'s frame, every row handed to `done` as soon as it is finished, a band of rows at
/// a time: on the thread that finished them, in no set order, each row exactly once, all before
/// this returns, which gives the frame's stats. A caller can write the frame out while the rest
/// of it renders. A frame of one sample is never held whole: each thread renders a band into
/// rows of its own and reuses them for its next band (a 500×500 frame would otherwise be 3 MB
/// of fresh memory for the kernel to zero, written out after it has left the caches).
pub fn render_streamed(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
    done: BandDone,
) -> FrameStats {
    render_impl(
        scene,
        camera,
        lights,
        settings,
        width,
        height,
        None,
        false,
        Some(done),
    )
    .stats
}

/// Renders a frame, reusing `cache`'s primary hits when they are still valid (one sample per
/// pixel, same camera and size) and refilling it otherwise.
pub fn render_cached(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
    cache: &mut HitCache,
) -> Frame {
    render_impl(
        scene,
        camera,
        lights,
        settings,
        width,
        height,
        Some(cache),
        false,
        None,
    )
}

/// Whether [`render_denoised`] changes a frame of these settings: only path-traced indirect
/// light is denoised (other frames come out as [`render`] gives them).
pub fn denoises(scene: &Scene, lights: &[PointLight], settings: &Settings) -> bool {
    Tracer::new(scene, lights, *settings).splits()
}

/// [`render_cached`], and with path-traced indirect light the denoiser's guide buffers too
/// ([`Frame::guides`]). The image is the same as [`render_cached`]'s.
pub fn render_guided(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
    cache: &mut HitCache,
) -> Frame {
    render_impl(
        scene,
        camera,
        lights,
        settings,
        width,
        height,
        Some(cache),
        true,
        None,
    )
}

/// One sample through `ray`. A path-traced frame's sample is split (the same colour either
/// way, but one way of computing it, so that guided and plain frames agree bit for bit), and
/// its parts are added to `guide` when the frame keeps guides.
#[inline]
fn sample(
    tracer: &Tracer,
    ray: &crate::geometry::Ray,
    hit: Option<Hit>,
    rng: &mut Stream,
    n: &mut RayCounts,
    guide: Option<&mut GuidePixel>,
) -> Vec3 {
    if !tracer.splits() {
        return tracer.shade_primary(ray, hit, rng, n);
    }
    let s = tracer.sample_primary(ray, hit, rng, n);
    if let Some(g) = guide {
        g.add(&s);
    }
    s.colour()
}

#[allow(clippy::too_many_arguments)]
fn render_impl(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
    mut cache: Option<&mut HitCache>,
    guided: bool,
    done: Option<BandDone>,
) -> Frame {
    let start = Instant::now();
    let samples = settings.effects.samples.max(1);
    let tracer = Tracer::new(scene, lights, *settings);
    // The sampler drives path-traced frames; the others keep their independent numbers.
    let sampler = if tracer.splits() {
        settings.effects.sampler
    } else {
        Sampler::Independent
    };
    let rays = camera.rays(width, height);
    let (w, h) = (width as usize, height as usize);
    // A streamed frame of one sample goes out band by band from each thread's own rows
    // (`render_streamed`): it has no image, and its `Frame` (never returned) a 0×0 one.
    let own_rows = done.is_some() && samples == 1;
    let mut image = if own_rows {
        Image::new(0, 0)
    } else {
        Image::new(width, height)
    };
    // Path-traced frames split every sample for the denoiser (same colour, in any case).
    let split = tracer.splits();
    let draws = tracer.draws_random_numbers();
    // Frames without path-traced light shade a tile at a time (the same colours), small
    // scenes on AVX2 straight from the tile kernel's lanes.
    let by_tile = tracer.shades_tiles();
    let lanes = by_tile && tracer.shades_tile_lanes();
    let mut guides = (guided && split).then(|| Guides {
        width,
        height,
        samples,
        pixels: vec![GuidePixel::default(); w * h],
    });
    if w == 0 || h == 0 {
        return Frame {
            image,
            stats: FrameStats {
                samples,
                ..FrameStats::default()
            },
            guides,
        };
    }
    // Rows of guide pixels, or none: zipped with the image's rows, `None` rows for none.
    let mut guide_rows: Vec<Option<&mut [GuidePixel]>> = match guides.as_mut() {
        Some(g) => g.pixels.chunks_mut(w).map(Some).collect(),
        None => (0..h).map(|_| None).collect(),
    };

    let key = Some((camera_key(camera), width, height));
    let counts = if samples == 1 {
        let reuse = cache
            .as_ref()
            .is_some_and(|c| c.key == key && c.hits.len() == w * h);
        // The cache's rows by band, or none (a frame whose hits nobody keeps stores none).
        let mut hit_bands: Vec<Option<&mut [Option<Hit>]>> = match cache.as_mut() {
            Some(c) => {
                if !reuse {
                    c.hits.resize(w * h, None);
                }
                c.hits.chunks_mut(TILE * w).map(Some).collect()
            }
            None => (0..h.div_ceil(TILE)).map(|_| None).collect(),
        };
        // Bands of `TILE` rows, walked in tiles of `TILE`×`TILE` pixels: each tile's camera
        // rays are traced together (`Scene::intersect_tile`), then shaded. Every thread takes
        // the next band until none is left, the calling thread too, from the top and the
        // others from the bottom (`on_every_thread`).
        // The image's rows by band, or none (each thread's own rows instead).
        let mut pixel_bands: Vec<Option<&mut [Vec3]>> = if own_rows {
            (0..h.div_ceil(TILE)).map(|_| None).collect()
        } else {
            image.pixels.chunks_mut(TILE * w).map(Some).collect()
        };
        let bands = Mutex::new(
            pixel_bands
                .iter_mut()
                .zip(hit_bands.iter_mut())
                .zip(guide_rows.chunks_mut(TILE))
                .enumerate(),
        );
        let counts = on_every_thread(h.div_ceil(TILE), |from_back| {
            let mut n = RayCounts::default();
            let mut tile_rays = RayTile::default();
            let mut tile_hits = [None; TILE_RAYS];
            let mut tile_best = [Best8::NONE; TILE_RAYS / 8];
            let mut tile_colours = [Vec3::ZERO; TILE_RAYS];
            let mut scratch = TileScratch::default();
            let mut tile_cache = TileCache::default();
            let mut own = Vec::new();
            loop {
                let next = next_band(&bands, from_back);
                let Some((band, ((pixels, hits), guide_rows))) = next else {
                    return n;
                };
                let (y0, rows) = (band * TILE, guide_rows.len());
                // Every pixel of a band is written below, so rows of this thread's own are
                // reused as they are.
                let pixels: &mut [Vec3] = match pixels {
                    Some(p) => p,
                    None => {
                        own.resize(own.len().max(rows * w), Vec3::ZERO);
                        &mut own[..rows * w]
                    }
                };
                for x0 in (0..w).step_by(TILE) {
                    let cols = (w - x0).min(TILE);
                    // The tile's row `dy` (`cols` rays from `dy·cols`) in the band's rows.
                    let row = |dy: usize| dy * w + x0..dy * w + x0 + cols;
                    rays.tile(scene.isa(), x0, y0, cols, rows, &mut tile_rays);
                    let k = tile_rays.len();
                    let colours = &mut tile_colours[..k];
                    if lanes {
                        // The tile kernel's hits as it leaves them, in lanes, to shading.
                        if !reuse {
                            n.primary += k as u64;
                            scene.intersect_tile_best(
                                &tile_rays,
                                f32::INFINITY,
                                &mut tile_best,
                                &mut tile_cache,
                            );
                        }
                        if let Some(h) = hits.as_deref_mut() {
                            for i in 0..k {
                                let at = (i / cols) * w + x0 + i % cols;
                                if reuse {
                                    tile_best[i / 8].set(i % 8, h[at]);
                                } else {
                                    h[at] = tile_best[i / 8].hit(i % 8);
                                }
                            }
                        }
                        tracer.shade_tile_best(
                            &tile_rays,
                            &tile_best,
                            colours,
                            &mut n,
                            &mut scratch,
                        );
                    } else {
                        if !reuse {
                            n.primary += k as u64;
                            scene.intersect_tile(
                                &tile_rays,
                                f32::INFINITY,
                                &mut tile_hits[..k],
                                &mut tile_cache,
                            );
                        }
                        if let Some(h) = hits.as_deref_mut() {
                            for (dy, tile_row) in tile_hits[..k].chunks_exact_mut(cols).enumerate()
                            {
                                if reuse {
                                    tile_row.copy_from_slice(&h[row(dy)]);
                                } else {
                                    h[row(dy)].copy_from_slice(tile_row);
                                }
                            }
                        }
                        if !by_tile {
                            for (i, &hit) in tile_hits[..k].iter().enumerate() {
                                let ray = &tile_rays.ray(i);
                                let (dy, x) = (i / cols, x0 + i % cols);
                                let y = y0 + dy;
                                // Only path-traced light draws random numbers: skip the hash otherwise.
                                let mut rng = if draws {
                                    Stream::for_sample(
                                        sampler,
                                        (y * w + x) as u64,
                                        0,
                                        1,
                                        settings.frame,
                                    )
                                } else {
                                    Stream::Independent(Rng::seeded(0))
                                };
                                let g = guide_rows[dy].as_mut().map(|r| &mut r[x]);
                                pixels[dy * w + x] = sample(&tracer, ray, hit, &mut rng, &mut n, g);
                            }
                            continue;
                        }
                        tracer.shade_tile(
                            &tile_rays,
                            &tile_hits[..k],
                            colours,
                            &mut n,
                            &mut scratch,
                        );
                    }
                    for (dy, tile_row) in colours.chunks_exact(cols).enumerate() {
                        pixels[row(dy)].copy_from_slice(tile_row);
                    }
                }
                if let Some(done) = done {
                    done(y0 as u32, pixels);
                }
            }
        });
        drop((pixel_bands, hit_bands));
        if let Some(c) = cache {
            c.key = key;
        }
        counts
    } else if by_tile {
        // Several samples of light that is not path traced (anti-aliasing): a pass of tiles
        // per sample.
        samples::by_tile(
            &mut image.pixels,
            w,
            samples,
            settings.frame,
            &rays,
            scene,
            &tracer,
            done,
        )
    } else {
        image
            .pixels
            .par_chunks_mut(w)
            .zip(guide_rows.par_iter_mut())
            .enumerate()
            .map(|(y, (row, guide_row))| {
                let mut n = RayCounts::default();
                for (x, px) in row.iter_mut().enumerate() {
                    let mut acc = Vec3::ZERO;
                    for s in 0..samples {
                        let pixel = (y * w + x) as u64;
                        let mut rng =
                            Stream::for_sample(sampler, pixel, s, samples, settings.frame);
                        let (ox, oy) = samples::pixel_offset(&mut rng, s, samples);
                        let ray = rays.ray(x as f32 + ox, y as f32 + oy);
                        n.primary += 1;
                        let hit = scene.intersect(&ray, f32::INFINITY);
                        let g = guide_row.as_mut().map(|r| &mut r[x]);
                        acc += sample(&tracer, &ray, hit, &mut rng, &mut n, g);
                    }
                    *px = acc / samples as f32;
                    if let Some(r) = guide_row.as_mut() {
                        r[x].scale(1.0 / samples as f32);
                    }
                }
                if let Some(done) = done {
                    done(y as u32, row);
                }
                n
            })
            .reduce(RayCounts::default, sum)
    };
    Frame {
        image,
        stats: FrameStats {
            rays: counts,
            samples,
            elapsed: start.elapsed(),
        },
        guides,
    }
}

fn sum(mut a: RayCounts, b: RayCounts) -> RayCounts {
    a += b;
    a
}

impl FrameStats {
    /// Millions of rays (all kinds) per second of the render's wall-clock time.
    pub fn mrays_per_s(&self) -> f64 {
        let s = self.elapsed.as_secs_f64();
        if s > 0.0 {
            self.rays.total() as f64 / s / 1e6
        } else {
            0.0
        }
    }

    /// One line for people: time, samples, rays by kind, M rays/s and the SIMD path.
    pub fn summary(&self, isa: crate::accel::Isa) -> String {
        let rays = self.rays.by_kind().map(|(kind, n)| format!("{n} {kind}"));
        format!(
            "{:.2} ms, {} spp, rays: {}; {:.2} M rays/s ({}, {} threads)",
            self.elapsed.as_secs_f64() * 1e3,
            self.samples,
            rays.join(", "),
            self.mrays_per_s(),
            isa.name(),
            rayon::current_num_threads()
        )
    }

    /// The same as one JSON object: `ms`, `spp`, `rays` (by kind), `mrays_per_s`, and the
    /// `simd` path and `threads`.
    pub fn to_json(&self, isa: crate::accel::Isa) -> String {
        let rays = self
            .rays
            .by_kind()
            .map(|(kind, n)| format!("\"{kind}\":{n}"));
        format!(
            "{{\"ms\":{:.3},\"spp\":{},\"rays\":{{{}}},\"mrays_per_s\":{:.3},\"simd\":\"{}\",\"threads\":{}}}",
            self.elapsed.as_secs_f64() * 1e3,
            self.samples,
            rays.join(","),
            self.mrays_per_s(),
            isa.name(),
            rayon::current_num_threads()
        )
    }
}

/// Renders a frame and, if its indirect light is path traced, denoises it: the frame's image
/// is the denoised one and its time includes the filter's. Other frames are as
/// [`render`] gives them.
pub fn render_denoised(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    settings: &Settings,
    width: u32,
    height: u32,
) -> Frame {
    let mut frame = render_impl(
        scene, camera, lights, settings, width, height, None, true, None,
    );
    if let Some(g) = &frame.guides {
        let start = Instant::now();
        frame.image = denoise(g).image;
        frame.stats.elapsed += start.elapsed();
    }
    frame
}
