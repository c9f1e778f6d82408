//! Shading: what colour a ray brings back. The seed's stages, direct light with shadow rays,
//! the constant indirect term, mirrors, and path-traced indirect light, all in the seed's units
//! (a pixel is ρ·E, with E the irradiance; the diffuse BRDF's 1/π is dropped, as the seed does).

use std::f32::consts::PI;

use glam::Vec3;

use crate::accel::Hit;
use crate::geometry::{Ray, RayTile, hit_point, offset_ray_origin};
use crate::sampler::SampleSource;
use crate::scene::{Indirect, Material, PointLight, Scene};

#[cfg(target_arch = "x86_64")]
mod lanes;
mod split;
mod stage;
mod tile;

pub use split::{GuideHit, SplitSample};
pub use stage::{Mode, RayCounts, Settings, Stage};

/// A shadow ray stops this fraction of its length short of the light, so that a light lying
/// exactly on a surface is not shadowed by that surface's own rounding. Relative, so it holds at
/// every scale.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// Mirror reflection stops after this many reflections (two facing mirrors would never end).
pub const MAX_MIRROR_DEPTH: u32 = 8;

/// Path-traced bounces before this many are always traced; from here on Russian roulette may end
/// a path. By then a path carries at most 0.75³ ≈ 0.42 of its first hit's weight in the Cornell
/// box, so ending it early adds little noise and saves the rays of the long tail (measured in
/// the README's "What accuracy costs").
pub const ROULETTE_START: u32 = 3;

/// Stage 6's bounce cap: a safety net, not a model. Paths end by Russian roulette; one that
/// survived 16 bounces in the Cornell box (albedo ≤ 0.75, an open front) carries under 0.75¹⁶ ≈
/// 1 % of its weight, and reaching it takes a run of survivals that almost never happens. It is
/// also the bench reference's bounce count, so stage 6 converges to the reference itself.
pub const GI_MAX_BOUNCES: u32 = 16;

/// Roulette never gives a path less than this chance to survive, so that the `1/q` weight of a
/// survivor (and the noise it brings) stays bounded on very dark surfaces.
pub const MIN_SURVIVAL: f32 = 0.1;

/// Shades rays for one frame.
pub struct Tracer<'a> {
    scene: &'a Scene,
    lights: &'a [PointLight],
    settings: Settings,
    min_r2: f32,
    /// What [`Tracer::shade_tile_lanes`] reads per triangle and light, built on first use.
    #[cfg(target_arch = "x86_64")]
    tables: std::sync::OnceLock<Box<lanes::Tables>>,
}

