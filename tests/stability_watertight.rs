//! Family 1, watertightness: a ray that starts inside a closed mesh always hits it, including
//! rays aimed exactly at its vertices and along its shared edges, and the Cornell room's creases
//! leave no gap for the course's integer-offset camera rays (the model: Embree's `verify`
//! watertight test and pbrt-v4's `Triangle.Watertight`). Meshes are scenes, so the tests go
//! through `Scene::intersect` and `Scene::occluded` and check the acceleration structure too.

mod common;

use common::{Rng, unit};
use glam::Vec3;
use raytty::scene::procedural;
use raytty::{Camera, Effects, Material, Ray, Scene, SceneBuilder, cornell_box};

/// Random rays per mesh in the random-ray test (the issue asks for 100 000 on the sphere).
const RANDOM_RAYS: u32 = 100_000;

/// Random rays per icosphere in the ignored full sweep
/// (`cargo test --test stability_watertight -- --ignored --nocapture`).
const SWEEP_RAYS: u32 = 1_000_000;

/// Icosphere radii are jittered per vertex in `1 ± RADIUS_JITTER`: the mesh is no longer convex
/// or regular, but stays star-shaped about its centre, hence closed and non-self-intersecting.
const RADIUS_JITTER: f32 = 0.2;

/// Ray origins lie within this radius of the sphere's centre: 0.1 inside the smallest vertex
/// radius (0.8), far more than the 0.008 spacing of `f32` at the 1e5 offset.
const ORIGIN_RADIUS: f32 = 0.7;

/// Embree's `verify` moves its watertight mesh this far from the origin.
const FAR_OFFSET: f32 = 1e5;

fn scene_of(triangles: Vec<[Vec3; 3]>) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::ONE));
    b.object(triangles, m);
    b.build("mesh", Camera::default(), Effects::SEED)
        .expect("test meshes are valid")
}

/// An icosahedron subdivided `levels` times, vertices shared between faces, each vertex at a
/// jittered radius from `centre`. Returns the shared vertex list and the faces.
fn icosphere(levels: u32, centre: Vec3, seed: u64) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let mut verts: Vec<Vec3> = procedural::icosahedron_vertices()
        .map(|v| v.as_vec3().normalize())
        .to_vec();
    let mut faces = procedural::ICOSAHEDRON_FACES.to_vec();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, verts: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push((verts[a] + verts[b]).normalize());
                verts.len() - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = midpoint(a, b, &mut verts);
                let bc = midpoint(b, c, &mut verts);
                let ca = midpoint(c, a, &mut verts);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    let mut rng = Rng::seeded(seed);
    for v in &mut verts {
        let r = 1.0 + RADIUS_JITTER * (2.0 * rng.next_f32() - 1.0);
        *v = centre + *v * r;
    }
    (verts, faces)
}

fn triangles(verts: &[Vec3], faces: &[[usize; 3]]) -> Vec<[Vec3; 3]> {
    faces.iter().map(|f| f.map(|i| verts[i])).collect()
}

/// The eight corners A..H of a Cornell block, read back from its ten triangles (the seed's
/// order: `[E,B,A], [E,F,B], [F,D,B], [F,H,D], [H,C,D], [H,G,C], ...`).
fn block_corners(scene: &Scene, first: usize) -> [Vec3; 8] {
    let t = |i: usize| scene.triangles()[first + i].v;
    let (e, b, a) = (t(0)[0], t(0)[1], t(0)[2]);
    let (f, d) = (t(2)[0], t(2)[1]);
    let (h, c) = (t(4)[0], t(4)[1]);
    let g = t(5)[1];
    [a, b, c, d, e, f, g, h]
}

/// A Cornell block closed with a bottom (the seed leaves it open; it stands on the floor).
fn closed_block(scene: &Scene, first: usize) -> Vec<[Vec3; 3]> {
    let [a, b, c, d, ..] = block_corners(scene, first);
    let mut tris: Vec<[Vec3; 3]> = (0..10).map(|i| scene.triangles()[first + i].v).collect();
    tris.push([a, b, d]);
    tris.push([a, d, c]);
    tris
}

