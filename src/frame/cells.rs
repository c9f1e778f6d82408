//! Sub-cell text modes: a cell shows a small grid of pixels (1×2, 2×2, 2×3 or 2×4) as one block
//! glyph in two colours, the foreground on the glyph's ink and the background elsewhere. Each
//! cell gets the split of its pixels into two groups, and the two colours (the groups' means),
//! with the least squared error, found by trying every split.
//!
//! The glyphs are Unicode's: `▀` for half-blocks; the quadrants of Block Elements (U+2596-259F)
//! with the half blocks; the sextants of Symbols for Legacy Computing (U+1FB00-1FB3B), which
//! leave out the four patterns that are a space, `▌`, `▐` or `█`; the octants of Symbols for
//! Legacy Computing Supplement (U+1CD00-1CDE5, Unicode 16), which leave out 26 patterns that
//! other characters already draw (the half and quadrant blocks, the one- and three-quarter
//! blocks, and four Unicode 16 quarter blocks). Source of the code points: the Unicode
//! Character Database's names (`BLOCK OCTANT-1234`, `BLOCK SEXTANT-135`, ...) as the Python
//! package `unicodedata2` 18.0.0 ships them; `tests/cells_glyphs.txt` lists every glyph with its
//! name, and `tests/cells.rs` holds this table to it.

use super::{Cell, CellGrid, ColorMode, Colour, luminance, nearest_256, palette_rgb, ramp};
use crate::image::Image;
use crate::simd::{Isa, Kernel, Path};

/// How many pixels a cell shows, and with which glyphs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CellMode {
    /// 1×2 pixels: `▀` (every terminal font has it). The default.
    #[default]
    Half,
    /// 2×2 pixels: the quadrant blocks (U+2596-259F).
    Quadrant,
    /// 2×3 pixels: the sextants (U+1FB00-1FB3B, Unicode 13).
    Sextant,
    /// 2×4 pixels: the octants (U+1CD00-1CDE5, Unicode 16).
    Octant,
}

impl CellMode {
    /// Every mode, coarsest first.
    pub const ALL: [CellMode; 4] = [
        CellMode::Half,
        CellMode::Quadrant,
        CellMode::Sextant,
        CellMode::Octant,
    ];

    /// The mode's name as the CLI and status line show it.
    pub fn name(self) -> &'static str {
        match self {
            CellMode::Half => "half",
            CellMode::Quadrant => "quadrant",
            CellMode::Sextant => "sextant",
            CellMode::Octant => "octant",
        }
    }

    /// The mode called `name`, if one is.
    pub fn from_name(name: &str) -> Option<CellMode> {
        CellMode::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The next mode in the cycle half → quadrant → sextant → octant → half.
    pub fn next(self) -> CellMode {
        let i = CellMode::ALL.iter().position(|&m| m == self).unwrap_or(0);
        CellMode::ALL[(i + 1) % CellMode::ALL.len()]
    }

    /// Pixels a cell shows: (columns, rows).
    pub fn pixels(self) -> (u32, u32) {
        match self {
            CellMode::Half => (1, 2),
            CellMode::Quadrant => (2, 2),
            CellMode::Sextant => (2, 3),
            CellMode::Octant => (2, 4),
        }
    }

    /// Pixels a cell is rendered at: square ones, for a cell twice as high as it is wide (the
    /// common shape of a terminal's cell). Half-blocks and octants show them as they are;
    /// quadrants and sextants, whose pixels are not square, show the mean of the area each
    /// covers of a render at octant resolution (see [`cell_pixels`]).
    pub fn render_pixels(self) -> (u32, u32) {
        match self {
            CellMode::Half => (1, 2),
            _ => (2, 4),
        }
    }

    /// The glyph whose ink covers the cell's pixels in `mask` (bit `i`: the `i`-th pixel in
    /// reading order, left to right then top to bottom).
    pub fn glyph(self, mask: u8) -> char {
        match self {
            CellMode::Half => OCTANT_GLYPHS[usize::from(octant_mask(1, 2, mask))],
            CellMode::Quadrant => OCTANT_GLYPHS[usize::from(octant_mask(2, 2, mask))],
            CellMode::Sextant => sextant_glyph(mask),
            CellMode::Octant => OCTANT_GLYPHS[usize::from(mask)],
        }
    }
}

