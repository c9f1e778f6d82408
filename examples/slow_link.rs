//! The slow-link bench: the real app (`target/release/raytty`) in a pseudo-terminal drained at
//! 1, 10 and 100 Mbit/s (the link emulator in `tests/support/slow_link.rs`), at 120×40 and
//! 200×50, truecolor. A key is held for a second (10 presses 100 ms apart): W (the light moves
//! forward) or Right (the camera turns). For each, the bytes the app wrote from the first press
//! until the screen was exact, and how long after the last press (the release) every pixel on
//! screen was within 8 levels per channel of the final frame, and exact.
//!
//! In a pixel mode (`kitty`, `sixel`: the app forced to it, in a terminal of 10×20-pixel
//! cells), the far end decodes the graphics escapes ([`graphics::PixelScreen`]) and every
//! pixel of the image area is judged against the app's exact image: the render at the
//! resolution the app settles at (as its status line says), for sixel as the app's own sixel
//! encoding of it shows it (its palette is all a sixel terminal can be exact to).
//!
//! Run: `cargo build --release && cargo run --release --example slow_link`
//! (one case: `... -- 120x40 w 1`: a size, `w` or `right`, Mbit/s, and optionally `kitty` or
//! `sixel`; the pixel modes at 120×40: `... -- pixels`; the emulator alone, draining 2 MB:
//! `... -- check 10`).

#[path = "../tests/support/slow_link.rs"]
mod slow_link;

use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::frame::encode_sixel;
use raytty::{Camera, CellGrid, PointLight, cornell_box};
use slow_link::graphics::{self, PixelScreen, max_pixel_error};
use slow_link::{SlowLink, app_image, app_pixels, max_error};

/// Presses per held key, and the time between them.
const PRESSES: usize = 10;
const PRESS_EVERY: Duration = Duration::from_millis(100);
/// "Close": every channel of every pixel within this many levels of the final frame.
const CLOSE: u16 = 8;
/// Longest wait for the first frame, or for the screen to settle.
const PATIENCE: Duration = Duration::from_secs(20);
/// Pixel modes: the terminal's cell in pixels (a common size: 10×20).
const CELL: (u16, u16) = (10, 20);
/// Pixel modes: the app is taken to have settled once it has written nothing for this long.
const QUIET: Duration = Duration::from_millis(700);

#[derive(Clone, Copy, PartialEq)]
enum Motion {
    Light,
    Turn,
}

/// The camera and lights after `presses` presses of the motion's key (its steps, as the app's
/// `update` applies them).
fn moved(motion: Motion, presses: usize) -> (Camera, Vec<PointLight>) {
    let scene = cornell_box();
    let mut camera = scene.camera();
    let mut lights = scene.lights().to_vec();
    for _ in 0..presses {
        match motion {
            Motion::Light => {
                let step = 0.1f32 * 1.0;
                lights[0].position += camera.to_world(Vec3::new(0.0, 0.0, 1.0) * step);
            }
            Motion::Turn => {
                let a = 5f32.to_radians() * 1.0;
                let pi = std::f32::consts::PI;
                camera.yaw = (camera.yaw + a + pi).rem_euclid(std::f32::consts::TAU) - pi;
            }
        }
    }
    (camera, lights)
}

/// The frame the app shows after `presses` presses of the motion's key.
fn expected(cols: u16, rows: u16, motion: Motion, presses: usize) -> CellGrid {
    let (camera, lights) = moved(motion, presses);
    app_image(&camera, &lights, cols, rows)
}

/// The pixels a pixel mode shows exactly after `presses` presses of the motion's key, at the
/// image size `(w, h)`: kitty's are the render's; sixel's are its own encoding's.
fn expected_pixels(
    protocol: &str,
    (w, h): (u32, u32),
    motion: Motion,
    presses: usize,
) -> Vec<[u8; 3]> {
    let (camera, lights) = moved(motion, presses);
    let rgb = app_pixels(&camera, &lights, w, h);
    if protocol == "kitty" {
        return rgb;
    }
    let mut out = Vec::new();
    encode_sixel(&rgb, w, h, &mut out);
    let (_, _, px) = graphics::decode_sixel(&out);
    px.into_iter()
        .map(|p| p.expect("every pixel painted"))
        .collect()
}

struct Row {
    bytes: usize,
    close: Option<f64>,
    exact: Option<f64>,
}

