//! `raytty render --tile I/N` and `raytty merge`: the tiles of a frame, merged in any order,
//! are byte for byte the frame one render writes (PNG and PFM), for every kind of frame loop
//! (one sample, anti-aliased, path traced) and a model (its own tone map); merge refuses what
//! is not the tiles of one frame.

use std::path::PathBuf;
use std::process::{Command, Output};

fn raytty(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(args)
        .env_remove("NO_COLOR")
        .output()
        .expect("run raytty")
}

/// A file in the temporary directory, removed when dropped.
struct Temp(PathBuf);

impl Temp {
    fn new(name: &str) -> Temp {
        Temp(std::env::temp_dir().join(format!("raytty-tiles-{}-{name}", std::process::id())))
    }

    fn path(&self) -> &str {
        self.0.to_str().expect("a UTF-8 temporary path")
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn ok(out: Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn merged_tiles_are_the_frame_byte_for_byte() {
    let cube = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/models/cube.obj");
    let cases: [&[&str]; 4] = [
        &["render", "--pixels", "61x43"],
        &["render", "--pixels", "40x33", "--samples", "3"],
        &[
            "render",
            "--stage",
            "gi",
            "--denoise",
            "off",
            "--pixels",
            "30x25",
            "--samples",
            "2",
        ],
        &["--scene", cube, "render", "--pixels", "37x41"],
    ];
    for (k, args) in cases.iter().enumerate() {
        for ext in ["png", "pfm"] {
            let whole = Temp::new(&format!("{k}-whole.{ext}"));
            ok(raytty(&[args, &["-o", whole.path()][..]].concat()));
            for n in [1, 2, 3] {
                let tiles: Vec<Temp> = (0..n)
                    .map(|i| Temp::new(&format!("{k}-{i}-{n}.pfm")))
                    .collect();
                for (i, t) in tiles.iter().enumerate() {
                    let part = format!("{i}/{n}");
                    ok(raytty(
                        &[args, &["--tile", &part, "-o", t.path()][..]].concat(),
                    ));
                }
                let merged = Temp::new(&format!("{k}-merged.{ext}"));
                let mut merge = vec!["merge", "-o", merged.path()];
                merge.extend(tiles.iter().rev().map(Temp::path));
                ok(raytty(&merge));
                let (a, b) = (
                    std::fs::read(&whole.0).unwrap(),
                    std::fs::read(&merged.0).unwrap(),
                );
                assert!(
                    a == b,
                    "{args:?} in {n} tiles, .{ext}: the merged frame differs"
                );
            }
        }
    }
}

#[test]
fn merge_refuses_what_is_not_one_frames_tiles() {
    let (t0, t1, other) = (Temp::new("r0.pfm"), Temp::new("r1.pfm"), Temp::new("o.pfm"));
    ok(raytty(&[
        "render",
        "--pixels",
        "20x20",
        "--tile",
        "0/2",
        "-o",
        t0.path(),
    ]));
    ok(raytty(&[
        "render",
        "--pixels",
        "20x20",
        "--tile",
        "1/2",
        "-o",
        t1.path(),
    ]));
    ok(raytty(&[
        "render",
        "--pixels",
        "20x24",
        "--tile",
        "1/2",
        "-o",
        other.path(),
    ]));
    let out = Temp::new("out.png");
    for (tiles, says) in [
        (vec![t0.path()], "tile 1 of 0 to 1 is missing"),
        (vec![t0.path(), t0.path(), t1.path()], "are both tile 0/2"),
        (vec![t0.path(), other.path()], "give the tiles of one frame"),
    ] {
        let r = raytty(&[&["merge", "-o", out.path()][..], &tiles].concat());
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(says), "{err}");
        assert!(!out.0.exists());
    }
    let whole = Temp::new("whole.pfm");
    ok(raytty(&["render", "--pixels", "20x20", "-o", whole.path()]));
    let r = raytty(&["merge", "-o", out.path(), whole.path()]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("not a tile"));
    let (pfm, png) = (Temp::new("refused.pfm"), Temp::new("refused.png"));
    let cases: [(&[&str], &str); 3] = [
        (
            &["render", "--stage", "gi", "--tile", "0/2", "-o", pfm.path()],
            "--denoise off",
        ),
        (
            &["render", "--tile", "0/2", "-o", png.path()],
            "give -o NAME.pfm",
        ),
        (
            &[
                "render",
                "--pixels",
                "16x16",
                "--tile",
                "0/3",
                "-o",
                pfm.path(),
            ],
            "at most 2 tiles",
        ),
    ];
    for (args, says) in cases {
        let r = raytty(args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(says), "{err}");
        assert!(!pfm.0.exists() && !png.0.exists(), "{args:?}");
    }
}
