//! Procedural meshes, generated at load: a subdivided, displaced icosphere for the large-mesh
//! scene.
//!
//! Each of the icosahedron's 20 faces is cut into a `k`×`k` grid of `k²` triangles, so the
//! sphere has `20·k²` triangles (k = 224 gives 1,003,520). Vertices on an edge shared by two
//! faces are computed from the same integers in the same order by both faces, so they are
//! bit-identical and the mesh has no cracks.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The icosahedron's 20 faces, as indices into [`icosahedron_vertices`], wound consistently.
pub const ICOSAHEDRON_FACES: [[usize; 3]; 20] = [
    [0, 11, 5],
    [0, 5, 1],
    [0, 1, 7],
    [0, 7, 10],
    [0, 10, 11],
    [1, 5, 9],
    [5, 11, 4],
    [11, 10, 2],
    [10, 7, 6],
    [7, 1, 8],
    [3, 9, 4],
    [3, 4, 2],
    [3, 2, 6],
    [3, 6, 8],
    [3, 8, 9],
    [4, 9, 5],
    [2, 4, 11],
    [6, 2, 10],
    [8, 6, 7],
    [9, 8, 1],
];

/// The icosahedron's 12 vertices (golden-ratio rectangles, not normalised).
pub fn icosahedron_vertices() -> [DVec3; 12] {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    [
        DVec3::new(-1.0, p, 0.0),
        DVec3::new(1.0, p, 0.0),
        DVec3::new(-1.0, -p, 0.0),
        DVec3::new(1.0, -p, 0.0),
        DVec3::new(0.0, -1.0, p),
        DVec3::new(0.0, 1.0, p),
        DVec3::new(0.0, -1.0, -p),
        DVec3::new(0.0, 1.0, -p),
        DVec3::new(p, 0.0, -1.0),
        DVec3::new(p, 0.0, 1.0),
        DVec3::new(-p, 0.0, -1.0),
        DVec3::new(-p, 0.0, 1.0),
    ]
}

/// A smooth, deterministic bump field on the unit sphere, in [-1, 1].
fn bumps(d: DVec3) -> f64 {
    use libm::sin;
    let a = sin(5.0 * d.x + 1.3) * sin(4.0 * d.y - 0.7) * sin(6.0 * d.z + 0.4);
    let b = sin(13.0 * d.x - 2.0 * d.z) * sin(11.0 * d.y + 3.0 * d.x);
    (0.7 * a + 0.3 * b).clamp(-1.0, 1.0)
}

/// The number of triangles [`displaced_icosphere`] makes for `k`.
pub fn icosphere_triangles(k: u32) -> u64 {
    20 * u64::from(k) * u64::from(k)
}

/// A unit icosphere with each face cut into `k`×`k` triangles (`20·k²` in all; `k ≥ 1`), its
/// radius displaced by `amplitude` times a smooth bump field (0 gives a plain sphere). Centred
/// on the origin; the caller transforms it.
pub fn displaced_icosphere(k: u32, amplitude: f32) -> Vec<[Vec3; 3]> {
    let k = k.max(1) as usize;
    let amplitude = f64::from(amplitude);
    let corners = icosahedron_vertices();
    let vertex = |face: [usize; 3], i: usize, j: usize| -> Vec3 {
        // Weights as exact integer ratios, summed in the order of the corners' indices so that
        // a point on a shared edge comes out bit-identical from both faces.
        let w = [k - i - j, i, j];
        let mut terms = [(face[0], w[0]), (face[1], w[1]), (face[2], w[2])];
        terms.sort_unstable_by_key(|t| t.0);
        let mut p = DVec3::ZERO;
        for (c, wt) in terms {
            if wt > 0 {
                p += corners[c] * (wt as f64 / k as f64);
            }
        }
        let d = p.normalize();
        (d * (1.0 + amplitude * bumps(d))).as_vec3()
    };
    ICOSAHEDRON_FACES
        .par_iter()
        .flat_map_iter(|&face| {
            let mut out = Vec::with_capacity(k * k);
            for i in 0..k {
                for j in 0..k - i {
                    let a = vertex(face, i, j);
                    let b = vertex(face, i + 1, j);
                    let c = vertex(face, i, j + 1);
                    out.push([a, b, c]);
                    if i + j + 1 < k {
                        let d = vertex(face, i + 1, j + 1);
                        out.push([b, d, c]);
                    }
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn counts_match() {
        for k in [1, 2, 5, 13] {
            assert_eq!(
                displaced_icosphere(k, 0.1).len() as u64,
                icosphere_triangles(k)
            );
        }
    }

    #[test]
    fn closed_every_edge_shared_by_exactly_two_triangles() {
        let tris = displaced_icosphere(6, 0.2);
        let key = |v: Vec3| (v.x.to_bits(), v.y.to_bits(), v.z.to_bits());
        let mut edges: HashMap<_, u32> = HashMap::new();
        for t in &tris {
            for e in 0..3 {
                let (a, b) = (key(t[e]), key(t[(e + 1) % 3]));
                *edges
                    .entry(if a < b { (a, b) } else { (b, a) })
                    .or_default() += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2), "an edge is not shared");
    }

    #[test]
    fn radius_stays_within_the_amplitude() {
        for t in displaced_icosphere(8, 0.1) {
            for v in t {
                assert!((0.9 - 1e-6..=1.1 + 1e-6).contains(&v.length()), "{v}");
            }
        }
    }
}
