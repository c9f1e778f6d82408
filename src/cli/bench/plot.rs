//! `raytty bench --plot`: the error-against-time chart as text, for a terminal (say over SSH,
//! where the SVG cannot be opened). Log axes as in the SVG; each series is a braille polyline
//! (2×4 dots per cell) with its points marked by a letter; plain characters, no colour, so it
//! reads in any terminal and in a log file.

use std::fmt::Write as _;

use super::report::{GOAL_MS, GOAL_RMSE, sizes};
use super::svg::{series, tick};
use raytty::bench::{BenchReport, Row, RowKind};

/// Plot area of one panel, in cells.
pub const PLOT_COLS: usize = 64;
/// See [`PLOT_COLS`].
pub const PLOT_ROWS: usize = 16;

/// Width of the y axis' labels.
const LABEL_W: usize = 7;

/// The chart: one panel per size, each with its legend.
pub fn plot(report: &BenchReport) -> String {
    let mut s = String::new();
    for (w, h) in sizes(report) {
        let rows: Vec<&Row> = report
            .rows
            .iter()
            .filter(|r| (r.width, r.height) == (w, h))
            .collect();
        panel(&mut s, w, h, &rows);
        s.push('\n');
    }
    s
}

/// A character grid with braille dots underneath and marks on top.
struct Canvas {
    dots: Vec<u8>,
    marks: Vec<Option<char>>,
}

impl Canvas {
    fn new() -> Canvas {
        Canvas {
            dots: vec![0; PLOT_COLS * PLOT_ROWS],
            marks: vec![None; PLOT_COLS * PLOT_ROWS],
        }
    }

    /// Sets the dot at (x, y) in dot units (x right, y down), if inside.
    fn dot(&mut self, x: i64, y: i64) {
        if x < 0 || y < 0 || x >= 2 * PLOT_COLS as i64 || y >= 4 * PLOT_ROWS as i64 {
            return;
        }
        // Braille bits by (column, row) in a cell: dots 1-3 and 7 on the left, 4-6 and 8 right.
        const BITS: [[u8; 4]; 2] = [[0x01, 0x02, 0x04, 0x40], [0x08, 0x10, 0x20, 0x80]];
        let (cx, cy) = (x as usize / 2, y as usize / 4);
        self.dots[cy * PLOT_COLS + cx] |= BITS[x as usize % 2][y as usize % 4];
    }

    /// A straight line of dots between two dot positions.
    fn line(&mut self, (x0, y0): (i64, i64), (x1, y1): (i64, i64)) {
        let steps = (x1 - x0).abs().max((y1 - y0).abs()).max(1);
        for i in 0..=steps {
            self.dot(x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps);
        }
    }

    /// Puts `c` in the cell holding dot (x, y).
    fn mark(&mut self, (x, y): (i64, i64), c: char) {
        let (cx, cy) = (
            x.clamp(0, 2 * PLOT_COLS as i64 - 1) / 2,
            y.clamp(0, 4 * PLOT_ROWS as i64 - 1) / 4,
        );
        self.marks[cy as usize * PLOT_COLS + cx as usize] = Some(c);
    }

    fn cell(&self, col: usize, row: usize) -> char {
        let i = row * PLOT_COLS + col;
        self.marks[i].unwrap_or_else(|| match self.dots[i] {
            0 => ' ',
            b => char::from_u32(0x2800 + u32::from(b)).unwrap_or(' '),
        })
    }
}

/// The letter that marks a series' points: its bounce count's first digit for raw GI (`R` for
/// stage 6's roulette, `I` for it with independent numbers), `D` for GI + denoiser.
fn letter(r: &Row) -> char {
    match r.kind {
        RowKind::Denoised { .. } => 'D',
        RowKind::Independent { .. } => 'I',
        RowKind::Gi { bounces, .. } if bounces == raytty::shading::GI_MAX_BOUNCES => 'R',
        RowKind::Gi { bounces, .. } => char::from_digit(bounces % 10, 10).unwrap_or('G'),
        RowKind::Aa { .. } => 'a',
        RowKind::Stage(_) => 's',
    }
}

