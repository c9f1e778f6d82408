//! The only code that touches the terminal: raw mode and the alternate screen, the event loop,
//! and the ways out. The terminal is restored on every exit path:
//! - quit (Esc, Ctrl-C), an I/O error, or a dropped tty: [`Guard`]'s `Drop` as `run` returns;
//! - a panic: the panic hook restores before the default hook prints the message;
//! - SIGTERM, SIGHUP, SIGINT, SIGQUIT: the signal thread turns them into a quit the loop sees
//!   at once; if the loop is stuck (a write blocked on a stalled link) the signal thread
//!   restores and exits itself after [`FORCED_EXIT_AFTER`].
//!
//! Idle means idle: with nothing to render the loop blocks on its channel. Input comes from a
//! reader thread that stops on end-of-file or EIO, and from the signal thread.

use std::io::{self, IsTerminal, Read, Write};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use crossterm::event::KeyEvent;
use crossterm::{cursor, execute, terminal};
use raytty::{ColorMode, Scene};
use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGSTOP, SIGTERM, SIGWINCH};
use signal_hook::iterator::Signals;

use super::app::{App, Message, update};
use super::input::KeyParser;
use super::keys::message_for;
use super::view::{GI_MAX_PASSES, Screen};

/// While refining, a new average is drawn at most this often: a few frames a second.
const REFINE_DRAW_INTERVAL: Duration = Duration::from_millis(250);
/// After a terminating signal the loop has this long to restore and exit before the signal
/// thread does it (the loop may be blocked writing to a link that no longer drains).
const FORCED_EXIT_AFTER: Duration = Duration::from_secs(2);
/// Exit status for a dropped terminal, as if by SIGHUP (128 + 1).
const HANGUP_STATUS: u8 = 129;

/// What the loop waits for.
enum Input {
    Key(KeyEvent),
    /// The terminal was resized (SIGWINCH).
    Resize,
    /// The tty gave end-of-file or an error: the connection is gone.
    Hangup,
    /// A terminating signal.
    Signal(i32),
}

/// Whether the terminal is in the app's modes and needs restoring.
static ACTIVE: AtomicBool = AtomicBool::new(false);

/// Puts the terminal back: main screen, cooked mode, cursor visible, colours reset. Safe to
/// call from any thread, more than once, and on a terminal that is gone (errors are ignored).
fn restore() {
    if ACTIVE.swap(false, Ordering::SeqCst) {
        let mut out = io::stdout();
        // End any half-written synchronized frame and reset the pen before leaving.
        let _ = out.write_all(b"\x1b[?2026l\x1b[0m");
        let _ = execute!(out, cursor::Show, terminal::LeaveAlternateScreen);
        let _ = terminal::disable_raw_mode();
    }
}

/// Holds the terminal in raw mode on the alternate screen; restores it when dropped.
struct Guard;

impl Guard {
    fn enter() -> Result<Guard> {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            restore();
            prev(info);
        }));
        take_terminal()?;
        Ok(Guard)
    }
}

/// Raw mode, the alternate screen, a hidden cursor and a clear screen; marks the terminal as
/// needing [`restore`].
fn take_terminal() -> Result<()> {
    terminal::enable_raw_mode().context("cannot put the terminal in raw mode")?;
    ACTIVE.store(true, Ordering::SeqCst);
    execute!(
        io::stdout(),
        terminal::EnterAlternateScreen,
        cursor::Hide,
        terminal::Clear(terminal::ClearType::All)
    )?;
    Ok(())
}

/// Ctrl-Z: gives the terminal back as it was, stops the process (as the shell's job control
/// expects; SIGSTOP, because raw mode turned the key into a byte rather than SIGTSTP), and once
/// continued (`fg`) takes the terminal again. The caller redraws every cell.
fn suspend() -> Result<()> {
    restore();
    signal_hook::low_level::raise(SIGSTOP).context("cannot suspend")?;
    take_terminal()
}

