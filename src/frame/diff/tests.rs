//! The diff encoder against a small terminal model that applies what it writes.

use super::*;
use crate::frame::{UPPER_HALF, half_block};

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
        LOWER_HALF => Look::Pixels(cell.bg, cell.fg),
        FULL_BLOCK => Look::Pixels(cell.fg, cell.fg),
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
        match ch {
            '\r' => c = 0,
            '\n' => r += 1,
            '\x1b' => {}
            _ => {
                screen.cells[r * screen.cols + c] = Cell { ch, fg, bg };
                c += 1;
            }
        }
        if ch != '\x1b' {
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
        // A relative move's count defaults to 1.
        let n = nums[0].max(1);
        match fin {
            'H' => (r, c) = (nums[0] - 1, nums[1] - 1),
            'C' => c += n,
            'D' => c -= n,
            'B' => r += n,
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
    let g = grid(
        vec![block(Colour::Rgb(76, 51, 25), Colour::Rgb(229, 229, 229))],
        1,
    );
    let mut out = Vec::new();
    encode_diff(Some(&g), &g, 0, &mut out);
    assert!(out.is_empty());
    encode_diff(None, &g, 0, &mut out);
    assert!(out.starts_with(b"\x1b[1;1H"));
}

/// A seeded xorshift generator for the random grids.
struct Seeded(u64);

impl Seeded {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n
    }

    /// One of 216 colours near each other (6 levels apart), so tolerances matter.
    fn colour(&mut self) -> Colour {
        let mut v = || 100 + 6 * self.below(6) as u8;
        Colour::Rgb(v(), v(), v())
    }

    /// A block cell (a third of them of one colour), or now and then text.
    fn cell(&mut self) -> Cell {
        if self.below(16) == 0 {
            Cell {
                ch: 'x',
                fg: Some(self.colour()),
                bg: Some(self.colour()),
            }
        } else {
            let up = self.colour();
            let lo = if self.below(3) == 0 {
                up
            } else {
                self.colour()
            };
            block(up, lo)
        }
    }
}

#[test]
fn diffs_within_limits_leave_the_screen_as_the_encoder_believes_and_reach_the_frame() {
    let mut rng = Seeded(0x2545_f491_4f6c_dd1d);
    for case in 0..300 {
        let cols = 1 + rng.below(20) as usize;
        let rows = 1 + rng.below(6) as usize;
        let prev = grid((0..cols * rows).map(|_| rng.cell()).collect(), cols);
        let next = grid((0..cols * rows).map(|_| rng.cell()).collect(), cols);
        let mut terminal = prev.clone();
        let mut shown = Some(prev.clone());
        // Frames cut short by random budgets and tolerances, then exact ones, until done.
        for frame in 0.. {
            assert!(frame < 200, "case {case}: never reached the frame");
            let limits = DiffLimits {
                tolerance: if frame < 3 {
                    [0, 8, 16][rng.below(3) as usize]
                } else {
                    0
                },
                max_bytes: 1 + rng.below(400) as usize,
                first_row: rng.below(rows as u64) as usize,
            };
            let mut out = Vec::new();
            let outcome = encode_diff_within(&mut shown, &next, 0, limits, &mut out);
            apply(&mut terminal, &out);
            let believed = shown.as_ref().expect("a screen");
            assert_eq!(
                looks(&terminal),
                looks(believed),
                "case {case} frame {frame}"
            );
            let worst = (believed.cells.iter().zip(&next.cells))
                .map(|(a, b)| distance(a, b))
                .max()
                .unwrap_or(0);
            if outcome.complete {
                assert!(worst <= u16::from(limits.tolerance), "case {case}");
                assert_eq!(outcome.max_error, worst, "case {case}");
                if worst == 0 {
                    assert_eq!(looks(&terminal), looks(&next), "case {case}");
                    break;
                }
            }
        }
    }
}

