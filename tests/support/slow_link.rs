//! A link emulator: runs a program in a pseudo-terminal and reads what it writes no faster than
//! a given rate, as a terminal at the far end of a slow SSH connection would receive it. What is
//! read goes through a terminal emulator (vt100), so the screen can be judged as a user sees
//! it, and the graphics escapes are kept (with when they arrived and where the cursor was) for
//! the pixels they draw ([`graphics::PixelScreen`]). Shared by `tests/tui_pty.rs` and
//! `examples/slow_link.rs` (the bench).
#![allow(dead_code)]

#[path = "graphics.rs"]
pub mod graphics;

use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use portable_pty::{Child, CommandBuilder, MasterPty, PtySize, native_pty_system};
use raytty::frame::{Colour, pixels};
use raytty::{Camera, CellGrid, ColorMode, Image, Options, PointLight, Stage, cornell_box};

/// The most the link lets through at once after an idle spell, in time at its rate (a real
/// link's queue): long enough that the reader's own scheduling delays on a busy machine do not
/// slow the link down.
const BURST: Duration = Duration::from_millis(10);
/// Longest read.
const READ_MAX: usize = 65536;
/// How often the reader wakes while waiting for the link's next bytes.
const TICK: Duration = Duration::from_millis(1);

/// What the far end has seen.
pub struct Far {
    /// The terminal the bytes were played into.
    pub screen: vt100::Parser,
    /// Bytes read so far.
    pub bytes: usize,
    /// The program closed the pty.
    pub closed: bool,
    /// When the last bytes were read.
    pub last_read: Option<Instant>,
    /// The graphics escapes read and not yet taken ([`SlowLink::take_graphics`]).
    pub graphics: Vec<Escape>,
}

/// A graphics escape the far end read.
pub struct Escape {
    /// When its last byte was read.
    pub at: Instant,
    /// The bytes read up to the end of that read.
    pub read: usize,
    /// The cursor (row, column) where it began.
    pub cursor: (u16, u16),
    pub bytes: Vec<u8>,
}

/// A program on the far side of a link of `rate` bytes per second.
pub struct SlowLink {
    pub child: Box<dyn Child + Send + Sync>,
    master: Box<dyn MasterPty + Send>,
    writer: Arc<Mutex<Box<dyn Write + Send>>>,
    pub far: Arc<Mutex<Far>>,
}

impl SlowLink {
    /// Starts `program` with `args` in a `cols × rows` pty drained at `rate` bytes per second.
    pub fn start(program: &str, args: &[&str], cols: u16, rows: u16, rate: f64) -> SlowLink {
        SlowLink::start_with(program, args, (cols, rows), (0, 0), rate, false)
    }

    /// Like [`SlowLink::start`], but as over SSH: the pty is drained at once into a deep buffer
    /// (sshd's and TCP's), which the link then carries at `rate`; and the far end answers the
    /// device-attributes query (`ESC [ c`) once it has processed it, as xterm and tmux do.
    pub fn start_behind_buffer(
        program: &str,
        args: &[&str],
        cols: u16,
        rows: u16,
        rate: f64,
    ) -> SlowLink {
        SlowLink::start_with(program, args, (cols, rows), (0, 0), rate, true)
    }

    /// Like [`SlowLink::start`], in a terminal whose cells are `cell` pixels (as
    /// `TIOCGWINSZ` tells the program).
    pub fn start_with_cells(
        program: &str,
        args: &[&str],
        cols: u16,
        rows: u16,
        cell: (u16, u16),
        rate: f64,
    ) -> SlowLink {
        SlowLink::start_with(program, args, (cols, rows), cell, rate, false)
    }

