//! The terminal's file descriptors, raw mode, and [`restore`]: the few system calls behind the
//! event loop, with no lock anywhere. Output goes through descriptors of our own, opened
//! non-blocking on the same terminal (so no thread ever sleeps inside `write(2)`, and the
//! shell's descriptor keeps its flags):
//! - the writer's, which [`restore`] points at `/dev/null` before it writes, so a frame still
//!   being written cannot land after the restore;
//! - the restore's own.

use std::io;
use std::os::fd::{AsRawFd, IntoRawFd, RawFd};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicU8, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The bytes that put the screen back: cancel any half-written escape sequence (CAN), end a
/// half-written synchronized frame, reset the pen, show the cursor, leave the alternate screen.
const RESTORE_BYTES: &[u8] = b"\x18\x1b[?2026l\x1b[0m\x1b[?1006l\x1b[?1002l\x1b[?25h\x1b[?1049l";
/// Enter the alternate screen, hide the cursor, clear.
const TAKE_BYTES: &[u8] = b"\x1b[?1049h\x1b[?25l\x1b[?1002h\x1b[?1006h\x1b[2J";
/// How long [`restore`] waits for the terminal to take its bytes behind what is already
/// queued, before it discards the queue (a stalled link: a frame nobody will see) and tries
/// once more. With the exit that follows a signal this stays well inside its 2 s.
const RESTORE_DRAIN: Duration = Duration::from_millis(400);
/// How long a second caller of [`restore`] waits for the first to finish (its drain, plus
/// margin), so that whoever exits the process exits with the terminal restored.
const RESTORE_WAIT: Duration = Duration::from_millis(600);
/// Between checks while waiting for another thread's restore.
const RESTORE_POLL: Duration = Duration::from_millis(2);

/// The terminal is ours (raw mode, alternate screen).
const ACTIVE: u8 = 1;
/// A [`restore`] is under way.
const RESTORING: u8 = 2;
/// Restored (or never taken).
const RESTORED: u8 = 3;

static STATE: AtomicU8 = AtomicU8::new(RESTORED);
/// Bumped each time the terminal is taken: a frame begun before a suspend is not finished after.
static EPOCH: AtomicU64 = AtomicU64::new(0);
/// The descriptor the termios settings are read from and set on (the input tty).
static TERMIOS_FD: AtomicI32 = AtomicI32::new(-1);
/// The writer's non-blocking output descriptor.
static WRITER_FD: AtomicI32 = AtomicI32::new(-1);
/// [`restore`]'s non-blocking output descriptor.
static RESTORE_FD: AtomicI32 = AtomicI32::new(-1);
/// kitty graphics were sent: [`restore`] deletes the images first.
static KITTY_IMAGES: AtomicBool = AtomicBool::new(false);
/// ... through tmux's passthrough.
static KITTY_VIA_TMUX: AtomicBool = AtomicBool::new(false);
/// The terminal's settings before raw mode.
static SAVED: OnceLock<libc::termios> = OnceLock::new();

/// Opens the output descriptors on the terminal that stdout is, and remembers `input` (the
/// tty keys are read from) for raw mode. Call once, before [`take`].
pub fn open(input: RawFd) -> io::Result<()> {
    TERMIOS_FD.store(input, Ordering::SeqCst);
    WRITER_FD.store(open_output()?, Ordering::SeqCst);
    RESTORE_FD.store(open_output()?, Ordering::SeqCst);
    let mut t = std::mem::MaybeUninit::<libc::termios>::uninit();
    // SAFETY: tcgetattr fills the struct on success; we read it only then.
    if unsafe { libc::tcgetattr(input, t.as_mut_ptr()) } != 0 {
        return Err(io::Error::last_os_error());
    }
    let _ = SAVED.set(unsafe { t.assume_init() });
    Ok(())
}

/// A new open file description of stdout's terminal, non-blocking. Opening it anew (rather than
/// setting `O_NONBLOCK` on fd 1) leaves the flags of the descriptor the shell shares alone.
fn open_output() -> io::Result<RawFd> {
    use std::os::unix::fs::OpenOptionsExt;
    let open = |path: &str| {
        std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path)
    };
    let file = open("/proc/self/fd/1").or_else(|_| open("/dev/tty"))?;
    Ok(file.into_raw_fd())
}

