//! The render: [`Scene::render`] turns a scene and its [`Options`] into a [`Frame`].
//!
//! A frame's pixels depend only on (scene, camera, lights, settings, size): each sample's random
//! numbers are seeded from (pixel, sample, frame), and the ray counts are integer sums, so the
//! image and the stats are the same with one thread or many.
//!
//! Three loops, by what a frame calls for: one sample per pixel (`bands.rs`: bands of rows in
//! tiles of camera rays traced together), several samples of light that is not path traced
//! (`samples.rs`: a pass of tiles per sample), and several path-traced samples (`paths.rs`: a
//! row at a time, a pixel's samples one after the other).

use std::time::{Duration, Instant};

use glam::Vec3;

mod bands;
mod paths;
mod samples;
mod threads;

use crate::accel::Hit;
use crate::camera::{Camera, RayGen};
use crate::denoise::{GuidePixel, Guides, denoised_image};
use crate::geometry::Ray;
use crate::image::Image;
use crate::sampler::{Sampler, Stream};
use crate::scene::{PointLight, Scene};
use crate::shading::{LightEffects, PathRun, RayCounts, Settings, Stage, Tracer};

/// The side of a tile of camera rays traced together (`TILE`² = [`crate::accel::TILE_RAYS`]).
const TILE: usize = 8;

/// What to render: the frame's size, and what to take instead of the scene's own camera,
/// lights and effects. `Options::default()` is a 0×0 frame of the scene as it is.
///
/// ```
/// use raytty::{Options, Stage, cornell_box};
/// let scene = cornell_box();
/// let settings = Some(Stage::Shadows.settings(scene.effects()));
/// let frame = scene.render(&Options { width: 64, height: 48, settings, ..Options::default() });
/// assert_eq!((frame.image.width, frame.image.height), (64, 48));
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct Options<'a> {
    /// The frame's width in pixels.
    pub width: u32,
    /// The frame's height in pixels.
    pub height: u32,
    /// Only these rows of the frame, `(first, count)`: the image is `width × count`, each
    /// pixel bit for bit the whole frame's (a pixel's samples depend on the pixel, not on
    /// what else is rendered), so frames rendered in parts join into the whole one. Rows past
    /// `height` are left out. The denoiser filters what it is given: a part denoised alone
    /// differs from the whole frame's near its edges. `None`: every row.
    pub rows: Option<(u32, u32)>,
    /// What is computed: the shading mode, the effects (samples per pixel and their sampler
    /// among them) and the frame number that seeds the random numbers. `None`: the default
    /// stage ([`Stage::Indirect`]) of the scene's own effects.
    pub settings: Option<Settings>,
    /// Where the rays come from; `None`: the scene's camera.
    pub camera: Option<Camera>,
    /// The lights; `None`: the scene's.
    pub lights: Option<&'a [PointLight]>,
    /// What the frame gives besides its image.
    pub output: Output<'a>,
}

/// What a render gives besides its image ([`Options::output`]).
#[derive(Clone, Copy, Default)]
pub enum Output<'a> {
    /// The image.
    #[default]
    Image,
    /// The image and, with path-traced indirect light, the denoiser's guide buffers
    /// ([`Frame::guides`]). The image is the same as [`Output::Image`]'s.
    Guides,
    /// With path-traced indirect light the image denoised (the frame's time includes the
    /// filter's); other frames as [`Output::Image`] gives them ([`Options::denoises`]).
    Denoised,
    /// Every band of finished rows handed to the function as soon as it is finished: on the
    /// thread that finished it, in no set order, each row exactly once, all before the render
    /// returns. A caller can write the frame out while the rest of it renders. A frame of one
    /// sample is then never held whole (the returned frame's image is 0×0): each thread
    /// renders a band into rows of its own and reuses them for its next band (a 500×500 frame
    /// would otherwise be 3 MB of fresh memory for the kernel to zero, written out after it
    /// has left the caches).
    Rows(BandDone<'a>),
}

impl std::fmt::Debug for Output<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Output::Image => "Image",
            Output::Guides => "Guides",
            Output::Denoised => "Denoised",
            Output::Rows(_) => "Rows(..)",
        })
    }
}

/// What [`Output::Rows`] hands each band of finished rows to: `(y0, pixels)`, the image's rows
/// from `y0` down, `pixels.len()` a whole number of rows.
pub type BandDone<'a> = &'a (dyn Fn(u32, &[Vec3]) + Sync);

impl Options<'_> {
    /// Whether [`Output::Denoised`] changes a frame of these options of `scene`: only
    /// path-traced indirect light is denoised.
    pub fn denoises(&self, scene: &Scene) -> bool {
        Job::new(scene, self).tracer.splits()
    }
}

