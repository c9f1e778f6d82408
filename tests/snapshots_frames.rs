//! 80×24 frames of each of the seed's stages, as ASCII and as truecolor ANSI, snapshotted with
//! insta. In the ANSI snapshots ESC is written as `␛` so the files read as text.

use raytty::{CellGrid, ColorMode, Options, Stage, cornell_box, encode_text};

fn frame(stage: Stage, mode: ColorMode) -> String {
    let scene = cornell_box();
    let settings = stage.settings(scene.effects());
    let f = scene.render(&Options {
        width: 80,
        height: 48,
        settings: Some(settings),
        ..Options::default()
    });
    String::from_utf8(encode_text(&CellGrid::from_image(&f.image, mode))).unwrap()
}

const SEED_STAGES: [Stage; 5] = [
    Stage::Flat,
    Stage::Light,
    Stage::Direct,
    Stage::Shadows,
    Stage::Indirect,
];

#[test]
fn ascii_frames() {
    for stage in SEED_STAGES {
        let text = frame(stage, ColorMode::Ascii);
        assert!(!text.contains('\x1b'), "ASCII frames have no escapes");
        assert_eq!(text.lines().count(), 24);
        assert!(text.lines().all(|l| l.chars().count() == 80));
        insta::assert_snapshot!(format!("ascii_{}", stage.name()), text);
    }
}

#[test]
fn ansi_frames() {
    for stage in SEED_STAGES {
        let text = frame(stage, ColorMode::TrueColor);
        assert_eq!(text.lines().count(), 24);
        insta::assert_snapshot!(format!("ansi_{}", stage.name()), text.replace('\x1b', "␛"));
    }
}

#[test]
fn ansi256_frame() {
    let text = frame(Stage::Indirect, ColorMode::Ansi256);
    assert!(text.contains("\x1b[38;5;"));
    assert!(!text.contains(";2;"), "no 24-bit colour in 256-colour mode");
    insta::assert_snapshot!("ansi256_indirect", text.replace('\x1b', "␛"));
}
