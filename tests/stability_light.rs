//! Family 5, the light in awkward places: on a wall, on a block's edge and vertex, inside a
//! block, at the camera. Every pixel of every lit stage is finite and non-negative, and no
//! pixel's direct irradiance exceeds the cap the r → 0 rule sets. The rule itself
//! (`Scene::min_light_distance`): r² in the inverse-square law is clamped to
//! (1e-3 × scene diagonal)², so a light approaching a surface gives a large but finite value;
//! a light exactly at the shaded point gives nothing (it has no direction), and a light behind
//! the surface gives nothing and costs no shadow ray.

mod common;

use std::f32::consts::PI;

use glam::Vec3;
use raytty::geometry::hit_point;
use raytty::rng::Rng;
use raytty::shading::RayCounts;
use raytty::{Options, PointLight, Ray, Scene, Stage, Tracer, cornell_box};

/// Frame size for the awkward-light renders (small: these check finiteness, not looks).
const SIZE: (u32, u32) = (96, 72);

/// Irradiance follows the formula to this relative error: f32 rounding of the light's
/// position next to the point (≲ 1e-6 relative to r at the distances checked) and of the sum.
const REL_TOL: f32 = 1e-3;

/// The stages whose pixels depend on the light.
const LIT: [Stage; 5] = [
    Stage::Light,
    Stage::Direct,
    Stage::Shadows,
    Stage::Indirect,
    Stage::Gi,
];

/// The largest irradiance one light may give anywhere: P/(4π·r_min²), cos θ ≤ 1.
fn cap(scene: &Scene, light: &PointLight) -> f32 {
    let r = scene.min_light_distance();
    light.power.max_element() / (4.0 * PI * r * r) * (1.0 + REL_TOL)
}

fn awkward_places(scene: &Scene) -> Vec<(&'static str, Vec3)> {
    let short = &scene.triangles()[10..20];
    let tall = &scene.triangles()[20..30];
    // The short block's first triangle is [E, B, A]: E is a top corner, E–A a vertical edge.
    let [e, _, a] = short[0].v;
    let centre = tall.iter().flat_map(|t| t.v).sum::<Vec3>() / 30.0;
    vec![
        ("on the back wall", Vec3::new(0.3, 0.2, 1.0)),
        ("on a side wall", Vec3::new(1.0, -0.4, 0.3)),
        ("on the floor", Vec3::new(-0.2, 1.0, -0.5)),
        ("on a room corner", Vec3::new(1.0, 1.0, 1.0)),
        ("on a block's vertex", e),
        ("on a block's edge", e.lerp(a, 0.5)),
        ("inside a block", centre),
        ("at the camera", scene.camera().position),
    ]
}

#[test]
fn awkward_lights_give_finite_pixels_within_the_cap() {
    let scene = cornell_box();
    for (name, position) in awkward_places(&scene) {
        let lights = [PointLight {
            position,
            ..scene.lights()[0]
        }];
        let cap = cap(&scene, &lights[0]);
        for stage in LIT {
            let settings = stage.settings(scene.effects());
            let frame = scene.render(&Options {
                width: SIZE.0,
                height: SIZE.1,
                settings: Some(settings),
                lights: Some(&lights),
                ..Options::default()
            });
            for (k, p) in frame.image.pixels.iter().enumerate() {
                let (x, y) = (k as u32 % SIZE.0, k as u32 / SIZE.0);
                assert!(
                    p.is_finite() && p.min_element() >= 0.0,
                    "light {name} at {position}, stage {}: pixel ({x}, {y}) is {p}",
                    stage.name()
                );
                if stage == Stage::Light {
                    assert!(
                        p.max_element() <= cap,
                        "light {name}: pixel ({x}, {y}) irradiance {p} above the cap {cap}"
                    );
                }
            }
        }
    }
}

#[test]
fn light_approaching_a_surface_follows_the_r_to_zero_rule() {
    let scene = cornell_box();
    // A point on the tall block's front face, seen by the centre camera ray.
    let ray = Ray::new(scene.camera().position, Vec3::Z);
    let hit = scene
        .intersect(&ray, f32::INFINITY)
        .expect("centre ray hits");
    let tri = &scene.triangles()[hit.triangle as usize];
    let (p, err) = hit_point(&tri.v, hit.b);
    let n = if tri.normal.dot(ray.dir) > 0.0 {
        -tri.normal
    } else {
        tri.normal
    };
    let power = scene.lights()[0].power;
    let r_min = scene.min_light_distance();
    let settings = Stage::Shadows.settings(scene.effects());
    for k in 0..=10 {
        let r = 10f32.powi(-k);
        for (side, expect_light) in [(1.0, true), (-1.0, false)] {
            let lights = [PointLight {
                position: p + n * (side * r),
                power,
            }];
            let tracer = Tracer::new(&scene, &lights, settings);
            let mut counts = RayCounts::default();
            let d = tracer.direct(p, err, n, &mut counts);
            let what = format!(
                "light {r:e} {} the surface at {p}",
                ["behind", "in front of"][usize::from(expect_light)]
            );
            assert!(d.is_finite() && d.min_element() >= 0.0, "{what}: {d}");
            if !expect_light {
                assert_eq!(d, Vec3::ZERO, "{what}");
                assert_eq!(counts.shadow, 0, "{what}: a shadow ray was traced");
                continue;
            }
            let cap = power / (4.0 * PI * r_min * r_min);
            assert!(
                d.cmple(cap * (1.0 + REL_TOL)).all(),
                "{what}: {d} above the cap {cap}"
            );
            // Where r is resolved (well above the f32 spacing at p), the formula holds exactly:
            // the clamped inverse square law with cos θ = 1.
            if r >= 1e-5 {
                let want = power / (4.0 * PI * (r * r).max(r_min * r_min));
                assert!(
                    ((d - want).abs() / want).max_element() < REL_TOL,
                    "{what}: irradiance {d}, rule says {want}"
                );
            }
        }
    }
    // Exactly at the point: no direction, no light, no NaN.
    let lights = [PointLight { position: p, power }];
    let d = Tracer::new(&scene, &lights, settings).direct(p, err, n, &mut RayCounts::default());
    assert_eq!(d, Vec3::ZERO);
    let c = Tracer::new(&scene, &lights, settings).shade_primary(
        &ray,
        Some(hit),
        &mut Rng::seeded(0),
        &mut RayCounts::default(),
    );
    assert!(c.is_finite(), "{c}");
}
