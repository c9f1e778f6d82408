//! Path tracing of physically based scenes: the materials of [`crate::material`] (asked only
//! through [`SurfaceBsdf`]), emitting triangles as area lights, and the point lights. At each
//! vertex, next-event estimation (each point light, exactly, as [`super::light::point_light`]
//! gives it; one point on the area lights, drawn by power and area, and where emitters face
//! different ways one of two such candidates, picked in proportion to what each would bring
//! ([`super::light::area_light`]), one shadow ray; three at a glossy first vertex:
//! `GLOSSY_FIRST_LIGHT_SAMPLES`) and one BSDF sample to go on with;
//! where the frame's [`Estimator`] says so, the two are combined by multiple importance
//! sampling with the power heuristic (Veach 1997), so that light reaching a vertex is counted
//! once.
//!
//! A frame runs this only where its scene calls for it ([`PathEffects::of`]): something emits,
//! is metal or transmits. The seed's scenes keep the seed's shading (`super::Tracer::shade`).
//!
//! Units are the seed's (pixel values are π × radiance): a BSDF's value is multiplied by π
//! under a point light (whose term is the seed's irradiance `P·cos/(4πr²)`), and an emitter's
//! `emission` is what the camera sees.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::lane::Scalar;
use super::light::{AreaIncident, STEP_Y, area_light, directional_light, point_light, spot_light};
use super::surface::{Surface, offset_origin};
use super::{MIN_SURVIVAL, Mode, ROULETTE_START, RayCounts, SHADOW_EPSILON, Tracer, surface_of};
use crate::accel::Hit;
use crate::geometry::{Ray, Triangle};
use crate::light::area_to_solid_angle;
use crate::material::{BsdfFlags, ShadingFrame, SurfaceBsdf};
use crate::sampler::SampleSource;
use crate::scene::{Indirect, Material, Scene};

/// How light is gathered at vertices that are not specular.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Estimator {
    /// What the scene calls for: MIS where something is glossy and something emits, else light
    /// sampling alone (at a diffuse vertex BSDF sampling finds a small light rarely, and MIS
    /// would trace the same rays for a weight near 1).
    #[default]
    Auto,
    /// Next-event estimation only: emission found by a BSDF ray counts only after a specular
    /// vertex (or the camera).
    Light,
    /// BSDF sampling only: emission counts wherever a path finds it; no area-light shadow ray.
    Bsdf,
    /// Both, weighted by the power heuristic.
    Mis,
}

impl Estimator {
    /// The names `--estimator` takes, in order: auto, light, bsdf, mis.
    pub const ALL: [Estimator; 4] = [
        Estimator::Auto,
        Estimator::Light,
        Estimator::Bsdf,
        Estimator::Mis,
    ];

    /// The estimator's name.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Auto => "auto",
            Estimator::Light => "light",
            Estimator::Bsdf => "bsdf",
            Estimator::Mis => "mis",
        }
    }
}

/// What a physically based scene calls for, derived from its materials and lights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathEffects {
    /// Some triangle emits: area lights are sampled.
    pub area_lights: bool,
    /// Some material is glossy (a rough metal or rough glass).
    pub glossy: bool,
    /// Some material refracts.
    pub refraction: bool,
    /// Some material is metal.
    pub metal: bool,
    /// Every material scatters only diffusely (no mirror, metal or glass part): the noise is
    /// in the diffuse bounces, and a diffuse first vertex sends [`FIRST_BRANCHES`] paths on.
    pub diffuse: bool,
}

impl PathEffects {
    /// The effects `scene` calls for, from its materials' BSDF flags and its emitters.
    pub fn of(scene: &Scene) -> PathEffects {
        let mut e = PathEffects {
            area_lights: scene.area_lights().is_some(),
            diffuse: scene.materials().iter().all(Material::only_diffuse),
            ..PathEffects::default()
        };
        for m in scene.materials() {
            let flags = SurfaceBsdf::new(m, m.colour).flags();
            e.glossy |= flags.contains(BsdfFlags::GLOSSY);
            e.refraction |= flags.contains(BsdfFlags::TRANSMISSION);
            e.metal |= m.metal > 0.0;
        }
        e
    }

