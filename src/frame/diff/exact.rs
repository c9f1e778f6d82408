//! The order of an exact diff's block cells. Every colour the pen lacks costs an SGR of 16-19
//! bytes, a cursor move 3-9: so the next cell sent is one that needs no new colour, wherever it
//! is on the screen, else one that shares a colour with the pen, and only when no cell does, the
//! next in reading order. The pen holds two colours and a block cell needs its one or two (as
//! `▀`/`▄` or space/`█`, whichever way round the pen holds them), so a walk from cell to cell
//! through shared colours pays about one colour per distinct pair of colours rather than one
//! per cell (a light move at 200×50: 0.84 distinct pairs per changed cell within a row, 0.48
//! over the whole screen). Among cells as cheap to draw, the nearest in reading order before
//! or after the cursor, whichever is cheaper to reach.

use std::collections::{BTreeSet, HashMap};
use std::hash::{BuildHasherDefault, Hasher};

use super::{
    Cell, CellGrid, Colour, DiffLimits, Writer, distance, pixels, quantize, sgr_cost, ways,
};

/// Cells by position in reading order (from the diff's first row), so the nearest to the
/// cursor is a range query.
type Places = BTreeSet<usize>;

/// A hasher for colour keys (small integers, not chosen by an adversary): one multiply per
/// word, several times faster than the default SipHash in this hot loop.
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u32(&mut self, n: u32) {
        self.write_u64(u64::from(n));
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
}

type Map<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// A colour as a number, so a pair of them can be put in order.
fn key(c: Colour) -> u32 {
    match c {
        Colour::Rgb(r, g, b) => u32::from_be_bytes([0, r, g, b]),
        Colour::Indexed(i) => 1 << 24 | u32::from(i),
    }
}

/// The pending cells, indexed three ways.
#[derive(Default)]
struct Pending {
    /// Two-colour cells by their (unordered) pair of colours.
    pairs: Map<(u32, u32), Places>,
    /// One-colour cells by their colour.
    singles: Map<u32, Places>,
    /// Every cell by each of its colours.
    by_colour: Map<u32, Places>,
    /// Every cell, in reading order.
    all: Places,
}

impl Pending {
    fn change(&mut self, place: usize, (up, lo): (Colour, Colour), add: bool) {
        let (a, b) = (key(up), key(lo));
        let edit = |set: &mut Places| {
            if add {
                set.insert(place);
            } else {
                set.remove(&place);
            }
        };
        if a == b {
            edit(self.singles.entry(a).or_default());
        } else {
            edit(self.pairs.entry((a.min(b), a.max(b))).or_default());
            edit(self.by_colour.entry(b).or_default());
        }
        edit(self.by_colour.entry(a).or_default());
        edit(&mut self.all);
    }

    /// Cells still to send that hold colour `c`.
    fn count(&self, c: Option<Colour>) -> usize {
        c.and_then(|c| self.by_colour.get(&key(c)))
            .map_or(0, BTreeSet::len)
    }
}

