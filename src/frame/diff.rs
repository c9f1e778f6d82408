//! Frame diffs: the bytes that bring a terminal showing one grid to showing another, exactly or
//! within a tolerance, optionally within a byte budget. Cheaper than a cell-by-cell repaint:
//! - unchanged cells are skipped, with the shortest cursor move (`CUF`, `CR LF`, `CUP`, ...);
//! - a short unchanged run is rewritten instead when that costs fewer bytes than the move;
//! - a block cell is drawn whichever way the pen's colours carry over best: its glyph with the
//!   ink as foreground, or the complement's glyph with the colours swapped (`▀` or `▄` for a
//!   half-block; every quadrant, sextant and octant has its complement), and a cell of one
//!   colour as a space (background) or `█` (foreground);
//! - one SGR sets the foreground and the background together, and only what changes;
//! - block cells are sent in the order that reuses the pen's colours most, across the whole
//!   screen (`exact.rs`); within a tolerance, with colours rounded to a lattice of that
//!   spacing, so that neighbours share them exactly.

use super::cells::{FULL_SHAPE, glyph_for_shape, shape};
use super::{Cell, CellGrid, Colour, Pen, WIDE_TAIL, write_char};

/// The lower-half block: its foreground paints the cell's lower pixel.
pub const LOWER_HALF: char = '▄';
/// The full block: its foreground paints both pixels.
pub const FULL_BLOCK: char = '█';

/// How far a cell on screen may be from the frame's: a cell is sent if any channel of any of
/// its pixels differs by more than `tolerance` levels (0: exact), or if it differs in any
/// way that is not a colour level (a character, a palette colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiffLimits {
    /// Largest per-channel difference left unsent (truecolor block cells only).
    pub tolerance: u8,
    /// Stop starting new cells once this many bytes are written (`usize::MAX`: no limit).
    pub max_bytes: usize,
    /// The row to begin with (rows are visited in order from it, wrapping around), so that
    /// frames cut short by the budget take turns over the screen.
    pub first_row: usize,
}

impl DiffLimits {
    /// Every difference, no budget.
    pub const EXACT: DiffLimits = DiffLimits {
        tolerance: 0,
        max_bytes: usize::MAX,
        first_row: 0,
    };
}

/// What a diff left undone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiffOutcome {
    /// Every cell beyond the tolerance was sent (the budget did not cut the frame short).
    pub complete: bool,
    /// Where the next frame should begin if this one was cut short.
    pub next_row: usize,
    /// The largest difference left on screen: 0 when the screen shows the frame exactly,
    /// [`UNLIKE`] when some cell differs in more than its colour levels.
    pub max_error: u16,
}

/// The distance between two cells that differ in more than colour levels.
pub const UNLIKE: u16 = 256;

/// The two colours a block cell shows, ink and background (`▀`, any other block glyph of the
/// cell modes, or a space with a background: then both are the background), if it is one.
pub fn pixels(cell: &Cell) -> Option<(Colour, Colour)> {
    match (cell.ch, cell.fg, cell.bg) {
        (' ', _, Some(b)) => Some((b, b)),
        (ch, Some(f), Some(b)) if shape(ch).is_some_and(|s| s != FULL_SHAPE) => Some((f, b)),
        _ => None,
    }
}

/// A block cell's ink shape (see [`shape`]: a space has none) and its two colours.
fn picture(cell: &Cell) -> Option<(u32, Colour, Colour)> {
    let (f, b) = pixels(cell)?;
    Some((if cell.ch == ' ' { 0 } else { shape(cell.ch)? }, f, b))
}

