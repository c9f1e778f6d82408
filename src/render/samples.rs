//! Anti-aliased frames whose light is not path traced: a pass of tiles per sample.

use std::sync::Mutex;

use glam::Vec3;

use super::threads::{next_band, on_every_thread};
use super::{Job, TILE};
use crate::accel::tri4::Best8;
use crate::accel::{TILE_RAYS, TileCache};
use crate::geometry::RayTile;
use crate::rng::first_two8;
use crate::sampler::{SampleSource, Stream};
#[cfg(doc)]
use crate::shading::Tracer;
use crate::shading::{RayCounts, TileScratch};

/// Where sample `s` of `samples` falls in its pixel (0 to 1 on each axis), stratified: the
/// sampler's own offset (Sobol points are), else an s×s grid when `samples` is square, else
/// strata in x. It draws from `rng` what the sample's offset needs.
pub(super) fn pixel_offset(rng: &mut Stream, s: u32, samples: u32) -> (f32, f32) {
    Cell::of(s, samples).offset(rng)
}

/// The stratum of sample `s` of `samples` ([`pixel_offset`]): what every pixel's sample `s`
/// shares, worked out once per sample rather than per pixel.
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// The cell's corner, in cells, on each axis.
    x: f32,
    y: f32,
    /// Cells across on each axis (1 on y where the strata are in x only).
    nx: f32,
    ny: f32,
}

impl Cell {
    fn of(s: u32, samples: u32) -> Cell {
        let strata = (samples as f32).sqrt() as u32;
        if strata * strata == samples {
            Cell {
                x: (s % strata) as f32,
                y: (s / strata) as f32,
                nx: strata as f32,
                ny: strata as f32,
            }
        } else {
            Cell {
                x: s as f32,
                y: 0.0,
                nx: samples as f32,
                ny: 1.0,
            }
        }
    }

    /// [`pixel_offset`] of a pixel's sample in this cell, from its numbers in `rng`.
    #[inline]
    fn offset(&self, rng: &mut Stream) -> (f32, f32) {
        match rng.pixel_offset() {
            Some([jx, jy]) => (jx, jy),
            None => self.place(rng.next_2d()),
        }
    }

    /// Where in its pixel a sample of this cell with numbers `[jx, jy]` falls (a cell of one
    /// on y leaves `jy` as it is: `(0 + jy) / 1` is `jy`).
    #[inline]
    fn place(&self, [jx, jy]: [f32; 2]) -> (f32, f32) {
        ((self.x + jx) / self.nx, (self.y + jy) / self.ny)
    }
}

