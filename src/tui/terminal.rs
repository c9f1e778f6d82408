//! The only code that touches the terminal: raw mode and the alternate screen (through
//! [`tty`](super::tty)), the event loop, and the ways out. The terminal is restored on every
//! exit path:
//! - quit (Esc, Ctrl-C), an I/O error, or a dropped tty: [`Guard`]'s `Drop` as `run` returns;
//! - a panic, on any thread: the panic hook restores before the default hook prints;
//! - SIGTERM, SIGHUP, SIGINT, SIGQUIT: the signal thread turns them into a quit the loop sees
//!   at once (no write can hold it up: frames are written by the writer thread, non-blocking);
//!   if the loop is busy (a long render) the signal thread restores and exits itself after
//!   [`FORCED_EXIT_AFTER`], with the status the binary gives that signal.
//!
//! Idle means idle: with nothing to render or write the loop blocks on its channel. Input comes
//! from a reader thread that stops on end-of-file or EIO, from the signal thread, and from the
//! writer thread (a frame is written).

use std::io::{self, IsTerminal};
use std::os::fd::{AsRawFd, RawFd};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use crossterm::event::KeyEvent;
use raytty::frame::CellMode;
use raytty::{ColorMode, Scene};
use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGSTOP, SIGTERM, SIGWINCH};
use signal_hook::iterator::Signals;

use super::app::{App, Message, update};
use super::detect::{self, Answers, Choice, Protocol};
use super::input::{ACK_QUERY, ESC_DELAY, KeyParser};
use super::keys::message_for;
use super::link::{ACK_WAIT, Acks, Link};
use super::tty;
use super::view::{GI_MAX_PASSES, LinkView, Screen};

/// While refining, a new average is drawn at most this often: a few frames a second.
const REFINE_DRAW_INTERVAL: Duration = Duration::from_millis(250);
/// After a terminating signal the loop has this long to restore and exit before the signal
/// thread does it. With [`tty::restore`]'s bounded drain the process is gone within 2 s.
const FORCED_EXIT_AFTER: Duration = Duration::from_secs(1);
/// The writer checks this often whether its frame is still wanted while the terminal takes
/// nothing (a stalled link).
const WRITER_POLL: Duration = Duration::from_millis(100);

/// While the terminal's answers are due and no frame is waiting, the writer looks for them
/// this often.
const ACK_POLL: Duration = Duration::from_millis(5);

/// The writer never waits longer than this for the queue to drain before taking the next
/// frame, whatever the link model says (a wrong estimate must not stall the app).
const MAX_PACING_WAIT: Duration = Duration::from_millis(250);

/// On quitting, how long the app waits for the terminal to answer the queries still
/// outstanding (an answer arriving after the restore would be echoed on the shell's line).
const QUIT_ACK_WAIT: Duration = Duration::from_millis(300);
/// How long the start waits for the terminal's answers to the graphics queries. Every
/// terminal answers the DA1 that ends them (over ssh, a round trip later), so this is waited
/// out only by one that answers nothing. Generous: kitty drawing in software on a loaded
/// machine took longer than 400 ms to answer its first queries.
const DETECT_TIMEOUT: Duration = Duration::from_millis(1000);
/// Inside tmux, how long after tmux's own DA1 answer the outer terminal's answer to the kitty
/// query is waited for (tmux 3.3a with allow-passthrough on, in kitty: 7 ms; with passthrough
/// off, none ever comes).
const TMUX_ANSWER_WAIT: Duration = Duration::from_millis(250);

/// Queries written and not answered yet (the writer adds, the reader takes away).
static UNANSWERED: AtomicUsize = AtomicUsize::new(0);
/// The terminal answers queries (set by the writer).
static ACKS_ON: AtomicBool = AtomicBool::new(false);

/// How the app ended; the binary turns it into an exit status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The user quit (Esc, Ctrl-C).
    Quit,
    /// A terminating signal arrived (its number).
    Signal(i32),
    /// The terminal went away (end-of-file or EIO on the tty).
    Hangup,
}

