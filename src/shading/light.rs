//! What a light gives a surface: one function per kind of light. The delta lights' (point,
//! directional, spot: exact, one shadow ray each) are written once over [`Lanes`] (the tile
//! kernel's), so that one ray at a time is width 1; the area light's (emitting triangles,
//! path-traced frames only) is one point at a time. The constant environment is no function
//! here: it is what a ray that leaves the scene brings back (see [`super::Tracer`]).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::lane::{Lanes, Scalar, each3};
use super::surface::{Surface, dot, offset_origin};
use crate::geometry::Ray;
use crate::light::{AreaLights, LightPoint, MAX_CANDIDATES};
use crate::scene::{DirectionalLight, PointLight, SpotLight};

/// The kinds of light a frame ran besides point lights and emitting triangles (for `render
/// --stats`): each only where the scene has one that gives light and the frame shades.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightEffects {
    /// Directional lights (one shadow ray each per shaded point they face).
    pub directional: bool,
    /// Spot lights (one shadow ray each per shaded point within their cone).
    pub spot: bool,
    /// A constant environment (seen by rays that leave the scene; unshadowed in frames that
    /// trace no random ray).
    pub environment: bool,
}

impl LightEffects {
    /// The names, in order: "directional lights", "spot lights", "environment".
    pub fn names(&self) -> Vec<&'static str> {
        [
            (self.directional, "directional lights"),
            (self.spot, "spot lights"),
            (self.environment, "environment"),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .collect()
    }
}

/// A point drawn on the area lights, as seen from a shaded point.
pub(crate) struct AreaIncident {
    /// The unit direction toward it.
    pub wi: Vec3,
    /// What an estimate divides by: the density per solid angle of having drawn it, or
    /// where it was resampled from several candidates, an unbiased estimate's reciprocal
    /// (see [`area_light`]).
    pub pdf: f32,
    /// The density per solid angle with which one candidate lands on it (by power, then by
    /// area): what multiple importance sampling weighs against the BSDF's density, at the
    /// vertex that samples the light and at one whose BSDF ray finds it alike.
    pub candidate_pdf: f32,
    /// What its front face emits toward the point.
    pub emission: Vec3,
    /// The shadow ray: from the offset point to the light point, blocked if anything is hit
    /// before `t = 1 − SHADOW_EPSILON`.
    pub shadow: Ray,
}

/// A point on `lights` for the point `at`, from `candidates` (at most
/// [`crate::light::MAX_CANDIDATES`]) drawn by power and area. One candidate is one of `lights`
/// picked by power and a point on it by area ([`AreaLights::sample`]) from `u`. Several are
/// resampled (resampled importance sampling, Talbot, Cline and Egbert 2005): candidate `j`
/// is drawn from `u` shifted by `(j/candidates, j·φ)` modulo 1 (a Cranley-Patterson rotation:
/// each is uniform, and together they spread over the lights), and one is kept by `u_pick`
/// in proportion to `target(wi, emission)` over its density. `target` should follow what
/// the candidate would bring (the BSDF's value times the emission and the cosine,
/// unshadowed), and may be zero only where that is. The kept point's `pdf` is then
/// `target / mean weight`, whose reciprocal is an unbiased estimate of the one a density
/// would give: a candidate on the back of an emitting ball or outside a glossy lobe is
/// seldom kept. `None` where no candidate can bring anything (no shadow ray is traced).
pub(crate) fn area_light(
    lights: &AreaLights,
    at: &Surface<f32>,
    candidates: usize,
    u: Vec2,
    u_pick: f32,
    target: impl Fn(Vec3, Vec3) -> f32,
) -> Option<AreaIncident> {
    let p = Vec3::from_array(at.p);
    let m = candidates.clamp(1, MAX_CANDIDATES);
    if m == 1 {
        // One candidate: kept whatever it brings, at its own density.
        let lp = lights.sample(u)?;
        let (wi, pdf) = seen_from(&lp, p)?;
        return Some(incident(at, &lp, wi, pdf, pdf));
    }
    // Each candidate: the point, its direction, density, target and weight.
    let mut drawn = [None; MAX_CANDIDATES];
    let mut total = 0.0;
    for (j, c) in drawn[..m].iter_mut().enumerate() {
        let shift = Vec2::new(j as f32 / m as f32, j as f32 * STEP_Y);
        let Some(lp) = lights.sample(Vec2::new((u.x + shift.x).fract(), (u.y + shift.y).fract()))
        else {
            continue;
        };
        let Some((wi, pdf)) = seen_from(&lp, p) else {
            continue;
        };
        let t = target(wi, lp.emission);
        let w = t / pdf;
        if !(t > 0.0 && w.is_finite()) {
            continue;
        }
        total += w;
        *c = Some((lp, wi, pdf, t, w));
    }
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    // The candidate in whose share of the total weight `u_pick` falls.
    let mut left = u_pick * total;
    let mut kept = None;
    for c in drawn.into_iter().flatten() {
        kept = Some(c);
        left -= c.4;
        if left < 0.0 {
            break;
        }
    }
    let (lp, wi, candidate_pdf, t, _) = kept?;
    let pdf = t * m as f32 / total;
    (pdf.is_finite() && pdf > 0.0).then(|| incident(at, &lp, wi, pdf, candidate_pdf))
}

