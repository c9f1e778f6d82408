//! Sixel (xterm as a VT340, foot, WezTerm, Konsole, Windows Terminal, VS Code): a frame as one
//! image in a DCS string, six pixel rows a band, with a palette of at most [`MAX_COLOURS`] made
//! for the frame by median cut. No dithering: the same frame gives the same bytes, and a
//! still picture does not shimmer.
//!
//! Written here rather than taken from a crate: the encoder is a hundred lines, and the one
//! candidate (`icy_sixel`, a port of libsixel) brings its own quantiser and dithering options
//! that raytty would not use.

/// Colours a palette holds (the registers xterm gives a VT340 by default is 16; xterm's
/// `-ti vt340` with `numColorRegisters` 256, foot and WezTerm take 256 or more).
pub const MAX_COLOURS: usize = 256;

/// Bits kept of each channel for the histogram the palette is cut from (32 768 boxes).
const BITS: u32 = 5;

/// A box of histogram entries: their indices in `entries`, and how many pixels they hold.
#[derive(Clone, Copy)]
struct Bucket {
    lo: usize,
    hi: usize,
    pixels: u32,
}

/// One histogram entry: a 15-bit colour, its pixel count and channel sums.
#[derive(Clone, Copy)]
struct Entry {
    key: u16,
    count: u32,
    sum: [u64; 3],
}

fn channel(key: u16, ch: usize) -> u16 {
    key >> (BITS as usize * (2 - ch)) & ((1 << BITS) - 1)
}

/// The palette for `rgb` (at most [`MAX_COLOURS`], 8-bit) and each pixel's index into it.
/// Median cut: the box with the most pixels (of those with more than one colour) is split at
/// the pixel median of its widest channel, until there are enough boxes; a box's colour is its
/// pixels' mean.
pub fn palette(rgb: &[[u8; 3]]) -> (Vec<[u8; 3]>, Vec<u8>) {
    let key = |p: &[u8; 3]| {
        let s = 8 - BITS;
        (u16::from(p[0] >> s) << (2 * BITS)) | (u16::from(p[1] >> s) << BITS) | u16::from(p[2] >> s)
    };
    let mut hist = vec![(0u32, [0u64; 3]); 1 << (3 * BITS)];
    for p in rgb {
        let e = &mut hist[usize::from(key(p))];
        e.0 += 1;
        for (sum, &v) in e.1.iter_mut().zip(p) {
            *sum += u64::from(v);
        }
    }
    let mut entries: Vec<Entry> = hist
        .iter()
        .enumerate()
        .filter(|(_, e)| e.0 > 0)
        .map(|(k, e)| Entry {
            key: k as u16,
            count: e.0,
            sum: e.1,
        })
        .collect();
    let mut boxes = vec![Bucket {
        lo: 0,
        hi: entries.len(),
        pixels: rgb.len() as u32,
    }];
    while boxes.len() < MAX_COLOURS {
        let Some(i) = (0..boxes.len())
            .filter(|&i| boxes[i].hi - boxes[i].lo > 1)
            .max_by_key(|&i| (boxes[i].pixels, usize::MAX - i))
        else {
            break;
        };
        let Bucket { lo, hi, pixels } = boxes[i];
        let span = |ch: usize| {
            let vals = entries[lo..hi].iter().map(|e| channel(e.key, ch));
            vals.clone().max().unwrap_or(0) - vals.min().unwrap_or(0)
        };
        let widest = (0..3).max_by_key(|&ch| (span(ch), 2 - ch)).unwrap_or(0);
        entries[lo..hi].sort_by_key(|e| (channel(e.key, widest), e.key));
        let half = pixels.div_ceil(2);
        let mut seen = 0;
        let mut cut = lo + 1;
        for (j, e) in entries[lo..hi - 1].iter().enumerate() {
            seen += e.count;
            cut = lo + j + 1;
            if seen >= half {
                break;
            }
        }
        let first: u32 = entries[lo..cut].iter().map(|e| e.count).sum();
        boxes[i] = Bucket {
            lo,
            hi: cut,
            pixels: first,
        };
        boxes.push(Bucket {
            lo: cut,
            hi,
            pixels: pixels - first,
        });
    }
    let mut index = vec![0u8; 1 << (3 * BITS)];
    let colours = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (mut n, mut s) = (0u64, [0u64; 3]);
            for e in &entries[b.lo..b.hi] {
                index[usize::from(e.key)] = i as u8;
                n += u64::from(e.count);
                for (sum, v) in s.iter_mut().zip(e.sum) {
                    *sum += v;
                }
            }
            s.map(|v| ((2 * v + n) / (2 * n.max(1))) as u8)
        })
        .collect();
    let indices = rgb.iter().map(|p| index[usize::from(key(p))]).collect();
    (colours, indices)
}

/// A palette level in sixel's percent (0-100), from 8 bits.
fn percent(v: u8) -> u32 {
    (u32::from(v) * 100 + 127) / 255
}

/// Appends to `out` the DCS string that shows `rgb` (`width × height` pixels, row-major) at
/// the cursor, one pixel to one screen pixel (raster attributes 1:1): the palette (`#i;2;r;g;b`
/// in percent), then each band of six rows as one line of sixels per colour used in it
/// (repeats of four or more as `!n`), `$` between colours and `-` between bands.
pub fn encode_sixel(rgb: &[[u8; 3]], width: u32, height: u32, out: &mut Vec<u8>) {
    debug_assert_eq!(rgb.len(), width as usize * height as usize);
    let (w, h) = (width as usize, height as usize);
    let (colours, index) = palette(rgb);
    out.extend_from_slice(format!("\x1bP0;1;0q\"1;1;{width};{height}").as_bytes());
    for (i, c) in colours.iter().enumerate() {
        let [r, g, b] = c.map(percent);
        out.extend_from_slice(format!("#{i};2;{r};{g};{b}").as_bytes());
    }
    let mut line = vec![0u8; w];
    for top in (0..h).step_by(6) {
        let rows = (h - top).min(6);
        let mut used = [false; MAX_COLOURS];
        for &k in &index[top * w..(top + rows) * w] {
            used[usize::from(k)] = true;
        }
        let mut first = true;
        for colour in (0..colours.len()).filter(|&k| used[k]) {
            line.fill(0);
            for dy in 0..rows {
                let row = &index[(top + dy) * w..(top + dy + 1) * w];
                for (bits, &k) in line.iter_mut().zip(row) {
                    *bits |= u8::from(usize::from(k) == colour) << dy;
                }
            }
            if !first {
                out.push(b'$');
            }
            first = false;
            out.extend_from_slice(format!("#{colour}").as_bytes());
            // Trailing empty sixels draw nothing: left out.
            let end = line.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
            let mut x = 0;
            while x < end {
                let run = line[x..end].iter().take_while(|&&b| b == line[x]).count();
                let ch = 63 + line[x];
                if run >= 4 {
                    out.extend_from_slice(format!("!{run}").as_bytes());
                    out.push(ch);
                } else {
                    out.extend(std::iter::repeat_n(ch, run));
                }
                x += run;
            }
        }
        if top + 6 < h {
            out.push(b'-');
        }
    }
    out.extend_from_slice(b"\x1b\\");
}
