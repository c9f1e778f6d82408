//! How much light an interface reflects (Fresnel) and where the rest goes (Snell's law).

use glam::Vec3;

/// The fraction of unpolarised light a smooth interface between dielectrics reflects.
/// `cos_i` is the cosine between the incident direction and the normal, positive on the side
/// the normal points to; `eta` is the index of refraction of the far side of the normal over
/// that of its own side (the glass's IOR, for a normal pointing out of the glass). Light
/// arriving from inside sees `1/eta`. 1 past the critical angle (total internal reflection).
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (parallel * parallel + perpendicular * perpendicular)).min(1.0)
}

/// Schlick's approximation of a conductor's Fresnel reflectance: `F0 + (1 − F0)(1 − cos)⁵`,
/// `F0` its colour at normal incidence.
pub fn fresnel_schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// `wo` reflected about the unit normal `n` (both pointing away from the surface).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + n * (2.0 * wo.dot(n))
}

/// `wi` (pointing away from the surface) refracted through the interface with unit normal `n`
/// and relative index `eta` (as in [`fresnel_dielectric`]): the transmitted direction and the
/// relative index it crossed (`eta`, or `1/eta` from the far side), or `None` past the
/// critical angle.
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wi);
    let (n, eta) = if cos_i < 0.0 {
        cos_i = -cos_i;
        (-n, 1.0 / eta)
    } else {
        (n, eta)
    };
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wi / eta + n * (cos_i / eta - cos_t), eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glass_reflects_four_percent_head_on_and_everything_at_grazing() {
        // ((1.5 − 1)/(1.5 + 1))² = 0.04 at normal incidence, from either side.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // At 90° every interface reflects all of it.
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
        assert!(fresnel_dielectric(1e-4, 1.5) > 0.99);
        // An IOR of 1 is no interface.
        for k in 0..=10 {
            let c = k as f32 / 10.0;
            assert!(fresnel_dielectric(c, 1.0).abs() < 1e-6 || c == 0.0, "{c}");
        }
        // Brewster's angle, tan θ = 1.5: the parallel part vanishes, (perp²)/2 is left.
        let theta = 1.5f32.atan();
        let r = fresnel_dielectric(theta.cos(), 1.5);
        let cos_t = (1.0 - (theta.sin() / 1.5).powi(2)).sqrt();
        let perp = (theta.cos() - 1.5 * cos_t) / (theta.cos() + 1.5 * cos_t);
        assert!((r - 0.5 * perp * perp).abs() < 1e-6, "{r}");
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        // From inside glass (cos < 0 against the outward normal), sin θc = 1/1.5.
        let critical = (1.0f32 / 1.5).asin();
        for (angle, tir) in [(critical - 0.01, false), (critical + 0.01, true)] {
            let wi = Vec3::new(angle.sin(), 0.0, -angle.cos());
            assert_eq!(fresnel_dielectric(wi.z, 1.5) == 1.0, tir, "{angle}");
            assert_eq!(refract(wi, Vec3::Z, 1.5).is_none(), tir, "{angle}");
        }
        // From outside there is no critical angle.
        let wi = Vec3::new(0.999f32.sqrt(), 0.0, 0.001f32.sqrt());
        assert!(refract(wi, Vec3::Z, 1.5).is_some());
    }

    #[test]
    fn refraction_follows_snell() {
        for k in 1..10 {
            let theta = k as f32 * 0.15;
            let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
            let (wt, eta) = refract(wi, Vec3::Z, 1.5).unwrap();
            assert_eq!(eta, 1.5);
            assert!((wt.length() - 1.0).abs() < 1e-5);
            assert!(wt.z < 0.0, "goes through");
            // sin θi = η sin θt, and the tangent points away from wi's (the plane of incidence).
            assert!((theta.sin() - 1.5 * -wt.x).abs() < 1e-5, "{wt}");
            // And back out again.
            let (back, _) = refract(wt, Vec3::Z, 1.5).unwrap();
            assert!((back - wi).length() < 1e-5, "{back} vs {wi}");
        }
    }

    #[test]
    fn schlick_is_f0_head_on_and_one_at_grazing() {
        let f0 = Vec3::new(0.9, 0.6, 0.2);
        assert_eq!(fresnel_schlick(f0, 1.0), f0);
        assert!((fresnel_schlick(f0, 0.0) - Vec3::ONE).abs().max_element() < 1e-6);
        assert!(fresnel_schlick(f0, 0.5).cmpge(f0).all());
    }
}
