//! What the terminal can show, asked of it at start: the queries, and a pure parser of the
//! answers. The event loop's [`terminal`](super::terminal) writes [`queries`], feeds what the
//! terminal sends back to [`Answers::feed`] until [`Answers::done`] or a timeout, and picks a
//! protocol with [`choose`].
//!
//! - kitty graphics: a query action (`a=q`) for a 1×1 image under id [`QUERY_ID`]; a terminal
//!   that speaks the protocol answers `ESC _ G i=31;OK ESC \` (kitty, WezTerm, Ghostty,
//!   Konsole), one that does not ignores the APC string.
//! - sixel: attribute 4 in the answer to DA1 (`CSI ? 62;4;… c`: xterm as a VT340, foot,
//!   WezTerm, mlterm, Windows Terminal 1.22+).
//! - the cell size in pixels: `CSI 16 t` (answered `CSI 6;h;w t`), else the text area
//!   `CSI 14 t` (`CSI 4;h;w t`) over the grid; the caller prefers `TIOCGWINSZ`'s pixel fields
//!   when the terminal fills them.
//! - the largest sixel image: XTSMGRAPHICS (`CSI ? 2;1 S`, answered `CSI ? 2;0;w;h S`), else
//!   [`SIXEL_MAX_UNTOLD`]: xterm draws nothing of a larger one.
//!
//! DA1 goes last: every terminal answers it, and in order, so its answer means no other
//! answer is still on its way. Inside tmux the kitty query goes to the outer terminal through
//! passthrough (`ESC P tmux; … ESC \`, tmux 3.3+ with `allow-passthrough on`), whose answer
//! comes back after tmux's own answer to DA1: there the parser waits for the timeout.

/// The image id of the kitty query (any id: the answer echoes it).
pub const QUERY_ID: u32 = 31;

/// Smallest and largest cell size in pixels believed (width, height): an answer outside is
/// taken as no answer (a terminal that answers `CSI 6;0;0t`, or garbage).
const CELL_RANGE: (std::ops::RangeInclusive<u32>, std::ops::RangeInclusive<u32>) =
    (2..=128, 4..=256);

/// A pixel protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Protocol {
    /// The kitty graphics protocol.
    Kitty,
    /// Sixel.
    Sixel,
}

impl Protocol {
    /// The name the status line and `--graphics` use.
    pub fn name(self) -> &'static str {
        match self {
            Protocol::Kitty => "kitty",
            Protocol::Sixel => "sixel",
        }
    }
}

/// What `--graphics` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// Whatever the terminal answers it speaks (kitty first), else text cells.
    Auto,
    /// This protocol, whatever the terminal answers.
    Force(Protocol),
    /// Text cells; nothing is asked.
    None,
}

/// Wraps `bytes` for tmux's passthrough: `ESC P tmux;` then the bytes with each ESC doubled,
/// then `ESC \`.
pub fn tmux_passthrough(bytes: &[u8], out: &mut Vec<u8>) {
    out.extend_from_slice(b"\x1bPtmux;");
    for &b in bytes {
        if b == 0x1b {
            out.push(0x1b);
        }
        out.push(b);
    }
    out.extend_from_slice(b"\x1b\\");
}

/// The queries, in the order they are written (the kitty query through tmux's passthrough if
/// `tmux`).
pub fn queries(tmux: bool) -> Vec<u8> {
    let kitty = format!("\x1b_Gi={QUERY_ID},s=1,v=1,a=q,t=d,f=24;AAAA\x1b\\");
    let mut out = Vec::new();
    if tmux {
        tmux_passthrough(kitty.as_bytes(), &mut out);
    } else {
        out.extend_from_slice(kitty.as_bytes());
    }
    out.extend_from_slice(b"\x1b[16t\x1b[14t\x1b[?2;1S\x1b[c");
    out
}

