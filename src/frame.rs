//! Frame encoding: an image becomes a grid of terminal cells (one cell = two pixels stacked),
//! and a grid becomes bytes, either as a whole text frame or as the difference from the frame
//! the terminal already shows. Pure functions: no terminal, no I/O.

use std::io::Write;

use crate::image::Image;

/// How cells are coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorMode {
    /// 24-bit colour: `▀` with the upper pixel as foreground and the lower as background.
    TrueColor,
    /// The xterm 256-colour palette (6×6×6 cube and grey ramp), nearest colour.
    Ansi256,
    /// No escapes at all: one character per cell from a luminance ramp.
    Ascii,
}

impl ColorMode {
    /// The mode's name as the CLI and status line show it.
    pub fn name(self) -> &'static str {
        match self {
            ColorMode::TrueColor => "truecolor",
            ColorMode::Ansi256 => "256",
            ColorMode::Ascii => "ascii",
        }
    }

    /// The next mode in the cycle truecolor → 256 → ascii → truecolor.
    pub fn next(self) -> ColorMode {
        match self {
            ColorMode::TrueColor => ColorMode::Ansi256,
            ColorMode::Ansi256 => ColorMode::Ascii,
            ColorMode::Ascii => ColorMode::TrueColor,
        }
    }
}

/// `s` without control characters (C0, DEL, C1) or format characters (bidi overrides and
/// isolates, zero-width joiners and spaces, the BOM, ...): safe to show in a terminal, and shown
/// left to right as it is stored. Text from outside (a scene's name, a path, a key from a scene
/// file) goes through this before it is shown.
pub fn printable(s: &str) -> String {
    s.chars()
        .filter(|&c| !c.is_control() && !is_format(c))
        .collect()
}

/// Unicode's format characters (general category Cf), which change how the text around them is
/// laid out without showing anything themselves.
fn is_format(c: char) -> bool {
    matches!(
        c as u32,
        0xAD | 0x600..=0x605
            | 0x61C
            | 0x6DD
            | 0x70F
            | 0x890..=0x891
            | 0x8E2
            | 0x180E
            | 0x200B..=0x200F
            | 0x202A..=0x202E
            | 0x2060..=0x2064
            | 0x2066..=0x206F
            | 0xFEFF
            | 0xFFF9..=0xFFFB
            | 0x110BD
            | 0x110CD
            | 0x13430..=0x1343F
            | 0x1BCA0..=0x1BCA3
            | 0x1D173..=0x1D17A
            | 0xE0001
            | 0xE0020..=0xE007F
    )
}

/// A terminal colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Colour {
    /// 24-bit RGB.
    Rgb(u8, u8, u8),
    /// An index into the 256-colour palette.
    Indexed(u8),
}

/// One terminal cell: a character with optional foreground and background colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cell {
    /// The character drawn (`▀`, a space, or an ASCII ramp character).
    pub ch: char,
    /// Foreground colour, if the character shows one.
    pub fg: Option<Colour>,
    /// Background colour, if any.
    pub bg: Option<Colour>,
}

/// The upper-half block: its foreground paints the cell's upper pixel.
pub const UPPER_HALF: char = '▀';

/// The cell to the right of a double-width character (a CJK ideograph, most emoji), which
/// covers it: the encoders never write it, and a grid holds it only right after such a
/// character.
pub const WIDE_TAIL: char = '\0';

/// The ASCII luminance ramp, darkest first.
pub const ASCII_RAMP: &[u8] = b" .:-=+*#%@";

/// A grid of cells, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CellGrid {
    /// Columns.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// `cols × rows` cells.
    pub cells: Vec<Cell>,
}

