//! Terminal input bytes to key events, for the legacy encoding every terminal speaks (xterm,
//! tmux, screen, the Linux console, over SSH). We read the tty ourselves rather than through
//! crossterm's reader because that reader spins when the tty reports end-of-file or EIO (a
//! dropped SSH connection); this parser is pure, so the reader thread can stop on EOF.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// Longest escape sequence kept across reads; anything longer is dropped as garbage. Room for
/// a kitty graphics answer with its error message.
const MAX_PENDING: usize = 64;

/// Parses a byte stream into key events, keeping an incomplete sequence for the next read.
#[derive(Debug, Default)]
pub struct KeyParser {
    pending: Vec<u8>,
    /// Replies to [`ACK_QUERY`] parsed and not yet taken.
    acks: usize,
    /// Mouse events parsed and not yet taken.
    mouse: Vec<Mouse>,
    /// Where the left button was last reported while held (cell column, row).
    held: Option<(i32, i32)>,
}

/// What the mouse did, from SGR mouse reports (`CSI < b ; x ; y M`, release `m`), which the app
/// asks for with button-event tracking: motion is reported only while a button is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mouse {
    /// Dragged with the left button by this many cells (right, down).
    Drag(i32, i32),
    /// The wheel turned one notch: -1 up, 1 down.
    Wheel(i32),
}

/// The query appended after a frame to learn when the terminal has processed it: primary
/// device attributes (DA1, `CSI c`). Every terminal since the VT100 answers it (xterm, tmux,
/// screen, VTE, kitty, alacritty, the Linux console), in order with the output before it, with
/// `CSI ? ... c`, which no key sends. The cursor position report (`CSI 6 n`) is answered by
/// fewer terminals, and its reply `CSI row ; col R` is also what xterm sends for F3 with a
/// modifier (`CSI 1 ; 2 R`), so a reply could be taken for a key or a key for a reply.
pub const ACK_QUERY: &[u8] = b"\x1b[c";

impl KeyParser {
    /// The key events in `bytes` (after what an earlier call left incomplete). A lone ESC at
    /// the end of `bytes` is kept: it may be the start of a sequence split across reads (a slow
    /// or choppy link splits them). The reader calls [`KeyParser::timeout`] if nothing follows
    /// within [`ESC_DELAY`].
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<KeyEvent> {
        let mut buf = std::mem::take(&mut self.pending);
        buf.extend_from_slice(bytes);
        let mut keys = Vec::new();
        let mut i = 0;
        while i < buf.len() {
            match parse_one(&buf[i..]) {
                Parsed::Reply(used) => {
                    self.acks += 1;
                    i += used;
                }
                Parsed::Key(used, key) => {
                    keys.extend(key);
                    i += used;
                }
                Parsed::Mouse(used, button, x, y, pressed) => {
                    self.mouse_report(button, x, y, pressed);
                    i += used;
                }
                Parsed::Incomplete => {
                    if buf.len() - i <= MAX_PENDING {
                        self.pending = buf[i..].to_vec();
                    }
                    break;
                }
            }
        }
        keys
    }

    /// The mouse events in the bytes fed so far (since the last call).
    pub fn take_mouse(&mut self) -> Vec<Mouse> {
        std::mem::take(&mut self.mouse)
    }

    /// One SGR report: the wheel's notches, and left-button drags as moves from the last cell.
    fn mouse_report(&mut self, button: u16, x: i32, y: i32, pressed: bool) {
        if button & 64 != 0 {
            if pressed {
                self.mouse
                    .push(Mouse::Wheel(if button & 1 == 0 { -1 } else { 1 }));
            }
            return;
        }
        if !pressed || button & 3 != 0 {
            self.held = None;
            return;
        }
        if button & 32 != 0
            && let Some((lx, ly)) = self.held
            && (x, y) != (lx, ly)
        {
            self.mouse.push(Mouse::Drag(x - lx, y - ly));
        }
        self.held = Some((x, y));
    }

    /// How many replies to [`ACK_QUERY`] the bytes fed so far held (since the last call):
    /// they are consumed silently, never as keys.
    pub fn take_acks(&mut self) -> usize {
        std::mem::take(&mut self.acks)
    }

    /// Whether a lone ESC waits for what follows it: the reader then waits at most
    /// [`ESC_DELAY`] for more bytes before calling [`KeyParser::timeout`].
    pub fn waiting_on_escape(&self) -> bool {
        self.pending == [0x1b]
    }

