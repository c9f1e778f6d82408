//! A frame traces only what its effects call for: the ray counts in `FrameStats`, by kind, for
//! each effect switched off and on. Counts, not timings, so these hold on any machine.

use glam::Vec3;
use raytty::{
    Camera, Effects, FrameStats, HitCache, Image, Indirect, Material, Options, PointLight, Scene,
    SceneBuilder, Settings, Stage, cornell_box,
};

const W: u32 = 48;
const H: u32 = 36;

fn settings(shadows: bool, indirect: Indirect, samples: u32) -> Settings {
    let mut s = Stage::Indirect.settings(Effects::SEED);
    s.effects = Effects {
        shadows,
        indirect,
        samples,
        ..Effects::SEED
    };
    s
}

fn stats(scene: &Scene, s: &Settings) -> FrameStats {
    scene
        .render(&Options {
            width: W,
            height: H,
            settings: Some(*s),
            ..Options::default()
        })
        .stats
}

const GI4: Indirect = Indirect::PathTraced { bounces: 4 };

#[test]
fn shadows_off_trace_no_shadow_ray() {
    let scene = cornell_box();
    for indirect in [Indirect::None, Indirect::Constant(0.5), GI4] {
        let off = stats(&scene, &settings(false, indirect, 1));
        assert_eq!(off.rays.shadow, 0, "{indirect:?}");
        // The control: the same frame with shadows on does trace them.
        let on = stats(&scene, &settings(true, indirect, 1));
        assert!(on.rays.shadow > 0, "{indirect:?}");
    }
}

#[test]
fn constant_or_no_indirect_traces_no_bounce_ray() {
    let scene = cornell_box();
    for indirect in [Indirect::None, Indirect::Constant(0.5)] {
        for samples in [1, 4] {
            let s = stats(&scene, &settings(true, indirect, samples));
            assert_eq!(s.rays.bounce, 0, "{indirect:?} {samples} spp");
        }
    }
    for stage in [
        Stage::Flat,
        Stage::Light,
        Stage::Direct,
        Stage::Shadows,
        Stage::Indirect,
    ] {
        let s = stats(&scene, &stage.settings(scene.effects()));
        assert_eq!(s.rays.bounce, 0, "{stage:?}");
    }
}

/// A wall facing the camera with the light behind it: every visible point faces away from the
/// light, so not one shadow ray is worth tracing (even with path-traced bounces, which land on
/// the same wall's lit-away side or miss).
#[test]
fn a_light_behind_every_visible_surface_costs_no_shadow_ray() {
    let mut b = SceneBuilder::new();
    let grey = b.material(Material::diffuse(Vec3::splat(0.75)));
    let (a, bb, c, d) = (
        Vec3::new(-5.0, -5.0, 1.0),
        Vec3::new(5.0, -5.0, 1.0),
        Vec3::new(5.0, 5.0, 1.0),
        Vec3::new(-5.0, 5.0, 1.0),
    );
    b.object([[a, bb, c], [a, c, d]], grey);
    b.light(PointLight {
        position: Vec3::new(0.3, -0.2, 2.0),
        power: Vec3::splat(14.0),
    });
    let wall = b
        .build("wall", Camera::default(), Effects::SEED)
        .expect("valid");
    for indirect in [Indirect::Constant(0.5), GI4] {
        let s = stats(&wall, &settings(true, indirect, 1));
        assert_eq!(s.rays.primary, u64::from(W * H));
        assert_eq!(s.rays.shadow, 0, "{indirect:?}");
    }
    // The control: the light moved in front of the wall casts shadow rays from every pixel.
    let mut front = wall.lights().to_vec();
    front[0].position.z = 0.0;
    let s = wall
        .render(&Options {
            width: W,
            height: H,
            settings: Some(settings(true, Indirect::Constant(0.5), 1)),
            lights: Some(&front),
            ..Options::default()
        })
        .stats;
    assert_eq!(s.rays.shadow, u64::from(W * H));
}

