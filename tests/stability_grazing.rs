//! Family 2, parallel and grazing rays: rays lying in a triangle's plane, rays parallel to it
//! just above it, and rays meeting it at angles down to 1e-7 rad. No NaN and no panic; every
//! hit has a finite positive `t` and barycentrics in [0, 1]; and the answer agrees with the
//! exact one (`common::expect`, in `f64` on the same `f32` inputs) wherever the exact answer is
//! farther from an edge than the watertight test's own `f32` error. The same rays through a
//! one-triangle `Scene` give the same answers, so the acceleration structure is checked too.
//!
//! Half the triangles are axis-aligned with dyadic coordinates (like the Cornell walls: the
//! in-plane rays are then exactly in the plane, and grazing decisions stay well conditioned);
//! half are randomly oriented.

mod common;

use common::{Expect, Rng, case, expect, unit};
use glam::Vec3;
use raytty::{Camera, Effects, Material, Ray, SceneBuilder, Triangle};

/// Triangles per run; each gets every kind of ray below.
const TRIANGLES: u64 = 2000;

/// Rays of each kind per triangle.
const RAYS: u32 = 8;

/// Heights above the plane of the parallel rays, and angles of the grazing ones (radians).
const HEIGHTS: [f32; 5] = [1e-1, 1e-3, 1e-5, 1e-7, 0.0];
const ANGLES: [f32; 5] = [1e-1, 1e-3, 1e-5, 1e-6, 1e-7];

/// Hits nearer than this (in units of the ray's direction, whose target is at t = 1) are
/// left to the test's own rejection of hits within rounding of the origin.
const MIN_T: f64 = 1e-3;

/// A random triangle of size about 1: axis-aligned with coordinates on a 1/64 grid (in the
/// plane `axis = c`), or randomly oriented.
fn random_triangle(rng: &mut Rng, aligned: bool) -> [Vec3; 3] {
    loop {
        let v = if aligned {
            let axis = (rng.next_u64() % 3) as usize;
            let c = (rng.next_u64() % 129) as f32 / 64.0 - 1.0;
            [0, 1, 2].map(|_| {
                let mut p = Vec3::new(
                    (rng.next_u64() % 129) as f32 / 64.0 - 1.0,
                    (rng.next_u64() % 129) as f32 / 64.0 - 1.0,
                    (rng.next_u64() % 129) as f32 / 64.0 - 1.0,
                );
                p[axis] = c;
                p
            })
        } else {
            [0, 1, 2].map(|_| common::in_cube(rng, 1.0))
        };
        if let Ok(t) = Triangle::new(v[0], v[1], v[2], 0)
            && (v[1] - v[0]).cross(v[2] - v[0]).length() > 0.05
        {
            let _ = t;
            return v;
        }
    }
}

/// A point of the triangle's plane with barycentrics in [−0.5, 1.5]: inside or outside.
fn plane_point(rng: &mut Rng, v: &[Vec3; 3]) -> Vec3 {
    let (b1, b2) = (
        common::uniform(rng, -0.5, 1.5),
        common::uniform(rng, -0.5, 1.5),
    );
    v[0] + (v[1] - v[0]) * b1 + (v[2] - v[0]) * b2
}

/// A unit direction in the triangle's plane (exactly in it when the plane is axis-aligned).
fn in_plane(rng: &mut Rng, n: Vec3) -> Vec3 {
    let w = unit(rng);
    let mut u = w - n * n.dot(w);
    for i in 0..3 {
        if n[i].abs() == 1.0 {
            u[i] = 0.0;
        }
    }
    u.normalize()
}

#[derive(Default)]
struct Tally {
    rays: u32,
    hits: u32,
    decided: u32,
}

fn check(seed: u64, origin: Vec3, dir: Vec3, v: &[Vec3; 3], tally: &mut Tally) {
    if !(dir.is_finite() && dir != Vec3::ZERO && origin.is_finite()) {
        return;
    }
    let why = |e: String| panic!("{}: {e}", case(seed, origin, dir, v));
    let tri = Triangle::new(v[0], v[1], v[2], 0).unwrap();
    let ray = Ray::new(origin, dir);
    let hit = tri.intersect(&ray, f32::INFINITY);
    tally.rays += 1;
    if let Some(h) = hit {
        tally.hits += 1;
        if !(h.t > 0.0 && h.t.is_finite()) || h.b.iter().any(|b| !(0.0..=1.0).contains(b)) {
            why(format!("invalid hit {h:?}"));
        }
    }
    match expect(origin, dir, v, MIN_T) {
        Expect::Hit(t) if hit.is_none() => why(format!("missed; exact hit at t = {t}")),
        Expect::Miss if hit.is_some() => why(format!("hit {hit:?}; exact answer is a miss")),
        e if e.either() => {}
        _ => tally.decided += 1,
    }
    // The same ray through a scene (and its acceleration structure): the same answer.
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::ONE));
    b.object([*v], m);
    let scene = b.build("one", Camera::default(), Effects::SEED).unwrap();
    let in_scene = scene.intersect(&ray, f32::INFINITY).map(|h| (h.t, h.b));
    if in_scene != hit.map(|h| (h.t, h.b)) || scene.occluded(&ray, f32::INFINITY) != hit.is_some() {
        why(format!("triangle says {hit:?}, scene says {in_scene:?}"));
    }
}

#[test]
fn parallel_and_grazing_rays_agree_with_the_exact_answer() {
    let mut tally = [Tally::default(), Tally::default(), Tally::default()];
    for seed in 0..TRIANGLES {
        let mut rng = Rng::seeded(seed);
        let v = random_triangle(&mut rng, seed % 2 == 0);
        let n = Triangle::new(v[0], v[1], v[2], 0).unwrap().normal;
        for _ in 0..RAYS {
            // In the plane, and parallel to it above it.
            let u = in_plane(&mut rng, n);
            let start = plane_point(&mut rng, &v) - u * 2.0;
            for h in HEIGHTS {
                let k = if h == 0.0 { 0 } else { 1 };
                check(seed, start + n * h, u, &v, &mut tally[k]);
            }
            // At a grazing angle, down onto a point inside or outside the triangle.
            let target = plane_point(&mut rng, &v);
            for a in ANGLES {
                let side = if rng.next_u64().is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                };
                let dir = u * a.cos() - n * (side * a.sin());
                check(seed, target - dir, dir, &v, &mut tally[2]);
            }
        }
    }
    for (name, t) in ["in the plane", "parallel above", "grazing"]
        .iter()
        .zip(&tally)
    {
        eprintln!(
            "{name}: {} rays, {} hits, {} decided by the exact answer",
            t.rays, t.hits, t.decided
        );
    }
    // The comparison must have teeth: most grazing and parallel rays are decided exactly.
    assert!(tally[1].decided > tally[1].rays / 2);
    assert!(tally[2].decided > tally[2].rays / 2);
}
