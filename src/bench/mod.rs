//! `raytty bench`: what each step of accuracy costs in time. Every row renders the Cornell box
//! (or any scene) at one size with one set of effects, several times after a warm-up, and is
//! compared with a path-traced reference that is rendered once and cached on disk.
//!
//! The library side of the command is the measuring: the rows, the timing, the errors against
//! the reference. Writing it out (tables, CSV, the charts, docs/performance.md) is the binary's.

mod environment;
pub mod estimators;
pub mod metrics;
pub mod progress;
pub mod reference;
pub mod scene;
pub mod throughput;
pub mod timing;

use std::io;
use std::path::PathBuf;
use std::time::Duration;

use crate::frame::{CellGrid, ColorMode, encode_text};
use crate::image::Image;
use crate::render::{Options, Output};
use crate::sampler::Sampler;
use crate::scene::{Effects, Indirect, Scene};
use crate::shading::{GI_MAX_BOUNCES, Mode, RayCounts, Settings, Stage};

use environment::{load_average, machine, utc_now};
pub use progress::{NoProgress, Progress};
pub use reference::{ReferenceInfo, ReferenceSpec};
use timing::{Runs, ms};

/// The seed's stages that get a row each (stage 6, GI, has its own rows).
pub const SEED_STAGES: [Stage; 5] = [
    Stage::Flat,
    Stage::Light,
    Stage::Direct,
    Stage::Shadows,
    Stage::Indirect,
];

/// Anti-aliasing rows: the seed's effects at these samples per pixel.
pub const AA_SPP: [u32; 2] = [4, 16];

/// GI rows: these bounce counts, each at a ladder of samples per pixel.
pub const GI_BOUNCES: [u32; 4] = [1, 2, 4, 8];

/// Stage 6 rows, raw and denoised: these samples per pixel (paths end by roulette, at most
/// [`GI_MAX_BOUNCES`] bounces).
pub const DENOISE_SPP: [u32; 3] = [1, 4, 16];

/// The most runs a fast row gets.
pub const MAX_RUNS: u32 = 51;

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchOptions {
    /// Image sizes in pixels, width × height.
    pub sizes: Vec<(u32, u32)>,
    /// Timed runs per row, after one warm-up run (at least; see `min_row_time`).
    pub runs: u32,
    /// A fast row is run more than `runs` times, until its timed runs add up to this long (or
    /// [`MAX_RUNS`]): a frame of a few milliseconds is at the mercy of the scheduler, and the
    /// median of more runs steadies it at little cost.
    pub min_row_time: Duration,
    /// The GI ladder goes 1, 4, 16, … up to this many samples per pixel.
    pub max_spp: u32,
    /// The reference's samples per pixel.
    pub ref_spp: u32,
    /// The reference's maximum bounces.
    pub ref_bounces: u32,
    /// Where references are cached.
    pub cache_dir: PathBuf,
}

impl BenchOptions {
    /// The full bench: the seed's 500×500 and a 200×100 terminal frame, 5 runs, GI up to 64
    /// spp, against a 1024 spp, 16-bounce reference.
    pub fn full() -> BenchOptions {
        BenchOptions {
            sizes: vec![(500, 500), (200, 100)],
            runs: 5,
            min_row_time: Duration::from_millis(500),
            max_spp: 64,
            ref_spp: 1024,
            ref_bounces: 16,
            cache_dir: reference::default_cache_dir(),
        }
    }

    /// A bench that runs in a second or two (for tests): tiny sizes, 2 runs (no more for fast
    /// rows), GI up to 4 spp,
    /// a 64 spp, 8-bounce reference.
    pub fn quick() -> BenchOptions {
        BenchOptions {
            sizes: vec![(40, 40), (32, 16)],
            runs: 2,
            min_row_time: Duration::ZERO,
            max_spp: 4,
            ref_spp: 64,
            ref_bounces: 8,
            ..BenchOptions::full()
        }
    }