/// The terminal's answers so far.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Answers {
    /// The kitty query was answered OK.
    pub kitty: bool,
    /// The kitty query was answered with an error (the message).
    pub kitty_error: Option<String>,
    /// DA1 was answered.
    pub da1: bool,
    /// DA1's answer lists attribute 4 (sixel).
    pub sixel: bool,
    /// The cell size in pixels (width, height), from `CSI 16 t`.
    pub cell: Option<(u32, u32)>,
    /// The text area in pixels (width, height), from `CSI 14 t`.
    pub area: Option<(u32, u32)>,
    /// The largest sixel image in pixels (width, height), from XTSMGRAPHICS.
    pub sixel_max: Option<(u32, u32)>,
    /// Bytes that were not answers (keys typed meanwhile), in order, for the key parser.
    pub other: Vec<u8>,
    /// An incomplete sequence kept for the next feed.
    pending: Vec<u8>,
}

/// Longest answer kept while incomplete; beyond it the bytes are given up as not an answer.
const MAX_ANSWER: usize = 256;

impl Answers {
    /// Parses `bytes` (after what an earlier call left incomplete).
    pub fn feed(&mut self, bytes: &[u8]) {
        let mut buf = std::mem::take(&mut self.pending);
        buf.extend_from_slice(bytes);
        let mut i = 0;
        while i < buf.len() {
            match self.one(&buf[i..]) {
                Some(used) => i += used,
                None if buf.len() - i <= MAX_ANSWER => {
                    self.pending = buf[i..].to_vec();
                    break;
                }
                None => {
                    self.other.push(buf[i]);
                    i += 1;
                }
            }
        }
    }

    /// Whether every answer that will come has come (DA1 answered), given whether the kitty
    /// query went through tmux (its answer then comes after DA1's: not done until it does).
    pub fn done(&self, tmux: bool) -> bool {
        self.da1 && (!tmux || self.kitty || self.kitty_error.is_some())
    }

    /// Bytes not answers, including an incomplete sequence left at the end (the timeout
    /// passed: it was not an answer).
    pub fn take_other(&mut self) -> Vec<u8> {
        let mut other = std::mem::take(&mut self.other);
        other.append(&mut self.pending);
        other
    }

    /// One answer or one other byte at the start of `b`: the bytes used, or `None` if `b`
    /// ends inside a sequence.
    fn one(&mut self, b: &[u8]) -> Option<usize> {
        if b[0] != 0x1b {
            self.other.push(b[0]);
            return Some(1);
        }
        match b.get(1)? {
            b'_' => {
                let end = b.windows(2).position(|w| w == b"\x1b\\")?;
                self.apc(&b[2..end]);
                Some(end + 2)
            }
            b'[' => {
                let mut j = 2;
                while j < b.len() && (0x20..=0x3f).contains(&b[j]) {
                    j += 1;
                }
                let f = *b.get(j)?;
                let params = std::str::from_utf8(&b[2..j]).unwrap_or("");
                if !self.csi(params, f) {
                    self.other.extend_from_slice(&b[..=j]);
                }
                Some(j + 1)
            }
            _ => {
                self.other.push(b[0]);
                Some(1)
            }
        }
    }

    /// An APC string's body: a kitty answer `G i=31;OK` (or `;ERROR:…`).
    fn apc(&mut self, body: &[u8]) {
        let Some(rest) = body.strip_prefix(b"G") else {
            return;
        };
        let text = String::from_utf8_lossy(rest);
        let (keys, message) = text.split_once(';').unwrap_or((&text, ""));
        let ours = keys
            .split(',')
            .any(|kv| kv == format!("i={QUERY_ID}").as_str());
        if !ours {
            return;
        }
        if message == "OK" {
            self.kitty = true;
        } else {
            self.kitty_error = Some(printable(message));
        }
    }

