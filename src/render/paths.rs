//! Frames of several path-traced samples per pixel: a row at a time (rows in parallel), each
//! pixel's samples one after the other, jittered within the pixel as `samples::pixel_offset`
//! puts them.

use glam::Vec3;
use rayon::prelude::*;

use super::Job;
use super::samples::pixel_offset;
use crate::denoise::GuidePixel;
use crate::sampler::Stream;
use crate::shading::RayCounts;

/// Renders `job`'s frame into `pixels`, each pixel the mean of its samples, and each row's
/// guide pixels (where they are kept) the means of the samples' parts. `job.done` gets each
/// row when it is finished.
pub(super) fn render(
    job: &Job,
    pixels: &mut [Vec3],
    guide_rows: &mut [Option<&mut [GuidePixel]>],
) -> RayCounts {
    let (w, samples) = (job.width, job.samples);
    pixels
        .par_chunks_mut(w)
        .zip(guide_rows.par_iter_mut())
        .enumerate()
        .map(|(row_index, (row, guide_row))| {
            // The frame's row (the rows rendered may start below its top).
            let y = job.top + row_index;
            let mut n = RayCounts::default();
            for (x, px) in row.iter_mut().enumerate() {
                let mut acc = Vec3::ZERO;
                for s in 0..samples {
                    let pixel = (y * w + x) as u64;
                    let mut rng = Stream::for_sample(job.sampler, pixel, s, samples, job.frame);
                    let (ox, oy) = pixel_offset(&mut rng, s, samples);
                    let ray = job.rays.ray(x as f32 + ox, y as f32 + oy);
                    n.primary += 1;
                    let hit = job.scene.intersect(&ray, f32::INFINITY);
                    let g = guide_row.as_mut().map(|r| &mut r[x]);
                    acc += job.sample(&ray, hit, &mut rng, &mut n, g);
                }
                *px = acc / samples as f32;
                if let Some(r) = guide_row.as_mut() {
                    r[x].scale(1.0 / samples as f32);
                }
            }
            if let Some(done) = job.done {
                done(row_index as u32, row);
            }
            n
        })
        .reduce(RayCounts::default, |mut a, b| {
            a += b;
            a
        })
}
