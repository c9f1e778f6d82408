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
}
