//! The pixel protocols as a terminal reads them: the kitty graphics escapes (keys, chunks,
//! base64, zlib or PNG) and sixel (palette, bands, repeats) decoded, and a screen of pixels
//! they are drawn on. Shared by `tests/graphics.rs` (the encoders rebuild their frame) and the
//! link emulator (`slow_link.rs`: what a pixel-mode terminal shows at the far end of a link).
#![allow(dead_code)]

use std::collections::HashMap;

/// Standard base64 (RFC 4648, `+/`, padded), decoded.
pub fn unbase64(text: &[u8]) -> Vec<u8> {
    let value = |b: u8| match b {
        b'A'..=b'Z' => b - b'A',
        b'a'..=b'z' => b - b'a' + 26,
        b'0'..=b'9' => b - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {b}"),
    };
    assert_eq!(text.len() % 4, 0, "base64 comes in fours");
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    for q in text.chunks(4) {
        let pad = q.iter().filter(|&&b| b == b'=').count();
        let n = q[..4 - pad]
            .iter()
            .fold(0u32, |n, &b| n << 6 | u32::from(value(b)))
            << (6 * pad);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// One kitty graphics command, whole (its chunks joined): the first escape's keys, and the
/// payload decoded (base64, then inflated if `o=z`).
pub struct Kitty {
    pub keys: HashMap<String, String>,
    pub payload: Vec<u8>,
}

impl Kitty {
    /// The key's value, if given.
    pub fn key(&self, k: &str) -> Option<&str> {
        self.keys.get(k).map(String::as_str)
    }

    /// A number the command must give.
    pub fn number(&self, k: &str) -> u32 {
        self.key(k)
            .unwrap_or_else(|| panic!("no {k}"))
            .parse()
            .unwrap_or_else(|_| panic!("{k} is not a number"))
    }

    /// The image it transmits (`f=24`: RGB of `s × v` pixels; `f=100`: PNG): width, height,
    /// pixels row-major.
    pub fn image(&self) -> (u32, u32, Vec<[u8; 3]>) {
        match self.key("f") {
            Some("24") => {
                let (w, h) = (self.number("s"), self.number("v"));
                assert_eq!(
                    self.payload.len(),
                    w as usize * h as usize * 3,
                    "RGB of s×v"
                );
                let px = self.payload.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
                (w, h, px)
            }
            Some("100") => {
                let mut reader = png::Decoder::new(std::io::Cursor::new(&self.payload[..]))
                    .read_info()
                    .expect("a PNG");
                let mut buf = vec![0; reader.output_buffer_size().expect("a size")];
                let info = reader.next_frame(&mut buf).expect("a PNG frame");
                assert_eq!(info.color_type, png::ColorType::Rgb, "RGB");
                assert_eq!(info.bit_depth, png::BitDepth::Eight, "8 bits");
                let px = buf[..info.buffer_size()]
                    .chunks(3)
                    .map(|p| [p[0], p[1], p[2]])
                    .collect();
                (info.width, info.height, px)
            }
            f => panic!("format {f:?}"),
        }
    }
}

/// The kitty escapes (`ESC _ G keys ; payload ESC \`) that begin `bytes`, up to and including
/// the chunk that ends the command (`m=0`, or no `m`), and the bytes after it.
pub fn kitty_command(bytes: &[u8]) -> (Kitty, &[u8]) {
    let mut rest = bytes;
    let mut first: Option<HashMap<String, String>> = None;
    let mut data = Vec::new();
    loop {
        let body = rest.strip_prefix(b"\x1b_G").expect("an APC G escape");
        let end = body.windows(2).position(|w| w == b"\x1b\\").expect("ST");
        let (control, payload) = match body[..end].iter().position(|&b| b == b';') {
            Some(i) => (&body[..i], &body[i + 1..end]),
            None => (&body[..end], &body[end..end]),
        };
        assert!(payload.len() <= 4096, "a chunk of {} bytes", payload.len());
        let keys: HashMap<String, String> = std::str::from_utf8(control)
            .expect("ASCII keys")
            .split(',')
            .map(|kv| {
                let (k, v) = kv.split_once('=').expect("key=value");
                (k.to_string(), v.to_string())
            })
            .collect();
        let more = keys.get("m").map(String::as_str) == Some("1");
        if first.is_none() {
            first = Some(keys);
        } else {
            assert_eq!(keys.len(), 1, "later chunks carry only m");
        }
        data.extend_from_slice(payload);
        rest = &body[end + 2..];
        if !more {
            break;
        }
    }
    let keys = first.expect("one escape");
    let mut payload = unbase64(&data);
    if keys.get("o").map(String::as_str) == Some("z") {
        payload = miniz_oxide::inflate::decompress_to_vec_zlib(&payload).expect("zlib");
    }
    (Kitty { keys, payload }, rest)
}

/// The image a stream of kitty escapes transmits (one command, `a=T`, nothing after it).
pub fn decode_kitty(bytes: &[u8]) -> Kitty {
    let (k, rest) = kitty_command(bytes);
    assert!(rest.is_empty(), "no escape after the last chunk (m=0)");
    assert_eq!(k.key("a"), Some("T"));
    k
}

/// The pixels a sixel DCS string paints (`None`: never painted), with its raster size.
pub fn decode_sixel(bytes: &[u8]) -> (usize, usize, Vec<Option<[u8; 3]>>) {
    let body = bytes.strip_prefix(b"\x1bP").expect("DCS");
    let q = body.iter().position(|&b| b == b'q').expect("q");
    let end = body.windows(2).position(|w| w == b"\x1b\\").expect("ST");
    let s = &body[q + 1..end];
    let mut i = 0;
    let number = |i: &mut usize| {
        let start = *i;
        while *i < s.len() && s[*i].is_ascii_digit() {
            *i += 1;
        }
        std::str::from_utf8(&s[start..*i])
            .unwrap()
            .parse::<usize>()
            .unwrap()
    };
    assert_eq!(s[0], b'"', "raster attributes first");
    i += 1;
    let attrs: Vec<usize> = (0..4)
        .map(|k| {
            if k > 0 {
                assert_eq!(s[i], b';');
                i += 1;
            }
            number(&mut i)
        })
        .collect();
    assert_eq!(&attrs[..2], &[1, 1], "square pixels");
    let (w, h) = (attrs[2], attrs[3]);
    let mut pixels = vec![None; w * h];
    let mut palette = HashMap::new();
    let (mut x, mut band, mut colour) = (0, 0, 0);
    while i < s.len() {
        match s[i] {
            b'#' => {
                i += 1;
                colour = number(&mut i);
                if s.get(i) == Some(&b';') {
                    i += 1;
                    assert_eq!(number(&mut i), 2, "RGB colour");
                    let pct: Vec<usize> = (0..3)
                        .map(|_| {
                            i += 1;
                            number(&mut i)
                        })
                        .collect();
                    assert!(pct.iter().all(|&p| p <= 100));
                    // Percent to 8 bits, as a terminal reads it.
                    palette.insert(colour, [0, 1, 2].map(|c| ((pct[c] * 255 + 50) / 100) as u8));
                }
            }
            b'$' => {
                x = 0;
                i += 1;
            }
            b'-' => {
                x = 0;
                band += 1;
                i += 1;
            }
            b'!' | b'?'..=b'~' => {
                let mut run = 1;
                if s[i] == b'!' {
                    i += 1;
                    run = number(&mut i);
                }
                let bits = s[i] - b'?';
                i += 1;
                let c = *palette.get(&colour).expect("a colour set before use");
                for _ in 0..run {
                    for dy in 0..6 {
                        let y = band * 6 + dy;
                        if bits >> dy & 1 == 1 {
                            assert!(x < w && y < h, "paints outside the raster");
                            pixels[y * w + x] = Some(c);
                        }
                    }
                    x += 1;
                }
            }
            b => panic!("unexpected byte {b} in sixel data"),
        }
    }
    (w, h, pixels)
}

/// Splits a stream of terminal output into text (everything else, for a text terminal
/// emulator) and the graphics escapes (kitty's APC `ESC _ G`, sixel's DCS `ESC P`), each held
/// back whole until its `ESC \`.
#[derive(Default)]
pub struct Splitter {
    /// The graphics escape being read (from its ESC), if any.
    escape: Option<Vec<u8>>,
    /// A lone ESC ended the last piece of text: what follows decides.
    esc: bool,
}

/// A piece of the stream.
pub enum Piece<'a> {
    Text(&'a [u8]),
    /// A whole graphics escape.
    Graphics(Vec<u8>),
}

impl Splitter {
    /// The pieces `bytes` completes, in order.
    pub fn split<'a>(&mut self, bytes: &'a [u8]) -> Vec<Piece<'a>> {
        let mut pieces = Vec::new();
        let mut text_from = 0;
        let mut i = 0;
        while i < bytes.len() {
            let b = bytes[i];
            if let Some(e) = self.escape.as_mut() {
                e.push(b);
                i += 1;
                if e.ends_with(b"\x1b\\") {
                    pieces.push(Piece::Graphics(self.escape.take().expect("an escape")));
                    text_from = i;
                }
                continue;
            }
            if self.esc {
                self.esc = false;
                if b == b'_' || b == b'P' {
                    // The ESC was at `i - 1` (or ended the last read, already held back).
                    let start = i.saturating_sub(1);
                    if start > text_from {
                        pieces.push(Piece::Text(&bytes[text_from..start]));
                    }
                    self.escape = Some(vec![0x1b, b]);
                    i += 1;
                    text_from = i;
                    continue;
                }
                if i == 0 {
                    pieces.push(Piece::Text(b"\x1b"));
                }
            }
            if b == 0x1b {
                self.esc = true;
                if i + 1 == bytes.len() {
                    // Held back until the next byte says what it begins.
                    if i > text_from {
                        pieces.push(Piece::Text(&bytes[text_from..i]));
                    }
                    return pieces;
                }
            }
            i += 1;
        }
        if self.escape.is_none() && text_from < bytes.len() {
            pieces.push(Piece::Text(&bytes[text_from..]));
        }
        pieces
    }
}

