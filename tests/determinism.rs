//! Frames do not depend on the number of threads: the same bytes with 1 thread and with 2,
//! both in-process (rayon pools) and through the binary (`RAYON_NUM_THREADS`).

use std::process::Command;

use raytty::{Effects, Indirect, Stage, cornell_box, render};

fn image_bytes(threads: usize, stage: Stage, samples: u32) -> Vec<u8> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let scene = cornell_box();
        let mut settings = stage.settings(scene.effects);
        settings.effects.samples = samples;
        let f = render(&scene, &scene.camera, &scene.lights, &settings, 64, 48);
        f.image
            .pixels
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect()
    })
}

#[test]
fn one_thread_and_two_give_the_same_floats() {
    for stage in Stage::ALL {
        for samples in [1, 4] {
            assert_eq!(
                image_bytes(1, stage, samples),
                image_bytes(2, stage, samples),
                "{stage:?} {samples} spp"
            );
        }
    }
}

#[test]
fn path_traced_frames_are_deterministic_across_threads() {
    let scene = cornell_box();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut s = Stage::Indirect.settings(scene.effects);
                s.effects = Effects {
                    shadows: true,
                    indirect: Indirect::PathTraced { bounces: 3 },
                    samples: 2,
                };
                render(&scene, &scene.camera, &scene.lights, &s, 40, 30).image
            })
    };
    assert_eq!(run(1), run(2));
}

fn cli_frame(threads: &str, format: &str) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["render", "--size", "100x30", "--format", format])
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

#[test]
fn binary_output_is_byte_identical_with_one_and_two_threads() {
    for format in ["ansi", "ansi256", "ascii", "pfm"] {
        let one = cli_frame("1", format);
        assert!(!one.is_empty());
        assert_eq!(one, cli_frame("2", format), "--format {format}");
    }
}
