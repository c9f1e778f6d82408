//! Physically based light transport (issue 21): the white furnace, the three estimators
//! agreeing, glass conserving energy, the effects a scene calls for, and no NaN or infinity
//! from any corner of the materials. Small frames with fixed seeds: each test renders the same
//! bytes every run. Heavier sweeps are `#[ignore]`d.

use glam::{Vec2, Vec3};
use raytty::material::SurfaceBsdf;
use raytty::rng::Rng;
use raytty::scene::builtin;
use raytty::scene::procedural::displaced_icosphere;
use raytty::shading::Estimator;
use raytty::{
    Camera, Effects, Image, Indirect, Material, Options, Scene, SceneBuilder, Settings, Stage,
};

/// Stage 6's settings with `spp` samples, frame `frame`, estimator `e`.
fn gi(spp: u32, frame: u32, e: Estimator) -> Settings {
    let mut s = Stage::Gi.settings(Effects::SEED);
    s.effects.samples = spp;
    s.frame = frame;
    s.estimator = e;
    s
}

fn render(scene: &Scene, w: u32, h: u32, s: Settings, camera: Option<Camera>) -> Image {
    scene
        .render(&Options {
            width: w,
            height: h,
            settings: Some(s),
            camera,
            ..Options::default()
        })
        .image
}

fn mean(img: &Image) -> Vec3 {
    img.pixels.iter().copied().sum::<Vec3>() / img.pixels.len() as f32
}

/// A sphere of radius 10 about the origin whose inside emits `e` and reflects nothing, around
/// a unit ball of `material`.
fn furnace(material: Material, e: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let wall = b.material(Material {
        emission: Vec3::splat(e),
        ..Material::diffuse(Vec3::ZERO)
    });
    let ball = b.material(material);
    // The icosphere's triangles face out; turned round, the enclosure faces in.
    let inside = displaced_icosphere(6, 0.0)
        .into_iter()
        .map(|[a, b, c]| [a * 10.0, c * 10.0, b * 10.0]);
    b.object(inside, wall);
    b.object(displaced_icosphere(12, 0.0), ball);
    b.build("furnace", Camera::default(), Effects::SEED)
        .unwrap()
}

/// White furnace: under uniform emission, a ball that absorbs nothing sends back exactly the
/// emission, whatever it is made of: the whole frame is the emission, within noise. (A rough
/// GGX metal loses what its single-scattering model drops between microfacets: a known
/// deficit, bounded here.)
#[test]
fn white_furnace_every_material_returns_the_emission() {
    let e = 0.5;
    let white = Vec3::ONE;
    let cases = [
        ("diffuse", Material::diffuse(white), 0.01),
        (
            "mirror",
            Material {
                mirror: 1.0,
                ..Material::diffuse(white)
            },
            0.01,
        ),
        (
            "smooth metal",
            Material {
                metal: 1.0,
                ..Material::diffuse(white)
            },
            0.01,
        ),
        (
            "metal 0.3",
            Material {
                metal: 1.0,
                roughness: 0.3,
                ..Material::diffuse(white)
            },
            0.02,
        ),
        (
            "glass",
            Material {
                transmission: 1.0,
                ..Material::diffuse(white)
            },
            0.02,
        ),
        (
            "rough glass 0.3",
            Material {
                transmission: 1.0,
                roughness: 0.3,
                ..Material::diffuse(white)
            },
            0.03,
        ),
        (
            "ior 1",
            Material {
                transmission: 1.0,
                ior: 1.0,
                ..Material::diffuse(white)
            },
            0.01,
        ),
    ];
    for (name, m, tol) in cases {
        let scene = furnace(m, e);
        for est in [Estimator::Auto, Estimator::Mis, Estimator::Bsdf] {
            let img = render(&scene, 24, 24, gi(32, 0, est), None);
            let got = mean(&img);
            assert!(
                (got - Vec3::splat(e)).abs().max_element() <= tol,
                "{name}, {est:?}: {got} for {e}"
            );
            assert!(img.pixels.iter().all(|p| p.is_finite()), "{name}");
        }
    }
    // A rough metal loses energy (single scattering), never gains it.
    let rough = furnace(
        Material {
            metal: 1.0,
            roughness: 1.0,
            ..Material::diffuse(white)
        },
        e,
    );
    let got = mean(&render(&rough, 24, 24, gi(32, 0, Estimator::Auto), None));
    assert!(
        got.max_element() <= e * 1.01 && got.min_element() >= 0.6 * e,
        "{got}"
    );
}