/// A point strictly inside a convex block: a random convex combination of its corners, each
/// weight at least 1/16 of the total, so it stays clear of every face.
fn inside_block(rng: &mut Rng, corners: &[Vec3; 8]) -> Vec3 {
    let w: Vec<f32> = (0..8).map(|_| 1.0 / 16.0 + rng.next_f32()).collect();
    let total: f32 = w.iter().sum();
    corners.iter().zip(&w).map(|(c, w)| *c * *w).sum::<Vec3>() / total
}

/// Checks that `ray` hits `scene` both as a closest-hit and as an any-hit query; returns a
/// description of the failure, naming the case with `what` (only called on failure).
fn check_hits(scene: &Scene, ray: &Ray, what: impl FnOnce() -> String) -> Option<String> {
    let closest = scene.intersect(ray, f32::INFINITY);
    let any = scene.occluded(ray, f32::INFINITY);
    match closest {
        Some(h) if any && h.t.is_finite() && h.t > 0.0 => None,
        _ => Some(format!(
            "{}: ray origin {:?} dir {:?}: intersect {closest:?}, occluded {any}",
            what(),
            ray.origin.to_array(),
            ray.dir.to_array()
        )),
    }
}

fn assert_no_failures(failures: Vec<String>, total: usize, what: &str) {
    assert!(
        failures.is_empty(),
        "{} of {total} {what} escaped the closed mesh; first ones:\n{}",
        failures.len(),
        failures
            .iter()
            .take(10)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// Shoots `rays` seeded random rays from inside a jittered icosphere, centred at the origin and
/// at Embree's far offset; every one must hit.
fn icosphere_sweep(rays: u32) {
    for (seed, centre) in [
        (1u64, Vec3::ZERO),
        (2, Vec3::new(FAR_OFFSET, -FAR_OFFSET, FAR_OFFSET)),
    ] {
        let start = std::time::Instant::now();
        let (verts, faces) = icosphere(2, centre, seed);
        let scene = scene_of(triangles(&verts, &faces));
        let mut rng = Rng::seeded(seed);
        let mut failures = Vec::new();
        for i in 0..rays {
            let origin = centre + unit(&mut rng) * ORIGIN_RADIUS * rng.next_f32().cbrt();
            let ray = Ray::new(origin, unit(&mut rng));
            failures.extend(check_hits(&scene, &ray, || format!("mesh {seed}, ray {i}")));
        }
        eprintln!(
            "icosphere at {centre}: {rays} rays, {} misses, {:.2?}",
            failures.len(),
            start.elapsed()
        );
        assert_no_failures(failures, rays as usize, "random rays");
    }
}

#[test]
fn random_rays_from_inside_a_jittered_icosphere_always_hit() {
    icosphere_sweep(RANDOM_RAYS);
}

#[test]
#[ignore = "the full sweep: 10⁶ rays per icosphere, a few seconds"]
fn full_sweep_of_random_rays_from_inside_a_jittered_icosphere() {
    icosphere_sweep(SWEEP_RAYS);
}

#[test]
fn random_rays_from_inside_the_closed_cornell_blocks_always_hit() {
    let cornell = cornell_box();
    for (seed, first) in [(3u64, 10usize), (4, 20)] {
        let scene = scene_of(closed_block(&cornell, first));
        let corners = block_corners(&cornell, first);
        let mut rng = Rng::seeded(seed);
        let mut failures = Vec::new();
        let n = RANDOM_RAYS / 4;
        for i in 0..n {
            let ray = Ray::new(inside_block(&mut rng, &corners), unit(&mut rng));
            failures.extend(check_hits(&scene, &ray, || {
                format!("block {first}, ray {i}")
            }));
        }
        assert_no_failures(failures, n as usize, "random rays");
    }
}

/// Targets on a mesh's vertices and along its edges: each vertex, and points at 1/4, 1/2 and
/// 3/4 of each edge (the `f32` ray aimed there passes within rounding of the shared edge).
fn vertex_and_edge_targets(tris: &[[Vec3; 3]]) -> Vec<Vec3> {
    let mut targets = Vec::new();
    for t in tris {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            targets.push(a);
            for f in [0.25, 0.5, 0.75] {
                targets.push(a.lerp(b, f));
            }
        }
    }
    targets
}

#[test]
fn rays_aimed_at_vertices_and_along_edges_hit() {
    let cornell = cornell_box();
    let (verts, faces) = icosphere(2, Vec3::ZERO, 5);
    let sphere = triangles(&verts, &faces);
    let mut rng = Rng::seeded(5);
    let sphere_origins: Vec<Vec3> = (0..4)
        .map(|_| unit(&mut rng) * ORIGIN_RADIUS * rng.next_f32())
        .collect();
    let mut meshes = vec![("icosphere", sphere, sphere_origins)];
    for first in [10, 20] {
        let corners = block_corners(&cornell, first);
        let origins = (0..4).map(|_| inside_block(&mut rng, &corners)).collect();
        meshes.push(("cornell block", closed_block(&cornell, first), origins));
    }
    let mut total = 0;
    let mut failures = Vec::new();
    for (name, tris, origins) in meshes {
        let scene = scene_of(tris.clone());
        for origin in origins {
            for target in vertex_and_edge_targets(&tris) {
                let ray = Ray::new(origin, target - origin);
                total += 1;
                failures.extend(check_hits(&scene, &ray, || name.to_string()));
            }
        }
    }
    assert_no_failures(failures, total, "vertex and edge rays");
}

/// The cube [−1, 1]³ as 12 triangles sharing its 8 corners, each face split along a diagonal.
fn cube() -> Vec<[Vec3; 3]> {
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { -1.0 } else { 1.0 },
        )
    };
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    quads
        .iter()
        .flat_map(|&[a, b, cc, d]| [[c(a), c(b), c(cc)], [c(a), c(cc), c(d)]])
        .collect()
}

