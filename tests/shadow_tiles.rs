//! Tiles shaded in lanes (hit points, light terms and shadow rays eight at a time, the shadow
//! rays after the tile's cull: `src/shading/lanes.rs`, `src/accel/shadow.rs`) give the frames
//! and ray counts that one pixel at a time gives, bit for bit, on every SIMD path: with the
//! light anywhere, on a surface, at a corner, on an edge of a block, inside a block, grazing
//! a wall; with several lights, mirrors and black surfaces; from cameras all around.

mod common;

use common::{Rng, in_cube, soup, uniform};
use glam::Vec3;
use raytty::accel::Isa;
use raytty::geometry::intersect_watertight;
use raytty::scene::builtin;
use raytty::{
    Camera, Material, Options, PointLight, Ray, Scene, SceneBuilder, Stage, Triangle, cornell_box,
};

/// The frame's pixels as bits, and its ray counts.
fn frame(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    stage: Stage,
) -> (Vec<u32>, String) {
    let settings = stage.settings(scene.effects());
    let f = scene.render(&Options {
        width: 61,
        height: 45,
        settings: Some(settings),
        camera: Some(*camera),
        lights: Some(lights),
        ..Options::default()
    });
    let bits = f
        .image
        .pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect();
    (bits, format!("{:?}", f.stats.rays))
}

/// A small generator (xorshift).
fn next(s: &mut u64) -> f32 {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    (*s >> 40) as f32 / (1u64 << 24) as f32
}

/// Light positions: random in the room, and on its surfaces, vertices, edges and inside blocks.
fn light_positions(scene: &Scene, n: usize, seed: u64) -> Vec<Vec3> {
    let mut s = seed;
    let tris = scene.triangles();
    (0..n)
        .map(|i| {
            let t = &tris[(next(&mut s) * tris.len() as f32) as usize % tris.len()];
            let (a, b) = (next(&mut s), next(&mut s));
            match i % 6 {
                0 => Vec3::new(next(&mut s), next(&mut s), next(&mut s)) * 1.9 - Vec3::splat(0.95),
                // On a surface (a point of a triangle, rounded).
                1 => t.v[0] * (1.0 - a - b * (1.0 - a)) + t.v[1] * a + t.v[2] * (b * (1.0 - a)),
                // At a vertex.
                2 => t.v[i % 3],
                // On an edge.
                3 => t.v[0] * a + t.v[1] * (1.0 - a),
                // Just off a surface (grazing light on it).
                4 => t.v[0] * 0.3 + t.v[1] * 0.3 + t.v[2] * 0.4 + t.normal * (1e-5 * a),
                // Inside a block: the blocks fill the lower half of the room.
                _ => Vec3::new(a - 0.5, 0.6 + 0.3 * b, 0.2 * a),
            }
        })
        .collect()
}

fn cameras() -> Vec<Camera> {
    let base = cornell_box().camera();
    vec![
        base,
        Camera {
            position: Vec3::new(0.6, 0.2, -1.5),
            yaw: 0.5,
            ..base
        },
        Camera {
            position: Vec3::new(-0.9, -0.8, 0.2),
            yaw: -1.9,
            ..base
        },
    ]
}

