//! Directional, spot and environment lights (issue 21): each gives the analytic value where
//! there is one (a directional light's irradiance `E·cos`, a spot's `P·cos·falloff/(4πr²)`
//! with glTF's smooth cone), the white furnace holds under a uniform environment, scene files
//! and glTF files bring them in, and no corner (a light on a surface, a zero or a right-angle
//! cone, grazing light) gives NaN or infinity.

use std::f32::consts::PI;

use glam::Vec3;
use raytty::scene::model::{self, View};
use raytty::scene::procedural::displaced_icosphere;
use raytty::shading::Estimator;
use raytty::{
    Camera, DirectionalLight, Effects, Image, Material, Options, RayCounts, Scene, SceneBuilder,
    Settings, SpotLight, Stage, Tracer,
};

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

/// Stage 6 with `spp` samples and estimator `e`.
fn gi(spp: u32, e: Estimator) -> Settings {
    let mut s = Stage::Gi.settings(Effects::SEED);
    s.effects.samples = spp;
    s.estimator = e;
    s
}

/// A floor of `material` at y = 1 (y points down), 8 wide, and what `lights` adds.
fn floor(material: Material, lights: impl FnOnce(&mut SceneBuilder)) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(material);
    let p = |x, z| Vec3::new(x, 1.0, z);
    b.object(
        [
            [p(-4., -4.), p(4., 4.), p(-4., 4.)],
            [p(-4., -4.), p(4., -4.), p(4., 4.)],
        ],
        m,
    );
    lights(&mut b);
    b.build("floor", Camera::default(), Effects::SEED).unwrap()
}

/// Direct irradiance at `p` on a surface of normal `normal` (facing the light side), and the
/// shadow rays it took.
fn direct(scene: &Scene, p: Vec3, normal: Vec3) -> (Vec3, u64) {
    let t = Tracer::new(
        scene,
        scene.lights(),
        Stage::Shadows.settings(scene.effects()),
    );
    let mut n = RayCounts::default();
    let e = t.direct(p, Vec3::ZERO, normal, &mut n);
    (e, n.shadow)
}

/// A directional light gives `E·cos` on a surface facing it, at any distance, and nothing
/// (and no shadow ray) to one facing away; a block in its way shadows a point beyond it.
#[test]
fn directional_irradiance_is_e_cos() {
    let irradiance = Vec3::new(2.0, 1.0, 0.5);
    let direction = Vec3::new(0.6, 0.8, 0.0);
    let scene = floor(Material::diffuse(Vec3::ONE), |b| {
        b.directional_light(DirectionalLight {
            direction: direction * 3.0,
            irradiance,
        })
    });
    let up = Vec3::new(0.0, -1.0, 0.0);
    for x in [-3.0, 0.0, 2.5] {
        let (e, rays) = direct(&scene, Vec3::new(x, 1.0, 0.3), up);
        assert!((e - irradiance * 0.8).abs().max_element() < 1e-6, "{e}");
        assert_eq!(rays, 1);
    }
    let (e, rays) = direct(&scene, Vec3::new(0.0, 1.0, 0.0), -up);
    assert_eq!((e, rays), (Vec3::ZERO, 0));
    // Rendered: every floor pixel is ρ·E·cos, in the direct stage and in stage 6 (nothing
    // else to bounce to, no environment).
    let camera = Camera {
        position: Vec3::new(0.0, -1.0, -1.0),
        pitch: 1.0,
        ..Camera::default()
    };
    for s in [
        Stage::Direct.settings(Effects::SEED),
        gi(2, Estimator::Auto),
    ] {
        let img = render(&scene, 16, 12, s, Some(camera));
        for p in &img.pixels {
            assert!((*p - irradiance * 0.8).abs().max_element() < 1e-5, "{p}");
        }
    }
    // A square one unit above the floor (x from −1 to 0) shadows the points whose way to the
    // light (up and to the left: −direction) passes through it: x from −0.25 to 0.75.
    let blocked = floor(Material::diffuse(Vec3::ONE), |b| {
        let m = b.material(Material::diffuse(Vec3::ONE));
        let q = |x, z| Vec3::new(x, 0.0, z);
        b.object(
            [
                [q(-1., -1.), q(0., 1.), q(-1., 1.)],
                [q(-1., -1.), q(0., -1.), q(0., 1.)],
            ],
            m,
        );
        b.directional_light(DirectionalLight {
            direction,
            irradiance,
        });
    });
    for (x, shadowed) in [
        (-0.5, false),
        (0.0, true),
        (0.25, true),
        (0.7, true),
        (1.5, false),
    ] {
        let (e, rays) = direct(&blocked, Vec3::new(x, 1.0, 0.0), up);
        assert_eq!((e == Vec3::ZERO, rays), (shadowed, 1), "x {x}");
    }
}

