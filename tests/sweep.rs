//! A seeded sweep of random camera and light poses, lights inside the blocks and on the walls
//! among them: every image is finite, every 8-bit pixel in range, and nothing panics.

use glam::Vec3;
use raytty::{Camera, Options, PointLight, Stage, cornell_box, rng::Rng};

/// Poses in the sweep (the issue asks for at least 1000).
const POSES: u32 = 1200;

fn uniform(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.next_f32()
}

/// A light position: anywhere around the box, inside a block, or on a wall, floor or ceiling.
fn light_position(rng: &mut Rng, kind: u32) -> Vec3 {
    let scene = cornell_box();
    match kind % 4 {
        0 => Vec3::new(
            uniform(rng, -1.5, 1.5),
            uniform(rng, -1.5, 1.5),
            uniform(rng, -3.5, 1.5),
        ),
        1 => {
            // Inside a block: a random point inside the convex hull of one block's corners.
            let block = &scene.triangles()[10 + 10 * (rng.next_u64() % 2) as usize..][..10];
            let corners: Vec<Vec3> = block.iter().flat_map(|t| t.v).collect();
            let w: Vec<f32> = corners.iter().map(|_| rng.next_f32()).collect();
            let sum: f32 = w.iter().sum();
            corners.iter().zip(&w).map(|(c, w)| *c * (w / sum)).sum()
        }
        2 => {
            // On a surface: a random point of a random triangle.
            let t = &scene.triangles()[(rng.next_u64() % scene.triangles().len() as u64) as usize];
            let (mut a, mut b) = (rng.next_f32(), rng.next_f32());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            t.v[0] * (1.0 - a - b) + t.v[1] * a + t.v[2] * b
        }
        _ => {
            // Exactly on a wall plane or a vertex.
            let t = &scene.triangles()[(rng.next_u64() % scene.triangles().len() as u64) as usize];
            t.v[(rng.next_u64() % 3) as usize]
        }
    }
}

#[test]
fn random_poses_give_finite_in_range_images() {
    let scene = cornell_box();
    let mut rng = Rng::seeded(0x5eed);
    for i in 0..POSES {
        let camera = Camera {
            position: Vec3::new(
                uniform(&mut rng, -1.2, 1.2),
                uniform(&mut rng, -1.2, 1.2),
                uniform(&mut rng, -4.0, 1.2),
            ),
            yaw: uniform(&mut rng, -3.2, 3.2),
            pitch: if i % 3 == 0 {
                uniform(&mut rng, -1.5, 1.5)
            } else {
                0.0
            },
            ..Camera::default()
        };
        let light = PointLight {
            position: light_position(&mut rng, i),
            ..scene.lights()[0]
        };
        let stage = Stage::ALL[(i % 6) as usize];
        let settings = stage.settings(scene.effects());
        let frame = scene.render(&Options {
            width: 32,
            height: 24,
            settings: Some(settings),
            camera: Some(camera),
            lights: Some(&[light]),
            ..Options::default()
        });
        for (p, px) in frame.image.pixels.iter().enumerate() {
            assert!(
                px.is_finite() && px.min_element() >= 0.0,
                "pose {i} ({camera:?}, {light:?}, {stage:?}): pixel {p} = {px}"
            );
        }
        assert_eq!(frame.image.to_rgb8().len(), 32 * 24);
    }
}
