//! Every BSDF answers pbrt-v4's four questions consistently, and physically: its sampling
//! draws directions with the density its `pdf` states (a χ² test over seeded directions, as
//! Mitsuba 3 and pbrt-v4 test theirs), it reflects no more than arrives (albedo ≤ 1 by Monte
//! Carlo), it is reciprocal, glass reflects and refracts as Fresnel and Snell say, and no input
//! (roughness 0 or 1, IOR 1, grazing directions) gives NaN or infinity.

use glam::{Vec2, Vec3};
use raytty::material::SurfaceBsdf;
use raytty::material::{
    Bsdf, BsdfFlags, Conductor, Dielectric, Lambertian, Mirror, RoughDielectric, ShadingFrame,
    fresnel_dielectric,
};
use raytty::rng::Rng;

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

fn uniform_sphere(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    dir(
        z.clamp(-1.0, 1.0).acos(),
        std::f32::consts::TAU * rng.next_f32(),
    )
}

/// What the χ² test asks of a sampler: one BSDF, or a material's weighted lobes.
trait Sampled {
    fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<raytty::material::BsdfSample>;
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3;
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
}

impl Sampled for Bsdf {
    fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<raytty::material::BsdfSample> {
        Bsdf::sample_f(self, wo, uc, u)
    }
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        Bsdf::f(self, wo, wi)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        Bsdf::pdf(self, wo, wi)
    }
}

impl Sampled for SurfaceBsdf {
    fn sample_f(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<raytty::material::BsdfSample> {
        SurfaceBsdf::sample_f(self, wo, uc, u)
    }
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        SurfaceBsdf::f(self, wo, wi)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        SurfaceBsdf::pdf(self, wo, wi)
    }
}

fn draw(bsdf: &impl Sampled, wo: Vec3, rng: &mut Rng) -> Option<raytty::material::BsdfSample> {
    let uc = rng.next_f32();
    let u = Vec2::new(rng.next_f32(), rng.next_f32());
    bsdf.sample_f(wo, uc, u)
}

/// The glossy and diffuse BSDFs the χ² test runs on, by name.
fn sampled_bsdfs() -> Vec<(&'static str, Bsdf)> {
    vec![
        (
            "lambertian",
            Bsdf::Lambertian(Lambertian {
                reflectance: Vec3::new(0.8, 0.5, 0.2),
            }),
        ),
        (
            "conductor r=0.4",
            Bsdf::Conductor(Conductor::new(Vec3::new(0.95, 0.64, 0.54), 0.4)),
        ),
        (
            "conductor r=1",
            Bsdf::Conductor(Conductor::new(Vec3::ONE, 1.0)),
        ),
        (
            "rough glass r=0.5",
            Bsdf::RoughDielectric(RoughDielectric::new(1.5, 0.5)),
        ),
        (
            "rough glass r=0.3 eta=1.33",
            Bsdf::RoughDielectric(RoughDielectric::new(1.33, 0.3)),
        ),
    ]
}

/// Outgoing directions the tests use: near the normal, oblique, grazing, and from below.
fn outgoing() -> [Vec3; 5] {
    [
        dir(0.05, 0.3),
        dir(0.8, 1.0),
        dir(1.45, 2.0),
        dir(2.6, 0.5),
        dir(1.8, 4.0),
    ]
}

/// Equal-area bins over the sphere: `Z_BINS` in cos θ times `PHI_BINS` in φ.
const Z_BINS: usize = 24;
const PHI_BINS: usize = 48;

/// The bins' frame, turned away from the surface's: a lobe around the normal (head-on
/// reflection, transmission straight through) would otherwise sit on a pole of the grid,
/// where its cells are thin wedges that the midpoint rule integrates badly.
fn bin_frame() -> glam::Quat {
    glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9)
}

