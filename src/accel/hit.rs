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
    let up = if best > 0.0 {
        // Four steps up from a positive float are four steps of its bits, stopping at +∞: the
        // same as the loop below, without its tests (this runs for every improved hit).
        f32::from_bits((best.to_bits() + 4).min(f32::INFINITY.to_bits()))
    } else {
        next_float_up(next_float_up(next_float_up(next_float_up(best))))
    };
    if up < t_max { up } else { t_max }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrunk_t_max_is_four_steps_up() {
        let four = |x: f32| next_float_up(next_float_up(next_float_up(next_float_up(x))));
        let mut cases = vec![
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            1.0,
            f32::MAX,
            f32::from_bits(f32::MAX.to_bits() - 2),
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -1.0,
        ];
        let mut rng = crate::rng::Rng::seeded(4);
        cases.extend((0..10_000).map(|_| f32::from_bits(rng.next_u64() as u32)));
        for best in cases {
            for t_max in [f32::INFINITY, 1.0, best] {
                let want = {
                    let up = four(best);
                    if up < t_max { up } else { t_max }
                };
                assert_eq!(
                    shrunk_t_max(best, t_max).to_bits(),
                    want.to_bits(),
                    "{best:e} {t_max:e}"
                );
            }
        }
    }
}