/// What a frame cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Rays traced by kind.
    pub rays: RayCounts,
    /// Samples per pixel.
    pub samples: u32,
    /// Wall-clock time of the render.
    pub elapsed: Duration,
    /// What the physically based path ran (`None`: the seed's shading).
    pub path: Option<PathRun>,
    /// The kinds of light besides point lights and emitters that lit the frame.
    pub lights: LightEffects,
}

/// A rendered frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The linear image.
    pub image: Image,
    /// What it cost.
    pub stats: FrameStats,
    /// The denoiser's guide buffers: only for [`Output::Guides`] with path-traced indirect
    /// light.
    pub guides: Option<Guides>,
}

/// The primary hits of the last frame, reused while the camera, size and geometry stay the
/// same: a frame where only the light (or the stage) changed traces no primary ray. Frames of
/// one sample per pixel use it ([`HitCache::render`]); the others leave it as it is.
#[derive(Clone, Debug, Default)]
pub struct HitCache {
    key: Option<CacheKey>,
    hits: Vec<Option<Hit>>,
}

/// The camera ([`Camera::key`]), the frame's size and the rows rendered (first, count).
type CacheKey = ([u32; 15], u32, u32, u32, u32);

fn cache_key(c: &Camera, width: u32, height: u32, top: u32, rows: u32) -> CacheKey {
    (c.key(), width, height, top, rows)
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

    /// [`Scene::render`], reusing this cache's primary hits when they are still valid (one
    /// sample per pixel, same camera and size) and refilling it otherwise. The frame is the
    /// same either way.
    pub fn render(&mut self, scene: &Scene, options: &Options) -> Frame {
        render(scene, options, Some(self))
    }
}

impl Scene {
    /// Renders a frame of this scene: see [`Options`] for what can be changed. Rendering
    /// never fails: a scene that loaded is a valid one.
    pub fn render(&self, options: &Options) -> Frame {
        render(self, options, None)
    }
}

/// One frame's inputs as the loops read them, shared by the render's threads.
struct Job<'a> {
    scene: &'a Scene,
    tracer: Tracer<'a>,
    camera: Camera,
    rays: RayGen,
    width: usize,
    /// The whole frame's height; the rows rendered are `height` of them from `top`.
    frame_height: u32,
    top: usize,
    height: usize,
    /// Samples per pixel (at least 1).
    samples: u32,
    /// Where a path-traced frame's numbers come from (independent ones for the others).
    sampler: Sampler,
    /// The frame number: seeds the random numbers.
    frame: u32,
    /// Where finished bands go ([`Output::Rows`]).
    done: Option<BandDone<'a>>,
}

impl<'a> Job<'a> {
    fn new(scene: &'a Scene, options: &Options<'a>) -> Job<'a> {
        let settings = options
            .settings
            .unwrap_or_else(|| Stage::Indirect.settings(scene.effects()));
        let camera = options.camera.unwrap_or_else(|| scene.camera());
        let tracer = Tracer::new(scene, options.lights.unwrap_or(scene.lights()), settings);
        // The sampler drives path-traced frames; the others keep their independent numbers.
        let sampler = if tracer.splits() {
            settings.effects.sampler
        } else {
            Sampler::Independent
        };
        let (top, count) = options.rows.map_or((0, options.height), |(first, count)| {
            let first = first.min(options.height);
            (first, count.min(options.height - first))
        });
        Job {
            scene,
            tracer,
            camera,
            rays: camera.rays(options.width, options.height),
            width: options.width as usize,
            frame_height: options.height,
            top: top as usize,
            height: count as usize,
            samples: settings.effects.samples.max(1),
            sampler,
            frame: settings.frame,
            done: match options.output {
                Output::Rows(done) => Some(done),
                _ => None,
            },
        }
    }

    /// One sample through `ray`. A path-traced frame's sample is split (the same colour
    /// either way, but one way of computing it, so that guided and plain frames agree bit for
    /// bit), and its parts are added to `guide` when the frame keeps guides.
    #[inline]
    fn sample(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        rng: &mut Stream,
        n: &mut RayCounts,
        guide: Option<&mut GuidePixel>,
    ) -> Vec3 {
        if !self.tracer.splits() {
            return self.tracer.shade_primary(ray, hit, rng, n);
        }
        let s = self.tracer.sample_primary(ray, hit, rng, n);
        if let Some(g) = guide {
            g.add(&s);
        }
        s.colour()
    }
}

