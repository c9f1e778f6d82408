//! Family 3, degenerate triangles. The choice: a triangle with zero area (repeated or
//! collinear vertices) or a NaN or infinite coordinate is REJECTED when the scene is built,
//! with an error naming the triangle and the problem; so a scene that was built holds only
//! triangles with a finite unit normal, and rendering it cannot fail. Nearly degenerate
//! triangles that are kept (slivers one ULP wide) have finite unit normals and never give a
//! NaN or negative `t` or barycentrics outside [0, 1].

mod common;

use common::{Rng, in_cube, unit};
use glam::Vec3;
use raytty::geometry::DegenerateTriangle;
use raytty::scene::SceneError;
use raytty::{Camera, Effects, Material, Ray, SceneBuilder, Triangle};

/// A unit normal's length may differ from 1 by a few `f32` roundings of its normalisation.
const UNIT_TOL: f32 = 4.0 * f32::EPSILON;

fn build(triangles: Vec<[Vec3; 3]>) -> Result<raytty::Scene, SceneError> {
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::ONE));
    b.object(triangles, m);
    b.build("test", Camera::default(), Effects::SEED)
}

#[test]
fn degenerate_triangles_are_rejected_with_a_clear_error() {
    let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
    let good = [a, b, c];
    let cases: [([Vec3; 3], DegenerateTriangle); 8] = [
        ([a, a, b], DegenerateTriangle::ZeroArea),
        ([a, a, a], DegenerateTriangle::ZeroArea),
        ([a, b, 2.0 * b], DegenerateTriangle::ZeroArea),
        ([a, b, -3.5 * b], DegenerateTriangle::ZeroArea),
        (
            [a, b, Vec3::new(f32::NAN, 0.0, 0.0)],
            DegenerateTriangle::NonFinite,
        ),
        ([a, Vec3::INFINITY, c], DegenerateTriangle::NonFinite),
        ([Vec3::NEG_INFINITY, b, c], DegenerateTriangle::NonFinite),
        (
            [Vec3::new(0.0, f32::MAX, 0.0) * 2.0, b, c],
            DegenerateTriangle::NonFinite,
        ),
    ];
    for (tri, problem) in cases {
        assert_eq!(
            Triangle::new(tri[0], tri[1], tri[2], 0),
            Err(problem),
            "{tri:?}"
        );
        // In a scene, after a valid triangle: the error names the second one.
        let err = build(vec![good, tri]).expect_err("a degenerate triangle must be rejected");
        assert_eq!(err, SceneError::Triangle { index: 1, problem });
        let message = err.to_string();
        assert!(
            message.starts_with("triangle 1: ") && message.len() > 20,
            "unclear message {message:?}"
        );
    }
    assert!(build(vec![good]).is_ok());
}

#[test]
fn collinear_points_at_every_scale_are_rejected() {
    // Exactly collinear: points p + k·d with small integers k, p an integer vector below 2²⁰
    // and d a small one, all times a power of two: every coordinate is exact in f32.
    let mut rng = Rng::seeded(3);
    for i in 0..10_000 {
        let scale = 2f32.powi((rng.next_u64() % 60) as i32 - 30);
        let offset = in_cube(&mut rng, (1 << 20) as f32).round() * scale;
        let d = Vec3::new(1.0, 2.0, -3.0) * scale;
        let k = [0, 1, 2].map(|_| (rng.next_u64() % 16) as f32);
        let v = k.map(|k| offset + d * k);
        assert_eq!(
            Triangle::new(v[0], v[1], v[2], 0),
            Err(DegenerateTriangle::ZeroArea),
            "case {i}: {v:?}"
        );
    }
}

#[test]
fn kept_slivers_have_unit_normals_and_never_give_nan() {
    // Triangles a few ULPs wide at random scales: where they are kept, the normal is finite
    // and unit, and rays give finite hits or misses.
    let mut kept = 0;
    for seed in 0..2000u64 {
        let mut rng = Rng::seeded(seed);
        let scale = 10f32.powf(common::uniform(&mut rng, -4.0, 4.0));
        let a = in_cube(&mut rng, scale);
        let b = a + unit(&mut rng) * scale;
        // The midpoint of a–b, nudged by one ULP in one coordinate: almost collinear.
        let mut c = a.lerp(b, 0.5);
        let axis = (rng.next_u64() % 3) as usize;
        c[axis] = f32::from_bits(c[axis].to_bits() + 1 + (rng.next_u64() % 4) as u32);
        let Ok(tri) = Triangle::new(a, b, c, 0) else {
            continue;
        };
        kept += 1;
        assert!(
            tri.normal.is_finite() && (tri.normal.length() - 1.0).abs() < UNIT_TOL,
            "seed {seed}: normal {} of {:?}",
            tri.normal,
            tri.v
        );
        for _ in 0..50 {
            let target = a.lerp(b, rng.next_f32());
            let origin = target + unit(&mut rng) * scale;
            let ray = Ray::new(origin, target - origin);
            if let Some(h) = tri.intersect(&ray, f32::INFINITY) {
                assert!(
                    h.t > 0.0 && h.t.is_finite() && h.b.iter().all(|b| (0.0..=1.0).contains(b)),
                    "{}: {h:?}",
                    common::case(seed, origin, target - origin, &tri.v)
                );
            }
        }
    }
    assert!(
        kept > 1000,
        "only {kept} slivers kept: the test checks nothing"
    );
}
