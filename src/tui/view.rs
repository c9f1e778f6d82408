//! The view: brings the image up to date with the [`App`] (one render, or one more progressive
//! pass in the GI stage) and encodes what the terminal must change, as one synchronized-output
//! write. Pure apart from the clock: no terminal I/O.

use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::bench::timing::ms;
use raytty::denoise::{Guides, denoise_on};
use raytty::frame::{CellMode, DiffLimits, Precision, UNLIKE, distance, encode_diff_within};
use raytty::{
    Camera, CellGrid, ColorMode, FrameStats, HitCache, Image, Options, Output, Stage, printable,
};

use super::app::App;
use super::detect::Protocol;
use super::link::describe;
use super::overlay::{blank, draw_help, put_line, put_text, text_width};
use super::pixels::{self, Costs, SETTLE};

/// Smallest terminal drawn: below this a short message replaces the frame.
pub const MIN_COLS: u16 = 10;
/// Smallest terminal height drawn (two image rows and the status line).
pub const MIN_ROWS: u16 = 3;
/// Progressive refinement in the GI stage stops after this many passes (one sample per pixel
/// each); the app is then idle.
pub const GI_MAX_PASSES: u32 = 256;

/// After a move of the light alone, the GI samples gathered before it keep at most this much
/// weight (in samples) against the new ones: the direct light is exact and recomputed at once,
/// and the indirect light, which changes slowly with the light, is not thrown away with it.
/// Measured at 200×100 after 16 passes, the light moved 1 or 4 key presses (0.1 each), the
/// last frame denoised against 256 raw passes (`cargo run --release --example denoise_eval --
/// light`): RMSE 0.0219 / 0.0278 starting afresh, 0.0171 / 0.0244 keeping 2 samples, 0.0168 /
/// 0.0268 keeping 4, 0.0163 / 0.0316 keeping 16 (the lag starts to show). A camera move
/// restarts from nothing (no reprojection).
pub const LIGHT_MOVE_HISTORY: u32 = 2;

/// The too-small message, line by line, each from its longest wording to its shortest: the
/// longest that fits the terminal's width is shown.
const TOO_SMALL: [&[&str]; 2] = [
    &[
        "raytty: terminal too small",
        "terminal too small",
        "too small",
        "small",
    ],
    &["Esc quits", "Esc:quit", "Esc"],
];

/// DEC private mode 2026: the terminal shows the frame only when it is complete.
const SYNC_BEGIN: &[u8] = b"\x1b[?2026h";
const SYNC_END: &[u8] = b"\x1b[?2026l";

/// What the last frame cost, for the status line.
#[derive(Clone, Copy, Debug, Default)]
pub struct DrawStats {
    /// The last render's stats (rays by kind, time).
    pub render: FrameStats,
    /// Time spent turning the image into bytes.
    pub encode: Duration,
    /// Bytes of the last frame written.
    pub bytes: usize,
}

/// The terminal's picture of the app and the buffers behind it.
#[derive(Debug)]
pub struct Screen {
    cache: HitCache,
    /// The app generation the image shows, once rendered.
    generation: Option<u64>,
    /// The generation the last draw showed.
    drawn: Option<u64>,
    /// The GI passes so far, as the denoiser's guides (means over the passes).
    guides: Option<Guides>,
    passes: u32,
    /// What the GI guides were rendered for: camera and size.
    gi_view: Option<(Camera, (u32, u32))>,
    /// Whether the image shows the GI passes denoised (`None`: not GI, or not yet shown).
    shows_denoised: Option<bool>,
    /// Render and filter time spent on the current GI image since it restarted.
    spent: Duration,
    /// Estimated RMSE of the raw GI estimate and of the image shown (from the variance).
    error: (f32, f32),
    image: Image,
    /// What the terminal shows now.
    shown: Option<CellGrid>,
    /// The row the next frame's diff begins with (after a frame the budget cut short).
    next_row: usize,
    /// The terminal shows an approximation of the latest frame: the next draw refines it.
    approximate: bool,
    /// The last frame's costs.
    pub stats: DrawStats,
    /// Pixel modes: one rendered pixel for `scale × scale` screen pixels (1 in text modes).
    scale: u32,
    /// When the image's inputs last changed (pixel modes: a reduced frame is refined to full
    /// resolution [`SETTLE`] after).
    changed_at: Instant,
    /// The pixel protocol the screen shows an image in, if it does.
    showing: Option<Protocol>,
    /// The image on screen is the current one (pixel modes).
    image_sent: bool,
    /// Pixel modes: what frames cost per rendered pixel.
    costs: Costs,
    /// Pixel modes: how close to the image the next image sent is (near while moving on a
    /// slow link, and until [`pixels::exact_settle`]).
    precision: Precision,
    /// The link as the writer measures it: each frame is fitted to its budget.
    pub link: LinkView,
}