    /// The GI ladder of samples per pixel: 1, 4, 16, … ≤ `max_spp`.
    pub fn spp_ladder(&self) -> Vec<u32> {
        std::iter::successors(Some(1u32), |s| s.checked_mul(4))
            .take_while(|&s| s <= self.max_spp.max(1))
            .collect()
    }
}

/// What a row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// One of the seed's stages, 1 sample per pixel (`Indirect` is the seed's constant N).
    Stage(Stage),
    /// The seed's effects with stratified anti-aliasing.
    Aa {
        /// Samples per pixel.
        spp: u32,
    },
    /// Path-traced global illumination.
    Gi {
        /// Maximum bounces.
        bounces: u32,
        /// Samples per pixel.
        spp: u32,
    },
    /// Stage 6 raw with independent random numbers instead of the scene's sampler (Sobol by
    /// default): what the sampler buys at equal samples.
    Independent {
        /// Samples per pixel.
        spp: u32,
    },
    /// Stage 6 (path-traced, at most [`GI_MAX_BOUNCES`] bounces) with the denoiser; the time
    /// includes the filter.
    Denoised {
        /// Samples per pixel.
        spp: u32,
    },
}

impl RowKind {
    /// A short name for tables and plots.
    pub fn label(&self) -> String {
        match *self {
            RowKind::Stage(Stage::Indirect) => "indirect (seed, N = 0.5)".into(),
            RowKind::Stage(s) => s.name().into(),
            RowKind::Aa { .. } => "AA (seed, N = 0.5)".into(),
            RowKind::Gi { .. } => "GI".into(),
            RowKind::Independent { .. } => "GI, independent numbers".into(),
            RowKind::Denoised { .. } => "GI + denoiser".into(),
        }
    }

    /// Samples per pixel.
    pub fn spp(&self) -> u32 {
        match *self {
            RowKind::Stage(_) => 1,
            RowKind::Aa { spp }
            | RowKind::Gi { spp, .. }
            | RowKind::Independent { spp }
            | RowKind::Denoised { spp } => spp,
        }
    }

    /// Maximum bounces (GI rows, raw and denoised).
    pub fn bounces(&self) -> Option<u32> {
        match *self {
            RowKind::Gi { bounces, .. } => Some(bounces),
            RowKind::Independent { .. } | RowKind::Denoised { .. } => Some(GI_MAX_BOUNCES),
            _ => None,
        }
    }

    /// Maximum bounces of a raw GI row with the scene's sampler (`None` for every other row,
    /// denoised and independent ones included).
    pub fn raw_bounces(&self) -> Option<u32> {
        match *self {
            RowKind::Gi { bounces, .. } => Some(bounces),
            _ => None,
        }
    }

    /// The settings the row renders with.
    pub fn settings(&self, scene: &Scene) -> Settings {
        match *self {
            RowKind::Stage(s) => s.settings(scene.effects()),
            RowKind::Aa { spp } => {
                let mut s = Stage::Indirect.settings(scene.effects());
                s.effects.samples = spp;
                s
            }
            RowKind::Gi { bounces, spp } => Settings {
                mode: Mode::Colour,
                effects: Effects {
                    shadows: true,
                    indirect: Indirect::PathTraced { bounces },
                    samples: spp,
                    sampler: scene.effects().sampler,
                },
                frame: 0,
                estimator: crate::shading::Estimator::Auto,
            },
            RowKind::Independent { spp } => {
                let mut s = RowKind::Gi {
                    bounces: GI_MAX_BOUNCES,
                    spp,
                }
                .settings(scene);
                s.effects.sampler = Sampler::Independent;
                s
            }
            RowKind::Denoised { spp } => RowKind::Gi {
                bounces: GI_MAX_BOUNCES,
                spp,
            }
            .settings(scene),
        }
    }

