//! `raytty render`: one frame to stdout or a file.

use std::fs::File;
use std::io::{self, BufWriter, IsTerminal, Seek, SeekFrom, Write};
use std::sync::{Mutex, PoisonError};

use anyhow::Context;
use clap::ValueEnum;
use glam::Vec3;
use raytty::frame::{CellMode, encode_kitty, encode_sixel};
use raytty::image::{pfm_band_offset, pfm_header, write_pfm_rows};
use raytty::{CellGrid, ColorMode, Options, Output, PointLight, Scene, encode_text};

use raytty::image::MAX_PIXELS;

use super::args::*;
use super::{Result, usage};

/// `--color` for `raytty render`, resolved: render's own, or the one given before the command
/// (`raytty --color 256 render`).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RenderColor {
    /// `raytty render --color`: picks the text format; refused with an image output.
    pub(super) own: Option<ColorMode>,
    /// `raytty --color … render`: picks the text format; images ignore it.
    pub(super) inherited: Option<ColorMode>,
}

/// `raytty render`; `no_color` (NO_COLOR is set) makes ascii the default text format, and
/// `color` picks the text format when `--format` is not given; `cells` is `--cells`, resolved.
pub(super) fn run_render(
    args: &RenderArgs,
    scene: Option<&str>,
    view: &raytty::scene::model::View,
    no_color: bool,
    color: RenderColor,
    cells: Option<CellMode>,
) -> Result<()> {
    if let Some(ext) = args.output.as_deref().and_then(unwritable_image_extension) {
        usage!(
            "-o {}: raytty cannot write .{ext} images: use a .png or .pfm file name (or --format ascii|ansi|ansi256 for text)",
            args.output
                .as_deref()
                .unwrap_or_else(|| "".as_ref())
                .display()
        );
    }
    let format = match (args.format, color.own, format_for(args.output.as_deref())) {
        (Some(f), _, _) => f,
        (None, Some(_), Format::Png | Format::Pfm) => {
            usage!(
                "--color sets a text format, and -o {} is an image: drop one of them",
                args.output.as_deref().unwrap_or("".as_ref()).display()
            );
        }
        (None, Some(mode), _) => text_format(mode),
        (None, None, Format::Ansi) => match color.inherited {
            Some(mode) => text_format(mode),
            None if no_color => Format::Ascii,
            None => Format::Ansi,
        },
        (None, None, f) => f,
    };
    if cells.is_some() && !matches!(format, Format::Ansi | Format::Ansi256) {
        usage!(
            "--cells picks the glyphs of a text frame in colour, and --format {} is not one: use --format ansi or ansi256",
            format_name(format)
        );
    }
    let cells = cells.unwrap_or_default();
    let image_format = matches!(format, Format::Png | Format::Pfm);
    if image_format && args.output.is_none() && io::stdout().is_terminal() {
        usage!(
            "--format {} writes binary data: give -o FILE or redirect stdout",
            format_name(format)
        );
    }
    let pictures = image_format || matches!(format, Format::Kitty | Format::Sixel);
    let (cw, ch) = cells.render_pixels();
    let (w, h) = match (args.pixels, args.size, pictures) {
        (Some(p), _, _) => p,
        (None, Some((cols, rows)), true) => (cols, rows * 2),
        (None, Some((cols, rows)), false) => (cols * cw, rows * ch),
        (None, None, true) => (500, 500),
        (None, None, false) => (80 * cw, 24 * ch),
    };
    let pixels = w as u64 * h as u64;
    if pixels > MAX_PIXELS {
        let asked = match args.pixels {
            Some(_) => format!("--pixels {w}x{h} is"),
            None => {
                let (cols, rows) = args.size.unwrap_or((80, 24));
                format!("--size {cols}x{rows} is {w}x{h} =")
            }
        };
        usage!(
            "{asked} {pixels} pixels, about {} MiB of memory; the limit is {MAX_PIXELS} pixels (e.g. --pixels 8192x8192 or --size 8192x4096)",
            pixels * 48 / (1024 * 1024)
        );
    }
    let tile = match args.tile {
        Some(part) if format != Format::Pfm => usage!(
            "--tile {}/{}: a tile is written as PFM (linear values, exact) for raytty merge: give -o NAME.pfm",
            part.0,
            part.1
        ),
        Some(part) => Some((part, crate::cli::tiles::rows_of(part, h)?)),
        None => None,
    };
    // Watched until the render is written: Ctrl-C ends it with 130 (`loading.rs`).
    let (mut scene, _watch) = crate::cli::scene_arg::load_scene(scene, view)?;
    if let Some(isa) = args.simd {
        let available: Vec<_> = raytty::simd::Isa::ALL
            .into_iter()
            .filter(|i| i.available())
            .map(|i| i.name())
            .collect();
        scene = match scene.with_isa(isa) {
            Some(s) => s,
            None => usage!(
                "--simd {}: this CPU does not have that path (it has {})",
                isa.name(),
                available.join(", ")
            ),
        };
    }
    let mut camera = scene.camera();
    if let Some([x, y, z, yaw]) = args.camera {
        camera.position = Vec3::new(x, y, z);
        camera.yaw = yaw.to_radians();
    }
    if args.light.is_some() && scene.lights().is_empty() {
        usage!(
            "--light moves the scene's first light, and this scene has none: add a [[light]] to the scene file"
        );
    }
    let lights = lights_with(&scene, args.light);
    let mut settings = args.stage.settings(scene.effects());
    if let Some(n) = args.samples {
        settings.effects.samples = n;
    }
    if let Some(s) = args.sampler {
        settings.effects.sampler = s;
    }
    if let Some(e) = args.estimator {
        settings.estimator = e;
    }
    if args.output.is_none() && stdout_was_closed() {
        return Err(anyhow::anyhow!(
            "stdout is closed: there is nowhere to write the frame (redirect it, or give -o FILE)"
        )
        .into());
    }
    let options = Options {
        width: w,
        height: h,
        settings: Some(settings),
        camera: Some(camera),
        lights: Some(&lights),
        rows: tile.map(|(_, rows)| rows),
        ..Options::default()
    };
    let denoised = args.denoise == Switch::On && options.denoises(&scene);
    if let (Some(((i, n), _)), true) = (tile, denoised) {
        usage!(
            "--tile {i}/{n}: the denoiser reads pixels across a tile's edges, so denoised tiles would not join into the frame: add --denoise off (with many samples per pixel it changes little)"
        );
    }
    // The output file is opened before the (maybe long) render, so a bad path fails at once.
    // It is not truncated here but after the write, to the length written: an existing file's
    // pages are overwritten in place rather than freed and allocated again (a few ms for a
    // 3 MB frame).
    let file = match &args.output {
        Some(path) => Some(
            File::options()
                .write(true)
                .create(true)
                .truncate(false)
                .open(path)
                .with_context(|| format!("cannot create {}", path.display()))?,
        ),
        None => None,
    };
    let mut out: Box<dyn Write + '_> = match &file {
        Some(f) => Box::new(BufWriter::new(f)),
        None => Box::new(BufWriter::new(io::stdout().lock())),
    };
    // A PFM file that is not denoised afterwards is written band by band as the render
    // finishes them, on the render's threads: the write overlaps the rest of the render.
    let streamed = match &file {
        Some(f)
            if format == Format::Pfm && !denoised && tile.is_none() && f.metadata()?.is_file() =>
        {
            Some(PfmBands::start(f, w, h).with_context(|| cannot_write(args))?)
        }
        _ => None,
    };
    let (stats, written) = match streamed {
        // Written as it renders: the frame is never held whole.
        Some(bands) => {
            let write = |y0, rows: &[Vec3]| bands.write(y0, rows);
            let output = Output::Rows(&write);
            let stats = scene.render(&Options { output, ..options }).stats;
            (stats, bands.finish())
        }
        _ => {
            let output = if denoised {
                Output::Denoised
            } else {
                Output::Image
            };
            let frame = scene.render(&Options { output, ..options });
            let tone = args.tonemap.unwrap_or(scene.tone_map());
            let written = match format {
                Format::Png => tone.image(&frame.image).write_png(&mut out),
                Format::Pfm => frame.image.write_pfm(&mut out).and_then(|()| match tile {
                    Some((part, rows)) => out
                        .write_all(crate::cli::tiles::trailer(part, rows, (w, h), tone).as_bytes()),
                    None => Ok(()),
                }),
                Format::Ansi | Format::Ansi256 | Format::Ascii => {
                    let mode = match format {
                        Format::Ansi => ColorMode::TrueColor,
                        Format::Ansi256 => ColorMode::Ansi256,
                        _ => ColorMode::Ascii,
                    };
                    let shown = tone.image(&frame.image);
                    out.write_all(&encode_text(&CellGrid::from_image_in(&shown, mode, cells)))
                }
                Format::Kitty | Format::Sixel => {
                    let mut bytes = Vec::new();
                    let encode = match format {
                        Format::Kitty => encode_kitty,
                        _ => encode_sixel,
                    };
                    encode(&tone.image(&frame.image).to_rgb8(), w, h, &mut bytes);
                    bytes.push(b'\n');
                    out.write_all(&bytes)
                }
            };
            (frame.stats, written)
        }
    };
    written
        .and_then(|()| out.flush())
        .and_then(|()| {
            drop(out);
            match &file {
                Some(f) if f.metadata()?.is_file() => f.set_len((&*f).stream_position()?),
                _ => Ok(()),
            }
        })
        .with_context(|| cannot_write(args))?;
    match args.stats {
        Some(StatsFormat::Text) => {
            let lights = if scene.lights_are_default() {
                "; lights: default (the file has none)"
            } else {
                ""
            };
            eprintln!("raytty: {w}x{h}, {}{lights}", stats.summary(scene.isa()))
        }
        Some(StatsFormat::Json) => {
            let json = stats.to_json(scene.isa());
            match (scene.lights_are_default(), json.strip_suffix('}')) {
                (true, Some(open)) => eprintln!("{open},\"default_lights\":true}}"),
                _ => eprintln!("{json}"),
            }
        }
        None => {}
    }
    Ok(())
}

