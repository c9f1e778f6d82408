//! Shading: what colour a ray brings back. The seed's stages, direct light with shadow rays,
//! the constant indirect term, mirrors, and path-traced indirect light, all in the seed's units
//! (a pixel is ρ·E, with E the irradiance; the diffuse BRDF's 1/π is dropped, as the seed does).

use std::f32::consts::PI;

use glam::Vec3;

use crate::accel::Hit;
use crate::geometry::{Ray, hit_point, offset_ray_origin};
use crate::rng::Rng;
use crate::scene::{Effects, Indirect, Material, PointLight, Scene};

/// The seed's stages, selectable by name and by the keys 1-6.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// The triangle's colour (the seed's Fig. 2).
    Flat,
    /// Direct irradiance D as grey, no shadows (Figs. 7-9).
    Light,
    /// ρ·D, no shadows (Figs. 10-12).
    Direct,
    /// ρ·D with shadow rays (Fig. 13).
    Shadows,
    /// ρ·(D + N): the effects the scene calls for (Fig. 14 for the Cornell box; the default).
    Indirect,
    /// Path-traced global illumination.
    Gi,
}

impl Stage {
    /// All stages in key order (1-6).
    pub const ALL: [Stage; 6] = [
        Stage::Flat,
        Stage::Light,
        Stage::Direct,
        Stage::Shadows,
        Stage::Indirect,
        Stage::Gi,
    ];

    /// The stage's name as the CLI takes it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Flat => "flat",
            Stage::Light => "light",
            Stage::Direct => "direct",
            Stage::Shadows => "shadows",
            Stage::Indirect => "indirect",
            Stage::Gi => "gi",
        }
    }

    /// Parses a stage name.
    pub fn from_name(name: &str) -> Option<Stage> {
        Stage::ALL.into_iter().find(|s| s.name() == name)
    }

    /// What this stage computes, given the effects the scene calls for.
    pub fn settings(self, scene: Effects) -> Settings {
        let none = Effects {
            shadows: false,
            indirect: Indirect::None,
            samples: 1,
        };
        let (mode, effects) = match self {
            Stage::Flat => (Mode::Flat, none),
            Stage::Light => (Mode::Irradiance, none),
            Stage::Direct => (Mode::Colour, none),
            Stage::Shadows => (
                Mode::Colour,
                Effects {
                    shadows: true,
                    ..none
                },
            ),
            Stage::Indirect => (Mode::Colour, scene),
            Stage::Gi => (
                Mode::Colour,
                Effects {
                    shadows: true,
                    indirect: Indirect::PathTraced {
                        bounces: GI_MAX_BOUNCES,
                    },
                    samples: 1,
                },
            ),
        };
        Settings {
            mode,
            effects,
            frame: 0,
        }
    }
}

/// What a hit's colour is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The material colour ρ.
    Flat,
    /// The direct irradiance D itself.
    Irradiance,
    /// ρ·(direct + indirect), with mirrors.
    Colour,
}

/// Everything that decides a frame's pixels besides the scene, camera, lights and size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// What a hit's colour is made of.
    pub mode: Mode,
    /// Which effects run.
    pub effects: Effects,
    /// Frame number: seeds the random numbers (progressive refinement uses a new one per pass).
    pub frame: u32,
}

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub primary: u64,
    /// Rays towards a light (any-hit queries).
    pub shadow: u64,
    /// Diffuse bounce rays of path-traced indirect light.
    pub bounce: u64,
    /// Mirror reflection rays.
    pub reflection: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.bounce + self.reflection
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.bounce += o.bounce;
        self.reflection += o.reflection;
    }
}

/// One sample of a pixel split for the denoiser: its colour is `rest + albedo·irradiance`.
/// `irradiance` is the noisy path-traced indirect irradiance at the pixel's guide vertex,
/// demodulated (not yet multiplied by any reflectance); everything else, above all the exact
/// direct light and its hard shadows, is in `rest`.
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
        }
    }

    /// The colour seen along a primary ray, given its closest hit.
    pub fn shade_primary(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        rng: &mut Rng,
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

    /// One sample along a primary ray, split for the denoiser (see [`SplitSample`]). Its
    /// colour equals [`Tracer::shade_primary`]'s in value; the random numbers are drawn in the
    /// same order.
    pub fn sample_primary(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        rng: &mut Rng,
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
        rng: &mut Rng,
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
        rng: &mut Rng,
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
        rng: &mut Rng,
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
        rng: &mut Rng,
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
                if q < 1.0 && rng.next_f32() >= q {
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
            // A dark light adds nothing: no shadow ray for it.
            if light.power == Vec3::ZERO {
                continue;
            }
            let to_light = light.position - p;
            let dist2 = to_light.length_squared();
            if !(dist2 > 0.0) {
                continue;
            }
            let cos = normal.dot(to_light) / dist2.sqrt();
            if !(cos > 0.0) {
                continue;
            }
            if self.settings.effects.shadows {
                let origin = offset_ray_origin(p, err, normal, to_light);
                let dir = light.position - origin;
                if dir != Vec3::ZERO && dir.is_finite() {
                    n.shadow += 1;
                    if self
                        .scene
                        .occluded(&Ray::new(origin, dir), 1.0 - SHADOW_EPSILON)
                    {
                        continue;
                    }
                }
            }
            sum += light.power * cos / (4.0 * PI * dist2.max(self.min_r2));
        }
        sum
    }
}

/// A cosine-weighted direction on the hemisphere around `n` (unit length).
pub(crate) fn cosine_sample(n: Vec3, rng: &mut Rng) -> Vec3 {
    let (u1, u2) = (rng.next_f32(), rng.next_f32());
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let (s, c) = (libm::sinf(phi), libm::cosf(phi));
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * c) + b * (r * s) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}