    /// Nothing followed a lone ESC within [`ESC_DELAY`]: it was the Esc key. A longer
    /// incomplete sequence (`ESC [ 1 ;`) is kept: a user cannot type that, so the rest is on its
    /// way.
    pub fn timeout(&mut self) -> Vec<KeyEvent> {
        if self.waiting_on_escape() {
            self.pending.clear();
            vec![KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE)]
        } else {
            Vec::new()
        }
    }
}

/// How long a lone ESC waits for the rest of an escape sequence before it counts as the Esc
/// key (ncurses' ESCDELAY, tmux's escape-time). Over a slow or choppy link the bytes of one
/// arrow key can arrive milliseconds apart; a person pressing Esc waits far longer than this
/// before expecting a reaction.
pub const ESC_DELAY: std::time::Duration = std::time::Duration::from_millis(50);

enum Parsed {
    /// Bytes used and the key they make, if any.
    Key(usize, Option<KeyEvent>),
    /// Bytes used by the terminal's reply to [`ACK_QUERY`].
    Reply(usize),
    /// Bytes used by an SGR mouse report: its button code, column, row, and press (not release).
    Mouse(usize, u16, i32, i32, bool),
    /// The buffer ends inside a sequence.
    Incomplete,
}

fn key(code: KeyCode, modifiers: KeyModifiers) -> Option<KeyEvent> {
    Some(KeyEvent::new(code, modifiers))
}

fn parse_one(b: &[u8]) -> Parsed {
    let none = KeyModifiers::NONE;
    match b[0] {
        0x1b => match b.get(1) {
            None => Parsed::Incomplete,
            Some(0x1b) => Parsed::Key(1, key(KeyCode::Esc, none)),
            Some(b'[') => parse_csi(b),
            // An APC or DCS string (a late answer to the start's graphics queries: kitty's
            // `ESC _ G i=31;OK ESC \`): swallowed whole, never keys.
            Some(b'_' | b'P') => match b.windows(2).position(|w| w == b"\x1b\\") {
                Some(end) => Parsed::Key(end + 2, None),
                None => Parsed::Incomplete,
            },
            Some(b'O') => match b.get(2) {
                None => Parsed::Incomplete,
                Some(&f) => Parsed::Key(3, arrow(f).map(|c| KeyEvent::new(c, none))),
            },
            // ESC then a key: Alt+key.
            Some(_) => match parse_one(&b[1..]) {
                Parsed::Reply(n) | Parsed::Mouse(n, ..) => Parsed::Key(n + 1, None),
                Parsed::Key(n, k) => Parsed::Key(
                    n + 1,
                    k.map(|mut k| {
                        k.modifiers |= KeyModifiers::ALT;
                        k
                    }),
                ),
                Parsed::Incomplete => Parsed::Incomplete,
            },
        },
        b'\r' | b'\n' => Parsed::Key(1, key(KeyCode::Enter, none)),
        b'\t' => Parsed::Key(1, key(KeyCode::Tab, none)),
        0x7f | 0x08 => Parsed::Key(1, key(KeyCode::Backspace, none)),
        c @ 0x01..=0x1a => Parsed::Key(
            1,
            key(KeyCode::Char((c - 1 + b'a') as char), KeyModifiers::CONTROL),
        ),
        c @ 0x20..=0x7e => {
            let shift = if c.is_ascii_uppercase() {
                KeyModifiers::SHIFT
            } else {
                none
            };
            Parsed::Key(1, key(KeyCode::Char(c as char), shift))
        }
        c if c >= 0xc0 => {
            let len = match c {
                0xc0..=0xdf => 2,
                0xe0..=0xef => 3,
                _ => 4,
            };
            if b.len() < len {
                return Parsed::Incomplete;
            }
            match std::str::from_utf8(&b[..len])
                .ok()
                .and_then(|s| s.chars().next())
            {
                Some(ch) => Parsed::Key(len, key(KeyCode::Char(ch), none)),
                None => Parsed::Key(1, None),
            }
        }
        _ => Parsed::Key(1, None),
    }
}