#[test]
fn a_light_only_change_traces_no_primary_ray() {
    let scene = cornell_box();
    let mut cache = HitCache::new();
    let s = scene.effects();
    for stage in [Stage::Shadows, Stage::Indirect, Stage::Gi] {
        let settings = stage.settings(s);
        let first = cache.render(
            &scene,
            &Options {
                width: W,
                height: H,
                settings: Some(settings),
                ..Options::default()
            },
        );
        assert_eq!(first.stats.rays.primary, u64::from(W * H), "{stage:?}");
        let mut moved = scene.lights().to_vec();
        moved[0].position += Vec3::new(0.2, 0.1, -0.1);
        let second = cache.render(
            &scene,
            &Options {
                width: W,
                height: H,
                settings: Some(settings),
                lights: Some(&moved),
                ..Options::default()
            },
        );
        assert_eq!(second.stats.rays.primary, 0, "{stage:?}");
        assert!(second.stats.rays.shadow > 0, "{stage:?}");
        // Reusing the hits changes no pixel.
        let fresh = scene.render(&Options {
            width: W,
            height: H,
            settings: Some(settings),
            lights: Some(&moved),
            ..Options::default()
        });
        assert_eq!(second.image, fresh.image, "{stage:?}");
        cache.clear();
    }
}

#[test]
fn no_mirrors_no_reflection_ray() {
    let scene = cornell_box();
    assert!(!scene.has_mirrors());
    for stage in Stage::ALL {
        let s = stats(&scene, &stage.settings(scene.effects()));
        assert_eq!(s.rays.reflection, 0, "{stage:?}");
    }
    let s = stats(&scene, &settings(true, GI4, 4));
    assert_eq!(s.rays.reflection, 0);

    // The control: the same box with a mirror back wall reflects.
    let mirror = mirrored_box();
    assert!(mirror.has_mirrors());
    let s = stats(&mirror, &Stage::Indirect.settings(mirror.effects()));
    assert!(s.rays.reflection > 0);
}

/// The Cornell box's walls again, with a perfect mirror facing the camera.
fn mirrored_box() -> Scene {
    let mut b = SceneBuilder::new();
    let white = b.material(Material::diffuse(Vec3::splat(0.75)));
    let glass = b.material(Material {
        mirror: 1.0,
        ..Material::diffuse(Vec3::splat(0.75))
    });
    let v = |x, y, z| Vec3::new(x, y, z);
    b.object(
        [
            [v(-1., -1., 1.), v(1., -1., 1.), v(1., 1., 1.)],
            [v(-1., -1., 1.), v(1., 1., 1.), v(-1., 1., 1.)],
        ],
        glass,
    );
    b.object(
        [
            [v(-1., 1., -1.), v(1., 1., -1.), v(1., 1., 1.)],
            [v(-1., 1., -1.), v(1., 1., 1.), v(-1., 1., 1.)],
        ],
        white,
    );
    b.light(PointLight {
        position: v(0.0, -0.5, 0.0),
        power: Vec3::splat(14.0),
    });
    b.build("mirror", Camera::default(), Effects::SEED)
        .expect("valid")
}

#[test]
fn gi_with_b_bounces_traces_at_most_b_bounce_rays_per_path() {
    let scene = cornell_box();
    for bounces in [1, 2, 4, 8] {
        for samples in [1, 4] {
            let s = stats(
                &scene,
                &settings(true, Indirect::PathTraced { bounces }, samples),
            );
            let paths = s.rays.primary;
            assert_eq!(paths, u64::from(W * H * samples));
            assert!(s.rays.bounce > 0, "{bounces} bounces");
            assert!(
                s.rays.bounce <= u64::from(bounces) * paths,
                "{bounces} bounces: {} bounce rays for {paths} paths",
                s.rays.bounce
            );
            // Every bounce that hits does next-event estimation: more shadow rays than with
            // direct light alone.
            let direct = stats(&scene, &settings(true, Indirect::None, samples));
            assert!(s.rays.shadow > direct.rays.shadow, "{bounces} bounces");
        }
    }
    // One bounce: every primary hit sends exactly one bounce ray (nothing ends a path before
    // its first bounce) and a miss sends none. The flat stage shows which pixels hit.
    let flat = scene.render(&Options {
        width: W,
        height: H,
        settings: Some(Stage::Flat.settings(scene.effects())),
        ..Options::default()
    });
    let hits = flat
        .image
        .pixels
        .iter()
        .filter(|p| **p != Vec3::ZERO)
        .count() as u64;
    assert!(hits > 0 && hits < u64::from(W * H), "{hits} hits");
    let s = stats(
        &scene,
        &settings(true, Indirect::PathTraced { bounces: 1 }, 1),
    );
    assert_eq!(s.rays.bounce, hits);
}