/// What the view needs of the link: the next frame's byte budget and the rate to show.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinkView {
    /// Bytes the next frame may take (`None`: no limit, every frame exact).
    pub budget: Option<usize>,
    /// The measured drain rate in bytes per second, if measured.
    pub rate: Option<f64>,
}

/// Tolerances tried for a frame over its budget, smallest first (levels per channel).
const TOLERANCES: [u8; 5] = [0, 8, 16, 32, 64];
/// What a cell sent within each of [`TOLERANCES`] costs, in bytes, to guess from a count of
/// cells which tolerance fits a budget: a light move 1 to 4 presses behind, at 120×40 and
/// 200×50, cost 14-18 B a cell exact and 6-8, 5-6, 4-6, 3-5 within 8, 16, 32, 64 levels
/// (coarser colours are shared by more cells).
const CELL_BYTES: [usize; 5] = [18, 7, 6, 5, 4];
/// A tolerance is taken if its cells fit in this many frames' budgets (exact: in one). A frame
/// the budget cuts short is continued by the next at no extra cost, whereas a coarser
/// tolerance sends most cells twice (coarse, then within 8). 120×40 W held over 1 Mbit/s
/// (`examples/slow_link`), within 8 levels after the release: 1 frame 0.14-0.16 s, 4 frames
/// 0.09-0.10 s, any number (always 8) 0.10 s but 200×50 0.15-0.24 s (4: 0.16-0.17 s).
const APPROXIMATE_FRAMES: usize = 4;
/// Once the app stops changing, the first refinement goes straight to this tolerance (a
/// ladder of coarser ones would send most cells again at each rung), then to exact.
const REFINE_TOLERANCE: u8 = 8;

/// The image size for a terminal of `cols × rows` cells (the last row is the status line) in
/// cells of `cells` ([`CellMode::render_pixels`]), or `None` if it is too small.
pub fn image_size(size: (u16, u16), cells: CellMode) -> Option<(u32, u32)> {
    let (cols, rows) = size;
    let (w, h) = cells.render_pixels();
    (cols >= MIN_COLS && rows >= MIN_ROWS).then(|| (w * cols as u32, h * (rows as u32 - 1)))
}

impl Screen {
    /// A screen that has drawn nothing yet.
    pub fn new() -> Screen {
        Screen {
            cache: HitCache::new(),
            generation: None,
            drawn: None,
            guides: None,
            passes: 0,
            gi_view: None,
            shows_denoised: None,
            spent: Duration::ZERO,
            error: (0.0, 0.0),
            image: Image::new(0, 0),
            shown: None,
            next_row: 0,
            approximate: false,
            stats: DrawStats::default(),
            link: LinkView::default(),
            scale: 1,
            changed_at: Instant::now(),
            showing: None,
            image_sent: false,
            costs: Costs::default(),
            precision: Precision::Exact,
        }
    }

