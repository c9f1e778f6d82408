//! The price of each physically based effect and estimator: the built-in scenes that each call
//! for one new effect (area lights, glossy metal under lights of several sizes, glass), each
//! rendered with light sampling alone, BSDF sampling alone and MIS at a few samples per pixel,
//! raw and denoised, timed, and compared with a high-sample reference of that scene (cached as
//! the Cornell box's is).

use std::io;

use super::metrics;
use super::progress::Progress;
use super::reference::{self, ReferenceInfo, ReferenceSpec};
use super::timing::{self, Runs, ms};
use super::{BenchOptions, MAX_RUNS};
use crate::render::{Options, Output};
use crate::scene::Scene;
use crate::scene::builtin;
use crate::shading::{Estimator, GI_MAX_BOUNCES, RayCounts, Stage};

/// The built-in scenes of the estimator rows, each calling for one new effect.
pub const SCENES: [&str; 3] = ["area", "plates", "glass"];

/// The estimators compared (auto resolves to one of these).
pub const ESTIMATORS: [Estimator; 3] = [Estimator::Light, Estimator::Bsdf, Estimator::Mis];

/// Samples per pixel of the estimator rows (those up to the bench's largest).
pub const SPP: [u32; 3] = [4, 16, 64];

/// The references of these rows have this many times the bench's reference samples (4096 per
/// pixel in the full bench): the rows go to 64 samples, whose error should not be the
/// reference's own noise.
pub const REFERENCE_FACTOR: u32 = 4;

/// One measured row: a scene, an estimator, a sample count.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimatorRow {
    /// The scene's name.
    pub scene: String,
    /// The effects the frame ran (`render --stats`'s names).
    pub effects: Vec<&'static str>,
    /// The estimator at vertices that are not specular.
    pub estimator: Estimator,
    /// Samples per pixel.
    pub spp: u32,
    /// Whether the frame was denoised (its time includes the filter's).
    pub denoised: bool,
    /// Image width and height in pixels.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// Median wall-clock time per frame, in milliseconds.
    pub median_ms: f64,
    /// Timed runs.
    pub runs: u32,
    /// Rays per frame, by kind.
    pub rays: RayCounts,
    /// RMSE against the reference, of values clamped to `0..=1` ([`metrics::shown`]).
    pub rmse: f64,
    /// RMSE of 10×10-pixel block means against the reference (bias shows here, noise less),
    /// of values clamped to `0..=1`.
    pub block_rmse: f64,
}

impl EstimatorRow {
    /// Time × RMSE² (seconds): the lower, the more accuracy per time; constant along one
    /// estimator's samples for an unbiased estimator, so estimators compare at any count.
    pub fn efficiency(&self) -> f64 {
        self.median_ms * 1e-3 * self.rmse * self.rmse
    }
}

/// Renders the rows at `options`' last size (the terminal frame in the full bench): the
/// references first (cached), then each scene, estimator and sample count.
pub fn run(
    options: &BenchOptions,
    progress: &mut dyn Progress,
) -> io::Result<(Vec<EstimatorRow>, Vec<ReferenceInfo>)> {
    let Some(&(width, height)) = options.sizes.last() else {
        return Ok((vec![], vec![]));
    };
    let scenes: Vec<Scene> = SCENES
        .iter()
        .map(|name| {
            builtin::find(name)
                .expect("a built-in scene")
                .load()
                .expect("built-in scenes load")
        })
        .collect();
    let mut references = Vec::new();
    let mut images = Vec::new();
    for scene in &scenes {
        let spp = options.ref_spp.saturating_mul(REFERENCE_FACTOR);
        let spec = ReferenceSpec::new(scene, width, height, spp, GI_MAX_BOUNCES);
        let (img, info) = reference::load_or_render(scene, &spec, &options.cache_dir, progress)?;
        images.push(metrics::shown(&img));
        references.push(info);
    }
    let spps: Vec<u32> = SPP
        .into_iter()
        .filter(|&s| s <= options.max_spp.max(1))
        .collect();
    let runs = Runs {
        min: options.runs.max(1),
        min_total: options.min_row_time,
        max: MAX_RUNS,
    };
    let total: u64 = spps.iter().map(|&s| u64::from(s)).sum::<u64>()
        * (2 * ESTIMATORS.len() * scenes.len()) as u64
        * u64::from(runs.min + 1);
    progress.start("estimators", total, 0);
    let mut rows = Vec::new();
    for (scene, reference) in scenes.iter().zip(&images) {
        for estimator in ESTIMATORS {
            for (&spp, denoised) in spps.iter().flat_map(|s| [(s, false), (s, true)]) {
                let name = format!("{} {} {spp}spp", scene.name(), estimator.name());
                progress.message(&name);
                let mut settings = Stage::Gi.settings(scene.effects());
                settings.effects.samples = spp;
                settings.estimator = estimator;
                let frame_options = Options {
                    width,
                    height,
                    settings: Some(settings),
                    output: match denoised {
                        true => Output::Denoised,
                        false => Output::Image,
                    },
                    ..Options::default()
                };
                let mut kept = None;
                let timing = timing::measure(
                    runs,
                    || {
                        let f = scene.render(&frame_options);
                        let t = f.stats.elapsed;
                        kept.get_or_insert(f);
                        t
                    },
                    || progress.advance(u64::from(spp)),
                );
                let frame = kept.expect("measured at least once");
                let shown = metrics::shown(&frame.image);
                rows.push(EstimatorRow {
                    scene: scene.name().to_string(),
                    effects: frame.stats.effect_names(),
                    estimator,
                    spp,
                    denoised,
                    width,
                    height,
                    median_ms: ms(timing.median()),
                    runs: timing.runs(),
                    rays: frame.stats.rays,
                    rmse: metrics::rmse(&shown, reference),
                    block_rmse: metrics::block_rmse(&shown, reference, 10),
                });
            }
        }
    }
    progress.finish();
    Ok((rows, references))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every scene, estimator and sample count gets a raw row and a denoised one, each naming
    /// what it ran, its error finite; the estimators' rays differ as they should (BSDF sampling
    /// alone traces no area-light shadow ray); the denoised frame is not the raw one.
    #[test]
    fn a_row_per_scene_estimator_and_count() {
        let dir = std::env::temp_dir().join(format!("raytty-estimators-{}", std::process::id()));
        let options = BenchOptions {
            sizes: vec![(12, 8)],
            runs: 1,
            max_spp: 4,
            ref_spp: 16,
            cache_dir: dir.clone(),
            ..BenchOptions::quick()
        };
        let (rows, refs) = run(&options, &mut super::super::NoProgress).unwrap();
        assert_eq!(refs.len(), SCENES.len());
        assert_eq!(rows.len(), 2 * SCENES.len() * ESTIMATORS.len());
        for r in &rows {
            assert_eq!((r.spp, r.width, r.height), (4, 12, 8));
            assert!(r.rmse.is_finite() && r.block_rmse.is_finite(), "{r:?}");
            assert!(r.effects.contains(&"path"), "{r:?}");
        }
        let row = |e: Estimator, denoised: bool| {
            rows.iter()
                .find(|r| r.scene == "area" && r.estimator == e && r.denoised == denoised)
                .unwrap()
        };
        let area = |e: Estimator| row(e, false);
        assert_ne!(row(Estimator::Mis, true).rmse, area(Estimator::Mis).rmse);
        assert!(area(Estimator::Light).rays.shadow > area(Estimator::Bsdf).rays.shadow);
        assert!(
            area(Estimator::Bsdf)
                .effects
                .contains(&"area lights (bsdf sampling)")
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
