//! The acceleration structures answer exactly as testing every triangle does: the BVH and the
//! flat object list against a brute-force loop (same triangle, bit-identical `t` and
//! barycentrics, same any-hit answer) over thousands of seeded rays, on random soups, a closed
//! icosphere (rays through shared edges and vertices, where hits tie), degenerate layouts and
//! extreme scales; whole frames are byte-identical whichever structure is used; and the BVH is
//! the same with any number of threads.

mod common;

use common::{Rng, in_cube, soup, uniform};
use glam::Vec3;
use raytty::accel::{BVH_THRESHOLD, MAX_DEPTH};
use raytty::geometry::intersect_watertight;
use raytty::scene::procedural::displaced_icosphere;
use raytty::{
    AccelKind, Camera, Effects, Hit, Material, Options, PointLight, Ray, Scene, SceneBuilder,
    Stage, Triangle, cornell_box,
};

/// The answer by definition: the smallest `t`, ties to the lowest index.
fn brute_force(triangles: &[Triangle], ray: &Ray, t_max: f32) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, t) in triangles.iter().enumerate() {
        if let Some(h) = intersect_watertight(ray, &t.v, t_max)
            && best.is_none_or(|b| h.t < b.t)
        {
            best = Some(Hit {
                t: h.t,
                b: h.b,
                triangle: i as u32,
            });
        }
    }
    best
}

fn brute_occluded(triangles: &[Triangle], ray: &Ray, t_max: f32) -> bool {
    triangles
        .iter()
        .any(|t| intersect_watertight(ray, &t.v, t_max).is_some())
}

fn scene_of(triangles: Vec<[Vec3; 3]>, kind: AccelKind) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::splat(0.7)));
    b.object(triangles, m);
    b.light(PointLight {
        position: Vec3::new(0.3, -0.8, -0.5),
        power: Vec3::splat(14.0),
    });
    b.accel(kind);
    b.build("test", Camera::default(), Effects::SEED).unwrap()
}

/// Seeded rays: random ones, and ones aimed at vertices and edge midpoints (where
/// neighbouring triangles tie), each with `t_max` = ∞ or a random fraction of the way.
fn rays(seed: u64, triangles: &[Triangle], n: usize, reach: f32) -> Vec<(Ray, f32)> {
    let mut rng = Rng::seeded(seed);
    (0..n)
        .map(|i| {
            let origin = in_cube(&mut rng, reach);
            let target = if triangles.is_empty() || i % 3 == 0 {
                in_cube(&mut rng, reach)
            } else {
                let t = &triangles[(rng.next_u64() % triangles.len() as u64) as usize];
                let k = (rng.next_u64() % 3) as usize;
                if i % 3 == 1 {
                    t.v[k]
                } else {
                    t.v[k] * 0.5 + t.v[(k + 1) % 3] * 0.5
                }
            };
            let mut dir = target - origin;
            if dir == Vec3::ZERO {
                dir = Vec3::Z;
            }
            let t_max = if i % 4 == 0 {
                uniform(&mut rng, 0.2, 1.5)
            } else {
                f32::INFINITY
            };
            (Ray::new(origin, dir), t_max)
        })
        .collect()
}

/// Every query on `triangles` answers as the brute-force loop, with both structures.
fn assert_exact(triangles: Vec<[Vec3; 3]>, seed: u64, n_rays: usize, reach: f32) {
    let bvh = scene_of(triangles.clone(), AccelKind::Bvh);
    let flat = scene_of(triangles, AccelKind::Flat);
    assert_eq!(bvh.accel_stats().kind, AccelKind::Bvh);
    assert_eq!(flat.accel_stats().kind, AccelKind::Flat);
    let tris = bvh.triangles();
    let mut hits = 0;
    for (i, (ray, t_max)) in rays(seed, tris, n_rays, reach).into_iter().enumerate() {
        let want = brute_force(tris, &ray, t_max);
        let context = || format!("ray {i}: {ray:?} t_max {t_max}");
        for (name, scene) in [("bvh", &bvh), ("flat", &flat)] {
            let got = scene.intersect(&ray, t_max);
            assert_eq!(got, want, "{name} closest hit, {}", context());
            if let (Some(g), Some(w)) = (got, want) {
                assert_eq!(g.t.to_bits(), w.t.to_bits(), "{name} t, {}", context());
            }
            assert_eq!(
                scene.occluded(&ray, t_max),
                brute_occluded(tris, &ray, t_max),
                "{name} any hit, {}",
                context()
            );
        }
        hits += usize::from(want.is_some());
    }
    // The rays must exercise hits, not only misses.
    if !tris.is_empty() {
        assert!(hits > n_rays / 4, "only {hits} of {n_rays} rays hit");
    }
}