/// The octants that Unicode draws with other characters (not in U+1CD00-1CDE5), by mask (bit
/// `i`: octant `i + 1`, numbered left to right then top to bottom, as in their names).
const OCTANT_ELSEWHERE: [(u8, char); 26] = [
    (0, ' '),
    (0b0000_0001, '\u{1CEA8}'), // LEFT HALF UPPER ONE QUARTER BLOCK
    (0b0000_0010, '\u{1CEAB}'), // RIGHT HALF UPPER ONE QUARTER BLOCK
    (0b0000_0011, '\u{1FB82}'), // UPPER ONE QUARTER BLOCK
    (0b0000_0101, '\u{2598}'),  // QUADRANT UPPER LEFT
    (0b0000_1010, '\u{259D}'),  // QUADRANT UPPER RIGHT
    (0b0000_1111, '\u{2580}'),  // UPPER HALF BLOCK
    (0b0001_0100, '\u{1FBE6}'), // MIDDLE LEFT ONE QUARTER BLOCK
    (0b0010_1000, '\u{1FBE7}'), // MIDDLE RIGHT ONE QUARTER BLOCK
    (0b0011_1111, '\u{1FB85}'), // UPPER THREE QUARTERS BLOCK
    (0b0100_0000, '\u{1CEA3}'), // LEFT HALF LOWER ONE QUARTER BLOCK
    (0b0101_0000, '\u{2596}'),  // QUADRANT LOWER LEFT
    (0b0101_0101, '\u{258C}'),  // LEFT HALF BLOCK
    (0b0101_1010, '\u{259E}'),  // QUADRANT UPPER RIGHT AND LOWER LEFT
    (0b0101_1111, '\u{259B}'),  // QUADRANT UPPER LEFT AND UPPER RIGHT AND LOWER LEFT
    (0b1000_0000, '\u{1CEA0}'), // RIGHT HALF LOWER ONE QUARTER BLOCK
    (0b1010_0000, '\u{2597}'),  // QUADRANT LOWER RIGHT
    (0b1010_0101, '\u{259A}'),  // QUADRANT UPPER LEFT AND LOWER RIGHT
    (0b1010_1010, '\u{2590}'),  // RIGHT HALF BLOCK
    (0b1010_1111, '\u{259C}'),  // QUADRANT UPPER LEFT AND UPPER RIGHT AND LOWER RIGHT
    (0b1100_0000, '\u{2582}'),  // LOWER ONE QUARTER BLOCK
    (0b1111_0000, '\u{2584}'),  // LOWER HALF BLOCK
    (0b1111_0101, '\u{2599}'),  // QUADRANT UPPER LEFT AND LOWER LEFT AND LOWER RIGHT
    (0b1111_1010, '\u{259F}'),  // QUADRANT UPPER RIGHT AND LOWER LEFT AND LOWER RIGHT
    (0b1111_1100, '\u{2586}'),  // LOWER THREE QUARTERS BLOCK
    (0b1111_1111, '\u{2588}'),  // FULL BLOCK
];

/// The first octant of the Unicode 16 block; the others follow in order of their masks,
/// skipping [`OCTANT_ELSEWHERE`].
const OCTANT_BLOCK: u32 = 0x1CD00;
/// The last octant of the block.
const OCTANT_BLOCK_END: u32 = 0x1CDE5;
/// The first sextant (`BLOCK SEXTANT-1`); the others follow in order of their masks, skipping
/// left half (135) and right half (246).
const SEXTANT_BLOCK: u32 = 0x1FB00;
/// The last sextant (`BLOCK SEXTANT-23456`).
const SEXTANT_BLOCK_END: u32 = 0x1FB3B;

