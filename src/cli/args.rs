//! The command line as clap types, and the parsers of its values.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use raytty::frame::CellMode;
use raytty::sampler::Sampler;
use raytty::scene::MAX_COORDINATE;
use raytty::shading::Estimator;
use raytty::simd::Isa;
use raytty::{ColorMode, Stage};

/// Renders the Cornell box (or another scene) by ray tracing, in the terminal.
///
/// With no command on a terminal, raytty runs the interactive app; when stdout is not a
/// terminal (or TERM is dumb) it prints one frame, as `raytty render` would. Frames are truecolor half-blocks:
/// each cell shows two pixels, so an 80×24 frame is 80×48 pixels; in a terminal that speaks
/// the kitty graphics protocol or sixel, the app draws real pixels (--graphics).
#[derive(Parser, Debug)]
#[command(name = "raytty", version, about, long_about)]
pub struct Cli {
    #[command(subcommand)]
    pub(super) command: Option<Command>,
    /// Colours of the app and of the frame printed with no command: auto (ascii if NO_COLOR is
    /// set, truecolor if COLORTERM is truecolor or 24bit, else 256), truecolor, 256 or ascii.
    /// ssh does not forward COLORTERM: pass --color truecolor (or press C) to get it back.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    pub(super) color: ColorChoice,
    /// Pixels a cell shows in the app: auto (half unless the terminal is known to draw the
    /// finer block glyphs itself: sextant in kitty, WezTerm and foot, octant in Ghostty 1.1 or
    /// later), half (1×2, `▀`), quadrant (2×2), sextant (2×3) or octant (2×4, Unicode 16). A
    /// font without the glyphs shows boxes: press B to cycle back.
    #[arg(long, value_enum, default_value_t = CellsChoice::Auto)]
    pub(super) cells: CellsChoice,
    /// Pixels in the app through a graphics protocol: auto (ask the terminal at start: kitty
    /// if it answers kitty's query, sixel if its device attributes list sixel and it tells
    /// its cell size; else text cells), kitty, sixel, or none (text cells, nothing asked).
    /// Inside tmux, kitty goes through passthrough (set allow-passthrough on). G toggles.
    #[arg(long, value_enum, default_value_t = GraphicsChoice::Auto)]
    pub(super) graphics: GraphicsChoice,
    /// The scene: a scene file (a path that exists or ends in .toml) or a built-in scene's name
    /// (`raytty scenes` lists them). Default: the Cornell box.
    #[arg(long, global = true, value_name = "PATH|NAME")]
    pub(super) scene: Option<String>,
    /// A model (.gltf, .glb, .obj, .ply, .stl) or scene file to open in the app, as
    /// --scene FILE does.
    #[arg(value_name = "FILE", conflicts_with = "scene")]
    pub(super) file: Option<String>,
    #[command(flatten)]
    pub(super) view: ViewArgs,
}

/// Where the camera looks from, for the app and every command (over the scene's camera; a
/// model file without one gets a camera framed on the model at a three-quarter view).
#[derive(Args, Debug, Default)]
pub(super) struct ViewArgs {
    /// Camera position x,y,z.
    #[arg(long, global = true, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(super) look_from: Option<Vec3>,
    /// The point the camera looks at, x,y,z.
    #[arg(long, global = true, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(super) look_at: Option<Vec3>,
    /// Up on screen, x,y,z (model files: +y; the built-in scenes: their own, -y).
    #[arg(long, global = true, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(super) up: Option<Vec3>,
    /// Vertical field of view in degrees, 1 to 170 (models: the file camera's, or 45; the
    /// built-in scenes: 2·atan(1/2) ≈ 53.13 across the shorter side).
    #[arg(long, global = true, value_name = "DEG")]
    pub(super) fov: Option<f32>,
    /// Which of a model file's cameras to look through, from 0 (default: the first, if any).
    #[arg(long, global = true, value_name = "N")]
    pub(super) camera_index: Option<usize>,
}

impl ViewArgs {
    /// The library's view.
    pub(super) fn view(&self) -> raytty::scene::model::View {
        raytty::scene::model::View {
            camera_index: self.camera_index,
            look_from: self.look_from,
            look_at: self.look_at,
            up: self.up,
            fov_degrees: self.fov,
        }
    }
}

/// The `--color` choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum ColorChoice {
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

/// The `--graphics` choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum GraphicsChoice {
    /// Ask the terminal.
    Auto,
    /// The kitty graphics protocol (kitty, WezTerm, Ghostty, Konsole).
    Kitty,
    /// Sixel (xterm -ti vt340, foot, WezTerm, mlterm, Windows Terminal).
    Sixel,
    /// Text cells only.
    None,
}

