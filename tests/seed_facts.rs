//! The seed's numbers, through the library's ray API: where three rays hit and what colour
//! they bring back in the `indirect` stage.

use glam::Vec3;
use raytty::{Ray, Stage, Tracer, cornell_box, rng::Rng, shading::RayCounts};

fn check(dir: Vec3, point: Vec3, colour: Vec3) -> f32 {
    let scene = cornell_box();
    let ray = Ray::new(Vec3::new(0.0, 0.0, -3.0), dir.normalize());
    let hit = scene
        .intersect(&ray, f32::INFINITY)
        .expect("the ray hits the box");
    let p = ray.at(hit.t);
    assert!(
        (p - point).abs().max_element() < 1e-4,
        "hit {p}, expected {point}"
    );
    let tracer = Tracer::new(
        &scene,
        scene.lights(),
        Stage::Indirect.settings(scene.effects()),
    );
    let mut counts = RayCounts::default();
    let c = tracer.shade_primary(&ray, Some(hit), &mut Rng::seeded(0), &mut counts);
    assert!(
        (c - colour).abs().max_element() < 1e-4,
        "colour {c}, expected {colour}"
    );
    assert_eq!(counts.shadow, 1, "one shadow ray per lit point");
    c.x
}

#[test]
fn centre_ray_hits_the_tall_block_front() {
    let c = check(
        Vec3::Z,
        Vec3::new(0.0, 0.0, 0.05270),
        Vec3::new(0.23782, 0.23782, 1.18911),
    );
    // ρ = 0.15, N = 0.5: D = c/ρ − N.
    assert!((c / 0.15 - 0.5 - 1.08548).abs() < 1e-3);
}

#[test]
fn left_ray_hits_the_purple_wall() {
    check(
        Vec3::new(-210.0, 0.0, 500.0),
        Vec3::new(-1.0, 0.0, -0.61905),
        Vec3::new(0.96821, 0.19364, 0.96821),
    );
}

#[test]
fn downward_ray_hits_the_floor() {
    let scene = cornell_box();
    let ray = Ray::new(
        Vec3::new(0.0, 0.0, -3.0),
        Vec3::new(0.0, 230.0, 500.0).normalize(),
    );
    let hit = scene.intersect(&ray, f32::INFINITY).unwrap();
    let p = ray.at(hit.t);
    assert!((p.y - 1.0).abs() < 1e-5, "on the floor: {p}");
    let tracer = Tracer::new(
        &scene,
        scene.lights(),
        Stage::Indirect.settings(scene.effects()),
    );
    let c = tracer.shade_primary(
        &ray,
        Some(hit),
        &mut Rng::seeded(0),
        &mut RayCounts::default(),
    );
    assert!(
        (c - Vec3::new(0.14849, 0.74246, 0.14849))
            .abs()
            .max_element()
            < 1e-4,
        "colour {c}"
    );
}
