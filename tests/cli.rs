//! The `raytty render` command as a user runs it: formats, sizes, and clear errors with exit
//! status 2 for bad flag values.

use std::process::{Command, Output};

fn raytty(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn text_formats_have_the_requested_size() {
    let out = raytty(&["render", "--size", "30x10", "--format", "ascii"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 10);
    assert!(text.lines().all(|l| l.len() == 30));
    let out = raytty(&["render", "--size", "30x10", "--format", "ansi"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 10);
    assert!(text.contains("\x1b[38;2;") && text.contains('▀'));
}

#[test]
fn images_are_written_to_files() {
    let dir = std::env::temp_dir().join(format!("raytty-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("f.png");
    let out = raytty(&[
        "render",
        "--pixels",
        "64x32",
        "--format",
        "png",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let pfm = dir.join("f.pfm");
    raytty(&[
        "render",
        "--pixels",
        "64x32",
        "--format",
        "pfm",
        "-o",
        pfm.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&pfm).unwrap();
    assert!(bytes.starts_with(b"PF\n64 32\n-1.0\n"));
    assert_eq!(bytes.len(), "PF\n64 32\n-1.0\n".len() + 64 * 32 * 12);
    // --size gives an image the pixels of that many cells; the extension picks the format.
    let sized = dir.join("cells.pfm");
    let out = raytty(&["render", "--size", "20x6", "-o", sized.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(std::fs::read(&sized).unwrap().starts_with(b"PF\n20 12\n"));
    // An existing file is overwritten to exactly the new frame, whether it was longer or shorter.
    for (name, old) in [
        ("long.pfm", vec![7u8; 100_000]),
        ("short.pfm", vec![7u8; 10]),
        ("long.txt", vec![7u8; 100_000]),
    ] {
        let (reused, fresh) = (dir.join(name), dir.join(format!("fresh-{name}")));
        std::fs::write(&reused, &old).unwrap();
        for path in [&fresh, &reused] {
            let out = raytty(&["render", "--pixels", "16x8", "-o", path.to_str().unwrap()]);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        assert_eq!(
            std::fs::read(&reused).unwrap(),
            std::fs::read(&fresh).unwrap(),
            "{name}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PFM file is written band by band while the frame renders: it holds the same bytes as the
/// PFM on stdout (written after the frame), on 1 and 2 threads, for a frame of one sample
/// (bands), of several (rows) and a denoised one (written after the frame).
#[test]
fn a_pfm_file_holds_the_bytes_stdout_gets() {
    let dir = std::env::temp_dir().join(format!("raytty-pfm-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("f.pfm");
    for threads in ["1", "2"] {
        for extra in [
            &["--stage", "shadows"][..],
            &["--stage", "gi", "--denoise", "off"],
            &["--stage", "gi", "--samples", "4"],
        ] {
            let run = |output: Option<&std::path::Path>| {
                let mut cmd = Command::new(env!("CARGO_BIN_EXE_raytty"));
                cmd.args(["render", "--pixels", "37x21", "--format", "pfm"])
                    .args(extra)
                    .env("RAYON_NUM_THREADS", threads);
                if let Some(path) = output {
                    cmd.arg("-o").arg(path);
                }
                let out = cmd.output().unwrap();
                assert!(
                    out.status.success(),
                    "{}",
                    String::from_utf8_lossy(&out.stderr)
                );
                out.stdout
            };
            let stdout = run(None);
            assert!(stdout.starts_with(b"PF\n37 21\n-1.0\n"));
            assert!(run(Some(&file)).is_empty());
            assert_eq!(
                std::fs::read(&file).unwrap(),
                stdout,
                "{threads} threads, {extra:?}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn camera_and_light_flags_change_the_frame() {
    let base = raytty(&["render", "--size", "20x8", "--format", "ascii"]).stdout;
    let moved = raytty(&[
        "render",
        "--size",
        "20x8",
        "--format",
        "ascii",
        "--camera",
        "0.2,0,-3,10",
    ])
    .stdout;
    let lit = raytty(&[
        "render", "--size", "20x8", "--format", "ascii", "--light", "0,-0.9,0",
    ])
    .stdout;
    assert_ne!(base, moved);
    assert_ne!(base, lit);
}

#[test]
fn bad_values_get_a_clear_message_and_status_2() {
    for (args, needle) in [
        (&["render", "--size", "80by24"][..], "expected WIDTHxHEIGHT"),
        (&["render", "--size", "0x24"], "expected WIDTHxHEIGHT"),
        (&["render", "--format", "gif"], "possible values"),
        (
            &["render", "--stage", "shiny"],
            "expected one of flat, light",
        ),
        (
            &["render", "--camera", "1,2"],
            "expected 4 comma-separated numbers",
        ),
        (&["render", "--light", "0,nan,0"], "out of range"),
        (&["render", "--light", "0,x,0"], "is not a number"),
        (
            &["render", "--sampler", "halton"],
            "'halton' is not a sampler: expected independent or sobol",
        ),
        (
            &[
                "render",
                "--pixels",
                "60000x60000",
                "--format",
                "png",
                "-o",
                "/dev/null",
            ],
            "limit",
        ),
        (
            &["render", "--size", "65535x65535"],
            "--size 65535x65535 is 65535x131070 = ",
        ),
        (
            &["render", "-o", "/nonexistent/box.jpg"],
            "cannot write .jpg",
        ),
        (
            &["--scene", "/nonexistent/box.toml", "render"],
            "--scene /nonexistent/box.toml: no such file: give the path of an existing model",
        ),
        (&["--scene", "/", "render"], "--scene /: is a folder"),
        (
            &["--scene", "/nonexistent/model.glb", "render"],
            "--scene /nonexistent/model.glb: no such file: give the path of an existing model",
        ),
        (
            &["--scene", "Cornell", "render"],
            "name; did you mean `cornell`? (built-in scenes: cornell, ",
        ),
    ] {
        let out = raytty(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn no_color_makes_the_default_text_format_ascii() {
    let run = |no_color: bool, args: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_raytty"));
        cmd.args(["render", "--size", "12x4"]).args(args);
        if no_color {
            cmd.env("NO_COLOR", "1");
        } else {
            cmd.env_remove("NO_COLOR");
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    assert!(run(false, &[]).contains("\x1b[38;2;"));
    let plain = run(true, &[]);
    assert!(
        !plain.contains('\x1b') && plain.lines().count() == 4,
        "{plain:?}"
    );
    // An explicit --format still wins.
    assert!(run(true, &["--format", "ansi"]).contains("\x1b[38;2;"));
}

/// The PFM `raytty render --stage gi --samples n --denoise on|off` writes, as linear floats.
fn gi_pixels_denoised(samples: &str, denoise: &str) -> Vec<f32> {
    let out = raytty(&[
        "render",
        "--stage",
        "gi",
        "--pixels",
        "24x24",
        "--format",
        "pfm",
        "--samples",
        samples,
        "--denoise",
        denoise,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let header = "PF\n24 24\n-1.0\n".len();
    out.stdout[header..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The raw estimate.
fn gi_pixels(samples: &str) -> Vec<f32> {
    gi_pixels_denoised(samples, "off")
}

#[test]
fn the_denoiser_is_a_switch_that_brings_one_sample_closer() {
    let reference = gi_pixels("256");
    let error = |p: Vec<f32>| -> f32 {
        p.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / p.len() as f32
    };
    let (raw, denoised) = (
        error(gi_pixels_denoised("1", "off")),
        error(gi_pixels_denoised("1", "on")),
    );
    assert!(
        denoised < raw / 2.0,
        "denoised ({denoised}) is not much closer to 256 samples than raw ({raw})"
    );
    // The default is on; a stage without path tracing is the same either way.
    let default = raytty(&["render", "--stage", "gi", "--size", "20x10"]);
    let on = raytty(&[
        "render",
        "--stage",
        "gi",
        "--size",
        "20x10",
        "--denoise",
        "on",
    ]);
    assert_eq!(default.stdout, on.stdout);
    let seed = |d: &str| raytty(&["render", "--size", "20x10", "--denoise", d]).stdout;
    assert_eq!(seed("on"), seed("off"));
    let out = raytty(&["render", "--denoise", "maybe"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("on"));
}

#[test]
fn samples_make_the_gi_stage_converge() {
    let reference = gi_pixels("256");
    let error = |samples: &str| -> f32 {
        let p = gi_pixels(samples);
        p.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / p.len() as f32
    };
    let (one, sixteen) = (error("1"), error("16"));
    assert!(
        sixteen < one / 2.0,
        "16 samples ({sixteen}) are not much closer to 256 than 1 sample ({one})"
    );
    let out = raytty(&["render", "--samples", "0"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn output_failures_are_one_line_with_status_1() {
    for (args, needle) in [
        (
            &["render", "-o", "/nonexistent/box.png"][..],
            "raytty: cannot create /nonexistent/box.png: No such file or directory\n",
        ),
        (
            &["render", "-o", "/dev/full"],
            "raytty: cannot write to /dev/full: No space left on device\n",
        ),
    ] {
        let out = raytty(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err, needle, "{args:?}");
    }
}

/// Runs `raytty ARGS` through `sh` with stdout closed (`>&-`), as a shell user would.
#[cfg(unix)]
fn with_stdout_closed(args: &str) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("exec \"$0\" {args} >&-"))
        .arg(env!("CARGO_BIN_EXE_raytty"))
        .output()
        .unwrap()
}

#[cfg(unix)]
#[test]
fn a_closed_stdout_is_an_error_and_a_closed_pipe_is_not() {
    // Closed before raytty started: nothing can be written, so exit status 1 and a message
    // (the bare command too, which prints one frame when stdout is not a terminal).
    for args in ["render --format ascii --size 8x4", "--color ascii"] {
        let out = with_stdout_closed(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args}: {err}");
        assert_eq!(
            err,
            "raytty: stdout is closed: there is nowhere to write the frame (redirect it, or give -o FILE)\n"
        );
    }
    // The list and the bench's table likewise.
    for (args, what) in [("scenes", "the list"), ("bench --quick", "the table")] {
        let out = with_stdout_closed(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args}: {err}");
        assert_eq!(
            err,
            format!("raytty: stdout is closed: there is nowhere to write {what} (redirect it)\n")
        );
    }
    // With -o the frame does not go to stdout, so a closed one does not matter.
    let file = std::env::temp_dir().join(format!("raytty-closed-{}.txt", std::process::id()));
    let out = with_stdout_closed(&format!("render --size 8x4 -o {}", file.display()));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&file).unwrap().len() > 0);
    let _ = std::fs::remove_file(&file);
    // A pipe whose reader goes away (`raytty render | head -c 1`) is not a failure: the frame
    // (about 400 KB) fills the pipe, the reader closes it unread, and the write fails with
    // EPIPE.
    let mut child = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["render", "--format", "ansi", "--size", "200x100"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.is_empty(), "{err}");
}

#[test]
fn a_bench_file_error_says_its_cause_once() {
    let cache = std::env::temp_dir().join(format!("raytty-cli-cache-{}", std::process::id()));
    // A report path that is a folder: found out only when the report is written.
    let report = cache.join("report.md");
    std::fs::create_dir_all(&report).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["bench", "--quick", "--report"])
        .arg(&report)
        .env("XDG_CACHE_HOME", &cache)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&cache);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.ends_with(&format!(
            "raytty: cannot write {}: Is a directory\n",
            report.display()
        )),
        "{err}"
    );
}

#[test]
fn bench_flags_that_would_be_ignored_or_fail_late_are_refused_first() {
    for (args, needle) in [
        (
            &["bench", "--scene", "cornell", "--csv"][..],
            "cannot be used with '--csv'",
        ),
        // --scene before the subcommand: the same declared conflict.
        (
            &[
                "--scene",
                "cornell",
                "bench",
                "--svg",
                "p.svg",
                "--max-spp",
                "4",
            ],
            "the argument '--max-spp' cannot be used with '--scene",
        ),
        (
            &["--scene", "cornell", "bench", "--ref-spp", "16"],
            "the argument '--ref-spp' cannot be used with '--scene",
        ),
        // One pixel cap for every bench, with or without --scene.
        (
            &["bench", "--scene", "cornell", "--sizes", "65535x65535"],
            "--sizes 65535x65535 is too large: at most 67108864 pixels",
        ),
        (
            &["bench", "--sizes", "8193x8193"],
            "--sizes 8193x8193 is too large: at most 67108864 pixels",
        ),
        (
            &["bench", "--quick", "--svg", "/nonexistent/plot.svg"],
            "--svg /nonexistent/plot.svg: the folder /nonexistent does not exist",
        ),
    ] {
        let out = raytty(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?} ran before refusing");
    }
    // --quick with --scene: the quick bench's tiny sizes, not 500×500.
    let out = raytty(&["bench", "--scene", "cornell", "--quick"]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        table.contains("| 40×40 |") && !table.contains("500×500"),
        "{table}"
    );
}

#[test]
fn light_on_a_scene_without_lights_is_refused() {
    let dir = std::env::temp_dir().join(format!("raytty-cli-nolight-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("dark.toml");
    std::fs::write(
        &file,
        "[material.w]\ncolour = [0.5, 0.5, 0.5]\n[[object]]\nkind = \"box\"\nmaterial = \"w\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\n",
    )
    .unwrap();
    let scene = file.to_str().unwrap();
    let lit = raytty(&["--scene", scene, "render", "--light", "0,0,0"]);
    let plain = raytty(&["--scene", scene, "render", "--format", "ascii"]);
    std::fs::remove_dir_all(&dir).unwrap();
    let err = String::from_utf8_lossy(&lit.stderr);
    assert_eq!(lit.status.code(), Some(2), "{err}");
    assert!(err.contains("this scene has none"), "{err}");
    assert!(plain.status.success());
}

/// `--color` picks render's text format, on `render` or before it; with an image output only
/// the one given to `render` is refused (it cannot apply), the other is for text.
#[test]
fn color_picks_the_text_format_of_render() {
    let text = |args: &[&str]| {
        let out = raytty(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let ascii = text(&["render", "--size", "8x4", "--format", "ascii"]);
    let ansi256 = text(&["render", "--size", "8x4", "--format", "ansi256"]);
    assert_ne!(ascii, ansi256);
    assert_eq!(
        text(&["render", "--size", "8x4", "--color", "ascii"]),
        ascii
    );
    assert_eq!(
        text(&["render", "--size", "8x4", "--color", "256"]),
        ansi256
    );
    assert_eq!(
        text(&["--color", "256", "render", "--size", "8x4"]),
        ansi256
    );
    // An explicit --format on render wins over a --color given before it.
    assert_eq!(
        text(&[
            "--color", "256", "render", "--size", "8x4", "--format", "ascii"
        ]),
        ascii
    );
    let out = raytty(&["render", "--color", "256", "--format", "ascii"]);
    assert_eq!(out.status.code(), Some(2));
    let png = std::env::temp_dir().join(format!("raytty-color-{}.png", std::process::id()));
    let out = raytty(&["render", "--color", "256", "-o", png.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--color sets a text format"), "{err}");
    let out = raytty(&[
        "--color",
        "256",
        "render",
        "--size",
        "4x2",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_file(&png);
}

/// `--help` and `help` end with the app's keys (built only when help is asked for); `-h`, the
/// short help, does not list them.
#[cfg(feature = "tui")]
#[test]
fn long_help_lists_the_app_keys() {
    for args in [&["--help"][..], &["help"][..]] {
        let out = raytty(args);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Keys in the app:"), "{args:?}: {text}");
        assert!(text.contains("Esc, Ctrl-C"), "{args:?}: {text}");
    }
    let short = raytty(&["-h"]);
    assert!(!String::from_utf8_lossy(&short.stdout).contains("Keys in the app:"));
}

/// Without `RAYON_NUM_THREADS`, a frame runs on as many threads as the CPUs the process may run
/// on (rayon's default, std's `available_parallelism`: the affinity mask, as `nproc` counts, and
/// any CPU quota), here one CPU and all of them; with it, on as many as it says.
#[cfg(target_os = "linux")]
#[test]
fn the_pool_has_a_thread_per_cpu_of_the_affinity_mask() {
    use std::os::unix::process::CommandExt;
    // SAFETY: a zeroed `cpu_set_t` is valid; the kernel writes the calling thread's mask.
    let all = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        assert_eq!(libc::sched_getaffinity(0, size_of_val(&set), &mut set), 0);
        set
    };
    // SAFETY: reads the set.
    let cpus = unsafe { libc::CPU_COUNT(&all) } as usize;
    let first = (0..libc::CPU_SETSIZE as usize)
        // SAFETY: reads the set.
        .find(|&c| unsafe { libc::CPU_ISSET(c, &all) })
        .unwrap();
    let threads = |one_cpu: bool, env: Option<&str>| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_raytty"));
        cmd.args([
            "render", "--pixels", "64x64", "--format", "ascii", "--stats",
        ])
        .env_remove("RAYON_NUM_THREADS");
        if let Some(n) = env {
            cmd.env("RAYON_NUM_THREADS", n);
        }
        if one_cpu {
            // SAFETY: between fork and exec only `sched_setaffinity`, async-signal-safe, runs.
            unsafe {
                cmd.pre_exec(move || {
                    let mut set: libc::cpu_set_t = std::mem::zeroed();
                    libc::CPU_SET(first, &mut set);
                    libc::sched_setaffinity(0, size_of_val(&set), &set);
                    Ok(())
                });
            }
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success());
        let err = String::from_utf8(out.stderr).unwrap();
        let n = err
            .rsplit(", ")
            .next()
            .unwrap()
            .trim_end()
            .trim_end_matches(')');
        n.split_whitespace()
            .next()
            .unwrap()
            .parse::<usize>()
            .unwrap()
    };
    assert_eq!(threads(false, None), cpus);
    assert_eq!(threads(true, None), 1);
    assert_eq!(threads(true, Some("3")), 3);
}

/// Under a CPU quota of half a CPU (a cgroup v1 `cpu` group, as containers set), a frame runs
/// on one thread: rayon's default count respects the quota. Needs root and cgroup v1's `cpu`
/// controller at /sys/fs/cgroup/cpu; elsewhere it says so and checks nothing.
#[cfg(target_os = "linux")]
#[test]
fn a_half_cpu_quota_gives_one_thread() {
    let group = std::path::Path::new("/sys/fs/cgroup/cpu")
        .join(format!("raytty-test-{}", std::process::id()));
    if std::fs::create_dir(&group).is_err() {
        eprintln!("no cgroup v1 cpu controller to write to: not checked");
        return;
    }
    let set = |file: &str, value: &str| std::fs::write(group.join(file), value).is_ok();
    let ok = set("cpu.cfs_period_us", "100000") && set("cpu.cfs_quota_us", "50000");
    let out = ok.then(|| {
        Command::new("sh")
            .arg("-c")
            .arg(format!(
                "echo $$ > {}/cgroup.procs && exec \"$0\" render --pixels 8x8 --format ascii --stats=json",
                group.display()
            ))
            .arg(env!("CARGO_BIN_EXE_raytty"))
            .env_remove("RAYON_NUM_THREADS")
            .output()
            .unwrap()
    });
    let _ = std::fs::remove_dir(&group);
    let Some(out) = out else {
        eprintln!("cannot set a CPU quota: not checked");
        return;
    };
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("\"threads\":1"), "{err}");
}

/// `--stats` names the physically based effects a frame ran; the hidden `--estimator` picks
/// how they gather light, and a wrong name is a usage error.
#[test]
fn stats_name_the_effects_and_the_estimator() {
    let run = |scene: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            scene,
            "--stage",
            "gi",
            "--pixels",
            "8x6",
            "--format",
            "pfm",
            "-o",
            "/dev/null",
            "--stats",
        ];
        args.extend_from_slice(extra);
        raytty(&args)
    };
    let out = run("plates", &[]);
    assert!(out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("effects: path, area lights (mis), glossy, metal"),
        "{err}"
    );
    let err = String::from_utf8(run("plates", &["--estimator", "bsdf"]).stderr).unwrap();
    assert!(err.contains("area lights (bsdf sampling)"), "{err}");
    let out = run("plates", &["--estimator", "mmis"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("expected auto, light, bsdf or mis")
    );
    // The seed's scenes name none.
    let out = run("cornell", &[]);
    assert!(out.status.success());
    assert!(!String::from_utf8(out.stderr).unwrap().contains("effects"));
}
