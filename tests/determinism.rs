//! Frames do not depend on the number of threads: the same bytes with 1 thread and with 2,
//! both in-process (rayon pools) and through the binary (`RAYON_NUM_THREADS`).

use std::process::Command;

use std::sync::Mutex;

use raytty::{Effects, Indirect, Options, Output, Stage, cornell_box};

fn image_bytes(threads: usize, stage: Stage, samples: u32) -> Vec<u8> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let scene = cornell_box();
        let mut settings = stage.settings(scene.effects());
        settings.effects.samples = samples;
        let f = scene.render(&Options {
            width: 64,
            height: 48,
            settings: Some(settings),
            ..Options::default()
        });
        float_bytes(&f.image)
    })
}

/// An image's exact floats, as little-endian bytes.
fn float_bytes(image: &raytty::Image) -> Vec<u8> {
    float_bytes_of(&image.pixels)
}

fn float_bytes_of(pixels: &[glam::Vec3]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect()
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
                let mut s = Stage::Indirect.settings(scene.effects());
                s.effects = Effects {
                    shadows: true,
                    indirect: Indirect::PathTraced { bounces: 3 },
                    samples: 2,
                    ..Effects::SEED
                };
                scene
                    .render(&Options {
                        width: 40,
                        height: 30,
                        settings: Some(s),
                        ..Options::default()
                    })
                    .image
            })
    };
    assert_eq!(run(1), run(2));
}

/// `Output::Rows` hands over every row of the plain frame exactly once, and counts its rays:
/// on 1 and 2 threads, one sample (bands of tiles, in each thread's own rows) and several
/// (rows), at a size whose last band and last tile column are partial, and with more bands than
/// threads (a thread's rows are reused).
#[test]
fn streamed_bands_hold_every_row_once_as_the_frame_has_it() {
    let scene = cornell_box();
    let (w, h) = (61, 37);
    for threads in [1, 2] {
        for (stage, samples) in [(Stage::Shadows, 1), (Stage::Gi, 1), (Stage::Indirect, 4)] {
            let mut settings = stage.settings(scene.effects());
            settings.effects.samples = samples;
            let bands = Mutex::new(Vec::new());
            let (streamed, plain) = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let done = |y0: u32, rows: &[glam::Vec3]| {
                        bands.lock().unwrap().push((y0, rows.to_vec()))
                    };
                    let streamed = scene
                        .render(&Options {
                            width: w,
                            height: h,
                            settings: Some(settings),
                            output: Output::Rows(&done),
                            ..Options::default()
                        })
                        .stats;
                    let plain = scene.render(&Options {
                        width: w,
                        height: h,
                        settings: Some(settings),
                        ..Options::default()
                    });
                    (streamed, plain)
                });
            let what = format!("{threads} threads, {stage:?}, {samples} spp");
            assert_eq!(streamed.rays, plain.stats.rays, "{what}");
            assert_eq!(streamed.samples, plain.stats.samples, "{what}");
            let mut seen = vec![0; h as usize];
            for (y0, rows) in bands.into_inner().unwrap() {
                assert_eq!(rows.len() % w as usize, 0, "{what}");
                for (dy, row) in rows.chunks(w as usize).enumerate() {
                    let y = y0 as usize + dy;
                    seen[y] += 1;
                    let start = y * w as usize;
                    assert_eq!(
                        float_bytes_of(row),
                        float_bytes_of(&plain.image.pixels[start..start + w as usize]),
                        "{what}, row {y}"
                    );
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{what}: rows seen {seen:?}");
        }
    }
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

/// FNV-1a over the bytes: a fingerprint small enough to commit.
fn fingerprint(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The exact floats of a frame of every stage (GI at 4 spp, with the camera turned so that its
/// sine and cosine matter), as fingerprints in a committed snapshot: a machine whose arithmetic
/// or sine rounds differently, or a change that moves any pixel by one bit, fails this test. Update the
/// numbers only for a change that is meant to alter images.
#[test]
fn frames_are_bit_identical_to_the_committed_fingerprints() {
    let scene = cornell_box();
    let mut camera = scene.camera();
    camera.yaw = 7f32.to_radians();
    camera.position.x = 0.1;
    let got: Vec<(Stage, u64)> = Stage::ALL
        .into_iter()
        .map(|stage| {
            let mut settings = stage.settings(scene.effects());
            settings.effects.samples = 4;
            let f = scene.render(&Options {
                width: 48,
                height: 32,
                settings: Some(settings),
                camera: Some(camera),
                ..Options::default()
            });
            (stage, fingerprint(&float_bytes(&f.image)))
        })
        .collect();
    insta::assert_debug_snapshot!(got);
}

/// Stage 6 with independent numbers is the frame stage 6 gave before it took Sobol points,
/// bit for bit (the fingerprint the `Gi` line held until then): the bench's references are
/// rendered with them, so their cached files stay valid.
#[test]
fn the_independent_sampler_renders_as_before_sobol() {
    let scene = cornell_box();
    let mut camera = scene.camera();
    camera.yaw = 7f32.to_radians();
    camera.position.x = 0.1;
    let mut settings = Stage::Gi.settings(scene.effects());
    settings.effects.samples = 4;
    settings.effects.sampler = raytty::sampler::Sampler::Independent;
    let f = scene.render(&Options {
        width: 48,
        height: 32,
        settings: Some(settings),
        camera: Some(camera),
        ..Options::default()
    });
    assert_eq!(fingerprint(&float_bytes(&f.image)), 1583959633513374627);
}

/// The physically based path (area lights, metal, glass; one sample a pixel through the bands
/// and several through the rows) gives the same floats on 1 and 2 threads and on every SIMD
/// path this CPU has.
#[test]
fn physically_based_frames_are_the_same_on_any_threads_and_simd_path() {
    for name in ["area", "glass", "plates"] {
        let scene = raytty::scene::builtin::find(name).unwrap().load().unwrap();
        for samples in [1, 3] {
            let run = |threads, isa: raytty::simd::Isa| {
                let scene = scene.clone().with_isa(isa)?;
                let mut s = Stage::Gi.settings(scene.effects());
                s.effects.samples = samples;
                let image = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        scene
                            .render(&Options {
                                width: 24,
                                height: 16,
                                settings: Some(s),
                                ..Options::default()
                            })
                            .image
                    });
                Some(float_bytes(&image))
            };
            let base = run(1, raytty::simd::Isa::Portable).unwrap();
            for isa in raytty::simd::Isa::ALL {
                for threads in [1, 2] {
                    if let Some(b) = run(threads, isa) {
                        assert!(
                            b == base,
                            "{name}, {samples} spp, {isa:?}, {threads} threads"
                        );
                    }
                }
            }
        }
    }
}
