//! How long the app takes to show a model: `raytty MODEL` started in a 120×40 pseudo-terminal
//! (truecolor, the device-attributes query answered as a terminal does, a link too fast to
//! matter), timed from the spawn until half the screen's cells show the frame's colours.
//! Prints each run and the median.
//!
//! Run: `cargo build --release && cargo run --release --example first_frame -- MODEL [RUNS]
//! [BINARY]` (by default this checkout's `target/release/raytty`)
//! (a million-triangle model: `cargo run --release --example big_ply -- 1000000 /tmp/m.ply`).
//! Nothing here is asserted.

#[path = "../tests/support/slow_link.rs"]
mod slow_link;

use std::time::{Duration, Instant};

use slow_link::SlowLink;

const COLS: u16 = 120;
const ROWS: u16 = 40;

/// Cells whose colours are set (the frame's): a loading bar or a cleared screen has few.
fn painted(screen: &vt100::Screen) -> usize {
    let mut n = 0;
    for r in 0..ROWS {
        for c in 0..COLS {
            if let Some(cell) = screen.cell(r, c)
                && matches!(cell.bgcolor(), vt100::Color::Rgb(..))
            {
                n += 1;
            }
        }
    }
    n
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let model = args
        .first()
        .expect("usage: first_frame MODEL [RUNS] [BINARY]");
    let runs: usize = args.get(1).and_then(|r| r.parse().ok()).unwrap_or(3);
    let binary = args.get(2).map_or(
        concat!(env!("CARGO_MANIFEST_DIR"), "/target/release/raytty"),
        String::as_str,
    );
    let mut times = Vec::new();
    for run in 0..runs {
        let start = Instant::now();
        let link = SlowLink::start_behind_buffer(
            binary,
            &[model, "--color", "truecolor"],
            COLS,
            ROWS,
            1e9,
        );
        let shown = link.wait_for(Duration::from_secs(60), |s| {
            painted(s) >= (COLS as usize * ROWS as usize) / 2
        });
        let t = start.elapsed().as_secs_f64();
        assert!(shown, "the model never showed");
        println!("run {run}: first frame after {t:.3} s");
        times.push(t);
        drop(link);
    }
    times.sort_by(f64::total_cmp);
    println!("median {:.3} s over {runs} runs", times[runs / 2]);
}
