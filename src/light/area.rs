//! A point uniformly on a triangle, and densities per area turned into densities per solid
//! angle.

use glam::{Vec2, Vec3};

/// A point drawn on a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrianglePoint {
    /// The point.
    pub position: Vec3,
    /// Its barycentric coordinates `(b0, b1, b2)`, summing to 1.
    pub barycentric: Vec3,
    /// The density per unit area: `1/area`.
    pub pdf_area: f32,
}

/// A uniform point on the triangle `v` from two uniform numbers: `b0 = 1 − √u₀`,
/// `b1 = u₁√u₀` (the square root spreads the points evenly between the apex `v[0]` and the
/// opposite edge). `None` for a triangle of zero area.
pub fn sample_triangle(v: &[Vec3; 3], u: Vec2) -> Option<TrianglePoint> {
    let area = triangle_area(v);
    if !(area > 0.0) || !area.is_finite() {
        return None;
    }
    let b = triangle_barycentrics(u);
    Some(TrianglePoint {
        position: v[0] * b.x + v[1] * b.y + v[2] * b.z,
        barycentric: b,
        pdf_area: 1.0 / area,
    })
}

/// The area of the triangle `v`.
#[inline]
pub(super) fn triangle_area(v: &[Vec3; 3]) -> f32 {
    0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()
}

/// [`sample_triangle`]'s barycentric coordinates from its two uniform numbers.
#[inline]
pub(super) fn triangle_barycentrics(u: Vec2) -> Vec3 {
    let s = u.x.clamp(0.0, 1.0).sqrt();
    let b0 = 1.0 - s;
    let b1 = u.y.clamp(0.0, 1.0) * s;
    let b2 = (1.0 - b0 - b1).max(0.0);
    Vec3::new(b0, b1, b2)
}

/// A density per area at a point on a light turned into one per solid angle at `reference`:
/// `pdf_area · r² / |cos θ|`, θ between the light's normal `light_normal` (unit) and the
/// direction from the light to `reference`. `None` where the light is seen edge-on or sits on
/// the point (no finite density).
pub fn area_to_solid_angle(
    pdf_area: f32,
    reference: Vec3,
    light_point: Vec3,
    light_normal: Vec3,
) -> Option<f32> {
    let d = reference - light_point;
    let r2 = d.length_squared();
    if !(r2 > 0.0) {
        return None;
    }
    let cos = light_normal.dot(d).abs() / r2.sqrt();
    let pdf = pdf_area * r2 / cos;
    (cos > 0.0 && pdf.is_finite()).then_some(pdf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn tri() -> [Vec3; 3] {
        [
            Vec3::new(0.3, -0.2, 1.0),
            Vec3::new(2.0, 0.1, 1.4),
            Vec3::new(0.5, 1.7, 0.6),
        ]
    }

    #[test]
    fn points_are_uniform_over_the_area() {
        // Split the triangle into its four midpoint triangles and each of those again (16
        // equal areas): every part gets a sixteenth, by χ² over seeded points.
        let v = tri();
        let mut rng = Rng::seeded(5);
        let n = 320_000u32;
        let mut counts = [0u32; 16];
        for _ in 0..n {
            let p = sample_triangle(&v, Vec2::new(rng.next_f32(), rng.next_f32())).unwrap();
            let b = p.barycentric;
            assert!((b.x + b.y + b.z - 1.0).abs() < 1e-6 && b.min_element() >= 0.0);
            assert!((v[0] * b.x + v[1] * b.y + v[2] * b.z - p.position).length() < 1e-5);
            counts[part(b.y, b.z, 2)] += 1;
        }
        let e = f64::from(n) / 16.0;
        let chi2: f64 = counts.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum();
        // 15 degrees of freedom: P(χ² > 37.7) = 0.001.
        assert!(chi2 < 37.7, "χ² = {chi2}: {counts:?}");
        let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        let p = sample_triangle(&v, Vec2::splat(0.5)).unwrap();
        assert!((p.pdf_area * area - 1.0).abs() < 1e-6);
        assert!(sample_triangle(&[v[0], v[1], v[0]], Vec2::splat(0.5)).is_none());
    }

    /// Which of the 4^levels midpoint-subdivided parts the barycentric point (·, b1, b2) lies
    /// in (a number below 4^levels).
    fn part(b1: f32, b2: f32, levels: u32) -> usize {
        let (mut x, mut y) = (b1, b2);
        let mut k = 0;
        for _ in 0..levels {
            // Corner parts at b0, b1, b2 and the middle (upside-down) one.
            let q = if x + y < 0.5 {
                (x, y, 0)
            } else if x >= 0.5 {
                (x - 0.5, y, 1)
            } else if y >= 0.5 {
                (x, y - 0.5, 2)
            } else {
                (0.5 - y, 0.5 - x, 3)
            };
            x = 2.0 * q.0;
            y = 2.0 * q.1;
            k = 4 * k + q.2;
        }
        k
    }

    /// Van Oosterom and Strackee's solid angle of a triangle seen from the origin.
    fn solid_angle(v: &[Vec3; 3]) -> f64 {
        let [a, b, c] = v.map(|p| p.as_dvec3());
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * num.atan2(den)
    }

    #[test]
    fn solid_angle_densities_integrate_to_the_solid_angle() {
        // E[1/pdf_ω] over points drawn by area is the triangle's solid angle.
        let mut rng = Rng::seeded(11);
        for (shift, n) in [(Vec3::ZERO, 200_000), (Vec3::new(0.0, 0.0, 3.0), 50_000)] {
            let v = tri().map(|p| p + shift);
            let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let mut sum = 0.0f64;
            for _ in 0..n {
                let p = sample_triangle(&v, Vec2::new(rng.next_f32(), rng.next_f32())).unwrap();
                let pdf = area_to_solid_angle(p.pdf_area, Vec3::ZERO, p.position, normal).unwrap();
                sum += 1.0 / f64::from(pdf);
            }
            let (got, want) = (sum / f64::from(n), solid_angle(&v));
            assert!((got - want).abs() < 0.005 * want, "{got} vs {want}");
        }
        // Edge-on and on the point: no density.
        let n = Vec3::Z;
        assert!(area_to_solid_angle(1.0, Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO, n).is_none());
        assert!(area_to_solid_angle(1.0, Vec3::ZERO, Vec3::ZERO, n).is_none());
        let at = area_to_solid_angle(2.0, Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, n).unwrap();
        assert!((at - 18.0).abs() < 1e-5);
    }
}