#[test]
fn n_samples_per_pixel_trace_n_w_h_primary_rays() {
    let scene = cornell_box();
    for samples in [1, 2, 3, 4, 9, 16] {
        for indirect in [Indirect::Constant(0.5), GI4] {
            let s = stats(&scene, &settings(true, indirect, samples));
            assert_eq!(s.samples, samples);
            assert_eq!(s.rays.primary, u64::from(samples * W * H), "{samples} spp");
        }
    }
}

fn mean(img: &Image) -> Vec3 {
    img.pixels.iter().copied().sum::<Vec3>() / img.pixels.len() as f32
}

/// GI is direct light plus what the bounces bring, never less: at one sample (the same primary
/// hits as the direct-only frame) every pixel is at least its direct value, and the mean of
/// what GI adds is the same at 1 and 16 samples (both estimate one expectation). One 1-sample
/// frame of 48×36 pixels estimates that mean to about ±5 %, so it is averaged over 16 frames
/// (as the app's passes add up) before the two are compared.
#[test]
fn gi_is_direct_light_plus_something() {
    let scene = cornell_box();
    let direct = scene
        .render(&Options {
            width: W,
            height: H,
            settings: Some(settings(true, Indirect::None, 1)),
            ..Options::default()
        })
        .image;
    let gi_frame = |samples, frame| {
        let mut s = settings(true, Indirect::PathTraced { bounces: 8 }, samples);
        s.frame = frame;
        scene
            .render(&Options {
                width: W,
                height: H,
                settings: Some(s),
                ..Options::default()
            })
            .image
    };
    let gi = |samples| gi_frame(samples, 0);
    let gi1 = gi(1);
    for (i, (g, d)) in gi1.pixels.iter().zip(&direct.pixels).enumerate() {
        assert!(g.cmpge(*d).all(), "pixel {i}: GI {g} < direct {d}");
    }
    let added1 = mean(&gi1) - mean(&direct);
    assert!(
        added1.min_element() > 0.05 * mean(&direct).max_element(),
        "GI adds only {added1}"
    );
    let added1 = (0..16).map(|f| mean(&gi_frame(1, f))).sum::<Vec3>() / 16.0 - mean(&direct);
    let direct16 = scene
        .render(&Options {
            width: W,
            height: H,
            settings: Some(settings(true, Indirect::None, 16)),
            ..Options::default()
        })
        .image;
    let added16 = mean(&gi(16)) - mean(&direct16);
    let rel = (added16 - added1).abs() / added16;
    assert!(
        rel.max_element() < 0.05,
        "what GI adds: {added1} at 1 spp, {added16} at 16"
    );
}

#[test]
fn gi_is_the_same_with_one_thread_and_two() {
    let scene = cornell_box();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| {
                scene.render(&Options {
                    width: W,
                    height: H,
                    settings: Some(settings(true, Indirect::PathTraced { bounces: 8 }, 4)),
                    ..Options::default()
                })
            })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.image, two.image);
    assert_eq!(one.stats.rays, two.stats.rays);
}

/// A wall filling the view with `material`, lit from in front of it.
fn wall_of(material: Material) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(material);
    let v = |x, y, z| Vec3::new(x, y, z);
    b.object(
        [
            [v(-9., -9., 1.), v(9., -9., 1.), v(9., 9., 1.)],
            [v(-9., -9., 1.), v(9., 9., 1.), v(-9., 9., 1.)],
        ],
        m,
    );
    b.light(PointLight {
        position: v(0.3, -0.2, 0.0),
        power: Vec3::splat(14.0),
    });
    b.build("wall", Camera::default(), Effects::SEED)
        .expect("valid")
}