/// "cannot write to FILE" (or stdout).
fn cannot_write(args: &RenderArgs) -> String {
    format!(
        "cannot write to {}",
        args.output
            .as_ref()
            .map_or_else(|| "stdout".to_string(), |p| p.display().to_string())
    )
}

/// A PFM file written a band of rows at a time, in any order, as the render hands them over
/// ([`Output::Rows`]): each band goes to its own place (rows are stored bottom first). The
/// first error stops the writing and is returned by [`PfmBands::finish`].
struct PfmBands<'f> {
    /// The file, and the first error writing to it.
    file: Mutex<(&'f File, Option<io::Error>)>,
    width: u32,
    height: u32,
    header: u64,
}

impl<'f> PfmBands<'f> {
    /// Writes the header of a `width`×`height` PFM at the start of `file`.
    fn start(mut file: &'f File, width: u32, height: u32) -> io::Result<PfmBands<'f>> {
        let header = pfm_header(width, height);
        file.seek(SeekFrom::Start(0))?;
        file.write_all(header.as_bytes())?;
        Ok(PfmBands {
            file: Mutex::new((file, None)),
            width,
            height,
            header: header.len() as u64,
        })
    }

    /// Writes the rows from `y0` down (whole rows) at their place, unless a write failed.
    fn write(&self, y0: u32, pixels: &[Vec3]) {
        let mut file = self.file.lock().unwrap_or_else(PoisonError::into_inner);
        if file.1.is_some() {
            return;
        }
        let rows = (pixels.len() / self.width as usize) as u32;
        let at = self.header + pfm_band_offset(self.width, self.height, y0, rows);
        let mut f = file.0;
        if let Err(e) = f
            .seek(SeekFrom::Start(at))
            .and_then(|_| write_pfm_rows(f, pixels, self.width as usize))
        {
            file.1 = Some(e);
        }
    }

    /// The first error, if a write failed; else leaves the file's position at the PFM's end,
    /// where [`run_render`] cuts the file (an older, longer file's tail goes).
    fn finish(self) -> io::Result<()> {
        let (mut file, error) = self
            .file
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner);
        if let Some(e) = error {
            return Err(e);
        }
        let pixels = u64::from(self.width) * u64::from(self.height) * 12;
        file.seek(SeekFrom::Start(self.header + pixels)).map(|_| ())
    }
}

