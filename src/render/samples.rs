//! Anti-aliased frames whose light is not path traced: a pass of tiles per sample.

use std::sync::Mutex;

use glam::Vec3;

use super::threads::{next_band, on_every_thread};
use super::{BandDone, TILE};
use crate::accel::{TILE_RAYS, TileCache};
use crate::camera::RayGen;
use crate::geometry::RayTile;
use crate::sampler::{SampleSource, Sampler, Stream};
use crate::scene::Scene;
use crate::shading::{RayCounts, TileScratch, Tracer};

/// Where sample `s` of `samples` falls in its pixel (0 to 1 on each axis), stratified: the
/// sampler's own offset (Sobol points are), else an s×s grid when `samples` is square, else
/// strata in x. It draws from `rng` what the sample's offset needs.
pub(super) fn pixel_offset(rng: &mut Stream, s: u32, samples: u32) -> (f32, f32) {
    let strata = (samples as f32).sqrt() as u32;
    let offset = rng.pixel_offset();
    let [jx, jy] = offset.unwrap_or_else(|| rng.next_2d());
    if offset.is_some() {
        (jx, jy)
    } else if strata * strata == samples {
        (
            ((s % strata) as f32 + jx) / strata as f32,
            ((s / strata) as f32 + jy) / strata as f32,
        )
    } else {
        ((s as f32 + jx) / samples as f32, jy)
    }
}

/// `pixels` (`w` wide) of a frame of `samples` samples whose light is not path traced
/// ([`Tracer::shades_tiles`]): per tile, each sample's camera rays (jittered as
/// [`pixel_offset`] puts them, from independent numbers) are traced and shaded together, and
/// added to their pixels in the samples' order, so every pixel gets the sums one ray at a time
/// would give. Bands of rows go to every thread as the one-sample frame's do; `done` gets each
/// band when it is finished.
#[allow(clippy::too_many_arguments)]
pub(super) fn by_tile(
    pixels: &mut [Vec3],
    w: usize,
    samples: u32,
    frame: u32,
    rays: &RayGen,
    scene: &Scene,
    tracer: &Tracer,
    done: Option<BandDone>,
) -> RayCounts {
    let h = pixels.len() / w.max(1);
    let sampler = Sampler::Independent;
    let bands = Mutex::new(pixels.chunks_mut(TILE * w).enumerate());
    on_every_thread(h.div_ceil(TILE), |from_back| {
        let mut n = RayCounts::default();
        let mut tile = RayTile::default();
        let (mut px, mut py) = ([0.0; TILE_RAYS], [0.0; TILE_RAYS]);
        let mut tile_hits = [None; TILE_RAYS];
        let mut colours = [Vec3::ZERO; TILE_RAYS];
        let mut sums = [Vec3::ZERO; TILE_RAYS];
        let mut scratch = TileScratch::default();
        let mut tile_cache = TileCache::default();
        loop {
            let next = next_band(&bands, from_back);
            let Some((band, pixels)) = next else {
                return n;
            };
            let (y0, rows) = (band * TILE, pixels.len() / w);
            for x0 in (0..w).step_by(TILE) {
                let cols = (w - x0).min(TILE);
                let k = cols * rows;
                sums[..k].fill(Vec3::ZERO);
                for s in 0..samples {
                    for i in 0..k {
                        let (x, y) = (x0 + i % cols, y0 + i / cols);
                        let pixel = (y * w + x) as u64;
                        let mut rng = Stream::for_sample(sampler, pixel, s, samples, frame);
                        let (ox, oy) = pixel_offset(&mut rng, s, samples);
                        (px[i], py[i]) = (x as f32 + ox, y as f32 + oy);
                    }
                    // `rays.ray(px[i], py[i])` for each, eight at a time.
                    rays.tile_at(cols, rows, &px, &py, &mut tile);
                    n.primary += k as u64;
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
                    for (sum, &c) in sums[..k].iter_mut().zip(&colours[..k]) {
                        *sum += c;
                    }
                }
                for (i, sum) in sums[..k].iter().enumerate() {
                    pixels[(i / cols) * w + x0 + i % cols] = *sum / samples as f32;
                }
            }
            if let Some(done) = done {
                done(y0 as u32, pixels);
            }
        }
    })
}