/// The `--cells` choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum CellsChoice {
    /// Decide from TERM, TERM_PROGRAM and the like.
    Auto,
    /// 1×2 pixels a cell (`▀`, in every font).
    Half,
    /// 2×2 pixels a cell (quadrant blocks).
    Quadrant,
    /// 2×3 pixels a cell (sextants, Unicode 13).
    Sextant,
    /// 2×4 pixels a cell (octants, Unicode 16).
    Octant,
}

/// What the terminal is known to be, from its environment variables.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct TermEnv<'a> {
    /// `TERM`.
    pub(super) term: Option<&'a str>,
    /// `TERM_PROGRAM`.
    pub(super) program: Option<&'a str>,
    /// `TERM_PROGRAM_VERSION`.
    pub(super) version: Option<&'a str>,
    /// `KITTY_WINDOW_ID` is set (kitty sets it; TERM may have been changed, e.g. over ssh).
    pub(super) kitty: bool,
}

/// The cell mode for `choice`. Auto picks half-blocks unless the terminal draws the finer
/// glyphs itself rather than from a font (which may lack them and show boxes instead):
/// - Ghostty 1.1 and later (`TERM_PROGRAM=ghostty`, its version in `TERM_PROGRAM_VERSION`):
///   its sprite font has the Unicode 16 octants: octant;
/// - kitty (`TERM=xterm-kitty` or `KITTY_WINDOW_ID`), WezTerm (`TERM_PROGRAM=WezTerm`) and
///   foot (`TERM=foot…`) draw the sextants themselves: sextant. foot draws octants from 1.20,
///   but no variable tells foot's version (it would take an XTVERSION query); kitty's and
///   WezTerm's releases with octants cannot be told from their environment either;
/// - anything else (xterm, VTE, tmux, screen, the Linux console, an unknown TERM): half.
pub(super) fn resolve_cells(choice: CellsChoice, env: TermEnv) -> CellMode {
    match choice {
        CellsChoice::Half => CellMode::Half,
        CellsChoice::Quadrant => CellMode::Quadrant,
        CellsChoice::Sextant => CellMode::Sextant,
        CellsChoice::Octant => CellMode::Octant,
        CellsChoice::Auto => {
            let term = env.term.unwrap_or("");
            // Inside tmux or screen, the outer terminal's variables may leak through but the
            // multiplexer redraws the cells in its own terminal: trust only TERM.
            if term.starts_with("tmux") || term.starts_with("screen") {
                return CellMode::Half;
            }
            let version = |v: Option<&str>| -> (u32, u32) {
                let mut parts = v.unwrap_or("").split(['.', '-']);
                let mut next = || parts.next().and_then(|p| p.parse().ok()).unwrap_or(0);
                (next(), next())
            };
            match env.program {
                Some("ghostty") if version(env.version) >= (1, 1) => CellMode::Octant,
                Some("ghostty" | "WezTerm") => CellMode::Sextant,
                _ if term == "xterm-kitty" || env.kitty => CellMode::Sextant,
                _ if term.starts_with("foot") => CellMode::Sextant,
                _ => CellMode::Half,
            }
        }
    }
}