/// The one render: sets up the frame's image and guides, runs the loop the frame calls for,
/// and denoises if asked to.
fn render(scene: &Scene, options: &Options, cache: Option<&mut HitCache>) -> Frame {
    let start = Instant::now();
    let job = Job::new(scene, options);
    let (width, height) = (options.width, job.height as u32);
    let (w, h) = (job.width, job.height);
    // A streamed frame of one sample goes out band by band from each thread's own rows.
    let own_rows = job.done.is_some() && job.samples == 1;
    let mut image = if own_rows {
        Image::new(0, 0)
    } else {
        Image::new(width, height)
    };
    // Path-traced frames split every sample for the denoiser (same colour, in any case).
    let guided = matches!(options.output, Output::Guides | Output::Denoised);
    let mut guides = (guided && job.tracer.splits()).then(|| Guides {
        width,
        height,
        samples: job.samples,
        pixels: vec![GuidePixel::default(); w * h],
    });
    let rays = if w == 0 || h == 0 {
        RayCounts::default()
    } else {
        // Rows of guide pixels, or none: `None` rows for none.
        let mut guide_rows: Vec<Option<&mut [GuidePixel]>> = match guides.as_mut() {
            Some(g) => g.pixels.chunks_mut(w).map(Some).collect(),
            None => (0..h).map(|_| None).collect(),
        };
        let pixels = (!own_rows).then_some(&mut image.pixels[..]);
        if job.samples == 1 {
            bands::render(&job, pixels, cache, &mut guide_rows)
        } else if job.tracer.shades_tiles() {
            samples::render(&job, &mut image.pixels)
        } else {
            paths::render(&job, &mut image.pixels, &mut guide_rows)
        }
    };
    let mut frame = Frame {
        image,
        stats: FrameStats {
            rays,
            samples: job.samples,
            elapsed: start.elapsed(),
            path: job.tracer.path_run(),
            lights: job.tracer.light_effects(),
        },
        guides,
    };
    if let (Output::Denoised, Some(g)) = (options.output, &frame.guides) {
        let start = Instant::now();
        frame.image = denoised_image(scene.isa(), g);
        frame.stats.elapsed += start.elapsed();
    }
    frame
}

impl FrameStats {
    /// The effects the frame ran beyond the seed's, by name: the physically based path's
    /// ([`PathRun::names`]), then the kinds of light ([`LightEffects::names`]).
    pub fn effect_names(&self) -> Vec<&'static str> {
        let mut names = self.path.map_or(vec![], |p| p.names());
        names.extend(self.lights.names());
        names
    }

    /// Millions of rays (all kinds) per second of the render's wall-clock time.
    pub fn mrays_per_s(&self) -> f64 {
        let s = self.elapsed.as_secs_f64();
        if s > 0.0 {
            self.rays.total() as f64 / s / 1e6
        } else {
            0.0
        }
    }

    /// One line for people: time, samples, rays by kind, M rays/s and the SIMD path, and the
    /// physically based effects where the frame ran them.
    pub fn summary(&self, isa: crate::accel::Isa) -> String {
        let rays = self.rays.by_kind().map(|(kind, n)| format!("{n} {kind}"));
        let names = self.effect_names();
        let effects = if names.is_empty() {
            String::new()
        } else {
            format!("; effects: {}", names.join(", "))
        };
        format!(
            "{:.2} ms, {} spp, rays: {}; {:.2} M rays/s ({}, {} threads){effects}",
            self.elapsed.as_secs_f64() * 1e3,
            self.samples,
            rays.join(", "),
            self.mrays_per_s(),
            isa.name(),
            rayon::current_num_threads()
        )
    }

    /// The same as one JSON object: `ms`, `spp`, `rays` (by kind), `mrays_per_s`, the
    /// `simd` path and `threads`, and `effects` (names) where the physically based path ran.
    pub fn to_json(&self, isa: crate::accel::Isa) -> String {
        let rays = self
            .rays
            .by_kind()
            .map(|(kind, n)| format!("\"{kind}\":{n}"));
        let names = self.effect_names();
        let effects = if names.is_empty() {
            String::new()
        } else {
            let names: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
            format!(",\"effects\":[{}]", names.join(","))
        };
        format!(
            "{{\"ms\":{:.3},\"spp\":{},\"rays\":{{{}}},\"mrays_per_s\":{:.3},\"simd\":\"{}\",\"threads\":{}{effects}}}",
            self.elapsed.as_secs_f64() * 1e3,
            self.samples,
            rays.join(","),
            self.mrays_per_s(),
            isa.name(),
            rayon::current_num_threads()
        )
    }
}
