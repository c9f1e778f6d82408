//! Family 8, precision: the `f32` tracer agrees with an `f64` reference tracer (written in
//! `tests/common/reference.rs`, sharing no code with the library's tracer) on every pixel of
//! the 500×500 `indirect` frame to within one 8-bit level, outside a mask of the pixels whose
//! primary or shadow ray passes within `EDGE_TOL` of a feature edge.

mod common;

use common::EDGE_TOL;
use common::reference::Reference;
use glam::DVec3;
use raytty::{Indirect, Options, Stage, cornell_box};

/// One 8-bit level of a linear channel.
const LEVEL: f64 = 1.0 / 255.0;

#[test]
fn indirect_frame_matches_the_f64_reference_within_one_level() {
    let scene = cornell_box();
    let (w, h) = (500, 500);
    let settings = Stage::Indirect.settings(scene.effects());
    let Indirect::Constant(ambient) = settings.effects.indirect else {
        panic!("the Cornell box's indirect stage is the seed's constant term");
    };
    let frame = scene.render(&Options {
        width: w,
        height: h,
        settings: Some(settings),
        ..Options::default()
    });
    let reference = Reference::new(&scene);
    let rays = scene.camera().rays(w, h);
    let pixels = reference.frame(
        &rays,
        (w, h),
        scene.lights(),
        true,
        ambient as f64,
        EDGE_TOL,
    );
    let mut masked = 0;
    let mut masked_off = 0;
    let mut worst = 0.0f64;
    let mut bad = Vec::new();
    for (k, (want, got)) in pixels.iter().zip(&frame.image.pixels).enumerate() {
        // Both clamped to [0, 1], as the 8-bit image is.
        let diff = (got.as_dvec3().min(DVec3::ONE) - want.colour.min(DVec3::ONE))
            .abs()
            .max_element();
        if want.masked {
            masked += 1;
            masked_off += usize::from(!(diff <= LEVEL));
            continue;
        }
        worst = worst.max(diff);
        if !(diff <= LEVEL) {
            bad.push((k as u32 % w, k as u32 / w, *got, want.colour));
        }
    }
    eprintln!(
        "precision mask: {masked} of {} pixels at edge tolerance {EDGE_TOL}, {masked_off} of \
         them more than one level off; worst unmasked difference {worst:.3e} ({:.4} levels)",
        w * h,
        worst / LEVEL
    );
    assert!(
        bad.is_empty(),
        "{} pixels differ by more than one level; first (x, y, f32, f64): {:?}",
        bad.len(),
        bad.iter().take(5).collect::<Vec<_>>()
    );
    assert!(masked < (w * h) as usize / 100, "{masked} pixels masked");
}