/// How far apart two cells look: 0 if alike; for truecolor block cells, the largest channel
/// difference between the colours they show at any place of the cell (both cut on the finest
/// grid of [`super::SHAPE_ROWS`] rows, so cells of different modes compare too); else
/// [`UNLIKE`].
pub fn distance(a: &Cell, b: &Cell) -> u16 {
    match (picture(a), picture(b)) {
        (Some(pa), Some(pb)) => {
            if pa == pb {
                return 0;
            }
            let d = |x: Colour, y: Colour| match (x, y) {
                (Colour::Rgb(r0, g0, b0), Colour::Rgb(r1, g1, b1)) => {
                    [r0.abs_diff(r1), g0.abs_diff(g1), b0.abs_diff(b1)]
                        .into_iter()
                        .max()
                        .map_or(0, u16::from)
                }
                _ if x == y => 0,
                _ => UNLIKE,
            };
            let (sa, sb) = (pa.0, pb.0);
            [
                (sa & sb, pa.1, pb.1),
                (sa & !sb, pa.1, pb.2),
                (!sa & sb, pa.2, pb.1),
                (!sa & !sb & FULL_SHAPE, pa.2, pb.2),
            ]
            .into_iter()
            .filter(|&(place, _, _)| place != 0)
            .map(|(_, x, y)| d(x, y))
            .max()
            .unwrap_or(0)
        }
        _ if a == b => 0,
        _ => UNLIKE,
    }
}

/// The bytes that turn a screen showing `prev` (or, if `None`, anything) into one showing
/// `next` exactly, with the grid's top-left at the screen's row `top` (0-based); the pen is
/// reset at the end. A `prev` of another size counts as `None`.
pub fn encode_diff(prev: Option<&CellGrid>, next: &CellGrid, top: usize, out: &mut Vec<u8>) {
    let mut shown = prev.cloned();
    encode_diff_within(&mut shown, next, top, DiffLimits::EXACT, out);
}

/// Like [`encode_diff`], within `limits`, updating `shown` (what the screen shows; `None` or
/// another size: unknown, so every cell is sent) to what it shows afterwards. Cells within the
/// tolerance are left as they are; a block cell that is sent is sent within it (each channel
/// rounded to a multiple of 2·tolerance + 1, so that nearby cells share colours).
pub fn encode_diff_within(
    shown: &mut Option<CellGrid>,
    next: &CellGrid,
    top: usize,
    limits: DiffLimits,
    out: &mut Vec<u8>,
) -> DiffOutcome {
    if shown
        .as_ref()
        .is_none_or(|s| s.cols != next.cols || s.rows != next.rows)
    {
        // Unknown: every cell is sent, against a screen taken to show nothing alike.
        *shown = Some(CellGrid {
            cols: next.cols,
            rows: next.rows,
            cells: vec![
                Cell {
                    ch: WIDE_TAIL,
                    fg: None,
                    bg: None,
                };
                next.cells.len()
            ],
        });
    }
    let Some(screen) = shown.as_mut() else {
        unreachable!("set above");
    };
    let start = out.len();
    let mut w = Writer {
        pen: Pen::default(),
        cursor: None,
        top,
    };
    let mut outcome = DiffOutcome {
        complete: true,
        next_row: 0,
        max_error: 0,
    };
    let cols = next.cols;
    // A row with text in it (the status line, the help) is sent whole, left to right, whatever
    // the budget: a half-sent line of text (its spaces are block cells) would read as garble.
    let text_rows: Vec<bool> = (0..next.rows)
        .map(|r| {
            next.cells[r * cols..(r + 1) * cols]
                .iter()
                .any(|c| pixels(c).is_none())
        })
        .collect();
    exact::send_block_cells(screen, next, &text_rows, limits, &mut w, out, start);
    'rows: for k in 0..next.rows {
        let r = (limits.first_row + k) % next.rows.max(1);
        let row = r * cols..(r + 1) * cols;
        let want = &next.cells[row.clone()];
        let have = &mut screen.cells[row];
        let dirty = |have: &[Cell], c: usize| -> bool {
            if want[c].ch == WIDE_TAIL {
                return false;
            }
            let tail = c + 1 < cols && want[c + 1].ch == WIDE_TAIL;
            distance(&have[c], &want[c]) > limits.tolerance as u16
                || (tail && have[c + 1] != want[c + 1])
        };
        // Block cells were sent above (or the budget stopped them): what is left is rows of
        // text, sent left to right (so that a frame shown half-received, by a terminal without
        // synchronized output, shows the new text up to a column and the old after it).
        let mut todo: Vec<usize> = (0..cols).filter(|&c| dirty(have, c)).collect();
        while !todo.is_empty() {
            // Over the budget, only rows of text are still sent: image cells wait for the next
            // frame, which begins with this row.
            if !text_rows[r] && out.len() - start >= limits.max_bytes {
                if outcome.complete {
                    outcome = DiffOutcome {
                        complete: false,
                        next_row: r,
                        max_error: UNLIKE,
                    };
                }
                continue 'rows;
            }
            let c = todo.remove(0);
            w.move_to(out, r, c);
            let cell = want[c];
            w.draw(out, &cell, todo.first().map(|&n| want[n]).as_ref());
            have[c] = cell;
            let wide = c + 1 < cols && want[c + 1].ch == WIDE_TAIL;
            if wide {
                have[c + 1] = want[c + 1];
            }
            // Past the last column the cursor position is terminal-dependent: forget it. So is
            // it after a wide character, should the terminal's width tables differ from ours.
            w.cursor = (c + 1 < cols && !wide).then_some((r, c + 1));
        }
    }
    if outcome.complete {
        outcome.max_error = screen
            .cells
            .iter()
            .zip(&next.cells)
            .map(|(a, b)| distance(a, b))
            .max()
            .unwrap_or(0);
    }
    if out.len() > start && (w.pen.fg.is_some() || w.pen.bg.is_some()) {
        out.extend_from_slice(b"\x1b[0m");
    }
    outcome
}

