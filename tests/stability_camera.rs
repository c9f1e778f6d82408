//! Family 6, the camera in awkward places: inside a block, exactly on a wall, looking straight
//! along a wall (the centre row's rays lie in the wall's plane), and turned by exact multiples
//! of 90° in yaw and pitch. Every stage renders, and every pixel is finite and non-negative.

use std::f32::consts::FRAC_PI_2;

use glam::Vec3;
use raytty::{Camera, Options, Stage, cornell_box};

/// Frame size (even, so the centre row and column of rays are exactly axis-parallel).
const SIZE: (u32, u32) = (64, 48);

fn cameras(short_block_centre: Vec3) -> Vec<(String, Camera)> {
    let at = |position: Vec3, yaw: f32, pitch: f32| Camera {
        position,
        yaw,
        pitch,
        ..Camera::default()
    };
    let mut list = vec![
        ("inside a block".into(), at(short_block_centre, 0.3, 0.0)),
        (
            "on the back wall, facing in".into(),
            at(Vec3::new(0.2, 0.1, 1.0), 2.0 * FRAC_PI_2, 0.0),
        ),
        (
            "on the back wall, facing out".into(),
            at(Vec3::new(0.2, 0.1, 1.0), 0.0, 0.0),
        ),
        (
            "on the floor, looking along it".into(),
            at(Vec3::new(0.0, 1.0, -0.5), 0.0, 0.0),
        ),
        (
            "on a side wall, looking along it".into(),
            at(Vec3::new(1.0, 0.0, -0.5), 0.0, 0.0),
        ),
        (
            "on a room corner".into(),
            at(Vec3::new(1.0, 1.0, 1.0), 2.0 * FRAC_PI_2, 0.0),
        ),
        (
            "at the open front's edge".into(),
            at(Vec3::new(-1.0, 0.0, -1.0), 0.0, 0.0),
        ),
    ];
    for (where_, position) in [
        ("outside", Vec3::new(0.0, 0.0, -3.0)),
        ("centre", Vec3::ZERO),
    ] {
        for k in 0..4 {
            for pitch in [-FRAC_PI_2, 0.0, FRAC_PI_2] {
                let name = format!("{where_}, yaw {}°, pitch {}°", 90 * k, pitch.to_degrees());
                list.push((name, at(position, k as f32 * FRAC_PI_2, pitch)));
            }
        }
    }
    list
}

#[test]
fn awkward_cameras_give_finite_images_in_every_stage() {
    let scene = cornell_box();
    let centre = scene.triangles()[10..20]
        .iter()
        .flat_map(|t| t.v)
        .sum::<Vec3>()
        / 30.0;
    for (name, camera) in cameras(centre) {
        for stage in Stage::ALL {
            let settings = stage.settings(scene.effects());
            let frame = scene.render(&Options {
                width: SIZE.0,
                height: SIZE.1,
                settings: Some(settings),
                camera: Some(camera),
                ..Options::default()
            });
            if let Some(k) = frame
                .image
                .pixels
                .iter()
                .position(|p| !(p.is_finite() && p.min_element() >= 0.0))
            {
                panic!(
                    "camera {name} ({camera:?}), stage {}: pixel ({}, {}) is {}",
                    stage.name(),
                    k as u32 % SIZE.0,
                    k as u32 / SIZE.0,
                    frame.image.pixels[k]
                );
            }
        }
    }
}

#[test]
fn a_camera_inside_a_closed_object_sees_only_its_inside() {
    // From inside the short block every primary ray hits the block (it is closed by the
    // floor), so no pixel shows the background.
    let scene = cornell_box();
    let centre = scene.triangles()[10..20]
        .iter()
        .flat_map(|t| t.v)
        .sum::<Vec3>()
        / 30.0;
    let camera = Camera {
        position: centre,
        yaw: 0.3,
        pitch: 0.2,
        ..Camera::default()
    };
    let settings = Stage::Flat.settings(scene.effects());
    let frame = scene.render(&Options {
        width: SIZE.0,
        height: SIZE.1,
        settings: Some(settings),
        camera: Some(camera),
        ..Options::default()
    });
    let background = frame
        .image
        .pixels
        .iter()
        .filter(|p| **p == Vec3::ZERO)
        .count();
    assert_eq!(
        background, 0,
        "{background} background pixels from inside the block"
    );
}