    /// Whether the scene needs the physically based path at all.
    pub fn any(&self) -> bool {
        self.area_lights || self.glossy || self.refraction || self.metal
    }

    /// The estimator `asked` resolves to for this scene.
    pub fn estimator(&self, asked: Estimator) -> Estimator {
        match asked {
            Estimator::Auto if self.area_lights && self.glossy => Estimator::Mis,
            Estimator::Auto => Estimator::Light,
            e => e,
        }
    }
}

/// What a frame's physically based path ran: the scene's effects and the estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathRun {
    /// What the scene calls for.
    pub effects: PathEffects,
    /// The estimator used at vertices that are not specular.
    pub estimator: Estimator,
}

impl PathRun {
    /// The effects' names, for `render --stats`: "path", then area lights with their
    /// estimator, glossy, metal, refraction, as the scene calls for them.
    pub fn names(&self) -> Vec<&'static str> {
        let e = self.effects;
        let mut names = vec!["path"];
        if e.area_lights {
            names.push(match self.estimator {
                Estimator::Bsdf => "area lights (bsdf sampling)",
                Estimator::Light => "area lights (light sampling)",
                _ => "area lights (mis)",
            });
        }
        if e.glossy {
            names.push("glossy");
        }
        if e.metal {
            names.push("metal");
        }
        if e.refraction {
            names.push("refraction");
        }
        names
    }
}

/// The power heuristic with β = 2: the weight of a sample of density `a` against one of `b`.
#[inline]
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

/// What the previous vertex's BSDF sample left for MIS: where it was, with what density it
/// chose the direction (`None`: the camera or a specular choice, whose emission counts
/// whole), and how many light samples it drew (the light's density counts that many times).
#[derive(Clone, Copy)]
struct Came {
    from: Vec3,
    pdf: Option<f32>,
    light_samples: f32,
}

/// Light samples drawn at a glossy first vertex (one elsewhere). There the reflected lights
/// are most of what the camera sees, and a sample costs one shadow ray where a path costs
/// several: on the plates (160x100, 256 spp, values clamped, against Mitsuba 3's 16384-spp
/// frame) two rather than one took the MSE 1.18e-4 -> 0.90e-4 for ~5 % more CPU time (time
/// x MSE -21 %). Since a sample resamples one of two candidates there
/// ([`crate::light::AreaLights::candidates`]), three rather than two (1024 spp): RMSE
/// 0.00433 -> 0.00404 for 9 % more instructions (time x MSE -5 %), four 0.00385 for 18 %
/// more (-7 % by instructions, no better by CPU time); glass within noise (RMSE 0.00834 ->
/// 0.00835, +0.7 % instructions), area untouched (no glossy first hit). Two at every first
/// vertex, diffuse too, bought nothing on area and cost on glass.
const GLOSSY_FIRST_LIGHT_SAMPLES: u32 = 3;

/// How many paths the first vertex sends on in a frame of several samples of a scene that
/// scatters only diffusely ([`PathEffects::diffuse`]). There the noise is the light that comes
/// back from the bounces (on the area-lit box at 1024 spp, the first vertex's own light is
/// ~3 % of the squared error), while the camera ray and the first vertex's light sample are
/// a good part of a path's time: two branches, each with its own bounces, take the noise of
/// the rest down by more than half (their first two directions are one 4D Sobol point, over
/// 2N points) for ~1.8x the CPU time. Against Mitsuba 3 (160x100, 1024 spp, both frames
/// against Mitsuba's 65536-spp one, CPU time x RMSE² over Mitsuba's, two interleaved runs):
/// area 0.500, 0.527 -> 0.383, 0.433 (RMSE 0.00225 -> 0.00147); glass, where the noise is in
/// caustics, 0.888, 0.902 -> 0.895, 0.902, and plates, in glossy reflections of small lights,
/// 0.305, 0.337 -> 0.417, 0.344: scenes with glossy, mirror or glass parts keep one path. A frame of one sample
/// (the app's, the bench's interactive rows) is judged by its time, and keeps one too.
pub const FIRST_BRANCHES: u32 = 2;