impl CellGrid {
    /// Turns an image of `cols × 2·rows` pixels into `cols × rows` cells. An odd last pixel row
    /// is paired with black.
    pub fn from_image(image: &Image, mode: ColorMode) -> CellGrid {
        let cols = image.width as usize;
        let rows = (image.height as usize).div_ceil(2);
        let rgb = image.to_rgb8();
        let px = |x: usize, y: usize| {
            if y < image.height as usize {
                rgb[y * cols + x]
            } else {
                [0; 3]
            }
        };
        let mut cells = Vec::with_capacity(cols * rows);
        for r in 0..rows {
            for x in 0..cols {
                let (up, lo) = (px(x, 2 * r), px(x, 2 * r + 1));
                cells.push(match mode {
                    ColorMode::TrueColor => half_block(
                        Colour::Rgb(up[0], up[1], up[2]),
                        Colour::Rgb(lo[0], lo[1], lo[2]),
                    ),
                    ColorMode::Ansi256 => half_block(
                        Colour::Indexed(nearest_256(up)),
                        Colour::Indexed(nearest_256(lo)),
                    ),
                    ColorMode::Ascii => {
                        let y = (luminance(up) + luminance(lo)) * 0.5;
                        let i = (y / 255.0 * (ASCII_RAMP.len() - 1) as f32 + 0.5) as usize;
                        Cell {
                            ch: ASCII_RAMP[i.min(ASCII_RAMP.len() - 1)] as char,
                            fg: None,
                            bg: None,
                        }
                    }
                });
            }
        }
        CellGrid { cols, rows, cells }
    }

    /// The cell at (col, row).
    pub fn get(&self, col: usize, row: usize) -> Cell {
        self.cells[row * self.cols + col]
    }
}

/// A cell showing `up` over `lo`: a space with only a background when the two are equal.
fn half_block(up: Colour, lo: Colour) -> Cell {
    if up == lo {
        Cell {
            ch: ' ',
            fg: None,
            bg: Some(lo),
        }
    } else {
        Cell {
            ch: UPPER_HALF,
            fg: Some(up),
            bg: Some(lo),
        }
    }
}

/// Rec. 709 luminance of an 8-bit colour, 0..=255.
fn luminance(c: [u8; 3]) -> f32 {
    0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32
}

/// The xterm cube's six levels.
const CUBE: [u8; 6] = [0, 95, 135, 175, 215, 255];

/// The nearest colour of the xterm 256 palette's cube (16-231) and grey ramp (232-255), by
/// squared RGB distance. The 16 system colours are left out: terminals theme them.
pub fn nearest_256(c: [u8; 3]) -> u8 {
    let level = |v: u8| {
        let mut best = 0;
        for (i, &l) in CUBE.iter().enumerate() {
            if (l as i32 - v as i32).abs() < (CUBE[best] as i32 - v as i32).abs() {
                best = i;
            }
        }
        best
    };
    let dist = |a: [u8; 3], b: [u8; 3]| -> i32 {
        (0..3).map(|i| (a[i] as i32 - b[i] as i32).pow(2)).sum()
    };
    let (r, g, b) = (level(c[0]), level(c[1]), level(c[2]));
    let cube = [CUBE[r], CUBE[g], CUBE[b]];
    let avg = (c[0] as i32 + c[1] as i32 + c[2] as i32) / 3;
    let gi = ((avg - 8).max(0) / 10).min(23) as u8;
    let grey = 8 + 10 * gi;
    if dist(c, [grey; 3]) < dist(c, cube) {
        232 + gi
    } else {
        16 + 36 * r as u8 + 6 * g as u8 + b as u8
    }
}

/// The SGR state the encoder believes the terminal is in.
#[derive(Clone, Copy, Default)]
struct Pen {
    fg: Option<Colour>,
    bg: Option<Colour>,
}

impl Pen {
    /// Writes one SGR sequence that gives `cell`'s colours (only the parts that changed; the
    /// foreground of a space is left alone), and updates the pen.
    fn set(&mut self, out: &mut Vec<u8>, cell: &Cell) {
        let fg = cell.fg.filter(|&c| Some(c) != self.fg);
        let bg = cell.bg.filter(|&c| Some(c) != self.bg);
        if fg.is_none() && bg.is_none() {
            return;
        }
        out.extend_from_slice(b"\x1b[");
        if let Some(c) = fg {
            write_colour(out, 38, c);
            self.fg = Some(c);
        }
        if let Some(c) = bg {
            if fg.is_some() {
                out.push(b';');
            }
            write_colour(out, 48, c);
            self.bg = Some(c);
        }
        out.push(b'm');
    }
}