    /// Forgets what the terminal shows, so that the next draw repaints every cell (after the
    /// terminal was handed to another program, e.g. while suspended).
    pub fn forget_shown(&mut self) {
        self.shown = None;
        self.image_sent = false;
    }

    /// Passes accumulated for the current image.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Whether [`Screen::render`] has work to do: the app changed, GI is still refining, or
    /// the denoiser was switched.
    pub fn needs_render(&self, app: &App) -> bool {
        self.render_size(app).is_some()
            && (self.generation != Some(app.generation)
                || self.upgrade_in(app) == Some(Duration::ZERO)
                || self.render_size(app) != Some((self.image.width, self.image.height))
                || (app.stage == Stage::Gi
                    && (self.passes < GI_MAX_PASSES || self.shows_denoised != Some(app.denoise))))
    }

    /// Pixel modes: how long until the reduced image on screen is rendered again at full
    /// resolution, or the near one sent exactly (zero: now), if it is either. The event loop
    /// waits at most this long.
    pub fn upgrade_in(&self, app: &App) -> Option<Duration> {
        let p = app.graphics()?;
        let settle = if self.scale > 1 {
            SETTLE
        } else if self.precision == Precision::Near {
            let full = pixels::full_size(p, app.size, app.cell_pixels, app.sixel_max);
            pixels::exact_settle(full, self.costs, self.link.rate)
        } else {
            return None;
        };
        Some(settle.saturating_sub(self.changed_at.elapsed()))
    }

    /// The size the image is rendered at: the cell mode's pixels a cell, or in a pixel mode
    /// the terminal's pixels over the current scale; `None` if the terminal is too small.
    fn render_size(&self, app: &App) -> Option<(u32, u32)> {
        let size = image_size(app.size, app.cell_mode())?;
        match app.graphics() {
            None => Some(size),
            Some(p) => Some(pixels::scaled(
                pixels::full_size(p, app.size, app.cell_pixels, app.sixel_max),
                self.scale,
            )),
        }
    }

    /// Picks the scale and precision of the next frame: a change of the image's inputs
    /// renders at the moving scale (see [`pixels::moving_scale`]), [`SETTLE`] after the last
    /// change at full resolution, and on a slow link kitty's frames are near until
    /// [`pixels::exact_settle`]. Whether only the precision changed (the image is the same:
    /// it is sent again, not rendered again).
    fn pick_scale(&mut self, app: &App) -> bool {
        let Some(p) = app.graphics() else {
            self.scale = 1;
            self.precision = Precision::Exact;
            return false;
        };
        if self.generation != Some(app.generation) {
            self.changed_at = Instant::now();
            let full = pixels::full_size(p, app.size, app.cell_pixels, app.sixel_max);
            self.scale = pixels::moving_scale(full, self.costs, self.link.budget);
            self.precision = if p == Protocol::Kitty && self.link.budget.is_some() {
                Precision::Near
            } else {
                Precision::Exact
            };
        } else if self.upgrade_in(app) == Some(Duration::ZERO) {
            if self.scale > 1 {
                self.scale = 1;
            } else {
                self.precision = Precision::Exact;
                return self.render_size(app) == Some((self.image.width, self.image.height));
            }
        }
        false
    }