/// A perfect mirror (mirror = 1) shows only what it reflects: its own direct and indirect light
/// would be weighted by 0, so neither a shadow ray nor a bounce ray is traced for it; and a
/// black surface (ρ = 0) likewise. A half mirror and a grey wall are the controls.
#[test]
fn a_perfect_mirror_or_a_black_surface_traces_no_shadow_or_bounce_ray() {
    let px = u64::from(W * H);
    let mirror = |m| Material {
        mirror: m,
        ..Material::diffuse(Vec3::splat(0.75))
    };
    for indirect in [Indirect::Constant(0.5), GI4] {
        let s = stats(&wall_of(mirror(1.0)), &settings(true, indirect, 1));
        assert_eq!(s.rays.primary, px, "{indirect:?}");
        assert_eq!(s.rays.reflection, px, "{indirect:?}: every pixel reflects");
        assert_eq!((s.rays.shadow, s.rays.bounce), (0, 0), "{indirect:?}");
        let black = stats(
            &wall_of(Material::diffuse(Vec3::ZERO)),
            &settings(true, indirect, 1),
        );
        assert_eq!(
            (black.rays.shadow, black.rays.bounce),
            (0, 0),
            "{indirect:?}"
        );
        // The controls.
        let half = stats(&wall_of(mirror(0.5)), &settings(true, indirect, 1));
        assert_eq!(half.rays.shadow, px, "{indirect:?}");
        let grey = stats(
            &wall_of(Material::diffuse(Vec3::splat(0.5))),
            &settings(true, indirect, 1),
        );
        assert_eq!(grey.rays.shadow, px, "{indirect:?}");
        if indirect == GI4 {
            assert_eq!(half.rays.bounce, px);
            assert_eq!(grey.rays.bounce, px);
        }
    }
    // What the mirror shows is unchanged: the reflected rays leave the scene, so it is black.
    let wall = wall_of(mirror(1.0));
    let f = wall.render(&Options {
        width: W,
        height: H,
        settings: Some(settings(true, GI4, 1)),
        ..Options::default()
    });
    assert!(f.image.pixels.iter().all(|p| *p == Vec3::ZERO));
}

/// A light of zero power adds nothing, so it costs no shadow ray, and the frame is the one
/// without it, bit for bit.
#[test]
fn a_dark_light_costs_no_shadow_ray() {
    let scene = cornell_box();
    let lit = scene.lights().to_vec();
    let dark = PointLight {
        position: lit[0].position + Vec3::new(0.1, 0.0, 0.0),
        power: Vec3::ZERO,
    };
    for stage in Stage::ALL {
        let s = stage.settings(scene.effects());
        let frame = |lights: &[PointLight]| {
            scene.render(&Options {
                width: W,
                height: H,
                settings: Some(s),
                lights: Some(lights),
                ..Options::default()
            })
        };
        let alone = frame(&[dark]);
        assert_eq!(alone.stats.rays.shadow, 0, "{stage:?}");
        assert_eq!(alone.image, frame(&[]).image, "{stage:?}");
        let both = frame(&[lit[0], dark]);
        let one = frame(&lit);
        assert_eq!(both.stats.rays, one.stats.rays, "{stage:?}");
        assert_eq!(both.image, one.image, "{stage:?}");
    }
    // The control: the same light with power casts shadow rays.
    let s = stats(&scene, &settings(true, Indirect::Constant(0.5), 1));
    assert!(s.rays.shadow > 0);
}

/// A floor at y = 1 seen from above, with what `lights` adds.
fn lit_floor(lights: impl FnOnce(&mut SceneBuilder)) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(Material::diffuse(Vec3::splat(0.75)));
    let p = |x, z| Vec3::new(x, 1.0, z);
    b.object(
        [
            [p(-9., -9.), p(9., 9.), p(-9., 9.)],
            [p(-9., -9.), p(9., -9.), p(9., 9.)],
        ],
        m,
    );
    lights(&mut b);
    let camera = Camera {
        position: Vec3::new(0.0, -1.0, -1.0),
        pitch: 1.0,
        ..Camera::default()
    };
    b.build("floor", camera, Effects::SEED).unwrap()
}