/// Every octant pattern's glyph, by mask.
const OCTANT_GLYPHS: [char; 256] = octant_glyphs();
/// The masks of U+1CD00.., in order.
const OCTANT_BLOCK_MASKS: [u8; 230] = octant_block_masks();

const fn elsewhere(mask: u8) -> Option<char> {
    let mut i = 0;
    while i < OCTANT_ELSEWHERE.len() {
        if OCTANT_ELSEWHERE[i].0 == mask {
            return Some(OCTANT_ELSEWHERE[i].1);
        }
        i += 1;
    }
    None
}

const fn octant_glyphs() -> [char; 256] {
    let mut out = [' '; 256];
    let mut next = OCTANT_BLOCK;
    let mut m = 0;
    while m < 256 {
        out[m] = match elsewhere(m as u8) {
            Some(c) => c,
            None => {
                next += 1;
                match char::from_u32(next - 1) {
                    Some(c) => c,
                    None => panic!("octant block out of range"),
                }
            }
        };
        m += 1;
    }
    assert!(next == OCTANT_BLOCK_END + 1);
    out
}

const fn octant_block_masks() -> [u8; 230] {
    let mut out = [0; 230];
    let (mut m, mut k) = (0, 0);
    while m < 256 {
        if elsewhere(m as u8).is_none() {
            out[k] = m as u8;
            k += 1;
        }
        m += 1;
    }
    out
}

fn sextant_glyph(mask: u8) -> char {
    match mask & 63 {
        0 => ' ',
        0b01_0101 => '\u{258C}',
        0b10_1010 => '\u{2590}',
        63 => '\u{2588}',
        m => {
            let skipped = u32::from(m > 0b01_0101) + u32::from(m > 0b10_1010);
            char::from_u32(SEXTANT_BLOCK + u32::from(m) - 1 - skipped).unwrap_or(' ')
        }
    }
}

/// The octant mask of the `w × h` pattern `mask` (`w` divides 2, `h` divides 4).
const fn octant_mask(w: u32, h: u32, mask: u8) -> u8 {
    let mut out = 0u8;
    let mut i = 0;
    while i < 8 {
        let (col, row) = (i % 2, i / 2);
        let sub = (row * h / 4) * w + col * w / 2;
        if mask >> sub & 1 == 1 {
            out |= 1 << i;
        }
        i += 1;
    }
    out
}

/// Rows of the finest grid every mode's pixels fall on (lcm of 2, 3 and 4); it has two columns.
pub const SHAPE_ROWS: u32 = 12;
/// The shape of a full block.
pub const FULL_SHAPE: u32 = (1 << (2 * SHAPE_ROWS)) - 1;

/// Where a `w × h` pattern puts ink, on the 2×[`SHAPE_ROWS`] grid (bit `2·row + col`).
const fn shape_of(w: u32, h: u32, mask: u8) -> u32 {
    let mut out = 0;
    let mut r = 0;
    while r < SHAPE_ROWS {
        let mut c = 0;
        while c < 2 {
            let sub = (r * h / SHAPE_ROWS) * w + c * w / 2;
            if mask >> sub & 1 == 1 {
                out |= 1 << (2 * r + c);
            }
            c += 1;
        }
        r += 1;
    }
    out
}

/// Where `ch` puts ink on the 2×[`SHAPE_ROWS`] grid, if it is a space or one of the block
/// glyphs the modes use (and so the same picture, whichever mode drew it).
pub fn shape(ch: char) -> Option<u32> {
    let c = ch as u32;
    match c {
        0x20 => Some(0),
        0x2580 => Some(shape_of(1, 2, 1)),
        OCTANT_BLOCK..=OCTANT_BLOCK_END => Some(shape_of(
            2,
            4,
            OCTANT_BLOCK_MASKS[(c - OCTANT_BLOCK) as usize],
        )),
        SEXTANT_BLOCK..=SEXTANT_BLOCK_END => {
            let mut m = c - SEXTANT_BLOCK + 1;
            m += u32::from(m >= 0b01_0101);
            m += u32::from(m >= 0b10_1010);
            Some(shape_of(2, 3, m as u8))
        }
        _ => OCTANT_ELSEWHERE
            .iter()
            .find(|&&(_, g)| g == ch)
            .map(|&(m, _)| shape_of(2, 4, m)),
    }
}