/// CSI: ESC [ parameters intermediates final.
fn parse_csi(b: &[u8]) -> Parsed {
    let mut j = 2;
    while j < b.len() && (0x20..=0x3f).contains(&b[j]) {
        j += 1;
    }
    let Some(&f) = b.get(j) else {
        return Parsed::Incomplete;
    };
    // The reply to the device-attributes query: `CSI ? 1 ; 2 c` and the like.
    if f == b'c' && b.get(2) == Some(&b'?') {
        return Parsed::Reply(j + 1);
    }
    let params = std::str::from_utf8(&b[2..j]).unwrap_or("");
    // An SGR mouse report: `CSI < button ; column ; row` then M (press, motion) or m (release).
    if let Some(report) = params.strip_prefix('<') {
        let n: Vec<Option<i32>> = report.split(';').map(|v| v.parse().ok()).collect();
        return match (n.as_slice(), f) {
            ([Some(b), Some(x), Some(y)], b'M' | b'm') if *b >= 0 => {
                Parsed::Mouse(j + 1, *b as u16, *x, *y, f == b'M')
            }
            _ => Parsed::Key(j + 1, None),
        };
    }
    // xterm's modifier parameter "1;m": m − 1 is a bit set of Shift 1, Alt 2, Ctrl 4.
    let m: u8 = params
        .split(';')
        .nth(1)
        .and_then(|m| m.parse().ok())
        .unwrap_or(1);
    let bits = m.saturating_sub(1);
    let mut mods = KeyModifiers::NONE;
    for (bit, flag) in [
        (1, KeyModifiers::SHIFT),
        (2, KeyModifiers::ALT),
        (4, KeyModifiers::CONTROL),
    ] {
        if bits & bit != 0 {
            mods |= flag;
        }
    }
    // `CSI 5 ~` and `CSI 6 ~`: Page Up and Page Down.
    let code = match (f, params.split(';').next()) {
        (b'~', Some("5")) => Some(KeyCode::PageUp),
        (b'~', Some("6")) => Some(KeyCode::PageDown),
        _ => arrow(f),
    };
    Parsed::Key(j + 1, code.map(|c| KeyEvent::new(c, mods)))
}

