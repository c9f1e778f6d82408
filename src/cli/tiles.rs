//! `raytty render --tile I/N` and `raytty merge`: a frame too big for one machine, rendered
//! as N tiles (bands of whole rows) on as many machines and joined again. Every pixel's samples
//! depend only on (pixel, sample, frame), so the joined image is byte for byte the one a single
//! render writes.
//!
//! A tile is a PFM of its rows (linear, exact) followed by one line of raytty's after the
//! pixels, `raytty-tile I/N rows FIRST+COUNT of WxH tonemap NAME`, so that `merge` needs no
//! order and no flags: it checks that the tiles are the N parts of one frame and writes it as
//! PNG (through the frame's tone map) or PFM. Tile I (0 to N−1, as a Kubernetes indexed Job's
//! `JOB_COMPLETION_INDEX` and a Slurm array `--array=0-(N-1)` number them) holds the frame's
//! bands of 8 rows from ⌊I·B/N⌋ to ⌊(I+1)·B/N⌋ of its B bands: each tile renders the very bands
//! the whole frame is made of.

use std::fs::File;
use std::io::{BufWriter, Write};

use anyhow::Context;
use raytty::Image;
use raytty::image::ToneMap;

use super::args::{Format, MergeArgs, parse_tonemap};
use super::render::format_for;
use super::{Failure, Result, usage};

/// Rows of a band: the render's tiles of camera rays are 8×8 pixels.
const BAND: u32 = 8;

/// What starts a tile's line after its pixels.
const MARK: &[u8] = b"\nraytty-tile ";

/// Tile `index` of `count` (0-based) of a frame `height` rows high: its rows, `(first, count)`.
pub(super) fn rows_of((index, count): (u32, u32), height: u32) -> Result<(u32, u32)> {
    let bands = height.div_ceil(BAND);
    if count > bands {
        usage!(
            "--tile {index}/{count}: a frame {height} pixels high has {bands} bands of {BAND} rows, so at most {bands} tiles"
        );
    }
    let band = |i: u32| (u64::from(i) * u64::from(bands) / u64::from(count)) as u32;
    let first = band(index) * BAND;
    let end = (band(index + 1) * BAND).min(height);
    Ok((first, end - first))
}

/// The line a tile ends with (after its pixels).
pub(super) fn trailer(
    (index, count): (u32, u32),
    (first, rows): (u32, u32),
    (width, height): (u32, u32),
    tone: ToneMap,
) -> String {
    format!(
        "\nraytty-tile {index}/{count} rows {first}+{rows} of {width}x{height} tonemap {}\n",
        tone.name()
    )
}

/// A tile as read back.
struct Tile {
    index: u32,
    count: u32,
    first: u32,
    size: (u32, u32),
    tone: ToneMap,
    image: Image,
}

/// Reads the tile in `bytes` (from `file`): its line, then its pixels.
fn read_tile(bytes: &[u8], file: &str) -> std::result::Result<Tile, String> {
    let not_tile = |why: &str| format!("{file}: not a tile of raytty render --tile ({why})");
    let at = bytes
        .windows(MARK.len())
        .rposition(|w| w == MARK)
        .ok_or_else(|| not_tile("no raytty-tile line after the pixels"))?;
    let line = std::str::from_utf8(&bytes[at + MARK.len()..])
        .map_err(|_| not_tile("its raytty-tile line is not text"))?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let bad_line = || {
        not_tile(&format!(
            "its line `raytty-tile {}` is not understood",
            line.trim()
        ))
    };
    let [part, "rows", rows, "of", size, "tonemap", tone] = words[..] else {
        return Err(bad_line());
    };
    let pair = |s: &str, sep: char| -> Option<(u32, u32)> {
        let (a, b) = s.split_once(sep)?;
        Some((a.parse().ok()?, b.parse().ok()?))
    };
    let ((index, count), (first, rows), size) =
        match (pair(part, '/'), pair(rows, '+'), pair(size, 'x')) {
            (Some(p), Some(r), Some(s)) => (p, r, s),
            _ => return Err(bad_line()),
        };
    let tone = parse_tonemap(tone).map_err(|_| bad_line())?;
    let image = Image::read_pfm(&bytes[..at]).map_err(|e| not_tile(&e.to_string()))?;
    if index >= count || image.width != size.0 || image.height != rows {
        return Err(bad_line());
    }
    Ok(Tile {
        index,
        count,
        first,
        size,
        tone,
        image,
    })
}