    /// A CSI answer: DA1 (`? … c`) or a size (`6;h;w t`, `4;h;w t`). Whether it was one.
    fn csi(&mut self, params: &str, f: u8) -> bool {
        if f == b'c'
            && let Some(attrs) = params.strip_prefix('?')
        {
            self.da1 = true;
            self.sixel |= attrs.split(';').skip(1).any(|a| a == "4");
            return true;
        }
        if f == b'S'
            && let Some(rest) = params.strip_prefix('?')
        {
            let n: Vec<Option<u32>> = rest.split(';').map(|v| v.parse().ok()).collect();
            if let [Some(2), Some(0), Some(w), Some(h)] = n.as_slice() {
                self.sixel_max = Some((*w, *h)).filter(|&(w, h)| w >= 16 && h >= 16);
            }
            return true;
        }
        if f != b't' {
            return false;
        }
        let n: Vec<Option<u32>> = params.split(';').map(|v| v.parse().ok()).collect();
        match n.as_slice() {
            [Some(6), Some(h), Some(w)] => {
                self.cell = Some((*w, *h)).filter(|&(w, h)| plausible(w, h));
                true
            }
            [Some(4), Some(h), Some(w)] => {
                self.area = Some((*w, *h)).filter(|&(w, h)| w > 0 && h > 0);
                true
            }
            _ => false,
        }
    }

    /// The cell size in pixels for a `cols × rows` terminal: `CSI 16 t`'s, else the text area
    /// over the grid, if plausible.
    pub fn cell_size(&self, cols: u16, rows: u16) -> Option<(u32, u32)> {
        self.cell.or_else(|| {
            let (w, h) = self.area?;
            let c = (w / u32::from(cols.max(1)), h / u32::from(rows.max(1)));
            plausible(c.0, c.1).then_some(c)
        })
    }
}

/// A cell size from `TIOCGWINSZ`'s pixel fields for a `cols × rows` terminal, if the terminal
/// filled them plausibly.
pub fn cell_from_winsize(cols: u16, rows: u16, xpixel: u16, ypixel: u16) -> Option<(u32, u32)> {
    if cols == 0 || rows == 0 {
        return None;
    }
    let c = (u32::from(xpixel / cols), u32::from(ypixel / rows));
    plausible(c.0, c.1).then_some(c)
}

fn plausible(w: u32, h: u32) -> bool {
    CELL_RANGE.0.contains(&w) && CELL_RANGE.1.contains(&h)
}

/// An answer's text with control characters replaced, to show in a message.
fn printable(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .take(60)
        .collect()
}

/// The protocol for `choice`, given the answers and whether the cell size in pixels is known.
/// Auto takes kitty if it answered OK, else sixel if DA1 lists it and the cell size is known
/// (sixel draws one image pixel to one screen pixel: guessing the size could scroll the
/// screen); forcing a protocol takes it regardless (kitty without a known size scales the
/// image to the cells; sixel then assumes [`FALLBACK_CELL`]).
pub fn choose(choice: Choice, answers: &Answers, cell_known: bool) -> Option<Protocol> {
    match choice {
        Choice::None => None,
        Choice::Force(p) => Some(p),
        Choice::Auto if answers.kitty => Some(Protocol::Kitty),
        Choice::Auto if answers.sixel && cell_known => Some(Protocol::Sixel),
        Choice::Auto => None,
    }
}

/// The largest sixel image assumed when the terminal does not answer XTSMGRAPHICS: xterm's
/// default `maxGraphicSize`, above which it draws nothing (xterm 379 as Debian builds it
/// answered neither XTSMGRAPHICS nor `CSI 16 t` under `-ti vt340`; it tells its pixels through
/// `TIOCGWINSZ`).
pub const SIXEL_MAX_UNTOLD: (u32, u32) = (1000, 1000);

/// The cell size assumed when the terminal tells none: 10×20 pixels, a common monospace cell
/// at 12–13 points. Only a forced protocol uses it.
pub const FALLBACK_CELL: (u32, u32) = (10, 20);

#[cfg(test)]
mod tests {
    use super::*;

