//! Linear float images and their 8-bit, PNG and PFM forms.

use std::io::{self, Write};

use glam::Vec3;

/// Most pixels one image may have, for every frame, bench size and image file raytty makes or
/// reads: about 48 bytes each while rendering (float image, cached hits, 8-bit copy, encoder
/// buffers), so 64 Mpixel stays near 3 GiB.
pub const MAX_PIXELS: u64 = 64 * 1024 * 1024;

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
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
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

    /// Writes a PFM: linear little-endian f32 RGB, bottom row first, as the format requires.
    pub fn write_pfm(&self, mut w: impl Write) -> io::Result<()> {
        write!(w, "PF\n{} {}\n-1.0\n", self.width, self.height)?;
        let mut buf = Vec::with_capacity(self.pixels.len() * 12);
        for y in (0..self.height).rev() {
            for x in 0..self.width {
                for c in self.get(x, y).to_array() {
                    buf.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        w.write_all(&buf)
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
mod png_tests {
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

    #[test]
    fn a_closed_pipe_stays_a_broken_pipe() {
        let e = Image::new(4, 4).write_png(ClosedPipe).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
        let e = Image::new(4, 4).write_pfm(ClosedPipe).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
    }
}
