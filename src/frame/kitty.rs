//! The kitty graphics protocol (kitty, WezTerm, Ghostty, Konsole): a frame as one image, its
//! 8-bit RGB zlib-compressed (or, within [`NEAR_LEVELS`], as PNG) and base64-encoded in APC
//! escapes (`ESC _ G keys ; data ESC \`) of at most [`CHUNK`] bytes of data each, as the
//! protocol asks of a terminal's input.

/// Most base64 bytes one escape carries (the protocol's limit; a multiple of 4).
pub const CHUNK: usize = 4096;

/// zlib's default level (not tuned: the seed frame at 400×400 is 60.7 kB in 6-7 ms of CPU,
/// `examples/cells_bench`).
const LEVEL: u8 = 6;

/// How close the image sent is to the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// Every pixel as it is: RGB compressed with zlib (`f=24,o=z`).
    Exact,
    /// Every channel within [`NEAR_LEVELS`] levels: rounded to the nearest of 16 levels (0,
    /// 17, ..., 255) and sent as PNG (`f=100`), whose row filter (each byte less the one
    /// above) turns the runs of equal levels into zeros for zlib. The seed's frame at
    /// 1200×780: 21 kB of PNG against 97 kB of zlib for the exact pixels, 28 kB of zlib for
    /// the same rounded ones (Paeth's filter and zlib level 9 gain nothing over these; rounding
    /// the difference to the pixel above instead, near-lossless DPCM, neither).
    Near,
}

/// The most a channel of a [`Precision::Near`] image differs from the frame's.
pub const NEAR_LEVELS: u8 = 8;

/// Where and how the app places its frame (see [`encode_kitty_placed`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The image and placement id: sending an image with the id again replaces the old one
    /// in place, without a blank frame between (the protocol's way to animate).
    pub id: u32,
    /// The cells the image is scaled to cover (columns, rows): a smaller image is scaled up
    /// by the terminal.
    pub cells: (u32, u32),
}

/// Appends to `out` the escapes that show `rgb` (`width × height` pixels, row-major) at the
/// cursor, one pixel to one screen pixel, with the terminal's replies turned off (`q=2`): the
/// image is sent whole (`a=T`, transmit and display), as 24-bit RGB (`f=24`) compressed with
/// zlib (`o=z`), in chunks (`m=1` on all but the last).
pub fn encode_kitty(rgb: &[[u8; 3]], width: u32, height: u32, out: &mut Vec<u8>) {
    encode(rgb, width, height, None, out);
}

/// [`encode_kitty`] at the given `precision`, with the image given an id (`i`, and the
/// placement `p`), scaled to cover `place.cells` (`c`, `r`), and the cursor left where it was
/// (`C=1`, so an image that ends on the last row does not scroll the screen).
pub fn encode_kitty_placed(
    rgb: &[[u8; 3]],
    width: u32,
    height: u32,
    place: Placement,
    precision: Precision,
    out: &mut Vec<u8>,
) {
    match precision {
        Precision::Exact => encode(rgb, width, height, Some(place), out),
        Precision::Near => match near_png(rgb, width, height) {
            Some(data) => transmit(&data, "f=100", width, height, Some(place), out),
            None => encode(rgb, width, height, Some(place), out),
        },
    }
}

/// `rgb` rounded to 16 levels a channel (within [`NEAR_LEVELS`]) as a PNG of `Up`-filtered
/// rows, zlib level 6; `None` if the PNG encoder refuses (it does not, writing to memory an
/// image of the size it was told; the caller then sends the exact image).
fn near_png(rgb: &[[u8; 3]], width: u32, height: u32) -> Option<Vec<u8>> {
    let step = 2 * u16::from(NEAR_LEVELS) + 1;
    let levels: Vec<u8> = rgb
        .iter()
        .flatten()
        .map(|&v| ((u16::from(v) + u16::from(NEAR_LEVELS)) / step * step) as u8)
        .collect();
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_filter(png::Filter::Up);
    encoder.set_deflate_compression(png::DeflateCompression::Level(LEVEL));
    let written = encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&levels).and_then(|()| w.finish()));
    written.ok().map(|()| out)
}

/// The escape that deletes every image the terminal shows (`a=d,d=A`), replies off.
pub const DELETE_ALL: &[u8] = b"\x1b_Ga=d,d=A,q=2\x1b\\";

fn encode(rgb: &[[u8; 3]], width: u32, height: u32, place: Option<Placement>, out: &mut Vec<u8>) {
    debug_assert_eq!(rgb.len(), width as usize * height as usize);
    let raw: Vec<u8> = rgb.iter().flatten().copied().collect();
    let packed = miniz_oxide::deflate::compress_to_vec_zlib(&raw, LEVEL);
    transmit(&packed, "f=24,o=z", width, height, place, out);
}

/// The escapes that transmit and show `data` (in `format`, the keys that say it).
fn transmit(
    data: &[u8],
    format: &str,
    width: u32,
    height: u32,
    place: Option<Placement>,
    out: &mut Vec<u8>,
) {
    let text = base64(data);
    let chunks: Vec<&[u8]> = text.chunks(CHUNK).collect();
    for (i, chunk) in chunks.iter().enumerate() {
        let more = u8::from(i + 1 < chunks.len());
        out.extend_from_slice(b"\x1b_G");
        if i == 0 {
            out.extend_from_slice(format!("a=T,{format},q=2,s={width},v={height}").as_bytes());
            if let Some(p) = place {
                let (c, r) = p.cells;
                out.extend_from_slice(format!(",i={0},p={0},c={c},r={r},C=1", p.id).as_bytes());
            }
            out.extend_from_slice(format!(",m={more}").as_bytes());
        } else {
            out.extend_from_slice(format!("m={more}").as_bytes());
        }
        out.push(b';');
        out.extend_from_slice(chunk);
        out.extend_from_slice(b"\x1b\\");
    }
}

/// Standard base64 (RFC 4648, `+/`, padded).
fn base64(data: &[u8]) -> Vec<u8> {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = Vec::with_capacity(data.len().div_ceil(3) * 4);
    for group in data.chunks(3) {
        let b = [
            group[0],
            *group.get(1).unwrap_or(&0),
            *group.get(2).unwrap_or(&0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= group.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize]);
            } else {
                out.push(b'=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_examples() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded.as_bytes());
        }
    }
}
