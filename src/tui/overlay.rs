//! Text drawn over the frame: the status line, the help box and the too-small message, as
//! cells in the frame's colour mode. Text from outside (a scene name) loses its control
//! characters first, so nothing shown can send escapes to the terminal.

use raytty::frame::{Cell, Colour};
use raytty::{CellGrid, ColorMode, printable};

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

/// Writes `text` into `grid` at (`col`, `row`), clipped to the grid, in text colours.
pub fn put_text(grid: &mut CellGrid, col: usize, row: usize, text: &str, mode: ColorMode) {
    if row >= grid.rows {
        return;
    }
    let (fg, bg) = text_colours(mode);
    for (i, ch) in printable(text).chars().enumerate() {
        let c = col + i;
        if c >= grid.cols {
            break;
        }
        grid.cells[row * grid.cols + c] = Cell { ch, fg, bg };
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
    let width = grid.cols;
    let padded: String = printable(text)
        .chars()
        .chain(std::iter::repeat(' '))
        .take(width)
        .collect();
    put_text(grid, 0, row, &padded, mode);
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
    let inner = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
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