/// Raw mode, the alternate screen, a hidden cursor and a clear screen; marks the terminal as
/// needing [`restore`]. Also after a suspend: points the writer at the terminal again.
pub fn take() -> io::Result<()> {
    let fd = TERMIOS_FD.load(Ordering::SeqCst);
    let Some(saved) = SAVED.get() else {
        return Err(io::Error::other("the terminal was not opened"));
    };
    let mut raw = *saved;
    // SAFETY: cfmakeraw and tcsetattr only read and write the struct and the descriptor.
    unsafe { libc::cfmakeraw(&mut raw) };
    if unsafe { libc::tcsetattr(fd, libc::TCSANOW, &raw) } != 0 {
        return Err(io::Error::last_os_error());
    }
    let fresh = open_output()?;
    let writer = WRITER_FD.load(Ordering::SeqCst);
    // SAFETY: both descriptors are ours; dup2 replaces the writer's atomically.
    unsafe {
        libc::dup2(fresh, writer);
        libc::close(fresh);
    }
    EPOCH.fetch_add(1, Ordering::SeqCst);
    STATE.store(ACTIVE, Ordering::SeqCst);
    write_until(writer, TAKE_BYTES, Instant::now() + RESTORE_DRAIN)
        .then_some(())
        .ok_or_else(|| io::Error::other("the terminal does not take output"))
}

/// Puts the terminal back: cooked mode at once, then the restoring bytes through a descriptor
/// of its own (see [`RESTORE_BYTES`]). Takes no lock, so it is safe from any thread (the
/// panic hook on a rayon worker, the signal thread) while another is writing a frame. The first
/// caller restores; a caller that comes while it does waits for it (bounded by
/// [`RESTORE_WAIT`]), so whichever thread then exits the process leaves a restored terminal. If
/// the terminal takes nothing within [`RESTORE_DRAIN`], what it has not read yet is discarded
/// and the bytes are tried once more, so this returns in bounded time even on a stalled link.
pub fn restore() {
    match STATE.compare_exchange(ACTIVE, RESTORING, Ordering::SeqCst, Ordering::SeqCst) {
        Ok(_) => {
            if let Some(saved) = SAVED.get() {
                // SAFETY: tcsetattr reads the saved struct; TCSANOW does not wait for output.
                unsafe { libc::tcsetattr(TERMIOS_FD.load(Ordering::SeqCst), libc::TCSANOW, saved) };
            }
            silence_writer();
            let fd = RESTORE_FD.load(Ordering::SeqCst);
            if KITTY_IMAGES.load(Ordering::SeqCst) {
                // The images go first (leaving the alternate screen would not remove them
                // from every terminal), within the same bounded drain.
                let delete = kitty_delete(KITTY_VIA_TMUX.load(Ordering::SeqCst));
                write_until(fd, &delete, Instant::now() + RESTORE_DRAIN);
            }
            if !write_until(fd, RESTORE_BYTES, Instant::now() + RESTORE_DRAIN) {
                // SAFETY: tcflush on our own descriptor of the terminal.
                unsafe { libc::tcflush(fd, libc::TCOFLUSH) };
                write_until(fd, RESTORE_BYTES, Instant::now() + RESTORE_POLL);
            }
            STATE.store(RESTORED, Ordering::SeqCst);
        }
        Err(RESTORING) => {
            let deadline = Instant::now() + RESTORE_WAIT;
            while STATE.load(Ordering::SeqCst) == RESTORING && Instant::now() < deadline {
                std::thread::sleep(RESTORE_POLL);
            }
        }
        Err(_) => {}
    }
}

/// The app is about to send kitty graphics (through tmux's passthrough if `tmux`): from now
/// on [`restore`] deletes every image first.
pub fn kitty_images(tmux: bool) {
    KITTY_VIA_TMUX.store(tmux, Ordering::SeqCst);
    KITTY_IMAGES.store(true, Ordering::SeqCst);
}

