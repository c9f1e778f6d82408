//! Command-line parsing and the non-interactive commands. The exit code is chosen here, once:
//! 0 for success (a closed output pipe included), 1 for a failure while running, 2 for bad
//! input (clap's own usage errors are 2 as well), and for the app 128 + N after signal N
//! ([`signal_status`]; a dropped terminal counts as SIGHUP).

use std::fs::File;
use std::io::{self, BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use raytty::{CellGrid, ColorMode, PointLight, Scene, Stage, encode_text, render};

/// Renders the Cornell box (or another scene) by ray tracing, in the terminal.
///
/// With no command on a terminal, raytty runs the interactive app; when stdout is not a
/// terminal (or TERM is dumb) it prints one frame, as `raytty render` would. Frames are truecolor half-blocks:
/// each cell shows two pixels, so an 80×24 frame is 80×48 pixels.
#[derive(Parser, Debug)]
#[command(name = "raytty", version, about, long_about)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Colours of the app and of the frame printed with no command: auto (ascii if NO_COLOR is
    /// set, truecolor if COLORTERM is truecolor or 24bit, else 256), truecolor, 256 or ascii.
    /// ssh does not forward COLORTERM: pass --color truecolor (or press C) to get it back.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    color: ColorChoice,
    /// The scene: a scene file (a path that exists or ends in .toml) or a built-in scene's name
    /// (`raytty scenes` lists them). Default: the Cornell box.
    #[arg(long, global = true, value_name = "PATH|NAME")]
    scene: Option<String>,
}

/// The `--color` choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ColorChoice {
    /// Decide from NO_COLOR and COLORTERM.
    Auto,
    /// 24-bit colour.
    Truecolor,
    /// The xterm 256-colour palette.
    #[value(name = "256")]
    Ansi256,
    /// No colour escapes at all.
    Ascii,
}

/// The colour mode for `choice`, given whether NO_COLOR is set (and not empty) and COLORTERM.
fn resolve_color(choice: ColorChoice, no_color: bool, colorterm: Option<&str>) -> ColorMode {
    match choice {
        ColorChoice::Truecolor => ColorMode::TrueColor,
        ColorChoice::Ansi256 => ColorMode::Ansi256,
        ColorChoice::Ascii => ColorMode::Ascii,
        ColorChoice::Auto if no_color => ColorMode::Ascii,
        ColorChoice::Auto if matches!(colorterm, Some("truecolor" | "24bit")) => {
            ColorMode::TrueColor
        }
        ColorChoice::Auto => ColorMode::Ansi256,
    }
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render one frame to stdout or a file (text frames or images).
    Render(RenderArgs),
    /// Measure what each step of accuracy costs: time per frame against error from a cached
    /// path-traced reference (a Markdown table, or CSV; an SVG plot; the README's table).
    Bench(BenchArgs),
    /// List the built-in scenes with their triangle counts.
    Scenes,
}

/// Options of `raytty bench`.
#[derive(Args, Debug)]
struct BenchArgs {
    /// Image sizes in pixels, comma-separated (default 500x500,200x100).
    #[arg(long, value_name = "WxH,...", value_parser = parse_size, value_delimiter = ',')]
    sizes: Vec<(u32, u32)>,
    /// Timed runs per row, after a warm-up (default 5).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    runs: Option<u32>,
    /// GI rows go 1, 4, 16, … samples per pixel up to this (default 64).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    max_spp: Option<u32>,
    /// The reference's samples per pixel (default 1024).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    ref_spp: Option<u32>,
    /// The reference's maximum bounces (default 16).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    ref_bounces: Option<u32>,
    /// Print CSV instead of the Markdown table.
    #[arg(long)]
    csv: bool,
    /// Write the error-against-time plot (log axes) to PATH as SVG.
    #[arg(long, value_name = "PATH")]
    svg: Option<PathBuf>,
    /// Rewrite the table between <!-- bench:start --> and <!-- bench:end --> in PATH.
    #[arg(long, value_name = "PATH")]
    readme: Option<PathBuf>,
    /// Tiny sizes, 2 runs, a small reference: seconds, for tests.
    #[arg(long)]
    quick: bool,
}

