//! The perfect mirror: all light leaves in the reflected direction.

use glam::Vec3;

use super::{BsdfFlags, BsdfSample};

/// A perfect specular reflector of a given reflectance per channel (the seed's mirrors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// The fraction reflected per channel, 0..=1.
    pub reflectance: Vec3,
}

impl Mirror {
    /// The one direction: `wo` reflected about the normal.
    pub fn sample_f(&self, wo: Vec3) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        Some(BsdfSample {
            wi,
            value: self.reflectance / wi.z.abs(),
            pdf: 1.0,
            flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
        })
    }
}