/// A glyph whose ink is `shape` (octants first, then sextants), if one is.
pub fn glyph_for_shape(shape: u32) -> Option<char> {
    [(2, 4, CellMode::Octant), (2, 3, CellMode::Sextant)]
        .into_iter()
        .find_map(|(w, h, mode)| {
            let mut mask = 0u8;
            for i in 0..w * h {
                let bit = shape_of(w, h, 1 << i);
                match shape & bit {
                    0 => {}
                    b if b == bit => mask |= 1 << i,
                    _ => return None,
                }
            }
            Some(mode.glyph(mask))
        })
}

/// Masks scored side by side: the low three bits of a mask pick a lane, the rest a group.
const LANES: usize = 8;

/// `1/k` for `k` pixels of `n` (0 for none) in the ink (`ink`) or the background of each mask
/// (lane `l` of group `g`: mask `8·g + l`): the weight of a group's squared sum.
const fn inverses<const G: usize>(n: u32, ink: bool) -> [[f32; LANES]; G] {
    let mut out = [[0.0; LANES]; G];
    let mut m = 0;
    while m < G * LANES {
        let k = if ink {
            (m as u32).count_ones()
        } else {
            n - (m as u32).count_ones()
        };
        if k > 0 {
            out[m / LANES][m % LANES] = 1.0 / k as f32;
        }
        m += 1;
    }
    out
}

/// Score weights for 4, 6 and 8 pixels.
const INV_4: ([[f32; LANES]; 1], [[f32; LANES]; 1]) = (inverses(4, true), inverses(4, false));
const INV_6: ([[f32; LANES]; 4], [[f32; LANES]; 4]) = (inverses(6, true), inverses(6, false));
const INV_8: ([[f32; LANES]; 16], [[f32; LANES]; 16]) = (inverses(8, true), inverses(8, false));