#[test]
fn an_exact_diff_sends_each_pair_of_colours_once_wherever_its_cells_are() {
    // Two colour pairs in a checkerboard over two rows: in reading order every cell would need
    // a new pair; sent by shared colours, each pair is set once (▀ and ▄ turn it round).
    let (a, b, c, d) = (
        Colour::Rgb(200, 10, 10),
        Colour::Rgb(10, 200, 10),
        Colour::Rgb(10, 10, 200),
        Colour::Rgb(100, 100, 100),
    );
    let cells = (0..16)
        .map(|i| match (i + i / 8) % 4 {
            0 => block(a, b),
            1 => block(c, d),
            2 => block(b, a),
            _ => block(d, c),
        })
        .collect();
    let next = grid(cells, 8);
    let prev = grid(vec![block(a, a); 16], 8);
    let out = round_trip(&prev, &next);
    let sgrs = String::from_utf8_lossy(&out).matches('m').count();
    // One SGR for a/b, one for c/d, and the reset at the end.
    assert!(
        sgrs <= 3,
        "{sgrs} SGRs: {:?}",
        String::from_utf8_lossy(&out)
    );
}

#[test]
fn within_a_tolerance_a_gradient_shares_a_few_colours_each_within_it() {
    // A smooth gradient, one level a cell: exact, every cell needs its own colour; within 8
    // levels, colours rounded to multiples of 17 cover whole stretches of it.
    let grey = |v: u8| Colour::Rgb(v, v, v);
    let next = grid(
        (0..40)
            .map(|i| block(grey(100 + i), grey(100 + i)))
            .collect(),
        40,
    );
    let prev = grid(vec![block(grey(0), grey(0)); 40], 40);
    let sgrs = |tolerance: u8| {
        let mut shown = Some(prev.clone());
        let mut out = Vec::new();
        let limits = DiffLimits {
            tolerance,
            ..DiffLimits::EXACT
        };
        encode_diff_within(&mut shown, &next, 0, limits, &mut out);
        let mut terminal = prev.clone();
        apply(&mut terminal, &out);
        assert_eq!(looks(&terminal), looks(shown.as_ref().unwrap()));
        let worst = (terminal.cells.iter().zip(&next.cells))
            .map(|(a, b)| distance(a, b))
            .max();
        assert!(worst <= Some(u16::from(tolerance)), "{worst:?}");
        let text = String::from_utf8_lossy(&out);
        text.matches("\x1b[38;2;").count() + text.matches("\x1b[48;2;").count()
    };
    assert_eq!(sgrs(0), 40);
    assert!(sgrs(8) <= 4, "{}", sgrs(8));
}

#[test]
fn over_the_budget_a_row_with_text_is_still_sent_whole_spaces_and_all() {
    let (a, b, c) = (
        Colour::Rgb(10, 20, 30),
        Colour::Rgb(200, 100, 50),
        Colour::Rgb(90, 90, 90),
    );
    let text = |ch: char| Cell {
        ch,
        fg: Some(b),
        bg: Some(c),
    };
    // Two image rows, then a status line whose spaces (with a background) are block cells.
    let mut prev = vec![block(a, a); 20];
    prev.extend("xxxxxxxxxx".chars().map(text));
    let mut next = vec![block(b, c); 20];
    next.extend("ab  cd  ef".chars().map(text));
    let (prev, next) = (grid(prev, 10), grid(next, 10));
    let mut shown = Some(prev.clone());
    let mut out = Vec::new();
    let limits = DiffLimits {
        max_bytes: 1,
        ..DiffLimits::EXACT
    };
    let outcome = encode_diff_within(&mut shown, &next, 0, limits, &mut out);
    let mut terminal = prev.clone();
    apply(&mut terminal, &out);
    assert!(!outcome.complete);
    assert_eq!(looks(&terminal)[20..], looks(&next)[20..]);
    assert_eq!(looks(&terminal), looks(shown.as_ref().unwrap()));
    assert_ne!(looks(&terminal)[..20], looks(&next)[..20]);
}