fn arrow(f: u8) -> Option<KeyCode> {
    match f {
        b'A' => Some(KeyCode::Up),
        b'B' => Some(KeyCode::Down),
        b'C' => Some(KeyCode::Right),
        b'D' => Some(KeyCode::Left),
        b'H' => Some(KeyCode::Home),
        b'F' => Some(KeyCode::End),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn codes(p: &mut KeyParser, bytes: &[u8]) -> Vec<(KeyCode, KeyModifiers)> {
        p.feed(bytes)
            .into_iter()
            .map(|k| (k.code, k.modifiers))
            .collect()
    }

    /// Left-button drags become moves from the last reported cell, the wheel notches; a
    /// release ends a drag, and a report split across reads waits for its end.
    #[test]
    fn mouse_drags_and_wheel() {
        let mut p = KeyParser::default();
        assert!(
            p.feed(b"\x1b[<0;10;5M\x1b[<32;12;5M\x1b[<32;12;7M")
                .is_empty()
        );
        assert_eq!(p.take_mouse(), vec![Mouse::Drag(2, 0), Mouse::Drag(0, 2)]);
        assert!(
            p.feed(b"\x1b[<0;12;7m\x1b[<32;20;7M\x1b[<64;1;1M\x1b[<6")
                .is_empty()
        );
        assert_eq!(p.take_mouse(), vec![Mouse::Wheel(-1)]);
        assert_eq!(
            codes(&mut p, b"5;1;1Mx"),
            vec![(KeyCode::Char('x'), KeyModifiers::NONE)]
        );
        assert_eq!(p.take_mouse(), vec![Mouse::Wheel(1)]);
    }

    #[test]
    fn arrows_in_normal_and_application_mode_with_modifiers() {
        let mut p = KeyParser::default();
        let n = KeyModifiers::NONE;
        assert_eq!(
            codes(&mut p, b"\x1b[A\x1bOD\x1b[1;2C\x1b[1;5B"),
            vec![
                (KeyCode::Up, n),
                (KeyCode::Left, n),
                (KeyCode::Right, KeyModifiers::SHIFT),
                (KeyCode::Down, KeyModifiers::CONTROL),
            ]
        );
    }

    #[test]
    fn lone_escape_is_esc_after_the_delay_and_split_sequences_wait() {
        let mut p = KeyParser::default();
        assert_eq!(codes(&mut p, b"\x1b"), vec![]);
        assert!(p.waiting_on_escape());
        assert_eq!(
            p.timeout()
                .into_iter()
                .map(|k| (k.code, k.modifiers))
                .collect::<Vec<_>>(),
            vec![(KeyCode::Esc, KeyModifiers::NONE)]
        );
        assert!(!p.waiting_on_escape() && p.timeout().is_empty());
        // An arrow split after its ESC, and after its `[`, as a slow link delivers it.
        assert_eq!(codes(&mut p, b"\x1b"), vec![]);
        assert_eq!(codes(&mut p, b"["), vec![]);
        assert!(!p.waiting_on_escape(), "ESC [ is a sequence under way");
        assert!(p.timeout().is_empty());
        assert_eq!(codes(&mut p, b"A"), vec![(KeyCode::Up, KeyModifiers::NONE)]);
        // Two ESCs in one read: the first is a key, the second waits.
        assert_eq!(
            codes(&mut p, b"\x1b\x1b"),
            vec![(KeyCode::Esc, KeyModifiers::NONE)]
        );
        assert!(p.waiting_on_escape());
        assert_eq!(
            codes(&mut p, b"OD"),
            vec![(KeyCode::Left, KeyModifiers::NONE)]
        );
        assert_eq!(
            codes(&mut p, b"w\x1b[1;"),
            vec![(KeyCode::Char('w'), KeyModifiers::NONE)]
        );
        assert_eq!(
            codes(&mut p, b"2A"),
            vec![(KeyCode::Up, KeyModifiers::SHIFT)]
        );
    }

    #[test]
    fn letters_control_keys_utf8_and_unknown_sequences() {
        let mut p = KeyParser::default();
        assert_eq!(
            codes(&mut p, "Q\x03é\x1b[15~?".as_bytes()),
            vec![
                (KeyCode::Char('Q'), KeyModifiers::SHIFT),
                (KeyCode::Char('c'), KeyModifiers::CONTROL),
                (KeyCode::Char('é'), KeyModifiers::NONE),
                (KeyCode::Char('?'), KeyModifiers::NONE),
            ]
        );
    }

    #[test]
    fn device_attribute_replies_are_counted_never_keys_whole_split_or_mixed() {
        let mut p = KeyParser::default();
        let n = KeyModifiers::NONE;
        // Whole, as xterm and tmux send it.
        assert_eq!(codes(&mut p, b"\x1b[?1;2c"), vec![]);
        assert_eq!(p.take_acks(), 1);
        assert_eq!(p.take_acks(), 0);
        // Mixed with keys on both sides, two replies in one read.
        assert_eq!(
            codes(&mut p, b"w\x1b[?62;22c\x1b[Aw\x1b[?6c"),
            vec![
                (KeyCode::Char('w'), n),
                (KeyCode::Up, n),
                (KeyCode::Char('w'), n)
            ]
        );
        assert_eq!(p.take_acks(), 2);
        // Split across reads at every point: no key, one reply, no Esc.
        let reply = b"\x1b[?1;2c";
        for cut in 1..reply.len() {
            assert_eq!(codes(&mut p, &reply[..cut]), vec![], "cut {cut}");
            assert_eq!(p.take_acks(), 0);
            assert!(p.timeout().is_empty() || cut == 1);
            if cut == 1 {
                // A lone ESC for longer than the delay is the Esc key (as before); a reply
                // arrives in one write, so this split only happens within the delay.
                p = KeyParser::default();
                continue;
            }
            assert_eq!(codes(&mut p, &reply[cut..]), vec![], "cut {cut}");
            assert_eq!(p.take_acks(), 1, "cut {cut}");
        }
        // Split right after the ESC, the rest within the delay.
        assert_eq!(codes(&mut p, b"\x1b"), vec![]);
        assert!(p.waiting_on_escape());
        assert_eq!(codes(&mut p, b"[?1;2cq"), vec![(KeyCode::Char('q'), n)]);
        assert_eq!(p.take_acks(), 1);
        // A late answer to the graphics queries, split, between keys: no key from it.
        assert_eq!(
            codes(&mut p, b"w\x1b_Gi=31;O"),
            vec![(KeyCode::Char('w'), n)]
        );
        assert_eq!(
            codes(&mut p, b"K\x1b\\\x1b[6;20;10tq"),
            vec![(KeyCode::Char('q'), n)]
        );
        // Other CSI ... c sequences (no `?`) are not replies.
        assert_eq!(codes(&mut p, b"\x1b[0c"), vec![]);
        assert_eq!(p.take_acks(), 0);
    }

    #[test]
    fn random_bytes_never_panic_and_never_grow_the_buffer() {
        let mut p = KeyParser::default();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            // xorshift64: a seeded stream of arbitrary bytes.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let bytes = state.to_le_bytes();
            p.feed(&bytes[..(state % 8) as usize]);
            assert!(p.pending.len() <= MAX_PENDING);
        }
    }
}