/// The split of `N` pixels (4, 6 or 8) into ink and background with the least squared error,
/// and the two colours (the groups' means, rounded): `(mask, ink, background)`, mask 0 for one
/// colour. The last pixel is always background (a split and its complement are one picture),
/// which leaves 2^(N−1) splits, and every one is scored: with `s` a group's sum of colours and
/// `k` its pixel count, the error is Σ|p|² − Σ|s|²/k over the two groups, so the best split
/// has the largest Σ|s|²/k. Ties go to the smallest mask. The sums are whole numbers below
/// 2^24, exact in `f32`, and each score is the same operations in the same order on every
/// machine (no FMA). Masks are scored eight at a time (a lane each, [`LANES`]), each lane
/// keeping its best, so that the compiler vectorises the loop: a 100×50 octant frame's cells
/// and text took 10.5 ms with one running best, 1.8 ms so (`examples/cells_bench`).
#[inline(always)]
fn best_split<const N: usize, const G: usize>(
    px: &[[u8; 3]; N],
    inv_ink: &[[f32; LANES]; G],
    inv_bg: &[[f32; LANES]; G],
) -> (u8, [u8; 3], [u8; 3]) {
    debug_assert_eq!(G * LANES, 1 << (N - 1));
    let p: [[f32; 3]; N] = px.map(|c| c.map(f32::from));
    // Sums of each subset of pixels 0-2 (a lane's) and of pixels 3..N−1 (a group's).
    // Each subset's sum is a smaller subset's plus one pixel (the subset without its lowest
    // bit): one add each, where testing every pixel's bit compiled to masked vector loads and
    // stores (200×50 octant cells 2.9 -> 1.8 ms of CPU, sextants 1.4 -> 1.2: medians of five
    // interleaved runs of `cells_bench`). Whole numbers, so exact in any order: the same cells.
    // Pixels 0-2 vary across lanes, 3..N−1 across groups (the last is always background).
    let mut low = [[0.0f32; LANES]; 3];
    let mut high = [[0.0f32; G]; 3];
    for ch in 0..3 {
        for l in 1..LANES {
            low[ch][l] = low[ch][l & (l - 1)] + p[l.trailing_zeros() as usize][ch];
        }
        for g in 1..G {
            high[ch][g] = high[ch][g & (g - 1)] + p[3 + g.trailing_zeros() as usize][ch];
        }
    }
    let total = [0, 1, 2].map(|ch| p.iter().map(|q| q[ch]).sum::<f32>());
    let mut best_q = [f32::MIN; LANES];
    let mut best_g = [0u32; LANES];
    for g in 0..G {
        for l in 0..LANES {
            let (r, gr, b) = (
                high[0][g] + low[0][l],
                high[1][g] + low[1][l],
                high[2][g] + low[2][l],
            );
            let (r0, g0, b0) = (total[0] - r, total[1] - gr, total[2] - b);
            let q = (r * r + gr * gr + b * b) * inv_ink[g][l]
                + (r0 * r0 + g0 * g0 + b0 * b0) * inv_bg[g][l];
            let better = q > best_q[l];
            best_q[l] = if better { q } else { best_q[l] };
            best_g[l] = if better { g as u32 } else { best_g[l] };
        }
    }
    let mut best = (f32::MIN, 0u32);
    for l in 0..LANES {
        let m = best_g[l] * LANES as u32 + l as u32;
        if best_q[l] > best.0 || (best_q[l] == best.0 && m < best.1) {
            best = (best_q[l], m);
        }
    }
    split_colours(px, best.1 as u8)
}

/// `(mask, ink, background)` for the split `mask` of `px`: the two groups' means, rounded
/// (both the mean of all for mask 0).
fn split_colours<const N: usize>(px: &[[u8; 3]; N], mask: u8) -> (u8, [u8; 3], [u8; 3]) {
    let mean = |ink: bool| {
        let mut s = [0u32; 3];
        let mut k = 0;
        for (i, p) in px.iter().enumerate() {
            if (mask >> i & 1 == 1) == ink || mask == 0 {
                k += 1;
                for ch in 0..3 {
                    s[ch] += u32::from(p[ch]);
                }
            }
        }
        s.map(|v| ((2 * v + k) / (2 * k.max(1))) as u8)
    };
    (mask, mean(true), mean(false))
}

/// The cell for one fitted split: a space with the background if the two colours are one, else
/// the mask's glyph with the ink as foreground.
fn cell_for(mode: CellMode, color: ColorMode, (mask, ink, bg): (u8, [u8; 3], [u8; 3])) -> Cell {
    let colour = |c: [u8; 3]| match color {
        ColorMode::Ansi256 => Colour::Indexed(nearest_256(c)),
        _ => Colour::Rgb(c[0], c[1], c[2]),
    };
    let (ink, bg) = (colour(ink), colour(bg));
    if mask == 0 {
        Cell::two(' ', bg, bg)
    } else {
        Cell::two(mode.glyph(mask), ink, bg)
    }
}

/// Fits every cell of `rgb` (`width × height` pixels, row-major) in `mode`: a grid of
/// `width / w × ⌈height / h⌉` cells for `mode`'s `w × h` pixels, the last row's missing pixels
/// taken as black. Truecolor or 256 colours (each of the two colours its nearest); in ASCII,
/// the ramp's character for the mean luminance of the cell's pixels. With AVX2, the same code
/// compiled for it (eight lanes to a register instead of four: the same operations in each
/// lane, so the same cells, bit for bit): 200×50 octant cells 2.4 -> 1.6-1.7 ms of CPU
/// (`examples/cells_bench`, a loaded machine).
fn fit_grid(
    rgb: &[[u8; 3]],
    width: usize,
    height: usize,
    mode: CellMode,
    color: ColorMode,
) -> CellGrid {
    Isa::detect().run(Fit(rgb, width, height, mode, color))
}