#[test]
fn rays_exactly_through_cube_vertices_edges_and_diagonals_hit() {
    // Dyadic origins and targets: every coordinate is exact, so each ray passes exactly
    // through the vertex or edge point it is aimed at.
    let tris = cube();
    let scene = scene_of(tris.clone());
    let origins = [
        Vec3::ZERO,
        Vec3::new(0.5, -0.25, 0.125),
        Vec3::new(-0.75, 0.5, 0.625),
    ];
    let mut total = 0;
    let mut failures = Vec::new();
    for origin in origins {
        let mut targets = vertex_and_edge_targets(&tris);
        for k in -8..=8 {
            let s = k as f32 / 8.0;
            // Points on every cube edge and every face diagonal (s, ±s on a face).
            for (a, b) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                targets.push(Vec3::new(s, a, b));
                targets.push(Vec3::new(a, s, b));
                targets.push(Vec3::new(a, b, s));
                targets.push(Vec3::new(a, s, s * b));
                targets.push(Vec3::new(s, a, s * b));
                targets.push(Vec3::new(s, s * b, a));
            }
        }
        for target in targets {
            total += 1;
            let ray = Ray::new(origin, target - origin);
            failures.extend(check_hits(&scene, &ray, || "cube".to_string()));
        }
    }
    assert_no_failures(failures, total, "exact vertex, edge and diagonal rays");
}

#[test]
fn cornell_creases_leave_no_background_pixel() {
    // The course's camera rays d = (x − W/2, y − H/2, W) at integer x, y: the diagonal x = y
    // runs exactly through the floor/wall and ceiling/wall creases, column 0 and row 0 through
    // the open front's edges, and the centre row and column are parallel to four walls.
    const W: i32 = 500;
    let scene = cornell_box();
    let origin = Vec3::new(0.0, 0.0, -3.0);
    let mut failures = Vec::new();
    for y in 0..W {
        for x in 0..W {
            let dir = Vec3::new((x - W / 2) as f32, (y - W / 2) as f32, W as f32);
            let ray = Ray::new(origin, dir);
            failures.extend(check_hits(&scene, &ray, || format!("pixel ({x}, {y})")));
        }
    }
    assert_no_failures(failures, (W * W) as usize, "Cornell camera rays");
}
