//! Tiles shaded in lanes (hit points, light terms and shadow rays eight at a time, the shadow
//! rays after the tile's cull: `src/shading/lanes.rs`, `src/accel/shadow.rs`) give the frames
//! and ray counts that one pixel at a time gives, bit for bit, on every SIMD path: with the
//! light anywhere, on a surface, at a corner, on an edge of a block, inside a block, grazing
//! a wall; with several lights, mirrors and black surfaces; from cameras all around.

use glam::Vec3;
use raytty::accel::Isa;
use raytty::scene::builtin;
use raytty::{Camera, Material, PointLight, Scene, SceneBuilder, Stage, cornell_box, render};

/// The frame's pixels as bits, and its ray counts.
fn frame(
    scene: &Scene,
    camera: &Camera,
    lights: &[PointLight],
    stage: Stage,
) -> (Vec<u32>, String) {
    let settings = stage.settings(scene.effects());
    let f = render(scene, camera, lights, &settings, 61, 45);
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
    // A box with a black wall and a half mirror.
    let cornell = cornell_box();
    let mut b = SceneBuilder::new();
    let black = b.material(Material::diffuse(Vec3::ZERO));
    let half = b.material(Material {
        mirror: 0.5,
        ..Material::diffuse(Vec3::splat(0.5))
    });
    let white = b.material(Material::diffuse(Vec3::splat(0.7)));
    for (i, t) in cornell.triangles().iter().enumerate() {
        b.object([t.v], [black, half, white][i % 3]);
    }
    b.light(cornell.lights()[0]);
    let scene = b
        .build("mixed", cornell.camera(), cornell.effects())
        .unwrap();
    assert_paths_agree(&scene, &lights, &Stage::ALL[1..5], "mixed");
}