/// `raytty merge`: joins the tiles into the frame and writes it as `-o`'s extension says.
pub(super) fn run_merge(args: &MergeArgs) -> Result<()> {
    let format = format_for(Some(&args.output));
    if !matches!(format, Format::Png | Format::Pfm) {
        usage!(
            "-o {}: raytty merge writes .png or .pfm images",
            args.output.display()
        );
    }
    let mut tiles = Vec::with_capacity(args.tiles.len());
    for path in &args.tiles {
        let shown = path.display().to_string();
        let bytes = std::fs::read(path)
            .map_err(|e| Failure::Usage(format!("{shown}: cannot be read: {e}")))?;
        tiles.push((
            shown.clone(),
            read_tile(&bytes, &shown).map_err(Failure::Usage)?,
        ));
    }
    let (first_name, first) = &tiles[0];
    let (count, size, tone) = (first.count, first.size, first.tone);
    for (name, t) in &tiles {
        if (t.count, t.size, t.tone) != (count, size, tone) {
            usage!(
                "{name} is tile {}/{} of a {}x{} frame (tonemap {}), and {first_name} of {count} tiles of {}x{} (tonemap {}): give the tiles of one frame",
                t.index,
                t.count,
                t.size.0,
                t.size.1,
                t.tone.name(),
                size.0,
                size.1,
                tone.name()
            );
        }
    }
    let mut have: Vec<Option<&str>> = vec![None; count as usize];
    for (name, t) in &tiles {
        if let Some(other) = have[t.index as usize].replace(name) {
            usage!("{other} and {name} are both tile {}/{count}", t.index);
        }
        let want = rows_of((t.index, count), size.1)?;
        if (t.first, t.image.height) != want {
            usage!(
                "{name}: tile {}/{count} of a frame {} rows high holds rows {}+{}, not {}+{}",
                t.index,
                size.1,
                want.0,
                want.1,
                t.first,
                t.image.height
            );
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| have[i as usize].is_none())
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        let (tiles, are) = match missing.len() {
            1 => ("tile", "is"),
            _ => ("tiles", "are"),
        };
        usage!(
            "{tiles} {} of 0 to {} {are} missing (raytty render --tile I/{count} makes tile I)",
            missing.join(", "),
            count - 1
        );
    }
    let mut frame = Image::new(size.0, size.1);
    let w = size.0 as usize;
    for (_, t) in &tiles {
        let at = t.first as usize * w;
        frame.pixels[at..at + t.image.pixels.len()].copy_from_slice(&t.image.pixels);
    }
    let tone = args.tonemap.unwrap_or(tone);
    let file = File::create(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let mut out = BufWriter::new(file);
    match format {
        Format::Png => tone.image(&frame).write_png(&mut out),
        _ => frame.write_pfm(&mut out),
    }
    .and_then(|()| out.flush())
    .with_context(|| format!("cannot write to {}", args.output.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tiles cover every band once, in order, each at least one band.
    #[test]
    fn tiles_split_the_bands() {
        for height in [1u32, 7, 8, 9, 100, 500, 1001] {
            let bands = height.div_ceil(BAND);
            for count in 1..=bands.min(40) {
                let mut next = 0;
                for index in 0..count {
                    let (first, rows) = rows_of((index, count), height).unwrap();
                    assert_eq!(first, next);
                    assert!(rows > 0 && first % BAND == 0);
                    next = first + rows;
                }
                assert_eq!(next, height);
            }
            assert!(rows_of((0, bands + 1), height).is_err());
        }
    }

    #[test]
    fn a_tile_reads_back() {
        let mut img = Image::new(3, 2);
        img.pixels[4] = glam::Vec3::new(1.0, 2.0, 3.0);
        let mut bytes = Vec::new();
        img.write_pfm(&mut bytes).unwrap();
        bytes.extend(trailer((1, 4), (8, 2), (3, 30), ToneMap::Neutral).as_bytes());
        let t = read_tile(&bytes, "t.pfm").unwrap();
        assert_eq!((t.index, t.count, t.first, t.size), (1, 4, 8, (3, 30)));
        assert_eq!(
            (t.tone, t.image.pixels[4]),
            (ToneMap::Neutral, img.pixels[4])
        );
        let e = read_tile(&bytes[..bytes.len() - 30], "t.pfm")
            .err()
            .unwrap();
        assert!(e.starts_with("t.pfm: not a tile"), "{e}");
    }
}