/// The pixels a terminal shows: sixel paints a canvas one to one at the cursor (pixels a
/// sixel leaves out keep their colour); the kitty image with id `i` (each transmission
/// replaces it) is shown over the cells it was placed on, scaled to cover them (nearest
/// pixel: the terminals filter, but only a full-resolution image can be exact). Text is not
/// drawn: the image area is compared, and the status line is below it.
pub struct PixelScreen {
    /// Pixels a cell.
    pub cell: (u32, u32),
    width: u32,
    height: u32,
    canvas: Vec<Option<[u8; 3]>>,
    /// The kitty image shown.
    kitty: Option<Placed>,
    /// Escapes of a kitty command whose last chunk has not come yet.
    pending: Vec<u8>,
}

/// A kitty image on screen: its pixels, and the pixel rectangle it covers (x, y, w, h).
struct Placed {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 3]>,
    rect: [u32; 4],
}

impl PixelScreen {
    /// A blank screen of `cols × rows` cells of `cell` pixels.
    pub fn new(cols: u16, rows: u16, cell: (u32, u32)) -> PixelScreen {
        let (width, height) = (u32::from(cols) * cell.0, u32::from(rows) * cell.1);
        PixelScreen {
            cell,
            width,
            height,
            canvas: vec![None; width as usize * height as usize],
            kitty: None,
            pending: Vec::new(),
        }
    }