/// Light sampling alone, BSDF sampling alone and MIS are three estimators of one integral:
/// on the plates (small and large lights, smooth and rough metal) their frame means agree
/// within four standard errors (estimated from 32 independent frames: with 8, one frame's
/// firefly could decide which estimator looked least noisy).
#[test]
fn light_bsdf_and_mis_agree_on_the_mean() {
    let scene = builtin::find("plates").unwrap().load().unwrap();
    let frames = 32;
    let stats = |e: Estimator| {
        let means: Vec<Vec3> = (0..frames)
            .map(|f| mean(&render(&scene, 40, 25, gi(8, 100 + f, e), None)))
            .collect();
        let m = means.iter().copied().sum::<Vec3>() / frames as f32;
        let var = means.iter().map(|x| (*x - m) * (*x - m)).sum::<Vec3>() / (frames - 1) as f32;
        (m, var / frames as f32)
    };
    let (light, bsdf, mis) = (
        stats(Estimator::Light),
        stats(Estimator::Bsdf),
        stats(Estimator::Mis),
    );
    for (a, b, what) in [
        (light, mis, "light vs mis"),
        (bsdf, mis, "bsdf vs mis"),
        (light, bsdf, "light vs bsdf"),
    ] {
        let se = (a.1 + b.1).max(Vec3::splat(1e-12)).powf(0.5);
        let z = ((a.0 - b.0).abs() / se).max_element();
        assert!(z < 4.0, "{what}: {} vs {} (z = {z})", a.0, b.0);
    }
    // And MIS is the least noisy of the three here.
    assert!(
        mis.1.max_element() <= light.1.max_element() && mis.1.max_element() <= bsdf.1.max_element(),
        "{mis:?} {light:?} {bsdf:?}"
    );
}

/// A slab of glass (two parallel smooth interfaces) absorbs nothing: what enters is reflected
/// or transmitted, and head on it transmits (1 − R)/(1 + R) with R = 0.04. Followed through
/// the material's own sampling, internal reflections and all.
#[test]
fn glass_slab_conserves_energy() {
    for roughness in [0.0f32, 0.3] {
        let glass = Material {
            transmission: 1.0,
            roughness,
            ..Material::diffuse(Vec3::ONE)
        };
        let bsdf = SurfaceBsdf::new(&glass, Vec3::ONE);
        let mut rng = Rng::seeded(3);
        for theta in [0.0f32, 0.5, 1.2] {
            let n = 100_000;
            let (mut reflected, mut transmitted) = (0.0f64, 0.0f64);
            for _ in 0..n {
                // The top face is z = 0 with air above (its front, +z); the bottom face is the
                // same interface turned over (its front, air, below): its frame flips z.
                let flip = |v: Vec3| Vec3::new(v.x, v.y, -v.z);
                let mut dir = -Vec3::new(theta.sin(), 0.0, theta.cos());
                let mut top = true;
                let mut weight = 1.0f32;
                let mut exit = None;
                for _ in 0..64 {
                    let wo = if top { -dir } else { flip(-dir) };
                    let u = Vec2::new(rng.next_f32(), rng.next_f32());
                    let Some(s) = bsdf.sample_f(wo, rng.next_f32(), u) else {
                        break;
                    };
                    weight *= s.weight().x;
                    if s.wi.z > 0.0 {
                        // Out into the air: above the slab from the top face, below from the
                        // bottom one.
                        exit = Some(top);
                        break;
                    }
                    dir = if top { s.wi } else { flip(s.wi) };
                    top = !top;
                }
                match exit {
                    Some(true) => reflected += f64::from(weight),
                    Some(false) => transmitted += f64::from(weight),
                    None => {}
                }
            }
            let (r, t) = (reflected / n as f64, transmitted / n as f64);
            let total = r + t;
            if roughness == 0.0 {
                assert!((total - 1.0).abs() < 0.01, "θ {theta}: R {r} + T {t}");
                if theta == 0.0 {
                    assert!((t - 0.96 / 1.04).abs() < 0.01, "T {t}");
                }
            } else {
                assert!(
                    total <= 1.01 && total > 0.85,
                    "rough θ {theta}: R {r} + T {t}"
                );
            }
        }
    }
}