/// Renders `job`'s frame into `pixels`, a frame of several samples whose light is not path
/// traced ([`Tracer::shades_tiles`]): per tile, each sample's camera rays (jittered as
/// [`pixel_offset`] puts them, from independent numbers) are traced and shaded together, and
/// added to their pixels in the samples' order, so every pixel gets the sums one ray at a time
/// would give. Bands of rows go to every thread as the one-sample frame's do; `job.done` gets
/// each band when it is finished.
pub(super) fn render(job: &Job, pixels: &mut [Vec3]) -> RayCounts {
    let (scene, tracer, rays) = (job.scene, &job.tracer, &job.rays);
    let (w, samples, frame, done) = (job.width, job.samples, job.frame, job.done);
    let h = pixels.len() / w.max(1);
    let bands = Mutex::new(pixels.chunks_mut(TILE * w).enumerate());
    on_every_thread(h.div_ceil(TILE), |from_back| {
        let mut n = RayCounts::default();
        let mut tile = RayTile::default();
        let (mut px, mut py) = ([0.0; TILE_RAYS], [0.0; TILE_RAYS]);
        let (mut jx, mut jy) = ([0.0; TILE_RAYS], [0.0; TILE_RAYS]);
        let (mut fx, mut fy) = ([0.0; TILE_RAYS], [0.0; TILE_RAYS]);
        let mut ids = [[0u64; 8]; TILE];
        let mut numbers = [[[0f32; 8]; 2]; TILE];
        let mut tile_hits = [None; TILE_RAYS];
        let mut tile_best = [Best8::NONE; TILE_RAYS / 8];
        // Small scenes on AVX2: the tile kernel's hits go to shading in lanes, as they are.
        let lanes = tracer.shades_tile_lanes();
        let mut colours = [Vec3::ZERO; TILE_RAYS];
        let mut sums = [Vec3::ZERO; TILE_RAYS];
        let mut scratch = TileScratch::default();
        let mut tile_cache = TileCache::default();
        loop {
            let next = next_band(&bands, from_back);
            let Some((band, pixels)) = next else {
                return n;
            };
            // `y0`: the frame's row (the rows rendered may start below its top).
            let (y0, rows) = (job.top + band * TILE, pixels.len() / w);
            for x0 in (0..w).step_by(TILE) {
                let cols = (w - x0).min(TILE);
                let k = cols * rows;
                sums[..k].fill(Vec3::ZERO);
                // The tile's pixel indices by row, eight lanes each (past `cols`, the last
                // again), and each pixel's corner.
                for (dy, row) in ids[..rows].iter_mut().enumerate() {
                    *row = std::array::from_fn(|l| ((y0 + dy) * w + x0 + l.min(cols - 1)) as u64);
                    for dx in 0..cols {
                        let i = dy * cols + dx;
                        (fx[i], fy[i]) = ((x0 + dx) as f32, (y0 + dy) as f32);
                    }
                }
                for s in 0..samples {
                    let cell = Cell::of(s, samples);
                    // Each pixel's two numbers, from independent numbers (what
                    // `Stream::for_sample` gives for `Sampler::Independent`, which has no
                    // offsets of its own: `Rng::for_sample`'s), a row's eight pixels at a time;
                    // then its place in the cell as `pixel_offset` puts it, in a loop of its own
                    // that the compiler vectorises.
                    first_two8(scene.isa(), &ids[..rows], s, frame, &mut numbers[..rows]);
                    for (dy, [rx, ry]) in numbers[..rows].iter().enumerate() {
                        let at = dy * cols;
                        jx[at..at + cols].copy_from_slice(&rx[..cols]);
                        jy[at..at + cols].copy_from_slice(&ry[..cols]);
                    }
                    for i in 0..k {
                        let (ox, oy) = cell.place([jx[i], jy[i]]);
                        (px[i], py[i]) = (fx[i] + ox, fy[i] + oy);
                    }
                    // `rays.ray(px[i], py[i])` for each, eight at a time.
                    rays.tile_at(scene.isa(), cols, rows, &px, &py, &mut tile);
                    n.primary += k as u64;
                    if lanes {
                        scene.intersect_tile_best(
                            &tile,
                            f32::INFINITY,
                            &mut tile_best,
                            &mut tile_cache,
                        );
                        tracer.shade_tile_best(
                            &tile,
                            &tile_best,
                            &mut colours[..k],
                            &mut n,
                            &mut scratch,
                        );
                    } else {
                        scene.intersect_tile(
                            &tile,
                            f32::INFINITY,
                            &mut tile_hits[..k],
                            &mut tile_cache,
                        );
                        tracer.shade_tile(
                            &tile,
                            &tile_hits[..k],
                            &mut colours[..k],
                            &mut n,
                            &mut scratch,
                        );
                    }
                    for (sum, &c) in sums[..k].iter_mut().zip(&colours[..k]) {
                        *sum += c;
                    }
                }
                for (i, sum) in sums[..k].iter().enumerate() {
                    pixels[(i / cols) * w + x0 + i % cols] = *sum / samples as f32;
                }
            }
            if let Some(done) = done {
                done((band * TILE) as u32, pixels);
            }
        }
    })
}