/// What the loop waits for.
enum Input {
    Key(KeyEvent),
    /// A mouse drag or wheel notch.
    Mouse(super::input::Mouse),
    /// The terminal was resized (SIGWINCH).
    Resize,
    /// The tty gave end-of-file or an error: the connection is gone.
    Hangup,
    /// A terminating signal.
    Signal(i32),
    /// The writer is done with a frame (or could not write it), and what it now knows of the
    /// link.
    Written(io::Result<LinkView>),
    /// The terminal's answers measured the link anew between frames.
    Link(LinkView),
}

/// A frame for the writer, tagged with the terminal's epoch it was encoded for, and how long
/// it took to encode (the writer comes back for the next one that long before the link would
/// run dry).
struct Job {
    epoch: u64,
    bytes: Vec<u8>,
    encode: Duration,
}

/// Holds the terminal in raw mode on the alternate screen; restores it when dropped.
struct Guard;

impl Guard {
    fn enter(input: RawFd) -> Result<Guard> {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            tty::restore();
            prev(info);
        }));
        tty::open(input).context("cannot open the terminal")?;
        let guard = Guard;
        tty::take().context("cannot put the terminal in raw mode")?;
        Ok(guard)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        tty::restore();
    }
}

/// Ctrl-Z: gives the terminal back as it was, stops the process (as the shell's job control
/// expects; SIGSTOP, because raw mode turned the key into a byte rather than SIGTSTP), and once
/// continued (`fg`) takes the terminal again. The caller redraws every cell.
fn suspend() -> Result<()> {
    tty::restore();
    signal_hook::low_level::raise(SIGSTOP).context("cannot suspend")?;
    tty::take().context("cannot take the terminal back")
}

