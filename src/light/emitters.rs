//! The emitting triangles of a scene as lights: one of them picked in proportion to its
//! power, then a point on it by area.

use glam::{Vec2, Vec3};

use super::{AliasTable, sample_triangle};
use crate::geometry::Triangle;

/// A scene's emitting triangles, each with its emission, and the table that picks them.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLights {
    /// The emitting triangles' indices in the scene, ascending.
    triangles: Vec<u32>,
    /// Picks a position in `triangles` by power (emission summed over the channels × area).
    table: AliasTable,
}

/// A point drawn on one of the lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    /// The triangle (its index in the scene).
    pub triangle: u32,
    /// The point.
    pub position: Vec3,
    /// The density per unit area of drawing it: the triangle's probability over its area.
    pub pdf_area: f32,
}

impl AreaLights {
    /// The triangles of `triangles` whose `emission` is not zero; `None` if there are none
    /// (or their powers cannot be summed).
    pub fn new(triangles: &[Triangle], emission: impl Fn(&Triangle) -> Vec3) -> Option<AreaLights> {
        let mut ids = Vec::new();
        let mut power = Vec::new();
        for (i, t) in triangles.iter().enumerate() {
            let e = emission(t);
            if e.max_element() > 0.0 {
                let area = 0.5 * (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).length();
                ids.push(i as u32);
                power.push((e.x + e.y + e.z) * area);
            }
        }
        let table = AliasTable::new(&power)?;
        Some(AreaLights {
            triangles: ids,
            table,
        })
    }

    /// How many triangles emit.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether none does (never: [`AreaLights::new`] gives `None` then).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// A light picked by `u` (in proportion to power), and a point on it by area from `uv`.
    pub fn sample(&self, triangles: &[Triangle], u: f32, uv: Vec2) -> Option<LightPoint> {
        let (k, pmf) = self.table.sample(u);
        let triangle = self.triangles[k];
        let p = sample_triangle(&triangles[triangle as usize].v, uv)?;
        Some(LightPoint {
            triangle,
            position: p.position,
            pdf_area: pmf * p.pdf_area,
        })
    }

    /// The density per unit area with which [`AreaLights::sample`] draws a point on
    /// `triangle` (0 for a triangle that does not emit).
    pub fn pdf_area(&self, triangles: &[Triangle], triangle: u32) -> f32 {
        let Ok(k) = self.triangles.binary_search(&triangle) else {
            return 0.0;
        };
        let v = &triangles[triangle as usize].v;
        let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        self.table.pmf(k) / area
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn lights_are_picked_by_power_and_their_pdf_matches() {
        let v = |x: f32| Vec3::new(x, 0.0, 0.0);
        let tri = |x: f32, size: f32, m| {
            Triangle::new(v(x), v(x) + Vec3::Y * size, v(x) + Vec3::Z * size, m).unwrap()
        };
        // A dark triangle, a small bright one and a large dim one of equal power.
        let tris = [tri(0.0, 1.0, 0), tri(2.0, 1.0, 1), tri(4.0, 2.0, 2)];
        let emission =
            |t: &Triangle| [Vec3::ZERO, Vec3::splat(4.0), Vec3::splat(1.0)][t.material as usize];
        let lights = AreaLights::new(&tris, emission).unwrap();
        assert_eq!(lights.len(), 2);
        assert_eq!(lights.pdf_area(&tris, 0), 0.0);
        // Equal power: each is picked half the time, and its density is that over its area.
        assert!((lights.pdf_area(&tris, 1) - 0.5 / 0.5).abs() < 1e-6);
        assert!((lights.pdf_area(&tris, 2) - 0.5 / 2.0).abs() < 1e-6);
        let mut rng = Rng::seeded(1);
        let mut on = [0u32; 3];
        for _ in 0..10_000 {
            let p = lights
                .sample(
                    &tris,
                    rng.next_f32(),
                    Vec2::new(rng.next_f32(), rng.next_f32()),
                )
                .unwrap();
            assert_eq!(p.pdf_area, lights.pdf_area(&tris, p.triangle));
            on[p.triangle as usize] += 1;
        }
        assert_eq!(on[0], 0);
        assert!((on[1] as i32 - 5000).abs() < 300, "{on:?}");
        assert!(AreaLights::new(&tris[..1], emission).is_none());
    }
}
