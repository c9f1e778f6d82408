//! What a closest-hit query returns, and the rule that keeps every structure's answer equal to
//! testing every triangle: smallest `t`, ties to the lowest index; a box culled only beyond
//! [`cull_bound`] of the best hit; triangles tested up to [`shrunk_t_max`].

use crate::geometry::next_float_up;

/// A closest hit in a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (`> 0`).
    pub t: f32,
    /// Barycentric weights of the triangle's three vertices.
    pub b: [f32; 3],
    /// Index of the triangle in [`crate::Scene::triangles`].
    pub triangle: u32,
}

/// A box is culled only if the ray enters it beyond the best hit's `t` times `1 + CULL_SLACK`.
///
/// The true hit point lies inside the triangle's box, but the watertight test's `t` carries
/// rounding error, largest for rays grazing the triangle's plane: about `u·size/θ` relative for a
/// ray at angle θ to it (u = 2⁻²⁴). 2⁻¹⁰ covers angles down to about 6e-5 rad, and costs almost
/// nothing: a box entered beyond the best hit but within a thousandth of its distance is rare.
pub const CULL_SLACK: f32 = 1.0 / 1024.0;

/// The `t` beyond which a box can hold no hit that beats `best` (or, with no hit yet, `t_max`).
#[inline]
pub fn cull_bound(bound: f32) -> f32 {
    bound * (1.0 + CULL_SLACK)
}

/// The `t_max` a triangle is tested with once a hit at `best` is known: four ULPs above it (the
/// test's own `t_max` comparisons round `t·det` and `1/det`, at most three ULPs between them), so
/// that a hit tying `best` is still reported; never above the query's `t_max`.
#[inline]
pub fn shrunk_t_max(best: f32, t_max: f32) -> f32 {
    let up = next_float_up(next_float_up(next_float_up(next_float_up(best))));
    if up < t_max { up } else { t_max }
}
