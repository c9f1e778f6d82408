//! Shading: what colour a ray brings back. The seed's stages, direct light with shadow rays,
//! the constant indirect term, mirrors, and path-traced indirect light, all in the seed's units
//! (a pixel is ρ·E, with E the irradiance; the diffuse BRDF's 1/π is dropped, as the seed does).

use std::f32::consts::PI;

use glam::Vec3;

use crate::accel::Hit;
use crate::accel::tri4::Best8;
use crate::geometry::{Ray, RayTile, Triangle};
use crate::sampler::SampleSource;
use crate::scene::{Indirect, PointLight, Scene};

mod lane;
mod light;
#[cfg(target_arch = "x86_64")]
mod packets;
mod path;
mod split;
mod stage;
mod surface;
mod tile;

use lane::{Lanes, Scalar};
use surface::{Surface, offset_origin, surface, with_shading};

pub use light::LightEffects;
pub use path::{Estimator, PathEffects, PathRun};
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
/// docs/performance.md).
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
    /// What the scene calls for of the physically based path ([`path`]).
    path_effects: PathEffects,
    /// Whether the scene has vertex normals: shading normals, and the checks they need.
    smooth: bool,
    /// The estimator the frame's settings resolve to for this scene.
    estimator: Estimator,
    /// How long a directional light's shadow ray is: longer than any segment within the
    /// scene's box (twice its diagonal), so that it covers the scene from any point on it.
    reach: f32,
    /// The environment added to every point's direct light, unshadowed: the scene's, in
    /// frames that trace no random ray (else zero: path-traced frames find it where their
    /// rays leave the scene).
    ambient: Vec3,
    /// What a ray that leaves the scene brings back in a colour frame: the scene's
    /// environment (zero in other frames).
    background: Vec3,
    /// Per light, the shadow cull of a small scene's tiles, built on first use.
    #[cfg(target_arch = "x86_64")]
    culls: std::sync::OnceLock<Vec<crate::accel::shadow::ShadowCull>>,
}

impl<'a> Tracer<'a> {
    /// A tracer of `scene` lit by `lights` (which may differ from the scene's own).
    pub fn new(scene: &'a Scene, lights: &'a [PointLight], settings: Settings) -> Tracer<'a> {
        let r = scene.min_light_distance();
        let path_effects = PathEffects::of(scene);
        let traced = matches!(settings.effects.indirect, Indirect::PathTraced { .. });
        let colour = settings.mode == Mode::Colour;
        Tracer {
            scene,
            lights,
            settings,
            min_r2: r * r,
            path_effects,
            smooth: scene.has_normals(),
            estimator: path_effects.estimator(settings.estimator),
            reach: 2.0 * scene.extent(),
            ambient: match (settings.mode, traced) {
                (Mode::Flat, _) | (_, true) => Vec3::ZERO,
                _ => scene.environment(),
            },
            background: if colour {
                scene.environment()
            } else {
                Vec3::ZERO
            },
            #[cfg(target_arch = "x86_64")]
            culls: std::sync::OnceLock::new(),
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
        let Some(hit) = hit else {
            return self.background;
        };
        let c = if self.physical() {
            self.path(ray, &hit, &surface_of(self.scene, &hit, ray), rng, n)
                .sum()
        } else {
            self.shade(ray, &hit, 0, 0, rng, n)
        };
        debug_assert!(c.is_finite(), "non-finite colour {c}");
        c
    }