fn bin_of(w: Vec3) -> usize {
    let w = bin_frame() * w;
    let z = ((w.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * Z_BINS as f32) as usize;
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += std::f32::consts::TAU;
    }
    let p = (phi / std::f32::consts::TAU * PHI_BINS as f32) as usize;
    z.min(Z_BINS - 1) * PHI_BINS + p.min(PHI_BINS - 1)
}

/// Each bin's probability by the stated pdf, integrated by the midpoint rule on a `k`×`k`
/// grid per bin (in cos θ and φ, so each cell has the same solid angle).
fn expected(bsdf: &impl Sampled, wo: Vec3, k: usize) -> Vec<f64> {
    let cell = 4.0 * std::f64::consts::PI / (Z_BINS * PHI_BINS * k * k) as f64;
    let mut out = vec![0.0; Z_BINS * PHI_BINS];
    for (b, e) in out.iter_mut().enumerate() {
        let (zb, pb) = (b / PHI_BINS, b % PHI_BINS);
        let mut sum = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let z = -1.0 + 2.0 * (zb as f64 + (i as f64 + 0.5) / k as f64) / Z_BINS as f64;
                let phi = std::f64::consts::TAU * (pb as f64 + (j as f64 + 0.5) / k as f64)
                    / PHI_BINS as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                let wi = bin_frame().inverse() * w;
                sum += f64::from(bsdf.pdf(wo, wi));
            }
        }
        *e = sum * cell;
    }
    out
}