    /// Renders one frame, or one more progressive pass in the GI stage (which restarts when
    /// the app's generation changes, but for a light move, which keeps a bounded history: see
    /// [`LIGHT_MOVE_HISTORY`]). Does nothing if the terminal is too small.
    pub fn render(&mut self, app: &App) {
        let resend = self.pick_scale(app);
        let Some((w, h)) = self.render_size(app) else {
            return;
        };
        self.image_sent = false;
        if resend {
            return;
        }
        let mut history = u32::MAX;
        if (w, h) != (self.image.width, self.image.height)
            && self.generation == Some(app.generation)
        {
            // The same view at another resolution (refined, or pixels toggled): GI starts
            // again at the new size.
            self.passes = 0;
            self.spent = Duration::ZERO;
            self.guides = None;
        }
        if self.generation != Some(app.generation) {
            self.generation = Some(app.generation);
            self.passes = 0;
            self.spent = Duration::ZERO;
            let same_view = self
                .gi_view
                .as_ref()
                .is_some_and(|(c, size)| *c == app.camera && *size == (w, h));
            if app.stage == Stage::Gi && same_view {
                history = LIGHT_MOVE_HISTORY;
            } else {
                self.guides = None;
            }
        }
        let mut settings = app.stage.settings(app.scene.effects());
        settings.frame = self.passes;
        let options = Options {
            width: w,
            height: h,
            settings: Some(settings),
            camera: Some(app.camera),
            lights: Some(&app.lights),
            ..Options::default()
        };
        if app.stage != Stage::Gi {
            let frame = self.cache.render(&app.scene, &options);
            self.stats.render = frame.stats;
            self.measure_render(frame.stats.elapsed, w, h);
            self.passes = GI_MAX_PASSES;
            self.guides = None;
            self.gi_view = None;
            self.shows_denoised = None;
            self.image = frame.image;
            return;
        }
        if self.passes < GI_MAX_PASSES {
            let output = Output::Guides;
            let frame = self
                .cache
                .render(&app.scene, &Options { output, ..options });
            self.stats.render = frame.stats;
            self.measure_render(frame.stats.elapsed, w, h);
            self.spent += frame.stats.elapsed;
            if let Some(new) = frame.guides {
                match &mut self.guides {
                    Some(g) if history != u32::MAX || self.passes > 0 => {
                        g.accumulate(&new, history)
                    }
                    _ => self.guides = Some(new),
                }
            }
            self.passes += 1;
            self.gi_view = Some((app.camera, (w, h)));
        }
        let Some(g) = &self.guides else { return };
        let start = Instant::now();
        let d = denoise_on(app.scene.isa(), g);
        if app.denoise {
            self.spent += start.elapsed();
            self.error = (d.raw_error, d.error);
            self.image = d.image;
        } else {
            self.error = (d.raw_error, d.raw_error);
            self.image = Image {
                width: g.width,
                height: g.height,
                pixels: g.raw(),
            };
        }
        self.shows_denoised = Some(app.denoise);
    }

    /// Pixel modes learn a render's time per pixel.
    fn measure_render(&mut self, elapsed: Duration, w: u32, h: u32) {
        self.costs.seconds = Some(elapsed.as_secs_f64() / (f64::from(w) * f64::from(h)).max(1.0));
    }

    /// Whether the terminal shows only an approximation of the latest frame (the link's budget
    /// left some cells within a tolerance, or unsent): drawing again refines it.
    pub fn approximate(&self) -> bool {
        self.approximate
    }

