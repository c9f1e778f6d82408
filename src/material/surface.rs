//! A scene's [`Material`] as one BSDF: its parts (mirror, metal, glass, diffuse base) as lobes
//! weighted by the fractions the material gives, sampled by picking a lobe by its weight.

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, Conductor, Lambertian, Mirror, RoughDielectric};
use crate::scene::Material;

/// Most lobes a material has: mirror, metal, glass and the diffuse base.
const MAX_LOBES: usize = 4;

/// A material at a hit, as a weighted sum of BSDFs: `f = Σ wᵢ fᵢ`, sampled by picking lobe
/// `i` with probability `wᵢ` (the weights sum to 1), so that `pdf = Σ wᵢ pdfᵢ` over the lobes
/// that are not specular.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceBsdf {
    lobes: [(f32, Bsdf); MAX_LOBES],
    count: usize,
    /// Transmitted light is tinted by this (the base colour).
    tint: Vec3,
}

impl SurfaceBsdf {
    /// The BSDF of `material` where its base colour is `colour` (see
    /// [`crate::Scene::base_colour`]): each part takes its fraction of what the parts before
    /// it leave, in the order mirror, metal, glass, diffuse. Parts of weight zero are left
    /// out.
    pub fn new(material: &Material, colour: Vec3) -> SurfaceBsdf {
        let mut lobes = [(
            0.0,
            Bsdf::Lambertian(Lambertian {
                reflectance: Vec3::ZERO,
            }),
        ); MAX_LOBES];
        let mut count = 0;
        let mut left = 1.0f32;
        let mut push = |fraction: f32, bsdf: Bsdf| {
            let w = left * fraction;
            left -= w;
            if w > 0.0 {
                lobes[count] = (w, bsdf);
                count += 1;
            }
        };
        push(
            material.mirror,
            Bsdf::Mirror(Mirror {
                reflectance: Vec3::ONE,
            }),
        );
        push(
            material.metal,
            Bsdf::Conductor(Conductor::new(colour, material.roughness)),
        );
        push(
            material.transmission,
            Bsdf::RoughDielectric(RoughDielectric::new(material.ior, material.roughness)),
        );
        push(
            1.0,
            Bsdf::Lambertian(Lambertian {
                reflectance: colour,
            }),
        );
        SurfaceBsdf {
            lobes,
            count,
            tint: colour,
        }
    }

    fn lobes(&self) -> &[(f32, Bsdf)] {
        &self.lobes[..self.count]
    }

    /// Every kind of scattering some lobe does.
    pub fn flags(&self) -> BsdfFlags {
        self.lobes()
            .iter()
            .fold(BsdfFlags::NONE, |f, (_, b)| f | b.flags())
    }

    /// Which of [`SurfaceBsdf::sample_f`]'s numbers it reads: `uc` (where it picks a lobe or
    /// chooses between reflection and refraction) and `u` (where a lobe is not specular).
    /// A path draws only those.
    pub fn draws(&self) -> (bool, bool) {
        let flags = self.flags();
        (
            self.count > 1 || flags.contains(BsdfFlags::TRANSMISSION),
            flags.intersects(BsdfFlags::DIFFUSE | BsdfFlags::GLOSSY),
        )
    }

    /// Whether it scatters nothing: diffuse only, of reflectance zero (a pure emitter's).
    /// Its `f` is zero everywhere and its samples carry zero.
    pub fn is_black(&self) -> bool {
        self.lobes()
            .iter()
            .all(|(_, b)| matches!(b, Bsdf::Lambertian(l) if l.reflectance == Vec3::ZERO))
    }

    /// `Σ wᵢ fᵢ(wo, wi)`, transmitted light tinted.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let f: Vec3 = self.lobes().iter().map(|(w, b)| b.f(wo, wi) * *w).sum();
        if wo.z * wi.z < 0.0 { f * self.tint } else { f }
    }

    /// `Σ wᵢ pdfᵢ(wo, wi)` (specular lobes have none).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.lobes().iter().map(|(w, b)| w * b.pdf(wo, wi)).sum()
    }

    /// A lobe picked by `uc`, then a direction from it (`uc` reused, rescaled, to choose
    /// within the lobe). A specular sample's value and pdf are its lobe's times its weight;
    /// any other sample's are the whole sum's, so that MIS sees the density every lobe gives
    /// its direction.
    pub fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        let lobes = self.lobes();
        let mut start = 0.0;
        let mut pick = lobes.len() - 1;
        for (i, (w, _)) in lobes.iter().enumerate() {
            if uc < start + w {
                pick = i;
                break;
            }
            start += w;
        }
        let (w, bsdf) = lobes[pick];
        let uc = ((uc - start) / w).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let mut s = bsdf.sample_f(wo, uc, u)?;
        if s.flags.is_specular() {
            s.value *= w;
            s.pdf *= w;
            if s.flags.contains(BsdfFlags::TRANSMISSION) {
                s.value *= self.tint;
            }
        } else if lobes.len() > 1 {
            s.value = self.f(wo, s.wi);
            s.pdf = self.pdf(wo, s.wi);
        } else if s.flags.contains(BsdfFlags::TRANSMISSION) {
            s.value *= self.tint;
        }
        (s.pdf > 0.0 && s.value.is_finite()).then_some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A material of every part: the estimate `E[f·|cos|/pdf]` of its albedo by its own
    /// sampling equals the weighted sum of its lobes' albedos, each estimated alone.
    #[test]
    fn the_mixture_samples_as_its_lobes_weighted() {
        let m = Material {
            mirror: 0.2,
            metal: 0.3,
            roughness: 0.5,
            transmission: 0.5,
            ..Material::diffuse(Vec3::new(0.8, 0.5, 0.2))
        };
        let s = SurfaceBsdf::new(&m, m.colour);
        assert_eq!(s.count, 4);
        let w: f32 = s.lobes().iter().map(|l| l.0).sum();
        assert!((w - 1.0).abs() < 1e-6);
        let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
        let mut rng = Rng::seeded(4);
        let n = 200_000;
        let albedo = |draw: &dyn Fn(f32, Vec2) -> Option<BsdfSample>, rng: &mut Rng| {
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                if let Some(x) = draw(rng.next_f32(), u) {
                    sum += x.weight();
                }
            }
            sum / n as f32
        };
        let whole = albedo(&|uc, u| s.sample_f(wo, uc, u), &mut rng);
        let mut parts = Vec3::ZERO;
        for (w, b) in s.lobes() {
            let one = SurfaceBsdf {
                lobes: [(1.0, *b); MAX_LOBES],
                count: 1,
                tint: s.tint,
            };
            parts += *w * albedo(&|uc, u| one.sample_f(wo, uc, u), &mut rng);
        }
        assert!(
            (whole - parts).abs().max_element() < 0.01,
            "{whole} vs {parts}"
        );
        assert!(whole.max_element() <= 1.0 + 0.01, "{whole}");
    }
}