fn run(binary: &str, cols: u16, rows: u16, motion: Motion, mbit: f64) -> Row {
    let start = expected(cols, rows, motion, 0);
    let end = expected(cols, rows, motion, PRESSES);
    let rate = mbit * 1e6 / 8.0;
    let mut link = SlowLink::start(binary, &["--color", "truecolor"], cols, rows, rate);
    assert!(
        link.wait_for(PATIENCE, |s| max_error(s, &start) == 0),
        "the first frame never showed"
    );
    let bytes_before = link.snapshot().1;
    let key: &[u8] = match motion {
        Motion::Light => b"w",
        Motion::Turn => b"\x1b[C",
    };
    let mut release = Instant::now();
    for i in 0..PRESSES {
        if i > 0 {
            std::thread::sleep(PRESS_EVERY);
        }
        // The release is taken before the last press is written: on a loaded machine the
        // bench can be descheduled after the write while the app answers on a fast link, and
        // reads from before the release are not judged.
        release = Instant::now();
        link.send(key);
    }
    // Judge the screen as of each read (copied out, so judging never slows the link).
    let (mut close, mut exact) = (None, None);
    let mut judged = None;
    while exact.is_none() && release.elapsed() < PATIENCE {
        let (screen, bytes, last_read) = link.snapshot();
        if last_read == judged || last_read.is_none_or(|t| t < release) {
            std::thread::sleep(Duration::from_micros(200));
            continue;
        }
        judged = last_read;
        let at = last_read
            .expect("a read")
            .saturating_duration_since(release);
        let e = max_error(&screen, &end);
        if e <= CLOSE && close.is_none() {
            close = Some(at.as_secs_f64());
        }
        if e == 0 {
            exact = Some((at.as_secs_f64(), bytes));
        }
    }
    if std::env::var_os("SLOW_LINK_DEBUG").is_some() {
        let (scr, _, _) = link.snapshot();
        eprintln!(
            "error to the final frame {}; status: {}",
            max_error(&scr, &end),
            scr.contents_between(rows - 1, 0, rows - 1, cols)
        );
    }
    Row {
        bytes: exact.map_or(link.snapshot().1, |(_, b)| b) - bytes_before,
        close,
        exact: exact.map(|(t, _)| t),
    }
}

/// The image size a pixel-mode status line states (`kitty 1200x780`).
fn stated_size(status: &str, protocol: &str) -> Option<(u32, u32)> {
    let rest = &status[status.find(&format!("{protocol} "))? + protocol.len() + 1..];
    let (w, rest) = rest.split_once('x')?;
    let h: String = rest.chars().take_while(char::is_ascii_digit).collect();
    Some((w.parse().ok()?, h.parse().ok()?))
}