/// Pearson's χ² of `counts` against `expected` probabilities of `n` draws, bins expected to
/// hold fewer than 5 pooled into one, as a z-score by Wilson and Hilferty's cube-root normal
/// approximation of the χ² distribution (accurate for the hundreds of degrees of freedom
/// here): a true sampler gives z of about ±1, a z above 4.5 has probability 3·10⁻⁶.
fn chi2_z(counts: &[u64], expected: &[f64], n: u64) -> (f64, usize) {
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
    for (&o, &p) in counts.iter().zip(expected) {
        let e = p * n as f64;
        if e < 5.0 {
            pooled_o += o as f64;
            pooled_e += e;
        } else {
            chi2 += (o as f64 - e).powi(2) / e;
            dof += 1;
        }
    }
    if pooled_e > 0.0 {
        chi2 += (pooled_o - pooled_e).powi(2) / pooled_e;
        dof += 1;
    }
    let k = (dof - 1) as f64;
    let z = ((chi2 / k).cbrt() - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    (z, dof)
}

/// Draws `n` directions and bins them; also checks each sample against `f` and `pdf`.
fn histogram(bsdf: &impl Sampled, wo: Vec3, n: u64, seed: u64) -> Vec<u64> {
    let mut rng = Rng::seeded(seed);
    let mut counts = vec![0u64; Z_BINS * PHI_BINS];
    for _ in 0..n {
        let Some(s) = draw(bsdf, wo, &mut rng) else {
            continue;
        };
        assert!(!s.flags.is_specular());
        assert!((s.wi.length() - 1.0).abs() < 1e-4, "{}", s.wi);
        let (f, pdf) = (bsdf.f(wo, s.wi), bsdf.pdf(wo, s.wi));
        assert!(
            (s.pdf - pdf).abs() <= 1e-3 * pdf
                && (s.value - f).abs().max_element() <= 1e-3 * f.max_element(),
            "sample ({}, {}) vs f {f}, pdf {pdf} at wo {wo} wi {}",
            s.value,
            s.pdf,
            s.wi
        );
        counts[bin_of(s.wi)] += 1;
    }
    counts
}

#[test]
fn sampling_matches_the_pdf_by_chi_square() {
    let n = 200_000;
    for (name, bsdf) in sampled_bsdfs() {
        for (i, wo) in outgoing().into_iter().enumerate() {
            let counts = histogram(&bsdf, wo, n, 100 + i as u64);
            let e = expected(&bsdf, wo, 12);
            let (z, dof) = chi2_z(&counts, &e, n);
            // The pdf's total is the share of draws that give a direction.
            let drawn: u64 = counts.iter().sum();
            let total: f64 = e.iter().sum();
            eprintln!("{name}, wo {wo}: χ² z = {z:.2} ({dof} bins), mass {total:.4}");
            assert!(
                (total - drawn as f64 / n as f64).abs() < 0.01,
                "{name}, wo {wo}: pdf integrates to {total}, {drawn} of {n} drawn"
            );
            assert!(z < 4.5, "{name}, wo {wo}: χ² z = {z} over {dof} bins");
        }
    }
}

/// A material of several glossy and diffuse parts (a scene's `Material` as the path tracer
/// sees it) samples its mixture with the density its `pdf` states: the lobe picked by weight,
/// the value and pdf those of the whole sum.
#[test]
fn a_materials_mixture_samples_its_pdf_by_chi_square() {
    let n = 200_000;
    let m = raytty::Material {
        metal: 0.3,
        transmission: 0.5,
        roughness: 0.4,
        ..raytty::Material::diffuse(Vec3::new(0.8, 0.6, 0.3))
    };
    let bsdf = SurfaceBsdf::new(&m, m.colour);
    for (i, wo) in outgoing().into_iter().enumerate() {
        let counts = histogram(&bsdf, wo, n, 300 + i as u64);
        let e = expected(&bsdf, wo, 12);
        let (z, dof) = chi2_z(&counts, &e, n);
        let drawn: u64 = counts.iter().sum();
        let total: f64 = e.iter().sum();
        assert!(
            (total - drawn as f64 / n as f64).abs() < 0.01,
            "wo {wo}: pdf integrates to {total}, {drawn} of {n} drawn"
        );
        assert!(z < 4.5, "wo {wo}: χ² z = {z} over {dof} bins");
    }
}

#[test]
fn the_chi_square_test_rejects_a_wrong_pdf() {
    // Lambertian samples judged against a uniform hemisphere's pdf: must fail.
    let lambert = Bsdf::Lambertian(Lambertian {
        reflectance: Vec3::ONE,
    });
    let n = 200_000;
    let counts = histogram(&lambert, Vec3::Z, n, 1);
    let uniform = {
        let mut e = vec![0.0; Z_BINS * PHI_BINS];
        for (b, p) in e.iter_mut().enumerate() {
            if b / PHI_BINS >= Z_BINS / 2 {
                *p = 1.0 / (Z_BINS * PHI_BINS / 2) as f64;
            }
        }
        e
    };
    let (z, _) = chi2_z(&counts, &uniform, n);
    assert!(z > 10.0, "z = {z}");
    // And a conductor judged by a rougher one's pdf.
    let c = Bsdf::Conductor(Conductor::new(Vec3::ONE, 0.4));
    let rougher = Bsdf::Conductor(Conductor::new(Vec3::ONE, 0.5));
    let counts = histogram(&c, dir(0.8, 1.0), n, 2);
    let (z, _) = chi2_z(&counts, &expected(&rougher, dir(0.8, 1.0), 12), n);
    assert!(z > 10.0, "z = {z}");
}

/// `E[f·|cos θi|/pdf]`, with transmitted samples weighed by η'² so that the estimate is the
/// fraction of energy (flux) that leaves, not of radiance, and its standard error.
fn albedo(bsdf: &Bsdf, wo: Vec3, n: u32, seed: u64) -> (Vec3, Vec3) {
    let mut rng = Rng::seeded(seed);
    let (mut sum, mut sum2) = (Vec3::ZERO, Vec3::ZERO);
    for _ in 0..n {
        if let Some(s) = draw(bsdf, wo, &mut rng) {
            let mut w = s.weight();
            if s.flags.contains(BsdfFlags::TRANSMISSION) {
                w *= eta_ratio(bsdf, wo).powi(2);
            }
            assert!(w.is_finite(), "{w}");
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f32;
    let var = (sum2 / n as f32 - mean * mean).max(Vec3::ZERO);
    (mean, (var / n as f32).powf(0.5))
}

/// η' of a refraction from `wo`'s side: the far side's index over the near side's.
fn eta_ratio(bsdf: &Bsdf, wo: Vec3) -> f32 {
    let eta = match bsdf {
        Bsdf::Dielectric(d) => d.eta,
        Bsdf::RoughDielectric(d) => d.eta,
        _ => 1.0,
    };
    if wo.z > 0.0 { eta } else { 1.0 / eta }
}

fn every_bsdf() -> Vec<(&'static str, Bsdf)> {
    let mut all = sampled_bsdfs();
    all.extend([
        (
            "mirror",
            Bsdf::Mirror(Mirror {
                reflectance: Vec3::new(0.9, 0.8, 1.0),
            }),
        ),
        (
            "conductor r=0",
            Bsdf::Conductor(Conductor::new(Vec3::ONE, 0.0)),
        ),
        (
            "conductor r=0.1",
            Bsdf::Conductor(Conductor::new(Vec3::ONE, 0.1)),
        ),
        ("glass", Bsdf::Dielectric(Dielectric { eta: 1.5 })),
        ("glass eta=1", Bsdf::Dielectric(Dielectric { eta: 1.0 })),
        (
            "rough glass r=0",
            Bsdf::RoughDielectric(RoughDielectric::new(1.5, 0.0)),
        ),
        (
            "rough glass r=1",
            Bsdf::RoughDielectric(RoughDielectric::new(1.5, 1.0)),
        ),
        (
            "rough glass eta=1",
            Bsdf::RoughDielectric(RoughDielectric::new(1.0, 0.5)),
        ),
    ]);
    all
}

#[test]
fn no_bsdf_reflects_more_than_arrives() {
    for (name, bsdf) in every_bsdf() {
        for (i, wo) in outgoing().into_iter().enumerate() {
            let (a, err) = albedo(&bsdf, wo, 100_000, 7 + i as u64);
            eprintln!("{name}, wo {wo}: albedo {a} ± {err}");
            assert!(
                (a - 3.0 * err).max_element() <= 1.0 + 1e-4,
                "{name}, wo {wo}: albedo {a} ± {err}"
            );
        }
    }
}

#[test]
fn lossless_materials_return_everything() {
    // A white Lambertian and glass lose nothing; a white metal loses only what single
    // scattering on GGX microfacets loses (a few % at this roughness, more at grazing).
    let white = Bsdf::Lambertian(Lambertian {
        reflectance: Vec3::ONE,
    });
    let glass = Bsdf::Dielectric(Dielectric { eta: 1.5 });
    let metal = Bsdf::Conductor(Conductor::new(Vec3::ONE, 0.3));
    for (i, wo) in outgoing().into_iter().enumerate() {
        for bsdf in [&white, &glass] {
            let (a, err) = albedo(bsdf, wo, 50_000, 40 + i as u64);
            assert!(
                (a - Vec3::ONE).abs().max_element() < 4.0 * err.max_element() + 1e-4,
                "{bsdf:?} {wo}: {a}"
            );
        }
        if wo.z.abs() > 0.3 {
            let (a, _) = albedo(&metal, wo, 50_000, 60 + i as u64);
            assert!(a.min_element() > 0.93, "{wo}: {a}");
        }
    }
}

/// The IOR of the medium a local direction lies in, for glass of index `eta` below z = 0.
fn medium(w: Vec3, eta: f32) -> f32 {
    if w.z > 0.0 { 1.0 } else { eta }
}

#[test]
fn bsdfs_are_reciprocal() {
    let mut rng = Rng::seeded(17);
    let mut transmitted = 0;
    for (name, bsdf) in every_bsdf() {
        let eta = match bsdf {
            Bsdf::RoughDielectric(d) => d.eta,
            _ => 1.0,
        };
        for _ in 0..20_000 {
            let (wo, wi) = (uniform_sphere(&mut rng), uniform_sphere(&mut rng));
            // Radiance BSDFs through an interface obey f(wo, wi)·ηi² = f(wi, wo)·ηo² (Veach
            // 1997, §5.2); reflection is plain symmetry. Through a microfacet seen almost
            // edge-on, 1 − F is a small difference of f32 values: a looser bound there (a
            // missing η² would be off by 125 %).
            let a = bsdf.f(wo, wi) * medium(wi, eta).powi(2);
            let b = bsdf.f(wi, wo) * medium(wo, eta).powi(2);
            let scale = a.max_element().max(b.max_element());
            let tol = if wo.z * wi.z < 0.0 { 2e-2 } else { 1e-3 };
            assert!(
                (a - b).abs().max_element() <= tol * scale + 1e-6,
                "{name}: f({wo}, {wi}) = {a}, reversed {b}"
            );
            if wo.z * wi.z < 0.0 && scale > 0.0 {
                transmitted += 1;
            }
        }
    }
    assert!(
        transmitted > 1000,
        "transmission was hardly tested: {transmitted}"
    );
}

#[test]
fn glass_reflects_past_the_critical_angle_and_follows_fresnel() {
    let glass = Bsdf::Dielectric(Dielectric { eta: 1.5 });
    let critical = (1.0f32 / 1.5).asin();
    // From inside (below), past the critical angle: every draw reflects, all of it.
    for theta in [critical + 0.01, 1.2, 1.5] {
        let wo = Vec3::new(theta.sin(), 0.0, -theta.cos());
        for k in 0..10 {
            let s = glass.sample_f(wo, k as f32 / 10.0, Vec2::ZERO).unwrap();
            assert!(s.flags.contains(BsdfFlags::REFLECTION), "{theta}");
            assert!((s.weight() - Vec3::ONE).abs().max_element() < 1e-5);
        }
        let rough = Bsdf::RoughDielectric(RoughDielectric::new(1.5, 0.05));
        let mut rng = Rng::seeded(4);
        for _ in 0..1000 {
            if let Some(s) = draw(&rough, wo, &mut rng) {
                // A rough facet tilts the critical angle a little; well past it, no draw
                // transmits.
                if theta > 1.2 {
                    assert!(s.flags.contains(BsdfFlags::REFLECTION), "{theta}");
                }
            }
        }
    }
    // Just inside the critical angle some light gets out.
    let wo = Vec3::new((critical - 0.01).sin(), 0.0, -(critical - 0.01).cos());
    assert!(
        glass
            .sample_f(wo, 0.99, Vec2::ZERO)
            .unwrap()
            .flags
            .contains(BsdfFlags::TRANSMISSION)
    );
    // Head on 4 % reflects (the draw's probability), at grazing all of it.
    let head_on = glass.sample_f(Vec3::Z, 0.0, Vec2::ZERO).unwrap();
    assert!((head_on.pdf - 0.04).abs() < 1e-6);
    let through = glass.sample_f(Vec3::Z, 0.5, Vec2::ZERO).unwrap();
    assert!((through.pdf - 0.96).abs() < 1e-6 && (through.wi + Vec3::Z).length() < 1e-6);
    // Transmitted radiance is concentrated by η² going in, as etendue says.
    assert!(
        (through.weight() - Vec3::splat(1.0 / 2.25))
            .abs()
            .max_element()
            < 1e-6
    );
    let grazing = Vec3::new(1.0, 0.0, 1e-4).normalize();
    assert!(fresnel_dielectric(grazing.z, 1.5) > 0.999);
}

#[test]
fn energy_is_conserved_through_a_slab_of_glass() {
    // Light enters a smooth slab and bounces between its faces until it leaves: it leaves up
    // with the slab's reflectance 2R/(1 + R) (R the one interface's, the same from both sides
    // at the refracted angle), and down with the rest; nothing is lost.
    let glass = Bsdf::Dielectric(Dielectric { eta: 1.5 });
    let mut rng = Rng::seeded(21);
    for theta in [0.0f32, 0.7, 1.3] {
        let n = 200_000;
        let (mut up, mut down) = (0.0f64, 0.0f64);
        for _ in 0..n {
            // Local frame of the top face (glass below it); the bottom face's frame is this
            // one upside down, so a direction there is the mirror image in z.
            let mut wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            let mut weight = 1.0f32;
            let mut top = true;
            loop {
                let s = glass.sample_f(wo, rng.next_f32(), Vec2::ZERO).unwrap();
                let w = s.weight().x
                    * if s.flags.contains(BsdfFlags::TRANSMISSION) {
                        eta_ratio(&glass, wo).powi(2)
                    } else {
                        1.0
                    };
                weight *= w;
                if s.wi.z > 0.0 {
                    // Outside this face: gone.
                    if top {
                        up += f64::from(weight);
                    } else {
                        down += f64::from(weight);
                    }
                    break;
                }
                // Inside: travels to the other face, where it arrives as that face's wo (the
                // way back, -wi, seen in the flipped frame).
                wo = Vec3::new(-s.wi.x, -s.wi.y, s.wi.z);
                top = !top;
            }
        }
        let r = f64::from(fresnel_dielectric(theta.cos(), 1.5));
        let (up, down) = (up / n as f64, down / n as f64);
        assert!((up + down - 1.0).abs() < 1e-5, "{theta}: {up} + {down}");
        let want = 2.0 * r / (1.0 + r);
        let err = 4.0 * (want * (1.0 - want) / n as f64).sqrt();
        assert!(
            (up - want).abs() < err,
            "{theta}: reflected {up}, want {want}"
        );
    }
}

#[test]
fn no_nan_or_infinity_anywhere() {
    let mut dirs: Vec<Vec3> = outgoing().to_vec();
    // Grazing from both sides, exactly in the plane, and nearly along the normal.
    for z in [1e-7f32, -1e-7, 0.0, 1e-3, -1e-3, 1.0, -1.0] {
        dirs.push(Vec3::new((1.0 - z * z).sqrt(), 0.0, z));
    }
    let mut rng = Rng::seeded(99);
    for _ in 0..50 {
        dirs.push(uniform_sphere(&mut rng));
    }
    for (name, bsdf) in every_bsdf() {
        for &wo in &dirs {
            for &wi in &dirs {
                let (f, pdf) = (bsdf.f(wo, wi), bsdf.pdf(wo, wi));
                assert!(
                    f.is_finite() && f.min_element() >= 0.0,
                    "{name}: f({wo}, {wi}) = {f}"
                );
                assert!(
                    pdf.is_finite() && pdf >= 0.0,
                    "{name}: pdf({wo}, {wi}) = {pdf}"
                );
            }
            for u in [0.0, 0.5, 0.999_999_9] {
                for uc in [0.0, 0.3, 0.999_999_9] {
                    if let Some(s) = bsdf.sample_f(wo, uc, Vec2::new(u, 1.0 - u)) {
                        let w = s.weight();
                        assert!(
                            s.pdf > 0.0 && s.pdf.is_finite() && w.is_finite() && s.wi.is_finite(),
                            "{name}: wo {wo}: {s:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn the_shading_frame_round_trips() {
    let mut rng = Rng::seeded(1);
    for _ in 0..1000 {
        let n = uniform_sphere(&mut rng).normalize();
        let frame = ShadingFrame::from_normal(n);
        assert!((frame.to_local(n) - Vec3::Z).length() < 1e-5);
        let v = uniform_sphere(&mut rng);
        assert!((frame.to_world(frame.to_local(v)) - v).length() < 1e-5);
        assert!(frame.tangent.dot(n).abs() < 1e-5 && frame.bitangent.dot(n).abs() < 1e-5);
    }
}