/// The colour mode for `choice`, given whether NO_COLOR is set (and not empty) and COLORTERM.
pub(super) fn resolve_color(
    choice: ColorChoice,
    no_color: bool,
    colorterm: Option<&str>,
) -> ColorMode {
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
pub(super) enum Command {
    /// Render one frame to stdout or a file (text frames or images).
    Render(RenderArgs),
    /// Measure what each step of accuracy costs: time per frame against error from a cached
    /// path-traced reference (a Markdown table, or CSV; an SVG plot; the report file, docs/performance.md).
    Bench(BenchArgs),
    /// List the built-in scenes with their triangle counts.
    Scenes,
    /// Join the tiles of `raytty render --tile I/N` into the frame: byte for byte the image
    /// one render would write.
    Merge(MergeArgs),
}

/// Options of `raytty merge`.
#[derive(Args, Debug)]
pub(super) struct MergeArgs {
    /// The tiles (PFM files from `raytty render --tile I/N -o TILE.pfm`), in any order.
    #[arg(value_name = "TILE", required = true)]
    pub(super) tiles: Vec<PathBuf>,
    /// The frame: a .png (through the frame's tone map) or .pfm file.
    #[arg(short, long, value_name = "FILE")]
    pub(super) output: PathBuf,
    /// How radiance is shown in PNG: none or neutral (default: the tiles' own, their scene's).
    #[arg(long, value_name = "none|neutral", value_parser = parse_tonemap)]
    pub(super) tonemap: Option<raytty::image::ToneMap>,
}

/// Options of `raytty bench`.
#[derive(Args, Debug)]
pub(super) struct BenchArgs {
    /// Image sizes in pixels, comma-separated (default 500x500,200x100).
    #[arg(long, value_name = "WxH,...", value_parser = parse_size, value_delimiter = ',')]
    pub(super) sizes: Vec<(u32, u32)>,
    /// Timed runs per row, after a warm-up (default 5).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub(super) runs: Option<u32>,
    /// GI rows go 1, 4, 16, … samples per pixel up to this (default 64).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536), conflicts_with = "scene")]
    pub(super) max_spp: Option<u32>,
    /// The reference's samples per pixel (default 1024).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576), conflicts_with = "scene")]
    pub(super) ref_spp: Option<u32>,
    /// The reference's maximum bounces (default 16).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024), conflicts_with = "scene")]
    pub(super) ref_bounces: Option<u32>,
    /// Print CSV instead of the Markdown table.
    #[arg(long, conflicts_with = "scene")]
    pub(super) csv: bool,
    /// Draw the error-against-time chart (log axes) in the terminal, after the table.
    #[arg(long, conflicts_with = "scene")]
    pub(super) plot: bool,
    /// Write the error-against-time plot (log axes) to PATH as SVG.
    #[arg(long, value_name = "PATH", conflicts_with = "scene")]
    pub(super) svg: Option<PathBuf>,
    /// Write the report (the stamp, the tables, a link to the SVG) to PATH, e.g.
    /// docs/performance.md.
    #[arg(long, value_name = "PATH", conflicts_with_all = ["scene", "csv"])]
    pub(super) report: Option<PathBuf>,
    /// Tiny sizes, 2 runs, a small reference: seconds, for tests.
    #[arg(long)]
    pub(super) quick: bool,
}

/// Output formats of `raytty render`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum Format {
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
    /// The kitty graphics protocol: one image of --pixels WxH (zlib-compressed RGB).
    Kitty,
    /// Sixel: one image of --pixels WxH with a palette of up to 256 colours.
    Sixel,
}

/// An on/off switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum Switch {
    /// On.
    On,
    /// Off.
    Off,
}

/// Options of `raytty render`.
#[derive(Args, Debug)]
pub(super) struct RenderArgs {
    /// Frame size in terminal cells, COLSxROWS: COLS × 2·ROWS pixels (default 80x24 for text;
    /// images default to 500x500 pixels unless --size or --pixels is given).
    #[arg(long, value_name = "COLSxROWS", value_parser = parse_size)]
    pub(super) size: Option<(u32, u32)>,
    /// Image size in pixels, WxH (default 500x500 for png and pfm; overrides --size).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub(super) pixels: Option<(u32, u32)>,
    /// Output format (default: from the -o file's extension, .png or .pfm; else ansi, or
    /// ascii if NO_COLOR is set).
    #[arg(long, value_enum)]
    pub(super) format: Option<Format>,
    /// The text format by colours, as the app's --color: auto, truecolor (ansi), 256 (ansi256)
    /// or ascii. For text frames only.
    #[arg(long, value_enum, conflicts_with = "format")]
    pub(super) color: Option<ColorChoice>,
    /// Pixels a text cell shows: half (the default: 1×2, `▀`), quadrant (2×2), sextant (2×3),
    /// octant (2×4, Unicode 16), or auto (as the app decides, from TERM and TERM_PROGRAM).
    /// --size COLSxROWS is then rendered at COLS·w × ROWS·h pixels. For ansi and ansi256.
    #[arg(long, value_enum)]
    pub(super) cells: Option<CellsChoice>,
    /// Shading stage: flat, light, direct, shadows, indirect (the default) or gi.
    #[arg(long, value_parser = parse_stage, default_value = "indirect")]
    pub(super) stage: Stage,
    /// Samples per pixel, 1 to 1024, spread over the pixel: smooth edges, and far less noise
    /// in the gi stage (one sample is noisy). Default: the scene's (1 for gi).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(super) samples: Option<u32>,
    /// Where path-traced samples' numbers come from: sobol (Owen-scrambled Sobol points, less
    /// noise at equal samples) or independent (random numbers). Default: the scene's (sobol).
    #[arg(long, value_parser = parse_sampler)]
    pub(super) sampler: Option<Sampler>,
    /// Denoise the gi stage's indirect light (on, the default) or give the raw, unbiased
    /// path-traced estimate (off). Other stages have no noise to remove.
    #[arg(long, value_enum, default_value_t = Switch::On)]
    pub(super) denoise: Switch,
    /// Camera position and yaw in degrees, x,y,z,yaw (default: the scene's camera).
    #[arg(long, value_name = "X,Y,Z,YAW", value_parser = parse_camera, allow_hyphen_values = true)]
    pub(super) camera: Option<[f32; 4]>,
    /// Light position x,y,z (default: the scene's first light).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(super) light: Option<Vec3>,
    /// How radiance is shown in PNG and text: none (clamped, the built-in scenes' look) or
    /// neutral (Khronos PBR Neutral and sRGB, the default for models). PFM stays linear.
    #[arg(long, value_name = "none|neutral", value_parser = parse_tonemap)]
    pub(super) tonemap: Option<raytty::image::ToneMap>,
    /// Write to FILE instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub(super) output: Option<PathBuf>,
    /// Render only tile I of N (I from 0 to N-1): a band of whole rows of the frame, written
    /// as PFM for `raytty merge`, which joins the N tiles into exactly the frame one render
    /// gives. Not with the denoiser (--denoise off): it reads across the tiles' edges.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    pub(super) tile: Option<(u32, u32)>,
    /// After the frame, print one line to stderr: render time in ms, samples per pixel, rays
    /// by kind, M rays/s and the SIMD path; --stats=json prints it as one JSON object (keys ms,
    /// spp, rays, mrays_per_s, simd, threads).
    #[arg(long, value_name = "FORMAT", num_args = 0..=1, require_equals = true, default_missing_value = "text")]
    pub(super) stats: Option<StatsFormat>,
    /// The SIMD path: portable, sse2, avx2 or avx512 (default: the widest this CPU has). Every
    /// path gives the same frame; this is for checking that.
    #[arg(long, value_name = "PATH", value_parser = parse_simd, hide = true)]
    pub(super) simd: Option<Isa>,
    /// How physically based scenes gather light at surfaces that are not specular: auto (what
    /// the scene calls for), light, bsdf or mis. For measuring the estimators.
    #[arg(long, value_name = "E", value_parser = parse_estimator, hide = true)]
    pub(super) estimator: Option<Estimator>,
}