    fn fed(chunks: &[&[u8]]) -> Answers {
        let mut a = Answers::default();
        for c in chunks {
            a.feed(c);
        }
        a
    }

    #[test]
    fn kitty_answers_ok_and_is_chosen_first() {
        let a = fed(&[b"\x1b_Gi=31;OK\x1b\\\x1b[6;20;10t\x1b[?62;4;22c"]);
        assert!(a.kitty && a.sixel && a.done(false));
        assert_eq!(a.cell, Some((10, 20)));
        assert_eq!(choose(Choice::Auto, &a, true), Some(Protocol::Kitty));
        assert!(a.other.is_empty());
    }

    #[test]
    fn sixel_needs_attribute_4_and_a_known_cell() {
        let a = fed(&[b"\x1b[4;780;1200t\x1b[?2;0;1000;1000S\x1b[?63;1;2;4;6;9;15;22c"]);
        assert_eq!(a.cell_size(120, 39), Some((10, 20)));
        assert_eq!(a.sixel_max, Some((1000, 1000)));
        assert_eq!(choose(Choice::Auto, &a, true), Some(Protocol::Sixel));
        assert_eq!(choose(Choice::Auto, &a, false), None);
        // "4" must be an attribute, not the class (`?4c` is not a VT340).
        let b = fed(&[b"\x1b[?4;6c"]);
        assert!(b.da1 && !b.sixel);
    }

    #[test]
    fn answers_split_at_every_byte_and_keys_between_are_kept() {
        let all: &[u8] = b"w\x1b_Gi=31;OK\x1b\\\x1b[A\x1b[6;17;8t\x1b[?1;2c";
        for cut in 0..all.len() {
            let a = fed(&[&all[..cut], &all[cut..]]);
            assert!(a.kitty && a.da1 && !a.sixel, "cut {cut}");
            assert_eq!(a.cell, Some((8, 17)));
            assert_eq!(a.other, b"w\x1b[A", "cut {cut}");
        }
    }

    #[test]
    fn wrong_answers_are_not_believed() {
        // Another image id, an error, an empty or absurd size, a DA1 without `?`.
        let mut a = fed(&[
            b"\x1b_Gi=7;OK\x1b\\\x1b_Gi=31;ENOTSUPPORTED:no\x1b\\\x1b[6;0;0t\x1b[4;9;99999t\x1b[0c",
        ]);
        assert!(!a.kitty && !a.da1);
        assert_eq!(a.kitty_error.as_deref(), Some("ENOTSUPPORTED:no"));
        assert_eq!(a.cell, None);
        assert_eq!(a.cell_size(80, 24), None);
        assert_eq!(choose(Choice::Auto, &a, false), None);
        assert_eq!(a.take_other(), b"\x1b[0c");
        // A string that never ends is given up (its bytes handed on), not kept forever.
        let mut b = fed(&[b"\x1b_G", &[b'x'; 300]]);
        assert!(b.take_other().len() >= 300);
        assert!(b.pending.len() <= MAX_ANSWER);
    }

    #[test]
    fn tmux_waits_for_the_outer_answer_and_doubles_escapes() {
        let q = queries(true);
        assert!(q.starts_with(b"\x1bPtmux;\x1b\x1b_Gi=31"));
        assert!(q.ends_with(b"\x1b[c"));
        let a = fed(&[b"\x1b[?1;2c"]);
        assert!(a.done(false) && !a.done(true));
        assert_eq!(cell_from_winsize(80, 24, 800, 480), Some((10, 20)));
        assert_eq!(cell_from_winsize(80, 24, 0, 0), None);
        assert_eq!(
            choose(Choice::Force(Protocol::Sixel), &a, false),
            Some(Protocol::Sixel)
        );
        assert_eq!(
            choose(Choice::None, &fed(&[b"\x1b_Gi=31;OK\x1b\\"]), true),
            None
        );
    }
}