#[test]
fn random_soups_match_brute_force() {
    for (seed, n, size) in [(1, 50, 0.3), (2, 2_000, 0.1), (3, 5_000, 0.02)] {
        assert_exact(soup(seed, n, 1.0, size, 1.0), seed, 3_000, 1.5);
    }
}

#[test]
fn icosphere_matches_brute_force_through_shared_edges_and_vertices() {
    // 8000 triangles, closed: rays aimed at vertices and edges hit several triangles at once.
    assert_exact(displaced_icosphere(20, 0.1), 7, 4_000, 2.0);
}

#[test]
fn empty_scene_has_no_hits() {
    for kind in [AccelKind::Flat, AccelKind::Bvh] {
        let s = scene_of(Vec::new(), kind);
        let stats = s.accel_stats();
        assert_eq!((stats.triangles, stats.nodes, stats.depth), (0, 0, 0));
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert_eq!(s.intersect(&ray, f32::INFINITY), None);
        assert!(!s.occluded(&ray, f32::INFINITY));
    }
}

#[test]
fn one_triangle() {
    let tri = [
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    let s = scene_of(vec![tri], AccelKind::Bvh);
    let stats = s.accel_stats();
    assert_eq!((stats.triangles, stats.nodes, stats.depth), (1, 1, 1));
    let hit = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY);
    assert_eq!(hit.map(|h| (h.triangle, h.t)), Some((0, 1.0)));
    assert!(s.occluded(&Ray::new(Vec3::ZERO, Vec3::Z), 2.0));
    assert!(!s.occluded(&Ray::new(Vec3::ZERO, Vec3::Z), 0.5));
    assert_exact(vec![tri], 11, 500, 2.0);
}

#[test]
fn identical_centroids_terminate_and_tie_to_the_lowest_index() {
    // Copies of one triangle, scaled about and turned in quarter turns about the centre of its
    // box: every box has the same centre, so no centroid split exists. Coplanar, so rays hit
    // many at the same t.
    let base = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let mut tris = Vec::new();
    for i in 0..3_000 {
        let s = 0.2 + (i % 37) as f32 * 0.1;
        let turn = |v: Vec3| match i % 4 {
            0 => v,
            1 => Vec3::new(-v.y, v.x, v.z),
            2 => Vec3::new(-v.x, -v.y, v.z),
            _ => Vec3::new(v.y, -v.x, v.z),
        };
        tris.push(base.map(|v| turn(v) * s));
    }
    let s = scene_of(tris.clone(), AccelKind::Bvh);
    let stats = s.accel_stats();
    assert!(stats.depth as usize <= MAX_DEPTH, "depth {}", stats.depth);
    let ray = Ray::new(Vec3::new(0.01, 0.02, -2.0), Vec3::Z);
    assert_eq!(
        s.intersect(&ray, f32::INFINITY),
        brute_force(s.triangles(), &ray, f32::INFINITY)
    );
    assert_exact(tris, 12, 2_000, 3.0);
    // Exact duplicates too: the same t, so the first one wins.
    let s = scene_of(vec![base; 1_000], AccelKind::Bvh);
    assert!(s.accel_stats().depth as usize <= MAX_DEPTH);
    assert_eq!(
        s.intersect(&ray, f32::INFINITY).map(|h| h.triangle),
        Some(0)
    );
}