    /// The bytes that bring the terminal up to date (empty if nothing visible changed),
    /// wrapped in synchronized output, within the link's budget: cells that differ by at most
    /// the smallest tolerance that fits are left for a later draw (see [`Screen::approximate`]).
    /// Remembers what the terminal now shows.
    pub fn draw(&mut self, app: &App) -> Vec<u8> {
        if let Some(p) = app.graphics()
            && self.render_size(app) == Some((self.image.width, self.image.height))
        {
            return self.draw_pixels(app, p);
        }
        let start = Instant::now();
        let mut out = SYNC_BEGIN.to_vec();
        if self.showing.take().is_some() {
            // Text over an image: the image goes, and every cell is drawn again.
            self.hide_image(app, &mut out);
        }
        let (cols, rows) = (app.size.0 as usize, app.size.1 as usize);
        let grid = if image_size(app.size, app.cell_mode())
            != Some((self.image.width, self.image.height))
        {
            let mut g = blank(cols, rows, app.color);
            for (i, variants) in TOO_SMALL.iter().enumerate() {
                put_text(&mut g, 0, i, longest_that_fits(variants, cols), app.color);
            }
            g
        } else {
            let shown = app.scene.tone_map().image(&self.image);
            let mut g = CellGrid::from_image_in(&shown, app.color, app.cell_mode());
            let status = blank(cols, 1, app.color);
            g.rows += 1;
            g.cells.extend(status.cells);
            if app.help {
                draw_help(&mut g, app.color);
            }
            g
        };
        // The same image as the last draw's (its status line aside): this draw refines it.
        let refining = self.drawn == self.generation && self.passes >= GI_MAX_PASSES;
        self.drawn = self.generation;
        let limits = match self.link.budget {
            None => DiffLimits::EXACT,
            Some(max_bytes) => DiffLimits {
                tolerance: tolerance_for(self.shown.as_ref(), &grid, max_bytes, refining),
                max_bytes,
                first_row: self.next_row,
            },
        };
        let mut grid = grid;
        if image_size(app.size, app.cell_mode()) == Some((self.image.width, self.image.height)) {
            self.approximate = limits.tolerance > 0;
            put_line(&mut grid, rows - 1, &self.status(app), app.color);
        }
        // Encoded straight after the begin marker: the frame is written into place, not copied.
        let outcome = encode_diff_within(&mut self.shown, &grid, 0, limits, &mut out);
        self.next_row = outcome.next_row;
        self.approximate = !outcome.complete || outcome.max_error > 0;
        self.finish(out, start)
    }

    /// Removes the image from the screen (kitty: deleted; sixel: the screen cleared) and
    /// forgets the text cells, so the next text frame draws every cell.
    fn hide_image(&mut self, app: &App, out: &mut Vec<u8>) {
        if app.protocol == Some(Protocol::Kitty) {
            out.extend_from_slice(&super::tty::kitty_delete(app.tmux));
        }
        out.extend_from_slice(b"\x1b[2J");
        self.shown = None;
        self.image_sent = false;
    }

    /// A pixel-mode frame: the image if it is not on screen yet (whole: kitty replaces the
    /// last one in place, sixel paints over it), then the status line as text.
    fn draw_pixels(&mut self, app: &App, p: Protocol) -> Vec<u8> {
        let start = Instant::now();
        let mut out = SYNC_BEGIN.to_vec();
        if self.showing != Some(p) {
            // From text (or the other protocol): the screen starts blank.
            if self.showing.is_some() {
                self.hide_image(app, &mut out);
            }
            out.extend_from_slice(b"\x1b[0m\x1b[2J");
            self.shown = None;
            self.image_sent = false;
        }
        self.showing = Some(p);
        self.drawn = self.generation;
        self.approximate = false;
        if !self.image_sent {
            let shown = app.scene.tone_map().image(&self.image);
            let (w, h) = (self.image.width, self.image.height);
            let full = pixels::full_size(p, app.size, app.cell_pixels, app.sixel_max);
            let cells = (u32::from(app.size.0), u32::from(app.size.1) - 1);
            let before = out.len();
            let precision = self.precision;
            let rgb = shown.to_rgb8();
            pixels::frame_bytes(p, &rgb, (w, h), full, cells, precision, app.tmux, &mut out);
            let per_pixel = Some((out.len() - before) as f64 / (f64::from(w) * f64::from(h)));
            match precision {
                Precision::Exact => self.costs.bytes = per_pixel,
                Precision::Near => self.costs.near_bytes = per_pixel,
            }
            self.image_sent = true;
        }
        let (cols, rows) = (app.size.0 as usize, app.size.1 as usize);
        let mut status = blank(cols, 1, app.color);
        put_line(&mut status, 0, &self.status(app), app.color);
        encode_diff_within(
            &mut self.shown,
            &status,
            rows - 1,
            DiffLimits::EXACT,
            &mut out,
        );
        self.finish(out, start)
    }

