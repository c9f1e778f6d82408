//! The GGX (Trowbridge–Reitz) microfacet distribution, isotropic: the normals' density `D`,
//! Smith's masking, and sampling of the normals visible from a direction (Heitz 2018).
//!
//! Masking and shadowing together use Smith's **height-correlated** form,
//! `G(wo, wi) = 1/(1 + Λ(wo) + Λ(wi))` (Heitz 2014, "Understanding the Masking-Shadowing
//! Function"), which counts a microfacet hidden from both directions once; it is what pbrt-v4
//! and Mitsuba 3 use.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

/// Below this α a surface is treated as smooth (a delta): the distribution's peak `1/(πα²)`
/// would exceed what f32 holds well, and the lobe is narrower than a pixel's footprint anyway.
/// Roughness ≈ 0.03 (pbrt-v4 uses the same cut-off).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// An isotropic GGX distribution of microfacet normals, in the local frame (z = the normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// The width α: `roughness²` (Burley's remapping, so that roughness reads linearly).
    pub alpha: f32,
}

impl Ggx {
    /// The distribution of a surface of perceptual `roughness` in 0..=1 (α = roughness²).
    pub fn from_roughness(roughness: f32) -> Ggx {
        let r = roughness.clamp(0.0, 1.0);
        Ggx { alpha: r * r }
    }

    /// Whether the surface is smooth enough to be a delta (see [`SMOOTH_ALPHA`]).
    pub fn is_smooth(&self) -> bool {
        self.alpha < SMOOTH_ALPHA
    }

    /// The density of microfacet normals `wm` (per projected area: `∫ D(wm) cos θm dwm = 1`).
    pub fn d(&self, wm: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let c2 = wm.z * wm.z;
        let k = c2 * (a2 - 1.0) + 1.0;
        if k <= 0.0 {
            return 0.0;
        }
        a2 / (PI * k * k)
    }

    /// Smith's Λ(w): the masked microfacet area per visible one, for direction `w`.
    pub fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        let tan2 = ((1.0 - c2) / c2).max(0.0);
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    /// The fraction of microfacets visible from `w` (Smith's masking).
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The fraction visible from both `wo` and `wi`, height-correlated.
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of normals visible from `w`: `G1(w)·max(0, w·wm)·D(wm)/|w.z|`.
    pub fn d_visible(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = w.z.abs();
        if cos == 0.0 {
            return 0.0;
        }
        self.g1(w) * w.dot(wm).abs() * self.d(wm) / cos
    }

    /// A microfacet normal drawn from the normals visible from `w` (on `w`'s side flipped to
    /// the upper hemisphere), density [`Ggx::d_visible`]: Heitz's 2018 method (stretch the
    /// view, sample the projected disk of a hemisphere, unstretch).
    pub fn sample_visible(&self, w: Vec3, u: Vec2) -> Vec3 {
        let w = if w.z < 0.0 { -w } else { w };
        // The view in the stretched configuration, where the distribution is the hemisphere.
        let wh = Vec3::new(self.alpha * w.x, self.alpha * w.y, w.z).normalize();
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        // A uniform point on the unit disk, then squeezed onto the part of it the visible
        // hemisphere projects to.
        let r = u.x.sqrt();
        let (s, c) = libm::sincosf(std::f32::consts::TAU * u.y);
        let (p1, mut p2) = (r * c, r * s);
        let h = (1.0 - p1 * p1).max(0.0).sqrt();
        let blend = 0.5 * (1.0 + wh.z);
        p2 = (1.0 - blend) * h + blend * p2;
        let pz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nh = t1 * p1 + t2 * p2 + wh * pz;
        // Back to the ellipsoid's normal.
        Vec3::new(self.alpha * nh.x, self.alpha * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Uniform directions on the sphere.
    fn uniform_sphere(rng: &mut Rng) -> Vec3 {
        let z = 1.0 - 2.0 * rng.next_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * rng.next_f32();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    #[test]
    fn the_normals_project_to_unit_area_and_the_visible_ones_to_the_view() {
        let mut rng = Rng::seeded(7);
        for roughness in [0.2f32, 0.5, 1.0] {
            let ggx = Ggx::from_roughness(roughness);
            // ∫ D(m) cos θm dm = 1 and ∫ D_w(m) dm = 1, by uniform sampling of the sphere.
            let n = 400_000;
            let (mut proj, mut vis) = (0.0f64, 0.0f64);
            let w = Vec3::new(0.6, 0.0, 0.8);
            for _ in 0..n {
                let m = uniform_sphere(&mut rng);
                if m.z > 0.0 {
                    proj += f64::from(ggx.d(m) * m.z);
                    if w.dot(m) > 0.0 {
                        vis += f64::from(ggx.d_visible(w, m));
                    }
                }
            }
            let area = 4.0 * std::f64::consts::PI / f64::from(n);
            let tol = if roughness < 0.3 { 0.05 } else { 0.02 };
            assert!(
                (proj * area - 1.0).abs() < tol,
                "{roughness}: {}",
                proj * area
            );
            assert!(
                (vis * area - 1.0).abs() < tol,
                "{roughness}: {}",
                vis * area
            );
        }
    }

    #[test]
    fn masking_is_one_head_on_and_falls_towards_grazing() {
        let ggx = Ggx::from_roughness(0.7);
        assert!((ggx.g1(Vec3::Z) - 1.0).abs() < 1e-6);
        let mut last = 1.0;
        for k in 1..=9 {
            let t = k as f32 * 0.17;
            let g = ggx.g1(Vec3::new(t.sin(), 0.0, t.cos()));
            assert!(g <= last && g > 0.0, "{t}: {g}");
            last = g;
        }
        assert_eq!(ggx.g1(Vec3::X), 0.0);
        // Height-correlated: never more than the product of the two maskings would allow.
        let (a, b) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.8, 0.6));
        assert!(ggx.g(a, b) >= ggx.g1(a) * ggx.g1(b) - 1e-6);
        assert!(ggx.g(a, b) <= ggx.g1(a).min(ggx.g1(b)));
    }
}
