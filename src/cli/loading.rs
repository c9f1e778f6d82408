//! A model's load as a person sees it: a progress bar on stderr once the load has taken half a
//! second (only when stderr is a terminal), and Ctrl-C (SIGINT), SIGTERM or SIGHUP ending raytty
//! at once with 128 + N, the bar cleared first. The load itself cannot be interrupted halfway
//! (the parser and the BVH build do not poll), and needs not be: nothing is written before it
//! ends (the output file is opened after), and the terminal is not yet the app's.
//!
//! [`Watch`] keeps watching those signals until it is dropped: `render` keeps it for the whole
//! command (Ctrl-C ends a long render the same way); the app drops it before it installs its
//! own handlers (a handler once installed cannot give the signal back its default action).

use std::io::{self, IsTerminal};
use std::sync::Arc;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};
use raytty::scene::model::LoadProgress;
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// A load shorter than this shows no bar.
const QUIET_FOR: Duration = Duration::from_millis(500);

/// How often the bar is redrawn and the signals looked at.
const TICK: Duration = Duration::from_millis(50);

/// The thread that draws the load's bar and watches for the signals that end raytty.
pub(crate) struct Watch {
    tx: Option<Sender<()>>,
    thread: Option<JoinHandle<()>>,
    progress: Arc<LoadProgress>,
}

impl Watch {
    /// Starts watching the load of `name` (as the bar shows it). Without signal handlers
    /// (they could not be installed) the signals keep their default actions.
    pub(crate) fn start(name: &str) -> Watch {
        let progress = Arc::new(LoadProgress::new());
        let (tx, rx) = mpsc::channel::<()>();
        let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return Watch {
                tx: None,
                thread: None,
                progress,
            };
        };
        let shown = progress.clone();
        let name = name.to_string();
        let thread = std::thread::spawn(move || {
            let start = Instant::now();
            let mut bar: Option<ProgressBar> = None;
            let mut counted = None;
            let mut loading = true;
            loop {
                if let Some(sig) = signals.pending().next() {
                    if let Some(bar) = bar.take() {
                        bar.finish_and_clear();
                    }
                    std::process::exit(crate::cli::signal_status(sig).into());
                }
                match rx.recv_timeout(TICK) {
                    // The load is over: no bar from now on, the signals still watched.
                    Ok(()) => {
                        loading = false;
                        if let Some(bar) = bar.take() {
                            bar.finish_and_clear();
                        }
                    }
                    Err(RecvTimeoutError::Disconnected) => {
                        if let Some(bar) = bar.take() {
                            bar.finish_and_clear();
                        }
                        return;
                    }
                    Err(RecvTimeoutError::Timeout) => {}
                }
                if loading && bar.is_none() && start.elapsed() >= QUIET_FOR {
                    bar = io::stderr().is_terminal().then(|| {
                        // The bar takes the line (the app's "loading" note may be on it).
                        eprint!("\r\x1b[2K");
                        let stderr = Box::new(Narrower(console::Term::stderr()));
                        ProgressBar::with_draw_target(
                            Some(1000),
                            ProgressDrawTarget::term_like(stderr),
                        )
                    });
                }
                if let Some(bar) = &bar {
                    draw(bar, &mut counted, &name, &shown);
                }
            }
        });
        Watch {
            tx: Some(tx),
            thread: Some(thread),
            progress,
        }
    }

    /// What the loader tells how far it has got.
    pub(crate) fn progress(&self) -> &LoadProgress {
        &self.progress
    }

    /// The load is over: the bar goes, the signals are still watched.
    pub(crate) fn loaded(&self) {
        if let Some(tx) = &self.tx {
            let _ = tx.send(());
        }
    }
}

/// Stops watching: the bar is cleared and the thread ends (its handlers with it).
impl Drop for Watch {
    fn drop(&mut self) {
        drop(self.tx.take());
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The bar as the load stands: a fraction while parsing, else a spinner with the step;
/// `counted` is whether it shows a fraction now (its style is set when that changes).
fn draw(bar: &ProgressBar, counted: &mut Option<bool>, name: &str, progress: &LoadProgress) {
    let fraction = progress.fraction();
    if *counted != Some(fraction.is_some()) {
        *counted = Some(fraction.is_some());
        let template = match fraction {
            Some(_) => "raytty: loading {msg} [{bar:30}] {percent:>3}% {elapsed}",
            None => "raytty: loading {msg} {spinner} {elapsed}",
        };
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
    }
    bar.set_message(format!("{name}: {}", progress.step().label()));
    match fraction {
        Some(f) => bar.set_position((f * 1000.0) as u64),
        None => bar.tick(),
    }
}

/// stderr as the bar draws on it, two columns narrower than the terminal. indicatif pads a
/// line to the right edge, where the terminal's echo of a typed ^C would wrap to a line of its
/// own, and clearing the bar would leave the bar's line behind; two columns short, the echo
/// stays on the bar's line and goes with it.
#[derive(Debug)]
struct Narrower(console::Term);

impl TermLike for Narrower {
    fn width(&self) -> u16 {
        self.0.size().1.saturating_sub(2).max(1)
    }

    fn move_cursor_up(&self, n: usize) -> io::Result<()> {
        self.0.move_cursor_up(n)
    }

    fn move_cursor_down(&self, n: usize) -> io::Result<()> {
        self.0.move_cursor_down(n)
    }

    fn move_cursor_right(&self, n: usize) -> io::Result<()> {
        self.0.move_cursor_right(n)
    }

    fn move_cursor_left(&self, n: usize) -> io::Result<()> {
        self.0.move_cursor_left(n)
    }

    fn write_line(&self, s: &str) -> io::Result<()> {
        self.0.write_line(s)
    }

    fn write_str(&self, s: &str) -> io::Result<()> {
        self.0.write_str(s)
    }

    fn clear_line(&self) -> io::Result<()> {
        self.0.clear_line()
    }

    fn flush(&self) -> io::Result<()> {
        self.0.flush()
    }
}