    /// A frame's bytes closed by the end of synchronized output, its encode time and size
    /// counted; nothing at all when nothing changed (`out` holds only the begin marker).
    fn finish(&mut self, mut out: Vec<u8>, start: Instant) -> Vec<u8> {
        if out.len() == SYNC_BEGIN.len() {
            return Vec::new();
        }
        out.extend_from_slice(SYNC_END);
        self.stats.encode = start.elapsed();
        self.stats.bytes = out.len();
        out
    }

    /// The status line: scene (first, so a narrow terminal still shows it), stage, camera,
    /// light, costs of the last frame, colour mode, the help key. Fields that do not fit the
    /// terminal's width are left out, least useful first (see [`fit_status`]). The scene's
    /// name comes from a file: its control characters are removed.
    fn status(&self, app: &App) -> String {
        let key = Stage::ALL.iter().position(|&s| s == app.stage).unwrap_or(0) + 1;
        let gi = app.stage == Stage::Gi;
        let spp = if gi {
            format!(" {}/{GI_MAX_PASSES}spp", self.passes)
        } else {
            String::new()
        };
        // The price, live: the time spent on this image and its error estimated from the
        // per-pixel variance (denoised: the noise left after the filter, then the raw one's).
        let (raw, shown) = self.error;
        // The physically based path's variance estimate covers only what the denoiser filters
        // (the light of diffuse first hits), not the light of mirror, metal and glass ones: its
        // frames show the time alone.
        let unguided = gi && raytty::shading::PathEffects::of(&app.scene).any();
        let price = if !gi {
            String::new()
        } else if unguided {
            format!("{:.2}s", self.spent.as_secs_f64())
        } else if app.denoise {
            format!("{:.2}s ±{shown:.4} raw ±{raw:.3}", self.spent.as_secs_f64())
        } else {
            format!("{:.2}s ±{raw:.4}", self.spent.as_secs_f64())
        };
        let filter = match (gi, app.denoise) {
            (false, _) => String::new(),
            (true, true) => "N:denoised".to_string(),
            (true, false) => "N:raw".to_string(),
        };
        let mut light = app.light().map_or_else(|| "none".into(), xyz);
        if app.scene.lights_are_default() {
            // The file has no light: these are the default rig's.
            light += " (default)";
        }
        // (text, rank): rank 0 is always shown, then the lowest ranks first while they fit.
        let mut fields = vec![
            (printable(app.scene.name()), 0),
            (format!("{key}:{}{spp}", app.stage.name()), 0),
            (price, 1),
            (filter, 2),
            (
                format!(
                    "cam {} {}°",
                    xyz(app.camera.position),
                    fixed(app.camera.yaw.to_degrees(), 0)
                ),
                4,
            ),
            (format!("light {light}"), 5),
            (format!("render {:.1}ms", ms(self.stats.render.elapsed)), 3),
            (format!("encode {:.1}ms", ms(self.stats.encode)), 9),
            (format!("{}B", self.stats.bytes), 8),
            (format!("link {}", describe(self.link.rate)), 7),
            (
                // Text cells left within a tolerance, or a pixel frame sent near.
                if self.approximate || (self.showing.is_some() && self.precision == Precision::Near)
                {
                    "approximate".into()
                } else {
                    String::new()
                },
                1,
            ),
            match app.graphics() {
                // The protocol and the resolution rendered (reduced while moving).
                Some(p) => (
                    format!("{} {}x{}", p.name(), self.image.width, self.image.height),
                    1,
                ),
                // The cell mode when it is not the default half-blocks (ASCII has none).
                None => (
                    match (app.color, app.cells) {
                        (ColorMode::Ascii, _) | (_, CellMode::Half) => app.color.name().to_string(),
                        _ => format!("{} {}", app.color.name(), app.cells.name()),
                    },
                    6,
                ),
            },
            ("H:help".to_string(), 2),
        ];
        fields.retain(|(t, _)| !t.is_empty());
        fit_status(&fields, app.size.0 as usize)
    }
}