/// What is sent for `cell` within `tolerance`: each channel of a truecolor pixel rounded to the
/// nearest multiple of `2·tolerance + 1` (at most `tolerance` off; 0: the cell as it is). Nearby
/// pixels then share exact colours, so an approximate frame sends a colour for a whole patch
/// of cells rather than for each (about 7 bytes a cell within 8 levels against 17 exact).
fn quantize(cell: &Cell, tolerance: u8) -> Cell {
    let step = 2 * u16::from(tolerance) + 1;
    let level = |v: u8| ((u16::from(v) + step / 2) / step * step).min(255) as u8;
    let round = |c: Colour| match c {
        Colour::Rgb(r, g, b) => Colour::Rgb(level(r), level(g), level(b)),
        c => c,
    };
    match pixels(cell) {
        Some((ink, bg)) if tolerance > 0 => Cell::two(cell.ch, round(ink), round(bg)),
        _ => *cell,
    }
}

/// The encoder's belief about the terminal: the pen and, if known, the cursor.
#[derive(Clone, Copy)]
struct Writer {
    pen: Pen,
    cursor: Option<(usize, usize)>,
    top: usize,
}

/// One way to draw a cell: the character, and the colours it needs (`None`: any).
type Way = (char, Option<Colour>, Option<Colour>);

/// The ways to draw `cell` that look the same: two for a block cell (its glyph, and its
/// complement's with the colours swapped), one for text.
fn ways(cell: &Cell) -> [Way; 2] {
    match picture(cell) {
        Some((_, u, l)) if u == l => [(' ', None, Some(u)), (FULL_BLOCK, Some(u), None)],
        Some((s, u, l)) => {
            let other = glyph_for_shape(!s & FULL_SHAPE)
                .map_or((cell.ch, Some(u), Some(l)), |g| (g, Some(l), Some(u)));
            [(cell.ch, Some(u), Some(l)), other]
        }
        None => [(cell.ch, cell.fg, cell.bg); 2],
    }
}

/// Bytes of the decimal form of `v`.
fn digits(v: u8) -> usize {
    match v {
        0..=9 => 1,
        10..=99 => 2,
        _ => 3,
    }
}

/// Bytes of `38;2;R;G;B` (or `38;5;N`) for `c`.
fn colour_len(c: Colour) -> usize {
    match c {
        Colour::Rgb(r, g, b) => 7 + digits(r) + digits(g) + digits(b),
        Colour::Indexed(i) => 5 + digits(i),
    }
}

/// Bytes of the SGR that gives `pen` the colours of `way`, and the pen afterwards.
fn sgr_cost(pen: Pen, way: &Way) -> (usize, Pen) {
    let fg = way.1.filter(|&c| Some(c) != pen.fg);
    let bg = way.2.filter(|&c| Some(c) != pen.bg);
    let len = match (fg, bg) {
        (None, None) => 0,
        (Some(a), None) | (None, Some(a)) => 3 + colour_len(a),
        (Some(a), Some(b)) => 4 + colour_len(a) + colour_len(b),
    };
    let after = Pen {
        fg: way.1.or(pen.fg),
        bg: way.2.or(pen.bg),
    };
    (len + way.0.len_utf8(), after)
}