/// Whether stdout was closed when raytty started (`raytty render >&-`), as opposed to a pipe
/// whose reader went away later (a broken pipe, which is not an error). Rust's runtime replaces
/// a closed standard descriptor with /dev/null before `main` (so that no file opened later
/// takes its number), after which writes to it succeed and vanish; so this is read earlier,
/// from an ELF constructor, while fd 1 is still as the shell left it. Elsewhere than on Linux,
/// false.
pub(super) fn stdout_was_closed() -> bool {
    #[cfg(target_os = "linux")]
    return stdout_at_start::CLOSED.load(std::sync::atomic::Ordering::Relaxed);
    #[cfg(not(target_os = "linux"))]
    false
}

#[cfg(target_os = "linux")]
mod stdout_at_start {
    use std::sync::atomic::{AtomicBool, Ordering};

    /// Set before `main` when fd 1 was not open.
    pub(super) static CLOSED: AtomicBool = AtomicBool::new(false);

    unsafe extern "C" {
        fn fcntl(fd: i32, cmd: i32, ...) -> i32;
    }
    /// `fcntl`'s "get descriptor flags": fails (EBADF) only if the descriptor is not open.
    const F_GETFD: i32 = 1;

    extern "C" fn record() {
        // SAFETY: F_GETFD reads a descriptor's flags and changes nothing; it takes no pointer.
        if unsafe { fcntl(1, F_GETFD) } == -1 {
            CLOSED.store(true, Ordering::Relaxed);
        }
    }

