//! The seed's 500×500 frame renders in every stage, and every pixel inside the box's front
//! opening (which exactly fills the frame from the seed's camera) hits geometry: no background
//! pixel leaks through a crease between floor, walls and ceiling.

use raytty::{Options, Stage, cornell_box};

#[test]
fn every_pixel_of_the_seed_view_hits_the_box() {
    let scene = cornell_box();
    for stage in Stage::ALL {
        let mut settings = stage.settings(scene.effects());
        if stage == Stage::Gi {
            settings.effects.samples = 1;
        }
        let frame = scene.render(&Options {
            width: 500,
            height: 500,
            settings: Some(settings),
            ..Options::default()
        });
        assert_eq!(frame.stats.rays.primary, 250_000);
        for (i, p) in frame.image.pixels.iter().enumerate() {
            assert!(p.is_finite(), "{stage:?}: pixel {i} is {p}");
        }
        if stage == Stage::Flat {
            // Every material colour is non-black; the background is black.
            let black: Vec<usize> = (0..frame.image.pixels.len())
                .filter(|&i| frame.image.pixels[i] == glam::Vec3::ZERO)
                .collect();
            assert!(
                black.is_empty(),
                "{} background pixels, first at {:?}",
                black.len(),
                black.first().map(|i| (i % 500, i / 500))
            );
        }
    }
}

#[test]
fn other_frame_shapes_see_the_whole_opening_too() {
    // With f = the shorter side, the opening fills the shorter side at any aspect ratio.
    let scene = cornell_box();
    let settings = Stage::Flat.settings(scene.effects());
    for (w, h) in [(200, 100), (100, 200), (81, 47)] {
        let frame = scene.render(&Options {
            width: w,
            height: h,
            settings: Some(settings),
            ..Options::default()
        });
        let (cx, cy) = (w / 2, h / 2);
        let r = w.min(h) / 2 - 1;
        for y in cy - r..cy + r {
            for x in cx - r..cx + r {
                assert_ne!(
                    frame.image.get(x, y),
                    glam::Vec3::ZERO,
                    "{w}x{h}: ({x}, {y}) misses"
                );
            }
        }
    }
}
