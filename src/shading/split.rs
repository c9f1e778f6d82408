//! What the tracer hands the denoiser: a sample split into its noisy indirect part and the
//! rest, and the surface it was guided by.

use glam::Vec3;

/// One sample of a pixel split for the denoiser: its colour is `rest + albedo·irradiance`.
/// `irradiance` is the noisy path-traced irradiance at the pixel's guide vertex, demodulated
/// (not yet multiplied by any reflectance): the indirect light, and in the physically based
/// path an area light's direct light too; everything else, above all the exact direct light of
/// point lights and its hard shadows, is in `rest`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SplitSample {
    /// What the denoiser leaves alone.
    pub rest: Vec3,
    /// The weight of `irradiance` in the pixel: the guide vertex's reflectance, times the
    /// mirror reflectances on the way there.
    pub albedo: Vec3,
    /// Indirect irradiance at the guide vertex (one path-traced estimate).
    pub irradiance: Vec3,
    /// The guide vertex, `None` for a ray that hit nothing.
    pub guide: Option<GuideHit>,
}

impl SplitSample {
    /// The sample's colour, as [`Tracer::shade_primary`] would give it.
    #[inline]
    pub fn colour(&self) -> Vec3 {
        self.rest + self.albedo * self.irradiance
    }
}

/// The surface a pixel's indirect light is filtered on: the primary hit, or for a mirror
/// whose reflection outweighs its own diffuse part, the reflected hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuideHit {
    /// The hit point.
    pub position: Vec3,
    /// The unit normal on the side the ray came from.
    pub normal: Vec3,
    /// The object hit (the order objects were added to the scene).
    pub object: u32,
    /// Mirror reflections before the hit (0 for the primary hit): a reflected floor is not the
    /// floor next to it.
    pub reflections: u32,
}