    /// A rough cost, for the progress bar: samples times (bounces + 1).
    fn weight(&self) -> u64 {
        u64::from(self.spp()) * (1 + u64::from(self.bounces().unwrap_or(0)))
    }
}

/// One measured row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// What was rendered.
    pub kind: RowKind,
    /// Median wall-clock time per frame, in milliseconds.
    pub median_ms: f64,
    /// Fastest run, in milliseconds.
    pub min_ms: f64,
    /// Slowest run, in milliseconds.
    pub max_ms: f64,
    /// Timed runs (the median is over these).
    pub runs: u32,
    /// Rays traced per frame, by kind.
    pub rays: RayCounts,
    /// Millions of rays per second at the median time.
    pub mrays_per_s: f64,
    /// RMSE of the linear values against the reference.
    pub rmse: f64,
    /// PSNR of the 8-bit image against the reference's, in dB (infinite if equal).
    pub psnr: f64,
    /// Bytes of one whole truecolor frame at the matching cell size (width × height/2 cells).
    pub ansi_bytes: usize,
}

/// Where and when the numbers were taken.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// UTC date and time, `YYYY-MM-DD HH:MM UTC`.
    pub date: String,
    /// The CPU model (from /proc/cpuinfo where there is one) and the architecture.
    pub machine: String,
    /// Cores (hardware threads) the process may run on.
    pub cores: usize,
    /// The SIMD path the kernels took.
    pub simd: &'static str,
    /// Threads the renders ran on (rayon's pool).
    pub threads: usize,
    /// One-minute load averages at the start and the end (where the OS reports them).
    pub load: Option<(f64, f64)>,
}

/// Everything a bench run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    /// The rows, size by size, in the order of [`rows_for`].
    pub rows: Vec<Row>,
    /// The reference of each size.
    pub references: Vec<ReferenceInfo>,
    /// Where and when.
    pub environment: Environment,
}

/// The rows of one size: the seed's stages, anti-aliasing, GI by bounces and samples, then
/// stage 6 raw, raw with independent numbers (the sampler's effect), and denoised.
pub fn rows_for(options: &BenchOptions) -> Vec<RowKind> {
    let mut rows: Vec<RowKind> = SEED_STAGES.iter().map(|&s| RowKind::Stage(s)).collect();
    rows.extend(AA_SPP.iter().map(|&spp| RowKind::Aa { spp }));
    for bounces in GI_BOUNCES {
        for spp in options.spp_ladder() {
            rows.push(RowKind::Gi { bounces, spp });
        }
    }
    let stage6 = DENOISE_SPP
        .iter()
        .filter(|&&spp| spp <= options.max_spp.max(1));
    rows.extend(stage6.clone().map(|&spp| RowKind::Gi {
        bounces: GI_MAX_BOUNCES,
        spp,
    }));
    rows.extend(stage6.clone().map(|&spp| RowKind::Independent { spp }));
    rows.extend(stage6.map(|&spp| RowKind::Denoised { spp }));
    rows
}

/// Runs the bench on `scene`: references first (cached), then every row of every size.
pub fn run(
    scene: &Scene,
    options: &BenchOptions,
    progress: &mut dyn Progress,
) -> io::Result<BenchReport> {
    let load_start = load_average();
    let mut references = Vec::new();
    let mut images = Vec::new();
    for &(w, h) in &options.sizes {
        let spec = ReferenceSpec::new(scene, w, h, options.ref_spp, options.ref_bounces);
        let (img, info) = reference::load_or_render(scene, &spec, &options.cache_dir, progress)?;
        images.push(img);
        references.push(info);
    }

    let kinds = rows_for(options);
    let runs = options.runs.max(1);
    let total: u64 = kinds
        .iter()
        .map(|k| k.weight() * u64::from(runs + 1))
        .sum::<u64>()
        * options.sizes.len() as u64;
    progress.start("bench", total, 0);
    let mut rows = Vec::new();
    for (&(w, h), reference) in options.sizes.iter().zip(&images) {
        for kind in &kinds {
            progress.message(&format!(
                "{w}x{h} {} {}spp",
                kind.label().split(' ').next().unwrap_or(""),
                kind.spp()
            ));
            rows.push(measure(scene, *kind, w, h, options, reference, || {
                progress.advance(kind.weight())
            }));
        }
    }
    progress.finish();
    let load_end = load_average();
    Ok(BenchReport {
        rows,
        references,
        environment: Environment {
            date: utc_now(),
            machine: machine(),
            cores: std::thread::available_parallelism().map_or(1, usize::from),
            simd: scene.isa().name(),
            threads: rayon::current_num_threads(),
            load: load_start.zip(load_end),
        },
    })
}

