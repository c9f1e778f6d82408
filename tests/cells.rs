//! The sub-cell text modes, decoded as a terminal would draw them: each glyph is drawn from its
//! Unicode name alone (`tests/cells_glyphs.txt`, not the encoder's tables), and the picture the
//! frame's bytes make is held to the render, cell by cell against every two-colour split. The
//! diff encoder's bytes go through a terminal emulator (vt100) and must show the same picture.

use std::collections::HashMap;

use raytty::frame::{CellMode, cell_pixels, encode_diff};
use raytty::{CellGrid, ColorMode, Image, Options, Stage, cornell_box, encode_text};

/// Rows of the grid every mode's pixels fall on (2, 3 and 4 divide it); two columns.
const ROWS: usize = 12;

/// Every glyph's ink, on the 2×12 grid (bit `2·row + col`), drawn from its name.
fn glyphs() -> HashMap<char, u32> {
    let text = include_str!("cells_glyphs.txt");
    let mut out = HashMap::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let (cp, name) = line.split_once('\t').expect("U+XXXX<tab>NAME");
        let ch = char::from_u32(u32::from_str_radix(&cp[2..], 16).unwrap()).unwrap();
        out.insert(ch, ink_of(name));
    }
    out
}

/// Ink covering grid columns `cols` and rows `rows`.
fn rect(cols: std::ops::Range<usize>, rows: std::ops::Range<usize>) -> u32 {
    let mut s = 0;
    for r in rows {
        for c in cols.clone() {
            s |= 1 << (2 * r + c);
        }
    }
    s
}

/// Ink of the `k`-th (1-based) of `w × h` mosaic pieces, numbered left to right, top to bottom.
fn piece(k: usize, h: usize) -> u32 {
    let (c, r) = ((k - 1) % 2, (k - 1) / 2);
    rect(c..c + 1, r * ROWS / h..(r + 1) * ROWS / h)
}

/// Where the glyph called `name` has ink.
fn ink_of(name: &str) -> u32 {
    let digits = |s: &str, h: usize| s.chars().map(|d| piece(d as usize - '0' as usize, h)).sum();
    if let Some(d) = name.strip_prefix("BLOCK OCTANT-") {
        return digits(d, 4);
    }
    if let Some(d) = name.strip_prefix("BLOCK SEXTANT-") {
        return digits(d, 3);
    }
    if let Some(parts) = name.strip_prefix("QUADRANT ") {
        return parts
            .split(" AND ")
            .map(|p| match p {
                "UPPER LEFT" => rect(0..1, 0..6),
                "UPPER RIGHT" => rect(1..2, 0..6),
                "LOWER LEFT" => rect(0..1, 6..12),
                "LOWER RIGHT" => rect(1..2, 6..12),
                _ => panic!("quadrant {p}"),
            })
            .sum();
    }
    match name {
        "SPACE" => 0,
        "FULL BLOCK" => rect(0..2, 0..12),
        "UPPER HALF BLOCK" => rect(0..2, 0..6),
        "LOWER HALF BLOCK" => rect(0..2, 6..12),
        "LEFT HALF BLOCK" => rect(0..1, 0..12),
        "RIGHT HALF BLOCK" => rect(1..2, 0..12),
        "UPPER ONE QUARTER BLOCK" => rect(0..2, 0..3),
        "LOWER ONE QUARTER BLOCK" => rect(0..2, 9..12),
        "UPPER THREE QUARTERS BLOCK" => rect(0..2, 0..9),
        "LOWER THREE QUARTERS BLOCK" => rect(0..2, 3..12),
        "MIDDLE LEFT ONE QUARTER BLOCK" => rect(0..1, 3..9),
        "MIDDLE RIGHT ONE QUARTER BLOCK" => rect(1..2, 3..9),
        "LEFT HALF UPPER ONE QUARTER BLOCK" => rect(0..1, 0..3),
        "RIGHT HALF UPPER ONE QUARTER BLOCK" => rect(1..2, 0..3),
        "LEFT HALF LOWER ONE QUARTER BLOCK" => rect(0..1, 9..12),
        "RIGHT HALF LOWER ONE QUARTER BLOCK" => rect(1..2, 9..12),
        _ => panic!("no drawing for {name}"),
    }
}

