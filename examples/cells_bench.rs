//! The price list of the cell modes and the pixel protocols: for the seed's frame in COLS×ROWS
//! cells (default 100×50) at 16 samples a pixel, what the terminal shows (decoded: each glyph's
//! ink and background painted on 12×24-pixel cells; a pixel image scaled up by repeating its
//! pixels) against the same frame rendered at 12×24 pixels a cell, as PSNR; the bytes of a
//! whole frame (`encode_text`, and the app's first diffed frame), of the app's diff after a
//! light move (the light 0.1 forward, one W) and after a turn (5°, one →) — for the pixel
//! protocols, the whole image again, as the app sends it — and the time to encode it
//! (median CPU time of the thread; the encoders run on one thread). With chafa installed, the same frame
//! through chafa (`-w 9`, given the 12×24-pixel render) for comparison.
//!
//! Run: `cargo run --release --example cells_bench [-- COLSxROWS]`

use std::io::Write;
use std::process::Command;
use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::bench::metrics::psnr8;
use raytty::bench::timing::{Runs, measure, ms};
use raytty::frame::{Cell, CellMode, Colour, encode_kitty, encode_sixel, paint};
use raytty::{CellGrid, ColorMode, Image, Options, cornell_box, encode_diff, encode_text};

/// CPU time of the calling thread: the machine this is measured on is shared, and a wall
/// clock would count other programs' turns on the core.
fn cpu_now() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: writes the clock into `t`, which lives for the call.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

/// The reference's pixels a cell, as a terminal with a 12×24 font shows them.
const CELL: (u32, u32) = (12, 24);
const SAMPLES: u32 = 16;

fn main() {
    let (cols, rows) = std::env::args()
        .nth(1)
        .and_then(|s| {
            let (c, r) = s.split_once('x')?;
            Some((c.parse().ok()?, r.parse().ok()?))
        })
        .unwrap_or((100u32, 50u32));
    let scene = cornell_box();
    let mut settings = raytty::Stage::Indirect.settings(scene.effects());
    settings.effects.samples = SAMPLES;
    let camera = scene.camera();
    let mut turned = camera;
    turned.yaw += 5f32.to_radians();
    let mut moved = scene.lights().to_vec();
    moved[0].position += camera.to_world(Vec3::new(0.0, 0.0, 0.1));
    // The frame as it starts, after a light move, after a turn.
    let render = |w: u32, h: u32, view: usize| {
        scene
            .render(&Options {
                width: w,
                height: h,
                settings: Some(settings),
                camera: Some(if view == 2 { turned } else { camera }),
                lights: (view == 1).then_some(&moved[..]),
                ..Options::default()
            })
            .image
    };
    let frame = |w: u32, h: u32| render(w, h, 0);
    let (full_w, full_h) = (cols * CELL.0, rows * CELL.1);
    let reference = frame(full_w, full_h);
    let runs = Runs {
        min: 5,
        min_total: Duration::from_millis(300),
        max: 200,
    };
    println!(
        "seed frame, {cols}x{rows} cells, {SAMPLES} spp; PSNR against {full_w}x{full_h}; encode: median CPU ms"
    );
    println!(
        "| mode | PSNR dB | text bytes | first diff bytes | light move bytes | turn bytes | encode ms |\n|---|---:|---:|---:|---:|---:|---:|"
    );
    for mode in CellMode::ALL {
        let (sw, sh) = mode.render_pixels();
        let image = frame(cols * sw, rows * sh);
        let grid = CellGrid::from_image_in(&image, ColorMode::TrueColor, mode);
        let shown = paint(&grid, CELL.0 as usize, CELL.1 as usize);
        let psnr = psnr8(&to_image(&shown, full_w, full_h), &reference);
        let text = encode_text(&grid).len();
        let mut diff = Vec::new();
        encode_diff(None, &grid, 0, &mut diff);
        let after = |view: usize| {
            let next = render(cols * sw, rows * sh, view);
            let next = CellGrid::from_image_in(&next, ColorMode::TrueColor, mode);
            let mut out = Vec::new();
            encode_diff(Some(&grid), &next, 0, &mut out);
            out.len()
        };
        let (light, turn) = (after(1), after(2));
        let t = measure(
            runs,
            || {
                let start = cpu_now();
                let g = CellGrid::from_image_in(&image, ColorMode::TrueColor, mode);
                std::hint::black_box(encode_text(&g));
                cpu_now() - start
            },
            || {},
        );
        println!(
            "| {} | {psnr:.2} | {text} | {} | {light} | {turn} | {:.2} |",
            mode.name(),
            diff.len(),
            ms(t.median())
        );
    }
    for (name, (pw, ph)) in [
        ("kitty", (4, 8)),
        ("kitty", (12, 24)),
        ("sixel", (4, 8)),
        ("sixel", (12, 24)),
    ] {
        let (w, h) = (cols * pw, rows * ph);
        let encode_rgb = |rgb: &[[u8; 3]], out: &mut Vec<u8>| match name {
            "kitty" => encode_kitty(rgb, w, h, out),
            _ => encode_sixel(rgb, w, h, out),
        };
        let again = |view: usize| {
            let mut out = Vec::new();
            encode_rgb(&render(w, h, view).to_rgb8(), &mut out);
            out.len()
        };
        let (light, turn) = (again(1), again(2));
        let rgb = frame(w, h).to_rgb8();
        let encode = |out: &mut Vec<u8>| encode_rgb(&rgb, out);
        let mut bytes = Vec::new();
        encode(&mut bytes);
        let shown = match name {
            "kitty" => rgb.clone(),
            _ => sixel_colours(&rgb),
        };
        let scaled = upscale(&shown, w, h, CELL.0 / pw, CELL.1 / ph);
        let psnr = psnr8(&to_image(&scaled, full_w, full_h), &reference);
        let t = measure(
            runs,
            || {
                let start = cpu_now();
                let mut out = Vec::new();
                encode(&mut out);
                std::hint::black_box(out);
                cpu_now() - start
            },
            || {},
        );
        println!(
            "| {name} {pw}x{ph} px/cell | {psnr:.2} | {} | - | {light} | {turn} | {:.2} |",
            bytes.len(),
            ms(t.median())
        );
    }
    chafa(&reference, cols, rows);
    encode_times(&frame, runs);
}