/// Which part of a path [`Tracer::walk`] traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Walk {
    /// The whole path.
    Whole,
    /// The first vertex's emission and lights, nothing after.
    FirstVertex,
    /// One of [`FIRST_BRANCHES`] continuations from the first vertex: what the bounces bring,
    /// weighted by 1/[`FIRST_BRANCHES`].
    Branch,
}

impl Tracer<'_> {
    /// Whether this frame shades by [`Tracer::path`]: a colour frame with path-traced light
    /// of a scene that calls for the physically based path.
    pub(super) fn physical(&self) -> bool {
        self.path_effects.any()
            && self.settings.mode == Mode::Colour
            && matches!(self.settings.effects.indirect, Indirect::PathTraced { .. })
    }

    /// What the physically based path runs in this frame (`None`: the seed's shading).
    pub fn path_run(&self) -> Option<PathRun> {
        self.physical().then_some(PathRun {
            effects: self.path_effects,
            estimator: self.estimator,
        })
    }

    /// What an emitter shows along `ray` (its front face only; zero for the rest).
    #[inline]
    pub(super) fn emitted(tri: &Triangle, material: &Material, ray: &Ray) -> Vec3 {
        if material.emits() && ray.dir.dot(tri.front()) < 0.0 {
            material.emission
        } else {
            Vec3::ZERO
        }
    }

    /// The shading frame at `at` (of a triangle with front normal `front`), and the
    /// direction `toward` the previous vertex in it: about the shading normal turned to the
    /// front, but about the triangle's own normal where the two normals put that direction on
    /// different sides (at silhouettes a shading normal can face away from a viewer the
    /// triangle faces).
    fn frame(&self, at: &Surface<f32>, front: Vec3, toward: Vec3) -> (ShadingFrame, Vec3) {
        if self.smooth {
            let (ng, ns) = (Vec3::from_array(at.normal), Vec3::from_array(at.shading));
            let n = if ng.dot(front) > 0.0 { ns } else { -ns };
            let frame = ShadingFrame::from_normal(n);
            let wo = frame.to_local(toward);
            if (wo.z > 0.0) == (toward.dot(front) > 0.0) {
                return (frame, wo);
            }
        }
        let frame = ShadingFrame::from_normal(front);
        (frame, frame.to_local(toward))
    }

    /// The BSDF's value for `wo` and `wl` (local; `wi` in the world), zero where the shading
    /// normal puts `wi` on another side of the triangle (of front normal `front`) than the
    /// triangle does: light from below a surface does not leak through it.
    fn f_both_sides(&self, bsdf: &SurfaceBsdf, wo: Vec3, wl: Vec3, wi: Vec3, front: Vec3) -> Vec3 {
        if self.smooth && (wi.dot(front) > 0.0) != (wl.z > 0.0) {
            return Vec3::ZERO;
        }
        bsdf.f(wo, wl)
    }

    /// One path from the primary `hit` of `ray` (`first`: its surface, as
    /// [`surface_of`] gives it): the colour it brings back, in two parts. In a frame of
    /// several samples of a scene that scatters only diffusely, the first vertex sends
    /// [`FIRST_BRANCHES`] paths on, each weighted by their number.
    pub(super) fn path<S: SampleSource>(
        &self,
        ray: &Ray,
        hit: &Hit,
        first: &Surface<f32>,
        rng: &mut S,
        n: &mut RayCounts,
    ) -> PathColour {
        if self.settings.effects.samples < 2 || !self.path_effects.diffuse {
            return self.walk(ray, hit, first, rng, n, Walk::Whole);
        }
        let mut c = self.walk(ray, hit, first, rng, n, Walk::FirstVertex);
        for b in 0..FIRST_BRANCHES {
            let mut branch = rng.branch(b, FIRST_BRANCHES);
            let d = self.walk(ray, hit, first, &mut branch, n, Walk::Branch);
            c.sharp += d.sharp;
            c.soft += d.soft;
        }
        c
    }

    /// The part `walk` of a path: see [`Tracer::path`].
    fn walk(
        &self,
        ray: &Ray,
        hit: &Hit,
        first: &Surface<f32>,
        rng: &mut impl SampleSource,
        n: &mut RayCounts,
        walk: Walk,
    ) -> PathColour {
        let bounces = match self.settings.effects.indirect {
            Indirect::PathTraced { bounces } => bounces,
            _ => 0,
        };
        let scene = self.scene;
        let mis = self.estimator;
        let smooth = self.smooth;
        // [sharp, soft] (see `PathColour`).
        let mut colour = [Vec3::ZERO; 2];
        // Whether the path has been focused (a glossy or specular bounce past the first
        // vertex): what it brings from then on is sharp.
        let mut focused = false;
        let mut beta = if walk == Walk::Branch {
            Vec3::splat(1.0 / FIRST_BRANCHES as f32)
        } else {
            Vec3::ONE
        };
        let (mut ray, mut hit, mut at) = (*ray, *hit, *first);
        let mut came = Came {
            from: ray.origin,
            pdf: None,
            light_samples: 1.0,
        };
        for vertex in 0..=bounces + 1 {
            // A branch gathers nothing at the first vertex (its path's first part did).
            let gathers = !(walk == Walk::Branch && vertex == 0);
            // Where this vertex's area light and what escapes from it go, and its emission and
            // delta lights (the first vertex's are exact: sharp).
            let soft = usize::from(!focused);
            let exact = if vertex == 0 { 0 } else { soft };
            let tri = &scene.triangle(hit.triangle);
            let material = &scene.materials()[tri.material as usize];
            let p = Vec3::from_array(at.p);
            let e = Tracer::emitted(tri, material, &ray);
            if e != Vec3::ZERO && gathers {
                let w = match (came.pdf, mis) {
                    (None, _) | (Some(_), Estimator::Bsdf) => 1.0,
                    (Some(_), Estimator::Light) => 0.0,
                    (Some(pb), _) => {
                        let area = scene
                            .area_lights()
                            .map_or(0.0, |a| a.pdf_area(hit.triangle));
                        let pl =
                            area_to_solid_angle(area, came.from, p, tri.front()).unwrap_or(0.0);
                        power_heuristic(pb, came.light_samples * pl)
                    }
                };
                colour[exact] += beta * e * w;
            }
            if vertex > bounces {
                break;
            }
            // Glass has air on the front side (local z > 0).
            let front = tri.front();
            let toward = -ray.dir.normalize();
            let bsdf = SurfaceBsdf::new(material, scene.base_colour(hit.triangle, hit.b));
            if bsdf.is_black() {
                // Nothing arrives through it: every light would add zero and the path's
                // weight would become zero (the plates' emitting balls, which bounce rays
                // from the plates find often).
                break;
            }
            let (frame, wo) = self.frame(&at, front, toward);
            // Only the numbers this vertex uses are drawn: each costs a Sobol dimension (a
            // hash per coordinate), and a diffuse or metal vertex has no lobe to choose.
            let (draws_choice, draws_direction) = bsdf.draws();
            let smooth_only = !draws_direction;
            let light_samples = if vertex == 0 && bsdf.flags().contains(BsdfFlags::GLOSSY) {
                GLOSSY_FIRST_LIGHT_SAMPLES
            } else {
                1
            };
            let k = light_samples as f32;
            // The sampler's first two pairs form one 4D point: at a first vertex that draws
            // both, this direction and this vertex's light sample (in a branch, which draws
            // no light there, the first two bounces' directions). Pairing the direction with
            // the next vertex's light sample instead (the one-bounce light depends on both)
            // took the area box's MSE down by only 1.3 % (160x100, 256 spp): not worth drawing
            // out of order. The first part of a split path draws no direction: its light
            // sample is its first pair.
            let u_bsdf = if draws_direction && walk != Walk::FirstVertex {
                Vec2::from(rng.next_2d())
            } else {
                Vec2::ZERO
            };
            if !smooth_only && gathers {
                // Point, directional and spot lights: exact, as the seed's (π·f times the
                // light's irradiance term), one shadow ray each.
                let points = self
                    .lights
                    .iter()
                    .filter(|l| l.power != Vec3::ZERO)
                    .map(|l| {
                        let inc = point_light(Scalar, l, self.min_r2, &at, true, smooth);
                        ((l.position - p).normalize(), inc)
                    });
                let directional = scene
                    .directional_lights()
                    .iter()
                    .filter(|l| l.irradiance != Vec3::ZERO)
                    .map(|l| {
                        let inc = directional_light(Scalar, l, self.reach, &at, true, smooth);
                        (-l.direction, inc)
                    });
                let spots = scene
                    .spot_lights()
                    .iter()
                    .filter(|l| l.power != Vec3::ZERO)
                    .map(|l| {
                        let inc = spot_light(Scalar, l, self.min_r2, &at, true, smooth);
                        ((l.position - p).normalize(), inc)
                    });
                for (wi, inc) in points.chain(directional).chain(spots) {
                    if inc.lit == 0 {
                        continue;
                    }
                    let f = self.f_both_sides(&bsdf, wo, frame.to_local(wi), wi, front);
                    if f == Vec3::ZERO {
                        continue;
                    }
                    if inc.traced != 0 {
                        n.shadow += 1;
                        let shadow =
                            Ray::new(Vec3::from_array(inc.origin), Vec3::from_array(inc.dir));
                        if scene.occluded(&shadow, 1.0 - SHADOW_EPSILON) {
                            continue;
                        }
                    }
                    colour[exact] += beta * f * Vec3::from_array(inc.term) * PI;
                }
                if mis != Estimator::Bsdf
                    && let Some(lights) = scene.area_lights()
                {
                    // One 2D number and one pick for the vertex's samples: sample i takes
                    // them shifted by (i/(k·candidates), i·φ) and i/k (each still uniform),
                    // so that its candidates fall between the others' (a grid of
                    // k·candidates in the first number) and no Sobol dimension is drawn
                    // for it.
                    let candidates = lights.candidates();
                    let u0 = Vec2::from(rng.next_2d());
                    let pick0 = if candidates > 1 { rng.next_1d() } else { 0.0 };
                    for i in 0..light_samples {
                        let (u, u_pick) = if i == 0 {
                            (u0, pick0)
                        } else {
                            let i = i as f32;
                            let dx = i / (k * candidates as f32);
                            (
                                Vec2::new((u0.x + dx).fract(), (u0.y + i * STEP_Y).fract()),
                                (pick0 + i / k).fract(),
                            )
                        };
                        // What a candidate would bring, unshadowed: the BSDF's value times the
                        // emission and the cosine.
                        let target = |wi: Vec3, emission: Vec3| {
                            let wl = frame.to_local(wi);
                            let f = self.f_both_sides(&bsdf, wo, wl, wi, front);
                            f.dot(emission) * wl.z.abs()
                        };
                        let Some(AreaIncident {
                            wi,
                            pdf,
                            candidate_pdf,
                            emission,
                            shadow,
                        }) = area_light(lights, &at, candidates, u, u_pick, target)
                        else {
                            continue;
                        };
                        let wl = frame.to_local(wi);
                        let f = self.f_both_sides(&bsdf, wo, wl, wi, front);
                        if f == Vec3::ZERO {
                            continue;
                        }
                        n.shadow += 1;
                        if scene.occluded(&shadow, 1.0 - SHADOW_EPSILON) {
                            continue;
                        }
                        // Each of k samples: f·L·cos/(k·pdf), weighed against the BSDF's
                        // density by the k samples' combined one (of a candidate: the density
                        // a BSDF ray that finds the light is weighed by too).
                        let k_pdf = k * pdf;
                        let w = if mis == Estimator::Mis {
                            power_heuristic(k * candidate_pdf, bsdf.pdf(wo, wl))
                        } else {
                            1.0
                        };
                        colour[soft] += beta * f * emission * (wl.z.abs() * w / k_pdf);
                    }
                }
            }
            if walk == Walk::FirstVertex {
                break;
            }
            // Go on along a direction the BSDF picks.
            let u_choice = if draws_choice { rng.next_1d() } else { 0.5 };
            let Some(s) = bsdf.sample_f(wo, u_choice, u_bsdf) else {
                break;
            };
            let mut weight = s.weight();
            // Where roulette starts, measured for this path too (area, 160x100, 256 spp,
            // values clamped, against Mitsuba 3's 16384-spp frame, its noise taken out; rays a
            // sample as the cost): from vertex 1, 2, 4, 5, 7 or never, MSE +61, +18, -7, -12,
            // -14, -14 % for rays -19, -9, +8, +14, +24, +47 %: rays x MSE +31, +8, 0, +1, +8,
            // +26 %. The seed's 3 is at the optimum.
            if vertex >= ROULETTE_START {
                // The survival chance follows what the surface keeps of the light: a
                // refraction's 1/η'² is radiance changing units across the interface (undone
                // on the way out), not light lost, so it is taken out: paths inside glass are
                // not cut short (the glass scene, 160x100 at 256 spp: RMSE 0.0245 -> 0.0165
                // against Mitsuba's 4096-spp frame, for 15 % more time).
                let kept = if s.flags.contains(BsdfFlags::TRANSMISSION) && wo.z * s.wi.z < 0.0 {
                    let etap = if wo.z > 0.0 {
                        material.ior
                    } else {
                        1.0 / material.ior
                    };
                    weight * (etap * etap)
                } else {
                    weight
                };
                let q = kept.max_element().clamp(MIN_SURVIVAL, 1.0);
                if q < 1.0 && rng.next_1d() >= q {
                    break;
                }
                weight /= q;
            }
            beta *= weight;
            if !(beta.max_element() > 0.0) || !beta.is_finite() {
                break;
            }
            let wi = frame.to_world(s.wi).normalize();
            // Where the shading normal sends the path to the other side of the triangle than
            // its own side says (a tilted shading normal), it ends: light does not leak.
            if self.smooth && (wi.dot(front) > 0.0) != (s.wi.z > 0.0) {
                break;
            }
            let origin = Vec3::from_array(offset_origin(Scalar, &at, wi.to_array()));
            ray = Ray::new(origin, wi);
            if s.flags.is_specular() {
                n.reflection += 1;
            } else {
                n.bounce += 1;
            }
            focused |= vertex > 0 && !s.flags.contains(BsdfFlags::DIFFUSE);
            came = Came {
                from: p,
                pdf: (!s.flags.is_specular()).then_some(s.pdf),
                light_samples: k,
            };
            match scene.intersect(&ray, f32::INFINITY) {
                Some(h) => {
                    hit = h;
                    at = surface_of(scene, &hit, &ray);
                }
                None => {
                    // The environment, found by BSDF sampling alone (counted whole): under a
                    // constant sky the BSDF's own sampling draws `f·cos` as well as any light
                    // sampling could, and costs no shadow ray.
                    colour[soft] += beta * self.background;
                    break;
                }
            }
        }
        let [sharp, soft] = colour;
        debug_assert!(
            sharp.is_finite() && soft.is_finite(),
            "non-finite colour {sharp} + {soft}"
        );
        if sharp.is_finite() && soft.is_finite() {
            PathColour { sharp, soft }
        } else {
            PathColour::default()
        }
    }
}

/// A path's colour in two parts, for the denoiser: the sharp part, which a filter must leave
/// as it is (what the first vertex gives exactly: the emitter the camera sees, the point,
/// directional and spot lights there; and the light of a path focused by a glossy or specular
/// bounce past the first vertex: caustics, which a filter would spread), and the soft part
/// (area lights, diffuse bounces, the environment: noisy, but smooth across a surface).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct PathColour {
    /// What a filter must leave as it is.
    pub(super) sharp: Vec3,
    /// The diffusely gathered rest.
    pub(super) soft: Vec3,
}

impl PathColour {
    /// The whole colour.
    pub(super) fn sum(self) -> Vec3 {
        self.sharp + self.soft
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_power_heuristic_weighs_two_samplers_to_one() {
        for (a, b) in [(1.0, 1.0), (0.3, 7.0), (0.0, 2.0), (5.0, 0.0)] {
            let s = power_heuristic(a, b) + power_heuristic(b, a);
            assert!((s - 1.0).abs() < 1e-6, "{a} {b}");
        }
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
    }
}