    fn start_with(
        program: &str,
        args: &[&str],
        (cols, rows): (u16, u16),
        cell: (u16, u16),
        rate: f64,
        deep: bool,
    ) -> SlowLink {
        let pair = native_pty_system()
            .openpty(PtySize {
                rows,
                cols,
                pixel_width: cols * cell.0,
                pixel_height: rows * cell.1,
            })
            .expect("open a pty");
        let mut cmd = CommandBuilder::new(program);
        cmd.args(args);
        cmd.env("TERM", "xterm-256color");
        // Half-blocks whatever terminal the tests run in (`--cells auto` reads these).
        for var in ["TERM_PROGRAM", "TERM_PROGRAM_VERSION", "KITTY_WINDOW_ID"] {
            cmd.env_remove(var);
        }
        cmd.env_remove("NO_COLOR");
        let child = pair.slave.spawn_command(cmd).expect("spawn the program");
        drop(pair.slave);
        let mut reader = pair.master.try_clone_reader().expect("pty reader");
        let writer = Arc::new(Mutex::new(pair.master.take_writer().expect("pty writer")));
        let answers = writer.clone();
        // The deep buffer: everything the program wrote that the link has not carried yet.
        let buffer: Arc<Mutex<(std::collections::VecDeque<u8>, bool)>> = Default::default();
        if deep {
            let buffer = buffer.clone();
            let mut reader = pair.master.try_clone_reader().expect("pty reader");
            std::thread::spawn(move || {
                let mut buf = vec![0u8; READ_MAX];
                loop {
                    let n = reader.read(&mut buf).unwrap_or(0);
                    let mut b = buffer.lock().expect("the buffer");
                    if n == 0 {
                        b.1 = true;
                        return;
                    }
                    b.0.extend(&buf[..n]);
                }
            });
        }
        let far = Arc::new(Mutex::new(Far {
            screen: vt100::Parser::new(
                std::num::NonZeroU16::new(rows).expect("rows"),
                std::num::NonZeroU16::new(cols).expect("columns"),
                0,
            ),
            bytes: 0,
            closed: false,
            last_read: None,
            graphics: Vec::new(),
        }));
        let shared = far.clone();
        std::thread::spawn(move || {
            let start = Instant::now();
            let mut read = 0.0f64;
            let mut buf = vec![0u8; READ_MAX];
            // The end of the bytes delivered so far, for a query split between deliveries.
            let mut tail: Vec<u8> = Vec::new();
            let mut splitter = graphics::Splitter::default();
            loop {
                // A token bucket: what the link has carried by now, less what was read, at most
                // a burst.
                let carried = rate * start.elapsed().as_secs_f64();
                read = read.max(carried - rate * BURST.as_secs_f64());
                let allowed = (carried - read).floor();
                if allowed < 1.0 {
                    std::thread::sleep(TICK);
                    continue;
                }
                let want = (allowed as usize).min(READ_MAX);
                let n = if deep {
                    let mut b = buffer.lock().expect("the buffer");
                    if b.0.is_empty() {
                        if b.1 {
                            break;
                        }
                        drop(b);
                        std::thread::sleep(TICK);
                        continue;
                    }
                    let n = want.min(b.0.len());
                    for (d, s) in buf.iter_mut().zip(b.0.drain(..n)) {
                        *d = s;
                    }
                    n
                } else {
                    match reader.read(&mut buf[..want]) {
                        Ok(0) | Err(_) => break,
                        Ok(n) => n,
                    }
                };
                read += n as f64;
                let now = Instant::now();
                let mut far = shared.lock().expect("the far end");
                far.bytes += n;
                for piece in splitter.split(&buf[..n]) {
                    match piece {
                        graphics::Piece::Text(t) => far.screen.process(t),
                        graphics::Piece::Graphics(bytes) => {
                            let escape = Escape {
                                at: now,
                                read: far.bytes,
                                cursor: far.screen.screen().cursor_position(),
                                bytes,
                            };
                            far.graphics.push(escape);
                        }
                    }
                }
                far.last_read = Some(now);
                drop(far);
                if deep {
                    // Answer each query once the bytes before it are shown.
                    tail.extend_from_slice(&buf[..n]);
                    let queries = tail.windows(3).filter(|w| w == b"\x1b[c").count();
                    for _ in 0..queries {
                        let mut w = answers.lock().expect("the pty writer");
                        let _ = w.write_all(b"\x1b[?62;22c").and_then(|()| w.flush());
                    }
                    let keep = tail.len().min(2);
                    tail.drain(..tail.len() - keep);
                }
            }
            shared.lock().expect("the far end").closed = true;
        });
        SlowLink {
            child,
            master: pair.master,
            writer,
            far,
        }
    }

    /// Types `bytes` (the link's upstream is not throttled: keys are small).
    pub fn send(&mut self, bytes: &[u8]) {
        let mut w = self.writer.lock().expect("the pty writer");
        w.write_all(bytes).expect("write to the pty");
        w.flush().expect("flush the pty");
    }