impl Writer {
    /// Draws `cell` at the cursor the cheapest way, counting what the pen it leaves costs the
    /// cell drawn `after` it, if any.
    fn draw(&mut self, out: &mut Vec<u8>, cell: &Cell, after: Option<&Cell>) {
        let best = ways(cell)
            .into_iter()
            .min_by_key(|way| {
                let (cost, pen) = sgr_cost(self.pen, way);
                let next = after.map_or(0, |n| {
                    ways(n)
                        .iter()
                        .map(|w| sgr_cost(pen, w).0)
                        .min()
                        .unwrap_or(0)
                });
                cost + next
            })
            .unwrap_or((cell.ch, cell.fg, cell.bg));
        self.pen.set(
            out,
            &Cell {
                ch: best.0,
                fg: best.1,
                bg: best.2,
            },
        );
        write_char(out, best.0);
        if let Some((r, c)) = self.cursor {
            self.cursor = Some((r, c + 1));
        }
    }

    /// Bytes of the cheapest way to draw `cell` with the pen as it is.
    fn draw_cost(&self, cell: &Cell) -> usize {
        ways(cell)
            .iter()
            .map(|w| sgr_cost(self.pen, w).0)
            .min()
            .unwrap_or(0)
    }

    /// Bytes of [`Writer::move_to`] (row, col), counted without writing them.
    fn move_len(&self, r: usize, c: usize) -> usize {
        let horizontal = |from: usize, to: usize| relative_len(from.abs_diff(to));
        let cup = 4 + decimal_len(self.top + r + 1) + decimal_len(c + 1);
        match self.cursor {
            Some((cr, cc)) if cr == r => cup.min(horizontal(cc, c)),
            Some((cr, cc)) if cr < r => {
                let down = r - cr;
                cup.min(1 + down + horizontal(0, c))
                    .min(relative_len(down) + horizontal(cc, c))
            }
            _ => cup,
        }
    }

    /// Moves the cursor to (row, col) of the grid the shortest way it knows.
    fn move_to(&mut self, out: &mut Vec<u8>, r: usize, c: usize) {
        // Already there (most cells of a whole frame): nothing to write, nothing to allocate.
        if self.cursor == Some((r, c)) {
            return;
        }
        let mut best = format!("\x1b[{};{}H", self.top + r + 1, c + 1);
        let mut consider = |s: String| {
            if s.len() < best.len() {
                best = s;
            }
        };
        let horizontal = |from: usize, to: usize| match to.cmp(&from) {
            std::cmp::Ordering::Equal => String::new(),
            std::cmp::Ordering::Greater => relative(to - from, 'C'),
            std::cmp::Ordering::Less => relative(from - to, 'D'),
        };
        match self.cursor {
            Some((cr, cc)) if cr == r => consider(horizontal(cc, c)),
            Some((cr, cc)) if cr < r => {
                let down = r - cr;
                consider(format!("\r{}{}", "\n".repeat(down), horizontal(0, c)));
                consider(format!("{}{}", relative(down, 'B'), horizontal(cc, c)));
            }
            _ => {}
        }
        debug_assert_eq!(best.len(), self.move_len(r, c));
        out.extend_from_slice(best.as_bytes());
        self.cursor = Some((r, c));
    }
}

/// Bytes of the decimal form of `n`.
fn decimal_len(n: usize) -> usize {
    n.checked_ilog10().map_or(1, |d| d as usize + 1)
}

/// Bytes of [`relative`] by `n` (0: no move).
fn relative_len(n: usize) -> usize {
    match n {
        0 => 0,
        1 => 3,
        n => 3 + decimal_len(n),
    }
}

/// A relative cursor move by `n` (CUF `C`, CUB `D`, CUD `B`), with the default count left out.
fn relative(n: usize, f: char) -> String {
    if n == 1 {
        format!("\x1b[{f}")
    } else {
        format!("\x1b[{n}{f}")
    }
}

mod exact;
#[cfg(test)]
mod tests;
