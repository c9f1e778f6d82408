//! Ideal diffuse reflection, the same on both sides of the surface.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample, cosine_hemisphere, same_hemisphere};

/// A Lambertian reflector: `f = R/π` for directions on the same side, whichever side that is
/// (a two-sided wall, as the seed's scenes have).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian {
    /// The reflectance R per channel, 0..=1.
    pub reflectance: Vec3,
}

impl Lambertian {
    /// The BSDF's value.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if same_hemisphere(wo, wi) {
            self.reflectance * FRAC_1_PI
        } else {
            Vec3::ZERO
        }
    }

    /// A cosine-weighted direction on `wo`'s side.
    pub fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            value: self.f(wo, wi),
            pdf,
            flags: BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE,
        })
    }

    /// `|cos θi|/π` on `wo`'s side.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if same_hemisphere(wo, wi) {
            wi.z.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }
}
