//! What a scene costs: the acceleration structure's build time, and frame times and ray
//! throughput at a few sizes for the effects the scene calls for (stage `indirect`).
//!
//! This is the library side of `raytty bench --scene NAME`; the numbers it reports depend on
//! the machine, so no test asserts them.

use std::time::Duration;

use super::timing::{self, Runs};
use crate::accel::AccelStats;
use crate::render::Options;
use crate::scene::Scene;
use crate::shading::Stage;

/// Frame times at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct SizeBench {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Timed frames (after one untimed warm-up frame).
    pub runs: u32,
    /// Median frame time.
    pub median: Duration,
    /// Fastest frame.
    pub min: Duration,
    /// Slowest frame.
    pub max: Duration,
    /// Rays traced per frame, all kinds.
    pub rays: u64,
}

impl SizeBench {
    /// Millions of rays per second at the median frame time.
    pub fn mrays_per_s(&self) -> f64 {
        let s = self.median.as_secs_f64();
        if s > 0.0 {
            self.rays as f64 / s / 1e6
        } else {
            0.0
        }
    }
}

/// A scene's benchmark: build and frames.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneBench {
    /// The scene's name.
    pub scene: String,
    /// Its acceleration structure, as rebuilt for the measurement (its `build` is the time).
    pub accel: AccelStats,
    /// Worker threads rendering the frames.
    pub threads: usize,
    /// One entry per requested size, in order.
    pub sizes: Vec<SizeBench>,
}

/// Rebuilds `scene`'s acceleration structure once (timed), then renders `runs` frames (at least
/// one) at each size with the scene's own camera, lights and effects, after one untimed frame.
pub fn bench_scene(scene: &Scene, sizes: &[(u32, u32)], runs: u32) -> SceneBench {
    let accel = scene.build_accel(scene.accel_stats().kind).stats();
    let settings = Stage::Indirect.settings(scene.effects());
    let runs = runs.max(1);
    let sizes = sizes
        .iter()
        .map(|&(width, height)| {
            let options = Options {
                width,
                height,
                settings: Some(settings),
                ..Options::default()
            };
            let frame = || scene.render(&options);
            let rays = frame().stats.rays.total();
            let timing = timing::measure(
                Runs {
                    min: runs,
                    min_total: Duration::ZERO,
                    max: runs,
                },
                || {
                    let f = frame();
                    debug_assert_eq!(f.stats.rays.total(), rays);
                    f.stats.elapsed
                },
                || {},
            );
            SizeBench {
                width,
                height,
                runs: timing.runs(),
                median: timing.median(),
                min: timing.min(),
                max: timing.max(),
                rays,
            }
        })
        .collect();
    SceneBench {
        scene: scene.name().to_string(),
        accel,
        threads: rayon::current_num_threads(),
        sizes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cornell_box;

    #[test]
    fn reports_every_size_with_its_rays() {
        let b = bench_scene(&cornell_box(), &[(8, 4), (16, 8)], 3);
        assert_eq!(b.sizes.len(), 2);
        assert_eq!(b.accel.triangles, 30);
        for z in &b.sizes {
            assert_eq!(z.runs, 3);
            assert!(z.min <= z.median && z.median <= z.max);
            // One primary ray per pixel, and shadow rays for the lit ones.
            assert!(z.rays >= u64::from(z.width * z.height));
        }
    }
}