/// The effects a frame runs come from the scene: the seed's scenes run none of the physically
/// based path; the area-lit box samples its light with no MIS (nothing is glossy) and
/// refracts nothing; the plates use MIS; glass refracts. `render --stats` names them.
#[test]
fn effects_are_what_the_scene_calls_for() {
    let names = |name: &str| {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let s = scene
            .render(&Options {
                width: 8,
                height: 6,
                settings: Some(gi(1, 0, Estimator::Auto)),
                ..Options::default()
            })
            .stats;
        s.path.map(|p| p.names()).unwrap_or_default()
    };
    for seed in ["cornell", "mirror", "lights"] {
        assert!(names(seed).is_empty(), "{seed}");
    }
    assert_eq!(names("area"), ["path", "area lights (light sampling)"]);
    assert_eq!(
        names("plates"),
        ["path", "area lights (mis)", "glossy", "metal"]
    );
    assert_eq!(
        names("glass"),
        ["path", "area lights (mis)", "glossy", "refraction"]
    );
    // Stages 1–5 of the seed's stages run the seed's shading.
    let area = builtin::find("area").unwrap().load().unwrap();
    let s = area
        .render(&Options {
            width: 8,
            height: 6,
            settings: Some(Stage::Shadows.settings(area.effects())),
            ..Options::default()
        })
        .stats;
    assert!(s.path.is_none());
}

/// A scene that scatters only diffusely (the area-lit box) sends two paths on from the first
/// vertex in a frame of several samples: with no bounce past the first (so that each path
/// traces one bounce ray), twice the bounce rays a sample; a frame of one sample, and a scene
/// with glass (whose noise is elsewhere), one path.
#[test]
fn only_a_diffuse_scene_splits_its_first_vertex_and_only_with_several_samples() {
    let per_sample = |name: &str, spp: u32| {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let mut s = gi(spp, 0, Estimator::Auto);
        s.effects.indirect = Indirect::PathTraced { bounces: 0 };
        let rays = scene
            .render(&Options {
                width: 32,
                height: 20,
                settings: Some(s),
                ..Options::default()
            })
            .stats
            .rays;
        rays.bounce as f64 / rays.primary as f64
    };
    let (one, two) = (per_sample("area", 1), per_sample("area", 2));
    assert!(one > 0.5 && (two / one - 2.0).abs() < 0.1, "{one} {two}");
    let (one, two) = (per_sample("glass", 1), per_sample("glass", 2));
    assert!(one > 0.5 && (two / one - 1.0).abs() < 0.1, "{one} {two}");
}

