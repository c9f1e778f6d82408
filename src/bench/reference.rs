//! The reference image a bench row's error is measured against: path-traced GI with many samples
//! and bounces, rendered once and cached on disk, keyed by everything that decides its pixels.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::Vec3;

use super::progress::Progress;

use crate::image::Image;
use crate::render::render;
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
            },
            frame: FRAME_BASE + pass,
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
    let info = |cached, render_time, resumed_spp| ReferenceInfo {
        spec: spec.clone(),
        path: path.clone(),
        cached,
        render_time,
        resumed_spp,
    };
    if let Ok(bytes) = fs::read(&path)
        && let Some(img) = read_pfm(&bytes)
        && (img.width, img.height) == (spec.width, spec.height)
    {
        return Ok((img, info(true, Duration::ZERO, 0)));
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
    if let (Ok(bytes), Ok(count)) = (fs::read(&partial), fs::read_to_string(&partial_count))
        && let (Some(img), Ok(n)) = (read_pfm(&bytes), count.trim().parse::<u32>())
    {
        start_from(img, n);
    }
    for fewer in (1..passes).rev() {
        let prefix = ReferenceSpec {
            spp: fewer * PASS_SPP,
            ..spec.clone()
        };
        if let Ok(bytes) = fs::read(dir.join(prefix.file_name()))
            && let Some(img) = read_pfm(&bytes)
        {
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
        let frame = render(
            scene,
            &scene.camera(),
            scene.lights(),
            &spec.settings(pass),
            spec.width,
            spec.height,
        );
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
    Ok((mean, info(false, start.elapsed(), resumed * PASS_SPP)))
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

/// Reads a colour PFM (`PF`, little-endian as [`Image::write_pfm`] writes it, bottom row first).
/// `None` if it is anything else or truncated.
pub fn read_pfm(bytes: &[u8]) -> Option<Image> {
    // Three whitespace-terminated header tokens after "PF": width, height, scale.
    let mut pos = 0;
    let mut token = || {
        while bytes.get(pos)?.is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while !bytes.get(pos)?.is_ascii_whitespace() {
            pos += 1;
        }
        let t = std::str::from_utf8(&bytes[start..pos]).ok()?;
        pos += 1; // the single whitespace byte that ends the token
        Some(t.to_string())
    };
    if token()? != "PF" {
        return None;
    }
    let width: u32 = token()?.parse().ok()?;
    let height: u32 = token()?.parse().ok()?;
    let scale: f32 = token()?.parse().ok()?;
    if !(scale < 0.0) {
        return None; // big-endian files are not ours
    }
    let n = width as usize * height as usize;
    let data = bytes.get(pos..pos + n * 12)?;
    let mut img = Image::new(width, height);
    for (i, px) in data.chunks_exact(12).enumerate() {
        let f = |k: usize| f32::from_le_bytes([px[k], px[k + 1], px[k + 2], px[k + 3]]);
        let (x, row) = (i % width as usize, i / width as usize);
        let y = height as usize - 1 - row;
        img.pixels[y * width as usize + x] = Vec3::new(f(0), f(4), f(8));
    }
    Some(img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::NoProgress;

    #[test]
    fn pfm_round_trips() {
        let mut img = Image::new(3, 2);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, 0.5 * i as f32, -1.25);
        }
        assert_eq!(read_pfm(&pfm_bytes(&img).unwrap()), Some(img));
        assert_eq!(read_pfm(b"P6\n1 1\n255\n..."), None);
        assert_eq!(read_pfm(b"PF\n2 2\n-1.0\n"), None);
    }

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