/// The bytes that delete every kitty image, wrapped for tmux if `tmux`.
pub fn kitty_delete(tmux: bool) -> Vec<u8> {
    let mut out = Vec::new();
    if tmux {
        super::detect::tmux_passthrough(raytty::frame::KITTY_DELETE_ALL, &mut out);
    } else {
        out.extend_from_slice(raytty::frame::KITTY_DELETE_ALL);
    }
    out
}

/// Writes `bytes` to the terminal through the writer's descriptor, waiting at most `timeout`
/// for room (the start's queries, before the writer thread runs). Whether all went.
pub fn write_now(bytes: &[u8], timeout: Duration) -> bool {
    write_until(
        WRITER_FD.load(Ordering::SeqCst),
        bytes,
        Instant::now() + timeout,
    )
}

/// Points the writer's descriptor at `/dev/null`: whatever it writes from now on goes nowhere.
fn silence_writer() {
    if let Ok(null) = std::fs::OpenOptions::new().write(true).open("/dev/null") {
        // SAFETY: dup2 onto our own descriptor; `null` stays open until it returns.
        unsafe { libc::dup2(null.as_raw_fd(), WRITER_FD.load(Ordering::SeqCst)) };
    }
}

/// Writes all of `bytes` to the non-blocking `fd`, waiting for room until `deadline`. Whether
/// everything was written.
fn write_until(fd: RawFd, mut bytes: &[u8], deadline: Instant) -> bool {
    while !bytes.is_empty() {
        match write_some(fd, bytes) {
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                let left = deadline.saturating_duration_since(Instant::now());
                if left.is_zero() || !wait_writable(fd, left) {
                    return false;
                }
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(_) => return false,
        }
    }
    true
}

/// One `write(2)`: how many bytes the terminal took (an error `WouldBlock` when it has no room).
pub fn write_some(fd: RawFd, bytes: &[u8]) -> io::Result<usize> {
    // SAFETY: the pointer and length describe `bytes`.
    let n = unsafe { libc::write(fd, bytes.as_ptr().cast(), bytes.len()) };
    if n < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(n as usize)
    }
}

/// Waits until `fd` can take more bytes, at most `timeout`. Whether it can.
pub fn wait_writable(fd: RawFd, timeout: Duration) -> bool {
    poll(fd, libc::POLLOUT, timeout)
}

/// Waits until `fd` has bytes to read (or end-of-file), at most `timeout` (`None`: forever).
pub fn wait_readable(fd: RawFd, timeout: Option<Duration>) -> bool {
    match timeout {
        Some(t) => poll(fd, libc::POLLIN, t),
        None => true,
    }
}

fn poll(fd: RawFd, events: libc::c_short, timeout: Duration) -> bool {
    let mut p = libc::pollfd {
        fd,
        events,
        revents: 0,
    };
    let ms = timeout.as_millis().min(i32::MAX as u128) as i32;
    // SAFETY: one valid pollfd.
    let n = unsafe { libc::poll(&mut p, 1, ms) };
    // An error or hang-up also wakes the caller: its next read or write reports it.
    n > 0
}

/// Whether the terminal is ours and a frame begun in `epoch` may still be written.
pub fn writable_in(epoch: u64) -> bool {
    STATE.load(Ordering::SeqCst) == ACTIVE && EPOCH.load(Ordering::SeqCst) == epoch
}

/// The current epoch: bumped each time the terminal is taken.
pub fn epoch() -> u64 {
    EPOCH.load(Ordering::SeqCst)
}

/// The writer's descriptor.
pub fn writer_fd() -> RawFd {
    WRITER_FD.load(Ordering::SeqCst)
}

/// The terminal's size in (columns, rows).
pub fn size() -> io::Result<(u16, u16)> {
    winsize().map(|ws| (ws.ws_col, ws.ws_row))
}

/// The terminal's size as `TIOCGWINSZ` gives it: columns, rows, and the pixel fields (zero
/// where the terminal does not fill them).
pub fn winsize() -> io::Result<libc::winsize> {
    let mut ws = libc::winsize {
        ws_row: 0,
        ws_col: 0,
        ws_xpixel: 0,
        ws_ypixel: 0,
    };
    // SAFETY: TIOCGWINSZ fills a winsize.
    if unsafe { libc::ioctl(RESTORE_FD.load(Ordering::SeqCst), libc::TIOCGWINSZ, &mut ws) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(ws)
}