/// Output formats of `raytty render`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Format {
    /// Truecolor half-blocks (24-bit SGR).
    Ansi,
    /// xterm 256-colour half-blocks.
    Ansi256,
    /// Plain ASCII luminance ramp, no escapes.
    Ascii,
    /// 8-bit PNG image (clamped linear values, no gamma).
    Png,
    /// Linear float PFM image.
    Pfm,
}

/// Options of `raytty render`.
#[derive(Args, Debug)]
struct RenderArgs {
    /// Frame size in terminal cells, COLSxROWS: COLS × 2·ROWS pixels (default 80x24 for text;
    /// images default to 500x500 pixels unless --size or --pixels is given).
    #[arg(long, value_name = "COLSxROWS", value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Image size in pixels, WxH (default 500x500 for png and pfm; overrides --size).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pixels: Option<(u32, u32)>,
    /// Output format (default: from the -o file's extension, .png or .pfm; else ansi, or
    /// ascii if NO_COLOR is set).
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Shading stage: flat, light, direct, shadows, indirect (the default) or gi.
    #[arg(long, value_parser = parse_stage, default_value = "indirect")]
    stage: Stage,
    /// Samples per pixel, 1 to 1024, spread over the pixel: smooth edges, and far less noise
    /// in the gi stage (one sample is noisy). Default: the scene's (1 for gi).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    samples: Option<u32>,
    /// Camera position and yaw in degrees, x,y,z,yaw (default: the scene's camera).
    #[arg(long, value_name = "X,Y,Z,YAW", value_parser = parse_camera, allow_hyphen_values = true)]
    camera: Option<[f32; 4]>,
    /// Light position x,y,z (default: the scene's first light).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    light: Option<Vec3>,
    /// Write to FILE instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

/// Most pixels `--pixels` may ask for: about 48 bytes each (float image, cached hits, 8-bit
/// copy, encoder buffers), so 64 Mpixel stays near 3 GiB.
const MAX_PIXELS: u64 = 64 * 1024 * 1024;

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || {
        format!(
            "'{s}' is not a size: expected WIDTHxHEIGHT with whole numbers from 1 to 65535, e.g. 80x24"
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > 65535 || h > 65535 {
        return Err(bad());
    }
    Ok((w, h))
}

fn parse_stage(s: &str) -> Result<Stage, String> {
    Stage::from_name(s).ok_or_else(|| {
        let names: Vec<_> = Stage::ALL.iter().map(|s| s.name()).collect();
        format!("'{s}' is not a stage: expected one of {}", names.join(", "))
    })
}

fn parse_floats<const N: usize>(s: &str, what: &str) -> Result<[f32; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!(
            "'{s}' is not {what}: expected {N} comma-separated numbers"
        ));
    }
    let mut out = [0.0f32; N];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p
            .trim()
            .parse()
            .map_err(|_| format!("'{p}' in '{s}' is not a number"))?;
        if !o.is_finite() || o.abs() > 1e6 {
            return Err(format!(
                "'{p}' in '{s}' is out of range: expected a finite number within ±1e6"
            ));
        }
    }
    Ok(out)
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    parse_floats::<3>(s, "a position x,y,z").map(Vec3::from)
}

fn parse_camera(s: &str) -> Result<[f32; 4], String> {
    parse_floats::<4>(s, "a camera x,y,z,yaw_degrees")
}

/// Parses the command line, runs it, and maps the outcome to an exit code.
pub fn main() -> ExitCode {
    #[allow(unused_mut)]
    let mut cmd = Cli::command();
    #[cfg(feature = "tui")]
    {
        cmd = cmd.after_long_help(crate::tui::keys::help_text());
    }
    let cli = Cli::from_arg_matches(&cmd.get_matches()).unwrap_or_else(|e| e.exit());
    let dumb = is_dumb(std::env::var("TERM").ok().as_deref());
    let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
    let color = resolve_color(
        cli.color,
        dumb || no_color,
        std::env::var("COLORTERM").ok().as_deref(),
    );
    let result = match cli.command {
        Some(Command::Render(args)) => {
            run_render(&args, cli.scene.as_deref(), no_color).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Scenes) => io::stdout()
            .write_all(crate::scene_arg::list().as_bytes())
            .map(|()| ExitCode::SUCCESS)
            .map_err(Into::into),
        Some(Command::Bench(a)) => run_bench(a, cli.scene.as_deref()).map(|()| ExitCode::SUCCESS),
        None => run_default(color, cli.scene.as_deref(), dumb),
    };
    match result {
        Ok(code) => code,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("raytty: {}", without_os_error(&format!("{e:#}")));
            ExitCode::from(if e.downcast_ref::<UsageError>().is_some() {
                2
            } else {
                1
            })
        }
    }
}