/// Ink of pattern `mask` of a `w × h` cell (bit `i`: pixel `i`, left to right, top to bottom).
fn mask_ink(w: usize, h: usize, mask: u32) -> u32 {
    (0..w * h)
        .filter(|i| mask >> i & 1 == 1)
        .map(|i| {
            let (c, r) = (i % w, i / w);
            let cols = if w == 1 { 0..2 } else { c..c + 1 };
            rect(cols, r * ROWS / h..(r + 1) * ROWS / h)
        })
        .sum()
}

#[test]
fn every_glyph_is_the_shape_its_name_draws() {
    let glyphs = glyphs();
    for mode in CellMode::ALL {
        let (w, h) = mode.pixels();
        let (w, h) = (w as usize, h as usize);
        let mut seen = std::collections::HashSet::new();
        for mask in 0..1u32 << (w * h) {
            let g = mode.glyph(mask as u8);
            let ink = glyphs.get(&g).copied();
            assert_eq!(
                ink,
                Some(mask_ink(w, h, mask)),
                "{} {mask:b}: {g:?} (U+{:04X})",
                mode.name(),
                g as u32
            );
            assert!(seen.insert(g), "{g:?} twice in {}", mode.name());
        }
    }
    // All of the octant block (U+1CD00-1CDE5) and all of the sextants (U+1FB00-1FB3B).
    let octants: Vec<char> = (0..=255).map(|m| CellMode::Octant.glyph(m)).collect();
    assert!((0x1CD00..=0x1CDE5).all(|c| octants.contains(&char::from_u32(c).unwrap())));
    let sextants: Vec<char> = (0..64).map(|m| CellMode::Sextant.glyph(m)).collect();
    assert!((0x1FB00..=0x1FB3B).all(|c| sextants.contains(&char::from_u32(c).unwrap())));
}

/// A cell as a terminal holds it: a character and the two colours as RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shown {
    ch: char,
    fg: Option<[u8; 3]>,
    bg: Option<[u8; 3]>,
}

/// The xterm palette's colour `i` (cube and grey ramp; the encoder never uses 0-15).
fn xterm(i: u8) -> [u8; 3] {
    let level = |l: u8| if l == 0 { 0 } else { 55 + 40 * l };
    match i {
        16..=231 => {
            let k = i - 16;
            [level(k / 36), level(k / 6 % 6), level(k % 6)]
        }
        232..=255 => [8 + 10 * (i - 232); 3],
        _ => panic!("system colour {i}"),
    }
}

/// The cells a stream of text with SGR colours (`encode_text`'s output) shows.
fn decode_text(bytes: &[u8]) -> Vec<Vec<Shown>> {
    let text = std::str::from_utf8(bytes).expect("UTF-8");
    let mut rows = Vec::new();
    for line in text.lines() {
        let (mut fg, mut bg) = (None, None);
        let mut row = Vec::new();
        let mut rest = line;
        while let Some(ch) = rest.chars().next() {
            if let Some(sgr) = rest.strip_prefix("\x1b[") {
                let end = sgr.find('m').expect("an SGR ends in m");
                let p: Vec<u32> = sgr[..end].split(';').map(|s| s.parse().unwrap()).collect();
                let mut i = 0;
                while i < p.len() {
                    let (colour, used) = match (p[i], p.get(i + 1)) {
                        (0, _) => (None, 1),
                        (38 | 48, Some(2)) => {
                            (Some([p[i + 2], p[i + 3], p[i + 4]].map(|v| v as u8)), 5)
                        }
                        (38 | 48, Some(5)) => (Some(xterm(p[i + 2] as u8)), 3),
                        _ => panic!("unexpected SGR {sgr}"),
                    };
                    match p[i] {
                        0 => (fg, bg) = (None, None),
                        38 => fg = colour,
                        _ => bg = colour,
                    }
                    i += used;
                }
                rest = &sgr[end + 1..];
                continue;
            }
            row.push(Shown { ch, fg, bg });
            rest = &rest[ch.len_utf8()..];
        }
        rows.push(row);
    }
    rows
}