/// glTF's recommended spot falloff, in `f64`: `t²` with `t` linear in the cosine from the
/// outer cone (0) to the inner one (1).
fn falloff(cos: f64, inner: f64, outer: f64) -> f64 {
    let (ci, co) = (inner.cos(), outer.cos());
    if ci <= co {
        return if cos > co { 1.0 } else { 0.0 };
    }
    let t = ((cos - co) / (ci - co)).clamp(0.0, 1.0);
    t * t
}

/// A spot pointing straight down at a floor: at each distance from its foot the irradiance is
/// `P·cos·falloff(θ)/(4πr²)` (θ from the axis, here also the angle of incidence); points
/// outside the outer cone get nothing and cost no shadow ray.
#[test]
fn spot_cone_falls_off_as_gltf_says() {
    let power = 20.0f32;
    let h = 2.0f64;
    for (inner, outer) in [(20.0f64, 40.0f64), (0.0, 30.0), (25.0, 25.0), (60.0, 90.0)] {
        let scene = floor(Material::diffuse(Vec3::ONE), |b| {
            b.spot_light(SpotLight {
                position: Vec3::new(0.0, 1.0 - h as f32, 0.0),
                direction: Vec3::new(0.0, 2.0, 0.0),
                power: Vec3::splat(power),
                inner: (inner as f32).to_radians(),
                outer: (outer as f32).to_radians(),
            })
        });
        let (mut inside, mut outside) = (0, 0);
        for i in 0..64 {
            let x = i as f64 * 0.06 + 0.013;
            let r2 = h * h + x * x;
            let cos = h / r2.sqrt();
            let f = falloff(cos, inner.to_radians(), outer.to_radians());
            let want = f64::from(power) * cos * f / (4.0 * std::f64::consts::PI * r2);
            let (e, rays) = direct(
                &scene,
                Vec3::new(x as f32, 1.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
            );
            let got = f64::from(e.x);
            assert!(
                (got - want).abs() <= 1e-5 * want.max(1e-3),
                "cone {inner}-{outer}, x {x}: {got} for {want}"
            );
            if f == 0.0 {
                assert_eq!((got, rays), (0.0, 0), "outside the cone, x {x}");
                outside += 1;
            } else {
                assert_eq!(rays, 1);
                inside += 1;
            }
        }
        assert!(
            inside > 5 && (outer == 90.0 || outside > 5),
            "{inner}-{outer}"
        );
    }
}

/// An open tray (a floor and low walls) and a ball of `material` on it, under a uniform
/// environment `e` and nothing else.
fn tray(material: Material, e: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(material);
    let q = |x, y, z| Vec3::new(x, y, z);
    let (lo, hi) = (-1.0, 1.0);
    let top = 0.6;
    // Floor at y = 1 and four walls up to y = 0.6, both sides seen (two-sided shading).
    let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [[a, b, c], [a, c, d]];
    let mut tris = vec![];
    tris.extend(quad(
        q(lo, 1., lo),
        q(hi, 1., lo),
        q(hi, 1., hi),
        q(lo, 1., hi),
    ));
    tris.extend(quad(
        q(lo, 1., lo),
        q(lo, top, lo),
        q(lo, top, hi),
        q(lo, 1., hi),
    ));
    tris.extend(quad(
        q(hi, 1., lo),
        q(hi, top, lo),
        q(hi, top, hi),
        q(hi, 1., hi),
    ));
    tris.extend(quad(
        q(lo, 1., hi),
        q(lo, top, hi),
        q(hi, top, hi),
        q(hi, 1., hi),
    ));
    tris.extend(quad(
        q(lo, 1., lo),
        q(lo, top, lo),
        q(hi, top, lo),
        q(hi, 1., lo),
    ));
    b.object(tris, m);
    b.object(
        displaced_icosphere(3, 0.0)
            .into_iter()
            .map(|t| t.map(|v| v * 0.3 + Vec3::new(0.0, 0.7, 0.0))),
        m,
    );
    b.environment(Vec3::splat(e));
    b.build("tray", Camera::default(), Effects::SEED).unwrap()
}

/// White furnace under the sky: in a uniform environment a surface that absorbs nothing
/// (white diffuse, a metal of F0 = 1, a mirror) sends back the environment, however the light
/// bounced on its way out of the tray: every pixel is the environment within noise, with every
/// estimator. Frames that trace no random ray take the environment unshadowed, exactly.
#[test]
fn white_furnace_under_a_uniform_environment() {
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
    ];
    let camera = Camera {
        position: Vec3::new(0.0, -1.2, -1.6),
        pitch: 0.7,
        ..Camera::default()
    };
    for (name, m, tol) in cases {
        let scene = tray(m, e);
        for est in Estimator::ALL {
            let img = render(&scene, 24, 24, gi(32, est), Some(camera));
            let got = mean(&img);
            assert!(
                (got - Vec3::splat(e)).abs().max_element() <= tol,
                "{name}, {est:?}: {got} for {e}"
            );
            assert!(img.pixels.iter().all(|p| p.is_finite()), "{name}");
        }
    }
    // The seed's stages: the white tray shows the environment exactly (ρ·(D + e), D = 0).
    let scene = tray(Material::diffuse(white), e);
    for stage in [Stage::Direct, Stage::Shadows, Stage::Indirect] {
        let mut s = stage.settings(Effects::SEED);
        s.effects.indirect = raytty::Indirect::None;
        let img = render(&scene, 16, 16, s, Some(camera));
        assert!(img.pixels.iter().all(|p| *p == Vec3::splat(e)), "{stage:?}");
    }
}