/// [`fit_cells`] as a kernel of the one SIMD dispatch (AVX-512 CPUs run its AVX2 code).
struct Fit<'a>(&'a [[u8; 3]], usize, usize, CellMode, ColorMode);

impl Kernel for Fit<'_> {
    type Output = CellGrid;
    #[inline(always)]
    fn run<P: Path>(self) -> CellGrid {
        let Fit(rgb, width, height, mode, color) = self;
        fit_cells(rgb, width, height, mode, color)
    }
}

/// [`fit_grid`]'s body, inlined into each of its compilations.
#[inline(always)]
fn fit_cells(
    rgb: &[[u8; 3]],
    width: usize,
    height: usize,
    mode: CellMode,
    color: ColorMode,
) -> CellGrid {
    let (w, h) = mode.pixels();
    let (w, h) = (w as usize, h as usize);
    let cols = width / w;
    let rows = height.div_ceil(h);
    let px = |x: usize, y: usize| {
        if y < height {
            rgb[y * width + x]
        } else {
            [0; 3]
        }
    };
    let mut cells = Vec::with_capacity(cols * rows);
    for r in 0..rows {
        for c in 0..cols {
            let gather = |i: usize| px(c * w + i % w, r * h + i / w);
            if color == ColorMode::Ascii {
                let y = (0..w * h).map(|i| luminance(gather(i))).sum::<f32>() / (w * h) as f32;
                cells.push(Cell {
                    ch: ramp(y),
                    fg: None,
                    bg: None,
                });
                continue;
            }
            let split = match mode {
                // Two pixels: two colours unless they are one.
                CellMode::Half => {
                    let px = [0, 1].map(gather);
                    split_colours(&px, u8::from(px[0] != px[1]))
                }
                CellMode::Quadrant => {
                    best_split::<4, 1>(&std::array::from_fn(gather), &INV_4.0, &INV_4.1)
                }
                CellMode::Sextant => {
                    best_split::<6, 4>(&std::array::from_fn(gather), &INV_6.0, &INV_6.1)
                }
                CellMode::Octant => {
                    best_split::<8, 16>(&std::array::from_fn(gather), &INV_8.0, &INV_8.1)
                }
            };
            cells.push(cell_for(mode, color, split));
        }
    }
    CellGrid { cols, rows, cells }
}

/// What a terminal shows for `grid` with cells of `cell_w × cell_h` pixels: each block cell's
/// ink in its foreground and the rest in its background; other cells (text) in their background,
/// or black. Row-major, `cols·cell_w × rows·cell_h` pixels.
pub fn paint(grid: &CellGrid, cell_w: usize, cell_h: usize) -> Vec<[u8; 3]> {
    let width = grid.cols * cell_w;
    let mut out = vec![[0u8; 3]; width * grid.rows * cell_h];
    let rgb = |c: Option<Colour>| match c {
        Some(Colour::Rgb(r, g, b)) => [r, g, b],
        Some(Colour::Indexed(i)) => palette_rgb(i),
        None => [0; 3],
    };
    for (i, cell) in grid.cells.iter().enumerate() {
        let (col, row) = (i % grid.cols, i / grid.cols);
        let ink_shape = shape(cell.ch).unwrap_or(0);
        let (ink, bg) = (rgb(cell.fg), rgb(cell.bg));
        for y in 0..cell_h {
            let line = (row * cell_h + y) * width + col * cell_w;
            let sr = (y * SHAPE_ROWS as usize / cell_h) as u32;
            for x in 0..cell_w {
                let sc = (x * 2 / cell_w) as u32;
                let on = ink_shape >> (2 * sr + sc) & 1 == 1;
                out[line + x] = if on { ink } else { bg };
            }
        }
    }
    out
}

