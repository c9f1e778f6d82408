//! An `f64` reference tracer of a scene's seed stages (direct light, shadow rays, constant
//! indirect term), written independently of the library: Möller–Trumbore over every triangle
//! (with a tiny slack that closes its holes along shared edges), no acceleration structure, no
//! offsets. It traces the exact `f32` rays the library traces,
//! so the two differ only by the library's rounding.

use std::f64::consts::PI;

use glam::DVec3;
use raytty::camera::RayGen;
use raytty::shading::SHADOW_EPSILON;
use raytty::{PointLight, Ray, Scene};

use super::edges::{feature_edges, near_any};

/// A shadow ray from a surface point cannot be blocked closer than this fraction of its
/// length: the `f64` hit point lies within ~1e-16 of its plane, so only a coplanar neighbour
/// could "hit" it at such a `t`, and no real occluder in a scene is that close.
const SELF_HIT_T: f64 = 1e-9;

/// A primary ray that misses is checked for edges out to this many scene diagonals.
const MISS_REACH: f64 = 10.0;

/// Barycentric slack of the reference's ray/triangle test. Plain Möller–Trumbore is not
/// watertight: a ray exactly along a crease (the 500×500 view's diagonal pixels) can round to
/// just outside both faces and see the background. A slack of 1e-12 (barycentrics are
/// relative to the triangle's size) closes those holes and moves no decision farther than
/// 1e-12 of a triangle from its edge, far inside the edge masks (`EDGE_TOL` = 2e-5).
const BARY_SLACK: f64 = 1e-12;

/// Möller–Trumbore in `f64` with [`BARY_SLACK`]: `t` of a hit with `t > 0`.
fn hit(o: DVec3, dir: DVec3, v: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let s = o - v[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let w = dir.dot(q) / det;
    if u < -BARY_SLACK || w < -BARY_SLACK || u + w > 1.0 + BARY_SLACK {
        return None;
    }
    let t = e2.dot(q) / det;
    (t > 0.0).then_some(t)
}

/// One reference pixel.
#[derive(Clone, Copy, Debug)]
pub struct Pixel {
    /// ρ·(D + N), unclamped.
    pub colour: DVec3,
    /// Index of the triangle hit, if any.
    pub triangle: Option<usize>,
    /// Whether every light with its front to the point reaches it (no shadow).
    pub lit: bool,
    /// Whether the primary ray or a shadow ray passes within the tolerance of a feature edge,
    /// or a light lies within the tolerance of the surface's plane: `f32` may differ here.
    pub masked: bool,
}

/// The reference tracer.
pub struct Reference {
    tris: Vec<[DVec3; 3]>,
    normals: Vec<DVec3>,
    colours: Vec<DVec3>,
    edges: Vec<(DVec3, DVec3)>,
    min_r2: f64,
    extent: f64,
}

impl Reference {
    /// The reference of `scene`.
    pub fn new(scene: &Scene) -> Reference {
        let tris = scene.triangles().iter().map(|t| super::d3(&t.v)).collect();
        let normals = scene
            .triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = super::d3(&t.v);
                (c - a).cross(b - a).normalize()
            })
            .collect();
        let colours = scene
            .triangles()
            .iter()
            .map(|t| scene.materials()[t.material as usize].colour.as_dvec3())
            .collect();
        let r = scene.min_light_distance() as f64;
        Reference {
            tris,
            normals,
            colours,
            edges: feature_edges(scene.triangles()),
            min_r2: r * r,
            extent: scene.extent() as f64,
        }
    }

    /// The number of feature edges masks are computed against.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The closest hit `(t, triangle)` of the ray `o + t·dir`, `t > t_min`.
    pub fn closest(&self, o: DVec3, dir: DVec3, t_min: f64) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, v) in self.tris.iter().enumerate() {
            if let Some(t) = hit(o, dir, v)
                && t > t_min
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, i));
            }
        }
        best
    }

    /// Whether anything other than triangle `skip` blocks `o + t·dir` for `SELF_HIT_T < t < t_max`.
    pub fn occluded(&self, o: DVec3, dir: DVec3, t_max: f64, skip: usize) -> bool {
        self.tris
            .iter()
            .enumerate()
            .any(|(i, v)| i != skip && hit(o, dir, v).is_some_and(|t| t > SELF_HIT_T && t < t_max))
    }

    /// The reference colour of the `f32` ray `ray`, with `ambient` as the constant indirect
    /// term, and whether it is masked at edge tolerance `tol` (in scene units).
    pub fn pixel(
        &self,
        ray: &Ray,
        lights: &[PointLight],
        shadows: bool,
        ambient: f64,
        tol: f64,
    ) -> Pixel {
        let (o, dir) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let Some((t, i)) = self.closest(o, dir, 0.0) else {
            let far = o + dir.normalize() * (MISS_REACH * self.extent);
            return Pixel {
                colour: DVec3::ZERO,
                triangle: None,
                lit: false,
                masked: near_any(&self.edges, o, far, tol),
            };
        };
        let p = o + dir * t;
        let mut masked = near_any(&self.edges, o, p, tol);
        let n = if self.normals[i].dot(dir) > 0.0 {
            -self.normals[i]
        } else {
            self.normals[i]
        };
        let mut sum = DVec3::ZERO;
        let mut lit = true;
        for light in lights {
            let l = light.position.as_dvec3();
            let to = l - p;
            let dist2 = to.length_squared();
            let height = n.dot(to);
            if height.abs() < tol {
                masked = true;
            }
            if !(dist2 > 0.0) || height <= 0.0 {
                continue;
            }
            if shadows {
                masked |= near_any(&self.edges, p, l, tol);
                if self.occluded(p, to, 1.0 - SHADOW_EPSILON as f64, i) {
                    lit = false;
                    continue;
                }
            }
            let cos = height / dist2.sqrt();
            sum += light.power.as_dvec3() * cos / (4.0 * PI * dist2.max(self.min_r2));
        }
        Pixel {
            colour: self.colours[i] * (sum + DVec3::splat(ambient)),
            triangle: Some(i),
            lit,
            masked,
        }
    }

    /// Reference pixels of a `width`×`height` frame, row-major, through the same pixel centres
    /// and `f32` rays as [`raytty::render`].
    pub fn frame(
        &self,
        rays: &RayGen,
        size: (u32, u32),
        lights: &[PointLight],
        shadows: bool,
        ambient: f64,
        tol: f64,
    ) -> Vec<Pixel> {
        use rayon::prelude::*;
        let (w, h) = size;
        (0..w * h)
            .into_par_iter()
            .map(|k| {
                let ray = rays.ray((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
                self.pixel(&ray, lights, shadows, ambient, tol)
            })
            .collect()
    }
}
