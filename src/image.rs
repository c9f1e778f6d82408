//! Linear float images and their 8-bit, PNG and PFM forms (PFM both written and read: the
//! bench caches its references as PFM).

use std::io::{self, Write};

use glam::Vec3;

/// Most pixels one image may have, for every frame, bench size and image file raytty makes or
/// reads: about 48 bytes each while rendering (float image, cached hits, 8-bit copy, encoder
/// buffers), so 64 Mpixel stays near 3 GiB.
pub const MAX_PIXELS: u64 = 64 * 1024 * 1024;

/// How an image's linear radiance becomes what a screen shows (PNG and the terminal; PFM stays
/// linear).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ToneMap {
    /// Clamped to [0, 1], no transfer function: the seed's look, kept by its scenes.
    #[default]
    Linear,
    /// Khronos PBR Neutral (the published reference curve), then the sRGB transfer: models.
    Neutral,
}

impl ToneMap {
    /// Every tone map, for the command line.
    pub const ALL: [ToneMap; 2] = [ToneMap::Linear, ToneMap::Neutral];

    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Linear => "none",
            ToneMap::Neutral => "neutral",
        }
    }

    /// The display value of linear radiance `c`, in [0, 1] per channel (NaN: 0).
    pub fn apply(self, c: Vec3) -> Vec3 {
        match self {
            ToneMap::Linear => c,
            ToneMap::Neutral => {
                let c = Vec3::from(
                    c.to_array()
                        .map(|x| if x.is_nan() { 0.0 } else { x.max(0.0) }),
                );
                pbr_neutral(c).to_array().map(srgb_encode).into()
            }
        }
    }

    /// `image` as a screen should show it: itself for [`ToneMap::Linear`] (not copied).
    pub fn image<'a>(self, image: &'a Image) -> std::borrow::Cow<'a, Image> {
        match self {
            ToneMap::Linear => std::borrow::Cow::Borrowed(image),
            _ => std::borrow::Cow::Owned(Image {
                width: image.width,
                height: image.height,
                pixels: image.pixels.iter().map(|&p| self.apply(p)).collect(),
            }),
        }
    }
}

