//! The app's model and `update`: what the user sees is a function of [`App`], and every change
//! to it is a [`Message`]. No terminal here, so all of it is testable as plain data.

use glam::Vec3;
use raytty::frame::CellMode;
use raytty::{Camera, ColorMode, PointLight, Scene, Stage};

use super::detect::Protocol;

/// Everything that can happen to the app.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Message {
    /// Move the camera along its forward axis by this many scene units (negative: back).
    Walk(f32),
    /// Turn the camera by this many radians (positive: to the right).
    Turn(f32),
    /// Tilt the camera by this many radians (positive: down), within ±[`MAX_PITCH_DEGREES`].
    Pitch(f32),
    /// Multiply the field of view by this factor (below 1: zoom in).
    Zoom(f32),
    /// Put the camera back where the scene starts it (the model framed again), lights kept.
    Frame,
    /// Orbit the camera by these yaw and pitch angles in radians about the point ahead of it
    /// as far as the scene's centre is (a mouse drag).
    Orbit(f32, f32),
    /// Move the light by this offset in camera axes (right, down, forward), scene units.
    MoveLight(Vec3),
    /// Switch to a stage.
    SetStage(Stage),
    /// Put the camera and the light back where the scene starts them.
    Reset,
    /// Next colour mode (truecolor → 256 → ascii).
    CycleColor,
    /// Next cell mode (half → quadrant → sextant → octant).
    CycleCells,
    /// Pixels (the terminal's protocol, if it has one) on or off (text cells).
    ToggleGraphics,
    /// A terminal cell is now this many pixels wide and high (after a resize or a font change).
    CellPixels {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Show or hide the key help.
    ToggleHelp,
    /// Turn the GI denoiser on or off.
    ToggleDenoise,
    /// The terminal now has this many columns and rows.
    Resize {
        /// Columns.
        cols: u16,
        /// Rows.
        rows: u16,
    },
    /// Leave the app.
    Quit,
    /// Give the terminal back to the shell until it resumes us (Ctrl-Z; `fg` resumes).
    Suspend,
}

/// The steepest the camera looks up or down, in degrees.
pub const MAX_PITCH_DEGREES: f32 = 89.0;

/// The app's state.
#[derive(Clone, Debug)]
pub struct App {
    /// The scene shown (any scene: the built-in box or one loaded from a file).
    pub scene: Scene,
    /// Where the camera is.
    pub camera: Camera,
    /// The lights; keys move the first one.
    pub lights: Vec<PointLight>,
    /// The shading stage.
    pub stage: Stage,
    /// How cells are coloured.
    pub color: ColorMode,
    /// How many pixels a cell shows (half-blocks, quadrants, sextants, octants).
    pub cells: CellMode,
    /// The pixel protocol the terminal speaks (asked at start, or forced), if any.
    pub protocol: Option<Protocol>,
    /// Whether frames are drawn with [`App::protocol`] rather than in text cells.
    pub pixels: bool,
    /// A cell's size in pixels (width, height): the pixel modes render at it.
    pub cell_pixels: (u32, u32),
    /// The largest sixel image the terminal draws (width, height), if it said.
    pub sixel_max: Option<(u32, u32)>,
    /// Pixel escapes go through tmux's passthrough.
    pub tmux: bool,
    /// Whether the key help covers the frame.
    pub help: bool,
    /// Whether the GI stage's indirect light is denoised (the raw, unbiased estimate if not).
    pub denoise: bool,
    /// Terminal size in cells (columns, rows).
    pub size: (u16, u16),
    /// Set by [`Message::Quit`].
    pub quit: bool,
    /// Set by [`Message::Suspend`]; the event loop suspends and clears it.
    pub suspend: bool,
    /// Bumped whenever the image's inputs change (camera, lights, stage, size): a progressive
    /// render restarts when it changes.
    pub generation: u64,
    /// Something visible changed since the last draw.
    pub dirty: bool,
}

impl App {
    /// The app at the scene's starting view, in the default stage.
    pub fn new(scene: Scene, color: ColorMode, size: (u16, u16)) -> App {
        App {
            camera: scene.camera(),
            lights: scene.lights().to_vec(),
            scene,
            stage: Stage::Indirect,
            color,
            cells: CellMode::Half,
            protocol: None,
            pixels: false,
            cell_pixels: super::detect::FALLBACK_CELL,
            sixel_max: None,
            tmux: false,
            help: false,
            denoise: true,
            size,
            quit: false,
            suspend: false,
            generation: 0,
            dirty: true,
        }
    }