/// Encode time at 200×50 cells, by step: cells from the image (`from_image_in`, one thread)
/// and the text (`encode_text`), and the app's first diffed frame (`encode_diff`).
fn encode_times(frame: &dyn Fn(u32, u32) -> Image, runs: Runs) {
    let (cols, rows) = (200, 50);
    println!(
        "\nencode at {cols}x{rows} cells, median CPU ms\n| mode | cells | text | diff |\n|---|---:|---:|---:|"
    );
    for mode in CellMode::ALL {
        let (sw, sh) = mode.render_pixels();
        let image = frame(cols * sw, rows * sh);
        let grid = CellGrid::from_image_in(&image, ColorMode::TrueColor, mode);
        let time = |f: &mut dyn FnMut()| {
            ms(measure(
                runs,
                || {
                    let start = cpu_now();
                    f();
                    cpu_now() - start
                },
                || {},
            )
            .median())
        };
        let cells = time(&mut || {
            std::hint::black_box(CellGrid::from_image_in(&image, ColorMode::TrueColor, mode));
        });
        let text = time(&mut || {
            std::hint::black_box(encode_text(&grid));
        });
        let diff = time(&mut || {
            let mut out = Vec::new();
            encode_diff(None, &grid, 0, &mut out);
            std::hint::black_box(out);
        });
        println!("| {} | {cells:.2} | {text:.2} | {diff:.2} |", mode.name());
    }
}

/// What sixel shows for `rgb`: each pixel its palette colour, as the terminal reads the
/// palette's percentages back.
fn sixel_colours(rgb: &[[u8; 3]]) -> Vec<[u8; 3]> {
    let (palette, index) = raytty::frame::sixel_palette(rgb);
    let back = |v: u8| {
        let pct = (u32::from(v) * 100 + 127) / 255;
        ((pct * 255 + 50) / 100) as u8
    };
    index
        .iter()
        .map(|&i| palette[usize::from(i)].map(back))
        .collect()
}

fn upscale(rgb: &[[u8; 3]], w: u32, h: u32, sx: u32, sy: u32) -> Vec<[u8; 3]> {
    let mut out = Vec::with_capacity((w * sx * h * sy) as usize);
    for y in 0..h * sy {
        for x in 0..w * sx {
            out.push(rgb[((y / sy) * w + x / sx) as usize]);
        }
    }
    out
}

fn to_image(rgb: &[[u8; 3]], w: u32, h: u32) -> Image {
    Image {
        width: w,
        height: h,
        pixels: rgb
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0)
            .collect(),
    }
}