/// Khronos PBR Neutral: colours below 0.76 pass unchanged (but for a small offset near black),
/// brighter ones are compressed towards 1 and desaturated. The constants are the published
/// curve's (start of compression 0.8 − 0.04, desaturation 0.15).
fn pbr_neutral(c: Vec3) -> Vec3 {
    const START: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = c.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c - Vec3::splat(offset);
    let peak = c.max_element();
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    let c = c * (new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.lerp(Vec3::splat(new_peak), g)
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
fn srgb_encode(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear RGB image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels, row-major from the top-left.
    pub pixels: Vec<Vec3>,
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            pixels: black(width as usize * height as usize),
        }
    }

    /// The pixel at (x, y).
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// The 8-bit sRGB-less form: each channel clamped to [0, 1] and scaled, no gamma (the seed's
    /// look). NaN maps to 0.
    pub fn to_rgb8(&self) -> Vec<[u8; 3]> {
        self.pixels.iter().map(|&p| to_rgb8(p)).collect()
    }

    /// Writes a PNG (8-bit RGB).
    pub fn write_png(&self, w: impl Write) -> io::Result<()> {
        let mut enc = png::Encoder::new(w, self.width, self.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(png_io_error)?;
        let data: Vec<u8> = self.to_rgb8().into_iter().flatten().collect();
        writer.write_image_data(&data).map_err(png_io_error)?;
        writer.finish().map_err(png_io_error)
    }

    /// Writes a PFM: linear little-endian f32 RGB, bottom row first, as the format requires
    /// ([`pfm_header`], then [`write_pfm_rows`] of every row).
    pub fn write_pfm(&self, mut w: impl Write) -> io::Result<()> {
        w.write_all(pfm_header(self.width, self.height).as_bytes())?;
        write_pfm_rows(w, &self.pixels, self.width as usize)
    }
}

/// The header of a `width`×`height` PFM: its pixel data starts after these bytes.
pub fn pfm_header(width: u32, height: u32) -> String {
    format!("PF\n{width} {height}\n-1.0\n")
}

/// Where the band of `rows` rows from row `y0` down starts in a `width`×`height` PFM's pixel
/// data (after the header): rows are stored bottom first, so the band's last row comes first.
pub fn pfm_band_offset(width: u32, height: u32, y0: u32, rows: u32) -> u64 {
    u64::from(height - y0 - rows) * u64::from(width) * 12
}

/// Writes `pixels` (whole rows of `width` pixels, top first) as PFM pixel data: the rows in
/// reverse, bottom first, as the format stores them. On a little-endian CPU a row of `Vec3` is
/// its PFM bytes, so the rows go out as they lie in memory, in as few vectored writes as the
/// writer takes: no copy, no per-pixel work.
pub fn write_pfm_rows(mut w: impl Write, pixels: &[Vec3], width: usize) -> io::Result<()> {
    if width == 0 {
        return Ok(());
    }
    #[cfg(target_endian = "little")]
    {
        let rows: Vec<&[u8]> = pixels.chunks_exact(width).rev().map(bytes).collect();
        let mut slices: Vec<io::IoSlice> = rows.iter().map(|r| io::IoSlice::new(r)).collect();
        write_all_vectored(&mut w, &mut slices)
    }
    #[cfg(not(target_endian = "little"))]
    {
        let mut buf = Vec::with_capacity(pixels.len() * 12);
        for row in pixels.chunks_exact(width).rev() {
            for c in row.iter().flat_map(|p| p.to_array()) {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        w.write_all(&buf)
    }
}

/// `n` black pixels from zeroed memory. `vec![Vec3::ZERO; n]` would write every pixel on the
/// calling thread (a 500×500 frame: 3 MB, 0.5-1 ms before the render starts, page faults
/// included); zeroed memory of that size comes from the OS untouched, and its pages are first
/// touched by the render's threads as they write their pixels, in parallel.
fn black(n: usize) -> Vec<Vec3> {
    let Ok(layout) = std::alloc::Layout::array::<Vec3>(n) else {
        panic!("an image of {n} pixels does not fit in memory");
    };
    if layout.size() == 0 {
        return Vec::new();
    }
    // SAFETY: the layout's size is not zero.
    let ptr = unsafe { std::alloc::alloc_zeroed(layout) }.cast::<Vec3>();
    if ptr.is_null() {
        std::alloc::handle_alloc_error(layout);
    }
    // SAFETY: `ptr` was allocated by the global allocator with `Vec<Vec3>`'s own layout for a
    // capacity of `n` (`Layout::array::<Vec3>(n)`), and all its bytes are zero, which is a valid
    // `Vec3` (three `0.0`), so all `n` elements are initialised.
    unsafe { Vec::from_raw_parts(ptr, n, n) }
}

/// The bytes of `pixels` as they lie in memory: three `f32` each, no padding.
#[cfg(target_endian = "little")]
fn bytes(pixels: &[Vec3]) -> &[u8] {
    const _: () = assert!(std::mem::size_of::<Vec3>() == 12 && std::mem::align_of::<Vec3>() == 4);
    // SAFETY: `Vec3` is `repr(C)` of three `f32` (12 bytes, checked above), so a slice of them is
    // `12·len` initialised bytes; `u8` has no alignment or validity requirement.
    unsafe {
        std::slice::from_raw_parts(pixels.as_ptr().cast::<u8>(), std::mem::size_of_val(pixels))
    }
}

/// `Write::write_all` for a list of slices (the standard one is not stable yet): writes them
/// all, in order, retrying interrupted and partial writes.
fn write_all_vectored(w: &mut impl Write, mut slices: &mut [io::IoSlice<'_>]) -> io::Result<()> {
    while !slices.is_empty() {
        match w.write_vectored(slices) {
            Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
            Ok(n) => io::IoSlice::advance_slices(&mut slices, n),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

impl Image {
    /// Reads a colour PFM as [`Image::write_pfm`] writes it: `PF`, width, height, a negative
    /// scale (little-endian), then exactly width × height pixels of three `f32`, bottom row
    /// first. Anything else (another format, a header out of range, too few or too many bytes)
    /// is an `InvalidData` error saying what is wrong; nothing is allocated before the size
    /// is checked against the bytes there are.
    pub fn read_pfm(bytes: &[u8]) -> io::Result<Image> {
        let invalid = |why: String| io::Error::new(io::ErrorKind::InvalidData, why);
        // Four header tokens, each ended by one whitespace byte: PF, width, height, scale.
        let mut pos = 0;
        let mut token = || -> Option<&[u8]> {
            while bytes.get(pos)?.is_ascii_whitespace() {
                pos += 1;
            }
            let start = pos;
            while !bytes.get(pos)?.is_ascii_whitespace() {
                pos += 1;
            }
            pos += 1;
            Some(&bytes[start..pos - 1])
        };
        let mut field = |what: &str| {
            token()
                .and_then(|t| std::str::from_utf8(t).ok())
                .map(str::to_string)
                .ok_or_else(|| invalid(format!("the header ends before its {what}")))
        };
        if field("PF")? != "PF" {
            return Err(invalid(
                "not a colour PFM (it does not start with PF)".into(),
            ));
        }
        let size = |t: String, what: &str| match t.parse::<u32>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(invalid(format!(
                "its {what} `{t}` is not a whole number from 1 up"
            ))),
        };
        let width = size(field("width")?, "width")?;
        let height = size(field("height")?, "height")?;
        let scale = field("scale")?;
        if !scale.parse::<f32>().is_ok_and(|s| s < 0.0) {
            return Err(invalid(format!(
                "its scale `{scale}` is not negative (only little-endian PFM is read)"
            )));
        }
        let data = &bytes[pos.min(bytes.len())..];
        // In u128, where 12·(2³² − 1)² cannot overflow.
        let expected = u128::from(width) * u128::from(height) * 12;
        if data.len() as u128 != expected {
            return Err(invalid(format!(
                "it holds {} bytes of pixels where {width}x{height} needs {expected}",
                data.len()
            )));
        }
        let mut img = Image::new(width, height);
        let w = width as usize;
        for (i, px) in data.chunks_exact(12).enumerate() {
            let f = |k: usize| f32::from_le_bytes([px[k], px[k + 1], px[k + 2], px[k + 3]]);
            let y = height as usize - 1 - i / w;
            img.pixels[y * w + i % w] = Vec3::new(f(0), f(4), f(8));
        }
        Ok(img)
    }
}

/// One linear pixel to 8 bits: clamp to [0, 1], scale by 255, round to nearest.
#[inline]
pub fn to_rgb8(p: Vec3) -> [u8; 3] {
    p.to_array().map(|c| {
        if c > 0.0 {
            (c.min(1.0) * 255.0 + 0.5) as u8
        } else {
            0
        }
    })
}

/// The encoder's error as an I/O error, keeping the writer's own error (and so its kind: a
/// closed pipe stays `BrokenPipe`, which the command line treats as success).
fn png_io_error(e: png::EncodingError) -> io::Error {
    match e {
        png::EncodingError::IoError(e) => e,
        e => io::Error::other(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer whose reader has gone away.
    struct ClosedPipe;

    impl Write for ClosedPipe {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::ErrorKind::BrokenPipe.into())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    fn pfm(img: &Image) -> Vec<u8> {
        let mut out = Vec::new();
        img.write_pfm(&mut out).unwrap();
        out
    }

    #[test]
    fn a_new_image_is_black_and_has_its_size() {
        for (w, h) in [(0, 0), (0, 7), (3, 2), (500, 500)] {
            let img = Image::new(w, h);
            assert_eq!(img.pixels.len(), w as usize * h as usize);
            assert!(
                img.pixels
                    .iter()
                    .all(|p| p.to_array().map(f32::to_bits) == [0; 3])
            );
        }
    }

    #[test]
    fn pfm_round_trips() {
        let mut img = Image::new(3, 2);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, 0.5 * i as f32, -1.25);
        }
        assert_eq!(Image::read_pfm(&pfm(&img)).unwrap(), img);
    }

    /// A writer that takes at most 5 bytes a call, and is interrupted every third call.
    struct Trickle(Vec<u8>, u32);

    impl Write for Trickle {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            self.1 += 1;
            if self.1.is_multiple_of(3) {
                return Err(io::ErrorKind::Interrupted.into());
            }
            let n = buf.len().min(5);
            self.0.extend_from_slice(&buf[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn pfm_survives_partial_and_interrupted_writes() {
        let mut img = Image::new(7, 5);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32, -(i as f32), 1.0 / (i as f32 + 1.0));
        }
        let mut out = Trickle(vec![], 0);
        img.write_pfm(&mut out).unwrap();
        assert_eq!(out.0, pfm(&img));
        assert_eq!(Image::read_pfm(&out.0).unwrap(), img);
    }

    #[test]
    fn a_corrupt_pfm_is_refused_with_a_reason() {
        let refused = |bytes: &[u8]| {
            let e = Image::read_pfm(bytes).unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidData);
            e.to_string()
        };
        assert!(refused(b"P6\n1 1\n255\n...").contains("PF"));
        assert!(refused(b"").contains("header ends"));
        assert!(refused(b"PF\n2 2").contains("header ends"));
        assert!(refused(b"PF\n2 2\n1.0\n").contains("little-endian"));
        assert!(refused(b"PF\n0 2\n-1.0\n").contains("width `0`"));
        assert!(refused(b"PF\n-2 2\n-1.0\n").contains("width `-2`"));
        assert!(refused(b"PF\n2 99999999999\n-1.0\n").contains("height"));
        // Truncated, or with bytes to spare.
        let good = pfm(&Image::new(3, 2));
        assert!(refused(&good[..good.len() - 1]).contains("needs 72"));
        assert!(refused(&[&good[..], b"x"].concat()).contains("needs 72"));
        assert!(refused(b"PF\n2 2\n-1.0\n").contains("holds 0 bytes"));
        // Sizes whose byte count overflows 32 or 64 bits are refused, not allocated.
        for header in [
            "PF\n4294967295 4294967295\n-1.0\n",
            "PF\n2147483648 2147483648\n-1.0\n",
            "PF\n65536 65536\n-1.0\n",
        ] {
            let mut bytes = header.as_bytes().to_vec();
            bytes.extend_from_slice(&[0; 24]);
            assert!(refused(&bytes).contains("bytes of pixels"), "{header}");
        }
    }

    #[test]
    fn a_closed_pipe_stays_a_broken_pipe() {
        let e = Image::new(4, 4).write_png(ClosedPipe).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
        let e = Image::new(4, 4).write_pfm(ClosedPipe).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
    }
}

#[cfg(test)]
mod tone_tests {
    use super::*;

    /// The neutral curve leaves mid tones alone (but for its 0.04 offset), keeps order, and
    /// brings any radiance, however bright, within [0, 1]; linear images are not copied.
    #[test]
    fn neutral_keeps_mid_tones_and_bounds_highlights() {
        let mid = pbr_neutral(Vec3::new(0.5, 0.3, 0.2));
        assert!((mid - Vec3::new(0.46, 0.26, 0.16)).length() < 1e-6);
        let mut last = -1.0;
        for i in 0..2000 {
            let x = i as f32 * 0.01;
            let y = ToneMap::Neutral.apply(Vec3::splat(x)).x;
            assert!(y >= last && (0.0..=1.0).contains(&y), "{x}: {y}");
            last = y;
        }
        assert!(ToneMap::Neutral.apply(Vec3::splat(f32::MAX)).max_element() <= 1.0);
        assert_eq!(ToneMap::Neutral.apply(Vec3::new(f32::NAN, 0.0, 0.0)).x, 0.0);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-5);
        let img = Image::new(2, 1);
        assert!(matches!(
            ToneMap::Linear.image(&img),
            std::borrow::Cow::Borrowed(_)
        ));
    }
}