/// Renders one row `runs + 1` times or more (the first is a warm-up) and measures it.
fn measure(
    scene: &Scene,
    kind: RowKind,
    width: u32,
    height: u32,
    options: &BenchOptions,
    reference: &Image,
    tick: impl FnMut(),
) -> Row {
    let settings = kind.settings(scene);
    let denoised = matches!(kind, RowKind::Denoised { .. });
    let frame_options = Options {
        width,
        height,
        settings: Some(settings),
        output: if denoised {
            Output::Denoised
        } else {
            Output::Image
        },
        ..Options::default()
    };
    let render_once = || scene.render(&frame_options);
    let runs = Runs {
        min: options.runs.max(1),
        min_total: options.min_row_time,
        max: MAX_RUNS,
    };
    // The first (warm-up) frame is kept for the error columns; every later one must equal it.
    let mut kept: Option<crate::render::Frame> = None;
    let timing = timing::measure(
        runs,
        || {
            let f = render_once();
            let t = f.stats.elapsed;
            match &kept {
                None => kept = Some(f),
                Some(k) => debug_assert_eq!(f.image, k.image, "frames are deterministic"),
            }
            t
        },
        tick,
    );
    let frame = kept.expect("measure renders at least once");
    let median_ms = ms(timing.median());
    let rays = frame.stats.rays;
    Row {
        width,
        height,
        kind,
        median_ms,
        runs: timing.runs(),
        min_ms: ms(timing.min()),
        max_ms: ms(timing.max()),
        rays,
        mrays_per_s: rays.total() as f64 / (median_ms * 1e-3).max(1e-9) / 1e6,
        rmse: metrics::rmse(&frame.image, reference),
        psnr: metrics::psnr8(&frame.image, reference),
        ansi_bytes: encode_text(&CellGrid::from_image(&frame.image, ColorMode::TrueColor)).len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ladder_goes_up_by_four() {
        let mut o = BenchOptions::quick();
        o.max_spp = 64;
        assert_eq!(o.spp_ladder(), [1, 4, 16, 64]);
        o.max_spp = 100;
        assert_eq!(o.spp_ladder(), [1, 4, 16, 64]);
        o.max_spp = 1;
        assert_eq!(o.spp_ladder(), [1]);
    }

    #[test]
    fn rows_cover_the_stages_aa_and_every_bounce_count() {
        let o = BenchOptions::quick();
        let rows = rows_for(&o);
        assert_eq!(rows.len(), 5 + 2 + 4 * o.spp_ladder().len() + 3 * 2);
        assert_eq!(rows[4], RowKind::Stage(Stage::Indirect));
        assert_eq!(rows[6], RowKind::Aa { spp: 16 });
        assert_eq!(rows[6 + 4 * 2], RowKind::Gi { bounces: 8, spp: 4 });
        assert_eq!(
            rows[6 + 4 * 2 + 1],
            RowKind::Gi {
                bounces: GI_MAX_BOUNCES,
                spp: 1
            }
        );
        assert_eq!(rows[rows.len() - 3], RowKind::Independent { spp: 4 });
        assert_eq!(rows.last(), Some(&RowKind::Denoised { spp: 4 }));
    }
}
