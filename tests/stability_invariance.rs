//! Family 7, scale and translation invariance: the Cornell scene, camera and light included,
//! scaled by 1e-4, 1e-2, 1e2 and 1e4 (the light's power by s², so the irradiance D is
//! unchanged), or translated by 1e4 along x, y and z, renders the same 8-bit `indirect` image
//! at 200×100 as the original. Pixels may differ by more than one level only where a primary
//! or shadow ray passes near a feature edge in the original (the edge mask, at a tolerance
//! that grows with the rounding of the moved coordinates), and only a stated small fraction.

mod common;

use common::EDGE_TOL;
use common::reference::Reference;
use glam::Vec3;
use raytty::{Camera, Options, PointLight, Scene, SceneBuilder, Stage, cornell_box};

const SIZE: (u32, u32) = (200, 100);

/// At most this fraction of pixels may differ by more than one level (all inside the mask).
const MAX_DIFFERING: f64 = 0.002;

/// Translated by 1e4, every coordinate is rounded to the f32 spacing there, 2⁻¹⁰ ≈ 1e-3 (half
/// that at worst): vertices, camera and light move by up to 5e-4 in a room 2 wide. Edges then
/// shift by that much, so the mask tolerance is four spacings.
const TRANSLATED_EDGE_TOL: f64 = 4.0 / 1024.0;

/// The scene moved: every point p ↦ s·p + offset, the light's power times s².
fn moved(base: &Scene, s: f32, offset: Vec3) -> (Scene, Camera, Vec<PointLight>) {
    let map = |p: Vec3| p * s + offset;
    let mut b = SceneBuilder::new();
    for m in base.materials() {
        b.material(m.clone());
    }
    // One object per run of triangles with the same material (objects only affect culling).
    let mut start = 0;
    for i in 1..=base.triangles().len() {
        if i == base.triangles().len()
            || base.triangles()[i].material != base.triangles()[start].material
        {
            let run = &base.triangles()[start..i];
            b.object(run.iter().map(|t| t.v.map(map)), run[0].material);
            start = i;
        }
    }
    let lights: Vec<PointLight> = base
        .lights()
        .iter()
        .map(|l| PointLight {
            position: map(l.position),
            power: l.power * (s * s),
        })
        .collect();
    let camera = Camera {
        position: map(base.camera().position),
        ..base.camera()
    };
    let scene = b
        .build("moved", camera, base.effects())
        .expect("a moved Cornell box is valid");
    (scene, camera, lights)
}

fn image(scene: &Scene, camera: &Camera, lights: &[PointLight]) -> Vec<[u8; 3]> {
    let settings = Stage::Indirect.settings(scene.effects());
    scene
        .render(&Options {
            width: SIZE.0,
            height: SIZE.1,
            settings: Some(settings),
            camera: Some(*camera),
            lights: Some(lights),
            ..Options::default()
        })
        .image
        .to_rgb8()
}

fn check(name: &str, s: f32, offset: Vec3, tol: f64) {
    let base = cornell_box();
    let want = image(&base, &base.camera(), base.lights());
    let (scene, camera, lights) = moved(&base, s, offset);
    let got = image(&scene, &camera, &lights);
    let reference = Reference::new(&base);
    let mask = reference.frame(
        &base.camera().rays(SIZE.0, SIZE.1),
        SIZE,
        base.lights(),
        true,
        0.5,
        tol,
    );
    let mut differing = 0;
    let mut unmasked = Vec::new();
    for (k, (a, b)) in want.iter().zip(&got).enumerate() {
        if a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > 1) {
            differing += 1;
            if !mask[k].masked {
                unmasked.push((k as u32 % SIZE.0, k as u32 / SIZE.0, *a, *b));
            }
        }
    }
    let total = (SIZE.0 * SIZE.1) as usize;
    let masked = mask.iter().filter(|p| p.masked).count();
    eprintln!("{name}: {differing} of {total} pixels differ by more than one level; mask {masked}");
    assert!(
        unmasked.is_empty(),
        "{name}: {} pixels away from edges differ; first (x, y, original, moved): {:?}",
        unmasked.len(),
        unmasked.iter().take(5).collect::<Vec<_>>()
    );
    assert!(
        differing as f64 <= MAX_DIFFERING * total as f64,
        "{name}: {differing} pixels differ"
    );
}

#[test]
fn scaled_scenes_render_the_same_image() {
    for s in [1e-4, 1e-2, 1e2, 1e4] {
        check(&format!("scale {s:e}"), s, Vec3::ZERO, EDGE_TOL);
    }
}

#[test]
fn translated_scene_renders_the_same_image() {
    check(
        "translated by 1e4",
        1.0,
        Vec3::splat(1e4),
        TRANSLATED_EDGE_TOL,
    );
}