/// Runs the app on the terminal until the user quits, the terminal goes away or a signal
/// arrives, and says which.
pub fn run(scene: Scene, color: ColorMode, cells: CellMode, graphics: Choice) -> Result<Outcome> {
    let stdin = io::stdin();
    let dev_tty;
    let input: RawFd = if stdin.is_terminal() {
        stdin.as_raw_fd()
    } else {
        dev_tty = std::fs::File::open("/dev/tty").context("cannot open /dev/tty to read keys")?;
        dev_tty.as_raw_fd()
    };
    let (tx, rx) = mpsc::channel();
    let signals = Signals::new([SIGWINCH, SIGTERM, SIGHUP, SIGINT, SIGQUIT])
        .context("cannot install signal handlers")?;
    let guard = Guard::enter(input)?;
    spawn_signal_thread(signals, tx.clone());
    let size = tty::size().context("cannot read the terminal size")?;
    let tmux = std::env::var_os("TMUX").is_some();
    let found = detect(input, graphics, size, tmux);
    let (ack_tx, ack_rx) = mpsc::channel();
    spawn_reader_thread(input, tx.clone(), ack_tx, found.keys);
    let writer = spawn_writer_thread(tx, ack_rx);
    let mut app = App::new(scene, color, size);
    app.cells = cells;
    app.protocol = found.protocol;
    app.pixels = found.protocol.is_some();
    app.cell_pixels = found.cell;
    app.sixel_max = found.sixel_max;
    app.tmux = tmux;
    if found.protocol == Some(Protocol::Kitty) {
        tty::kitty_images(tmux);
    }
    let outcome = event_loop(app, &rx, &writer);
    if matches!(outcome, Ok(Outcome::Quit)) {
        // Let the answers to the last queries come in while raw mode still hides them, so
        // they do not land on the shell's command line.
        let deadline = Instant::now() + QUIT_ACK_WAIT;
        while ACKS_ON.load(Ordering::SeqCst)
            && UNANSWERED.load(Ordering::SeqCst) > 0
            && Instant::now() < deadline
        {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
    drop(guard);
    outcome
}

/// What the start learnt of the terminal.
struct Found {
    /// The protocol to draw with.
    protocol: Option<Protocol>,
    /// A cell's size in pixels (or [`detect::FALLBACK_CELL`]).
    cell: (u32, u32),
    /// Bytes read meanwhile that were not answers: keys, for the reader.
    keys: Vec<u8>,
    /// The largest sixel image, if the terminal said.
    sixel_max: Option<(u32, u32)>,
}

/// Asks the terminal what it can show (see [`detect`]), unless `choice` is none, and reads
/// its answers until DA1's (or [`DETECT_TIMEOUT`]). Then clears the screen: a terminal that
/// printed a query it did not understand shows nothing of it.
fn detect(input: RawFd, choice: Choice, size: (u16, u16), tmux: bool) -> Found {
    let ws = tty::winsize().ok();
    let from_winsize =
        ws.and_then(|w| detect::cell_from_winsize(w.ws_col, w.ws_row, w.ws_xpixel, w.ws_ypixel));
    let mut answers = Answers::default();
    if choice != Choice::None && tty::write_now(&detect::queries(tmux), DETECT_TIMEOUT) {
        let mut deadline = Instant::now() + DETECT_TIMEOUT;
        let mut buf = [0u8; 1024];
        let mut da1 = false;
        while !answers.done(tmux) {
            if answers.da1 && !da1 {
                da1 = true;
                deadline = deadline.min(Instant::now() + TMUX_ANSWER_WAIT);
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() || !tty::wait_readable(input, Some(left)) {
                break;
            }
            // SAFETY: reads into `buf`, within its length.
            let n = unsafe { libc::read(input, buf.as_mut_ptr().cast(), buf.len()) };
            if n <= 0 {
                break;
            }
            answers.feed(&buf[..n as usize]);
        }
        tty::write_now(b"\x1b[2J", DETECT_TIMEOUT);
    }
    let cell = from_winsize.or_else(|| answers.cell_size(size.0, size.1.max(1)));
    Found {
        protocol: detect::choose(choice, &answers, cell.is_some()),
        cell: cell.unwrap_or(detect::FALLBACK_CELL),
        keys: answers.take_other(),
        sixel_max: answers.sixel_max.or(Some(detect::SIXEL_MAX_UNTOLD)),
    }
}

/// Reads keys until end-of-file or an error. A lone ESC waits up to [`ESC_DELAY`] for the rest
/// of a sequence a slow link may have split. The terminal's replies to the writer's queries go
/// to the writer (`acks`, with the time they arrived), never to the loop as keys.
fn spawn_reader_thread(fd: RawFd, tx: Sender<Input>, acks: Sender<Instant>, early: Vec<u8>) {
    std::thread::spawn(move || {
        let mut parser = KeyParser::default();
        let mut buf = [0u8; 1024];
        // Keys typed while the start waited for the terminal's answers.
        for k in parser.feed(&early) {
            if tx.send(Input::Key(k)).is_err() {
                return;
            }
        }
        loop {
            let wait = parser.waiting_on_escape().then_some(ESC_DELAY);
            let keys = if tty::wait_readable(fd, wait) {
                // SAFETY: reads into `buf`, within its length.
                let n = unsafe { libc::read(fd, buf.as_mut_ptr().cast(), buf.len()) };
                match n {
                    0 => break,
                    n if n > 0 => parser.feed(&buf[..n as usize]),
                    _ if io::Error::last_os_error().kind() == io::ErrorKind::Interrupted => {
                        continue;
                    }
                    _ => break,
                }
            } else {
                parser.timeout()
            };
            let now = Instant::now();
            for _ in 0..parser.take_acks() {
                // The writer may be gone (the app is ending): the keys still go to the loop.
                let _ = acks.send(now);
                let _ = UNANSWERED.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                    Some(n.saturating_sub(1))
                });
            }
            for k in keys {
                if tx.send(Input::Key(k)).is_err() {
                    return;
                }
            }
            for m in parser.take_mouse() {
                if tx.send(Input::Mouse(m)).is_err() {
                    return;
                }
            }
        }
        let _ = tx.send(Input::Hangup);
    });
}

fn spawn_signal_thread(mut signals: Signals, tx: Sender<Input>) {
    std::thread::spawn(move || {
        for sig in signals.forever() {
            if sig == SIGWINCH {
                if tx.send(Input::Resize).is_err() {
                    return;
                }
                continue;
            }
            let _ = tx.send(Input::Signal(sig));
            // The loop should have restored and exited well before this.
            std::thread::sleep(FORCED_EXIT_AFTER);
            tty::restore();
            std::process::exit(crate::cli::signal_status(sig).into());
        }
    });
}

/// The writer: takes frames one at a time and writes each through the non-blocking descriptor,
/// waiting for room as the terminal drains. A frame from before a suspend, or after a restore,
/// is dropped. Reports each frame back to the loop. Frames are paced by the terminal's
/// acknowledgements where it answers (see [`Acks`]), else by the drain rate alone.
fn spawn_writer_thread(tx: Sender<Input>, acks_rx: Receiver<Instant>) -> Sender<Job> {
    let (jobs, rx) = mpsc::channel::<Job>();
    std::thread::spawn(move || {
        let mut link = Link::new(Instant::now());
        let mut acks = Acks::new();
        loop {
            // While answers are due, look for them between frames too, so the loop's next
            // frame already fits the link they measure.
            let mut job = if acks.outstanding() {
                match rx.recv_timeout(ACK_POLL) {
                    Ok(job) => job,
                    Err(mpsc::RecvTimeoutError::Timeout) => {
                        let mut answered = false;
                        while let Ok(at) = acks_rx.try_recv() {
                            acks.acked(at, &mut link);
                            answered = true;
                        }
                        acks.expire(Instant::now());
                        let view = LinkView {
                            budget: link.budget(),
                            rate: link.rate(),
                        };
                        if answered && tx.send(Input::Link(view)).is_err() {
                            return;
                        }
                        continue;
                    }
                    Err(mpsc::RecvTimeoutError::Disconnected) => return,
                }
            } else {
                match rx.recv() {
                    Ok(job) => job,
                    Err(_) => return,
                }
            };
            while let Ok(at) = acks_rx.try_recv() {
                acks.acked(at, &mut link);
            }
            let start = Instant::now();
            let (before, after) = acks.queries(start);
            if before {
                job.bytes.splice(0..0, ACK_QUERY.iter().copied());
            }
            if after {
                job.bytes.extend_from_slice(ACK_QUERY);
            }
            let report = write_frame(&job, &mut link, acks.on()).map(|()| {
                acks.wrote(start, job.bytes.len(), before, after);
                UNANSWERED.fetch_add(usize::from(before) + usize::from(after), Ordering::SeqCst);
                // Let the queue drain to its low-water mark before taking the next frame, so
                // the next frame shows soon after it is encoded.
                let wait = link.wait(Instant::now(), job.encode).min(MAX_PACING_WAIT);
                std::thread::sleep(wait);
                // And keep at most one frame unacknowledged by a terminal that answers.
                let deadline = Instant::now() + ACK_WAIT;
                while acks.waiting() {
                    match acks_rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                        Ok(at) => acks.acked(at, &mut link),
                        Err(_) => acks.give_up(),
                    }
                }
                ACKS_ON.store(acks.on(), Ordering::SeqCst);
                LinkView {
                    budget: link.budget(),
                    rate: link.rate(),
                }
            });
            if tx.send(Input::Written(report)).is_err() {
                return;
            }
        }
    });
    jobs
}