/// The colour a terminal paints at grid place (`r`, `c`) of a shown cell.
fn colour_at(glyphs: &HashMap<char, u32>, cell: &Shown, r: usize, c: usize) -> [u8; 3] {
    let ink = *glyphs
        .get(&cell.ch)
        .unwrap_or_else(|| panic!("not a block glyph: {:?}", cell.ch));
    let on = ink >> (2 * r + c) & 1 == 1;
    let pick = if on { cell.fg } else { cell.bg };
    pick.unwrap_or_else(|| panic!("{cell:?} paints with a colour it has not set"))
}

/// The picture shown cells make, at `w × h` pixels a cell (sampled at each pixel's centre).
fn picture(glyphs: &HashMap<char, u32>, rows: &[Vec<Shown>], w: usize, h: usize) -> Vec<[u8; 3]> {
    let cols = rows[0].len();
    let mut out = vec![[0; 3]; cols * w * rows.len() * h];
    for (cr, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), cols, "rows of one length");
        for (cc, cell) in row.iter().enumerate() {
            for y in 0..h {
                for x in 0..w {
                    let gr = (2 * y + 1) * ROWS / (2 * h);
                    let gc = if w == 1 { 0 } else { x };
                    out[(cr * h + y) * cols * w + cc * w + x] = colour_at(glyphs, cell, gr, gc);
                }
            }
        }
    }
    out
}

fn frame(w: u32, h: u32, light_dx: f32) -> Image {
    let scene = cornell_box();
    let mut settings = Stage::Indirect.settings(scene.effects());
    settings.effects.samples = 2;
    let mut lights = scene.lights().to_vec();
    lights[0].position.x += light_dx;
    scene
        .render(&Options {
            width: w,
            height: h,
            settings: Some(settings),
            lights: Some(&lights),
            ..Options::default()
        })
        .image
}

fn sq(a: [u8; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (f64::from(a[i]) - b[i]).powi(2)).sum()
}

/// The least squared error of any two-colour split of `px` (colours: the groups' means).
fn best_error(px: &[[u8; 3]]) -> f64 {
    (0..1u32 << px.len())
        .map(|mask| {
            [true, false]
                .iter()
                .map(|&ink| {
                    let g: Vec<[u8; 3]> = (0..px.len())
                        .filter(|&i| (mask >> i & 1 == 1) == ink)
                        .map(|i| px[i])
                        .collect();
                    let n = g.len().max(1) as f64;
                    let mean =
                        [0, 1, 2].map(|c| g.iter().map(|p| f64::from(p[c])).sum::<f64>() / n);
                    g.iter().map(|&p| sq(p, mean)).sum::<f64>()
                })
                .sum()
        })
        .fold(f64::MAX, f64::min)
}

