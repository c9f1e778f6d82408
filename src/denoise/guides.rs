//! What a path-traced frame hands the denoiser, pixel by pixel: the unfiltered part of the
//! colour, the albedo, the indirect irradiance's mean and moments, and the guide surface.

use glam::Vec3;

use crate::shading::{GuideHit, SplitSample};

/// One pixel's samples, summed (see [`GuidePixel::add`]) or averaged ([`Guides`] holds means).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GuidePixel {
    /// The part of the colour the denoiser leaves alone (direct light, shadows, mirror parts).
    pub rest: Vec3,
    /// The weight of the indirect irradiance in the colour (reflectance, mirrors included).
    pub albedo: Vec3,
    /// The indirect light as it appears in the colour: the mean of `albedo·irradiance`, so
    /// that `rest + indirect` is the raw pixel.
    pub indirect: Vec3,
    /// The first two moments of the demodulated irradiance's luminance: its mean and the mean
    /// of its square, for the variance.
    pub moments: [f32; 2],
    /// The first sample's guide surface (`None`: it saw the background).
    pub guide: Option<GuideHit>,
}

impl GuidePixel {
    /// Adds one sample to the sums (the guide is the first sample's).
    #[inline]
    pub fn add(&mut self, s: &SplitSample) {
        self.rest += s.rest;
        self.albedo += s.albedo;
        self.indirect += s.albedo * s.irradiance;
        let l = luminance(s.irradiance);
        self.moments[0] += l;
        self.moments[1] += l * l;
        if self.guide.is_none() {
            self.guide = s.guide;
        }
    }

    /// Divides the sums by the number of samples added.
    #[inline]
    pub fn scale(&mut self, k: f32) {
        self.rest *= k;
        self.albedo *= k;
        self.indirect *= k;
        self.moments = self.moments.map(|m| m * k);
    }
}

/// A frame's guide buffers: one [`GuidePixel`] per pixel (means over its samples), row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Guides {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel behind the means.
    pub samples: u32,
    /// The pixels.
    pub pixels: Vec<GuidePixel>,
}

impl Guides {
    /// The raw image these guides add up to: `rest + indirect` per pixel.
    pub fn raw(&self) -> Vec<Vec3> {
        self.pixels.iter().map(|p| p.rest + p.indirect).collect()
    }

    /// Folds `other` (a later frame of the same view: same size, same primary hits) into these
    /// guides, each side weighted by its samples, so the means cover both frames.
    /// `max_history` caps the weight the samples already here keep (`u32::MAX`: no cap); a cap
    /// is how a light move reuses the old indirect light for a bounded while.
    pub fn accumulate(&mut self, other: &Guides, max_history: u32) {
        debug_assert_eq!((self.width, self.height), (other.width, other.height));
        let old = self.samples.min(max_history);
        let total = old + other.samples;
        if total == 0 {
            return;
        }
        let (a, b) = (
            old as f32 / total as f32,
            other.samples as f32 / total as f32,
        );
        for (p, q) in self.pixels.iter_mut().zip(&other.pixels) {
            // The unfiltered part is exact per pixel (one shadow ray per light), so the new
            // frame's replaces the old one's whenever it may differ (a light move).
            p.rest = if max_history == u32::MAX {
                p.rest * a + q.rest * b
            } else {
                q.rest
            };
            p.albedo = p.albedo * a + q.albedo * b;
            p.indirect = p.indirect * a + q.indirect * b;
            p.moments = [
                p.moments[0] * a + q.moments[0] * b,
                p.moments[1] * a + q.moments[1] * b,
            ];
            if p.guide.is_none() {
                p.guide = q.guide;
            }
        }
        self.samples = total;
    }
}

/// Luminance (Rec. 709 weights) of a linear colour.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
