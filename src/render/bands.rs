//! Frames of one sample per pixel: bands of [`TILE`] rows, walked in tiles of `TILE`×`TILE`
//! pixels; each tile's camera rays are traced together (`Scene::intersect_tile`), then shaded.
//! Every thread takes the next band until none is left, the calling thread too, from the top
//! and the others from the bottom (`on_every_thread`).

use std::sync::Mutex;

use glam::Vec3;

use super::threads::{next_band, on_every_thread};
use super::{HitCache, Job, TILE, cache_key};
use crate::accel::tri4::Best8;
use crate::accel::{Hit, TILE_RAYS, TileCache};
use crate::denoise::GuidePixel;
use crate::geometry::RayTile;
use crate::rng::Rng;
use crate::sampler::Stream;
use crate::shading::{RayCounts, TileScratch};

/// Renders `job`'s frame into `pixels` (or, with none, into each thread's own rows, handed to
/// `job.done`), reusing `cache`'s primary hits when they are still valid and refilling it
/// otherwise, and adds each path-traced sample's parts to `guide_rows` where they are kept.
pub(super) fn render(
    job: &Job,
    pixels: Option<&mut [Vec3]>,
    mut cache: Option<&mut HitCache>,
    guide_rows: &mut [Option<&mut [GuidePixel]>],
) -> RayCounts {
    let (w, h) = (job.width, job.height);
    let bands = h.div_ceil(TILE);
    let key = Some(cache_key(
        &job.camera,
        w as u32,
        job.frame_height,
        job.top as u32,
        h as u32,
    ));
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
        None => (0..bands).map(|_| None).collect(),
    };
    // The image's rows by band, or none (each thread's own rows instead).
    let mut pixel_bands: Vec<Option<&mut [Vec3]>> = match pixels {
        Some(p) => p.chunks_mut(TILE * w).map(Some).collect(),
        None => (0..bands).map(|_| None).collect(),
    };
    let queue = Mutex::new(
        pixel_bands
            .iter_mut()
            .zip(hit_bands.iter_mut())
            .zip(guide_rows.chunks_mut(TILE))
            .enumerate(),
    );
    let frame = OneSample::new(job, reuse);
    let counts = on_every_thread(bands, |from_back| {
        let mut n = RayCounts::default();
        let mut tiles = Tiles::default();
        let mut own = Vec::new();
        while let Some((band, ((pixels, hits), guide_rows))) = next_band(&queue, from_back) {
            let rows = guide_rows.len();
            // Every pixel of a band is written, so rows of this thread's own are reused as
            // they are.
            let pixels: &mut [Vec3] = match pixels {
                Some(p) => p,
                None => {
                    own.resize(own.len().max(rows * w), Vec3::ZERO);
                    &mut own[..rows * w]
                }
            };
            let y0 = band * TILE;
            frame.band(
                &mut tiles,
                job.top + y0,
                pixels,
                hits.as_deref_mut(),
                guide_rows,
                &mut n,
            );
            if let Some(done) = job.done {
                done(y0 as u32, pixels);
            }
        }
        n
    });
    drop((pixel_bands, hit_bands));
    if let Some(c) = cache {
        c.key = key;
    }
    counts
}

/// How a one-sample frame traces and shades its tiles.
struct OneSample<'j, 'a> {
    job: &'j Job<'a>,
    /// The primary hits come from the cache (none are traced).
    reuse: bool,
    /// Frames without path-traced light shade a tile at a time (the same colours)...
    by_tile: bool,
    /// ...small scenes on AVX2 straight from the tile kernel's lanes.
    lanes: bool,
    /// Only path-traced light draws random numbers: the hash is skipped otherwise.
    draws: bool,
}

/// A thread's buffers for one tile.
struct Tiles {
    rays: RayTile,
    hits: [Option<Hit>; TILE_RAYS],
    best: [Best8; TILE_RAYS / 8],
    colours: [Vec3; TILE_RAYS],
    scratch: TileScratch,
    cache: TileCache,
}

impl Default for Tiles {
    fn default() -> Tiles {
        Tiles {
            rays: RayTile::default(),
            hits: [None; TILE_RAYS],
            best: [Best8::NONE; TILE_RAYS / 8],
            colours: [Vec3::ZERO; TILE_RAYS],
            scratch: TileScratch::default(),
            cache: TileCache::default(),
        }
    }
}

impl<'j, 'a> OneSample<'j, 'a> {
    fn new(job: &'j Job<'a>, reuse: bool) -> Self {
        let by_tile = job.tracer.shades_tiles();
        OneSample {
            job,
            reuse,
            by_tile,
            lanes: by_tile && job.tracer.shades_tile_lanes(),
            draws: job.tracer.draws_random_numbers(),
        }
    }

