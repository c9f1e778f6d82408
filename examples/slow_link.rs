//! The slow-link bench: the real app (`target/release/raytty`) in a pseudo-terminal drained at
//! 1, 10 and 100 Mbit/s (the link emulator in `tests/support/slow_link.rs`), at 120×40 and
//! 200×50, truecolor. A key is held for a second (10 presses 100 ms apart): W (the light moves
//! forward) or Right (the camera turns). For each, the bytes the app wrote from the first press
//! until the screen was exact, and how long after the last press (the release) every pixel on
//! screen was within 8 levels per channel of the final frame, and exact.
//!
//! Run: `cargo build --release && cargo run --release --example slow_link`
//! (one case: `... -- 120x40 w 1`: a size, `w` or `right`, Mbit/s; the emulator alone, draining
//! 2 MB: `... -- check 10`).

#[path = "../tests/support/slow_link.rs"]
mod slow_link;

use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::{CellGrid, cornell_box};
use slow_link::{SlowLink, app_image, max_error};

/// Presses per held key, and the time between them.
const PRESSES: usize = 10;
const PRESS_EVERY: Duration = Duration::from_millis(100);
/// "Close": every channel of every pixel within this many levels of the final frame.
const CLOSE: u16 = 8;
/// Longest wait for the first frame, or for the screen to settle.
const PATIENCE: Duration = Duration::from_secs(20);

#[derive(Clone, Copy, PartialEq)]
enum Motion {
    Light,
    Turn,
}

/// The frame the app shows after `presses` presses of the motion's key (its steps, as the
/// app's `update` applies them).
fn expected(cols: u16, rows: u16, motion: Motion, presses: usize) -> CellGrid {
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
    app_image(&camera, &lights, cols, rows)
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
                cases.push((cols, rows, motion, mbit));
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
    if let [size, key, mbit] = &args[..] {
        let (c, r) = size.split_once('x').expect("COLSxROWS");
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
        )];
    }
    println!("| size | key held 1 s | link | bytes sent | within {CLOSE} levels | exact |");
    println!("|---|---|---|---:|---:|---:|");
    let s = |t: Option<f64>| t.map_or("never".into(), |t| format!("{t:.2} s"));
    for (cols, rows, motion, mbit) in cases {
        let row = run(&binary, cols, rows, motion, mbit);
        println!(
            "| {cols}×{rows} | {} | {mbit} Mbit/s | {:.0} kB | {} | {} |",
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