/// The exit status of a run ended by signal `sig`: 128 + N, as shells report it. The app's
/// forced exit after a signal (when its loop cannot return in time) uses this too.
#[cfg(feature = "tui")]
pub fn signal_status(sig: i32) -> u8 {
    (128 + sig).clamp(0, 255) as u8
}

/// The exit status of the app: 0 on quit, [`signal_status`] of the signal, and for a dropped
/// terminal that of SIGHUP (129), as if the hangup had been signalled.
#[cfg(feature = "tui")]
fn app_status(outcome: crate::tui::Outcome) -> ExitCode {
    use crate::tui::Outcome;
    match outcome {
        Outcome::Quit => ExitCode::SUCCESS,
        Outcome::Signal(sig) => ExitCode::from(signal_status(sig)),
        Outcome::Hangup => ExitCode::from(signal_status(libc::SIGHUP)),
    }
}

/// `raytty bench`: with no `--scene`, the accuracy price list of the Cornell box; with
/// `--scene`, what that scene costs (load and acceleration build, frame times, M rays/s).
fn run_bench(a: BenchArgs, scene: Option<&str>) -> Result<()> {
    if let Some(name) = scene {
        // These shape the accuracy bench only: refuse them rather than ignore them.
        let unused: Vec<&str> = [
            (a.csv, "--csv"),
            (a.svg.is_some(), "--svg"),
            (a.readme.is_some(), "--readme"),
            (a.max_spp.is_some(), "--max-spp"),
            (a.ref_spp.is_some(), "--ref-spp"),
            (a.ref_bounces.is_some(), "--ref-bounces"),
        ]
        .into_iter()
        .filter_map(|(given, flag)| given.then_some(flag))
        .collect();
        if !unused.is_empty() {
            bail!(UsageError(format!(
                "{} belong to the accuracy bench (no --scene); with --scene, bench times frames: --sizes, --runs, --quick",
                unused.join(", ")
            )));
        }
        let start = std::time::Instant::now();
        let scene = crate::scene_arg::load_scene(Some(name))?;
        let load = start.elapsed();
        let sizes = match (a.sizes.is_empty(), a.quick) {
            (false, _) => a.sizes,
            (true, true) => raytty::bench::BenchOptions::quick().sizes,
            (true, false) => vec![(200, 100), (500, 500)],
        };
        let runs = a.runs.unwrap_or(if a.quick { 2 } else { 5 });
        let report = raytty::scene_bench::bench_scene(&scene, &sizes, runs);
        let mut out = io::stdout().lock();
        writeln!(
            out,
            "Scene `{}` loaded in {:.0} ms (parse, generate, validate, build).\n",
            raytty::printable(name),
            load.as_secs_f64() * 1e3
        )?;
        out.write_all(report.to_markdown().as_bytes())?;
        return Ok(());
    }
    // The plot is written after the (long) run: a folder that does not exist fails now.
    if let Some(dir) = a.svg.as_deref().and_then(std::path::Path::parent)
        && !dir.as_os_str().is_empty()
        && !dir.is_dir()
    {
        bail!(UsageError(format!(
            "--svg {}: the folder {} does not exist",
            a.svg.as_deref().unwrap_or(dir).display(),
            dir.display()
        )));
    }
    let request = raytty::bench::BenchRequest {
        quick: a.quick,
        sizes: a.sizes,
        runs: a.runs,
        max_spp: a.max_spp,
        ref_spp: a.ref_spp,
        ref_bounces: a.ref_bounces,
        csv: a.csv,
        svg: a.svg,
        readme: a.readme,
        command: std::iter::once("raytty".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
    };
    raytty::bench::run_command(
        &raytty::cornell_box(),
        &request,
        &mut io::stdout().lock(),
        &mut io::stderr().lock(),
    )
    .map_err(|e| match e {
        raytty::bench::BenchError::Usage(m) => UsageError(m).into(),
        // The I/O error as the cause, said once (BenchError's own text repeats it).
        raytty::bench::BenchError::Io { what, error } => anyhow::Error::new(error).context(what),
    })
}

/// An error in what the user asked for (exit status 2).
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Whether `TERM` names a terminal that cannot move its cursor (`dumb`, as in Emacs' shell):
/// the app cannot draw there, and auto colour means none.
fn is_dumb(term: Option<&str>) -> bool {
    term == Some("dumb")
}

/// No command: the app on a terminal; otherwise (or on a dumb terminal) one frame to stdout,
/// as `raytty render` with its defaults would print in `color`.
fn run_default(color: ColorMode, scene: Option<&str>, dumb: bool) -> Result<ExitCode> {
    #[cfg(feature = "tui")]
    if io::stdout().is_terminal() {
        if !dumb {
            // A big scene takes seconds to generate and build: say so rather than show a
            // blank terminal, then erase the line before the app (or an error) takes over.
            let note = io::stderr().is_terminal();
            if note {
                eprint!(
                    "raytty: loading {}…",
                    raytty::printable(scene.unwrap_or("the Cornell box"))
                );
            }
            let loaded = crate::scene_arg::load_scene(scene);
            if note {
                eprint!("\r\x1b[2K");
            }
            return crate::tui::run(loaded?, color).map(app_status);
        }
        eprintln!("raytty: TERM=dumb cannot run the app (it moves the cursor): one frame follows");
    }
    #[cfg(not(feature = "tui"))]
    let _ = dumb;
    run_render(
        &RenderArgs {
            size: Some((80, 24)),
            pixels: None,
            format: Some(match color {
                ColorMode::TrueColor => Format::Ansi,
                ColorMode::Ansi256 => Format::Ansi256,
                ColorMode::Ascii => Format::Ascii,
            }),
            stage: Stage::Indirect,
            samples: None,
            camera: None,
            light: None,
            output: None,
        },
        scene,
        false,
    )?;
    Ok(ExitCode::SUCCESS)
}

/// `raytty render`; `no_color` (NO_COLOR is set) makes ascii the default text format.
fn run_render(args: &RenderArgs, scene: Option<&str>, no_color: bool) -> Result<()> {
    if let Some(ext) = args.output.as_deref().and_then(unwritable_image_extension) {
        bail!(UsageError(format!(
            "-o {}: raytty cannot write .{ext} images: use a .png or .pfm file name (or --format ascii|ansi|ansi256 for text)",
            args.output
                .as_deref()
                .unwrap_or_else(|| "".as_ref())
                .display()
        )));
    }
    let format = args
        .format
        .unwrap_or_else(|| match format_for(args.output.as_deref()) {
            Format::Ansi if no_color => Format::Ascii,
            f => f,
        });
    let image_format = matches!(format, Format::Png | Format::Pfm);
    if image_format && args.output.is_none() && io::stdout().is_terminal() {
        bail!(UsageError(format!(
            "--format {} writes binary data: give -o FILE or redirect stdout",
            format_name(format)
        )));
    }
    let (w, h) = match (args.pixels, args.size, image_format) {
        (Some(p), _, _) => p,
        (None, Some((cols, rows)), _) => (cols, rows * 2),
        (None, None, true) => (500, 500),
        (None, None, false) => (80, 48),
    };
    let pixels = w as u64 * h as u64;
    if pixels > MAX_PIXELS {
        let asked = match args.pixels {
            Some(_) => format!("--pixels {w}x{h} is"),
            None => format!("--size {}x{} is {w}x{h} =", w, h / 2),
        };
        bail!(UsageError(format!(
            "{asked} {pixels} pixels, about {} MiB of memory; the limit is {MAX_PIXELS} pixels (e.g. --pixels 8192x8192 or --size 8192x4096)",
            pixels * 48 / (1024 * 1024)
        )));
    }
    let scene = crate::scene_arg::load_scene(scene)?;
    let mut camera = scene.camera;
    if let Some([x, y, z, yaw]) = args.camera {
        camera.position = Vec3::new(x, y, z);
        camera.yaw = yaw.to_radians();
    }
    if args.light.is_some() && scene.lights.is_empty() {
        bail!(UsageError(
            "--light moves the scene's first light, and this scene has none: add a [[light]] to the scene file".into()
        ));
    }
    let lights = lights_with(&scene, args.light);
    let mut settings = args.stage.settings(scene.effects);
    if let Some(n) = args.samples {
        settings.effects.samples = n;
    }
    // The output file is created before the (maybe long) render, so a bad path fails at once.
    let mut out: Box<dyn Write> = match &args.output {
        Some(path) => Box::new(BufWriter::new(
            File::create(path).with_context(|| format!("cannot create {}", path.display()))?,
        )),
        None => Box::new(BufWriter::new(io::stdout().lock())),
    };
    let frame = render(&scene, &camera, &lights, &settings, w, h);
    let written = match format {
        Format::Png => frame.image.write_png(&mut out),
        Format::Pfm => frame.image.write_pfm(&mut out),
        Format::Ansi | Format::Ansi256 | Format::Ascii => {
            let mode = match format {
                Format::Ansi => ColorMode::TrueColor,
                Format::Ansi256 => ColorMode::Ansi256,
                _ => ColorMode::Ascii,
            };
            out.write_all(&encode_text(&CellGrid::from_image(&frame.image, mode)))
        }
    };
    written.and_then(|()| out.flush()).with_context(|| {
        format!(
            "cannot write to {}",
            args.output
                .as_ref()
                .map_or_else(|| "stdout".to_string(), |p| p.display().to_string())
        )
    })
}

/// `message` without the " (os error N)" that Rust's I/O errors end with: the words before it
/// say it all, and the number means nothing to a user.
fn without_os_error(message: &str) -> String {
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
fn format_for(output: Option<&std::path::Path>) -> Format {
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
fn unwritable_image_extension(path: &std::path::Path) -> Option<String> {
    const IMAGES: [&str; 12] = [
        "jpg", "jpeg", "gif", "bmp", "tif", "tiff", "webp", "avif", "heic", "exr", "hdr", "ppm",
    ];
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    IMAGES.contains(&ext.as_str()).then_some(ext)
}

/// A format's name as `--format` spells it.
fn format_name(format: Format) -> String {
    format
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// The scene's lights, with the first one moved to `light` if given.
fn lights_with(scene: &Scene, light: Option<Vec3>) -> Vec<PointLight> {
    let mut lights = scene.lights.clone();
    if let (Some(p), Some(first)) = (light, lights.first_mut()) {
        first.position = p;
    }
    lights
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_extension_picks_the_format() {
        use std::path::Path;
        assert_eq!(format_for(Some(Path::new("a.png"))), Format::Png);
        assert_eq!(format_for(Some(Path::new("dir/A.PFM"))), Format::Pfm);
        assert_eq!(format_for(Some(Path::new("frame.txt"))), Format::Ansi);
        assert_eq!(format_for(None), Format::Ansi);
        assert_eq!(
            unwritable_image_extension(Path::new("box.JPG")).as_deref(),
            Some("jpg")
        );
        assert_eq!(unwritable_image_extension(Path::new("box.png")), None);
        assert_eq!(unwritable_image_extension(Path::new("frame.txt")), None);
        assert_eq!(unwritable_image_extension(Path::new("frame")), None);
        assert_eq!(format_name(Format::Png), "png");
    }

    #[test]
    fn os_error_numbers_are_dropped_from_messages() {
        assert_eq!(
            without_os_error("cannot create x: No such file or directory (os error 2)"),
            "cannot create x: No such file or directory"
        );
        assert_eq!(without_os_error("a (os error 2); b (os error 28)"), "a; b");
        assert_eq!(without_os_error("kept (os error x)"), "kept (os error x)");
    }

    #[test]
    fn a_dumb_terminal_is_recognised() {
        assert!(is_dumb(Some("dumb")));
        assert!(!is_dumb(Some("xterm-256color")));
        assert!(!is_dumb(Some("")));
        assert!(!is_dumb(None));
    }

    #[test]
    fn auto_colour_follows_no_color_then_colorterm() {
        let auto = ColorChoice::Auto;
        assert_eq!(
            resolve_color(auto, true, Some("truecolor")),
            ColorMode::Ascii
        );
        assert_eq!(
            resolve_color(auto, false, Some("truecolor")),
            ColorMode::TrueColor
        );
        assert_eq!(
            resolve_color(auto, false, Some("24bit")),
            ColorMode::TrueColor
        );
        assert_eq!(resolve_color(auto, false, Some("yes")), ColorMode::Ansi256);
        assert_eq!(resolve_color(auto, false, None), ColorMode::Ansi256);
        assert_eq!(
            resolve_color(ColorChoice::Truecolor, true, None),
            ColorMode::TrueColor
        );
    }
}