/// Sends the block cells of `next` that `screen` shows further than the tolerance from it
/// (0: not exactly), [`quantize`]d to the tolerance, cheapest first (see the module's note),
/// updating `screen`, until `out` holds `max_bytes` since `start`. Rows with text in them
/// (`text_rows`) are left to the caller, which sends them whole.
pub(super) fn send_block_cells(
    screen: &mut CellGrid,
    next: &CellGrid,
    text_rows: &[bool],
    limits: DiffLimits,
    w: &mut Writer,
    out: &mut Vec<u8>,
    start: usize,
) {
    let DiffLimits {
        tolerance,
        max_bytes,
        first_row,
    } = limits;
    let (cols, rows) = (next.cols, next.rows);
    if cols == 0 || rows == 0 {
        return;
    }
    // Position in reading order from `first_row`, and back.
    let place = |r: usize, c: usize| ((r + rows - first_row % rows) % rows) * cols + c;
    let cell_at = |p: usize| ((p / cols + first_row) % rows, p % cols);
    // What is sent for each cell (only block cells further than the tolerance are).
    let send: Vec<Cell> = (screen.cells.iter().zip(&next.cells))
        .map(|(have, want)| {
            let far = distance(have, want) > u16::from(tolerance);
            if far && pixels(want).is_some() {
                quantize(want, tolerance)
            } else {
                *have
            }
        })
        .collect();
    let mut pending = Pending::default();
    for r in (0..rows).filter(|&r| !text_rows[r]) {
        for c in 0..cols {
            let i = r * cols + c;
            if let Some(px) = pixels(&send[i])
                && screen.cells[i] != send[i]
            {
                pending.change(place(r, c), px, true);
            }
        }
    }
    // Where the cursor is in reading order (after the last cell sent, if it is not known).
    let mut here = 0;
    while out.len() - start < max_bytes {
        if let Some((r, c)) = w.cursor {
            here = place(r, c);
        }
        let Some(p) = pick(w, &send, cols, &pending, here, &cell_at) else {
            break;
        };
        let (r, c) = cell_at(p);
        let cell = send[r * cols + c];
        if let Some(px) = pixels(&cell) {
            pending.change(p, px, false);
        }
        w.move_to(out, r, c);
        let way = best_way(w, &cell, &pending);
        w.pen.set(
            out,
            &Cell {
                ch: way.0,
                fg: way.1,
                bg: way.2,
            },
        );
        super::write_char(out, way.0);
        screen.cells[r * cols + c] = cell;
        w.cursor = (c + 1 < cols).then_some((r, c + 1));
        here = p + 1;
    }
}

/// The next cell to send: one the pen can draw as it is, else one that needs one colour more,
/// else the next in reading order; each time the cheapest to reach of the nearest before and
/// after the cursor.
fn pick(
    w: &Writer,
    send: &[Cell],
    cols: usize,
    pending: &Pending,
    here: usize,
    cell_at: &impl Fn(usize) -> (usize, usize),
) -> Option<usize> {
    if pending.all.contains(&here) && w.cursor.is_some() {
        let (r, c) = cell_at(here);
        if w.draw_cost(&send[r * cols + c]) == 0 {
            return Some(here);
        }
    }
    let cost = |p: usize| {
        let (r, c) = cell_at(p);
        w.move_len(r, c) + w.draw_cost(&send[r * cols + c])
    };
    let cheapest = |places: Vec<usize>| places.into_iter().min_by_key(|&p| (cost(p), p));
    let (fg, bg) = (w.pen.fg.map(key), w.pen.bg.map(key));
    let mut free = Vec::new();
    if let (Some(a), Some(b)) = (fg, bg) {
        free.extend(nearest(pending.pairs.get(&(a.min(b), a.max(b))), here));
    }
    for c in [fg, bg].into_iter().flatten() {
        free.extend(nearest(pending.singles.get(&c), here));
    }
    if let Some(p) = cheapest(free) {
        return Some(p);
    }
    let sharing: Vec<usize> = [fg, bg]
        .into_iter()
        .flatten()
        .flat_map(|c| nearest(pending.by_colour.get(&c), here))
        .collect();
    cheapest(sharing).or_else(|| {
        pending
            .all
            .range(here..)
            .next()
            .or(pending.all.first())
            .copied()
    })
}

/// The places in `set` nearest `here`: the first at or after it, and the last before it.
fn nearest(set: Option<&Places>, here: usize) -> impl Iterator<Item = usize> + '_ {
    set.into_iter().flat_map(move |s| {
        [
            s.range(here..).next().copied(),
            s.range(..here).next_back().copied(),
        ]
        .into_iter()
        .flatten()
    })
}

/// The cheapest way to draw `cell` with the pen as it is; of two as cheap, the one that keeps
/// the pen's colour with more cells still to send.
fn best_way(w: &Writer, cell: &Cell, pending: &Pending) -> (char, Option<Colour>, Option<Colour>) {
    ways(cell)
        .into_iter()
        .min_by_key(|way| {
            let (cost, pen) = sgr_cost(w.pen, way);
            (
                cost,
                usize::MAX - pending.count(pen.fg) - pending.count(pen.bg),
            )
        })
        .unwrap_or((cell.ch, cell.fg, cell.bg))
}
