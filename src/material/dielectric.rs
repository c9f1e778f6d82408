//! Smooth glass: Fresnel reflection and Snell refraction at one interface, total internal
//! reflection past the critical angle.

use glam::Vec3;

use super::{BsdfFlags, BsdfSample, fresnel_dielectric, refract};

/// A smooth interface between air (the side the normal points to, z > 0) and a medium of
/// index `eta` (z < 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// The index of refraction inside (1.5 for glass; 1 is no interface at all).
    pub eta: f32,
}

impl Dielectric {
    /// Reflection and transmission, both specular (only transmission with an IOR of 1).
    pub fn flags(&self) -> BsdfFlags {
        if self.eta == 1.0 {
            BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR
        } else {
            BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR
        }
    }

    /// Reflects with the Fresnel probability R, else refracts (`uc` chooses). The reflected
    /// sample weighs R, the transmitted 1 − R scaled by 1/η'² (radiance through an interface
    /// of relative index η'), each divided by its probability: an estimator's weight is
    /// exactly 1 and 1/η'², with no noise from the choice.
    pub fn sample_f(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = fresnel_dielectric(wo.z, self.eta);
        let t = 1.0 - r;
        if uc < r {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                wi,
                value: Vec3::splat(r / wi.z.abs()),
                pdf: r,
                flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
            });
        }
        let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
        if wi.z == 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            value: Vec3::splat(t / (wi.z.abs() * etap * etap)),
            pdf: t,
            flags: BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
        })
    }
}
