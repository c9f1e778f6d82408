//! Ray throughput by kind: how many million rays per second the acceleration structure and the
//! triangle kernels trace, on one thread and on all, with no shading.
//!
//! Each kind is a batch of rays made from one frame's primary hits, as the tracer makes them:
//! **primary** (camera rays through pixel centres; closest hit), **shadow** (from each hit that
//! faces the light, offset off its surface, to the scene's first light; any-hit, stopping
//! [`SHADOW_EPSILON`] short), **bounce** (a cosine-weighted direction from each hit, seeded by
//! pixel; closest hit) and **reflection** (the camera ray mirrored at each hit; closest hit).
//! A batch is traced once untimed, then `runs` times ([`timing::measure`], timed by the clock
//! around the tracing alone); the median counts.

use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

use super::timing::{self, Runs};
use crate::accel::Isa;
use crate::geometry::{Ray, hit_point, offset_ray_origin};
use crate::rng::Rng;
use crate::scene::Scene;
use crate::shading::{SHADOW_EPSILON, cosine_sample};

/// One kind's rate.
#[derive(Clone, Debug, PartialEq)]
pub struct KindRate {
    /// "primary", "shadow", "bounce" or "reflection".
    pub kind: &'static str,
    /// Rays in the batch.
    pub rays: usize,
    /// M rays/s on one thread (median run).
    pub one_thread: f64,
    /// M rays/s on all threads (median run).
    pub all_threads: f64,
}

/// A scene's throughput.
#[derive(Clone, Debug, PartialEq)]
pub struct Throughput {
    /// The scene's name.
    pub scene: String,
    /// Its triangle count.
    pub triangles: usize,
    /// Its structure ("flat" or "bvh").
    pub accel: &'static str,
    /// The frame the batches come from.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// The SIMD path the kernels took.
    pub isa: Isa,
    /// Threads in the "all threads" column.
    pub threads: usize,
    /// One entry per kind.
    pub kinds: Vec<KindRate>,
}

/// A batch of rays with their `t_max`; shadow rays are any-hit queries.
struct Batch {
    kind: &'static str,
    rays: Vec<(Ray, f32)>,
    any_hit: bool,
}

fn batches(scene: &Scene, width: u32, height: u32) -> Vec<Batch> {
    let camera = scene.camera().rays(width, height);
    let light = scene.lights().first().map(|l| l.position);
    let mut primary = Vec::new();
    let mut shadow = Vec::new();
    let mut bounce = Vec::new();
    let mut reflection = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
            primary.push((ray, f32::INFINITY));
            let Some(hit) = scene.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let tri = &scene.triangle(hit.triangle);
            let (p, err) = hit_point(&tri.v, hit.b);
            let n = if tri.normal.dot(ray.dir) > 0.0 {
                -tri.normal
            } else {
                tri.normal
            };
            if let Some(l) = light
                && n.dot(l - p) > 0.0
            {
                let o = offset_ray_origin(p, err, n, l - p);
                let d = l - o;
                if d != Vec3::ZERO && d.is_finite() {
                    shadow.push((Ray::new(o, d), 1.0 - SHADOW_EPSILON));
                }
            }
            let mut rng = Rng::for_sample(u64::from(y * width + x), 0, 0);
            let d = cosine_sample(n, &mut rng);
            bounce.push((Ray::new(offset_ray_origin(p, err, n, d), d), f32::INFINITY));
            let v = ray.dir.normalize();
            let d = v - 2.0 * v.dot(n) * n;
            reflection.push((Ray::new(offset_ray_origin(p, err, n, d), d), f32::INFINITY));
        }
    }
    vec![
        Batch {
            kind: "primary",
            rays: primary,
            any_hit: false,
        },
        Batch {
            kind: "shadow",
            rays: shadow,
            any_hit: true,
        },
        Batch {
            kind: "bounce",
            rays: bounce,
            any_hit: false,
        },
        Batch {
            kind: "reflection",
            rays: reflection,
            any_hit: false,
        },
    ]
}

/// Traces a batch, on all threads or on this one; returns the hit count (so nothing is
/// optimised away).
fn trace(scene: &Scene, b: &Batch, parallel: bool) -> usize {
    let one = |&(ray, t_max): &(Ray, f32)| {
        if b.any_hit {
            scene.occluded(&ray, t_max)
        } else {
            scene.intersect(&ray, t_max).is_some()
        }
    };
    if parallel {
        b.rays
            .par_chunks(1024)
            .map(|c| c.iter().filter(|r| one(r)).count())
            .sum()
    } else {
        b.rays.iter().filter(|r| one(r)).count()
    }
}

fn rate(scene: &Scene, b: &Batch, parallel: bool, runs: u32) -> f64 {
    let mut hits = None;
    let timing = timing::measure(
        Runs {
            min: runs.max(1),
            min_total: Duration::ZERO,
            max: runs.max(1),
        },
        || {
            let start = Instant::now();
            let n = trace(scene, b, parallel);
            let elapsed = start.elapsed();
            assert_eq!(
                *hits.get_or_insert(n),
                n,
                "a batch traced twice hit differently"
            );
            elapsed
        },
        || {},
    );
    let median = timing.median().as_secs_f64();
    if median > 0.0 {
        b.rays.len() as f64 / median / 1e6
    } else {
        0.0
    }
}

/// Measures `scene`'s throughput by kind on batches from a `width`×`height` frame.
pub fn measure(scene: &Scene, width: u32, height: u32, runs: u32) -> Throughput {
    let kinds = batches(scene, width, height)
        .iter()
        .map(|b| KindRate {
            kind: b.kind,
            rays: b.rays.len(),
            one_thread: rate(scene, b, false, runs),
            all_threads: rate(scene, b, true, runs),
        })
        .collect();
    Throughput {
        scene: scene.name().to_string(),
        triangles: scene.triangle_count(),
        accel: scene.accel_stats().kind.name(),
        width,
        height,
        isa: scene.isa(),
        threads: rayon::current_num_threads(),
        kinds,
    }
}