    /// The band of the frame's rows from `y0` (`guide_rows.len()` of them) into `pixels`, its
    /// hits from or into `hits` (the cache's rows) if there are any.
    fn band(
        &self,
        t: &mut Tiles,
        y0: usize,
        pixels: &mut [Vec3],
        mut hits: Option<&mut [Option<Hit>]>,
        guide_rows: &mut [Option<&mut [GuidePixel]>],
        n: &mut RayCounts,
    ) {
        let w = self.job.width;
        let rows = guide_rows.len();
        for x0 in (0..w).step_by(TILE) {
            let cols = (w - x0).min(TILE);
            self.job
                .rays
                .tile(self.job.scene.isa(), x0, y0, cols, rows, &mut t.rays);
            let k = t.rays.len();
            if self.lanes {
                self.trace_lanes(t, x0, cols, hits.as_deref_mut(), n);
                let Tiles {
                    rays,
                    best,
                    colours,
                    scratch,
                    ..
                } = t;
                let colours = &mut colours[..k];
                self.job
                    .tracer
                    .shade_tile_best(rays, best, colours, n, scratch);
            } else {
                self.trace(t, x0, cols, hits.as_deref_mut(), n);
                if !self.by_tile {
                    self.shade_pixels(t, x0, y0, cols, pixels, guide_rows, n);
                    continue;
                }
                let Tiles {
                    rays,
                    hits,
                    colours,
                    scratch,
                    ..
                } = t;
                let colours = &mut colours[..k];
                self.job
                    .tracer
                    .shade_tile(rays, &hits[..k], colours, n, scratch);
            }
            for (dy, tile_row) in t.colours[..k].chunks_exact(cols).enumerate() {
                pixels[dy * w + x0..dy * w + x0 + cols].copy_from_slice(tile_row);
            }
        }
    }

    /// The tile's hits as the tile kernel leaves them, in lanes (`t.best`): traced, or from
    /// `hits`, and into `hits` when traced.
    fn trace_lanes(
        &self,
        t: &mut Tiles,
        x0: usize,
        cols: usize,
        hits: Option<&mut [Option<Hit>]>,
        n: &mut RayCounts,
    ) {
        let (w, k) = (self.job.width, t.rays.len());
        if !self.reuse {
            n.primary += k as u64;
            let scene = self.job.scene;
            scene.intersect_tile_best(&t.rays, f32::INFINITY, &mut t.best, &mut t.cache);
        }
        if let Some(h) = hits {
            for i in 0..k {
                let at = (i / cols) * w + x0 + i % cols;
                if self.reuse {
                    t.best[i / 8].set(i % 8, h[at]);
                } else {
                    h[at] = t.best[i / 8].hit(i % 8);
                }
            }
        }
    }

    /// The tile's hits (`t.hits`): traced, or from `hits`, and into `hits` when traced.
    fn trace(
        &self,
        t: &mut Tiles,
        x0: usize,
        cols: usize,
        hits: Option<&mut [Option<Hit>]>,
        n: &mut RayCounts,
    ) {
        let (w, k) = (self.job.width, t.rays.len());
        if !self.reuse {
            n.primary += k as u64;
            let scene = self.job.scene;
            scene.intersect_tile(&t.rays, f32::INFINITY, &mut t.hits[..k], &mut t.cache);
        }
        if let Some(h) = hits {
            for (dy, tile_row) in t.hits[..k].chunks_exact_mut(cols).enumerate() {
                let row = &mut h[dy * w + x0..dy * w + x0 + cols];
                if self.reuse {
                    tile_row.copy_from_slice(row);
                } else {
                    row.copy_from_slice(tile_row);
                }
            }
        }
    }

    /// Shades the tile's hits one pixel at a time (path-traced light), straight into
    /// `pixels`.
    #[allow(clippy::too_many_arguments)]
    fn shade_pixels(
        &self,
        t: &Tiles,
        x0: usize,
        y0: usize,
        cols: usize,
        pixels: &mut [Vec3],
        guide_rows: &mut [Option<&mut [GuidePixel]>],
        n: &mut RayCounts,
    ) {
        let job = self.job;
        let w = job.width;
        for (i, &hit) in t.hits[..t.rays.len()].iter().enumerate() {
            let ray = &t.rays.ray(i);
            let (dy, x) = (i / cols, x0 + i % cols);
            let pixel = (y0 + dy) * w + x;
            let mut rng = if self.draws {
                Stream::for_sample(job.sampler, pixel as u64, 0, 1, job.frame)
            } else {
                Stream::Independent(Rng::seeded(0))
            };
            let g = guide_rows[dy].as_mut().map(|r| &mut r[x]);
            pixels[dy * w + x] = job.sample(ray, hit, &mut rng, n, g);
        }
    }
}