    /// The cell mode frames are drawn in: [`App::cells`], but half-blocks in ASCII (one
    /// character a cell, whatever the mode: finer pixels would only cost render time).
    pub fn cell_mode(&self) -> CellMode {
        if self.color == ColorMode::Ascii {
            CellMode::Half
        } else {
            self.cells
        }
    }

    /// The pixel protocol frames are drawn with now, if any (none while the help is shown:
    /// it is text).
    pub fn graphics(&self) -> Option<Protocol> {
        self.protocol.filter(|_| self.pixels && !self.help)
    }

    /// The position of the light the keys move, if the scene has one.
    pub fn light(&self) -> Option<Vec3> {
        self.lights.first().map(|l| l.position)
    }
}

/// Applies one message.
pub fn update(app: &mut App, msg: Message) {
    let image_changes = match msg {
        Message::Walk(d) => {
            // Steps are the Cornell box's, scaled to the scene's size (1 for the box: exact).
            app.camera.position += app.camera.forward() * (d * app.scene.step());
            d != 0.0
        }
        Message::Pitch(a) => {
            let max = MAX_PITCH_DEGREES.to_radians();
            let pitch = (app.camera.pitch + a).clamp(-max, max);
            let changed = pitch != app.camera.pitch;
            app.camera.pitch = pitch;
            changed
        }
        Message::Zoom(f) => {
            let (lo, hi) = raytty::camera::FOV_RANGE_DEGREES;
            // A camera on the seed's rule starts from the field of view it has across the
            // image's height.
            let (w, h) = (app.size.0.max(1) as f32, 2.0 * app.size.1.max(1) as f32);
            let now = app
                .camera
                .fov
                .unwrap_or_else(|| 2.0 * (0.5 * h / w.min(h)).atan());
            let fov = (now * f).clamp(lo.to_radians(), hi.to_radians());
            let changed = Some(fov) != app.camera.fov;
            app.camera.fov = Some(fov);
            changed
        }
        Message::Frame => {
            app.camera = app.scene.camera();
            true
        }
        Message::Orbit(yaw, pitch) => {
            let c = &mut app.camera;
            let r = (app.scene.centre() - c.position).length();
            let pivot = c.position + c.forward() * r;
            let max = MAX_PITCH_DEGREES.to_radians();
            c.yaw = (c.yaw + yaw + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
                - std::f32::consts::PI;
            c.pitch = (c.pitch + pitch).clamp(-max, max);
            c.position = pivot - c.forward() * r;
            yaw != 0.0 || pitch != 0.0
        }
        Message::Turn(a) => {
            // Keep yaw in (−π, π] so the status line stays readable after many turns.
            let yaw = (app.camera.yaw + a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
                - std::f32::consts::PI;
            let changed = yaw != app.camera.yaw;
            app.camera.yaw = yaw;
            changed
        }
        Message::MoveLight(local) => {
            let world = app.camera.to_world(local * app.scene.step());
            match app.lights.first_mut() {
                Some(l) => {
                    l.position += world;
                    true
                }
                None => false,
            }
        }
        Message::SetStage(s) => {
            let changed = s != app.stage;
            app.stage = s;
            changed
        }
        Message::Reset => {
            app.camera = app.scene.camera();
            app.lights = app.scene.lights().to_vec();
            true
        }
        // Into or out of ASCII, the image's size changes unless the cells are half-blocks.
        Message::CycleColor => {
            let before = app.cell_mode();
            app.color = app.color.next();
            app.dirty = true;
            app.cell_mode() != before
        }
        // The image is rendered again at the new mode's pixels a cell.
        Message::CycleCells => {
            let before = app.cell_mode();
            app.cells = app.cells.next();
            app.dirty = true;
            app.cell_mode() != before
        }
        // The image is rendered again at the new mode's size.
        Message::ToggleGraphics => {
            let on = app.protocol.is_some() && !app.pixels;
            let changed = on != app.pixels;
            app.pixels = on;
            app.dirty = true;
            changed
        }
        Message::CellPixels { width, height } => {
            let changed = (width, height) != app.cell_pixels;
            app.cell_pixels = (width, height);
            changed && app.graphics().is_some()
        }
        Message::ToggleHelp => {
            app.help = !app.help;
            app.dirty = true;
            false
        }
        // The samples so far are kept: the view filters them again, or shows them raw.
        Message::ToggleDenoise => {
            app.denoise = !app.denoise;
            app.dirty = true;
            false
        }
        Message::Resize { cols, rows } => {
            let changed = (cols, rows) != app.size;
            app.size = (cols, rows);
            changed
        }
        Message::Quit => {
            app.quit = true;
            false
        }
        Message::Suspend => {
            app.suspend = true;
            false
        }
    };
    if image_changes {
        app.generation += 1;
        app.dirty = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytty::cornell_box;

    /// Moves are sums of a few f32 steps: this is far above their rounding, far below a step.
    const TOLERANCE: f32 = 1e-5;

    fn app() -> App {
        App::new(cornell_box(), ColorMode::TrueColor, (80, 24))
    }

    #[test]
    fn walking_moves_along_the_view_and_turning_changes_the_view() {
        let mut a = app();
        let start = a.camera.position;
        update(&mut a, Message::Walk(0.1));
        assert!((a.camera.position - start - Vec3::new(0.0, 0.0, 0.1)).length() < TOLERANCE);
        update(&mut a, Message::Turn(std::f32::consts::FRAC_PI_2));
        update(&mut a, Message::Walk(0.1));
        assert!((a.camera.position - start - Vec3::new(0.1, 0.0, 0.1)).length() < TOLERANCE);
        assert_eq!(a.generation, 3);
    }

    /// Orbiting keeps the distance to the pivot and keeps looking at it.
    #[test]
    fn orbit_circles_the_point_looked_at() {
        let mut a = app();
        let r = (a.scene.centre() - a.camera.position).length();
        let pivot = a.camera.position + a.camera.forward() * r;
        update(&mut a, Message::Orbit(0.7, -0.3));
        assert!((a.camera.position + a.camera.forward() * r - pivot).length() < TOLERANCE);
        assert!(((a.camera.position - pivot).length() - r).abs() < TOLERANCE);
    }

    #[test]
    fn pitch_zoom_and_frame_again() {
        let mut a = app();
        update(&mut a, Message::Pitch(2.0));
        assert_eq!(a.camera.pitch, MAX_PITCH_DEGREES.to_radians());
        update(&mut a, Message::Zoom(0.5));
        let fov = a.camera.fov.unwrap();
        // 80x24 cells are 80x48 pixels: the seed's rule spans 2·atan(½) across the height.
        assert!((fov - 0.5f32.atan()).abs() < TOLERANCE, "{fov}");
        let g = a.generation;
        update(&mut a, Message::Frame);
        assert_eq!(a.camera, a.scene.camera());
        assert_eq!(a.generation, g + 1);
    }

    #[test]
    fn light_moves_along_the_camera_axes_and_reset_restores_it() {
        let mut a = app();
        let start = a.light().unwrap();
        update(&mut a, Message::Turn(std::f32::consts::FRAC_PI_2));
        // Forward is +x after a quarter turn right.
        update(&mut a, Message::MoveLight(Vec3::new(0.0, 0.0, 0.1)));
        assert!((a.light().unwrap() - start - Vec3::new(0.1, 0.0, 0.0)).length() < TOLERANCE);
        update(&mut a, Message::Reset);
        assert_eq!(a.light(), Some(start));
        assert_eq!(a.camera, a.scene.camera());
    }

    #[test]
    fn yaw_stays_in_one_turn_after_many_turns() {
        let mut a = app();
        for _ in 0..1000 {
            update(&mut a, Message::Turn(5f32.to_radians()));
        }
        assert!(a.camera.yaw.abs() <= std::f32::consts::PI + TOLERANCE);
    }

    #[test]
    fn only_image_changes_restart_the_render() {
        let mut a = app();
        a.dirty = false;
        update(&mut a, Message::CycleColor);
        update(&mut a, Message::ToggleHelp);
        update(&mut a, Message::ToggleDenoise);
        assert_eq!(
            (a.generation, a.dirty, a.color, a.help, a.denoise),
            (0, true, ColorMode::Ansi256, true, false)
        );
        update(&mut a, Message::SetStage(Stage::Indirect));
        update(&mut a, Message::Resize { cols: 80, rows: 24 });
        assert_eq!(a.generation, 0, "nothing changed");
        update(&mut a, Message::SetStage(Stage::Gi));
        update(
            &mut a,
            Message::Resize {
                cols: 100,
                rows: 30,
            },
        );
        assert_eq!((a.generation, a.size), (2, (100, 30)));
        assert!(!a.quit);
        // Pixels toggle only where the terminal has a protocol.
        update(&mut a, Message::ToggleGraphics);
        assert!(!a.pixels);
        a.protocol = Some(Protocol::Kitty);
        update(&mut a, Message::ToggleGraphics);
        assert!(a.pixels && a.graphics().is_none(), "the help is text");
        update(&mut a, Message::ToggleHelp);
        assert_eq!(a.graphics(), Some(Protocol::Kitty));
        update(
            &mut a,
            Message::CellPixels {
                width: 9,
                height: 18,
            },
        );
        assert_eq!((a.generation, a.cell_pixels), (4, (9, 18)));
        update(&mut a, Message::Quit);
        assert!(a.quit);
    }
}
