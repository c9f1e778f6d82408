//! Text drawn over the frame: the status line, the help box and the too-small message, as
//! cells in the frame's colour mode. Text from outside (a scene name) loses its control
//! characters first, so nothing shown can send escapes to the terminal.

use raytty::frame::{Cell, Colour, WIDE_TAIL};
use raytty::{CellGrid, ColorMode, printable};
use unicode_width::UnicodeWidthChar;

use super::keys::KEYS;

/// Text colours per mode: light grey on dark grey, or none at all in ASCII.
fn text_colours(mode: ColorMode) -> (Option<Colour>, Option<Colour>) {
    match mode {
        ColorMode::TrueColor => (
            Some(Colour::Rgb(230, 230, 230)),
            Some(Colour::Rgb(40, 40, 40)),
        ),
        ColorMode::Ansi256 => (Some(Colour::Indexed(254)), Some(Colour::Indexed(236))),
        ColorMode::Ascii => (None, None),
    }
}

/// How many terminal columns `text` takes once shown (after [`printable`]): two for a wide
/// character (CJK, most emoji), none for a combining mark.
pub fn text_width(text: &str) -> usize {
    printable(text)
        .chars()
        .map(|c| c.width().unwrap_or(0))
        .sum()
}

/// Writes `text` into `grid` at (`col`, `row`), clipped to the grid, in text colours. A wide
/// character takes two cells (the second is [`WIDE_TAIL`]); one that would straddle the right
/// edge is left out; zero-width characters are dropped.
pub fn put_text(grid: &mut CellGrid, col: usize, row: usize, text: &str, mode: ColorMode) {
    if row >= grid.rows {
        return;
    }
    let (fg, bg) = text_colours(mode);
    let start = row * grid.cols;
    let line = &mut grid.cells[start..start + grid.cols];
    let mut c = col;
    for ch in printable(text).chars() {
        let w = ch.width().unwrap_or(0);
        if w == 0 {
            continue;
        }
        if c + w > line.len() {
            break;
        }
        // Half of a wide character left behind would not be drawn: blank it.
        if line[c].ch == WIDE_TAIL && c > 0 {
            line[c - 1] = Cell { ch: ' ', fg, bg };
        }
        line[c] = Cell { ch, fg, bg };
        if w == 2 {
            line[c + 1] = Cell {
                ch: WIDE_TAIL,
                fg,
                bg,
            };
        }
        c += w;
        if line.get(c).is_some_and(|t| t.ch == WIDE_TAIL) {
            line[c] = Cell { ch: ' ', fg, bg };
        }
    }
}

/// A `cols × rows` grid of blank text cells.
pub fn blank(cols: usize, rows: usize, mode: ColorMode) -> CellGrid {
    let (fg, bg) = text_colours(mode);
    CellGrid {
        cols,
        rows,
        cells: vec![Cell { ch: ' ', fg, bg }; cols * rows],
    }
}

/// Fills row `row` with `text`, padded with blanks to the grid's width.
pub fn put_line(grid: &mut CellGrid, row: usize, text: &str, mode: ColorMode) {
    put_text(grid, 0, row, &" ".repeat(grid.cols), mode);
    put_text(grid, 0, row, text, mode);
}

/// The lines of the help box.
pub fn help_lines() -> Vec<String> {
    let mut lines = vec!["raytty keys".to_string(), String::new()];
    lines.extend(KEYS.iter().map(|(k, what)| format!("{k:<13} {what}")));
    lines.extend([
        String::new(),
        "Over ssh COLORTERM is not sent: run".to_string(),
        "COLORTERM=truecolor raytty, or press C".to_string(),
        String::new(),
        "H or ? closes this help".to_string(),
    ]);
    lines
}

/// Draws the help box centred over `grid`, clipped if the grid is small.
pub fn draw_help(grid: &mut CellGrid, mode: ColorMode) {
    let lines = help_lines();
    let inner = lines.iter().map(|l| text_width(l)).max().unwrap_or(0);
    let (w, h) = (inner + 4, lines.len() + 2);
    let left = grid.cols.saturating_sub(w) / 2;
    let top = grid.rows.saturating_sub(h) / 2;
    let blank_line = " ".repeat(w);
    for r in 0..h {
        put_text(grid, left, top + r, &blank_line, mode);
    }
    for (i, line) in lines.iter().enumerate() {
        put_text(grid, left + 2, top + 1 + i, line, mode);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_stripped() {
        assert_eq!(printable("box\x1b[2J\x07\u{9b}31m\n"), "box[2J31m");
        let mut g = blank(12, 1, ColorMode::TrueColor);
        put_line(&mut g, 0, "a\x1bb", ColorMode::TrueColor);
        let text: String = g.cells.iter().map(|c| c.ch).collect();
        assert_eq!(text, "ab          ");
    }

    fn shown(g: &CellGrid) -> String {
        g.cells
            .iter()
            .map(|c| c.ch)
            .filter(|&c| c != WIDE_TAIL)
            .collect()
    }

    #[test]
    fn wide_characters_take_two_cells_and_never_straddle_the_edge() {
        let mut g = blank(6, 1, ColorMode::TrueColor);
        put_line(&mut g, 0, "a漢字😀b", ColorMode::TrueColor);
        let chars: Vec<char> = g.cells.iter().map(|c| c.ch).collect();
        assert_eq!(chars, ['a', '漢', WIDE_TAIL, '字', WIDE_TAIL, ' ']);
        assert_eq!(text_width("a漢字😀b"), 8);
        // Overwriting half of a wide character blanks the other half.
        put_text(&mut g, 2, 0, "x", ColorMode::TrueColor);
        assert_eq!(shown(&g), "a x字 ");
        put_text(&mut g, 3, 0, "y", ColorMode::TrueColor);
        assert_eq!(shown(&g), "a xy  ");
    }

    #[test]
    fn bidi_and_format_characters_are_stripped() {
        let mut g = blank(12, 1, ColorMode::Ascii);
        put_line(
            &mut g,
            0,
            "evil\u{202e}box\u{200b}\u{2066}",
            ColorMode::Ascii,
        );
        assert_eq!(shown(&g), "evilbox     ");
        assert_eq!(text_width("\u{202e}\u{feff}e\u{301}"), 1);
    }

    #[test]
    fn help_lists_every_key_and_clips_to_a_small_grid() {
        let help = help_lines().join("\n");
        for (k, _) in KEYS {
            assert!(help.contains(k), "{k} missing from the help");
        }
        let mut g = blank(10, 3, ColorMode::Ascii);
        draw_help(&mut g, ColorMode::Ascii);
        assert_eq!(g.cells.len(), 30);
    }
}