/// No area-light shadow ray without emitting triangles, none with BSDF sampling alone; a scene
/// of point lights and metal traces one per point light and vertex that the light reaches.
#[test]
fn no_area_light_rays_where_nothing_emits() {
    let scene = |emission: f32| {
        let mut b = SceneBuilder::new();
        let m = b.material(Material {
            metal: 1.0,
            roughness: 0.5,
            emission: Vec3::splat(emission),
            ..Material::diffuse(Vec3::splat(0.8))
        });
        // One square facing the camera (its front toward −z).
        let v = |x, y| Vec3::new(x, y, 0.0);
        b.object(
            [
                [v(-1., -1.), v(-1., 1.), v(1., 1.)],
                [v(-1., -1.), v(1., 1.), v(1., -1.)],
            ],
            m,
        );
        b.build("square", Camera::default(), Effects::SEED).unwrap()
    };
    let rays = |s: &Scene, e| {
        s.render(&Options {
            width: 16,
            height: 16,
            settings: Some(gi(1, 0, e)),
            ..Options::default()
        })
        .stats
        .rays
    };
    let dark = scene(0.0);
    assert!(dark.area_lights().is_none());
    assert_eq!(rays(&dark, Estimator::Mis).shadow, 0);
    let lit = scene(1.0);
    assert_eq!(lit.area_lights().map(|a| a.len()), Some(2));
    assert_eq!(rays(&lit, Estimator::Bsdf).shadow, 0);
    // A flat emitter cannot light itself: every light point is edge-on, no shadow ray.
    assert_eq!(rays(&lit, Estimator::Mis).shadow, 0);
}

/// The stability suite, for the physically based path: roughness 0 and 1, an IOR of 1,
/// grazing views, a light on a surface and the camera inside glass give finite pixels.
#[test]
fn no_nan_or_infinity_from_any_material() {
    let corners = [
        Material {
            metal: 1.0,
            roughness: 0.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            metal: 1.0,
            roughness: 1.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            roughness: 0.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            roughness: 1.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            ior: 1.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            ior: 1.0,
            roughness: 0.5,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            ior: 4.0,
            roughness: 0.02,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            mirror: 0.5,
            metal: 0.5,
            transmission: 0.5,
            roughness: 0.7,
            ..Material::diffuse(Vec3::ONE)
        },
    ];
    let cameras = [
        None,
        // Inside the ball.
        Some(Camera {
            position: Vec3::new(0.1, 0.05, -0.2),
            ..Camera::default()
        }),
        // Grazing: level with the floor, looking along it.
        Some(Camera {
            position: Vec3::new(0.0, 0.999_99, -0.9),
            ..Camera::default()
        }),
    ];
    for (i, m) in corners.into_iter().enumerate() {
        let mut b = SceneBuilder::new();
        let ball = b.material(m.clone());
        let floor = b.material(m);
        // A light lying on the floor, facing up (−y is up).
        let light = b.material(Material {
            emission: Vec3::splat(5.0),
            ..Material::diffuse(Vec3::splat(0.5))
        });
        b.object(
            displaced_icosphere(4, 0.0)
                .into_iter()
                .map(|t| t.map(|v| v * 0.5)),
            ball,
        );
        let p = |x, z| Vec3::new(x, 1.0, z);
        b.object(
            [
                [p(-2., -2.), p(2., 2.), p(2., -2.)],
                [p(-2., -2.), p(-2., 2.), p(2., 2.)],
            ],
            floor,
        );
        b.object([[p(0.5, 0.5), p(0.8, 0.5), p(0.5, 0.8)]], light);
        b.light(raytty::PointLight {
            position: Vec3::new(0.0, 1.0, 0.0),
            power: Vec3::splat(3.0),
        });
        let scene = b
            .build("corners", Camera::default(), Effects::SEED)
            .unwrap();
        for camera in cameras {
            for e in Estimator::ALL {
                let img = render(&scene, 12, 10, gi(2, 0, e), camera);
                assert!(
                    img.pixels
                        .iter()
                        .all(|p| p.is_finite() && p.min_element() >= 0.0),
                    "material {i}, {camera:?}, {e:?}"
                );
            }
        }
    }
}

/// The seed's scenes are not touched by any of this: their materials call for nothing new.
#[test]
fn seed_scenes_call_for_no_physically_based_effect() {
    for name in ["cornell", "mirror", "lights", "sphere"] {
        let b = builtin::find(name).unwrap();
        if b.triangles > 10_000 {
            continue;
        }
        let scene = b.load().unwrap();
        assert!(!raytty::shading::PathEffects::of(&scene).any(), "{name}");
        assert!(scene.area_lights().is_none());
    }
    let _ = Indirect::None;
}