fn assert_paths_agree(scene: &Scene, lights: &[Vec<PointLight>], stages: &[Stage], what: &str) {
    let paths: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.available()).collect();
    let portable = scene.clone().with_isa(Isa::Portable).unwrap();
    for (c, camera) in cameras().iter().enumerate() {
        for (l, lights) in lights.iter().enumerate() {
            for &stage in stages {
                let want = frame(&portable, camera, lights, stage);
                for &isa in &paths {
                    let s = scene.clone().with_isa(isa).unwrap();
                    let got = frame(&s, camera, lights, stage);
                    assert!(
                        got == want,
                        "{what}: {stage:?} on {isa:?} differs, camera {c}, lights {l} {lights:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_cornell_box_with_the_light_anywhere_is_the_same_on_every_path() {
    let scene = cornell_box();
    let power = scene.lights()[0].power;
    let lights: Vec<Vec<PointLight>> = light_positions(&scene, 24, 7)
        .into_iter()
        .map(|position| vec![PointLight { position, power }])
        .collect();
    assert_paths_agree(
        &scene,
        &lights,
        &[Stage::Light, Stage::Shadows, Stage::Indirect],
        "cornell",
    );
}

#[test]
fn several_lights_mirrors_and_black_surfaces_are_the_same_on_every_path() {
    let mut lights: Vec<Vec<PointLight>> = vec![];
    let positions = light_positions(&cornell_box(), 12, 9);
    for k in 0..4 {
        lights.push(
            (0..3)
                .map(|j| PointLight {
                    position: positions[(3 * k + j) % positions.len()],
                    // One dark light among them.
                    power: if j == 1 && k == 2 {
                        Vec3::ZERO
                    } else {
                        Vec3::new(3.0 + j as f32, 5.0, 9.0 - 2.0 * j as f32)
                    },
                })
                .collect(),
        );
    }
    for name in ["lights", "mirror"] {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let mut all = lights.clone();
        all.push(scene.lights().to_vec());
        assert_paths_agree(&scene, &all, &Stage::ALL[1..5], name);
    }
    // A box with a black wall and a half mirror; and, up to the lanes' limit of 64
    // triangles so that triangles 32 and on (the high half of the lanes' bit mask of surfaces
    // shaded in lanes) are seen too, the box and the box again at half size inside it.
    let cornell = cornell_box();
    let box_tris: Vec<[Vec3; 3]> = cornell.triangles().iter().map(|t| t.v).collect();
    let shrunk = box_tris.iter().map(|v| v.map(|p| p * 0.5));
    let sixty: Vec<[Vec3; 3]> = box_tris.iter().copied().chain(shrunk).collect();
    assert_eq!(sixty.len(), 60);
    for (name, tris, turns) in [("mixed", box_tris, 3), ("sixty", sixty, 4)] {
        let mut b = SceneBuilder::new();
        let black = b.material(Material::diffuse(Vec3::ZERO));
        let half = b.material(Material {
            mirror: 0.5,
            ..Material::diffuse(Vec3::splat(0.5))
        });
        let white = b.material(Material::diffuse(Vec3::splat(0.7)));
        let red = b.material(Material::diffuse(Vec3::new(0.7, 0.2, 0.2)));
        for (i, v) in tris.into_iter().enumerate() {
            b.object([v], [black, half, white, red][i % turns]);
        }
        b.light(cornell.lights()[0]);
        let scene = b.build(name, cornell.camera(), cornell.effects()).unwrap();
        assert_paths_agree(&scene, &lights, &Stage::ALL[1..5], name);
    }
}

/// The shadow-ray kernel and its driver, lane by lane against the scalar test: eight rays
/// with their own origins toward one light (through vertices and edge midpoints of a soup,
/// so that edge functions round to zero and lanes are redone in `f64`), every lane's answer
/// the scalar test's: the kernel's own lanes where it does not hand them back, and the
/// driver's (cull, "behind" rule, redo) for every lane.
#[cfg(target_arch = "x86_64")]
#[test]
fn shadow_lanes_answer_as_the_scalar_test() {
    use raytty::accel::shadow::{ShadowCull, ShadowRays8, any_hit8_avx2};
    if !Isa::Avx2.available() {
        eprintln!("note: this CPU has no avx2; the shadow lanes are not tested");
        return;
    }
    let t_max = 1.0 - raytty::shading::SHADOW_EPSILON;
    let (mut hits, mut redos, mut lanes_tested) = (0, 0, 0);
    let mut rng = Rng::seeded(3);
    for case in 0..400 {
        let scale = [1.0, 1e-3, 200.0][case % 3];
        let tris: Vec<Triangle> = soup(case as u64, 1 + case % 40, 1.0, 0.6, scale)
            .into_iter()
            .map(|v| Triangle::new(v[0], v[1], v[2], 0).unwrap())
            .collect();
        let light = in_cube(&mut rng, 1.2) * scale;
        let centre = in_cube(&mut rng, 1.0) * scale;
        let spread = [0.0, 0.01, 0.3][case % 3] * scale;
        // Origins around a point, or on the line from the light through a vertex or an edge's
        // midpoint (the ray then passes through it).
        let rays: Vec<Ray> = (0..8)
            .map(|i| {
                let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
                let k = (rng.next_u64() % 3) as usize;
                let o = match (case + i) % 3 {
                    0 => centre + in_cube(&mut rng, 1.0) * spread,
                    1 => light + (t.v[k] - light) * uniform(&mut rng, 1.1, 2.0),
                    _ => {
                        let mid = t.v[k] * 0.5 + t.v[(k + 1) % 3] * 0.5;
                        light + (mid - light) * uniform(&mut rng, 1.1, 2.0)
                    }
                };
                Ray::new(o, light - o)
            })
            .filter(|r| r.dir != Vec3::ZERO && r.dir.is_finite())
            .collect();
        let cull = ShadowCull::new(&tris, light);
        // Packets of the rays that share the first one's axes.
        let mut left: Vec<&Ray> = rays.iter().collect();
        while let Some(first) = left.first() {
            let axes = first.axes();
            let (packet, rest): (Vec<&Ray>, Vec<&Ray>) =
                left.iter().partition(|r| r.axes() == axes);
            left = rest;
            let mut p = ShadowRays8 {
                axes,
                ..ShadowRays8::default()
            };
            for (l, r) in packet.iter().enumerate() {
                for (j, &a) in axes.iter().enumerate() {
                    p.origin[j][l] = r.origin[a];
                    p.shear[j][l] = r.shear()[j];
                }
            }
            let lanes = (1u32 << packet.len()) - 1;
            let want: Vec<Vec<bool>> = tris
                .iter()
                .map(|t| {
                    packet
                        .iter()
                        .map(|r| intersect_watertight(r, &t.v, t_max).is_some())
                        .collect()
                })
                .collect();
            for (t, want) in tris.iter().zip(&want) {
                let v = t.v.map(|v| [v.x, v.y, v.z, 0.0]);
                // SAFETY: the CPU has AVX2 (checked above).
                let (hit, redo) = unsafe { any_hit8_avx2(&v, &p, t_max) };
                for (l, &w) in want.iter().enumerate() {
                    lanes_tested += 1;
                    if redo >> l & 1 == 1 {
                        redos += 1;
                        continue;
                    }
                    hits += w as usize;
                    assert_eq!(
                        hit >> l & 1 == 1,
                        w,
                        "case {case} lane {l}: {:?} {:?}",
                        packet[l],
                        t.v
                    );
                }
            }
            let (lo, hi) = packet
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), r| {
                    (lo.min(r.origin), hi.max(r.origin))
                });
            let kz = axes[2];
            let oz = packet
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), r| {
                    (a.min(r.origin[kz]), b.max(r.origin[kz]))
                });
            let all = if tris.len() == 64 {
                u64::MAX
            } else {
                (1 << tris.len()) - 1
            };
            for kept in [all, cull.kept(Isa::detect(), lo, hi)] {
                // SAFETY: as above.
                let blocked =
                    unsafe { cull.occluded8_avx2(kept, &p, lanes, oz, t_max, |l| *packet[l]) };
                for l in 0..packet.len() {
                    let w = want.iter().any(|w| w[l]);
                    assert_eq!(
                        blocked >> l & 1 == 1,
                        w,
                        "case {case} lane {l}: {:?}",
                        packet[l]
                    );
                }
            }
        }
    }
    assert!(
        hits > 500 && redos > 0,
        "{hits} hits, {redos} lanes redone of {lanes_tested}"
    );
}
