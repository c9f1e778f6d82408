//! Rays, triangles and the watertight ray/triangle test.
//!
//! The intersection follows Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection"
//! (JCGT 2013), with a conservative error bound on `t` in the spirit of pbrt-v4's but tighter
//! ([`t_error_bound`]): a ray that passes exactly through a shared edge or vertex hits at least
//! one of the triangles that share it, and a hit is never reported at a distance that rounding
//! error cannot tell from zero. New rays leave a
//! surface from an origin pushed out of the hit point's own rounding-error box
//! ([`offset_ray_origin`]), so no tuned epsilon depends on the scene's scale.

mod aabb;
mod float;
mod offset;
mod ray;
mod ray_tile;
mod triangle;
mod watertight;

pub use aabb::Aabb;
pub(crate) use aabb::enter_boxes;
pub use float::{gamma, next_float_down, next_float_up};
pub use offset::{hit_point, offset_ray_origin};
pub use ray::{Ray, RayFrame};
pub(crate) use ray::{axes_of, main_axis, shear_of};
pub use ray_tile::{RayTile, TILE_RAYS};
pub use triangle::{DegenerateTriangle, Triangle};
pub(crate) use watertight::watertight_lanes;
pub use watertight::{TriHit, intersect_watertight, t_error_bound};

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn next_float_steps_one_ulp() {
        assert!(next_float_up(1.0) > 1.0);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert_eq!(next_float_down(next_float_up(2.5)), 2.5);
    }

    #[test]
    fn hits_inside_and_misses_outside() {
        let v = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let hit = intersect_watertight(&ray, &v, f32::INFINITY).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-6);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(5.0, 0.0, 1.0));
        assert!(intersect_watertight(&ray, &v, f32::INFINITY).is_none());
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        assert!(intersect_watertight(&ray, &v, f32::INFINITY).is_none());
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!(intersect_watertight(&ray, &v, 0.5).is_none());
    }

    #[test]
    fn t_error_bound_is_small_head_on_and_none_in_the_plane() {
        let v = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        // A direction far from unit length, as a shadow ray's `light − p` can be: the bound
        // stays a few ulps of t (pbrt-v4's grows with t², see `t_error_bound`).
        let ray = Ray::new(Vec3::ZERO, Vec3::Z * 1e-3);
        let frame = ray.frame(&v);
        let e = frame.edge_functions();
        let hit = intersect_watertight(&ray, &v, f32::INFINITY).expect("head-on hit");
        let bound = t_error_bound(&ray, &frame, e, hit.t).expect("a bound exists");
        assert!((hit.t - 1000.0).abs() <= bound, "{hit:?} {bound}");
        assert!(
            bound > 0.0 && bound < hit.t * 1e-5,
            "{bound} for t = {}",
            hit.t
        );
        // In the triangle's plane the determinant is zero: no bound, no hit.
        let ray = Ray::new(Vec3::new(-2.0, 0.0, 1.0), Vec3::X);
        let frame = ray.frame(&v);
        assert_eq!(
            t_error_bound(&ray, &frame, frame.edge_functions(), 2.0),
            None
        );
        assert_eq!(intersect_watertight(&ray, &v, f32::INFINITY), None);
    }

    #[test]
    fn degenerate_triangles_are_rejected() {
        let a = Vec3::ZERO;
        let b = Vec3::X;
        assert_eq!(Triangle::new(a, a, b, 0), Err(DegenerateTriangle::ZeroArea));
        assert_eq!(
            Triangle::new(a, b, 2.0 * b, 0),
            Err(DegenerateTriangle::ZeroArea)
        );
        assert_eq!(
            Triangle::new(a, b, Vec3::NAN, 0),
            Err(DegenerateTriangle::NonFinite)
        );
        assert!(Triangle::new(a, b, Vec3::Y, 0).is_ok());
    }
}
