//! Frame encoding: an image becomes a grid of terminal cells (one cell = two pixels stacked, or
//! 2×2, 2×3 or 2×4 of them in the other [`CellMode`]s), and a grid becomes bytes, either as a
//! whole text frame or as the difference from the frame the terminal already shows; or an
//! image becomes one picture in a pixel protocol ([`encode_kitty`], [`encode_sixel`]). Pure
//! functions: no terminal, no I/O.

mod cells;
mod diff;
mod kitty;
mod sixel;

pub use diff::{
    DiffLimits, DiffOutcome, FULL_BLOCK, LOWER_HALF, UNLIKE, distance, encode_diff,
    encode_diff_within, pixels,
};

pub use kitty::{
    DELETE_ALL as KITTY_DELETE_ALL, NEAR_LEVELS, Placement, Precision, encode_kitty,
    encode_kitty_placed,
};
pub use sixel::{encode_sixel, palette as sixel_palette};

pub use cells::{CellMode, FULL_SHAPE, SHAPE_ROWS, cell_pixels, glyph_for_shape, paint, shape};

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

impl Cell {
    /// `ch` in `ink` over `bg`: a space with only a background when the two are equal (the
    /// glyph would not show).
    pub(crate) fn two(ch: char, ink: Colour, bg: Colour) -> Cell {
        if ink == bg {
            Cell {
                ch: ' ',
                fg: None,
                bg: Some(bg),
            }
        } else {
            Cell {
                ch,
                fg: Some(ink),
                bg: Some(bg),
            }
        }
    }
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
    /// Turns an image of `cols × 2·rows` pixels into `cols × rows` half-block cells (see
    /// [`CellGrid::from_image_in`] for the other cell modes). An odd last pixel row is paired
    /// with black.
    pub fn from_image(image: &Image, mode: ColorMode) -> CellGrid {
        CellGrid::from_image_in(image, mode, CellMode::Half)
    }

    /// The cell at (col, row).
    pub fn get(&self, col: usize, row: usize) -> Cell {
        self.cells[row * self.cols + col]
    }
}

/// A cell showing `up` over `lo`: a space with only a background when the two are equal.
#[cfg(test)]
fn half_block(up: Colour, lo: Colour) -> Cell {
    Cell::two(UPPER_HALF, up, lo)
}

/// The [`ASCII_RAMP`] character for a luminance of 0..=255.
fn ramp(y: f32) -> char {
    let i = (y / 255.0 * (ASCII_RAMP.len() - 1) as f32 + 0.5) as usize;
    ASCII_RAMP[i.min(ASCII_RAMP.len() - 1)] as char
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

/// The colour the xterm 256-colour palette gives index `i` (the 16 system colours as xterm's
/// defaults; the rest are fixed by the palette's formula).
pub fn palette_rgb(i: u8) -> [u8; 3] {
    const SYSTEM: [[u8; 3]; 16] = [
        [0, 0, 0],
        [205, 0, 0],
        [0, 205, 0],
        [205, 205, 0],
        [0, 0, 238],
        [205, 0, 205],
        [0, 205, 205],
        [229, 229, 229],
        [127, 127, 127],
        [255, 0, 0],
        [0, 255, 0],
        [255, 255, 0],
        [92, 92, 255],
        [255, 0, 255],
        [0, 255, 255],
        [255, 255, 255],
    ];
    match i {
        0..=15 => SYSTEM[usize::from(i)],
        16..=231 => {
            let k = i - 16;
            [k / 36, k / 6 % 6, k % 6].map(|l| CUBE[usize::from(l)])
        }
        _ => [8 + 10 * (i - 232); 3],
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

/// `38;2;r;g;b` and the like, written digit by digit: through `write!` the formatting machinery
/// took most of a frame's encoding (200×50 octant cells, encode_text: see `cells_bench`).
fn write_colour(out: &mut Vec<u8>, base: u8, c: Colour) {
    write_u8(out, base);
    match c {
        Colour::Rgb(r, g, b) => {
            out.extend_from_slice(b";2;");
            write_u8(out, r);
            out.push(b';');
            write_u8(out, g);
            out.push(b';');
            write_u8(out, b);
        }
        Colour::Indexed(i) => {
            out.extend_from_slice(b";5;");
            write_u8(out, i);
        }
    }
}

/// `v` in decimal, no leading zeros.
fn write_u8(out: &mut Vec<u8>, v: u8) {
    if v >= 100 {
        out.push(b'0' + v / 100);
    }
    if v >= 10 {
        out.push(b'0' + v / 10 % 10);
    }
    out.push(b'0' + v % 10);
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
    fn colours_are_written_as_format_would() {
        for v in 0..=255u8 {
            let mut out = Vec::new();
            write_colour(&mut out, 38, Colour::Rgb(v, 255 - v, v / 3));
            write_colour(&mut out, 48, Colour::Indexed(v));
            let want = format!("38;2;{v};{};{}48;5;{v}", 255 - v, v / 3);
            assert_eq!(String::from_utf8(out).unwrap(), want);
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
}