pub(super) fn parse_estimator(s: &str) -> Result<Estimator, String> {
    Estimator::ALL
        .into_iter()
        .find(|e| e.name() == s)
        .ok_or_else(|| format!("'{s}' is not an estimator: expected auto, light, bsdf or mis"))
}

/// How `render --stats` prints the frame's cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(super) enum StatsFormat {
    /// One line for people.
    Text,
    /// One JSON object.
    Json,
}

pub(super) fn parse_simd(s: &str) -> Result<Isa, String> {
    Isa::ALL
        .into_iter()
        .find(|isa| isa.name() == s)
        .ok_or_else(|| format!("'{s}' is not a SIMD path: expected portable, sse2, avx2 or avx512"))
}

pub(super) fn parse_size(s: &str) -> Result<(u32, u32), String> {
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

pub(super) fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let bad =
        || format!("'{s}' is not a tile: expected I/N, I from 0 to N-1 and N from 1, e.g. 0/8");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let i: u32 = i.trim().parse().map_err(|_| bad())?;
    let n: u32 = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

pub(super) fn parse_sampler(s: &str) -> Result<Sampler, String> {
    Sampler::from_name(s).ok_or_else(|| {
        let names: Vec<_> = Sampler::ALL.iter().map(|s| s.name()).collect();
        format!("'{s}' is not a sampler: expected {}", names.join(" or "))
    })
}

pub(super) fn parse_tonemap(s: &str) -> Result<raytty::image::ToneMap, String> {
    raytty::image::ToneMap::ALL
        .into_iter()
        .find(|t| t.name() == s)
        .ok_or_else(|| format!("'{s}' is not a tone map: expected none or neutral"))
}

pub(super) fn parse_stage(s: &str) -> Result<Stage, String> {
    Stage::from_name(s).ok_or_else(|| {
        let names: Vec<_> = Stage::ALL.iter().map(|s| s.name()).collect();
        format!("'{s}' is not a stage: expected one of {}", names.join(", "))
    })
}

pub(super) fn parse_floats<const N: usize>(s: &str, what: &str) -> Result<[f32; N], String> {
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
        if !o.is_finite() || o.abs() > MAX_COORDINATE {
            return Err(format!(
                "'{p}' in '{s}' is out of range: expected a finite number within ±{MAX_COORDINATE:e}"
            ));
        }
    }
    Ok(out)
}

pub(super) fn parse_vec3(s: &str) -> Result<Vec3, String> {
    parse_floats::<3>(s, "a position x,y,z").map(Vec3::from)
}

pub(super) fn parse_camera(s: &str) -> Result<[f32; 4], String> {
    parse_floats::<4>(s, "a camera x,y,z,yaw_degrees")
}
