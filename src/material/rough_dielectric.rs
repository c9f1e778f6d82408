//! Rough glass: GGX microfacets that reflect and refract (Walter et al. 2007), sampled by
//! visible normals, Smith's height-correlated masking.

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample, Dielectric, Ggx, fresnel_dielectric, reflect, refract};

/// A rough interface between air (z > 0) and a medium of index `eta` (z < 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// The index of refraction inside.
    pub eta: f32,
    /// The microfacet distribution.
    pub ggx: Ggx,
}

/// The pair's microfacet normal (upper hemisphere) and relative index η' (1 for reflection),
/// or `None` where no microfacet joins them facing both.
fn half_vector(wo: Vec3, wi: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (co, ci) = (wo.z, wi.z);
    if co == 0.0 || ci == 0.0 {
        return None;
    }
    let etap = if co * ci > 0.0 {
        1.0
    } else if co > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    if wm.length_squared() == 0.0 {
        return None;
    }
    let wm = wm.normalize();
    let wm = if wm.z < 0.0 { -wm } else { wm };
    // A microfacet that faces away from either direction cannot join them.
    if wm.dot(wi) * ci <= 0.0 || wm.dot(wo) * co <= 0.0 {
        return None;
    }
    Some((wm, etap))
}

impl RoughDielectric {
    /// Glass of index `eta` and perceptual `roughness` (α = roughness²).
    pub fn new(eta: f32, roughness: f32) -> RoughDielectric {
        RoughDielectric {
            eta,
            ggx: Ggx::from_roughness(roughness),
        }
    }

    /// A smooth surface or an index of 1 (no interface) scatters as smooth glass does.
    fn smooth(&self) -> Option<Dielectric> {
        (self.eta == 1.0 || self.ggx.is_smooth()).then_some(Dielectric { eta: self.eta })
    }

    /// Glossy reflection and transmission (specular when smooth).
    pub fn flags(&self) -> BsdfFlags {
        match self.smooth() {
            Some(d) => d.flags(),
            None => BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::GLOSSY,
        }
    }

    /// Reflection `D·G·F/(4|cos θo cos θi|)`; transmission
    /// `D·G·(1 − F)·|wi·wm||wo·wm| / (|cos θo cos θi|(wi·wm + wo·wm/η')²) / η'²`.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.smooth().is_some() {
            return Vec3::ZERO;
        }
        let Some((wm, etap)) = half_vector(wo, wi, self.eta) else {
            return Vec3::ZERO;
        };
        let f = fresnel_dielectric(wo.dot(wm), self.eta);
        let dg = self.ggx.d(wm) * self.ggx.g(wo, wi);
        let cos = (wo.z * wi.z).abs();
        let v = if etap == 1.0 {
            dg * f / (4.0 * cos)
        } else {
            let denom = wi.dot(wm) + wo.dot(wm) / etap;
            dg * (1.0 - f) * (wi.dot(wm) * wo.dot(wm)).abs() / (cos * denom * denom * etap * etap)
        };
        Vec3::splat(v)
    }

    /// A visible microfacet normal, then reflection about it with probability F, else
    /// refraction through it.
    pub fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if let Some(d) = self.smooth() {
            return d.sample_f(wo, uc);
        }
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.ggx.sample_visible(wo, u);
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let (wi, flags) = if uc < r {
            let wi = reflect(wo, wm);
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            (wi, BsdfFlags::REFLECTION | BsdfFlags::GLOSSY)
        } else {
            let (wi, _) = refract(wo, wm, self.eta)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            (wi, BsdfFlags::TRANSMISSION | BsdfFlags::GLOSSY)
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            value: self.f(wo, wi),
            pdf,
            flags,
        })
    }

    /// The visible normals' density, through the reflection's or the refraction's Jacobian,
    /// times the probability of that lobe (F or 1 − F).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.smooth().is_some() {
            return 0.0;
        }
        let Some((wm, etap)) = half_vector(wo, wi, self.eta) else {
            return 0.0;
        };
        let f = fresnel_dielectric(wo.dot(wm), self.eta);
        let visible = self.ggx.d_visible(wo, wm);
        if etap == 1.0 {
            visible / (4.0 * wo.dot(wm).abs()) * f
        } else {
            let denom = wi.dot(wm) + wo.dot(wm) / etap;
            visible * wi.dot(wm).abs() / (denom * denom) * (1.0 - f)
        }
    }
}