fn panel(s: &mut String, w: u32, h: u32, rows: &[&Row]) {
    let pos = |v: f64| v.max(1e-9).log10();
    let range = |vals: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let (lo, hi) = (lo.floor(), hi.ceil());
        if hi > lo { (lo, hi) } else { (lo, lo + 1.0) }
    };
    let (tx0, tx1) = range(&mut rows.iter().map(|r| pos(r.median_ms)).chain([pos(GOAL_MS)]));
    let (ey0, ey1) = range(&mut rows.iter().map(|r| pos(r.rmse)).chain([pos(GOAL_RMSE)]));
    let to_dot = |ms: f64, e: f64| -> (i64, i64) {
        let x = (pos(ms) - tx0) / (tx1 - tx0) * (2 * PLOT_COLS - 1) as f64;
        let y = (ey1 - pos(e)) / (ey1 - ey0) * (4 * PLOT_ROWS - 1) as f64;
        (x.round() as i64, y.round() as i64)
    };
    let mut c = Canvas::new();
    let series = series(rows);
    for (_, _, members) in &series {
        for pair in members.windows(2) {
            c.line(
                to_dot(pair[0].median_ms, pair[0].rmse),
                to_dot(pair[1].median_ms, pair[1].rmse),
            );
        }
    }
    c.mark(to_dot(GOAL_MS, GOAL_RMSE), '+');
    for r in rows {
        c.mark(to_dot(r.median_ms, r.rmse), letter(r));
    }
    let _ = writeln!(
        s,
        "{w}x{h}: RMSE against the reference (log, up) by ms per frame (log, right)"
    );
    for row in 0..PLOT_ROWS {
        // A label on the rows where a decade falls.
        let label = (ey0 as i32..=ey1 as i32)
            .find(|&k| {
                let (_, y) = to_dot(1.0, 10f64.powi(k));
                y / 4 == row as i64
            })
            .map_or(String::new(), tick);
        let line: String = (0..PLOT_COLS).map(|col| c.cell(col, row)).collect();
        let _ = writeln!(s, "{label:>w$} │{line}", w = LABEL_W - 1);
    }
    let _ = writeln!(s, "{} └{}", " ".repeat(LABEL_W - 1), "─".repeat(PLOT_COLS));
    let mut axis = vec![' '; PLOT_COLS + 8];
    for k in tx0 as i32..=tx1 as i32 {
        let (x, _) = to_dot(10f64.powi(k), 1.0);
        let col = (x / 2) as usize;
        for (i, ch) in tick(k).chars().enumerate() {
            if let Some(a) = axis.get_mut(col + i) {
                *a = ch;
            }
        }
    }
    let axis: String = axis.into_iter().collect();
    let _ = writeln!(s, "{}{}", " ".repeat(LABEL_W + 1), axis.trim_end());
    let mut legend: Vec<String> = series
        .iter()
        .filter_map(|(name, _, m)| m.first().map(|r| format!("{} {name}", letter(r))))
        .collect();
    legend.push("s seed stages".into());
    legend.push("a anti-aliasing".into());
    legend.push(format!("+ goal ({GOAL_MS} ms, RMSE {GOAL_RMSE})"));
    // The legend, wrapped to the plot's width.
    let mut line = String::new();
    for item in legend {
        if !line.is_empty() && line.chars().count() + 3 + item.chars().count() > PLOT_COLS {
            let _ = writeln!(s, "{}{line}", " ".repeat(LABEL_W + 1));
            line.clear();
        }
        if !line.is_empty() {
            line.push_str(" · ");
        }
        line.push_str(&item);
    }
    let _ = writeln!(s, "{}{line}", " ".repeat(LABEL_W + 1));
}
