//! How far an image is from the reference: RMSE of linear values and PSNR of the 8-bit image.

use crate::image::{Image, to_rgb8};

/// Root-mean-square difference of the linear values, over every pixel and channel. Both images
/// must have the same size.
pub fn rmse(a: &Image, b: &Image) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    let n = a.pixels.len() * 3;
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            let d = (*p - *q).as_dvec3();
            d.dot(d)
        })
        .sum();
    (sum / n as f64).sqrt()
}

/// RMSE of `block`×`block` pixel means (blocks at the right and bottom edges may be smaller):
/// noise averages away in a block's mean and bias does not, so this is the error a filter's
/// bias shows in. Both images must have the same size; `block` is at least 1.
pub fn block_rmse(a: &Image, b: &Image, block: u32) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    assert!(block >= 1, "a block has at least one pixel");
    let (w, h) = (a.width, a.height);
    let (mut sum, mut n) = (0.0f64, 0usize);
    for by in (0..h).step_by(block as usize) {
        for bx in (0..w).step_by(block as usize) {
            let mut d = glam::DVec3::ZERO;
            let mut count = 0u32;
            for y in by..(by + block).min(h) {
                for x in bx..(bx + block).min(w) {
                    let i = (y * w + x) as usize;
                    d += (a.pixels[i] - b.pixels[i]).as_dvec3();
                    count += 1;
                }
            }
            let d = d / f64::from(count);
            sum += d.dot(d);
            n += 3;
        }
    }
    if n == 0 { 0.0 } else { (sum / n as f64).sqrt() }
}

/// The image as a display shows it: every value clamped to `0..=1`. Errors of scenes whose
/// lights are in view are measured on it: an emitter's own pixels (values ~20) and their
/// anti-aliased edges would otherwise outweigh the rest of the frame.
pub fn shown(img: &Image) -> Image {
    Image {
        width: img.width,
        height: img.height,
        pixels: img
            .pixels
            .iter()
            .map(|p| p.clamp(glam::Vec3::ZERO, glam::Vec3::ONE))
            .collect(),
    }
}

/// Peak signal-to-noise ratio of the 8-bit images (clamped, no gamma, as displayed), in dB:
/// `10·log10(255²/MSE)`. Infinite when the 8-bit images are equal.
pub fn psnr8(a: &Image, b: &Image) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    let n = a.pixels.len() * 3;
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            let (p, q) = (to_rgb8(*p), to_rgb8(*q));
            (0..3)
                .map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2))
                .sum::<f64>()
        })
        .sum();
    if sum == 0.0 || n == 0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64 * 255.0 / (sum / n as f64)).log10()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn rmse_and_psnr_of_known_differences() {
        let a = Image::new(2, 2);
        let mut b = Image::new(2, 2);
        assert_eq!(rmse(&a, &b), 0.0);
        assert_eq!(psnr8(&a, &b), f64::INFINITY);
        b.pixels[0] = Vec3::new(0.4, 0.0, 0.0);
        // One channel of twelve differs by 0.4: sqrt(0.16 / 12).
        assert!((rmse(&a, &b) - (0.16f64 / 12.0).sqrt()).abs() < 1e-7);
        // 0.4·255 rounds to 102: MSE = 102² / 12.
        let want = 10.0 * (255.0f64.powi(2) / (102.0f64.powi(2) / 12.0)).log10();
        assert!((psnr8(&a, &b) - want).abs() < 1e-9);
        // Values above 1 clamp in 8 bits but not in linear RMSE.
        let mut c = Image::new(2, 2);
        c.pixels[0] = Vec3::new(5.0, 0.0, 0.0);
        let mut d = Image::new(2, 2);
        d.pixels[0] = Vec3::new(2.0, 0.0, 0.0);
        assert!(rmse(&c, &d) > 0.8);
        assert_eq!(psnr8(&c, &d), f64::INFINITY);
    }

    #[test]
    fn block_rmse_averages_noise_away_but_not_an_offset() {
        // A checkerboard of ±0.1 around b: every pixel is off by 0.1, every 2×2 block's mean
        // is exact.
        let b = Image::new(4, 3);
        let mut a = Image::new(4, 3);
        for (i, p) in a.pixels.iter_mut().enumerate() {
            let (x, y) = (i % 4, i / 4);
            *p = Vec3::splat(if (x + y) % 2 == 0 { 0.1 } else { -0.1 });
        }
        assert!((rmse(&a, &b) - 0.1).abs() < 1e-7);
        assert_eq!(block_rmse(&a, &b, 1), rmse(&a, &b));
        // The last row's blocks are 2×1: +0.1 and −0.1 still cancel.
        assert!(block_rmse(&a, &b, 2) < 1e-9);
        // An offset stays in every block's mean.
        for p in &mut a.pixels {
            *p += Vec3::new(0.0, 0.3, 0.0);
        }
        let want = (0.09f64 / 3.0).sqrt();
        assert!((block_rmse(&a, &b, 2) - want).abs() < 1e-7);
        assert!((block_rmse(&a, &b, 10) - want).abs() < 1e-7);
    }
}
