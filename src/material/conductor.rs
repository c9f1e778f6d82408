//! A metal: GGX microfacets reflecting with Schlick's Fresnel, its colour the reflectance at
//! normal incidence (F0). Two-sided, as the seed's surfaces are.

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample, Ggx, fresnel_schlick, reflect, same_hemisphere};

/// A GGX conductor (Walter et al. 2007's microfacet model, Smith's height-correlated masking,
/// sampled by visible normals).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Reflectance at normal incidence per channel, 0..=1 (a metal's colour).
    pub f0: Vec3,
    /// The microfacet distribution.
    pub ggx: Ggx,
}

/// Both directions moved to the upper side (the surface is two-sided: mirrored in its plane,
/// the same surface).
fn upper(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 {
        (
            wo * Vec3::new(1.0, 1.0, -1.0),
            wi * Vec3::new(1.0, 1.0, -1.0),
        )
    } else {
        (wo, wi)
    }
}

impl Conductor {
    /// A metal of colour `f0` and perceptual `roughness` (α = roughness²; 0 is a mirror).
    pub fn new(f0: Vec3, roughness: f32) -> Conductor {
        Conductor {
            f0,
            ggx: Ggx::from_roughness(roughness),
        }
    }

    /// Specular when smooth, else glossy; reflection only.
    pub fn flags(&self) -> BsdfFlags {
        if self.ggx.is_smooth() {
            BsdfFlags::REFLECTION | BsdfFlags::SPECULAR
        } else {
            BsdfFlags::REFLECTION | BsdfFlags::GLOSSY
        }
    }

    /// `D(wm)·F(wo·wm)·G(wo, wi)/(4|cos θo||cos θi|)`, wm the half vector.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.ggx.is_smooth() || !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (wo, wi) = upper(wo, wi);
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return Vec3::ZERO;
        }
        let wm = wm.normalize();
        let f = fresnel_schlick(self.f0, wo.dot(wm));
        f * (self.ggx.d(wm) * self.ggx.g(wo, wi) / (4.0 * wo.z * wi.z))
    }

    /// A direction reflected about a visible microfacet normal (or the mirror direction when
    /// smooth).
    pub fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.ggx.is_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                wi,
                value: fresnel_schlick(self.f0, wo.z.abs()) / wi.z.abs(),
                pdf: 1.0,
                flags: self.flags(),
            });
        }
        let flip = wo.z < 0.0;
        let (up, _) = upper(wo, wo);
        let wm = self.ggx.sample_visible(up, u);
        let wi = reflect(up, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let wi = if flip {
            wi * Vec3::new(1.0, 1.0, -1.0)
        } else {
            wi
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            value: self.f(wo, wi),
            pdf,
            flags: self.flags(),
        })
    }

    /// The density of visible normals, mapped through the reflection: `D_wo(wm)/(4|wo·wm|)`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.ggx.is_smooth() || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let (wo, wi) = upper(wo, wi);
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        self.ggx.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
    }
}
