//! The reference image a bench row's error is measured against: path-traced GI with many samples
//! and bounces, rendered once and cached on disk, keyed by everything that decides its pixels.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::Vec3;

use super::progress::Progress;

use crate::image::Image;
use crate::render::Options;
use crate::sampler::Sampler;
use crate::scene::{Effects, Indirect, Scene};
use crate::shading::{Mode, Settings};

/// Bump when the renderer's expected image changes (the shading model, the camera, the scene),
/// so that a stale reference is never reused. Noise-only changes (sampling, roulette) keep it.
pub const REFERENCE_VERSION: u32 = 1;

/// Samples per pixel of one reference pass: a 4×4 stratified grid. The reference is the mean of
/// `spp / PASS_SPP` passes, each seeded with its own frame number, so the progress bar moves and
/// an interrupted render resumes from its last finished pass.
pub const PASS_SPP: u32 = 16;

/// Frame numbers of reference passes start here, far from the frames (0, 1, …) that bench rows
/// and the app use, so the reference's noise is independent of the images it judges.
const FRAME_BASE: u32 = 0x4000_0000;

/// What a reference is: the scene, the size, and how it is rendered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReferenceSpec {
    /// The scene's name (part of the cache key).
    pub scene: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel (rounded up to a multiple of [`PASS_SPP`]).
    pub spp: u32,
    /// Maximum path-traced bounces.
    pub bounces: u32,
}

impl ReferenceSpec {
    /// The spec for `scene` at `width`×`height`, with `spp` rounded up to whole passes.
    pub fn new(scene: &Scene, width: u32, height: u32, spp: u32, bounces: u32) -> ReferenceSpec {
        ReferenceSpec {
            scene: scene.name().to_string(),
            width,
            height,
            spp: spp.max(1).div_ceil(PASS_SPP) * PASS_SPP,
            bounces,
        }
    }

    /// The cache file's name: every field of the key, and the version.
    pub fn file_name(&self) -> String {
        let scene: String = self
            .scene
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        format!(
            "reference-{scene}-{}x{}-{}spp-{}b-v{REFERENCE_VERSION}.pfm",
            self.width, self.height, self.spp, self.bounces
        )
    }

    fn passes(&self) -> u32 {
        self.spp / PASS_SPP
    }

    fn settings(&self, pass: u32) -> Settings {
        Settings {
            mode: Mode::Colour,
            effects: Effects {
                shadows: true,
                indirect: Indirect::PathTraced {
                    bounces: self.bounces,
                },
                samples: PASS_SPP,
                // The cached references were rendered with independent numbers: keep them,
                // bit for bit.
                sampler: Sampler::Independent,
            },
            frame: FRAME_BASE + pass,
            estimator: crate::shading::Estimator::Auto,
        }
    }
}

/// Where a reference came from.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceInfo {
    /// What it is.
    pub spec: ReferenceSpec,
    /// The cache file.
    pub path: PathBuf,
    /// True when it was read from the cache, false when rendered now.
    pub cached: bool,
    /// Time spent rendering it now (zero when cached).
    pub render_time: Duration,
    /// Samples per pixel taken over from a partial or smaller cached reference (0 if none).
    pub resumed_spp: u32,
    /// Cache files that were refused (corrupt, truncated, another size) and removed, each
    /// as a sentence saying which and why; what they held was rendered again.
    pub refused: Vec<String>,
}

impl ReferenceInfo {
    /// One line saying how the reference was made and where it is cached.
    pub fn describe(&self) -> String {
        let s = &self.spec;
        let how = if self.cached {
            "read from the cache".to_string()
        } else if self.resumed_spp > 0 {
            format!(
                "rendered in {:.1} s after the first {} spp (cached before)",
                self.render_time.as_secs_f64(),
                self.resumed_spp
            )
        } else {
            format!("rendered in {:.1} s", self.render_time.as_secs_f64())
        };
        format!(
            "reference {}x{}: path-traced GI, {} spp ({} passes of {PASS_SPP}), up to {} bounces, \
             shadows, scene '{}'; {how}: {}",
            s.width,
            s.height,
            s.spp,
            s.passes(),
            s.bounces,
            s.scene,
            home_relative(&self.path)
        )
    }
}

/// `path` with the home directory written as `~`, as a person would type it.
fn home_relative(path: &Path) -> String {
    match std::env::var_os("HOME").filter(|h| !h.is_empty()) {
        Some(home) => match path.strip_prefix(&home) {
            Ok(rest) => format!("~/{}", rest.display()),
            Err(_) => path.display().to_string(),
        },
        None => path.display().to_string(),
    }
}

/// The cache directory: `$XDG_CACHE_HOME/raytty`, else `~/.cache/raytty`, else a `raytty`
/// folder in the system's temporary directory.
pub fn default_cache_dir() -> PathBuf {
    let env = |k| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(x) = env("XDG_CACHE_HOME") {
        x.join("raytty")
    } else if let Some(h) = env("HOME") {
        h.join(".cache").join("raytty")
    } else {
        std::env::temp_dir().join("raytty")
    }
}

