//! The app end to end in a real pseudo-terminal: the built binary runs in a pty, and what it
//! writes is parsed by a terminal emulator (vt100), so the assertions are about the screen a
//! user would see. Every wait is a bounded deadline loop on a condition, never a bare sleep.

use std::io::{Read, Write};
use std::num::NonZeroU16;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

#[path = "support/slow_link.rs"]
mod slow_link;

use glam::Vec3;
use portable_pty::{Child, CommandBuilder, MasterPty, PtySize, native_pty_system};
use raytty::frame::Colour;
use raytty::{CellGrid, cornell_box};

/// How long any one condition may take before the test fails: generous, for a loaded machine
/// (a 60×20 frame renders in milliseconds).
const TIMEOUT: Duration = Duration::from_secs(30);
/// How soon the app must exit once its pty is closed, or on a signal.
const EXIT_WITHIN: Duration = Duration::from_secs(5);
/// Between checks of whether the child has exited, or of a paused reader whether to go on.
const EXIT_POLL: Duration = Duration::from_millis(20);
/// The bound: after a signal the app is gone within this, even on a stalled link.
const EXIT_AFTER_SIGNAL: Duration = Duration::from_secs(2);

struct Session {
    child: Box<dyn Child + Send + Sync>,
    master: Option<Box<dyn MasterPty + Send>>,
    writer: Option<Box<dyn Write + Send>>,
    output: Receiver<Vec<u8>>,
    screen: vt100::Parser,
    /// Every byte the app wrote that the test has processed.
    raw: Vec<u8>,
    /// While set, the reader stops reading (a stalled link: the app's writes fill the pty).
    paused: Arc<AtomicBool>,
}

impl Session {
    /// Starts `raytty --color truecolor` in a `cols × rows` pty. If `first_frame_only`, the
    /// reader stops after the first complete frame (so that dropping the master closes the pty).
    fn start(cols: u16, rows: u16, first_frame_only: bool) -> Session {
        Session::start_with(cols, rows, first_frame_only, &[])
    }

    /// [`Session::start`] with more arguments for raytty.
    fn start_with(cols: u16, rows: u16, first_frame_only: bool, args: &[&str]) -> Session {
        Session::start_term(cols, rows, first_frame_only, args, "xterm-256color")
    }

    /// [`Session::start_with`] with `TERM` set to `term`.
    fn start_term(
        cols: u16,
        rows: u16,
        first_frame_only: bool,
        args: &[&str],
        term: &str,
    ) -> Session {
        Session::start_pixels(cols, rows, (0, 0), first_frame_only, args, term)
    }

