//! The SIMD paths (portable, SSE2, AVX2: each forced in turn) answer exactly as the scalar
//! watertight test does: the same hit lanes with the same `t` and barycentrics, bit for bit
//! (but for lanes handed back to the scalar test's `f64` redo, the same on every path); the
//! same closest hit (`t`, barycentrics, index) and any-hit answer from both structures; and the
//! same frames. The rays are the stability suite's and the accel tests' kinds: through
//! the shared edges and vertices of a jittered icosphere (also at a 1e5 offset), grazing and
//! in-plane rays, random soups, and coordinates from 1e-15 to 2e38. A path this CPU lacks is
//! skipped (and says so).

mod common;

use common::{Rng, in_cube, log_uniform, soup, uniform, unit};
use glam::Vec3;
use raytty::accel::tri4::{Best8, Hits, Tri4, hits as hits_in, hits2};
use raytty::accel::{Isa, TILE_RAYS, TileCache};
use raytty::geometry::{RayTile, TriHit, intersect_watertight};
use raytty::scene::procedural::displaced_icosphere;
use raytty::{
    AccelKind, Camera, Effects, Hit, Material, Options, PointLight, Ray, Scene, SceneBuilder,
    Stage, cornell_box,
};

/// The paths this CPU runs (always the portable one and, on x86-64, SSE2).
fn paths() -> Vec<Isa> {
    let all: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.available()).collect();
    for isa in Isa::ALL {
        if !isa.available() {
            eprintln!(
                "note: this CPU has no {}; that path is not tested",
                isa.name()
            );
        }
    }
    all
}