/// The pixels `mode`'s cells show, from `image` rendered at [`CellMode::render_pixels`] a
/// cell: 8-bit, `width × height` (returned with them), row-major. Each is the mean of the part
/// of the image it covers: for quadrants, two rows of the render; for sextants, a row and a
/// third of one (a third of a sextant's height falls in each of two rows of the render for
/// the first and last, a half in each for the middle one). A missing last row is black.
pub fn cell_pixels(image: &Image, mode: CellMode) -> (Vec<[u8; 3]>, usize, usize) {
    let (w, h) = (image.width as usize, image.height as usize);
    let (_, out_rows) = mode.pixels();
    let (_, in_rows) = mode.render_pixels();
    if out_rows == in_rows {
        return (image.to_rgb8(), w, h);
    }
    let (out_rows, in_rows) = (out_rows as usize, in_rows as usize);
    let cell_rows = h.div_ceil(in_rows);
    let height = cell_rows * out_rows;
    let mut out = Vec::with_capacity(w * height);
    for y in 0..height {
        let (cell, j) = (y / out_rows, y % out_rows);
        // Row j covers [j·in, (j+1)·in) and source row k covers [k·out, (k+1)·out), in units
        // of 1/(in·out) of a cell: the overlaps, over `in_rows`, are the weights.
        let rows: Vec<(usize, f32)> = (0..in_rows)
            .filter_map(|k| {
                let lo = (j * in_rows).max(k * out_rows);
                let hi = ((j + 1) * in_rows).min((k + 1) * out_rows);
                let src = cell * in_rows + k;
                (hi > lo && src < h).then(|| (src, (hi - lo) as f32 / in_rows as f32))
            })
            .collect();
        for x in 0..w {
            let p = rows.iter().fold(glam::Vec3::ZERO, |acc, &(src, wt)| {
                acc + image.get(x as u32, src as u32) * wt
            });
            out.push(crate::image::to_rgb8(p));
        }
    }
    (out, w, height)
}

