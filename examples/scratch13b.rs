#[path = "../tests/support/slow_link.rs"]
mod slow_link;
use glam::Vec3;
use raytty::frame::{Cell, Colour, DiffLimits, distance, encode_diff_within, pixels};
use raytty::{CellGrid, cornell_box};

fn state(cols: u16, rows: u16, presses: usize) -> CellGrid {
    let scene = cornell_box();
    let camera = scene.camera();
    let mut lights = scene.lights().to_vec();
    for _ in 0..presses {
        lights[0].position += camera.to_world(Vec3::new(0.0, 0.0, 0.1));
    }
    slow_link::app_image(&camera, &lights, cols, rows)
}

fn quant(c: Colour, step: u8) -> Colour {
    match c {
        Colour::Rgb(r, g, b) => {
            let q =
                |v: u8| ((v as u16 + step as u16 / 2) / step as u16 * step as u16).min(255) as u8;
            Colour::Rgb(q(r), q(g), q(b))
        }
        x => x,
    }
}

fn half(up: Colour, lo: Colour) -> Cell {
    if up == lo {
        Cell {
            ch: ' ',
            fg: None,
            bg: Some(lo),
        }
    } else {
        Cell {
            ch: '▀',
            fg: Some(up),
            bg: Some(lo),
        }
    }
}

fn main() {
    for (cols, rows) in [(120u16, 40u16), (200, 50)] {
        let target = state(cols, rows, 10);
        for behind in [1usize, 2, 4] {
            let start = state(cols, rows, 10 - behind);
            let mut line = format!("{cols}x{rows} behind {behind}:");
            for k in [0u8, 8, 16, 32, 64] {
                let step = 2 * k + 1;
                let mut q = target.clone();
                let mut dirty = 0;
                for (i, cell) in q.cells.iter_mut().enumerate() {
                    if distance(&start.cells[i], &target.cells[i]) <= k as u16 {
                        *cell = start.cells[i];
                        continue;
                    }
                    dirty += 1;
                    if let Some((u, l)) = pixels(cell) {
                        *cell = half(quant(u, step), quant(l, step));
                    }
                }
                let mut shown = Some(start.clone());
                let mut out = Vec::new();
                encode_diff_within(&mut shown, &q, 0, DiffLimits::EXACT, &mut out);
                line += &format!(
                    "  k{k}: {dirty} cells {} B ({:.1}/cell)",
                    out.len(),
                    out.len() as f64 / dirty as f64
                );
            }
            println!("{line}");
        }
    }
}