/// Light sampling alone, BSDF sampling alone and MIS see the environment alike: it is found by
/// BSDF sampling in all three, so a scene lit by it and by an area light has one mean.
#[test]
fn the_environment_is_the_same_under_every_estimator() {
    let scene = tray(
        Material {
            metal: 1.0,
            roughness: 0.4,
            colour: Vec3::splat(0.8),
            ..Material::diffuse(Vec3::ONE)
        },
        0.3,
    );
    let camera = Camera {
        position: Vec3::new(0.0, -1.2, -1.6),
        pitch: 0.7,
        ..Camera::default()
    };
    let means: Vec<Vec3> = [Estimator::Light, Estimator::Bsdf, Estimator::Mis]
        .into_iter()
        .map(|e| mean(&render(&scene, 24, 24, gi(64, e), Some(camera))))
        .collect();
    for m in &means {
        assert!((*m - means[0]).abs().max_element() < 0.005, "{means:?}");
    }
}

/// No NaN, no infinity, nothing negative: a spot on the floor pointing into it and along it,
/// cones of zero and of 90 degrees, a directional light grazing the floor, lights of the
/// largest power, an environment seen through glass and in mirrors, the camera grazing.
#[test]
fn no_nan_from_lights_at_their_limits() {
    let materials = [
        Material::diffuse(Vec3::splat(0.7)),
        Material {
            mirror: 1.0,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            transmission: 1.0,
            roughness: 0.2,
            ..Material::diffuse(Vec3::ONE)
        },
        Material {
            metal: 1.0,
            roughness: 1.0,
            ..Material::diffuse(Vec3::ONE)
        },
    ];
    let cameras = [
        None,
        Some(Camera {
            position: Vec3::new(0.0, 0.999_99, -0.9),
            ..Camera::default()
        }),
    ];
    for m in materials {
        let mut b = SceneBuilder::new();
        let ball = b.material(m.clone());
        let ground = b.material(m);
        b.object(
            displaced_icosphere(3, 0.0)
                .into_iter()
                .map(|t| t.map(|v| v * 0.5)),
            ball,
        );
        let p = |x, z| Vec3::new(x, 1.0, z);
        b.object(
            [
                [p(-2., -2.), p(2., 2.), p(-2., 2.)],
                [p(-2., -2.), p(2., -2.), p(2., 2.)],
            ],
            ground,
        );
        let on_floor = Vec3::new(0.3, 1.0, 0.3);
        for (direction, inner, outer) in [
            (Vec3::Y, 0.0, 0.0),
            (Vec3::X, PI / 2.0, PI / 2.0),
            (Vec3::new(1.0, 0.0, 1.0), 0.1, 0.2),
        ] {
            b.spot_light(SpotLight {
                position: on_floor,
                direction,
                power: Vec3::splat(1e12),
                inner,
                outer,
            });
        }
        b.directional_light(DirectionalLight {
            direction: Vec3::X,
            irradiance: Vec3::splat(1e12),
        });
        b.directional_light(DirectionalLight {
            direction: Vec3::new(1e-30, 1.0, 0.0),
            irradiance: Vec3::splat(1.0),
        });
        b.environment(Vec3::splat(1e6));
        let scene = b.build("limits", Camera::default(), Effects::SEED).unwrap();
        for camera in cameras {
            for stage in Stage::ALL {
                let mut s = stage.settings(Effects::SEED);
                s.effects.samples = 2;
                let img = render(&scene, 12, 10, s, camera);
                assert!(
                    img.pixels
                        .iter()
                        .all(|p| p.is_finite() && p.min_element() >= 0.0),
                    "{stage:?} {camera:?}"
                );
            }
        }
    }
}