impl CellGrid {
    /// Turns an image of `cols·w × rows·h` pixels, for `mode`'s [`CellMode::render_pixels`]
    /// `w × h`, into `cols × rows` cells, each the glyph and two colours nearest its pixels
    /// ([`cell_pixels`]; see the module's note). A missing last row of pixels is black. In
    /// ASCII, a cell is one character of the luminance ramp for its pixels' mean.
    pub fn from_image_in(image: &Image, color: ColorMode, mode: CellMode) -> CellGrid {
        let (rgb, width, height) = cell_pixels(image, mode);
        fit_grid(&rgb, width, height, mode, color)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_avx2_compilation_fits_the_same_cells() {
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx2.available() {
            let mut state = 0x2545_f491_4f6c_dd1du64;
            for mode in CellMode::ALL {
                let (w, h) = mode.pixels();
                let (width, height) = (37 * w as usize, 11 * h as usize + 1);
                // Smooth ramps with noise, and flat patches: near ties and exact ties.
                let rgb: Vec<[u8; 3]> = (0..width * height)
                    .map(|i| {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        let base = (i % width * 255 / width) as u8;
                        if i % 97 < 30 {
                            [base; 3]
                        } else {
                            [base, (state % 256) as u8, (state >> 8) as u8 & 0xf0]
                        }
                    })
                    .collect();
                for color in [ColorMode::TrueColor, ColorMode::Ansi256] {
                    let portable = fit_cells(&rgb, width, height, mode, color);
                    let avx2 = Isa::Avx2.run(Fit(&rgb, width, height, mode, color));
                    assert_eq!(portable, avx2, "{mode:?} {color:?}");
                }
            }
        }
    }

    #[test]
    fn quadrant_and_sextant_pixels_are_the_means_of_the_area_they_cover() {
        // Four rows a cell, of levels 0, 1, 0.5 and 0.25 (255, 128, 64 in 8 bits); a second
        // cell row cut short after one row.
        let levels = [0.0, 1.0, 0.5, 0.25, 1.0];
        let image = Image {
            width: 2,
            height: 5,
            pixels: levels
                .iter()
                .flat_map(|&v| [glam::Vec3::splat(v); 2])
                .collect(),
        };
        let column = |mode| {
            let (px, w, h) = cell_pixels(&image, mode);
            assert_eq!((w, px.len() / w), (2, h));
            px.iter().step_by(2).map(|p| p[0]).collect::<Vec<u8>>()
        };
        let v = |x: f32| (x * 255.0 + 0.5) as u8;
        assert_eq!(column(CellMode::Octant), [0, 255, 128, 64, 255]);
        assert_eq!(column(CellMode::Quadrant), [v(0.5), v(0.375), v(0.5), 0]);
        assert_eq!(
            column(CellMode::Sextant),
            [v(0.25), v(0.75), v(0.3125), v(0.75), 0, 0]
        );
    }

    #[test]
    fn glyph_tables_are_one_to_one() {
        let mut seen = std::collections::HashSet::new();
        for m in 0..=255u8 {
            let g = CellMode::Octant.glyph(m);
            assert!(seen.insert(g), "{g:?} twice");
            assert_eq!(shape(g), Some(shape_of(2, 4, m)), "mask {m:08b}");
            assert_eq!(glyph_for_shape(shape_of(2, 4, m)), Some(g));
        }
        for m in 0..64u8 {
            let g = CellMode::Sextant.glyph(m);
            assert_eq!(shape(g), Some(shape_of(2, 3, m)), "mask {m:06b}");
            assert_eq!(glyph_for_shape(shape_of(2, 3, m)), Some(g));
        }
        for (mode, n) in [(CellMode::Quadrant, 16u8), (CellMode::Half, 4)] {
            let (w, h) = mode.pixels();
            for m in 0..n {
                assert_eq!(shape(mode.glyph(m)), Some(shape_of(w, h, m)));
            }
        }
        assert_eq!(CellMode::Half.glyph(1), '▀');
        assert_eq!(CellMode::Quadrant.glyph(0b1001), '▚');
        assert_eq!(CellMode::Sextant.glyph(1), '\u{1FB00}');
        assert_eq!(CellMode::Sextant.glyph(0b11_1110), '\u{1FB3B}');
        assert_eq!(CellMode::Octant.glyph(0b100), '\u{1CD00}');
        assert_eq!(CellMode::Octant.glyph(0b1111_1110), '\u{1CDE5}');
    }

    /// The error of a split, summed over the pixels, in whole numbers.
    fn error(px: &[[u8; 3]], mask: u8) -> f64 {
        let mut e = 0.0;
        for ink in [true, false] {
            let group: Vec<[u8; 3]> = (0..px.len())
                .filter(|&i| (mask >> i & 1 == 1) == ink)
                .map(|i| px[i])
                .collect();
            let k = group.len() as f64;
            for ch in 0..3 {
                let mean = group.iter().map(|p| f64::from(p[ch])).sum::<f64>() / k.max(1.0);
                e += group
                    .iter()
                    .map(|p| (f64::from(p[ch]) - mean).powi(2))
                    .sum::<f64>();
            }
        }
        e
    }

    #[test]
    fn the_split_found_is_the_best_of_all() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..2000 {
            // Few distinct levels, so that exact ties and near ties happen.
            let levels = [2u64, 4, 256][case % 3];
            let px: [[u8; 3]; 8] = std::array::from_fn(|_| {
                [0; 3].map(|_: u8| (next() % levels * 255 / (levels - 1).max(1)) as u8)
            });
            let (mask, _, _) = best_split::<8, 16>(&px, &INV_8.0, &INV_8.1);
            let best = (0..128u8).map(|m| error(&px, m)).fold(f64::MAX, f64::min);
            // Within the scores' rounding (about one unit in 2^24 of a sum of squares).
            assert!(error(&px, mask) <= best + 2.0, "{px:?}: {mask:08b}");
            assert!(mask < 128);
        }
    }
}