    /// The kinds of light besides points and emitters that this frame shades with.
    pub fn light_effects(&self) -> LightEffects {
        let shading = self.settings.mode != Mode::Flat;
        let scene = self.scene;
        LightEffects {
            directional: shading
                && scene
                    .directional_lights()
                    .iter()
                    .any(|l| l.irradiance != Vec3::ZERO),
            spot: shading && scene.spot_lights().iter().any(|l| l.power != Vec3::ZERO),
            environment: self.ambient != Vec3::ZERO || self.background != Vec3::ZERO,
        }
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
            return SplitSample {
                rest: self.background,
                ..SplitSample::default()
            };
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
        let tri = &self.scene.triangle(hit.triangle);
        let material = &self.scene.materials()[tri.material as usize];
        if self.settings.mode != Mode::Colour {
            return SplitSample {
                rest: self.shade(ray, hit, mirror_depth, 0, rng, n),
                ..SplitSample::default()
            };
        }
        let at = surface_of(self.scene, hit, ray);
        let (p, normal) = (Vec3::from_array(at.p), Vec3::from_array(at.normal));
        if self.physical() {
            let c = self.path(ray, hit, &at, rng, n);
            let guide = Some(GuideHit {
                position: p,
                normal,
                object: self.scene.object_of(hit.triangle),
                reflections: mirror_depth,
            });
            // A first hit that only scatters diffusely: the soft part of the light its path
            // brings is its colour times an irradiance, which the denoiser filters (soft
            // shadows and bounces alike). A mirror, metal or glass first hit keeps all its
            // light as it is: a filter on the surface would blur what it reflects.
            if !material.only_diffuse() {
                return SplitSample {
                    rest: c.sum(),
                    guide,
                    ..SplitSample::default()
                };
            }
            let albedo = self.scene.base_colour(hit.triangle, hit.b);
            // Per channel: a black channel (which a diffuse surface brings no light in) keeps
            // whatever it has apart.
            let part = |sharp: f32, soft: f32, a: f32| {
                if a > 0.0 {
                    (sharp, soft / a)
                } else {
                    (sharp + soft, 0.0)
                }
            };
            let (x, y, z) = (
                part(c.sharp.x, c.soft.x, albedo.x),
                part(c.sharp.y, c.soft.y, albedo.y),
                part(c.sharp.z, c.soft.z, albedo.z),
            );
            return SplitSample {
                rest: Vec3::new(x.0, y.0, z.0),
                albedo,
                irradiance: Vec3::new(x.1, y.1, z.1),
                guide,
            };
        }
        let colour = self.scene.base_colour(hit.triangle, hit.b);
        let reflects = material.mirror > 0.0 && mirror_depth < MAX_MIRROR_DEPTH;
        // As in `shade`: a perfect mirror's own shading and a black surface's cost no ray.
        let (direct, irradiance) = if (reflects && material.mirror >= 1.0) || colour == Vec3::ZERO {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            (
                self.direct_at(&at, n),
                self.indirect(colour, &at, mirror_depth, 0, rng, n),
            )
        };
        let own = SplitSample {
            rest: colour * direct,
            albedo: colour,
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
        let reflected_ray = self.mirror_ray(&at, ray);
        n.reflection += 1;
        let reflected = match self.scene.intersect(&reflected_ray, f32::INFINITY) {
            Some(h) => self.split(&reflected_ray, &h, mirror_depth + 1, rng, n),
            None => SplitSample {
                rest: self.background,
                ..SplitSample::default()
            },
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
            None => self.background,
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
        let tri = &self.scene.triangle(hit.triangle);
        let material = &self.scene.materials()[tri.material as usize];
        let colour = self.scene.base_colour(hit.triangle, hit.b);
        if self.settings.mode == Mode::Flat {
            return colour;
        }
        let at = surface_of(self.scene, hit, ray);
        if self.settings.mode == Mode::Irradiance {
            return self.direct_at(&at, n);
        }
        let reflects = material.mirror > 0.0 && mirror_depth < MAX_MIRROR_DEPTH;
        // What cannot change the pixel is not traced: a perfect mirror's own shading is
        // weighted by 1 − mirror = 0, and a black surface's by ρ = 0.
        let diffuse = if (reflects && material.mirror >= 1.0) || colour == Vec3::ZERO {
            Vec3::ZERO
        } else {
            let direct = self.direct_at(&at, n);
            let indirect = self.indirect(colour, &at, mirror_depth, bounce, rng, n);
            let [r, g, b] = diffuse(
                Scalar,
                colour.to_array(),
                direct.to_array(),
                indirect.to_array(),
            );
            Vec3::new(r, g, b)
        };
        let shaded = if reflects {
            n.reflection += 1;
            let reflected =
                self.trace(&self.mirror_ray(&at, ray), mirror_depth + 1, bounce, rng, n);
            diffuse * (1.0 - material.mirror) + reflected * material.mirror
        } else {
            diffuse
        };
        // (Only an emitter adds: `+ 0` would turn a −0 into +0.)
        if material.emits() {
            shaded + Tracer::emitted(tri, material, ray)
        } else {
            shaded
        }
    }

    /// The indirect irradiance at a diffuse hit: the seed's constant, or one path-traced
    /// bounce (with Russian roulette past [`ROULETTE_START`] bounces).
    fn indirect(
        &self,
        colour: Vec3,
        at: &Surface<f32>,
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
                    colour.max_element().clamp(MIN_SURVIVAL, 1.0)
                } else {
                    1.0
                };
                if q < 1.0 && rng.next_1d() >= q {
                    Vec3::ZERO
                } else {
                    let dir = cosine_sample(Vec3::from_array(at.shading), rng);
                    // A direction about the shading normal may point into the surface: the
                    // path ends there (no light comes from inside).
                    if self.smooth && !(dir.dot(Vec3::from_array(at.normal)) > 0.0) {
                        return Vec3::ZERO;
                    }
                    let origin = Vec3::from_array(offset_origin(Scalar, at, dir.to_array()));
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
    /// The tile kernel at width 1, one point.
    pub fn direct(&self, p: Vec3, err: Vec3, normal: Vec3, n: &mut RayCounts) -> Vec3 {
        let at = Surface {
            p: p.to_array(),
            err: err.to_array(),
            normal: normal.to_array(),
            shading: normal.to_array(),
        };
        self.direct_at(&at, n)
    }

    /// Whether the tile kernel finishes a hit on `triangle` in lanes: in light-only frames
    /// every hit, in colour frames a surface that is all diffuse ([`diffuse`]), not black and
    /// not emitting. Mirrors, black surfaces (whose own shading costs no ray), emitters and
    /// flat colour are shaded one ray at a time.
    #[inline]
    fn in_lanes(&self, triangle: u32) -> bool {
        let material = &self.scene.materials()[self.scene.material_of(triangle) as usize];
        match self.settings.mode {
            Mode::Flat => false,
            Mode::Irradiance => true,
            Mode::Colour => {
                !(material.mirror > 0.0) && material.colour != Vec3::ZERO && !material.emits()
            }
        }
    }

    /// The shadow culls of this frame's lights, for a small scene with shadows (else `None`).
    #[cfg(target_arch = "x86_64")]
    fn culls(&self) -> Option<&[crate::accel::shadow::ShadowCull]> {
        use crate::accel::shadow::{SHADOW_TILE_TRIANGLES, ShadowCull};
        let tris = self.scene.triangles();
        if !self.settings.effects.shadows || self.scene.triangle_count() > SHADOW_TILE_TRIANGLES {
            return None;
        }
        let culls = self.culls.get_or_init(|| {
            self.lights
                .iter()
                .map(|l| ShadowCull::new(tris, l.position))
                .collect()
        });
        Some(culls)
    }

    /// Whether [`Tracer::shade_tile`] can shade this frame's primary hits: one sample, light
    /// that is not path traced.
    pub fn shades_tiles(&self) -> bool {
        !self.draws_random_numbers()
    }

    /// Whether [`Tracer::shade_tile_best`] is the better entry for this frame's tiles: where
    /// the scene's tile query leaves its hits in lanes as the kernel reads them (the flat list
    /// of a small scene on AVX2 or AVX-512), rather than as [`Hit`]s.
    pub(crate) fn shades_tile_lanes(&self) -> bool {
        matches!(
            self.scene.isa(),
            crate::simd::Isa::Avx2 | crate::simd::Isa::Avx512
        ) && self.scene.triangle_count() <= crate::accel::shadow::SHADOW_TILE_TRIANGLES
    }

    /// [`Tracer::shade_tile`] of hits in lanes as [`crate::Scene::intersect_tile_best`] leaves
    /// them (ray `i`'s in lane `i % 8` of `best[i / 8]`).
    pub(crate) fn shade_tile_best(
        &self,
        rays: &RayTile,
        best: &[Best8; crate::accel::TILE_RAYS / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut TileScratch,
    ) {
        debug_assert!(self.shades_tiles());
        self.shade_tile_in(rays, best, out, n, scratch);
    }

    /// [`Tracer::shade_primary`] for a tile of primary rays and their hits (at most
    /// [`crate::accel::TILE_RAYS`]), into `out`: the same colours bit for bit and the same rays
    /// counted, computed light by light across the tile by the tile kernel (each pixel's terms
    /// still added in the lights' order), so that the tile's shadow rays are traced together,
    /// not interleaved with shading. Only for frames that [`Tracer::shades_tiles`].
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
        let mut best = [Best8::NONE; crate::accel::TILE_RAYS / 8];
        for (i, &h) in hits.iter().enumerate() {
            best[i / 8].set(i % 8, h);
        }
        self.shade_tile_in(rays, &best, out, n, scratch);
    }
}

/// Scratch space [`Tracer::shade_tile`] reuses from tile to tile: start with
/// `TileScratch::default()`.
#[derive(Clone, Debug, Default)]
pub struct TileScratch {
    gathered: Box<tile::Gathered>,
    points: Box<tile::Points<{ crate::accel::TILE_RAYS / 8 }>>,
    shadows: tile::ShadowScratch,
    /// A big model's tile triangles, rebuilt from its mesh (see [`Tracer::shade_tile`]).
    triangles: Vec<Triangle>,
}

/// The hit of `ray` at `hit` in `scene`: the tile kernel's [`surface`] at width 1, with the
/// scene's shading normal there.
fn surface_of(scene: &Scene, hit: &Hit, ray: &Ray) -> Surface<f32> {
    let tri: &Triangle = &scene.triangle(hit.triangle);
    let v = tri.v.map(|v| v.to_array());
    let mut at = surface(Scalar, v, tri.normal.to_array(), hit.b, ray.dir.to_array());
    if let Some(n) = scene.shading_normal(hit.triangle, hit.b) {
        with_shading(Scalar, &mut at, n.to_array());
    }
    at
}

impl Tracer<'_> {
    /// The mirror reflection of `ray` at `at`, about the shading normal; where that would send
    /// it into the surface (a shading normal tilted from the triangle's), about the triangle's.
    fn mirror_ray(&self, at: &Surface<f32>, ray: &Ray) -> Ray {
        let d = ray.dir.normalize();
        let reflect = |n: Vec3| d - 2.0 * d.dot(n) * n;
        let normal = Vec3::from_array(at.normal);
        let mut dir = reflect(Vec3::from_array(at.shading));
        if self.smooth && !(dir.dot(normal) > 0.0) {
            dir = reflect(normal);
        }
        let origin = offset_origin(Scalar, at, dir.to_array());
        Ray::new(Vec3::from_array(origin), dir)
    }
}

/// A diffuse surface of reflectance `rho` (per channel) under `direct` and `indirect`
/// irradiance: `ρ·(D + N)`, in the seed's units (the BRDF's 1/π dropped). The one place the
/// tile kernel and one ray at a time shade a diffuse surface.
#[inline(always)]
fn diffuse<S: Lanes>(s: S, rho: [S::F; 3], direct: [S::F; 3], indirect: [S::F; 3]) -> [S::F; 3] {
    lane::each3!(|k| s.mul(rho[k], s.add(direct[k], indirect[k])))
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