/// Writes one frame, measuring the link as it goes (see [`Link`]). With `acknowledged` (the
/// terminal answers queries) a frame that never blocked says nothing of the link: the
/// acknowledgements measure it.
fn write_frame(job: &Job, link: &mut Link, acknowledged: bool) -> io::Result<()> {
    let fd = tty::writer_fd();
    let mut rest = &job.bytes[..];
    // When the queue was first found full, and the bytes taken since.
    let mut full_since: Option<Instant> = None;
    let mut drained = 0;
    while !rest.is_empty() && tty::writable_in(job.epoch) {
        match tty::write_some(fd, rest) {
            Ok(n) => {
                rest = &rest[n..];
                link.wrote(n, Instant::now());
                if full_since.is_some() {
                    drained += n;
                }
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                if full_since.is_none() {
                    full_since = Some(Instant::now());
                    link.full(Instant::now());
                }
                tty::wait_writable(fd, WRITER_POLL);
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    let now = Instant::now();
    if full_since.is_some() || !acknowledged {
        link.frame_done(drained, full_since.map(|t| now - t), now);
    }
    Ok(())
}

/// Applies one input; returns the outcome if it ends the app.
fn handle(
    app: &mut App,
    screen: &mut Screen,
    input: Input,
    busy: &mut bool,
) -> Result<Option<Outcome>> {
    match input {
        Input::Key(k) => {
            if let Some(m) = message_for(k) {
                update(app, m);
            }
            return Ok(app.quit.then_some(Outcome::Quit));
        }
        Input::Mouse(m) => {
            if let Some(msg) = super::keys::message_for_mouse(m) {
                update(app, msg);
            }
            return Ok(None);
        }
        Input::Resize => {
            if let Ok(ws) = tty::winsize() {
                let (cols, rows) = (ws.ws_col, ws.ws_row);
                update(app, Message::Resize { cols, rows });
                // A new size may come with a new font size: the pixels follow the terminal.
                if let Some((width, height)) =
                    detect::cell_from_winsize(cols, rows, ws.ws_xpixel, ws.ws_ypixel)
                {
                    update(app, Message::CellPixels { width, height });
                }
            }
        }
        Input::Hangup => return Ok(Some(Outcome::Hangup)),
        Input::Signal(s) => return Ok(Some(Outcome::Signal(s))),
        Input::Link(view) => screen.link = view,
        Input::Written(report) => {
            *busy = false;
            screen.link = report.context("cannot write to the terminal")?;
        }
    }
    Ok(None)
}

fn event_loop(mut app: App, rx: &Receiver<Input>, writer: &Sender<Job>) -> Result<Outcome> {
    let mut screen = Screen::new();
    let mut last_draw = Instant::now();
    // A frame is with the writer.
    let mut busy = false;
    // The image or the app changed since the last frame was encoded.
    let mut stale = true;
    loop {
        let can_draw = stale && !busy;
        if !screen.needs_render(&app) && !can_draw {
            // Idle: block until a key, a resize, a signal or the writer; in a pixel mode
            // showing a reduced frame, at most until it is due at full resolution.
            let input = match screen.upgrade_in(&app) {
                Some(wait) => match rx.recv_timeout(wait) {
                    Ok(input) => Some(input),
                    Err(mpsc::RecvTimeoutError::Timeout) => None,
                    Err(mpsc::RecvTimeoutError::Disconnected) => return Ok(Outcome::Hangup),
                },
                None => match rx.recv() {
                    Ok(input) => Some(input),
                    Err(_) => return Ok(Outcome::Hangup),
                },
            };
            if let Some(input) = input
                && let Some(outcome) = handle(&mut app, &mut screen, input, &mut busy)?
            {
                return Ok(outcome);
            }
        }
        // Drain everything pending, so a held key never queues frames behind it.
        while let Ok(input) = rx.try_recv() {
            if let Some(outcome) = handle(&mut app, &mut screen, input, &mut busy)? {
                return Ok(outcome);
            }
        }
        // A changed app, or a screen the link's budget left approximate, needs a frame.
        if app.dirty || screen.approximate() {
            stale = true;
            app.dirty = false;
        }
        if app.suspend {
            suspend()?;
            app.suspend = false;
            // The terminal may have been resized, and shows whatever ran meanwhile.
            if let Ok((cols, rows)) = tty::size() {
                update(&mut app, Message::Resize { cols, rows });
            }
            screen.forget_shown();
            stale = true;
        }
        if screen.needs_render(&app) {
            screen.render(&app);
            // A refinement pass is drawn at most every REFINE_DRAW_INTERVAL, and the last one.
            stale |= screen.passes() <= 1
                || screen.passes() >= GI_MAX_PASSES
                || last_draw.elapsed() >= REFINE_DRAW_INTERVAL;
        }
        if stale && !busy {
            stale = false;
            last_draw = Instant::now();
            let bytes = screen.draw(&app);
            // Debug builds only: a test's way to make the app panic with the terminal taken
            // (`tests/tui_pty.rs`: restored first, then std's message and status 101).
            #[cfg(debug_assertions)]
            if std::env::var_os("RAYTTY_TEST_PANIC").is_some() {
                panic!("RAYTTY_TEST_PANIC is set");
            }
            if !bytes.is_empty() {
                let job = Job {
                    epoch: tty::epoch(),
                    bytes,
                    encode: last_draw.elapsed(),
                };
                writer
                    .send(job)
                    .map_err(|_| io::Error::other("the writer stopped"))
                    .context("cannot write to the terminal")?;
                busy = true;
            }
        }
    }
}