#[test]
fn huge_and_tiny_coordinates() {
    // The triangle test itself finds hits from about 1e-15 to 1e15 (beyond, the edge functions'
    // products underflow or overflow f32); further out the BVH must still agree. At 2e38 the
    // scene's extent overflows f32 (its boxes' areas would too): the build must
    // still split, and rays must find what the loop finds.
    for (scale, reach) in [
        (1e-15, 1.5),
        (1e-6, 1.5),
        (1e6, 1.5),
        (1e15, 1.5),
        (1e30, 1.5),
        (2e38, 0.1),
    ] {
        let bvh = scene_of(soup(21, 1_000, 1.0, 0.2, scale), AccelKind::Bvh);
        let t = bvh.triangles();
        assert!(bvh.accel_stats().nodes > 100, "scale {scale}: not split");
        let mut hits = 0;
        for (i, (ray, t_max)) in rays(22, t, 2_000, reach * scale).into_iter().enumerate() {
            let want = brute_force(t, &ray, t_max);
            assert_eq!(bvh.intersect(&ray, t_max), want, "scale {scale} ray {i}");
            assert_eq!(bvh.occluded(&ray, t_max), brute_occluded(t, &ray, t_max));
            hits += usize::from(want.is_some());
        }
        assert!(hits > 500 || scale > 1e15, "scale {scale}: {hits} hits");
    }
}

fn frame_bytes(scene: &Scene, stage: Stage, w: u32, h: u32) -> (Vec<u8>, raytty::RayCounts) {
    let settings = stage.settings(scene.effects());
    let f = scene.render(&Options {
        width: w,
        height: h,
        settings: Some(settings),
        ..Options::default()
    });
    let bytes = f
        .image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    (bytes, f.stats.rays)
}

#[test]
fn cornell_frames_are_identical_with_either_structure() {
    let flat = cornell_box().with_accel(AccelKind::Flat);
    let bvh = cornell_box().with_accel(AccelKind::Bvh);
    assert_eq!(bvh.accel_stats().kind, AccelKind::Bvh);
    for stage in Stage::ALL {
        assert_eq!(
            frame_bytes(&flat, stage, 120, 90),
            frame_bytes(&bvh, stage, 120, 90),
            "{stage:?}"
        );
    }
}

#[test]
fn soup_frames_are_identical_with_either_structure() {
    let tris = soup(31, 3_000, 1.0, 0.15, 1.0);
    let flat = scene_of(tris.clone(), AccelKind::Flat);
    let bvh = scene_of(tris, AccelKind::Bvh);
    for stage in [Stage::Flat, Stage::Shadows, Stage::Gi] {
        assert_eq!(
            frame_bytes(&flat, stage, 60, 40),
            frame_bytes(&bvh, stage, 60, 40),
            "{stage:?}"
        );
    }
}

#[test]
fn the_cornell_box_uses_the_measured_choice() {
    let s = cornell_box();
    assert_eq!(s.accel_stats().kind, AccelKind::for_triangles(30));
    assert_eq!(s.accel_stats().triangles, 30);
    assert_eq!(AccelKind::for_triangles(BVH_THRESHOLD), AccelKind::Bvh);
    assert_eq!(AccelKind::for_triangles(BVH_THRESHOLD - 1), AccelKind::Flat);
}

/// The 1M-triangle sphere (k = 224) against brute force: slow (each brute-force ray tests a
/// million triangles; 17 s here), so run by hand: `cargo test --test accel -- --ignored`.
#[test]
#[ignore]
fn million_triangle_icosphere_matches_brute_force() {
    assert_exact(displaced_icosphere(224, 0.08), 41, 300, 2.0);
}

#[test]
fn wide_nodes_of_every_fill_match_brute_force() {
    // Traversal reads the binary tree collapsed into nodes of up to eight children. Meshes
    // from a single leaf up to a few thousand triangles give roots and nodes with every number
    // of children and leaves of every size; each must answer as the loop does.
    for n in [1, 2, 9, 17, 40, 64, 100, 300, 1_000, 4_000] {
        let tris = soup(40 + n as u64, n, 1.0, 0.3, 1.0);
        assert_exact(tris, 41 + n as u64, 400, 1.5);
    }
}