/// The smallest of [`TOLERANCES`] whose cells to send (those of `next` further than it from
/// `shown`) fit in `max_bytes` at [`CELL_BYTES`] each (the approximate ones in
/// [`APPROXIMATE_FRAMES`] frames: the budget cuts the frame short), else the largest; when
/// `refining` (`next` is the frame the last draw approximated), at most [`REFINE_TOLERANCE`].
/// Exact when the screen is unknown (a first frame or a new size).
fn tolerance_for(
    shown: Option<&CellGrid>,
    next: &CellGrid,
    max_bytes: usize,
    refining: bool,
) -> u8 {
    let Some(shown) = shown.filter(|s| s.cols == next.cols && s.rows == next.rows) else {
        return 0;
    };
    // Image cells further than each tolerance (text is sent whatever the tolerance).
    let mut beyond = [0usize; TOLERANCES.len()];
    for (a, b) in shown.cells.iter().zip(&next.cells) {
        let d = distance(a, b);
        if d == UNLIKE {
            continue;
        }
        for (n, &t) in beyond.iter_mut().zip(&TOLERANCES) {
            *n += usize::from(d > u16::from(t));
        }
    }
    let fits = |i: usize| {
        let frames = if i == 0 { 1 } else { APPROXIMATE_FRAMES };
        beyond[i] * CELL_BYTES[i] <= max_bytes * frames
    };
    let mut i = (0..TOLERANCES.len())
        .find(|&i| fits(i))
        .unwrap_or(TOLERANCES.len() - 1);
    if refining {
        i = i.min(
            TOLERANCES
                .iter()
                .position(|&t| t == REFINE_TOLERANCE)
                .unwrap_or(i),
        );
    }
    // Always progress: a tolerance that sends nothing while the screen is not exact gives way
    // to the largest smaller one that sends something (the budget cuts it short).
    let i = (0..=i).rev().find(|&j| beyond[j] > 0).unwrap_or(i);
    TOLERANCES[i]
}

/// Joins `fields` (text, rank) into a status line of at most `width` columns where
/// possible: fields are taken by rank, lowest first, each one only if the line still fits
/// with it; the fields kept stay in their order. Rank-0 fields are always kept (the line is
/// clipped when drawn instead).
fn fit_status(fields: &[(String, u8)], width: usize) -> String {
    let line = |keep: &[bool]| -> String {
        let kept: Vec<&str> = fields
            .iter()
            .zip(keep)
            .filter(|((t, _), k)| **k && !t.is_empty())
            .map(|((t, _), _)| t.as_str())
            .collect();
        format!(" {}", kept.join("  "))
    };
    let mut keep: Vec<bool> = fields.iter().map(|(_, r)| *r == 0).collect();
    let mut by_rank: Vec<usize> = (0..fields.len()).filter(|&i| fields[i].1 > 0).collect();
    by_rank.sort_by_key(|&i| fields[i].1);
    for i in by_rank {
        keep[i] = true;
        if text_width(&line(&keep)) > width {
            keep[i] = false;
        }
    }
    line(&keep)
}

/// The first of `variants` (longest first) that fits in `width` columns, else the last.
fn longest_that_fits<'a>(variants: &[&'a str], width: usize) -> &'a str {
    variants
        .iter()
        .find(|v| text_width(v) <= width)
        .or(variants.last())
        .copied()
        .unwrap_or("")
}

/// `v` with `decimals` places, and no "-0" for a value that rounds to zero.
fn fixed(v: f32, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s.chars().all(|c| matches!(c, '-' | '0' | '.')) {
        s[1..].to_string()
    } else {
        s
    }
}

fn xyz(v: Vec3) -> String {
    format!("{},{},{}", fixed(v.x, 2), fixed(v.y, 2), fixed(v.z, 2))
}

#[cfg(test)]
mod tests;
