//! Base-colour textures: a decoded image (PNG through the `png` crate, which raytty already
//! writes frames with; JPEG through `zune-jpeg`, a decoder of its own with no other
//! dependency than its core crate) and how it is sampled (glTF's sampler: a wrap mode per
//! axis, nearest or bilinear filtering).
//!
//! Texels are kept as their 8-bit sRGB codes, 3 bytes each (a 4096² texture is 48 MiB), and
//! decoded to linear through a table when sampled; bilinear filtering weighs the four linear
//! values. There are no mipmaps: a ray carries no footprint to choose a level by, so a
//! texture seen from afar aliases at one sample per pixel and is averaged by more samples
//! (`--samples`). Sixteen-bit images are read at 8 bits a channel; alpha is not used.

use std::sync::LazyLock;

use glam::{Vec2, Vec3};

/// Widest and tallest texture read (each side): 8192² texels are 192 MiB.
pub const MAX_TEXTURE_SIDE: u32 = 8192;

/// How a texture coordinate outside [0, 1] is brought back in, per axis (glTF's wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image repeats (glTF's default, `REPEAT`).
    #[default]
    Repeat,
    /// The edge texel extends (`CLAMP_TO_EDGE`).
    Clamp,
    /// The image repeats mirrored every other time (`MIRRORED_REPEAT`).
    Mirror,
}

/// How texels are combined at a texture coordinate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The four nearest texels weighed by distance, in linear values (glTF's `LINEAR`, and
    /// what raytty does when the file does not say).
    #[default]
    Bilinear,
    /// The nearest texel (glTF's `NEAREST` magnification filter).
    Nearest,
}

/// A decoded texture and its sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    /// sRGB codes, rows from the top of the image (texture coordinate v = 0).
    texels: Vec<[u8; 3]>,
    /// The wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// The filter.
    pub filter: Filter,
}

/// The linear value of each 8-bit sRGB code.
static SRGB_TO_LINEAR: LazyLock<[f32; 256]> = LazyLock::new(|| {
    std::array::from_fn(|i| crate::scene::model::srgb_to_linear(i as f32 / 255.0))
});

impl Texture {
    /// A texture of `width` × `height` sRGB texels, rows from the top; `None` if the sizes do
    /// not match or a side is 0 or above [`MAX_TEXTURE_SIDE`].
    pub fn from_srgb(width: u32, height: u32, texels: Vec<[u8; 3]>) -> Option<Texture> {
        let sides = 1..=MAX_TEXTURE_SIDE;
        (sides.contains(&width)
            && sides.contains(&height)
            && texels.len() == width as usize * height as usize)
            .then_some(Texture {
                width,
                height,
                texels,
                wrap: [Wrap::Repeat; 2],
                filter: Filter::Bilinear,
            })
    }

    /// Decodes a PNG or JPEG image (told apart by their first bytes); the error says why not.
    pub fn decode(bytes: &[u8]) -> Result<Texture, String> {
        let (width, height, rgb) = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            decode_png(bytes)?
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            decode_jpeg(bytes)?
        } else {
            return Err("not a PNG or JPEG image (raytty reads those two)".into());
        };
        let texels = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Texture::from_srgb(width, height, texels).ok_or_else(|| {
            format!("a {width}x{height} image: each side must be 1 to {MAX_TEXTURE_SIDE} pixels")
        })
    }

    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The linear colour at texture coordinate `uv` (u to the right, v down from the top
    /// edge, as glTF's), wrapped and filtered as the texture says.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as i64, self.height as i64);
        // Texel centres are at half-integers; `as` saturates (and takes NaN to 0), so any
        // coordinate gives an index the wrap brings into range.
        let x = uv.x * self.width as f32;
        let y = uv.y * self.height as f32;
        match self.filter {
            Filter::Nearest => {
                let i = wrap(self.wrap[0], x.floor() as i64, w);
                let j = wrap(self.wrap[1], y.floor() as i64, h);
                self.texel(i, j)
            }
            Filter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let (fx, fy) = (fx.clamp(0.0, 1.0), fy.clamp(0.0, 1.0));
                let (x0, y0) = (x0 as i64, y0 as i64);
                let (i0, i1) = (
                    wrap(self.wrap[0], x0, w),
                    wrap(self.wrap[0], x0.saturating_add(1), w),
                );
                let (j0, j1) = (
                    wrap(self.wrap[1], y0, h),
                    wrap(self.wrap[1], y0.saturating_add(1), h),
                );
                let top = self.texel(i0, j0) * (1.0 - fx) + self.texel(i1, j0) * fx;
                let bottom = self.texel(i0, j1) * (1.0 - fx) + self.texel(i1, j1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }

    /// Texel (`i`, `j`), in range, as linear RGB.
    #[inline]
    fn texel(&self, i: usize, j: usize) -> Vec3 {
        let t = self.texels[j * self.width as usize + i];
        let lin = &*SRGB_TO_LINEAR;
        Vec3::new(lin[t[0] as usize], lin[t[1] as usize], lin[t[2] as usize])
    }
}

/// Index `i` of an axis of `n` texels brought into `0..n` by `mode`.
fn wrap(mode: Wrap, i: i64, n: i64) -> usize {
    (match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let k = i.rem_euclid(2 * n);
            if k >= n { 2 * n - 1 - k } else { k }
        }
    }) as usize
}