/// Rays at the mesh's vertices and edge midpoints (ties between neighbours), random rays, and
/// rays grazing or lying in a triangle's plane, each with `t_max` ∞ or a fraction of the way.
fn rays(seed: u64, tris: &[[Vec3; 3]], n: usize, reach: f32, centre: Vec3) -> Vec<(Ray, f32)> {
    let mut rng = Rng::seeded(seed);
    (0..n)
        .map(|i| {
            let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
            let k = (rng.next_u64() % 3) as usize;
            let origin = centre + in_cube(&mut rng, reach);
            let (origin, target) = match i % 5 {
                0 => (origin, centre + in_cube(&mut rng, reach)),
                1 => (origin, t[k]),
                2 => (origin, t[k] * 0.5 + t[(k + 1) % 3] * 0.5),
                // In the plane of the triangle, through its edge.
                3 => {
                    let a = t[k] * 0.5 + t[(k + 1) % 3] * 0.5;
                    (a + (t[k] - t[(k + 2) % 3]) * uniform(&mut rng, 0.5, 3.0), a)
                }
                // Grazing: just off the plane, by an angle down to 1e-7 rad.
                _ => {
                    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                    let a = t[k] * 0.3 + t[(k + 1) % 3] * 0.3 + t[(k + 2) % 3] * 0.4;
                    let along = (t[k] - a).normalize();
                    let angle = log_uniform(&mut rng, -7.0, -2.0);
                    let d = along + n * angle;
                    (a - d * (t[k] - a).length() * 2.0, a)
                }
            };
            let origin = if origin.is_finite() { origin } else { centre };
            let mut dir = target - origin;
            if dir == Vec3::ZERO || !dir.is_finite() {
                dir = unit(&mut rng);
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

/// Every path's hits in every block, one block and two at a time, against the scalar test: a
/// lane is hit exactly when `intersect_watertight` hits it, with its `t` and barycentrics bit
/// for bit, unless the kernel hands it back to be redone in `f64` (an edge function rounded to
/// 0), and every path hands back the same lanes. Returns the number of scalar hits seen
/// and of lanes handed back.
fn assert_kernels_agree(tris: &[[Vec3; 3]], rays: &[(Ray, f32)], what: &str) -> (usize, usize) {
    let blocks = Tri4::pack(tris.iter().copied());
    let paths = paths();
    let (mut hits, mut redone) = (0, 0);
    let bits = |h: &Hits, l: usize| (h.t[l].to_bits(), [0, 1, 2].map(|k| h.b[k][l].to_bits()));
    for (r, &(ray, t_max)) in rays.iter().enumerate() {
        let scalar: Vec<Option<TriHit>> = blocks
            .iter()
            .flat_map(|b| (0..4).map(|l| intersect_watertight(&ray, &b.vertices(l), t_max)))
            .collect();
        hits += scalar.iter().flatten().count();
        for &isa in &paths {
            let mut redo_lanes = vec![];
            for (b, block) in blocks.iter().enumerate() {
                let got = hits_in(isa, block, &ray, t_max);
                for l in 0..4 {
                    let i = b * 4 + l;
                    let at =
                        || format!("{what}: ray {r} {ray:?} t_max {t_max} triangle {i} on {isa:?}");
                    if got.redo & 1 << l != 0 {
                        assert!(got.mask & 1 << l == 0, "{}: hit and redo", at());
                        redo_lanes.push(i);
                        continue;
                    }
                    match scalar[i] {
                        Some(h) => {
                            assert!(got.mask & 1 << l != 0, "{}: scalar hit {h:?} missed", at());
                            assert_eq!(
                                bits(&got, l),
                                (h.t.to_bits(), h.b.map(f32::to_bits)),
                                "{}: {h:?}",
                                at()
                            );
                        }
                        None => {
                            assert!(
                                got.mask & 1 << l == 0,
                                "{}: a hit the scalar test misses",
                                at()
                            )
                        }
                    }
                }
            }
            if isa == Isa::Portable {
                redone += redo_lanes.len();
            }
            // Two blocks at once (AVX2's eight lanes) give both blocks' lanes.
            for (p, pair) in blocks.chunks(2).enumerate().filter(|(_, p)| p.len() == 2) {
                let one = [0, 1].map(|k| hits_in(isa, &pair[k], &ray, t_max));
                let two = hits2(isa, &pair[0], &pair[1], &ray, t_max);
                let at = || {
                    format!(
                        "{what}: ray {r} {ray:?} blocks {} and {} on {isa:?}",
                        2 * p,
                        2 * p + 1
                    )
                };
                assert_eq!(two.mask, one[0].mask | one[1].mask << 4, "{}", at());
                assert_eq!(two.redo, one[0].redo | one[1].redo << 4, "{}", at());
                for l in 0..8 {
                    if two.mask & 1 << l != 0 {
                        assert_eq!(bits(&two, l), bits(&one[l / 4], l % 4), "{} lane {l}", at());
                    }
                }
            }
        }
        // Every path hands back the same lanes (the one-lane form's too).
        let redo_of = |isa: Isa| -> Vec<u32> {
            blocks
                .iter()
                .map(|b| hits_in(isa, b, &ray, t_max).redo)
                .collect()
        };
        for &isa in &paths {
            assert_eq!(
                redo_of(isa),
                redo_of(Isa::Portable),
                "{what}: ray {r} {ray:?} on {isa:?}"
            );
        }
    }
    (hits, redone)
}

/// The answer by definition: the smallest `t`, ties to the lowest index.
fn brute_force(tris: &[[Vec3; 3]], ray: &Ray, t_max: f32) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, v) in tris.iter().enumerate() {
        if let Some(h) = intersect_watertight(ray, v, t_max)
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

fn scene_of(objects: &[Vec<[Vec3; 3]>], kind: AccelKind) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::splat(0.7)));
    for o in objects {
        b.object(o.iter().copied(), m);
    }
    b.light(PointLight {
        position: Vec3::new(0.3, -0.8, -0.5),
        power: Vec3::splat(14.0),
    });
    b.accel(kind);
    b.build("test", Camera::default(), Effects::SEED).unwrap()
}

/// Both structures on every path answer every query as the brute-force loop, bit for bit.
fn assert_structures_agree(objects: &[Vec<[Vec3; 3]>], rays: &[(Ray, f32)], what: &str) {
    let tris: Vec<[Vec3; 3]> = objects.concat();
    for kind in [AccelKind::Flat, AccelKind::Bvh] {
        let scene = scene_of(objects, kind);
        for isa in paths() {
            let s = scene.clone().with_isa(isa).expect("available");
            assert_eq!(s.isa(), isa);
            for (r, &(ray, t_max)) in rays.iter().enumerate() {
                let want = brute_force(&tris, &ray, t_max);
                let got = s.intersect(&ray, t_max);
                assert_eq!(
                    got.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                    want.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                    "{what}: ray {r} {ray:?} t_max {t_max}, {kind:?} on {isa:?}"
                );
                assert_eq!(
                    s.occluded(&ray, t_max),
                    want.is_some(),
                    "{what}: ray {r} {ray:?} any-hit, {kind:?} on {isa:?}"
                );
            }
        }
    }
}

/// A jittered icosphere (shared vertices: rays through its edges and vertices tie) split into
/// a few objects, around `centre`.
fn icosphere(centre: Vec3) -> Vec<Vec<[Vec3; 3]>> {
    let tris: Vec<[Vec3; 3]> = displaced_icosphere(4, 0.2)
        .into_iter()
        .map(|v| v.map(|p| p + centre))
        .collect();
    tris.chunks(50).map(<[_]>::to_vec).collect()
}

#[test]
fn kernels_match_the_scalar_test_on_an_icosphere_through_edges_and_vertices() {
    for centre in [Vec3::ZERO, Vec3::splat(1e5)] {
        let tris = icosphere(centre).concat();
        let rays = rays(1, &tris, 3_000, 0.7, centre);
        let (hits, redone) = assert_kernels_agree(&tris, &rays, &format!("icosphere at {centre}"));
        assert!(hits > 2_000, "{hits} hits");
        // Rays through shared vertices round edge functions to 0: the f64 redo is exercised.
        assert!(redone > 100, "{redone} lanes redone");
    }
}

#[test]
fn kernels_match_the_scalar_test_on_soups_from_1e_minus_15_to_2e38() {
    for (seed, scale, reach) in [
        (2, 1e-15, 1.5),
        (3, 1e-6, 1.5),
        (4, 1.0, 1.5),
        (5, 1e6, 1.5),
        (6, 1e15, 1.5),
        (7, 1e30, 1.5),
        (8, 2e38, 0.1),
    ] {
        let tris = soup(seed, 64, 1.0, 0.3, scale);
        let rays = rays(seed, &tris, 1_500, reach * scale, Vec3::ZERO);
        assert_kernels_agree(&tris, &rays, &format!("soup at scale {scale}"));
    }
}

#[test]
fn kernels_match_on_the_cornell_box_camera_and_shadow_rays() {
    let scene = cornell_box();
    let tris: Vec<[Vec3; 3]> = scene.triangles().iter().map(|t| t.v).collect();
    let cam = scene.camera().rays(100, 100);
    let light = scene.lights()[0].position;
    let mut rays = vec![];
    for y in 0..100 {
        for x in 0..100 {
            let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
            rays.push((ray, f32::INFINITY));
            if let Some(h) = scene.intersect(&ray, f32::INFINITY) {
                let p = ray.at(h.t);
                rays.push((Ray::new(p, light - p), 0.9999));
            }
        }
    }
    assert!(assert_kernels_agree(&tris, &rays, "cornell").0 > 10_000);
}

#[test]
fn structures_on_every_path_match_brute_force() {
    for centre in [Vec3::ZERO, Vec3::splat(1e5)] {
        let objects = icosphere(centre);
        let tris = objects.concat();
        let rays = rays(11, &tris, 2_000, 0.7, centre);
        assert_structures_agree(&objects, &rays, &format!("icosphere at {centre}"));
    }
    for (seed, scale) in [(12, 1e-15), (13, 1.0), (14, 1e30)] {
        // Many small objects: more than the flat list sorts by entry distance.
        let objects: Vec<Vec<[Vec3; 3]>> = soup(seed, 300, 1.0, 0.2, scale)
            .chunks(3)
            .map(<[_]>::to_vec)
            .collect();
        let tris = objects.concat();
        let rays = rays(seed, &tris, 1_000, 1.5 * scale, Vec3::ZERO);
        assert_structures_agree(&objects, &rays, &format!("soup at scale {scale}"));
    }
}

/// Tiles of rays from one origin (as the camera's): a grid of up to 8×8 directions around a
/// vertex, an edge's midpoint or a random point of `tris`, spaced from 1e-7 to 0.3 of the
/// distance, some with a ray exactly through a vertex (an edge function of 0) and some from
/// an origin on a triangle's plane.
fn tiles(seed: u64, tris: &[[Vec3; 3]], n: usize, reach: f32, centre: Vec3) -> Vec<(RayTile, f32)> {
    let mut rng = Rng::seeded(seed);
    (0..n)
        .map(|i| {
            let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
            let k = (rng.next_u64() % 3) as usize;
            let origin = match i % 7 {
                // In the triangle's plane.
                6 => t[k] + (t[k] - t[(k + 1) % 3]) * uniform(&mut rng, 0.5, 3.0),
                _ => centre + in_cube(&mut rng, reach),
            };
            let target = match i % 3 {
                0 => t[k],
                1 => t[k] * 0.5 + t[(k + 1) % 3] * 0.5,
                _ => centre + in_cube(&mut rng, reach),
            };
            let dist = (target - origin).length();
            let spacing = log_uniform(&mut rng, -7.0, -0.5) * dist;
            let (u, v) = (target - origin).normalize().any_orthonormal_pair();
            let (w, h) = (1 + rng.next_u64() % 8, 1 + rng.next_u64() % 8);
            let mut rays: Vec<Ray> = (0..h)
                .flat_map(|y| {
                    (0..w).map(move |x| (x as f32 - w as f32 / 2.0, y as f32 - h as f32 / 2.0))
                })
                .map(|(x, y)| target + u * (x * spacing) + v * (y * spacing) - origin)
                .filter(|d| *d != Vec3::ZERO && d.is_finite())
                .map(|d| Ray::new(origin, d))
                .collect();
            if i % 2 == 0 && t[k] != origin {
                let l = (rng.next_u64() % rays.len().max(1) as u64) as usize;
                let exact = Ray::new(origin, t[k] - origin);
                if l < rays.len() {
                    rays[l] = exact;
                } else {
                    rays.push(exact);
                }
            }
            let t_max = if i % 5 == 0 {
                uniform(&mut rng, 0.2, 1.5)
            } else {
                f32::INFINITY
            };
            (RayTile::from_rays(&rays), t_max)
        })
        .collect()
}

/// `Scene::intersect_tile` on both structures and every path gives each ray of a tile the
/// brute-force hit, bit for bit (`t`, barycentrics, index), one cache kept across all tiles;
/// and `Scene::intersect_tile_best` the same hits in lanes.
fn assert_tiles_agree(objects: &[Vec<[Vec3; 3]>], tiles: &[(RayTile, f32)], what: &str) {
    let tris: Vec<[Vec3; 3]> = objects.concat();
    for kind in [AccelKind::Flat, AccelKind::Bvh] {
        let scene = scene_of(objects, kind);
        for isa in paths() {
            let s = scene.clone().with_isa(isa).expect("available");
            let mut cache = TileCache::default();
            let mut lanes_cache = TileCache::default();
            for (i, (tile, t_max)) in tiles.iter().enumerate() {
                let mut hits = vec![None; tile.len()];
                s.intersect_tile(tile, *t_max, &mut hits, &mut cache);
                let mut best = [Best8::NONE; TILE_RAYS / 8];
                s.intersect_tile_best(tile, *t_max, &mut best, &mut lanes_cache);
                for (r, got) in hits.iter().enumerate() {
                    let lane = best[r / 8].hit(r % 8);
                    assert_eq!(
                        got.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                        lane.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                        "{what}: tile {i} ray {r} in lanes, {kind:?} on {isa:?}"
                    );
                    let ray = &tile.ray(r);
                    let want = brute_force(&tris, ray, *t_max);
                    assert_eq!(
                        got.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                        want.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                        "{what}: tile {i} ray {r} {ray:?} t_max {t_max}, {kind:?} on {isa:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn tiles_of_rays_on_every_path_match_brute_force() {
    // At most 64 triangles: the flat list culls tiles triangle by triangle up to there.
    for centre in [Vec3::ZERO, Vec3::splat(1e5)] {
        let objects: Vec<Vec<[Vec3; 3]>> = icosphere(centre).concat()[..60]
            .chunks(12)
            .map(<[_]>::to_vec)
            .collect();
        let tris = objects.concat();
        let tiles = tiles(21, &tris, 300, 0.7, centre);
        assert_tiles_agree(&objects, &tiles, &format!("icosphere cap at {centre}"));
    }
    for (seed, scale) in [(22, 1e-15), (23, 1e-6), (24, 1.0), (25, 1e6), (26, 1e30)] {
        let objects: Vec<Vec<[Vec3; 3]>> = soup(seed, 60, 1.0, 0.3, scale)
            .chunks(10)
            .map(<[_]>::to_vec)
            .collect();
        let tris = objects.concat();
        let tiles = tiles(seed, &tris, 300, 1.5 * scale, Vec3::ZERO);
        assert_tiles_agree(&objects, &tiles, &format!("soup at scale {scale}"));
    }
    let scene = cornell_box();
    let objects: Vec<Vec<[Vec3; 3]>> = vec![scene.triangles().iter().map(|t| t.v).collect()];
    let cam = scene.camera();
    let mut rng = Rng::seeded(27);
    // The camera's own tiles (`RayGen::tile`), whole and cut at the image's edges.
    let tiles: Vec<(RayTile, f32)> = (0..200)
        .map(|_| {
            let g = Camera {
                position: cam.position + in_cube(&mut rng, 0.8),
                yaw: uniform(&mut rng, -3.0, 3.0),
                pitch: uniform(&mut rng, -1.0, 1.0),
                ..Camera::default()
            }
            .rays(61, 45);
            let (x0, y0) = (
                (rng.next_u64() % 61) as usize,
                (rng.next_u64() % 45) as usize,
            );
            let mut tile = RayTile::default();
            g.tile(
                Isa::detect(),
                x0,
                y0,
                (61 - x0).min(8),
                (45 - y0).min(8),
                &mut tile,
            );
            (tile, f32::INFINITY)
        })
        .collect();
    assert_tiles_agree(&objects, &tiles, "cornell cameras");
}

/// A `w`×`h` grid of rays from `origin` around `target`, `spacing` apart.
fn grid(origin: Vec3, target: Vec3, spacing: f32, w: u64, h: u64) -> RayTile {
    let (u, v) = (target - origin).normalize().any_orthonormal_pair();
    let rays: Vec<Ray> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x as f32 - w as f32 / 2.0, y as f32 - h as f32 / 2.0)))
        .map(|(x, y)| target + u * (x * spacing) + v * (y * spacing) - origin)
        .filter(|d| *d != Vec3::ZERO && d.is_finite())
        .map(|d| Ray::new(origin, d))
        .collect();
    RayTile::from_rays(&rays)
}

/// Tiles where the watertight test's error bound decides (the tile kernel may skip it only
/// where `flat/tile.rs` proves it passes; debug builds also assert that on every such
/// packet): origins just off a triangle's plane (a determinant within its own error), and
/// triangles whose nearest vertex is a tiny fraction of the farthest's depth, seen from
/// close to it (a `t` within its error bound).
#[test]
fn tiles_near_the_error_bound_match_brute_force() {
    let mut rng = Rng::seeded(31);
    for scale in [1e-3, 1.0, 1e3] {
        let tris = soup(32, 40, 1.0, 0.3, scale);
        let objects = vec![tris.clone()];
        let mut tiles = vec![];
        for i in 0..400 {
            let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
            let k = (rng.next_u64() % 3) as usize;
            let c = (t[0] + t[1] + t[2]) / 3.0;
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            let size = (t[k] - c).length();
            let (origin, target) = if i % 2 == 0 {
                // Just off the plane, outside the triangle, looking at its middle.
                let side = c + (t[k] - c) * uniform(&mut rng, 1.5, 4.0);
                let off = size * log_uniform(&mut rng, -9.0, -2.0);
                let origin = side + n * if i % 4 == 0 { off } else { -off };
                (
                    origin,
                    c + (t[(k + 1) % 3] - c) * uniform(&mut rng, -0.3, 0.3),
                )
            } else {
                // Close in front of a vertex, looking past it along the triangle.
                let d = size * log_uniform(&mut rng, -8.0, -2.0);
                let origin = t[k] + (n * uniform(&mut rng, -1.0, 1.0) - (c - t[k]).normalize()) * d;
                (
                    origin,
                    t[k] + (c - t[k]) * log_uniform(&mut rng, -7.0, -0.3),
                )
            };
            let dist = (target - origin).length();
            let spacing = dist * log_uniform(&mut rng, -7.0, -1.0);
            let (w, h) = (1 + rng.next_u64() % 8, 1 + rng.next_u64() % 8);
            tiles.push((grid(origin, target, spacing, w, h), f32::INFINITY));
        }
        assert_tiles_agree(
            &objects,
            &tiles,
            &format!("near the bound at scale {scale}"),
        );
    }
}

#[test]
fn cornell_frames_are_identical_on_every_path() {
    // 101×61: tiles of 5 columns or 5 rows, whose odd number of packets of eight rays leaves
    // AVX-512's last packet to AVX2.
    let scene = cornell_box();
    // One sample (tiles), and three (anti-aliased: a pass of tiles per sample; path-traced
    // stages one ray at a time).
    for (stage, samples) in Stage::ALL.into_iter().flat_map(|s| [(s, 1), (s, 3)]) {
        let mut settings = stage.settings(scene.effects());
        settings.effects.samples = samples;
        let frame = |s: &Scene| {
            let f = s.render(&Options {
                width: 101,
                height: 61,
                settings: Some(settings),
                ..Options::default()
            });
            let bits: Vec<u32> = f
                .image
                .pixels
                .iter()
                .flat_map(|p| p.to_array().map(f32::to_bits))
                .collect();
            (bits, f.stats.rays)
        };
        let want = frame(&scene.clone().with_isa(Isa::Portable).unwrap());
        for isa in paths() {
            for kind in [AccelKind::Flat, AccelKind::Bvh] {
                let s = scene.clone().with_accel(kind).with_isa(isa).unwrap();
                assert!(
                    frame(&s) == want,
                    "{stage:?} at {samples} spp differs on {isa:?} {kind:?}"
                );
            }
        }
    }
}

#[test]
fn bvh_batches_on_every_path_match_brute_force() {
    // The BVH answers a tile of camera rays (`Scene::intersect_tile`) and a batch of shadow
    // rays (`Scene::occluded_each`) with the path picked once for the batch: each answer must
    // be the brute-force one, on every path, through a tree of many leaves (8000 triangles).
    let centre = Vec3::splat(0.5);
    let tris: Vec<[Vec3; 3]> = displaced_icosphere(20, 0.1)
        .into_iter()
        .map(|v| v.map(|p| p + centre))
        .collect();
    let objects = vec![tris.clone()];
    let tiles = tiles(31, &tris, 120, 2.0, centre);
    let scene = scene_of(&objects, AccelKind::Bvh);
    assert_eq!(scene.accel_stats().kind, AccelKind::Bvh);
    // (hits, misses, blocked, unblocked): both answers of each kind must come up.
    let mut seen = [0; 4];
    for isa in paths() {
        let s = scene.clone().with_isa(isa).expect("available");
        let mut cache = TileCache::default();
        for (i, (tile, t_max)) in tiles.iter().enumerate() {
            let mut hits = vec![None; tile.len()];
            s.intersect_tile(tile, *t_max, &mut hits, &mut cache);
            let rays: Vec<Ray> = (0..tile.len()).map(|r| tile.ray(r)).collect();
            for h in &hits {
                seen[usize::from(h.is_none())] += 1;
            }
            for (r, got) in hits.iter().enumerate() {
                let want = brute_force(&tris, &rays[r], *t_max);
                assert_eq!(
                    got.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                    want.map(|h| (h.t.to_bits(), h.b.map(f32::to_bits), h.triangle)),
                    "tile {i} ray {r} on {isa:?}"
                );
            }
            // Shadow rays from each hit (or from along the ray) back toward the tile's origin
            // and beyond it: occluded by the mesh or not.
            let shadows: Vec<Ray> = rays
                .iter()
                .zip(&hits)
                .map(|(ray, h)| {
                    let p = ray.at(h.map_or(1.0, |h| h.t * 0.999));
                    Ray::new(p, tile.origin() - p + Vec3::new(0.3, -0.2, 0.1))
                })
                .filter(|r| r.dir != Vec3::ZERO && r.dir.is_finite())
                .collect();
            let mut blocked = vec![false; shadows.len()];
            s.occluded_each(&shadows, 1.0, &mut blocked);
            for (r, (ray, got)) in shadows.iter().zip(&blocked).enumerate() {
                let want = tris
                    .iter()
                    .any(|v| intersect_watertight(ray, v, 1.0).is_some());
                assert_eq!(*got, want, "tile {i} shadow ray {r} {ray:?} on {isa:?}");
                seen[2 + usize::from(!want)] += 1;
            }
        }
    }
    assert!(
        seen.iter().all(|&n| n > 100),
        "(hits, misses, blocked, not) {seen:?}"
    );
}
