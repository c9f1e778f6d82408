//! How surfaces scatter light: one BSDF per material, each answering pbrt-v4's four questions
//! (`f`, `sample_f`, `pdf`, `flags`) so that an integrator asks only those and never learns a
//! material's name.
//!
//! Every direction here is in the surface's local shading frame ([`ShadingFrame`]): z is the
//! normal, and both `wo` (towards the viewer) and `wi` (towards the light) point away from the
//! surface. Values are for radiance carried from `wi` to `wo` (pbrt-v4's
//! `TransportMode::Radiance`): light refracted into a medium of higher index is concentrated by
//! `η²`, so a transmitting BSDF's `f` includes that factor. `f` does not include the cosine
//! `|wi.z|`; an estimator multiplies it in.
//!
//! [`SurfaceBsdf`] is a scene's [`crate::scene::Material`] as the weighted sum of these; the
//! path tracer of physically based scenes asks it only.

mod conductor;
mod dielectric;
mod fresnel;
mod ggx;
mod lambertian;
mod mirror;
mod rough_dielectric;
mod surface;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use fresnel::{fresnel_dielectric, fresnel_schlick, reflect, refract};
pub use ggx::Ggx;
pub use lambertian::Lambertian;
pub use mirror::Mirror;
pub use rough_dielectric::RoughDielectric;
pub use surface::SurfaceBsdf;

use glam::{Vec2, Vec3};

/// What kind of scattering a BSDF (or one sampled direction) is: a set of bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    /// No scattering at all.
    pub const NONE: BsdfFlags = BsdfFlags(0);
    /// Light leaves on the side it arrived from.
    pub const REFLECTION: BsdfFlags = BsdfFlags(1);
    /// Light passes through the surface.
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(2);
    /// Scattered evenly over the hemisphere (Lambertian).
    pub const DIFFUSE: BsdfFlags = BsdfFlags(4);
    /// Scattered around a preferred direction (rough microfacets).
    pub const GLOSSY: BsdfFlags = BsdfFlags(8);
    /// A single direction (a Dirac delta): `f` and `pdf` are zero for every given pair.
    pub const SPECULAR: BsdfFlags = BsdfFlags(16);

    /// Whether every bit of `other` is set here.
    pub fn contains(self, other: BsdfFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether any bit of `other` is set here.
    pub fn intersects(self, other: BsdfFlags) -> bool {
        self.0 & other.0 != 0
    }

    /// Whether the flags say a sampled direction is a Dirac delta.
    pub fn is_specular(self) -> bool {
        self.intersects(BsdfFlags::SPECULAR)
    }
}

impl std::ops::BitOr for BsdfFlags {
    type Output = BsdfFlags;
    fn bitor(self, rhs: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | rhs.0)
    }
}

/// One direction drawn by [`Bsdf::sample_f`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The incident direction (local frame, unit length).
    pub wi: Vec3,
    /// `f(wo, wi)` per channel; for a specular sample the delta's weight divided by `|wi.z|`,
    /// so that `value·|wi.z|/pdf` is the sample's throughput either way.
    pub value: Vec3,
    /// The solid-angle density of `wi` (for a specular sample, the probability of choosing
    /// its lobe).
    pub pdf: f32,
    /// The kind of scattering this sample is: one of reflection or transmission, and one of
    /// diffuse, glossy or specular.
    pub flags: BsdfFlags,
}

impl BsdfSample {
    /// The sample's throughput weight `value·|cos θi|/pdf`.
    pub fn weight(&self) -> Vec3 {
        self.value * (self.wi.z.abs() / self.pdf)
    }
}

/// A surface's scattering, one variant per material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Ideal diffuse reflection on both sides.
    Lambertian(Lambertian),
    /// The perfect mirror.
    Mirror(Mirror),
    /// A GGX microfacet metal.
    Conductor(Conductor),
    /// Smooth glass.
    Dielectric(Dielectric),
    /// Rough glass (GGX transmission).
    RoughDielectric(RoughDielectric),
}

impl Bsdf {
    /// The BSDF's value for light arriving along `wi` and leaving along `wo` (zero for
    /// specular materials: a delta has no value at a given pair).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Bsdf::Lambertian(b) => b.f(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => Vec3::ZERO,
            Bsdf::Conductor(b) => b.f(wo, wi),
            Bsdf::RoughDielectric(b) => b.f(wo, wi),
        }
    }

    /// Draws an incident direction for `wo` from two uniform numbers `u` and a third `uc` that
    /// picks between lobes (reflection or transmission). `None` where no light can scatter
    /// (a grazing `wo`, a microfacet facing away, or total internal reflection through a
    /// rough facet that the sample cannot follow).
    pub fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            Bsdf::Lambertian(b) => b.sample_f(wo, u),
            Bsdf::Mirror(b) => b.sample_f(wo),
            Bsdf::Conductor(b) => b.sample_f(wo, u),
            Bsdf::Dielectric(b) => b.sample_f(wo, uc),
            Bsdf::RoughDielectric(b) => b.sample_f(wo, uc, u),
        }
    }

    /// The solid-angle density with which [`Bsdf::sample_f`] draws `wi` for `wo` (zero for
    /// specular materials).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Lambertian(b) => b.pdf(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => 0.0,
            Bsdf::Conductor(b) => b.pdf(wo, wi),
            Bsdf::RoughDielectric(b) => b.pdf(wo, wi),
        }
    }

    /// Every kind of scattering the material can do.
    pub fn flags(&self) -> BsdfFlags {
        match self {
            Bsdf::Lambertian(_) => BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE,
            Bsdf::Mirror(_) => BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
            Bsdf::Conductor(b) => b.flags(),
            Bsdf::Dielectric(b) => b.flags(),
            Bsdf::RoughDielectric(b) => b.flags(),
        }
    }
}

/// An orthonormal frame around a unit normal: world directions to local ones (z = the normal)
/// and back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingFrame {
    /// The first tangent (local x).
    pub tangent: Vec3,
    /// The second tangent (local y).
    pub bitangent: Vec3,
    /// The normal (local z).
    pub normal: Vec3,
}

impl ShadingFrame {
    /// A frame around the unit normal `n`, its tangents chosen without branches on
    /// near-parallel axes (glam's `any_orthonormal_pair`, after Duff et al. 2017).
    pub fn from_normal(n: Vec3) -> ShadingFrame {
        debug_assert!(n.is_normalized(), "{n}");
        let (tangent, bitangent) = n.any_orthonormal_pair();
        ShadingFrame {
            tangent,
            bitangent,
            normal: n,
        }
    }

    /// A world direction in this frame's coordinates.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(
            v.dot(self.tangent),
            v.dot(self.bitangent),
            v.dot(self.normal),
        )
    }

    /// A local direction in world coordinates.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

/// Whether two local directions lie on the same side of the surface.
#[inline]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// A cosine-weighted direction on the upper hemisphere (z > 0) from two uniform numbers, by
/// Malley's method: a uniform point on the unit disk (polar map) lifted onto the hemisphere.
/// Its density is `z/π`.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let (s, c) = libm::sincosf(std::f32::consts::TAU * u.y);
    Vec3::new(r * c, r * s, (1.0 - u.x).max(0.0).sqrt())
}