/// The unit direction from `p` toward the light point `lp`, and the density per solid angle
/// of having drawn it; `None` where the light's back faces `p` or is edge-on (only its front
/// face emits) or sits on it.
#[inline]
fn seen_from(lp: &LightPoint, p: Vec3) -> Option<(Vec3, f32)> {
    let d = lp.position - p;
    let cos_d = -d.dot(lp.front);
    if !(cos_d > 0.0) {
        return None;
    }
    // `area_to_solid_angle`'s `pdf_area·r²/cos θ`, with cos θ = cos_d/r.
    let r2 = d.length_squared();
    let r = r2.sqrt();
    let pdf = lp.pdf_area * r2 * r / cos_d;
    (pdf.is_finite() && pdf > 0.0).then(|| (d / r, pdf))
}

/// The light point `lp` as seen from `at` along `wi`, with its shadow ray.
#[inline]
fn incident(
    at: &Surface<f32>,
    lp: &LightPoint,
    wi: Vec3,
    pdf: f32,
    candidate_pdf: f32,
) -> AreaIncident {
    let origin = Vec3::from_array(offset_origin(Scalar, at, wi.to_array()));
    AreaIncident {
        wi,
        pdf,
        candidate_pdf,
        emission: lp.emission,
        shadow: Ray::new(origin, lp.position - origin),
    }
}

/// How far each candidate's second number is shifted from the previous one's (the golden
/// ratio's fraction: the shifts stay apart for any number of candidates); the path tracer
/// shifts a vertex's several light samples by it too.
pub(super) const STEP_Y: f32 = 0.618_034;

/// One light's contribution at a [`Surface`]'s points, one per lane.
pub(crate) struct Incident<F> {
    /// What the light adds per channel if nothing blocks it.
    pub term: [F; 3],
    /// The shadow ray: its origin (the offset hit point) and direction (to the light).
    pub origin: [F; 3],
    pub dir: [F; 3],
    /// The lanes the light reaches (bit per lane): it is not behind the surface or at the
    /// point. A lane not lit adds nothing and costs no shadow ray.
    pub lit: u32,
    /// The lanes whose shadow ray can be traced (a direction neither zero nor infinite); a lit
    /// lane without one counts as seen.
    pub traced: u32,
}

/// A point light at the points of `at`: irradiance `P·max(r̂·n̂, 0)/(4πr²)` with n̂ the
/// shading normal, `r²` clamped to `min_r2` (the scene's minimum light distance, squared),
/// and where `shadows` the shadow ray (else none is traced: `traced` is 0). Where the scene
/// has shading normals (`smooth`), a light must also be in front of the triangle itself: a
/// light the shading normal sees from below the surface would leak through it. The light's
/// power is not zero (a dark light is skipped before).
#[inline(always)]
pub(crate) fn point_light<S: Lanes>(
    s: S,
    light: &PointLight,
    min_r2: f32,
    at: &Surface<S::F>,
    shadows: bool,
    smooth: bool,
) -> Incident<S::F> {
    let zero = s.splat(0.0);
    let lp = light.position.to_array();
    let to_light = each3!(|k| s.sub(s.splat(lp[k]), at.p[k]));
    let dist2 = dot(s, to_light, to_light);
    let cos = s.div(dot(s, at.shading, to_light), s.sqrt(dist2));
    let mut lit = s.and(s.gt(dist2, zero), s.gt(cos, zero));
    if smooth {
        lit = s.and(lit, s.gt(dot(s, at.normal, to_light), zero));
    }
    let lit_bits = s.bits(lit);
    if lit_bits == 0 {
        // Nothing to add, no ray to trace.
        return Incident {
            term: [zero; 3],
            origin: [zero; 3],
            dir: [zero; 3],
            lit: 0,
            traced: 0,
        };
    }
    // `dist2` is positive where it matters, never NaN there.
    let denom = s.mul(s.splat(4.0 * PI), s.max(dist2, s.splat(min_r2)));
    let pw = light.power;
    let mut term = [s.div(s.mul(s.splat(pw.x), cos), denom); 3];
    // A white light's three terms are one value (the same operations on the same inputs).
    if pw.y.to_bits() != pw.x.to_bits() || pw.z.to_bits() != pw.x.to_bits() {
        term[1] = s.div(s.mul(s.splat(pw.y), cos), denom);
        term[2] = s.div(s.mul(s.splat(pw.z), cos), denom);
    }
    if !shadows {
        return Incident {
            term,
            origin: [zero; 3],
            dir: [zero; 3],
            lit: lit_bits,
            traced: 0,
        };
    }
    let origin = offset_origin(s, at, to_light);
    let dir = each3!(|k| s.sub(s.splat(lp[k]), origin[k]));
    let inf = s.splat(f32::INFINITY);
    let nonzero = s.or(
        s.or(s.ne(dir[0], zero), s.ne(dir[1], zero)),
        s.ne(dir[2], zero),
    );
    let finite = each3!(|k| s.lt(s.abs(dir[k]), inf));
    let finite = s.and(s.and(finite[0], finite[1]), finite[2]);
    Incident {
        term,
        origin,
        dir,
        lit: lit_bits,
        traced: s.bits(s.and(nonzero, finite)),
    }
}