    /// [`Session::start_term`] in a pty whose size says `pixels` (width, height; zero: not
    /// told, as many terminals leave it).
    fn start_pixels(
        cols: u16,
        rows: u16,
        pixels: (u16, u16),
        first_frame_only: bool,
        args: &[&str],
        term: &str,
    ) -> Session {
        let pair = native_pty_system()
            .openpty(PtySize {
                rows,
                cols,
                pixel_width: pixels.0,
                pixel_height: pixels.1,
            })
            .expect("open a pty");
        let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_raytty"));
        cmd.args(["--color", "truecolor", "--cells", "half"]);
        cmd.args(args);
        cmd.env("TERM", term);
        cmd.env_remove("NO_COLOR");
        // Not inside the test runner's tmux, if any: the queries go to this pty as they are.
        cmd.env_remove("TMUX");
        let child = pair.slave.spawn_command(cmd).expect("spawn raytty");
        drop(pair.slave);
        let mut reader = pair.master.try_clone_reader().expect("pty reader");
        let writer = pair.master.take_writer().expect("pty writer");
        let (tx, output) = mpsc::channel();
        let paused = Arc::new(AtomicBool::new(false));
        let pause = paused.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 65536];
            let mut seen = Vec::new();
            loop {
                while pause.load(Ordering::SeqCst) {
                    std::thread::sleep(EXIT_POLL);
                }
                let Ok(n @ 1..) = reader.read(&mut buf) else {
                    break;
                };
                if tx.send(buf[..n].to_vec()).is_err() {
                    break;
                }
                if first_frame_only {
                    seen.extend_from_slice(&buf[..n]);
                    if seen.windows(8).any(|w| w == b"\x1b[?2026l") {
                        break;
                    }
                }
            }
        });
        Session {
            child,
            master: Some(pair.master),
            writer: Some(writer),
            output,
            screen: vt100::Parser::new(nonzero(rows), nonzero(cols), 0),
            raw: Vec::new(),
            paused,
        }
    }

    fn process(&mut self, bytes: &[u8]) {
        self.screen.process(bytes);
        self.raw.extend_from_slice(bytes);
    }

    /// Reads output until `cond` holds for the screen; fails with the screen if it never does.
    fn wait_for(&mut self, what: &str, cond: impl Fn(&vt100::Screen) -> bool) {
        let deadline = Instant::now() + TIMEOUT;
        while !cond(self.screen.screen()) {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.output.recv_timeout(left) {
                Ok(bytes) => self.process(&bytes),
                Err(_) => panic!(
                    "timed out waiting for {what}; the screen shows:\n{}",
                    self.screen.screen().contents()
                ),
            }
        }
    }

    /// Waits until the status line (the last row) contains every one of `parts`.
    fn wait_for_status(&mut self, parts: &[&str]) {
        let what = format!("a status line with {parts:?}");
        self.wait_for(&what, |s| {
            let (rows, cols) = (s.size().0.get(), s.size().1.get());
            let line = s.contents_between(rows - 1, 0, rows - 1, cols);
            parts.iter().all(|p| line.contains(p))
        });
    }

    /// Reads output until the bytes written so far satisfy `cond`.
    fn wait_raw(&mut self, what: &str, cond: impl Fn(&[u8]) -> bool) {
        let deadline = Instant::now() + TIMEOUT;
        while !cond(&self.raw) {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.output.recv_timeout(left) {
                Ok(bytes) => self.process(&bytes),
                Err(_) => panic!("timed out waiting for {what}"),
            }
        }
    }

    /// Waits for the start's graphics queries (the kitty query, then DA1 last), then answers
    /// them with `answer` as a terminal would.
    fn answer_queries(&mut self, answer: &[u8]) {
        self.wait_raw("the graphics queries", |raw| {
            find(raw, b"a=q").is_some_and(|at| find(&raw[at..], b"\x1b[c").is_some())
        });
        self.send(answer);
    }

    fn send(&mut self, bytes: &[u8]) {
        let w = self.writer.as_mut().expect("the pty is open");
        w.write_all(bytes).expect("write to the pty");
        w.flush().expect("flush the pty");
    }

    /// Reads everything until the pty closes, then the child's exit status.
    fn finish(&mut self) -> portable_pty::ExitStatus {
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.output.recv_timeout(left) {
                Ok(bytes) => self.process(&bytes),
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
                Err(mpsc::RecvTimeoutError::Timeout) => panic!("the app did not exit"),
            }
        }
        self.wait_exit(TIMEOUT)
    }

    /// The child's exit status, failing if it takes longer than `limit`.
    fn wait_exit(&mut self, limit: Duration) -> portable_pty::ExitStatus {
        let deadline = Instant::now() + limit;
        loop {
            if let Some(status) = self.child.try_wait().expect("query the child") {
                return status;
            }
            if Instant::now() > deadline {
                let _ = self.child.kill();
                panic!("the app was still running {limit:?} later");
            }
            std::thread::sleep(EXIT_POLL);
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// The cells the library gives for the default view with these changes, `cols × rows` cells
/// of image (the status line is not included).
fn expected(cols: u16, rows: u16, camera_z: f32, light_y: f32) -> CellGrid {
    let scene = cornell_box();
    let mut camera = scene.camera();
    camera.position += camera.forward() * camera_z;
    let mut lights = scene.lights().to_vec();
    lights[0].position += camera.to_world(Vec3::new(0.0, light_y, 0.0));
    slow_link::app_image(&camera, &lights, cols, rows)
}

/// Where `part` first occurs in `bytes`.
fn find(bytes: &[u8], part: &[u8]) -> Option<usize> {
    bytes.windows(part.len()).position(|w| w == part)
}

fn nonzero(n: u16) -> NonZeroU16 {
    NonZeroU16::new(n).expect("a terminal size is not zero")
}

fn rgb(c: vt100::Color) -> Option<Colour> {
    match c {
        vt100::Color::Rgb(r, g, b) => Some(Colour::Rgb(r, g, b)),
        _ => None,
    }
}

/// The (upper, lower) pixel colours a block-drawing cell shows, whichever of the
/// equivalent ways it was drawn (`▀` or `▄` with the colours swapped, a space or a full block);
/// `None` for any other character.
fn pixels(
    ch: char,
    fg: Option<Colour>,
    bg: Option<Colour>,
) -> Option<(Option<Colour>, Option<Colour>)> {
    match ch {
        '▀' => Some((fg, bg)),
        '▄' => Some((bg, fg)),
        '█' => Some((fg, fg)),
        ' ' => Some((bg, bg)),
        _ => None,
    }
}

/// The pixels the terminal shows at (row, col), if the cell is a block-drawing one.
fn shown_pixels(
    screen: &vt100::Screen,
    r: u16,
    c: u16,
) -> Option<(Option<Colour>, Option<Colour>)> {
    let got = screen.cell(r, c)?;
    let ch = got.contents().chars().next().unwrap_or(' ');
    pixels(ch, rgb(got.fgcolor()), rgb(got.bgcolor()))
}

/// Whether the screen's image rows show exactly `grid`: the same two pixels in every cell.
fn shows(screen: &vt100::Screen, grid: &CellGrid) -> bool {
    (0..grid.rows).all(|r| {
        (0..grid.cols).all(|c| {
            let want = grid.get(c, r);
            let want = pixels(want.ch, want.fg, want.bg);
            want.is_some() && shown_pixels(screen, r as u16, c as u16) == want
        })
    })
}

#[test]
fn the_first_frame_shows_the_box_in_truecolor_half_blocks() {
    // Wide enough for the whole status line.
    let mut s = Session::start(120, 13, false);
    let want = expected(120, 13, 0.0, 0.0);
    s.wait_for("the default frame", |scr| shows(scr, &want));
    let screen = s.screen.screen();
    assert!(screen.alternate_screen() && screen.hide_cursor());
    // The seed's walls, purple on the left and yellow on the right, as the terminal shows them:
    // the box's front opening spans the 24-pixel-high image's middle 24 columns (48-71).
    let left = shown_pixels(screen, 6, 50).unwrap().1;
    let right = shown_pixels(screen, 6, 69).unwrap().1;
    assert!(
        matches!(left, Some(Colour::Rgb(r, g, b)) if r as u16 > 2 * g as u16 && b as u16 > 2 * g as u16),
        "{left:?}"
    );
    assert!(
        matches!(right, Some(Colour::Rgb(r, g, b)) if r as u16 > 2 * b as u16 && g as u16 > 2 * b as u16),
        "{right:?}"
    );
    s.wait_for_status(&["5:indirect", "truecolor", "cornell"]);
}

#[test]
fn the_light_keys_and_the_arrows_change_the_cells_they_should() {
    let mut s = Session::start(120, 13, false);
    s.wait_for("the default frame", |scr| {
        shows(scr, &expected(120, 13, 0.0, 0.0))
    });
    s.send(b"q");
    let lifted = expected(120, 13, 0.0, -0.1);
    s.wait_for("the frame with the light moved up", |scr| {
        shows(scr, &lifted)
    });
    s.send(b"\x1b[A");
    let closer = expected(120, 13, 0.1, -0.1);
    assert_ne!(lifted, closer);
    s.wait_for("the frame after a step forward", |scr| shows(scr, &closer));
    s.wait_for_status(&["cam 0.00,0.00,-2.90", "light 0.00,-0.60,-0.70"]);
    s.send(b"\x1b[D");
    s.wait_for("the frame after a turn left", |scr| {
        !shows(scr, &closer) && scr.contents().contains("-5°")
    });
}

#[test]
fn a_resize_gives_a_frame_of_the_new_size() {
    let mut s = Session::start(40, 13, false);
    s.wait_for("the default frame", |scr| {
        shows(scr, &expected(40, 13, 0.0, 0.0))
    });
    let size = PtySize {
        rows: 20,
        cols: 60,
        pixel_width: 0,
        pixel_height: 0,
    };
    s.master.as_ref().unwrap().resize(size).expect("resize");
    s.screen.set_size(nonzero(20), nonzero(60));
    let bigger = expected(60, 20, 0.0, 0.0);
    s.wait_for("a 60x20 frame", |scr| shows(scr, &bigger));
    s.wait_for_status(&["5:indirect"]);
}

#[test]
fn esc_and_ctrl_c_exit_0_and_leave_the_alternate_screen() {
    for key in [&b"\x1b"[..], b"\x03"] {
        let mut s = Session::start(30, 10, false);
        s.wait_for("the app's screen", |scr| scr.alternate_screen());
        s.wait_for_status(&["indirect"]);
        s.send(key);
        let status = s.finish();
        assert!(status.success(), "{key:?}: {status:?}");
        let screen = s.screen.screen();
        assert!(
            !screen.alternate_screen(),
            "{key:?}: still on the alternate screen"
        );
        assert!(!screen.hide_cursor(), "{key:?}: the cursor is still hidden");
    }
}

#[test]
fn c_cycles_the_colour_mode_live() {
    let mut s = Session::start(120, 13, false);
    s.wait_for_status(&["truecolor"]);
    s.send(b"c");
    s.wait_for("256-colour cells", |scr| {
        matches!(
            scr.cell(6, 50).map(|c| c.bgcolor()),
            Some(vt100::Color::Idx(_))
        )
    });
    s.wait_for_status(&[" 256 "]);
    s.send(b"c");
    s.wait_for("ASCII cells", |scr| {
        scr.cell(6, 50).map(|c| c.bgcolor()) == Some(vt100::Color::Default)
    });
    s.wait_for_status(&["ascii"]);
}

/// A panic in the app (forced by a debug build's `RAYTTY_TEST_PANIC`) restores the terminal
/// before std's message, which names the panic, and exits with std's status for it, 101.
#[test]
fn a_panic_restores_the_terminal_and_exits_101() {
    let pair = native_pty_system()
        .openpty(PtySize {
            rows: 10,
            cols: 30,
            pixel_width: 0,
            pixel_height: 0,
        })
        .expect("open a pty");
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_raytty"));
    cmd.env("TERM", "xterm-256color");
    cmd.env("RAYTTY_TEST_PANIC", "1");
    let mut child = pair.slave.spawn_command(cmd).expect("spawn raytty");
    drop(pair.slave);
    let mut reader = pair.master.try_clone_reader().expect("pty reader");
    let mut raw = Vec::new();
    let mut buf = [0u8; 4096];
    while let Ok(n @ 1..) = reader.read(&mut buf) {
        raw.extend_from_slice(&buf[..n]);
        if child.try_wait().expect("query the child").is_some() {
            break;
        }
    }
    let status = child.wait().expect("wait for raytty");
    let text = String::from_utf8_lossy(&raw);
    let panicked = text.find("RAYTTY_TEST_PANIC is set").expect(&text);
    let left = text
        .rfind("\x1b[?1049l")
        .expect("the alternate screen is left");
    assert!(left < panicked, "restored after the message: {text:?}");
    assert!(text.contains("panicked at"), "{text:?}");
    assert_eq!(status.exit_code(), 101, "{text:?}");
}

#[test]
fn sigterm_restores_the_terminal() {
    let mut s = Session::start(30, 10, false);
    s.wait_for_status(&["indirect"]);
    let pid = s.child.process_id().expect("pid");
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .expect("run kill");
    assert!(killed.success());
    let status = s.finish();
    assert_eq!(status.exit_code(), 128 + 15);
    assert!(!s.screen.screen().alternate_screen());
    assert!(!s.screen.screen().hide_cursor());
}

#[test]
fn closing_the_pty_ends_the_app_within_seconds() {
    let mut s = Session::start(30, 10, true);
    s.wait_for_status(&["indirect"]);
    // Wait for the reader to finish, so that the master below is the last handle on the pty.
    while s.output.recv_timeout(TIMEOUT).is_ok() {}
    drop(s.writer.take());
    drop(s.master.take());
    s.wait_exit(EXIT_WITHIN);
}

#[test]
fn the_app_shows_the_scene_given_with_scene() {
    let mut s = Session::start_with(120, 13, false, &["--scene", "lights"]);
    s.wait_for_status(&["lights", "5:indirect"]);
    // Three coloured lights on white walls: the frame is not the Cornell box's.
    let cornell = expected(120, 13, 0.0, 0.0);
    assert!(!shows(s.screen.screen(), &cornell));
    s.send(b"\x03");
    assert!(s.finish().success());
}

#[test]
fn a_bad_scene_is_refused_before_the_terminal_is_touched() {
    let mut s = Session::start_with(100, 10, false, &["--scene", "no-such-scene"]);
    let status = s.finish();
    assert_eq!(status.exit_code(), 2);
    let screen = s.screen.screen();
    assert!(!screen.alternate_screen() && !screen.hide_cursor());
    let text = screen.contents();
    assert!(
        text.contains("no-such-scene") && text.contains("cornell, mirror, lights, sphere"),
        "{text}"
    );
}

#[test]
fn the_loading_note_is_erased_when_the_app_ends_and_before_an_error() {
    let mut s = Session::start(60, 10, false);
    s.wait_for_status(&["indirect"]);
    s.send(b"\x1b");
    assert!(s.finish().success());
    let shown = s.screen.screen().contents();
    assert!(!shown.contains("loading"), "{shown}");
    let mut s = Session::start_with(100, 10, false, &["--scene", "no-such-scene"]);
    assert_eq!(s.finish().exit_code(), 2);
    let shown = s.screen.screen().contents();
    assert!(
        shown.starts_with("raytty: --scene no-such-scene"),
        "{shown}"
    );
}

#[test]
fn a_dumb_terminal_gets_one_frame_not_the_app() {
    let mut s = Session::start_term(100, 40, false, &[], "dumb");
    let status = s.finish();
    assert!(status.success(), "{status:?}");
    let shown = s.screen.screen().contents();
    // The app would have left the alternate screen and with it the frame; a printed frame
    // stays on the main screen, under the note that says why.
    assert!(shown.contains("TERM=dumb"), "{shown}");
    assert!(shown.contains('▀'), "{shown}");
    assert!(!shown.contains("H:help"), "{shown}");
}

/// The state letter of process `pid` (`T` when stopped), from /proc.
#[cfg(target_os = "linux")]
fn process_state(pid: u32) -> Option<char> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // After the parenthesised command name: " S ...".
    stat.rsplit_once(')')?.1.trim_start().chars().next()
}

#[test]
#[cfg(target_os = "linux")]
fn ctrl_z_gives_the_terminal_back_and_continuing_redraws() {
    let mut s = Session::start(40, 12, false);
    s.wait_for_status(&["indirect"]);
    let pid = s.child.process_id().expect("pid");
    s.send(b"\x1a");
    s.wait_for("the main screen and a visible cursor", |sc| {
        !sc.alternate_screen() && !sc.hide_cursor()
    });
    let deadline = Instant::now() + TIMEOUT;
    while process_state(pid) != Some('T') {
        assert!(Instant::now() < deadline, "raytty did not stop on Ctrl-Z");
        std::thread::yield_now();
    }
    let continued = std::process::Command::new("kill")
        .args(["-CONT", &pid.to_string()])
        .status()
        .expect("run kill");
    assert!(continued.success());
    s.wait_for("the app's screen again", |sc| {
        sc.alternate_screen() && sc.hide_cursor()
    });
    s.wait_for_status(&["indirect"]);
    s.send(b"\x1b");
    assert!(s.finish().success());
}

#[test]
fn an_arrow_split_across_reads_moves_the_camera_and_does_not_quit() {
    let mut s = Session::start(120, 10, false);
    s.wait_for_status(&["cam 0.00,0.00,-3.00"]);
    // A slow or choppy link delivers the three bytes of Up apart; these gaps are the input
    // under test, not waits (the app's ESC delay is tens of milliseconds).
    for part in [&b"\x1b"[..], b"[", b"A"] {
        s.send(part);
        std::thread::sleep(Duration::from_millis(5));
    }
    s.wait_for_status(&["cam 0.00,0.00,-2.90"]);
    assert!(s.child.try_wait().expect("query the child").is_none());
    // A lone Esc still quits, once nothing follows it.
    s.send(b"\x1b");
    assert!(s.finish().success());
}

/// The master's unread bytes: when they stop being read, the app's writes fill the pty.
#[cfg(target_os = "linux")]
fn unread(master: &dyn MasterPty) -> usize {
    let fd = master.as_raw_fd().expect("a unix pty");
    let mut n: libc::c_int = 0;
    // SAFETY: FIONREAD stores an int.
    unsafe { libc::ioctl(fd, libc::FIONREAD, &mut n) };
    n as usize
}

#[test]
#[cfg(target_os = "linux")]
fn a_signal_ends_the_app_in_time_and_restores_even_when_the_link_is_stalled() {
    for (sig, name) in [
        (libc::SIGTERM, "TERM"),
        (libc::SIGINT, "INT"),
        (libc::SIGHUP, "HUP"),
    ] {
        let mut s = Session::start(300, 100, false);
        s.wait_for_status(&["indirect"]);
        // The terminal stops reading (a stalled SSH connection) while keys keep coming.
        s.paused.store(true, Ordering::SeqCst);
        let deadline = Instant::now() + TIMEOUT;
        // The app writes new frames into the pty until it holds 4000 unread bytes. The light
        // goes back and forth, 20 presses at a time, so every batch changes the frame (the
        // reader may have taken one last chunk as it paused, and a light far out of the box
        // changes nothing).
        let full = |s: &Session| unread(s.master.as_deref().unwrap()) >= 4000;
        for batch in 0.. {
            if full(&s) {
                break;
            }
            assert!(
                Instant::now() < deadline,
                "SIG{name}: the app wrote no new frame"
            );
            s.send(&[if batch % 2 == 0 { b'd' } else { b'a' }; 20]);
            let next_batch = Instant::now() + Duration::from_millis(300);
            while !full(&s) && Instant::now() < next_batch {
                std::thread::sleep(EXIT_POLL);
            }
        }
        let pid = s.child.process_id().expect("pid");
        let killed = std::process::Command::new("kill")
            .args([&format!("-{name}"), &pid.to_string()])
            .status()
            .expect("run kill");
        assert!(killed.success());
        let status = s.wait_exit(EXIT_AFTER_SIGNAL);
        assert_eq!(status.exit_code(), 128 + sig as u32, "SIG{name}");
        // Cooked mode again, although the terminal has read nothing since.
        let termios = s.master.as_ref().unwrap().get_termios().expect("termios");
        let local = termios.local_flags.bits() as libc::tcflag_t;
        assert!(
            local & libc::ICANON != 0 && local & libc::ECHO != 0,
            "SIG{name}: still in raw mode"
        );
        // Once the link resumes, the screen is the shell's again.
        s.paused.store(false, Ordering::SeqCst);
        drop(s.writer.take());
        drop(s.master.take());
        s.finish();
        let screen = s.screen.screen();
        assert!(
            !screen.alternate_screen() && !screen.hide_cursor(),
            "SIG{name}: the terminal was not restored"
        );
    }
}

/// A scene file in the temporary directory named `name`; removed when dropped.
struct SceneFile(std::path::PathBuf);

impl SceneFile {
    fn named(name: &str, tag: &str) -> SceneFile {
        let path = std::env::temp_dir().join(format!("raytty-{tag}-{}.toml", std::process::id()));
        let source = format!(
            "name = \"{name}\"\n[material.m]\ncolour = [1, 1, 1]\n[[object]]\nkind = \"box\"\nmaterial = \"m\"\ncentre = [0, 0, 0]\nsize = [1, 1, 1]\n"
        );
        std::fs::write(&path, source).expect("write a scene file");
        SceneFile(path)
    }

    fn path(&self) -> &str {
        self.0.to_str().expect("a UTF-8 temporary path")
    }
}

impl Drop for SceneFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn wide_and_bidi_scene_names_keep_the_status_line_on_one_row() {
    let wide = SceneFile::named(&"漢".repeat(200), "wide");
    let mut s = Session::start_with(80, 12, false, &["--scene", wide.path()]);
    s.wait_for_status(&["漢漢漢"]);
    let screen = s.screen.screen();
    let above = screen.contents_between(10, 0, 10, 80);
    assert!(!above.contains('漢'), "the status line wrapped: {above:?}");
    // The row above the status line is still the image: block cells with colours.
    assert!(shown_pixels(screen, 10, 40).is_some_and(|(up, lo)| up.is_some() && lo.is_some()));
    s.send(b"\x1b");
    assert!(s.finish().success());

    let bidi = SceneFile::named("evil\u{202e}box\u{2066}x\u{200b}", "bidi");
    let mut s = Session::start_with(80, 12, false, &["--scene", bidi.path()]);
    s.wait_for_status(&["evilboxx"]);
    s.send(b"\x1b");
    assert!(s.finish().success());
    for c in ['\u{202e}', '\u{2066}', '\u{200b}'] {
        let mut utf8 = [0; 4];
        let bytes = c.encode_utf8(&mut utf8).as_bytes();
        assert!(
            !s.raw.windows(bytes.len()).any(|w| w == bytes),
            "{c:?} reached the terminal"
        );
    }
}

#[test]
fn over_a_slow_link_a_move_is_sent_approximately_then_settles_exact() {
    // 60 kB/s: the first 100x30 frame (about 70 kB) fills the pty, so the app measures the
    // link; a light move of five steps is then far over a frame's budget (about 3 kB).
    let (cols, rows) = (100u16, 30u16);
    let mut link = slow_link::SlowLink::start(
        env!("CARGO_BIN_EXE_raytty"),
        &["--color", "truecolor"],
        cols,
        rows,
        60_000.0,
    );
    let start = expected(cols, rows, 0.0, 0.0);
    assert!(
        link.wait_for(TIMEOUT, |s| slow_link::max_error(s, &start) == 0),
        "the first frame never showed"
    );
    link.send(b"wwwww");
    let scene = cornell_box();
    let camera = scene.camera();
    let mut lights = scene.lights().to_vec();
    for _ in 0..5 {
        lights[0].position += camera.to_world(Vec3::new(0.0, 0.0, 1.0) * (0.1 * 1.0));
    }
    let moved = slow_link::app_image(&camera, &lights, cols, rows);
    settles_after_approximate(&mut link, &moved, rows, cols, "the link was not measured");
}

/// Waits until `link`'s screen is `moved` exactly with no `approximate` in the status line
/// (row `rows - 1`), and asserts that the status line said `approximate` on the way (for many
/// frames on a slow link); `why` says what its absence means.
fn settles_after_approximate(
    link: &mut slow_link::SlowLink,
    moved: &CellGrid,
    rows: u16,
    cols: u16,
    why: &str,
) {
    let mut seen_approximate = false;
    let settled = link.wait_for(TIMEOUT, |s| {
        let status = s.contents_between(rows - 1, 0, rows - 1, cols);
        seen_approximate |= status.contains("approximate");
        slow_link::max_error(s, moved) == 0 && !status.contains("approximate")
    });
    assert!(settled, "the screen never settled on the exact frame");
    assert!(
        seen_approximate,
        "the move was never shown approximately: {why}"
    );
}

#[test]
fn behind_a_deep_buffer_a_terminal_that_answers_paces_the_frames() {
    // As over SSH: the pty drains at once into a deep buffer, the link behind it carries
    // 60 kB/s, and the far end answers each device-attributes query once it has shown what came
    // before. Writes never block, so only the answers can show the link is slow: a light move
    // is then sent approximately (a budget, so a measured rate: writes never block here).
    let (cols, rows) = (100u16, 30u16);
    let mut link = slow_link::SlowLink::start_behind_buffer(
        env!("CARGO_BIN_EXE_raytty"),
        &["--color", "truecolor"],
        cols,
        rows,
        60_000.0,
    );
    let start = expected(cols, rows, 0.0, 0.0);
    assert!(
        link.wait_for(TIMEOUT, |s| slow_link::max_error(s, &start) == 0),
        "the first frame never showed"
    );
    // One step first, shown exact: by then the first frame's answer has measured the link
    // (keys sent the instant the first frame shows would race that answer).
    let scene = cornell_box();
    let camera = scene.camera();
    let mut lights = scene.lights().to_vec();
    let step = camera.to_world(Vec3::new(0.0, 0.0, 1.0) * (0.1 * 1.0));
    lights[0].position += step;
    let one = slow_link::app_image(&camera, &lights, cols, rows);
    link.send(b"w");
    assert!(
        link.wait_for(TIMEOUT, |s| slow_link::max_error(s, &one) == 0),
        "the first step never showed"
    );
    link.send(b"wwww");
    for _ in 0..4 {
        lights[0].position += step;
    }
    let moved = slow_link::app_image(&camera, &lights, cols, rows);
    settles_after_approximate(
        &mut link,
        &moved,
        rows,
        cols,
        "the answers did not measure the link",
    );
    // The answers were consumed as answers: nothing typed reached the app as keys (a reply
    // read as keys would be Esc, `[`, `?`... and Esc quits).
    assert!(link.child.try_wait().expect("the child's status").is_none());
}

/// The status line (the last row) of the screen.
fn status_line(s: &vt100::Screen) -> String {
    let (rows, cols) = (s.size().0.get(), s.size().1.get());
    s.contents_between(rows - 1, 0, rows - 1, cols)
}

#[test]
fn a_terminal_that_answers_kitty_gets_one_image_replaced_in_place_and_deleted_on_quit() {
    let mut s = Session::start_with(60, 13, false, &["--graphics", "auto"]);
    // kitty's answer, a cell of 8×16 pixels, and DA1 (which lists sixel too: kitty is first).
    s.answer_queries(b"\x1b_Gi=31;OK\x1b\\\x1b[6;16;8t\x1b[?62;4;22c");
    s.wait_for_status(&["kitty 480x192", "cornell"]);
    let at = find(&s.raw, b"\x1b[c").unwrap();
    let image = b"\x1b[H\x1b_Ga=T,f=24,o=z,q=2,s=480,v=192,i=1,p=1,c=60,r=12,C=1";
    assert!(
        find(&s.raw[at..], image).is_some(),
        "the frame as one kitty image"
    );
    // A light move sends the image again under the same id (replaced in place).
    s.send(b"q");
    s.wait_raw("a second image", |raw| {
        raw.windows(12).filter(|w| *w == b"i=1,p=1,c=60").count() >= 2
    });
    s.send(b"\x1b");
    assert_eq!(s.finish().exit_code(), 0);
    let delete = find(&s.raw, b"\x1b_Ga=d,d=A,q=2\x1b\\").expect("the images deleted");
    let leave = find(&s.raw, b"\x1b[?1049l").expect("the alternate screen left");
    assert!(delete < leave);
}

#[test]
fn a_terminal_that_lists_sixel_and_tells_its_size_gets_sixel_frames() {
    // The cell size from the pty's own pixel fields (TIOCGWINSZ): 6×12.
    let mut s = Session::start_pixels(60, 13, (360, 156), false, &[], "xterm-256color");
    s.answer_queries(b"\x1b[?63;1;2;4;6;9;15;22c");
    s.wait_for_status(&["sixel 360x144"]);
    assert!(find(&s.raw, b"\x1b[H\x1bP0;1;0q\"1;1;360;144").is_some());
    // A terminal that draws no sixel image over 300×300 (XTSMGRAPHICS) gets the same view in
    // fewer pixels.
    let mut small = Session::start_pixels(60, 13, (360, 156), false, &[], "xterm-256color");
    small.answer_queries(b"\x1b[?2;0;300;300S\x1b[?63;1;2;4;6;9;15;22c");
    small.wait_for_status(&["sixel 300x120"]);
    // G turns the pixels off: text cells, exactly the text frame.
    s.send(b"g");
    s.wait_for("the text frame", |scr| {
        shows(scr, &expected(60, 13, 0.0, 0.0))
    });
    s.send(b"\x1b");
    assert_eq!(s.finish().exit_code(), 0);
}

#[test]
fn a_terminal_that_does_not_answer_gets_text_and_nothing_of_the_queries_on_screen() {
    let mut s = Session::start_with(60, 13, false, &[]);
    s.wait_for("the text frame", |scr| {
        shows(scr, &expected(60, 13, 0.0, 0.0))
    });
    let at = find(&s.raw, b"a=q").expect("the terminal was asked");
    assert!(
        find(&s.raw[at..], b"\x1b[2J").is_some(),
        "cleared after asking"
    );
    let status = status_line(s.screen.screen());
    assert!(
        !status.contains("kitty") && !status.contains("sixel"),
        "{status}"
    );
    // Nothing asked with --graphics none.
    let mut none = Session::start_with(60, 13, false, &["--graphics", "none"]);
    none.wait_for("the text frame", |scr| {
        shows(scr, &expected(60, 13, 0.0, 0.0))
    });
    assert!(find(&none.raw, b"a=q").is_none());
}

#[test]
fn wrong_answers_are_not_believed_and_a_late_answer_is_not_keys() {
    let mut s = Session::start_with(60, 13, false, &[]);
    // An error from kitty, a zero cell, DA1 listing sixel (but no size known): text.
    s.answer_queries(b"\x1b_Gi=31;EINVAL:nope\x1b\\\x1b[6;0;0t\x1b[?62;4c");
    s.wait_for("the text frame", |scr| {
        shows(scr, &expected(60, 13, 0.0, 0.0))
    });
    let status = status_line(s.screen.screen());
    assert!(
        !status.contains("kitty") && !status.contains("sixel"),
        "{status}"
    );
    // Answers arriving after the start are swallowed: `=` in them would zoom, `-` unzoom.
    s.send(b"\x1b_Gi=31;OK\x1b\\\x1b[6;20;10t\x1b[4;240;600t\x1b[?62;4cq");
    s.wait_for("the frame with the light moved up, unzoomed", |scr| {
        shows(scr, &expected(60, 13, 0.0, -0.1))
    });
    s.send(b"\x1b");
    assert_eq!(s.finish().exit_code(), 0);
}

/// A model file that never finishes loading: a FIFO named `….ply` that nobody writes (opening
/// it blocks), so the load is still under way whenever the test looks. Removed when dropped.
struct StuckModel(std::path::PathBuf);

impl StuckModel {
    fn new(tag: &str) -> StuckModel {
        let path =
            std::env::temp_dir().join(format!("raytty-stuck-{tag}-{}.ply", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let c = std::ffi::CString::new(path.to_str().expect("a UTF-8 temporary path"))
            .expect("no NUL in the path");
        // SAFETY: a valid C string; mkfifo only reads it.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
        StuckModel(path)
    }
}

impl Drop for StuckModel {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// A load past half a second shows a bar on stderr; Ctrl-C then ends raytty with 130, the bar
/// erased, no output file made, the terminal never taken (the app's) — in `render` and in the
/// app.
#[test]
fn ctrl_c_during_a_models_load_exits_130_with_the_bar_cleared() {
    let model = StuckModel::new("ctrl-c");
    let path = model.0.to_str().expect("a UTF-8 temporary path");
    let out = std::env::temp_dir().join(format!("raytty-stuck-{}.png", std::process::id()));
    let out_s = out.to_str().expect("a UTF-8 temporary path");
    for args in [vec![path, "render", "-o", out_s], vec![path]] {
        let mut s = Session::start_with(100, 10, false, &args);
        s.wait_for("the load's bar", |screen| {
            screen.contents().contains("raytty: loading raytty-stuck-")
                && screen.contents().contains(": reading")
        });
        s.send(b"\x03");
        let status = s.finish();
        let shown = s.screen.screen().contents();
        assert_eq!(status.exit_code(), 130, "{args:?}: {shown}");
        assert!(!shown.contains("loading"), "{args:?}: {shown}");
        assert!(find(&s.raw, b"\x1b[?1049h").is_none(), "{args:?}");
        assert!(!out.exists(), "{args:?}");
    }
}