impl Drop for Guard {
    fn drop(&mut self) {
        restore();
    }
}

/// Runs the app on the terminal until the user quits, the terminal goes away or a signal
/// arrives. The exit code is 0 for a quit, 128 + N for signal N.
pub fn run(scene: Scene, color: ColorMode) -> Result<ExitCode> {
    let tty: Box<dyn Read + Send> = if io::stdin().is_terminal() {
        Box::new(io::stdin())
    } else {
        Box::new(std::fs::File::open("/dev/tty").context("cannot open /dev/tty to read keys")?)
    };
    let (tx, rx) = mpsc::channel();
    let signals = Signals::new([SIGWINCH, SIGTERM, SIGHUP, SIGINT, SIGQUIT])
        .context("cannot install signal handlers")?;
    let guard = Guard::enter()?;
    spawn_signal_thread(signals, tx.clone());
    spawn_reader_thread(tty, tx);
    let size = terminal::size().context("cannot read the terminal size")?;
    let code = event_loop(App::new(scene, color, size), &rx);
    drop(guard);
    code
}

fn spawn_reader_thread(mut tty: Box<dyn Read + Send>, tx: Sender<Input>) {
    std::thread::spawn(move || {
        let mut parser = KeyParser::default();
        let mut buf = [0u8; 1024];
        loop {
            match tty.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    for k in parser.feed(&buf[..n]) {
                        if tx.send(Input::Key(k)).is_err() {
                            return;
                        }
                    }
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(_) => break,
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
            restore();
            std::process::exit(128 + sig);
        }
    });
}

/// Applies one input; returns the exit code if it ends the app.
fn handle(app: &mut App, input: Input) -> Option<ExitCode> {
    match input {
        Input::Key(k) => {
            if let Some(m) = message_for(k) {
                update(app, m);
            }
            app.quit.then_some(ExitCode::SUCCESS)
        }
        Input::Resize => {
            if let Ok((cols, rows)) = terminal::size() {
                update(app, Message::Resize { cols, rows });
            }
            None
        }
        Input::Hangup => Some(ExitCode::from(HANGUP_STATUS)),
        Input::Signal(s) => Some(ExitCode::from(128 + s as u8)),
    }
}

fn event_loop(mut app: App, rx: &Receiver<Input>) -> Result<ExitCode> {
    let mut screen = Screen::new();
    let mut out = io::stdout().lock();
    let mut last_draw = Instant::now();
    loop {
        if !app.dirty && !screen.needs_render(&app) {
            // Idle: block until a key, a resize or a signal.
            let Ok(input) = rx.recv() else {
                return Ok(ExitCode::from(HANGUP_STATUS));
            };
            if let Some(code) = handle(&mut app, input) {
                return Ok(code);
            }
        }
        // Drain everything pending, so a held key never queues frames behind it.
        while let Ok(input) = rx.try_recv() {
            if let Some(code) = handle(&mut app, input) {
                return Ok(code);
            }
        }
        if app.suspend {
            out.flush().context("cannot write to the terminal")?;
            suspend()?;
            app.suspend = false;
            // The terminal may have been resized, and shows whatever ran meanwhile.
            if let Ok((cols, rows)) = terminal::size() {
                update(&mut app, Message::Resize { cols, rows });
            }
            screen.forget_shown();
            app.dirty = true;
        }
        if screen.needs_render(&app) {
            screen.render(&app);
            let refined = screen.passes() > 1;
            if refined
                && !app.dirty
                && screen.passes() < GI_MAX_PASSES
                && last_draw.elapsed() < REFINE_DRAW_INTERVAL
            {
                continue;
            }
        }
        let bytes = screen.draw(&app);
        app.dirty = false;
        last_draw = Instant::now();
        if !bytes.is_empty() {
            out.write_all(&bytes)
                .context("cannot write to the terminal")?;
            out.flush().context("cannot write to the terminal")?;
        }
    }
}