/// An [`Incident`] that adds nothing and traces nothing.
#[inline(always)]
fn unlit<S: Lanes>(s: S) -> Incident<S::F> {
    let zero = s.splat(0.0);
    Incident {
        term: [zero; 3],
        origin: [zero; 3],
        dir: [zero; 3],
        lit: 0,
        traced: 0,
    }
}

/// A directional light at the points of `at`: irradiance `E·max(n̂·l̂, 0)` with `l̂ =
/// −direction` toward the light, and where `shadows` the shadow ray toward it, `reach` long
/// (longer than any segment within the scene's box, so that `t < 1 − ε` covers the scene). The
/// irradiance is not zero (a dark light is skipped before).
#[inline(always)]
pub(crate) fn directional_light<S: Lanes>(
    s: S,
    light: &DirectionalLight,
    reach: f32,
    at: &Surface<S::F>,
    shadows: bool,
    smooth: bool,
) -> Incident<S::F> {
    let zero = s.splat(0.0);
    let l = (-light.direction).to_array();
    let toward = each3!(|k| s.splat(l[k]));
    let cos = dot(s, at.shading, toward);
    let mut lit = s.gt(cos, zero);
    if smooth {
        lit = s.and(lit, s.gt(dot(s, at.normal, toward), zero));
    }
    let lit = s.bits(lit);
    if lit == 0 {
        return unlit(s);
    }
    let e = light.irradiance.to_array();
    let term = each3!(|k| s.mul(s.splat(e[k]), cos));
    if !shadows {
        return Incident {
            term,
            lit,
            traced: 0,
            ..unlit(s)
        };
    }
    Incident {
        term,
        origin: offset_origin(s, at, toward),
        dir: each3!(|k| s.splat(l[k] * reach)),
        lit,
        traced: lit,
    }
}