impl<'a> Tracer<'a> {
    /// A tracer of `scene` lit by `lights` (which may differ from the scene's own).
    pub fn new(scene: &'a Scene, lights: &'a [PointLight], settings: Settings) -> Tracer<'a> {
        let r = scene.min_light_distance();
        Tracer {
            scene,
            lights,
            settings,
            min_r2: r * r,
            #[cfg(target_arch = "x86_64")]
            tables: std::sync::OnceLock::new(),
        }
    }

    /// The colour seen along a primary ray, given its closest hit.
    pub fn shade_primary(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> Vec3 {
        let Some(hit) = hit else { return Vec3::ZERO };
        let c = self.shade(ray, &hit, 0, 0, rng, n);
        debug_assert!(c.is_finite(), "non-finite colour {c}");
        c
    }

    /// Whether this frame's indirect light is path traced, so that [`Tracer::sample_primary`]
    /// has something to split.
    pub fn splits(&self) -> bool {
        self.settings.mode == Mode::Colour
            && matches!(self.settings.effects.indirect, Indirect::PathTraced { .. })
    }

    /// Whether shading draws random numbers at all: only path-traced indirect light does (a
    /// frame without it may pass any generator, which is left untouched).
    pub fn draws_random_numbers(&self) -> bool {
        matches!(self.settings.effects.indirect, Indirect::PathTraced { .. })
    }

    /// One sample along a primary ray, split for the denoiser (see [`SplitSample`]). Its
    /// colour equals [`Tracer::shade_primary`]'s in value; the random numbers are drawn in the
    /// same order.
    pub fn sample_primary(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> SplitSample {
        let Some(hit) = hit else {
            return SplitSample::default();
        };
        let s = self.split(ray, &hit, 0, rng, n);
        debug_assert!(s.colour().is_finite(), "non-finite colour {}", s.colour());
        s
    }

    fn split(
        &self,
        ray: &Ray,
        hit: &Hit,
        mirror_depth: u32,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> SplitSample {
        let tri = &self.scene.triangles()[hit.triangle as usize];
        let material = &self.scene.materials()[tri.material as usize];
        if self.settings.mode != Mode::Colour {
            return SplitSample {
                rest: self.shade(ray, hit, mirror_depth, 0, rng, n),
                ..SplitSample::default()
            };
        }
        let (p, err) = hit_point(&tri.v, hit.b);
        let normal = if tri.normal.dot(ray.dir) > 0.0 {
            -tri.normal
        } else {
            tri.normal
        };
        let reflects = material.mirror > 0.0 && mirror_depth < MAX_MIRROR_DEPTH;
        // As in `shade`: a perfect mirror's own shading and a black surface's cost no ray.
        let (direct, irradiance) =
            if (reflects && material.mirror >= 1.0) || material.colour == Vec3::ZERO {
                (Vec3::ZERO, Vec3::ZERO)
            } else {
                (
                    self.direct(p, err, normal, n),
                    self.indirect(material, p, err, normal, mirror_depth, 0, rng, n),
                )
            };
        let own = SplitSample {
            rest: material.colour * direct,
            albedo: material.colour,
            irradiance,
            guide: Some(GuideHit {
                position: p,
                normal,
                object: self.scene.object_of(hit.triangle),
                reflections: mirror_depth,
            }),
        };
        if !reflects {
            return own;
        }
        let m = material.mirror;
        let d = ray.dir.normalize();
        let dir = d - 2.0 * d.dot(normal) * normal;
        let origin = offset_ray_origin(p, err, normal, dir);
        n.reflection += 1;
        let reflected_ray = Ray::new(origin, dir);
        let reflected = match self.scene.intersect(&reflected_ray, f32::INFINITY) {
            Some(h) => self.split(&reflected_ray, &h, mirror_depth + 1, rng, n),
            None => SplitSample::default(),
        };
        // The pixel is filtered on whichever surface weighs more in it; the other one's
        // indirect light stays in `rest`, unfiltered.
        if reflected.guide.is_some()
            && (reflected.albedo * m).max_element() > (own.albedo * (1.0 - m)).max_element()
        {
            SplitSample {
                rest: own.colour() * (1.0 - m) + reflected.rest * m,
                albedo: reflected.albedo * m,
                ..reflected
            }
        } else {
            SplitSample {
                rest: own.rest * (1.0 - m) + reflected.colour() * m,
                albedo: own.albedo * (1.0 - m),
                ..own
            }
        }
    }

    /// The colour seen along `ray` (any depth).
    fn trace(
        &self,
        ray: &Ray,
        mirror_depth: u32,
        bounce: u32,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> Vec3 {
        match self.scene.intersect(ray, f32::INFINITY) {
            Some(hit) => self.shade(ray, &hit, mirror_depth, bounce, rng, n),
            None => Vec3::ZERO,
        }
    }

    fn shade(
        &self,
        ray: &Ray,
        hit: &Hit,
        mirror_depth: u32,
        bounce: u32,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> Vec3 {
        let tri = &self.scene.triangles()[hit.triangle as usize];
        let material = &self.scene.materials()[tri.material as usize];
        if self.settings.mode == Mode::Flat {
            return material.colour;
        }
        let (p, err) = hit_point(&tri.v, hit.b);
        // Two-sided shading: light the side the ray came from.
        let normal = if tri.normal.dot(ray.dir) > 0.0 {
            -tri.normal
        } else {
            tri.normal
        };
        if self.settings.mode == Mode::Irradiance {
            return self.direct(p, err, normal, n);
        }
        let reflects = material.mirror > 0.0 && mirror_depth < MAX_MIRROR_DEPTH;
        // What cannot change the pixel is not traced: a perfect mirror's own shading is
        // weighted by 1 − mirror = 0, and a black surface's by ρ = 0.
        let diffuse = if (reflects && material.mirror >= 1.0) || material.colour == Vec3::ZERO {
            Vec3::ZERO
        } else {
            material.colour
                * (self.direct(p, err, normal, n)
                    + self.indirect(material, p, err, normal, mirror_depth, bounce, rng, n))
        };
        if reflects {
            let d = ray.dir.normalize();
            let dir = d - 2.0 * d.dot(normal) * normal;
            let origin = offset_ray_origin(p, err, normal, dir);
            n.reflection += 1;
            let reflected = self.trace(&Ray::new(origin, dir), mirror_depth + 1, bounce, rng, n);
            diffuse * (1.0 - material.mirror) + reflected * material.mirror
        } else {
            diffuse
        }
    }

    /// The indirect irradiance at a diffuse hit: the seed's constant, or one path-traced
    /// bounce (with Russian roulette past [`ROULETTE_START`] bounces).
    #[allow(clippy::too_many_arguments)]
    fn indirect(
        &self,
        material: &Material,
        p: Vec3,
        err: Vec3,
        normal: Vec3,
        mirror_depth: u32,
        bounce: u32,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
    ) -> Vec3 {
        match self.settings.effects.indirect {
            Indirect::None => Vec3::ZERO,
            Indirect::Constant(k) => Vec3::splat(k),
            Indirect::PathTraced { bounces } if bounce < bounces => {
                // Russian roulette: past the first bounces, a path goes on with probability q
                // (the surface's albedo, which scales whatever comes back) and what it brings
                // is divided by q, so the expected value is unchanged.
                let q = if bounce >= ROULETTE_START {
                    material.colour.max_element().clamp(MIN_SURVIVAL, 1.0)
                } else {
                    1.0
                };
                if q < 1.0 && rng.next_1d() >= q {
                    Vec3::ZERO
                } else {
                    let dir = cosine_sample(normal, rng);
                    let origin = offset_ray_origin(p, err, normal, dir);
                    n.bounce += 1;
                    self.trace(&Ray::new(origin, dir), mirror_depth, bounce + 1, rng, n) / q
                }
            }
            Indirect::PathTraced { .. } => Vec3::ZERO,
        }
    }

    /// Direct irradiance at `p` (error bound `err`) on a surface with normal `normal`, summed
    /// over the lights: `D = P·max(r̂·n̂, 0)/(4πr²)`, with `r²` clamped to the scene's minimum
    /// light distance. A light behind the surface contributes nothing and costs no shadow ray.
    pub fn direct(&self, p: glam::Vec3, err: Vec3, normal: Vec3, n: &mut RayCounts) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for light in self.lights {
            let Some((term, shadow)) = self.light_term(light, p, err, normal) else {
                continue;
            };
            if let Some(ray) = shadow {
                n.shadow += 1;
                if self.scene.occluded(&ray, 1.0 - SHADOW_EPSILON) {
                    continue;
                }
            }
            sum += term;
        }
        sum
    }

    /// What `light` adds to [`Tracer::direct`] at `p` if nothing blocks it, and the shadow ray
    /// that decides whether something does (`None`: no ray is traced, the light counts as
    /// seen). `None` for a light that adds nothing: dark, at `p`, or behind the surface.
    #[inline(always)]
    fn light_term(
        &self,
        light: &PointLight,
        p: Vec3,
        err: Vec3,
        normal: Vec3,
    ) -> Option<(Vec3, Option<Ray>)> {
        // A dark light adds nothing: no shadow ray for it.
        if light.power == Vec3::ZERO {
            return None;
        }
        let to_light = light.position - p;
        let dist2 = to_light.length_squared();
        if !(dist2 > 0.0) {
            return None;
        }
        let cos = normal.dot(to_light) / dist2.sqrt();
        if !(cos > 0.0) {
            return None;
        }
        let term = light.power * cos / (4.0 * PI * dist2.max(self.min_r2));
        if !self.settings.effects.shadows {
            return Some((term, None));
        }
        let origin = offset_ray_origin(p, err, normal, to_light);
        let dir = light.position - origin;
        let shadow = (dir != Vec3::ZERO && dir.is_finite()).then(|| Ray::new(origin, dir));
        Some((term, shadow))
    }

    /// Whether [`Tracer::shade_tile`] can shade this frame's primary hits: one sample, light
    /// that is not path traced.
    pub fn shades_tiles(&self) -> bool {
        !self.draws_random_numbers()
    }

    /// Whether [`Tracer::shade_tile_best`] shades this frame's tiles (AVX2, a small scene).
    pub(crate) fn shades_tile_lanes(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.shades_in_lanes();
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// [`Tracer::shade_tile`] of hits in lanes as [`crate::Scene::intersect_tile_best`] leaves
    /// them (ray `i`'s in lane `i % 8` of `best[i / 8]`), without putting them in [`Hit`]s
    /// first. Only where [`Tracer::shades_tile_lanes`] (elsewhere it puts them in `Hit`s for
    /// [`Tracer::shade_tile`]).
    pub(crate) fn shade_tile_best(
        &self,
        rays: &RayTile,
        best: &[crate::accel::tri4::Best8; crate::accel::TILE_RAYS / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut TileScratch,
    ) {
        #[cfg(target_arch = "x86_64")]
        self.shade_tile_best_lanes(rays, best, out, n, &mut scratch.lanes);
        #[cfg(not(target_arch = "x86_64"))]
        {
            let hits: Vec<Option<Hit>> = (0..rays.len()).map(|i| best[i / 8].hit(i % 8)).collect();
            self.shade_tile(rays, &hits, out, n, scratch);
        }
    }

    /// [`Tracer::shade_primary`] for a tile of primary rays and their hits (at most
    /// [`crate::accel::TILE_RAYS`]), into `out`: the same colours bit for bit and the same rays
    /// counted, computed light by light across the tile (each pixel's terms still added in the
    /// lights' order), so that the tile's shadow rays are traced together, not interleaved
    /// with shading. Only for frames that [`Tracer::shades_tiles`].
    pub fn shade_tile(
        &self,
        rays: &RayTile,
        hits: &[Option<Hit>],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut TileScratch,
    ) {
        debug_assert!(self.shades_tiles());
        assert!(hits.len() == rays.len() && out.len() == rays.len());
        #[cfg(target_arch = "x86_64")]
        if self.shades_in_lanes() {
            self.shade_tile_lanes(rays, hits, out, n, &mut scratch.lanes);
            return;
        }
        // Per pixel being shaded here: the hit point, its error, the normal facing the ray,
        // and where it goes in `out`.
        let TileScratch {
            at,
            sum,
            terms,
            rays: shadows,
            blocked,
            ..
        } = scratch;
        at.clear();
        for (i, hit) in hits.iter().enumerate() {
            let Some(hit) = hit else {
                out[i] = Vec3::ZERO;
                continue;
            };
            let tri = &self.scene.triangles()[hit.triangle as usize];
            let material = &self.scene.materials()[tri.material as usize];
            let mode = self.settings.mode;
            // As `shade`: flat colour; a black surface or a mirror (shaded one at a time).
            let own = mode == Mode::Irradiance
                || (mode == Mode::Colour
                    && !(material.mirror > 0.0)
                    && material.colour != Vec3::ZERO);
            if !own {
                let ray = rays.ray(i);
                out[i] = self.shade_primary(&ray, Some(*hit), &mut crate::rng::Rng::seeded(0), n);
                continue;
            }
            let (p, err) = hit_point(&tri.v, hit.b);
            let normal = if tri.normal.dot(rays.dir(i)) > 0.0 {
                -tri.normal
            } else {
                tri.normal
            };
            at.push((p, err, normal, i));
        }
        sum.clear();
        sum.resize(at.len(), Vec3::ZERO);
        for light in self.lights {
            terms.clear();
            self.light_terms(light, at, terms);
            // The tile's shadow rays, traced together.
            shadows.clear();
            shadows.extend(terms.iter().filter_map(|t| t.and_then(|(_, s)| s)));
            blocked.clear();
            blocked.resize(shadows.len(), false);
            self.scene
                .occluded_each(shadows, 1.0 - SHADOW_EPSILON, blocked);
            n.shadow += shadows.len() as u64;
            let mut blocked = blocked.iter();
            for (s, t) in sum.iter_mut().zip(terms.iter()) {
                let Some((term, shadow)) = t else { continue };
                if shadow.is_some() && *blocked.next().expect("one answer per shadow ray") {
                    continue;
                }
                *s += *term;
            }
        }
        for (&(.., i), &sum) in at.iter().zip(sum.iter()) {
            out[i] = if self.settings.mode == Mode::Irradiance {
                sum
            } else {
                let tri = &self.scene.triangles()[hits[i].expect("a hit").triangle as usize];
                let material = &self.scene.materials()[tri.material as usize];
                let indirect = match self.settings.effects.indirect {
                    Indirect::Constant(k) => Vec3::splat(k),
                    _ => Vec3::ZERO,
                };
                material.colour * (sum + indirect)
            };
            debug_assert!(out[i].is_finite(), "non-finite colour {}", out[i]);
        }
    }
}

/// Scratch space [`Tracer::shade_tile`] reuses from tile to tile: start with
/// `TileScratch::default()`.
#[derive(Clone, Debug, Default)]
pub struct TileScratch {
    at: Vec<(Vec3, Vec3, Vec3, usize)>,
    sum: Vec<Vec3>,
    terms: Vec<Option<(Vec3, Option<Ray>)>>,
    rays: Vec<Ray>,
    blocked: Vec<bool>,
    /// What [`Tracer::shade_tile_lanes`] keeps.
    #[cfg(target_arch = "x86_64")]
    lanes: Box<lanes::LaneScratch>,
}

/// A cosine-weighted direction on the hemisphere around `n` (unit length).
pub(crate) fn cosine_sample(n: Vec3, rng: &mut impl SampleSource) -> Vec3 {
    let [u1, u2] = rng.next_2d();
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    // One range reduction for both; the same bits as `sinf` and `cosf` apart for every angle
    // a sample can give (checked for all 2²⁴ of them below).
    let (s, c) = libm::sincosf(phi);
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * c) + b * (r * s) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    /// `libm::sincosf` gives `sinf`'s and `cosf`'s bits for every angle `cosine_sample` can be
    /// given: samplers hand out multiples of 2⁻²⁴, all 2²⁴ of which are tried. (Frames, and
    /// the bench's cached references, were made with the two apart.)
    #[test]
    fn sincos_is_sin_and_cos_for_every_sample_angle() {
        for k in 0..1u32 << 24 {
            let phi = 2.0 * PI * (k as f32 * (1.0 / (1u32 << 24) as f32));
            let (s, c) = libm::sincosf(phi);
            assert_eq!(s.to_bits(), libm::sinf(phi).to_bits(), "sin at {k}");
            assert_eq!(c.to_bits(), libm::cosf(phi).to_bits(), "cos at {k}");
        }
    }
}