fn write_colour(out: &mut Vec<u8>, base: u8, c: Colour) {
    let _ = match c {
        Colour::Rgb(r, g, b) => write!(out, "{base};2;{r};{g};{b}"),
        Colour::Indexed(i) => write!(out, "{base};5;{i}"),
    };
}

fn write_char(out: &mut Vec<u8>, ch: char) {
    let mut buf = [0; 4];
    out.extend_from_slice(ch.encode_utf8(&mut buf).as_bytes());
}

/// A whole frame as text for a stream (stdout, a file): rows separated by newlines, each
/// coloured row ending in a reset so no colour bleeds past it. ASCII frames have no escapes.
pub fn encode_text(grid: &CellGrid) -> Vec<u8> {
    let mut out = Vec::with_capacity(grid.cells.len() * 8);
    for row in grid.cells.chunks(grid.cols.max(1)) {
        let mut pen = Pen::default();
        for cell in row.iter().filter(|c| c.ch != WIDE_TAIL) {
            pen.set(&mut out, cell);
            write_char(&mut out, cell.ch);
        }
        if pen.fg.is_some() || pen.bg.is_some() {
            out.extend_from_slice(b"\x1b[0m");
        }
        out.push(b'\n');
    }
    out
}

/// The bytes that turn a screen showing `prev` (or, if `None`, anything) into one showing
/// `next`, with the grid's top-left at the screen's row `top` (0-based). Unchanged cells are
/// skipped with cursor moves; colours are set only when they change; the pen is reset at the
/// end. A `prev` of another size counts as `None`.
pub fn encode_diff(prev: Option<&CellGrid>, next: &CellGrid, top: usize, out: &mut Vec<u8>) {
    let prev = prev.filter(|p| p.cols == next.cols && p.rows == next.rows);
    let mut pen = Pen::default();
    // Where the terminal's cursor is, if known.
    let mut cursor: Option<(usize, usize)> = None;
    let mut wrote = false;
    for r in 0..next.rows {
        for c in 0..next.cols {
            let i = r * next.cols + c;
            let cell = next.cells[i];
            let wide =
                next.cells.get(i + 1).is_some_and(|t| t.ch == WIDE_TAIL) && c + 1 < next.cols;
            let same = |j: usize| prev.is_some_and(|p| p.cells[j] == next.cells[j]);
            if cell.ch == WIDE_TAIL || (same(i) && (!wide || same(i + 1))) {
                continue;
            }
            match cursor {
                Some((cr, cc)) if cr == r && cc == c => {}
                Some((cr, cc)) if cr == r && cc < c => {
                    let _ = write!(out, "\x1b[{}C", c - cc);
                }
                _ => {
                    let _ = write!(out, "\x1b[{};{}H", top + r + 1, c + 1);
                }
            }
            pen.set(out, &cell);
            write_char(out, cell.ch);
            wrote = true;
            // Past the last column the cursor position is terminal-dependent: forget it. So is
            // it after a wide character, should the terminal's width tables differ from ours.
            cursor = (c + 1 < next.cols && !wide).then_some((r, c + 1));
        }
    }
    if wrote && (pen.fg.is_some() || pen.bg.is_some()) {
        out.extend_from_slice(b"\x1b[0m");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn image(pixels: &[[f32; 3]], w: u32) -> Image {
        let pixels: Vec<Vec3> = pixels.iter().map(|&p| Vec3::from(p)).collect();
        Image {
            width: w,
            height: pixels.len() as u32 / w,
            pixels,
        }
    }

    #[test]
    fn equal_pixels_make_a_space_with_a_background() {
        let img = image(
            &[
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            2,
        );
        let g = CellGrid::from_image(&img, ColorMode::TrueColor);
        assert_eq!(g.cells.len(), 2);
        let text = String::from_utf8(encode_text(&g)).unwrap();
        assert_eq!(text, "\x1b[48;2;255;0;0m \x1b[48;2;0;0;255m \x1b[0m\n");
        let img = image(&[[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 1);
        let g = CellGrid::from_image(&img, ColorMode::TrueColor);
        assert_eq!(
            g.cells[0],
            Cell {
                ch: ' ',
                fg: None,
                bg: Some(Colour::Rgb(255, 0, 0))
            }
        );
    }

    #[test]
    fn colours_are_emitted_only_when_they_change() {
        let img = image(
            &[[1.0, 0.0, 0.0]; 6]
                .iter()
                .chain(&[[0.0, 1.0, 0.0]; 6])
                .copied()
                .collect::<Vec<_>>(),
            6,
        );
        let text = encode_text(&CellGrid::from_image(&img, ColorMode::TrueColor));
        assert_eq!(
            String::from_utf8(text).unwrap(),
            "\x1b[38;2;255;0;0;48;2;0;255;0m▀▀▀▀▀▀\x1b[0m\n"
        );
    }

    #[test]
    fn nearest_256_hits_cube_and_grey() {
        assert_eq!(nearest_256([0, 0, 0]), 16);
        assert_eq!(nearest_256([255, 255, 255]), 231);
        assert_eq!(nearest_256([255, 0, 0]), 196);
        assert_eq!(nearest_256([128, 128, 128]), 244);
    }

    /// What a cell shows: its two pixels for a block-drawing cell, else its character and
    /// colours (the foreground of a space is invisible).
    #[derive(Debug, PartialEq)]
    enum Look {
        Pixels(Option<Colour>, Option<Colour>),
        Text(char, Option<Colour>, Option<Colour>),
    }

    fn look(cell: &Cell) -> Look {
        match cell.ch {
            UPPER_HALF => Look::Pixels(cell.fg, cell.bg),
            '▄' => Look::Pixels(cell.bg, cell.fg),
            '█' => Look::Pixels(cell.fg, cell.fg),
            ' ' => Look::Pixels(cell.bg, cell.bg),
            ch => Look::Text(ch, cell.fg, cell.bg),
        }
    }

    fn looks(g: &CellGrid) -> Vec<Look> {
        g.cells.iter().map(look).collect()
    }

    /// A small terminal: applies cursor moves, SGR colours and characters to `screen`, as the
    /// encoders use them; panics on anything else.
    fn apply(screen: &mut CellGrid, bytes: &[u8]) {
        let text = std::str::from_utf8(bytes).expect("UTF-8 output");
        let (mut r, mut c) = (0usize, 0usize);
        let (mut fg, mut bg) = (None, None);
        let mut chars = text.chars().peekable();
        while let Some(ch) = chars.next() {
            if ch != '\x1b' {
                screen.cells[r * screen.cols + c] = Cell { ch, fg, bg };
                c += 1;
                continue;
            }
            assert_eq!(chars.next(), Some('['));
            let mut params = String::new();
            let fin = loop {
                let ch = chars.next().expect("a whole sequence");
                if ch.is_ascii_alphabetic() {
                    break ch;
                }
                params.push(ch);
            };
            let nums: Vec<usize> = params.split(';').map(|p| p.parse().unwrap_or(0)).collect();
            match fin {
                'H' => (r, c) = (nums[0] - 1, nums[1] - 1),
                'C' => c += nums[0],
                'm' => {
                    let mut i = 0;
                    while i < nums.len() {
                        let target = match nums[i] {
                            0 => {
                                (fg, bg) = (None, None);
                                i += 1;
                                continue;
                            }
                            38 => &mut fg,
                            48 => &mut bg,
                            n => panic!("SGR {n}"),
                        };
                        if nums[i + 1] == 2 {
                            let v = |k: usize| nums[i + k] as u8;
                            *target = Some(Colour::Rgb(v(2), v(3), v(4)));
                            i += 5;
                        } else {
                            *target = Some(Colour::Indexed(nums[i + 2] as u8));
                            i += 3;
                        }
                    }
                }
                f => panic!("unexpected sequence ending in {f}"),
            }
        }
    }

    fn grid(cells: Vec<Cell>, cols: usize) -> CellGrid {
        CellGrid {
            cols,
            rows: cells.len() / cols,
            cells,
        }
    }

    fn block(up: Colour, lo: Colour) -> Cell {
        half_block(up, lo)
    }

    /// `encode_diff(prev → next)` applied to a screen showing `prev` shows `next`; returns the
    /// bytes.
    fn round_trip(prev: &CellGrid, next: &CellGrid) -> Vec<u8> {
        let mut out = Vec::new();
        encode_diff(Some(prev), next, 0, &mut out);
        let mut screen = prev.clone();
        apply(&mut screen, &out);
        assert_eq!(
            looks(&screen),
            looks(next),
            "{:?}",
            String::from_utf8_lossy(&out)
        );
        out
    }

    #[test]
    fn a_change_of_only_the_background_foreground_or_character_is_sent() {
        let (a, b, c) = (
            Colour::Rgb(10, 20, 30),
            Colour::Rgb(200, 100, 0),
            Colour::Rgb(7, 7, 7),
        );
        let prev = grid(vec![block(a, b), block(b, a), block(a, c)], 3);
        let only_bg = grid(vec![block(a, b), block(b, c), block(a, c)], 3);
        let only_fg = grid(vec![block(a, b), block(c, a), block(a, c)], 3);
        let mut only_ch = prev.clone();
        only_ch.cells[1].ch = 'x';
        for next in [&only_bg, &only_fg, &only_ch] {
            let out = round_trip(&prev, next);
            assert!(!out.is_empty());
            // One cell changed: the first and last are not rewritten.
            let mut screen = prev.clone();
            screen.cells[0].ch = '?';
            screen.cells[2].ch = '?';
            apply(&mut screen, &out);
            assert_eq!((screen.cells[0].ch, screen.cells[2].ch), ('?', '?'));
        }
    }

    #[test]
    fn seeded_random_diffs_bring_any_screen_to_the_next_frame() {
        struct XorShift(u64);
        impl XorShift {
            fn below(&mut self, n: u64) -> u64 {
                self.0 ^= self.0 << 13;
                self.0 ^= self.0 >> 7;
                self.0 ^= self.0 << 17;
                self.0 % n
            }
        }
        // A few colours, so runs, equal pixels and carried-over pens all happen.
        let palette = [
            Colour::Rgb(0, 0, 0),
            Colour::Rgb(255, 255, 255),
            Colour::Rgb(1, 2, 3),
            Colour::Indexed(16),
        ];
        let cell = |rng: &mut XorShift| match rng.below(8) {
            0 => Cell {
                ch: (b'a' + rng.below(3) as u8) as char,
                fg: Some(palette[rng.below(4) as usize]),
                bg: Some(palette[rng.below(4) as usize]),
            },
            _ => block(
                palette[rng.below(4) as usize],
                palette[rng.below(4) as usize],
            ),
        };
        let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
        for case in 0..500 {
            let cols = 1 + rng.below(12) as usize;
            let rows = 1 + rng.below(4) as usize;
            let prev = grid((0..cols * rows).map(|_| cell(&mut rng)).collect(), cols);
            let mut next = prev.clone();
            for _ in 0..rng.below(2 * (cols * rows) as u64) {
                let i = rng.below((cols * rows) as u64) as usize;
                next.cells[i] = cell(&mut rng);
            }
            let out = round_trip(&prev, &next);
            assert_eq!(out.is_empty(), looks(&prev) == looks(&next), "case {case}");
            let mut any = grid(vec![block(palette[0], palette[0]); cols * rows], cols);
            let mut full = Vec::new();
            encode_diff(None, &next, 0, &mut full);
            apply(&mut any, &full);
            assert_eq!(looks(&any), looks(&next), "case {case}");
        }
    }

    #[test]
    fn diff_of_identical_frames_is_empty() {
        let img = image(&[[0.3, 0.2, 0.1], [0.9, 0.9, 0.9]], 1);
        let g = CellGrid::from_image(&img, ColorMode::TrueColor);
        let mut out = Vec::new();
        encode_diff(Some(&g), &g, 0, &mut out);
        assert!(out.is_empty());
        encode_diff(None, &g, 0, &mut out);
        assert!(out.starts_with(b"\x1b[1;1H"));
    }
}
