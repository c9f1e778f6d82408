//! What a frame costs the app at 200×50 cells (200×98 pixels plus the status line): bytes of the
//! diffed encoding against a naive one (a full SGR for every cell), and render and encode times,
//! while the light moves and while the camera turns, as the app's keys would move them.
//!
//! Run: `cargo run --release --example frame_bytes`

use std::io::Write;
use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::frame::{Cell, Colour};
use raytty::{CellGrid, ColorMode, HitCache, Options, Stage, cornell_box, encode_diff};

const COLS: u32 = 200;
const ROWS: u32 = 50;
/// Key presses per sweep (0.1 units and 5° each, the app's steps).
const STEPS: usize = 8;

/// Every cell with its own cursor move and full SGR: what an encoder without diffing writes.
fn naive(grid: &CellGrid) -> usize {
    let mut out = Vec::new();
    for r in 0..grid.rows {
        let _ = write!(out, "\x1b[{};1H", r + 1);
        for c in 0..grid.cols {
            let Cell { ch, fg, bg } = grid.get(c, r);
            let rgb = |c: Option<Colour>| match c {
                Some(Colour::Rgb(r, g, b)) => (r, g, b),
                _ => (0, 0, 0),
            };
            let (f, b) = (rgb(fg), rgb(bg));
            let _ = write!(
                out,
                "\x1b[38;2;{};{};{};48;2;{};{};{}m{ch}",
                f.0, f.1, f.2, b.0, b.1, b.2
            );
        }
    }
    out.len()
}

fn main() {
    let scene = cornell_box();
    let settings = Stage::Indirect.settings(scene.effects());
    let (w, h) = (COLS, 2 * (ROWS - 1));
    for sweep in ["light moves (D)", "camera turns (Right)"] {
        let mut camera = scene.camera();
        let mut lights = scene.lights().to_vec();
        let mut cache = HitCache::new();
        let mut prev: Option<CellGrid> = None;
        let (mut diff_bytes, mut naive_bytes) = (0, 0);
        let (mut render_t, mut encode_t) = (Duration::ZERO, Duration::ZERO);
        let mut primary = 0;
        let mut changed = 0;
        for step in 0..=STEPS {
            if step > 0 {
                if sweep.starts_with("light") {
                    lights[0].position += camera.to_world(Vec3::new(0.1, 0.0, 0.0));
                } else {
                    camera.yaw += 5f32.to_radians();
                }
            }
            let frame = cache.render(
                &scene,
                &Options {
                    width: w,
                    height: h,
                    settings: Some(settings),
                    camera: Some(camera),
                    lights: Some(&lights),
                    ..Options::default()
                },
            );
            let start = Instant::now();
            let grid = CellGrid::from_image(&frame.image, ColorMode::TrueColor);
            let mut out = Vec::new();
            encode_diff(prev.as_ref(), &grid, 0, &mut out);
            let enc = start.elapsed();

            // The first frame is the full paint; the sweep is the frames after it.
            if step > 0 {
                diff_bytes += out.len();
                naive_bytes += naive(&grid);
                render_t += frame.stats.elapsed;
                encode_t += enc;
                primary += frame.stats.rays.primary;
                let before = prev.as_ref().expect("a first frame");
                changed += (before.cells.iter().zip(&grid.cells))
                    .filter(|(a, b)| a != b)
                    .count();
            } else {
                println!(
                    "{sweep}: first full frame {} bytes (naive {})",
                    out.len(),
                    naive(&grid)
                );
            }
            prev = Some(grid);
        }
        let n = STEPS as f64;
        println!(
            "{sweep}: {:.0} bytes/frame diffed vs {:.0} naive ({:.1}%), {:.0}% of cells changed ({:.1} B each), render {:.1} ms, encode {:.2} ms, primary rays/frame {}",
            diff_bytes as f64 / n,
            naive_bytes as f64 / n,
            100.0 * diff_bytes as f64 / naive_bytes as f64,
            100.0 * changed as f64 / (n * (COLS * (ROWS - 1)) as f64),
            diff_bytes as f64 / changed as f64,
            render_t.as_secs_f64() * 1e3 / n,
            encode_t.as_secs_f64() * 1e3 / n,
            primary / STEPS as u64,
        );
    }
}