    /// Draws a graphics escape the terminal read with its cursor at `(row, col)`; whether the
    /// picture changed (a kitty command's last chunk, a sixel image).
    pub fn apply(&mut self, escape: &[u8], (row, col): (u16, u16)) -> bool {
        let (x0, y0) = (u32::from(col) * self.cell.0, u32::from(row) * self.cell.1);
        if let Some(dcs) = escape.strip_prefix(b"\x1bP") {
            let params = dcs.iter().take_while(|b| b.is_ascii_digit() || **b == b';');
            if dcs.get(params.count()) != Some(&b'q') {
                return false; // a DCS other than sixel
            }
            let (w, h, px) = decode_sixel(escape);
            for y in 0..h as u32 {
                for x in 0..w as u32 {
                    let (sx, sy) = (x0 + x, y0 + y);
                    if let Some(p) = px[(y * w as u32 + x) as usize]
                        && sx < self.width
                        && sy < self.height
                    {
                        self.canvas[(sy * self.width + sx) as usize] = Some(p);
                    }
                }
            }
            return true;
        }
        if !escape.starts_with(b"\x1b_G") {
            return false; // an APC other than kitty's
        }
        self.pending.extend_from_slice(escape);
        let keys = escape[3..].split(|&b| b == b';' || b == 0x1b).next();
        if keys.is_some_and(|k| k.split(|&b| b == b',').any(|kv| kv == b"m=1")) {
            return false;
        }
        let bytes = std::mem::take(&mut self.pending);
        let (k, rest) = kitty_command(&bytes);
        assert!(rest.is_empty(), "one kitty command at a time");
        match k.key("a") {
            Some("T") => {
                let (w, h, px) = k.image();
                let cells = (k.number("c"), k.number("r"));
                let rect = [x0, y0, cells.0 * self.cell.0, cells.1 * self.cell.1];
                self.kitty = Some(Placed {
                    width: w,
                    height: h,
                    pixels: px,
                    rect,
                });
                true
            }
            Some("d") => self.kitty.take().is_some(),
            _ => false,
        }
    }

    /// The `w × h` pixels from the top-left corner as shown (`None`: nothing drawn there).
    pub fn shown(&self, w: u32, h: u32) -> Vec<Option<[u8; 3]>> {
        let mut out = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h {
            for x in 0..w {
                let mut p = if x < self.width && y < self.height {
                    self.canvas[(y * self.width + x) as usize]
                } else {
                    None
                };
                if let Some(k) = &self.kitty
                    && let [rx, ry, rw, rh] = k.rect
                    && (rx..rx + rw).contains(&x)
                    && (ry..ry + rh).contains(&y)
                {
                    let sx = u64::from(x - rx) * u64::from(k.width) / u64::from(rw);
                    let sy = u64::from(y - ry) * u64::from(k.height) / u64::from(rh);
                    p = Some(k.pixels[(sy * u64::from(k.width) + sx) as usize]);
                }
                out.push(p);
            }
        }
        out
    }
}

/// The largest difference, in levels of one channel, between `shown` and `want`; 256 where a
/// pixel was never drawn.
pub fn max_pixel_error(shown: &[Option<[u8; 3]>], want: &[[u8; 3]]) -> u16 {
    assert_eq!(shown.len(), want.len());
    shown
        .iter()
        .zip(want)
        .map(|(s, w)| match s {
            Some(s) => (0..3)
                .map(|c| u16::from(s[c].abs_diff(w[c])))
                .max()
                .unwrap_or(0),
            None => 256,
        })
        .max()
        .unwrap_or(0)
}