#[test]
fn text_frames_show_each_cell_s_best_two_colour_split() {
    let glyphs = glyphs();
    let (cols, rows) = (24u32, 9u32);
    for mode in CellMode::ALL {
        let (rw, rh) = mode.render_pixels();
        let image = frame(cols * rw, rows * rh, 0.0);
        // What the cells are fitted to: the render, or for quadrants and sextants the mean of
        // the area each of their pixels covers.
        let (rgb, _, _) = cell_pixels(&image, mode);
        let (w, h) = mode.pixels();
        for color in [ColorMode::TrueColor, ColorMode::Ansi256] {
            let bytes = encode_text(&CellGrid::from_image_in(&image, color, mode));
            let shown = decode_text(&bytes);
            assert_eq!(
                (shown.len(), shown[0].len()),
                (rows as usize, cols as usize)
            );
            let pic = picture(&glyphs, &shown, w as usize, h as usize);
            let (w, h) = (w as usize, h as usize);
            let mut total = 0.0;
            for cr in 0..rows as usize {
                for cc in 0..cols as usize {
                    let at = |i: usize| (cr * h + i / w) * cols as usize * w + cc * w + i % w;
                    let px: Vec<[u8; 3]> = (0..w * h).map(|i| rgb[at(i)]).collect();
                    let got: f64 = (0..w * h)
                        .map(|i| sq(pic[at(i)], px[i].map(f64::from)))
                        .sum();
                    total += got;
                    if color == ColorMode::TrueColor {
                        // Rounding the means to whole levels adds at most 1/4 a channel.
                        let slack = 0.75 * (w * h) as f64 + 2.0;
                        let best = best_error(&px);
                        assert!(
                            got <= best + slack,
                            "{} cell ({cc},{cr}): error {got} against the best {best}",
                            mode.name()
                        );
                    }
                }
            }
            let mse = total / (rgb.len() * 3) as f64;
            let psnr = 10.0 * (255.0f64 * 255.0 / mse).log10();
            let floor = if color == ColorMode::TrueColor {
                27.0
            } else {
                22.0
            };
            assert!(psnr > floor, "{} {color:?}: {psnr:.1} dB", mode.name());
        }
    }
}

/// The cells of a vt100 screen (rows × cols).
fn screen_cells(screen: &vt100::Screen, rows: u16, cols: u16) -> Vec<Vec<Shown>> {
    let rgb = |c: vt100::Color| match c {
        vt100::Color::Rgb(r, g, b) => Some([r, g, b]),
        vt100::Color::Idx(i) => Some(xterm(i)),
        vt100::Color::Default => None,
    };
    (0..rows)
        .map(|r| {
            (0..cols)
                .map(|c| {
                    let cell = screen.cell(r, c).expect("on screen");
                    Shown {
                        ch: cell.contents().chars().next().unwrap_or(' '),
                        fg: rgb(cell.fgcolor()),
                        bg: rgb(cell.bgcolor()),
                    }
                })
                .collect()
        })
        .collect()
}

#[test]
fn diffs_between_frames_and_modes_show_the_new_frame() {
    let glyphs = glyphs();
    let (cols, rows) = (20u16, 8u16);
    let grid = |mode: CellMode, dx: f32, color: ColorMode| {
        let (w, h) = mode.render_pixels();
        CellGrid::from_image_in(&frame(cols as u32 * w, rows as u32 * h, dx), color, mode)
    };
    for color in [ColorMode::TrueColor, ColorMode::Ansi256] {
        let steps = [
            (CellMode::Octant, 0.0),
            (CellMode::Octant, 0.3),
            (CellMode::Sextant, 0.3),
            (CellMode::Quadrant, -0.2),
            (CellMode::Half, -0.2),
            (CellMode::Octant, 0.1),
        ];
        let nz = |n: u16| std::num::NonZeroU16::new(n).expect("not zero");
        let mut vt = vt100::Parser::new(nz(rows), nz(cols), 0);
        let mut prev: Option<CellGrid> = None;
        for (mode, dx) in steps {
            let next = grid(mode, dx, color);
            let mut out = Vec::new();
            encode_diff(prev.as_ref(), &next, 0, &mut out);
            vt.process(&out);
            let shown = screen_cells(vt.screen(), rows, cols);
            let want = decode_text(&encode_text(&next));
            assert_eq!(
                picture(&glyphs, &shown, 2, ROWS),
                picture(&glyphs, &want, 2, ROWS),
                "{color:?} {} after the diff",
                mode.name()
            );
            prev = Some(next);
        }
    }
}

#[test]
fn text_frames_of_each_mode() {
    for mode in CellMode::ALL {
        let (w, h) = mode.render_pixels();
        let image = frame(32 * w, 10 * h, 0.0);
        let text = encode_text(&CellGrid::from_image_in(&image, ColorMode::TrueColor, mode));
        let text = String::from_utf8(text).unwrap().replace('\x1b', "␛");
        insta::assert_snapshot!(format!("cells_{}", mode.name()), text);
    }
}