    /// Waits until `cond` holds for the far end's screen, at most `limit`; whether it did.
    /// The screen is copied out of the lock, so judging it never holds up the link.
    pub fn wait_for(&self, limit: Duration, mut cond: impl FnMut(&vt100::Screen) -> bool) -> bool {
        let deadline = Instant::now() + limit;
        loop {
            if cond(&self.snapshot().0) {
                return true;
            }
            if Instant::now() > deadline {
                return false;
            }
            std::thread::sleep(TICK);
        }
    }

    /// A copy of the far end's screen, the bytes read and when the last were read.
    pub fn snapshot(&self) -> (vt100::Screen, usize, Option<Instant>) {
        let far = self.far.lock().expect("the far end");
        (far.screen.screen().clone(), far.bytes, far.last_read)
    }

    /// The graphics escapes read since the last call, oldest first.
    pub fn take_graphics(&self) -> Vec<Escape> {
        std::mem::take(&mut self.far.lock().expect("the far end").graphics)
    }

    /// The pty's master side (to resize it).
    pub fn master(&self) -> &dyn MasterPty {
        self.master.as_ref()
    }
}

impl Drop for SlowLink {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The two pixels a block-drawing cell shows (`▀`, `▄`, `█`, a space), if it is one.
pub fn shown_pixels(screen: &vt100::Screen, r: u16, c: u16) -> Option<(Colour, Colour)> {
    let cell = screen.cell(r, c)?;
    let rgb = |c: vt100::Color| match c {
        vt100::Color::Rgb(r, g, b) => Some(Colour::Rgb(r, g, b)),
        _ => None,
    };
    let (fg, bg) = (rgb(cell.fgcolor()), rgb(cell.bgcolor()));
    match cell.contents().chars().next().unwrap_or(' ') {
        '▀' => Some((fg?, bg?)),
        '▄' => Some((bg?, fg?)),
        '█' => Some((fg?, fg?)),
        ' ' => Some((bg?, bg?)),
        _ => None,
    }
}

/// The largest difference, in levels of one channel, between the screen's image rows and
/// `want`'s pixels; 256 where a cell is not a block cell at all.
pub fn max_error(screen: &vt100::Screen, want: &CellGrid) -> u16 {
    let d = |a: Colour, b: Colour| match (a, b) {
        (Colour::Rgb(r0, g0, b0), Colour::Rgb(r1, g1, b1)) => {
            r0.abs_diff(r1).max(g0.abs_diff(g1)).max(b0.abs_diff(b1)) as u16
        }
        _ => 256,
    };
    let mut worst = 0;
    for r in 0..want.rows {
        for c in 0..want.cols {
            let w = pixels(&want.get(c, r));
            let got = shown_pixels(screen, r as u16, c as u16);
            let e = match (w, got) {
                (Some(w), Some(g)) => d(w.0, g.0).max(d(w.1, g.1)),
                _ => 256,
            };
            worst = worst.max(e);
        }
    }
    worst
}

/// The image the app shows (truecolor, without its status line) in a `cols × rows` terminal
/// with the Cornell box seen from `camera` under `lights`.
pub fn app_image(camera: &Camera, lights: &[PointLight], cols: u16, rows: u16) -> CellGrid {
    let image = app_render(camera, lights, u32::from(cols), 2 * (u32::from(rows) - 1));
    CellGrid::from_image(&image, ColorMode::TrueColor)
}

/// The pixels the app shows in a pixel mode once exact (its image of `width × height`).
pub fn app_pixels(camera: &Camera, lights: &[PointLight], width: u32, height: u32) -> Vec<[u8; 3]> {
    app_render(camera, lights, width, height).to_rgb8()
}

/// The app's render of the Cornell box (its default stage, its tone map: none).
fn app_render(camera: &Camera, lights: &[PointLight], width: u32, height: u32) -> Image {
    let scene = cornell_box();
    let settings = Stage::Indirect.settings(scene.effects());
    scene
        .render(&Options {
            width,
            height,
            settings: Some(settings),
            camera: Some(*camera),
            lights: Some(lights),
            ..Options::default()
        })
        .image
}