/// A PNG as 8-bit RGB: palettes expanded, 16 bits cut to 8, grey made RGB, alpha dropped.
fn decode_png(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    let side = MAX_TEXTURE_SIDE as usize;
    let limits = png::Limits {
        // The largest image's 16-bit RGBA rows.
        bytes: side * side * 8,
    };
    let mut d = png::Decoder::new_with_limits(std::io::Cursor::new(bytes), limits);
    d.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let bad = |e: png::DecodingError| format!("not a readable PNG: {e}");
    let mut reader = d.read_info().map_err(bad)?;
    let (w, h) = (reader.info().width, reader.info().height);
    if w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!(
            "a {w}x{h} PNG: each side must be at most {MAX_TEXTURE_SIDE} pixels"
        ));
    }
    let size = reader
        .output_buffer_size()
        .ok_or("not a readable PNG: its size overflows")?;
    let mut buf = vec![0; size];
    let info = reader.next_frame(&mut buf).map_err(bad)?;
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err("not a readable PNG: a palette left".into()),
    };
    let (w, h) = (info.width as usize, info.height as usize);
    let mut rgb = Vec::with_capacity(w * h * 3);
    for row in buf.chunks(info.line_size).take(h) {
        for px in row.chunks_exact(channels).take(w) {
            match channels {
                1 | 2 => rgb.extend_from_slice(&[px[0]; 3]),
                _ => rgb.extend_from_slice(&px[..3]),
            }
        }
    }
    if rgb.len() != w * h * 3 {
        return Err("not a readable PNG: its data is short".into());
    }
    Ok((info.width, info.height, rgb))
}

/// A JPEG as 8-bit RGB.
fn decode_jpeg(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    use zune_jpeg::zune_core::bytestream::ZCursor;
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let side = MAX_TEXTURE_SIDE as usize;
    let options = DecoderOptions::default()
        .jpeg_set_out_colorspace(ColorSpace::RGB)
        .set_max_width(side)
        .set_max_height(side);
    let mut d = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    let rgb = d
        .decode()
        .map_err(|e| format!("not a readable JPEG: {e:?}"))?;
    let info = d.info().ok_or("not a readable JPEG: no header")?;
    let (w, h) = (info.width as u32, info.height as u32);
    if rgb.len() != w as usize * h as usize * 3 {
        return Err("not a readable JPEG: its data is short".into());
    }
    Ok((w, h, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2×2: red, green / blue, white.
    fn checker() -> Texture {
        Texture::from_srgb(
            2,
            2,
            vec![[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]],
        )
        .unwrap()
    }

    #[test]
    fn texel_centres_give_their_texels_and_wraps_bring_coordinates_back() {
        let mut t = checker();
        for filter in [Filter::Bilinear, Filter::Nearest] {
            t.filter = filter;
            t.wrap = [Wrap::Repeat; 2];
            assert_eq!(t.sample(Vec2::new(0.25, 0.25)), Vec3::X);
            assert_eq!(t.sample(Vec2::new(0.75, 0.25)), Vec3::Y);
            assert_eq!(t.sample(Vec2::new(0.25, 0.75)), Vec3::Z);
            assert_eq!(t.sample(Vec2::new(1.75, -0.25)), Vec3::ONE);
            t.wrap = [Wrap::Clamp; 2];
            assert_eq!(t.sample(Vec2::new(7.0, -3.0)), Vec3::Y);
            t.wrap = [Wrap::Mirror; 2];
            assert_eq!(t.sample(Vec2::new(1.25, 0.25)), Vec3::Y);
            assert_eq!(t.sample(Vec2::new(2.25, 0.25)), Vec3::X);
        }
        for uv in [Vec2::NAN, Vec2::splat(f32::INFINITY), Vec2::splat(-1e30)] {
            assert!(t.sample(uv).is_finite());
        }
    }

    #[test]
    fn bilinear_weighs_linear_values_and_nearest_does_not_blend() {
        let mut t = checker();
        t.wrap = [Wrap::Clamp; 2];
        // Halfway between red and green (linear 1 and 0): 0.5 each.
        assert_eq!(t.sample(Vec2::new(0.5, 0.25)), Vec3::new(0.5, 0.5, 0.0));
        t.filter = Filter::Nearest;
        assert_eq!(t.sample(Vec2::new(0.49, 0.25)), Vec3::X);
        // A code of 128 is sRGB: about 0.216 linear.
        let grey = Texture::from_srgb(1, 1, vec![[128; 3]]).unwrap();
        assert!((grey.sample(Vec2::ZERO).x - 0.2158).abs() < 1e-3);
    }

    #[test]
    fn png_is_decoded_and_garbage_is_refused() {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, 2, 1);
            enc.set_color(png::ColorType::Rgba);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[255, 0, 0, 255, 0, 0, 255, 128])
                .unwrap();
        }
        let t = Texture::decode(&bytes).unwrap();
        assert_eq!(t.size(), (2, 1));
        assert_eq!(t.texels, vec![[255, 0, 0], [0, 0, 255]]);
        assert!(
            Texture::decode(b"GIF89a")
                .unwrap_err()
                .contains("PNG or JPEG")
        );
        assert!(Texture::decode(&bytes[..30]).unwrap_err().contains("PNG"));
        assert!(
            Texture::decode(&[0xff, 0xd8, 0xff, 0, 1])
                .unwrap_err()
                .contains("JPEG")
        );
    }
}
