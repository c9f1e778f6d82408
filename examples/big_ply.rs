//! Writes a large binary PLY for measuring model loading: a bumpy torus of about N triangles
//! (shared vertices, half as many as triangles, in grid order as a scan's would be), `float x y
//! z` and `list uchar int vertex_indices`, little-endian.
//!
//! Run: `cargo run --release --example big_ply -- 10000000 /tmp/big.ply`, then for example
//! `/usr/bin/time -v target/release/raytty /tmp/big.ply render --pixels 1x1 -o /dev/null`.
//! Add `--colours` for `uchar red green blue` on each vertex. Nothing here is asserted.

use std::io::{BufWriter, Write};

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: big_ply TRIANGLES OUT.ply [--colours]";
    let triangles: u64 = args.first().and_then(|a| a.parse().ok()).expect(usage);
    let out = args.get(1).expect(usage);
    let colours = args.iter().any(|a| a == "--colours");
    // A torus of `rows` × `cols` vertices has 2·rows·cols triangles; cols ≈ 2·rows.
    let rows = ((triangles as f64 / 4.0).sqrt().round() as u64).max(3);
    let cols = triangles.div_ceil(2 * rows).max(3);
    let (vertices, faces) = (rows * cols, 2 * rows * cols);
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(out)?);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment raytty examples/big_ply: a bumpy torus\n\
         element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n"
    )?;
    if colours {
        write!(
            w,
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
        )?;
    }
    write!(
        w,
        "element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )?;
    let tau = std::f64::consts::TAU;
    for i in 0..rows {
        let v = tau * i as f64 / rows as f64;
        for j in 0..cols {
            let u = tau * j as f64 / cols as f64;
            let bump =
                0.03 * (7.0 * u).sin() * (5.0 * v).cos() + 0.01 * (31.0 * u + 17.0 * v).sin();
            let r = 0.35 + bump;
            let p = [
                ((1.0 + r * v.cos()) * u.cos()) as f32,
                (r * v.sin()) as f32,
                ((1.0 + r * v.cos()) * u.sin()) as f32,
            ];
            for c in p {
                w.write_all(&c.to_le_bytes())?;
            }
            if colours {
                w.write_all(&[
                    (255.0 * (0.5 + 0.5 * u.sin())) as u8,
                    160,
                    (255.0 * (0.5 + 0.5 * v.cos())) as u8,
                ])?;
            }
        }
    }
    let at = |i: u64, j: u64| ((i % rows) * cols + j % cols) as i32;
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            for tri in [[a, b, c], [a, c, d]] {
                w.write_all(&[3])?;
                for k in tri {
                    w.write_all(&k.to_le_bytes())?;
                }
            }
        }
    }
    w.flush()?;
    eprintln!("{out}: {vertices} vertices, {faces} triangles");
    Ok(())
}