/// The reference for `spec`, from `dir` if cached there, else rendered (resuming a partial
/// render left by an interrupted run) and written there, reporting its passes to `progress`.
pub fn load_or_render(
    scene: &Scene,
    spec: &ReferenceSpec,
    dir: &Path,
    progress: &mut dyn Progress,
) -> io::Result<(Image, ReferenceInfo)> {
    let path = dir.join(spec.file_name());
    let mut refused = Vec::new();
    let cached = |file: &Path, what: &str, refused: &mut Vec<String>| match read_cached(
        file,
        spec.width,
        spec.height,
    ) {
        Ok(img) => img,
        Err(why) => {
            refused.push(format!(
                "{what} {} was refused and removed ({why}); rendering it again",
                home_relative(file)
            ));
            None
        }
    };
    if let Some(img) = cached(&path, "the cached reference", &mut refused) {
        let info = ReferenceInfo {
            spec: spec.clone(),
            path,
            cached: true,
            render_time: Duration::ZERO,
            resumed_spp: 0,
            refused,
        };
        return Ok((img, info));
    }
    fs::create_dir_all(dir)?;
    let partial = path.with_extension("partial.pfm");
    let partial_count = path.with_extension("partial.txt");
    let passes = spec.passes();

    // Resume: the partial file holds the mean of the first `done` passes. Pass k is seeded by
    // k alone, so a cached reference with fewer samples (and the same key otherwise) is the
    // mean of this one's first passes: start from the largest one.
    let mut done = 0;
    let mut sum = vec![Vec3::ZERO; spec.width as usize * spec.height as usize];
    let mut start_from = |img: Image, n: u32| {
        if (img.width, img.height) == (spec.width, spec.height) && n > done && n < passes {
            done = n;
            for (s, p) in sum.iter_mut().zip(&img.pixels) {
                *s = *p * n as f32;
            }
        }
    };
    if let Some(img) = cached(&partial, "the partial reference", &mut refused) {
        match fs::read_to_string(&partial_count)
            .ok()
            .and_then(|c| c.trim().parse::<u32>().ok())
        {
            Some(n) => start_from(img, n),
            None => {
                let _ = fs::remove_file(&partial);
                refused.push(format!(
                    "the partial reference {} was removed (its pass count {} is missing or \
                     unreadable); rendering it again",
                    home_relative(&partial),
                    home_relative(&partial_count)
                ));
            }
        }
    }
    for fewer in (1..passes).rev() {
        let prefix = ReferenceSpec {
            spp: fewer * PASS_SPP,
            ..spec.clone()
        };
        if let Some(img) = cached(
            &dir.join(prefix.file_name()),
            "the cached reference",
            &mut refused,
        ) {
            start_from(img, fewer);
            break;
        }
    }

    progress.start(
        &format!("reference {}x{}", spec.width, spec.height),
        u64::from(passes),
        u64::from(done),
    );
    let resumed = done;
    let start = Instant::now();
    let mut mean = Image::new(spec.width, spec.height);
    for pass in done..passes {
        let frame = scene.render(&Options {
            width: spec.width,
            height: spec.height,
            settings: Some(spec.settings(pass)),
            ..Options::default()
        });
        for (s, p) in sum.iter_mut().zip(&frame.image.pixels) {
            *s += *p;
        }
        let n = (pass + 1) as f32;
        for (m, s) in mean.pixels.iter_mut().zip(&sum) {
            *m = *s / n;
        }
        if pass + 1 < passes {
            write_atomically(&partial, &pfm_bytes(&mean)?)?;
            fs::write(&partial_count, format!("{}\n", pass + 1))?;
        }
        progress.advance(1);
    }
    progress.finish();
    write_atomically(&path, &pfm_bytes(&mean)?)?;
    let _ = fs::remove_file(&partial);
    let _ = fs::remove_file(&partial_count);
    let info = ReferenceInfo {
        spec: spec.clone(),
        path,
        cached: false,
        render_time: start.elapsed(),
        resumed_spp: resumed * PASS_SPP,
        refused,
    };
    Ok((mean, info))
}