    /// Run by the loader before `main`, as the standard library's own argument capture is.
    #[used]
    #[unsafe(link_section = ".init_array")]
    static RECORD: extern "C" fn() = record;
}

/// `message` without the " (os error N)" that Rust's I/O errors end with: the words before it
/// say it all, and the number means nothing to a user.
pub(super) fn without_os_error(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(i) = rest.find(" (os error ") {
        let after = &rest[i + " (os error ".len()..];
        let digits = after.chars().take_while(char::is_ascii_digit).count();
        if digits > 0 && after[digits..].starts_with(')') {
            out.push_str(&rest[..i]);
            rest = &after[digits + 1..];
        } else {
            out.push_str(&rest[..i + 1]);
            rest = &rest[i + 1..];
        }
    }
    out.push_str(rest);
    out
}

/// The format an output file's extension implies: `.png` and `.pfm` are images, anything else
/// (and stdout) gets truecolor text.
pub(super) fn format_for(output: Option<&std::path::Path>) -> Format {
    let ext = output
        .and_then(|p| p.extension())
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Format::Png,
        Some("pfm") => Format::Pfm,
        _ => Format::Ansi,
    }
}

/// The extension of an image format raytty cannot write (`jpg`, `gif`, …), so that `-o
/// box.jpg` is refused instead of filled with terminal text.
pub(super) fn unwritable_image_extension(path: &std::path::Path) -> Option<String> {
    const IMAGES: [&str; 12] = [
        "jpg", "jpeg", "gif", "bmp", "tif", "tiff", "webp", "avif", "heic", "exr", "hdr", "ppm",
    ];
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    IMAGES.contains(&ext.as_str()).then_some(ext)
}

/// The text format that shows `mode`'s colours.
pub(super) fn text_format(mode: ColorMode) -> Format {
    match mode {
        ColorMode::TrueColor => Format::Ansi,
        ColorMode::Ansi256 => Format::Ansi256,
        ColorMode::Ascii => Format::Ascii,
    }
}

/// A format's name as `--format` spells it.
pub(super) fn format_name(format: Format) -> String {
    format
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// The scene's lights, with the first one moved to `light` if given.
pub(super) fn lights_with(scene: &Scene, light: Option<Vec3>) -> Vec<PointLight> {
    let mut lights = scene.lights().to_vec();
    if let (Some(p), Some(first)) = (light, lights.first_mut()) {
        first.position = p;
    }
    lights
}
