//! What a path-traced frame hands the denoiser, pixel by pixel: the unfiltered part of the
//! colour, the albedo, the indirect irradiance's mean and moments, and the guide surface.

use glam::Vec3;

use super::SAME_NORMAL_COS;
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
    /// Whether the pixel's samples saw more than one surface (an edge or a silhouette runs
    /// through it; see [`same_surface`]). The spread of such a pixel's samples is mostly the
    /// two surfaces' difference, which its jittered samples average well, not noise. Filtered
    /// like the rest, it was pulled towards one side and the difference handed to its
    /// neighbours, a bias along every edge that more samples did not take away; so the
    /// denoiser keeps it out of the restore and moves it back towards its raw value as samples
    /// grow.
    pub mixed: bool,
    /// Whether a sample has been added (the guide is the first one's).
    pub seen: bool,
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
        if !self.seen {
            self.guide = s.guide;
            self.seen = true;
        } else if !same_surface(self.guide, s.guide) {
            self.mixed = true;
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
            if old == 0 {
                (p.guide, p.mixed, p.seen) = (q.guide, q.mixed, q.seen);
            } else {
                p.mixed |= q.mixed || !same_surface(p.guide, q.guide);
            }
        }
        self.samples = total;
    }
}

/// Whether two samples' guides are one surface: both the background, or the same object seen
/// after as many mirrors, with normals within the restore's [`SAME_NORMAL_COS`] (about 17°).
fn same_surface(a: Option<GuideHit>, b: Option<GuideHit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            (a.object, a.reflections) == (b.object, b.reflections)
                && a.normal.dot(b.normal) >= SAME_NORMAL_COS
        }
        _ => false,
    }
}

/// Luminance (Rec. 709 weights) of a linear colour.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    fn guides(v: f32, samples: u32) -> Guides {
        let p = GuidePixel {
            rest: Vec3::splat(v),
            albedo: Vec3::ONE,
            indirect: Vec3::splat(v),
            moments: [v, v * v],
            ..GuidePixel::default()
        };
        Guides {
            width: 1,
            height: 1,
            samples,
            pixels: vec![p],
        }
    }

    #[test]
    fn accumulation_weighs_by_samples_and_a_cap_bounds_the_history() {
        let mut g = guides(1.0, 3);
        g.accumulate(&guides(5.0, 1), u32::MAX);
        assert_eq!(g.samples, 4);
        assert_eq!(g.pixels[0].indirect, Vec3::splat(2.0));
        assert_eq!(g.raw(), [Vec3::splat(4.0)]);
        // Capped at 1: old and new weigh the same; the exact part is the new frame's.
        let mut g = guides(1.0, 100);
        g.accumulate(&guides(3.0, 1), 1);
        assert_eq!(g.samples, 2);
        assert_eq!(g.pixels[0].indirect, Vec3::splat(2.0));
        assert_eq!(g.pixels[0].rest, Vec3::splat(3.0));
    }

    fn hit(object: u32, normal: Vec3) -> Option<GuideHit> {
        Some(GuideHit {
            position: Vec3::ZERO,
            normal,
            object,
            reflections: 0,
        })
    }

    fn pixel_of(guides: &[Option<GuideHit>]) -> GuidePixel {
        let mut p = GuidePixel::default();
        for &guide in guides {
            p.add(&SplitSample {
                guide,
                ..SplitSample::default()
            });
        }
        p
    }

    #[test]
    fn a_pixel_whose_samples_see_two_surfaces_is_mixed() {
        let (up, side) = (Vec3::Y, Vec3::X);
        // 10° apart: one curved surface.
        let near = Vec3::new(10f32.to_radians().sin(), 10f32.to_radians().cos(), 0.0);
        assert!(!pixel_of(&[hit(1, up), hit(1, up), hit(1, near)]).mixed);
        assert!(!pixel_of(&[None, None]).mixed);
        assert!(pixel_of(&[hit(1, up), hit(2, up)]).mixed, "two objects");
        assert!(pixel_of(&[hit(1, up), hit(1, side)]).mixed, "a crease");
        assert!(pixel_of(&[None, hit(1, up)]).mixed, "a silhouette");
        assert!(pixel_of(&[hit(1, up), None]).mixed, "a silhouette");
        let mut reflected = hit(1, up);
        reflected.as_mut().unwrap().reflections = 1;
        assert!(pixel_of(&[hit(1, up), reflected]).mixed, "a mirror's edge");
        // The guide stays the first sample's, the background included.
        assert_eq!(pixel_of(&[None, hit(1, up)]).guide, None);
        // Frames folded together: a pixel is mixed if either frame's is, or their surfaces
        // differ.
        let frame = |p: GuidePixel| Guides {
            width: 1,
            height: 1,
            samples: 1,
            pixels: vec![p],
        };
        let mut g = frame(pixel_of(&[hit(1, up)]));
        g.accumulate(&frame(pixel_of(&[hit(1, up)])), u32::MAX);
        assert!(!g.pixels[0].mixed);
        g.accumulate(&frame(pixel_of(&[hit(2, up)])), u32::MAX);
        assert!(g.pixels[0].mixed);
        let mut g = frame(GuidePixel::default());
        g.samples = 0;
        g.accumulate(&frame(pixel_of(&[hit(1, up), hit(2, up)])), u32::MAX);
        assert!(
            g.pixels[0].mixed,
            "an empty history takes the new frame's pixel"
        );
    }
}