/// A spot light at the points of `at`: the [`point_light`] it is cut from, times its cone's
/// falloff ([`SpotLight::falloff`]) toward each point; points outside the cone are not lit
/// and cost no shadow ray.
#[inline(always)]
pub(crate) fn spot_light<S: Lanes>(
    s: S,
    light: &SpotLight,
    min_r2: f32,
    at: &Surface<S::F>,
    shadows: bool,
    smooth: bool,
) -> Incident<S::F> {
    let point = PointLight {
        position: light.position,
        power: light.power,
    };
    let mut inc = point_light(s, &point, min_r2, at, shadows, smooth);
    if inc.lit == 0 {
        return inc;
    }
    // The cosine between the axis and the way from the light to each point.
    let zero = s.splat(0.0);
    let lp = light.position.to_array();
    let from = each3!(|k| s.sub(at.p[k], s.splat(lp[k])));
    let axis = light.direction.to_array();
    let axis = each3!(|k| s.splat(axis[k]));
    let cos = s.div(dot(s, axis, from), s.sqrt(dot(s, from, from)));
    let (co, scale) = light.cone();
    let t = s.min(
        s.max(s.mul(s.sub(cos, s.splat(co)), s.splat(scale)), zero),
        s.splat(1.0),
    );
    let falloff = s.mul(t, t);
    let inside = s.bits(s.gt(falloff, zero));
    inc.term = each3!(|k| s.mul(inc.term[k], falloff));
    inc.lit &= inside;
    inc.traced &= inside;
    inc
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::geometry::{hit_point, offset_ray_origin};
    use crate::rng::Rng;
    use crate::shading::lane::Scalar;
    use crate::shading::surface::surface;

    fn uniform(rng: &mut Rng) -> f32 {
        (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    fn vec(rng: &mut Rng) -> Vec3 {
        Vec3::new(uniform(rng), uniform(rng), uniform(rng))
    }

    /// A point light's term and shadow ray at one point, `[term, origin, dir]` as bits, and
    /// whether it is lit and traced.
    type Bits = ([[u32; 3]; 3], bool, bool);

    fn bits(i: &Incident<f32>) -> Bits {
        let b = |v: [f32; 3]| v.map(f32::to_bits);
        (
            [b(i.term), b(i.origin), b(i.dir)],
            i.lit != 0,
            i.traced != 0,
        )
    }

    /// Random triangles, hits, rays and lights at several scales, with the edge cases (the
    /// light at the point, signed zeros, no error, an offset that lands on 0): width 1 is the
    /// scalar formulas of `geometry` (`hit_point`, `offset_ray_origin`) bit for bit, and on
    /// AVX2 eight lanes are eight times width 1.
    #[test]
    fn one_lane_is_the_scalar_formulas_and_eight_lanes_are_eight_of_one() {
        let mut rng = Rng::seeded(5);
        let mut lit = 0;
        for case in 0..4000 {
            let scale = [1e-6f32, 1.0, 1e4][case % 3];
            let light = PointLight {
                position: vec(&mut rng) * scale,
                power: Vec3::new(uniform(&mut rng).abs() * 20.0, 3.0, uniform(&mut rng).abs()),
            };
            let white = PointLight {
                power: Vec3::splat(5.0),
                ..light
            };
            let mut points = vec![];
            for i in 0..8 {
                let v = [0; 3].map(|_| vec(&mut rng) * scale);
                let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(Vec3::Y);
                let (b1, b2) = (uniform(&mut rng).abs(), uniform(&mut rng).abs());
                let b = [1.0 - b1 - b2 * (1.0 - b1), b1, b2 * (1.0 - b1)];
                let dir = vec(&mut rng).normalize_or(Vec3::X);
                let at = surface(
                    Scalar,
                    v.map(|v| v.to_array()),
                    normal.to_array(),
                    b,
                    dir.to_array(),
                );
                let (p, err) = hit_point(&v, b);
                assert_eq!(at.p.map(f32::to_bits), p.to_array().map(f32::to_bits));
                assert_eq!(at.err.map(f32::to_bits), err.to_array().map(f32::to_bits));
                let facing = if normal.dot(dir) > 0.0 {
                    -normal
                } else {
                    normal
                };
                assert_eq!(
                    at.normal.map(f32::to_bits),
                    facing.to_array().map(f32::to_bits)
                );
                let mut at = at;
                match (case + i) % 9 {
                    0 => at.p = light.position.to_array(),
                    1 => at.p = [-0.0, 0.0, at.p[2]],
                    2 => at.err = [0.0; 3],
                    3 => {
                        // A point the offset takes exactly to 0 in x (one of the signs does).
                        let n = Vec3::from_array(at.normal);
                        let d = n.abs().dot(Vec3::from_array(at.err));
                        at.p[0] = if i % 2 == 0 { n.x * d } else { -(n.x * d) };
                    }
                    _ => {}
                }
                let w = vec(&mut rng);
                let o = offset_origin(Scalar, &at, w.to_array());
                let want = offset_ray_origin(
                    Vec3::from_array(at.p),
                    Vec3::from_array(at.err),
                    Vec3::from_array(at.normal),
                    w,
                );
                assert_eq!(o.map(f32::to_bits), want.to_array().map(f32::to_bits));
                points.push(at);
            }
            for light in [light, white] {
                let one: Vec<Bits> = points
                    .iter()
                    .map(|at| bits(&point_light(Scalar, &light, 1e-4, at, true, false)))
                    .collect();
                lit += one.iter().filter(|b| b.1).count();
                #[cfg(target_arch = "x86_64")]
                if let Some(s) = crate::shading::lane::Avx2::of(crate::simd::Isa::Avx2) {
                    let lanes = |f: fn(&Surface<f32>) -> [f32; 3]| {
                        [0, 1, 2].map(|k| s.gather(|l| f(&points[l])[k]))
                    };
                    let at = Surface {
                        p: lanes(|a| a.p),
                        err: lanes(|a| a.err),
                        normal: lanes(|a| a.normal),
                        shading: lanes(|a| a.shading),
                    };
                    let eight = point_light(s, &light, 1e-4, &at, true, false);
                    let lane = |v: &[std::arch::x86_64::__m256; 3], l: usize| {
                        v.map(|v| {
                            let mut a = [0.0; 8];
                            s.store(&mut a, v);
                            a[l]
                        })
                    };
                    for (l, want) in one.iter().enumerate() {
                        let got = Incident {
                            term: lane(&eight.term, l),
                            origin: lane(&eight.origin, l),
                            dir: lane(&eight.dir, l),
                            lit: eight.lit >> l & 1,
                            traced: eight.traced >> l & 1,
                        };
                        // Terms and rays of lanes not lit are not used: compare the rest.
                        let got = bits(&got);
                        assert_eq!(got.1, want.1, "case {case} lane {l}");
                        if want.1 {
                            assert_eq!((got.0, got.2), (want.0, want.2), "case {case} lane {l}");
                        }
                    }
                }
            }
        }
        assert!(lit > 10_000, "only {lit} points lit");
    }

    /// Resampling from several candidates keeps the mean of one candidate's estimate and
    /// lowers its spread where emitters face away: an emitting ball's two halves (a cube's
    /// faces, all emitting outwards) and a flat light beside it, seen from a point below.
    #[test]
    fn resampled_light_samples_keep_the_mean_and_lower_the_spread() {
        use crate::geometry::Triangle;
        use crate::light::AreaLights;
        let cube = |c: Vec3, h: f32| {
            let mut t = vec![];
            for axis in 0..3 {
                for sign in [-1.0f32, 1.0] {
                    let mut n = Vec3::ZERO;
                    n[axis] = sign;
                    let (a, b) = (
                        n.any_orthonormal_pair().0 * h,
                        n.any_orthonormal_pair().1 * h,
                    );
                    let f = c + n * h;
                    // Counter-clockwise seen from outside: the front faces out.
                    let quad = [f - a - b, f + a - b, f + a + b, f - a + b];
                    for (i, j, k) in [(0, 1, 2), (0, 2, 3)] {
                        let mut tri = Triangle::new(quad[i], quad[j], quad[k], 0).unwrap();
                        if tri.front().dot(n) < 0.0 {
                            tri = Triangle::new(quad[i], quad[k], quad[j], 0).unwrap();
                        }
                        t.push(tri);
                    }
                }
            }
            t
        };
        let mut tris = cube(Vec3::new(-0.6, -1.0, 0.3), 0.2);
        tris.extend(cube(Vec3::new(0.7, -1.5, -0.2), 0.35));
        let lights = AreaLights::new(&tris, |_| Vec3::new(1.0, 0.8, 0.5)).unwrap();
        assert!(lights.candidates() > 1);
        let at = surface(
            Scalar,
            [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]],
            [0.0, -1.0, 0.0],
            [0.3, 0.3, 0.4],
            [0.0, 1.0, 0.0],
        );
        let n = Vec3::from_array(at.shading);
        let target = |wi: Vec3, e: Vec3| (e.x + e.y + e.z) * n.dot(wi).max(0.0);
        // The estimate of Σ emission·cos over the lights' solid angle, by each count of
        // candidates: mean and standard deviation over seeded draws.
        let estimate = |m: usize| {
            let mut rng = Rng::seeded(17);
            let k = 400_000;
            let (mut sum, mut sq) = (0.0f64, 0.0f64);
            for _ in 0..k {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                let x = match area_light(&lights, &at, m, u, rng.next_f32(), target) {
                    Some(i) => f64::from(target(i.wi, i.emission) / i.pdf),
                    None => 0.0,
                };
                sum += x;
                sq += x * x;
            }
            let mean = sum / f64::from(k);
            (
                mean,
                (sq / f64::from(k) - mean * mean).sqrt(),
                (k as f64).sqrt(),
            )
        };
        let (one, one_sd, root) = estimate(1);
        for m in [2, 4] {
            let (mean, sd, _) = estimate(m);
            let se = (one_sd * one_sd + sd * sd).sqrt() / root;
            assert!(
                (mean - one).abs() < 4.0 * se,
                "{m}: {mean} vs {one} (se {se})"
            );
            assert!(sd < 0.9 * one_sd, "{m}: spread {sd} vs {one_sd}");
        }
    }
}