/// The `width`×`height` image cached at `path`: `Ok(None)` if there is no such file, `Err` with
/// the reason if there is one but it is not such an image (another format, corrupt, truncated,
/// another size); that file is then removed, so it is refused once, not on every run. A file
/// larger than the image needs is refused without being read.
fn read_cached(path: &Path, width: u32, height: u32) -> Result<Option<Image>, String> {
    let refuse = |why: String| {
        let _ = fs::remove_file(path);
        Err(why)
    };
    let mut file = match fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("it cannot be read: {e}")),
    };
    // The header ("PF\n", two numbers of at most 10 digits, "-1.0\n") takes under 64 bytes.
    let most = (u64::from(width) * u64::from(height))
        .saturating_mul(12)
        .saturating_add(64);
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    if len > most {
        return refuse(format!(
            "it is {len} bytes, more than a {width}x{height} image takes"
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    io::Read::read_to_end(&mut file, &mut bytes).map_err(|e| format!("it cannot be read: {e}"))?;
    match Image::read_pfm(&bytes) {
        Ok(img) if (img.width, img.height) == (width, height) => Ok(Some(img)),
        Ok(img) => refuse(format!(
            "it is {}x{}, not {width}x{height}",
            img.width, img.height
        )),
        Err(e) => refuse(e.to_string()),
    }
}

fn pfm_bytes(img: &Image) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    img.write_pfm(&mut out)?;
    Ok(out)
}

/// Writes `bytes` to a temporary file next to `path`, then renames it into place, so a reader
/// never sees half a file.
fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    fs::write(&tmp, bytes)?;
    fs::rename(&tmp, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::NoProgress;

    /// A reference that starts from a cached one with fewer samples equals one rendered whole
    /// (up to the rounding of mean·n), and a second call reads it from the cache.
    #[test]
    fn more_samples_resume_from_fewer_and_are_cached() {
        let scene = crate::scene::cornell::cornell_box();
        let tmp = std::env::temp_dir().join(format!("raytty-ref-test-{}", std::process::id()));
        let (a, b) = (tmp.join("a"), tmp.join("b"));
        let spec = |spp| ReferenceSpec::new(&scene, 12, 10, spp, 4);
        let (whole, info) = load_or_render(&scene, &spec(48), &a, &mut NoProgress).unwrap();
        assert!(!info.cached);
        load_or_render(&scene, &spec(16), &b, &mut NoProgress).unwrap();
        let (resumed, _) = load_or_render(&scene, &spec(48), &b, &mut NoProgress).unwrap();
        for (p, q) in whole.pixels.iter().zip(&resumed.pixels) {
            assert!((*p - *q).abs().max_element() <= 1e-5 * p.max_element().max(1.0));
        }
        let (again, info) = load_or_render(&scene, &spec(48), &b, &mut NoProgress).unwrap();
        assert!(info.cached && info.describe().contains("read from the cache"));
        assert_eq!(again, resumed);
        let _ = fs::remove_dir_all(&tmp);
    }

    /// References take independent numbers, whatever the scene's sampler: their cached files
    /// were rendered so (`tests/determinism.rs` pins that sampler's frames bit for bit).
    #[test]
    fn references_use_independent_numbers() {
        let scene = crate::scene::cornell::cornell_box();
        assert_eq!(scene.effects().sampler, Sampler::Sobol);
        let spec = ReferenceSpec::new(&scene, 12, 10, 32, 4);
        for pass in 0..2 {
            assert_eq!(spec.settings(pass).effects.sampler, Sampler::Independent);
        }
    }

    /// A corrupt cache file (here a header whose size overflows, which used to be read with
    /// an unchecked `width·height·12`) is refused with a message, removed, and rendered again.
    #[test]
    fn a_corrupt_cache_file_is_refused_and_rendered_again() {
        let scene = crate::scene::cornell::cornell_box();
        let dir = std::env::temp_dir().join(format!("raytty-ref-corrupt-{}", std::process::id()));
        let spec = ReferenceSpec::new(&scene, 12, 10, 16, 4);
        let (good, _) = load_or_render(&scene, &spec, &dir, &mut NoProgress).unwrap();
        let path = dir.join(spec.file_name());
        for corrupt in [
            &b"PF\n4294967295 4294967295\n-1.0\n\0\0\0\0"[..],
            b"PF\n12 10\n-1.0\ntruncated",
            b"PF\n3 2\n-1.0\n",
            &[0u8; 2000],
        ] {
            fs::write(&path, corrupt).unwrap();
            let (img, info) = load_or_render(&scene, &spec, &dir, &mut NoProgress).unwrap();
            assert_eq!(img, good);
            assert!(!info.cached);
            assert_eq!(info.refused.len(), 1, "{:?}", info.refused);
            let note = &info.refused[0];
            assert!(
                note.contains(&spec.file_name()) && note.contains("refused"),
                "{note}"
            );
            // Rewritten whole: the next call reads it back and refuses nothing.
            let (again, info) = load_or_render(&scene, &spec, &dir, &mut NoProgress).unwrap();
            assert!(info.cached && info.refused.is_empty());
            assert_eq!(again, good);
        }
        let _ = fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_file_name_holds_the_whole_key() {
        let spec = ReferenceSpec {
            scene: "cornell box".into(),
            width: 500,
            height: 400,
            spp: 1024,
            bounces: 16,
        };
        assert_eq!(
            spec.file_name(),
            format!("reference-cornell-box-500x400-1024spp-16b-v{REFERENCE_VERSION}.pfm")
        );
    }
}