/// A spot traces a shadow ray only where its cone reaches: fewer than the hits for a narrow
/// cone, none pointing away; the control, a cone of 90 degrees over the floor, one per hit.
#[test]
fn a_spot_traces_no_shadow_ray_outside_its_cone() {
    let spot = |direction: Vec3, outer: f32| {
        lit_floor(|b| {
            b.spot_light(raytty::SpotLight {
                position: Vec3::new(0.0, -1.0, 1.0),
                direction,
                power: Vec3::splat(10.0),
                inner: 0.0,
                outer,
            })
        })
    };
    let s = settings(true, Indirect::None, 1);
    let hits = (W * H) as u64;
    let wide = stats(&spot(Vec3::Y, std::f32::consts::FRAC_PI_2), &s);
    assert_eq!(wide.rays.shadow, hits);
    let narrow = stats(&spot(Vec3::Y, 0.3), &s);
    assert!(
        narrow.rays.shadow > 0 && narrow.rays.shadow < hits / 2,
        "{narrow:?}"
    );
    let away = stats(&spot(Vec3::NEG_Y, 1.0), &s);
    assert_eq!(away.rays.shadow, 0);
    assert_eq!(wide.effect_names(), ["spot lights"]);
}

/// A directional light from below the floor (behind every visible surface) costs no shadow
/// ray; from above, one per hit.
#[test]
fn a_directional_light_behind_the_surface_costs_no_shadow_ray() {
    let sun = |direction: Vec3| {
        lit_floor(|b| {
            b.directional_light(raytty::DirectionalLight {
                direction,
                irradiance: Vec3::ONE,
            })
        })
    };
    let s = settings(true, Indirect::None, 1);
    let below = stats(&sun(Vec3::new(0.2, -1.0, 0.1)), &s);
    assert_eq!(below.rays.shadow, 0);
    let above = stats(&sun(Vec3::new(0.2, 1.0, 0.1)), &s);
    assert_eq!(above.rays.shadow, (W * H) as u64);
    assert_eq!(above.effect_names(), ["directional lights"]);
}

/// The environment costs no ray (it is what rays that leave the scene see): the same counts
/// with and without it, in the seed's stages and in stage 6, diffuse or metal; `--stats`
/// names it only where the scene has one and the frame shades.
#[test]
fn the_environment_costs_no_ray_and_is_named() {
    for metal in [0.0, 1.0] {
        let scene = |sky: f32| {
            let mut b = SceneBuilder::new();
            let m = b.material(Material {
                metal,
                roughness: 0.5,
                ..Material::diffuse(Vec3::splat(0.75))
            });
            let p = |x, z| Vec3::new(x, 1.0, z);
            b.object([[p(-1., -1.), p(1., 1.), p(-1., 1.)]], m);
            b.light(PointLight {
                position: Vec3::new(0.0, -1.0, 0.0),
                power: Vec3::splat(5.0),
            });
            b.environment(Vec3::splat(sky));
            let camera = Camera {
                position: Vec3::new(0.0, -1.0, -1.0),
                pitch: 0.8,
                ..Camera::default()
            };
            b.build("sky", camera, Effects::SEED).unwrap()
        };
        let (dark, sky) = (scene(0.0), scene(0.4));
        for stage in Stage::ALL {
            let mut s = stage.settings(Effects::SEED);
            s.effects.samples = 2;
            let (a, b) = (stats(&dark, &s), stats(&sky, &s));
            assert_eq!(a.rays, b.rays, "{stage:?} metal {metal}");
            assert!(!a.effect_names().contains(&"environment"));
            let named = b.effect_names().contains(&"environment");
            assert_eq!(named, stage != Stage::Flat, "{stage:?}");
        }
    }
}