/// [`run`] in a pixel mode (`protocol`: `kitty` or `sixel`).
fn run_pixels(
    binary: &str,
    cols: u16,
    rows: u16,
    motion: Motion,
    mbit: f64,
    protocol: &str,
) -> Row {
    let rate = mbit * 1e6 / 8.0;
    let args = ["--color", "truecolor", "--graphics", protocol];
    let mut link = SlowLink::start_with_cells(binary, &args, cols, rows, CELL, rate);
    let cell = (u32::from(CELL.0), u32::from(CELL.1));
    let mut screen = PixelScreen::new(cols, rows, cell);
    let draw = |screen: &mut PixelScreen, link: &SlowLink| {
        let mut drawn = Vec::new();
        for e in link.take_graphics() {
            if screen.apply(&e.bytes, e.cursor) {
                drawn.push((e.at, e.read));
            }
        }
        drawn
    };
    // Settled: drawn, and quiet since.
    let t = Instant::now();
    let mut drawn = false;
    loop {
        drawn |= !draw(&mut screen, &link).is_empty();
        let (_, _, last) = link.snapshot();
        if drawn && last.is_some_and(|l| l.elapsed() > QUIET) {
            break;
        }
        assert!(t.elapsed() < PATIENCE, "the first frame never settled");
        std::thread::sleep(Duration::from_millis(10));
    }
    let (s, _, _) = link.snapshot();
    let status = s.contents_between(rows - 1, 0, rows - 1, cols);
    let size = stated_size(&status, protocol)
        .unwrap_or_else(|| panic!("no {protocol} size in the status line: {status}"));
    let start = expected_pixels(protocol, size, motion, 0);
    let first = max_pixel_error(&screen.shown(size.0, size.1), &start);
    assert_eq!(first, 0, "the first frame is not exact ({status})");
    let end = expected_pixels(protocol, size, motion, PRESSES);
    let bytes_before = link.snapshot().1;
    let key: &[u8] = match motion {
        Motion::Light => b"w",
        Motion::Turn => b"\x1b[C",
    };
    let mut release = Instant::now();
    for i in 0..PRESSES {
        if i > 0 {
            std::thread::sleep(PRESS_EVERY);
        }
        release = Instant::now();
        link.send(key);
    }
    let (mut close, mut exact) = (None, None);
    while exact.is_none() && release.elapsed() < PATIENCE {
        for (at, read) in draw(&mut screen, &link) {
            if at < release {
                continue;
            }
            let after = at.saturating_duration_since(release).as_secs_f64();
            let e = max_pixel_error(&screen.shown(size.0, size.1), &end);
            if std::env::var_os("SLOW_LINK_DEBUG").is_some() {
                eprintln!(
                    "{after:.3} s: {} kB, error {e}",
                    (read - bytes_before) / 1000
                );
            }
            if e <= CLOSE && close.is_none() {
                close = Some(after);
            }
            if e == 0 && exact.is_none() {
                exact = Some((after, read));
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    if std::env::var_os("SLOW_LINK_DEBUG").is_some() {
        let (s, _, _) = link.snapshot();
        eprintln!(
            "status: {}",
            s.contents_between(rows - 1, 0, rows - 1, cols)
        );
    }
    Row {
        bytes: exact.map_or(link.snapshot().1, |(_, b)| b) - bytes_before,
        close,
        exact: exact.map(|(t, _)| t),
    }
}

fn main() {
    let exe = std::env::current_exe().expect("the example's path");
    let binary = exe
        .parent()
        .and_then(|d| d.parent())
        .map(|d| d.join("raytty"))
        .expect("target/<profile>/raytty");
    let binary = binary.to_str().expect("a UTF-8 path").to_string();
    assert!(
        std::path::Path::new(&binary).exists(),
        "{binary} is missing: run `cargo build --release` first"
    );
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut cases = Vec::new();
    for (cols, rows) in [(120u16, 40u16), (200, 50)] {
        for motion in [Motion::Light, Motion::Turn] {
            for mbit in [1.0, 10.0, 100.0] {
                cases.push((cols, rows, motion, mbit, "text"));
            }
        }
    }
    if args == ["pixels"] {
        cases.clear();
        for protocol in ["kitty", "sixel"] {
            for motion in [Motion::Light, Motion::Turn] {
                for mbit in [1.0, 10.0] {
                    cases.push((120, 40, motion, mbit, protocol));
                }
            }
        }
    }
    if let [check, mbit] = &args[..]
        && check == "check"
    {
        // The emulator alone: how fast it drains 2 MB written as fast as possible.
        let rate = mbit.parse::<f64>().expect("Mbit/s") * 1e6 / 8.0;
        let link = SlowLink::start(
            "sh",
            &["-c", "head -c 2000000 /dev/zero | tr '\\0' x"],
            200,
            50,
            rate,
        );
        let t = Instant::now();
        while link.snapshot().1 < 2_000_000 && t.elapsed() < PATIENCE {
            std::thread::sleep(Duration::from_millis(1));
        }
        let secs = t.elapsed().as_secs_f64();
        println!("2 MB in {secs:.2} s: {:.1} Mbit/s", 16.0 / secs);
        return;
    }
    if let [size, key, mbit, rest @ ..] = &args[..] {
        let (c, r) = size.split_once('x').expect("COLSxROWS");
        let mode = match rest {
            [] => "text",
            [m] if m == "kitty" || m == "sixel" => m.as_str(),
            _ => panic!("a mode: kitty or sixel"),
        };
        let motion = if key == "w" {
            Motion::Light
        } else {
            Motion::Turn
        };
        cases = vec![(
            c.parse().expect("columns"),
            r.parse().expect("rows"),
            motion,
            mbit.parse().expect("Mbit/s"),
            mode,
        )];
    }
    println!("| size | mode | key held 1 s | link | bytes sent | within {CLOSE} levels | exact |");
    println!("|---|---|---|---|---:|---:|---:|");
    let s = |t: Option<f64>| t.map_or("never".into(), |t| format!("{t:.2} s"));
    for (cols, rows, motion, mbit, mode) in cases {
        let row = match mode {
            "text" => run(&binary, cols, rows, motion, mbit),
            p => run_pixels(&binary, cols, rows, motion, mbit, p),
        };
        println!(
            "| {cols}×{rows} | {mode} | {} | {mbit} Mbit/s | {:.0} kB | {} | {} |",
            if motion == Motion::Light {
                "W (light)"
            } else {
                "Right (turn)"
            },
            row.bytes as f64 / 1e3,
            s(row.close),
            s(row.exact),
        );
    }
}