/// The builder refuses a light it could not render: a zero or non-finite direction, a
/// negative power, a cone wider than a hemisphere or inside out, a negative environment.
#[test]
fn bad_lights_are_refused() {
    let build = |f: &dyn Fn(&mut SceneBuilder)| {
        let mut b = SceneBuilder::new();
        f(&mut b);
        b.build("bad", Camera::default(), Effects::SEED)
    };
    let spot = SpotLight {
        position: Vec3::ZERO,
        direction: Vec3::Y,
        power: Vec3::ONE,
        inner: 0.1,
        outer: 0.2,
    };
    let sun = DirectionalLight {
        direction: Vec3::Y,
        irradiance: Vec3::ONE,
    };
    assert!(build(&|b| b.spot_light(spot)).is_ok());
    assert!(build(&|b| b.directional_light(sun)).is_ok());
    let bad_spots = [
        SpotLight {
            direction: Vec3::ZERO,
            ..spot
        },
        SpotLight {
            direction: Vec3::splat(f32::MAX),
            ..spot
        },
        SpotLight {
            power: Vec3::new(1.0, -1.0, 1.0),
            ..spot
        },
        SpotLight {
            inner: 0.3,
            outer: 0.2,
            ..spot
        },
        SpotLight { outer: 1.6, ..spot },
        SpotLight {
            position: Vec3::splat(f32::NAN),
            ..spot
        },
    ];
    for s in bad_spots {
        assert!(build(&|b| b.spot_light(s)).is_err(), "{s:?}");
    }
    for d in [
        DirectionalLight {
            direction: Vec3::ZERO,
            ..sun
        },
        DirectionalLight {
            irradiance: Vec3::splat(f32::INFINITY),
            ..sun
        },
    ] {
        assert!(build(&|b| b.directional_light(d)).is_err(), "{d:?}");
    }
    assert!(build(&|b| b.environment(Vec3::new(0.1, -0.1, 0.0))).is_err());
    let err = build(&|b| b.spot_light(bad_spots[3]))
        .unwrap_err()
        .to_string();
    assert!(err.contains("spot light 0"), "{err}");
}

/// A glTF file's directional and spot lights (`KHR_lights_punctual`) come in as such: the
/// node's −z is where they point, a spot's cone its angles, its intensity (candela) a power of
/// 4π times it, a directional light's (lux) its irradiance.
#[test]
fn gltf_directional_and_spot_lights_are_used() {
    let dir = std::env::temp_dir().join(format!("raytty-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let base = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/two_nodes.gltf"),
    )
    .unwrap();
    // Two light nodes after the model's, both turned so that −z points down (−y).
    let down = "\"rotation\": [-0.70710678, 0, 0, 0.70710678]";
    let gltf = base
        .replacen(
            "\"scene\": 0,",
            "\"scene\": 0,\n \"extensionsUsed\": [\"KHR_lights_punctual\"],\n \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"directional\", \"intensity\": 2, \"color\": [1, 0.5, 0.25]}, {\"type\": \"spot\", \"intensity\": 3, \"spot\": {\"innerConeAngle\": 0.2, \"outerConeAngle\": 0.5}}]}},",
            1,
        )
        .replacen("\"nodes\": [\n    0\n   ]", "\"nodes\": [0, 2, 3]", 1)
        .replacen(
            "\n ],\n \"meshes\"",
            &format!(
                ",\n  {{\"extensions\": {{\"KHR_lights_punctual\": {{\"light\": 0}}}}, {down}}},\n  {{\"extensions\": {{\"KHR_lights_punctual\": {{\"light\": 1}}}}, \"translation\": [0, 3, 0], {down}}}\n ],\n \"meshes\""
            ),
            1,
        );
    assert_ne!(gltf, base);
    let path = dir.join("lit.gltf");
    std::fs::write(&path, gltf).unwrap();
    let loaded = model::load(&path, &View::default()).unwrap();
    let s = &loaded.scene;
    assert!(
        s.lights().is_empty() && !s.lights_are_default(),
        "{:?}",
        loaded.notes
    );
    let [sun] = s.directional_lights() else {
        panic!("{:?}", s.directional_lights())
    };
    assert!((sun.direction - Vec3::NEG_Y).length() < 1e-5, "{sun:?}");
    assert_eq!(sun.irradiance, Vec3::new(2.0, 1.0, 0.5));
    let [spot] = s.spot_lights() else {
        panic!("{:?}", s.spot_lights())
    };
    assert!((spot.direction - Vec3::NEG_Y).length() < 1e-5, "{spot:?}");
    assert!((spot.position - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-5);
    assert!((spot.power.x - 3.0 * 4.0 * PI).abs() < 1e-4);
    assert_eq!((spot.inner, spot.outer), (0.2, 0.5));
    std::fs::remove_dir_all(&dir).unwrap();
}