/// The reference through chafa, per symbol set, if chafa is installed: PSNR of what it shows,
/// bytes, time.
fn chafa(reference: &Image, cols: u32, rows: u32) {
    let png = std::env::temp_dir().join("cells_bench_reference.png");
    let Ok(mut f) = std::fs::File::create(&png) else {
        return;
    };
    if reference
        .write_png(&mut f)
        .and_then(|()| f.flush())
        .is_err()
    {
        return;
    }
    for symbols in ["hhalf", "half", "quad", "sextant", "octant"] {
        let start = Instant::now();
        let Ok(out) = Command::new("chafa")
            .args([
                "--format",
                "symbols",
                "--colors",
                "full",
                "--symbols",
                symbols,
            ])
            .args([
                "-w",
                "9",
                "--animate",
                "off",
                "--polite",
                "on",
                "--threads",
                "1",
            ])
            .arg("--size")
            .arg(format!("{cols}x{rows}"))
            .arg(&png)
            .output()
        else {
            println!("(chafa not found)");
            return;
        };
        let elapsed = start.elapsed();
        if !out.status.success() {
            println!(
                "| chafa {symbols} | failed: {} |",
                String::from_utf8_lossy(&out.stderr).trim()
            );
            continue;
        }
        let (grid, unknown) = parse_ansi(&out.stdout, cols as usize, rows as usize);
        let shown = paint(&grid, CELL.0 as usize, CELL.1 as usize);
        let psnr = psnr8(&to_image(&shown, cols * CELL.0, rows * CELL.1), reference);
        println!(
            "| chafa -w 9 {symbols} | {psnr:.2} | {} | - | - | - | {:.0} (process) |{}",
            out.stdout.len(),
            ms(elapsed),
            if unknown > 0 {
                format!(" {unknown} cells with other glyphs, shown as background")
            } else {
                String::new()
            }
        );
    }
}

/// Cells from a stream of text with 24-bit SGR (as chafa writes it): rows end at newlines;
/// inverse video swaps the colours. Also counts the cells whose glyph is not a known block.
fn parse_ansi(bytes: &[u8], cols: usize, rows: usize) -> (CellGrid, usize) {
    let blank = Cell {
        ch: ' ',
        fg: None,
        bg: None,
    };
    let mut grid = CellGrid {
        cols,
        rows,
        cells: vec![blank; cols * rows],
    };
    let (mut fg, mut bg, mut inverse) = (None, None, false);
    let (mut r, mut c) = (0, 0);
    let mut unknown = 0;
    let text = String::from_utf8_lossy(bytes);
    let mut chars = text.chars().peekable();
    while let Some(ch) = chars.next() {
        match ch {
            '\x1b' => {
                if chars.peek() != Some(&'[') {
                    continue;
                }
                chars.next();
                let mut params = String::new();
                let mut fin = ' ';
                for x in chars.by_ref() {
                    if x.is_ascii_alphabetic() || x == '~' {
                        fin = x;
                        break;
                    }
                    params.push(x);
                }
                if fin != 'm' {
                    continue;
                }
                let p: Vec<u32> = params.split(';').map(|s| s.parse().unwrap_or(0)).collect();
                let mut i = 0;
                while i < p.len() {
                    match p[i] {
                        0 => (fg, bg, inverse) = (None, None, false),
                        7 => inverse = true,
                        27 => inverse = false,
                        39 => fg = None,
                        49 => bg = None,
                        38 | 48 if p.get(i + 1) == Some(&2) && i + 4 < p.len() => {
                            let c = Colour::Rgb(p[i + 2] as u8, p[i + 3] as u8, p[i + 4] as u8);
                            if p[i] == 38 {
                                fg = Some(c);
                            } else {
                                bg = Some(c);
                            }
                            i += 4;
                        }
                        _ => {}
                    }
                    i += 1;
                }
            }
            '\n' => (r, c) = (r + 1, 0),
            '\r' => c = 0,
            ch if !ch.is_control() => {
                if r < rows && c < cols {
                    let (f, b) = if inverse { (bg, fg) } else { (fg, bg) };
                    if raytty::frame::shape(ch).is_none() {
                        unknown += 1;
                    }
                    grid.cells[r * cols + c] = Cell { ch, fg: f, bg: b };
                }
                c += 1;
            }
            _ => {}
        }
    }
    (grid, unknown)
}
