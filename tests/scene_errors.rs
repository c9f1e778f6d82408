//! What bad input gets: every mistake in a scene file, a mesh or a flag is a message naming the
//! file, line and column, what was wrong and what would be right, and exit status 2. Each test
//! runs the real binary on a small file written for it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One test's folder of files, removed when the test ends (passed or failed).
struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh folder for one test's files.
fn dir(test: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("raytty-scene-errors-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// Runs `raytty render --scene FILE` on `scene` written to `d/scene.toml`, expects exit status
/// 2, and returns stderr.
fn fails(d: &Path, scene: &str) -> String {
    let path = d.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["render", "--format", "ascii", "--size", "8x4", "--scene"])
        .arg(&path)
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(out.stdout.is_empty());
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// Asserts `err` names `file` at `line:col` and contains every one of `words`.
fn says(err: &str, file: &Path, line: usize, col: usize, words: &[&str]) {
    let at = format!("{}:{line}:{col}: ", file.display());
    assert!(err.contains(&at), "expected `{at}` in: {err}");
    for w in words {
        assert!(err.contains(w), "expected `{w}` in: {err}");
    }
}

/// A valid scene to start from: one light, one material, one triangle.
const BASE: &str = "[[light]]\nposition = [0, -0.5, -0.7]\npower = 14\n\n[material.white]\ncolour = [0.75, 0.75, 0.75]\n";

#[test]
fn toml_syntax_error() {
    let d = dir("syntax");
    let err = fails(&d, "[camera]\nposition = [0, 0, -3\nyaw = 0\n");
    says(
        &err,
        &d.join("scene.toml"),
        3,
        1,
        &["missing comma", "expected `,`"],
    );
}

#[test]
fn unknown_key_with_a_suggestion() {
    let d = dir("unknown");
    let err = fails(&d, &format!("{BASE}mirorr = 0.5\n"));
    says(
        &err,
        &d.join("scene.toml"),
        7,
        1,
        &[
            "unknown key `mirorr`",
            "did you mean `mirror`?",
            "colour, mirror",
        ],
    );
    // Far from every key: no suggestion, but the list of keys.
    let err = fails(&d, "[camera]\nzoom = 2\n");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        1,
        &["unknown key `zoom`", "position, yaw, pitch"],
    );
    assert!(!err.contains("did you mean"), "{err}");
}

#[test]
fn missing_obj_file() {
    let d = dir("missing-obj");
    let err = fails(
        &d,
        &format!(
            "{BASE}\n[[object]]\nkind = \"obj\"\nmaterial = \"white\"\npath = \"nowhere.obj\"\n"
        ),
    );
    says(
        &err,
        &d.join("scene.toml"),
        11,
        8,
        &["nowhere.obj", "relative to the scene file"],
    );
}

#[test]
fn nan_infinite_and_absurd_coordinates() {
    let d = dir("coordinates");
    for (value, shown) in [("nan", "NaN"), ("-inf", "-inf"), ("1e7", "10000000")] {
        let err = fails(&d, &format!("[camera]\nposition = [0, {value}, -3]\n"));
        says(&err, &d.join("scene.toml"), 2, 12, &[shown, "within ±1e6"]);
    }
    // In a triangle, and beyond the limit only after the object's transform.
    let tri = "[[object]]\nkind = \"triangles\"\nmaterial = \"white\"\ntriangles = [\n  [[0, 0, 0], [1, 0, 0], [0, 1, 0]],\n  [[0, 0, 0], [1, 0, 0], [0, 1e300, 0]],\n]\n";
    let err = fails(&d, &format!("{BASE}{tri}"));
    says(&err, &d.join("scene.toml"), 12, 3, &["within ±1e6"]);
    let err = fails(
        &d,
        &format!("{BASE}{}scale = 1e6\n", tri.replace("1e300", "2")),
    );
    says(
        &err,
        &d.join("scene.toml"),
        12,
        3,
        &["after the object's transform"],
    );
}

#[test]
fn negative_or_nan_light_power() {
    let d = dir("power");
    for power in ["-1", "nan", "[14, -0.5, 14]", "inf"] {
        let err = fails(
            &d,
            &format!("[[light]]\nposition = [0, 0, 0]\npower = {power}\n"),
        );
        says(
            &err,
            &d.join("scene.toml"),
            3,
            9,
            &["light power", "from 0 to 1e12"],
        );
    }
}

#[test]
fn degenerate_triangles_are_errors_in_scene_files_and_meshes() {
    let d = dir("degenerate");
    let err = fails(
        &d,
        &format!(
            "{BASE}[[object]]\nkind = \"triangles\"\nmaterial = \"white\"\ntriangles = [\n  [[0, 0, 0], [1, 0, 0], [0, 1, 0]],\n  [[0, 0, 0], [1, 1, 1], [2, 2, 2]],\n]\n"
        ),
    );
    says(
        &err,
        &d.join("scene.toml"),
        12,
        3,
        &["degenerate triangle", "zero area"],
    );
    // A mesh face: the error names the OBJ file's line and column.
    std::fs::write(
        d.join("flat.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n",
    )
    .unwrap();
    let err = fails(
        &d,
        &format!("{BASE}[[object]]\nkind = \"obj\"\nmaterial = \"white\"\npath = \"flat.obj\"\n"),
    );
    says(&err, &d.join("flat.obj"), 5, 1, &["degenerate triangle"]);
    // A fine box made degenerate by its transform: a micrometre box ten units out, where f32
    // steps are a micrometre apart. The message blames the transform, not the box.
    let err = fails(
        &d,
        &format!(
            "{BASE}[[object]]\nkind = \"box\"\nmaterial = \"white\"\ncentre = [0, 0, 0]\nsize = [1, 0.5, 1]\nscale = 1e-6\ntranslate = [-10, -10, 0]\n"
        ),
    );
    says(
        &err,
        &d.join("scene.toml"),
        7,
        1,
        &[
            "the transform makes a triangle degenerate",
            "nearer the origin",
        ],
    );
}

#[test]
fn meshes_over_the_triangle_limit() {
    let d = dir("limit");
    // 2,000,001 faces: one over the limit, reported at the face that crosses it.
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    obj += &"f 1 2 3\n".repeat(2_000_001);
    std::fs::write(d.join("big.obj"), obj).unwrap();
    let err = fails(
        &d,
        &format!("{BASE}[[object]]\nkind = \"obj\"\nmaterial = \"white\"\npath = \"big.obj\"\n"),
    );
    says(
        &err,
        &d.join("big.obj"),
        2_000_004,
        1,
        &["more than 2000000 triangles"],
    );
    // A procedural mesh is refused before it is generated.
    let err = fails(
        &d,
        &format!(
            "{BASE}[[object]]\nkind = \"icosphere\"\nmaterial = \"white\"\nsubdivisions = 400\n"
        ),
    );
    says(
        &err,
        &d.join("scene.toml"),
        10,
        16,
        &["subdivisions is 400", "from 1 to 316"],
    );
}

#[test]
fn samples_and_bounces_out_of_range() {
    let d = dir("effects");
    let err = fails(&d, "[effects]\nsamples = 0\n");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        11,
        &["samples", "from 1 to 1024"],
    );
    let err = fails(&d, "[effects]\nindirect = { bounces = 100 }\n");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        12,
        &["bounces is 100", "from 0 to 16"],
    );
    let err = fails(&d, "[effects]\nindirect = \"always\"\n");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        12,
        &["\"none\"", "bounces = n"],
    );
    let err = fails(&d, "[effects]\nsampler = \"halton\"\n");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        11,
        &["unknown sampler `halton`", "independent or sobol"],
    );
}

#[test]
fn pixels_over_the_memory_budget_are_refused_with_the_estimate() {
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args([
            "render",
            "--pixels",
            "20000x20000",
            "--format",
            "pfm",
            "-o",
            "/dev/null",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("400000000 pixels") && err.contains("18310 MiB"),
        "{err}"
    );
}

#[test]
fn unknown_scene_names_list_the_built_ins() {
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["render", "--scene", "mirorr"])
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cornell, mirror, lights, sphere") && err.contains("did you mean `mirror`"),
        "{err}"
    );
}

#[test]
fn control_characters_in_the_file_never_reach_the_terminal() {
    let d = dir("control");
    let err = fails(&d, "[camera]\n\"evil\\u001b[2J\" = 1\n");
    assert!(!err.contains('\x1b'), "{err:?}");
    says(
        &err,
        &d.join("scene.toml"),
        2,
        1,
        &["unknown key `evil[2J`"],
    );
}

/// Runs `raytty render --scene FILE` on `scene` (bytes) written to `d/scene.toml`, expects
/// success, and returns the frame.
fn renders(d: &Path, scene: &[u8]) -> String {
    let path = d.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(["render", "--format", "ascii", "--size", "8x4", "--scene"])
        .arg(&path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr: {err}");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_first_line() {
    let d = dir("bom");
    // An OBJ file from a Windows editor: its first vertex is still read, so the face is valid
    // and renders as the same file without the mark does.
    let obj = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
    let scene = format!(
        "{BASE}[[object]]\nkind = \"obj\"\nmaterial = \"white\"\npath = \"m.obj\"\n[camera]\nposition = [0, 0, -3]\n"
    );
    std::fs::write(d.join("m.obj"), obj).unwrap();
    let plain = renders(&d, scene.as_bytes());
    std::fs::write(d.join("m.obj"), format!("\u{FEFF}{obj}")).unwrap();
    assert_eq!(renders(&d, scene.as_bytes()), plain);
    // A scene file with the mark loads the same, and its first line's columns start after it.
    assert_eq!(renders(&d, format!("\u{FEFF}{scene}").as_bytes()), plain);
    let err = fails(&d, "\u{FEFF}zoom = 1\n");
    says(&err, &d.join("scene.toml"), 1, 1, &["unknown key `zoom`"]);
    assert!(err.contains("\n 1 | zoom = 1\n   | ^"), "{err}");
    // An error in the OBJ's first line is at its first character too.
    std::fs::write(d.join("m.obj"), "\u{FEFF}v 0 x 0\n").unwrap();
    let err = fails(&d, &scene);
    says(&err, &d.join("m.obj"), 1, 5, &["`x` is not a number"]);
}

/// The character of the shown line that the caret under it points at.
fn under_caret(err: &str) -> char {
    let lines: Vec<&str> = err.lines().collect();
    let caret = lines
        .iter()
        .rposition(|l| l.ends_with('^'))
        .expect("a caret line");
    let at = |l: &str| l.split_once(" | ").map(|(_, rest)| rest.to_string());
    let shown = at(lines[caret - 1]).expect("a shown line");
    let column = at(lines[caret]).expect("a caret").chars().count();
    shown
        .chars()
        .nth(column - 1)
        .expect("the caret is within the line")
}

#[test]
fn columns_count_characters_in_meshes_as_in_scene_files() {
    let d = dir("columns");
    // "é" is two bytes and "→" three: the bad index is the 11th character (the 14th byte), and
    // the caret is under it.
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/é 2/→ 9\n").unwrap();
    let err = fails(
        &d,
        &format!("{BASE}[[object]]\nkind = \"obj\"\nmaterial = \"white\"\npath = \"m.obj\"\n"),
    );
    says(&err, &d.join("m.obj"), 4, 11, &["vertex index 9"]);
    assert!(err.contains("\n 4 | f 1/é 2/→ 9\n"), "{err}");
    assert_eq!(under_caret(&err), '9', "{err}");
    // The same in a scene file: the column of the value after a non-ASCII key.
    let err = fails(&d, "[camera]\n\"é→\" = 1\n");
    says(&err, &d.join("scene.toml"), 2, 1, &["unknown key `é→`"]);
    let err = fails(
        &d,
        "object = [{ material = \"é→\", kind = \"x\", triangles = 1 }]\n",
    );
    says(&err, &d.join("scene.toml"), 1, 54, &[]);
    assert_eq!(under_caret(&err), '1', "{err}");
}

/// Directional, spot and environment lights: each mistake at its place (an unknown kind, a key
/// of another kind, a missing key, a zero direction, a cone inside out or past 90 degrees).
#[test]
fn bad_light_kinds_and_values() {
    let d = dir("light-kinds");
    let file = d.join("scene.toml");
    let cases: [(&str, usize, usize, &[&str]); 7] = [
        (
            "[[light]]\nkind = \"sun\"\ndirection = [0, 1, 0]\n",
            2,
            8,
            &["unknown light kind `sun`", "directional, spot, environment"],
        ),
        (
            "[[light]]\nkind = \"directional\"\ndirection = [0, 1, 0]\nirradiance = 1\npower = 3\n",
            5,
            9,
            &[
                "`power` is not a key of kind = \"directional\" lights",
                "direction, irradiance",
            ],
        ),
        (
            "[[light]]\nkind = \"spot\"\nposition = [0, 0, 0]\npower = 3\n",
            1,
            1,
            &[
                "missing key `direction`",
                "kind = \"spot\"",
                "direction = [x, y, z]",
            ],
        ),
        (
            "[[light]]\nkind = \"directional\"\nirradiance = 1\ndirection = [0, 0, 0]\n",
            4,
            13,
            &["the light direction is [0, 0, 0]", "not zero"],
        ),
        (
            "[[light]]\nkind = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, 1, 0]\npower = 3\ninner_angle = 30\nouter_angle = 20\n",
            6,
            15,
            &["inner_angle 30 is wider than its outer_angle 20"],
        ),
        (
            "[[light]]\nkind = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, 1, 0]\npower = 3\nouter_angle = 95\n",
            6,
            15,
            &["outer_angle (degrees) is 95", "from 0 to 90"],
        ),
        (
            "[[light]]\nkind = \"environment\"\nemission = [0.1, -1, 0]\n",
            3,
            12,
            &["environment emission -1 is not allowed"],
        ),
    ];
    for (light, line, col, words) in cases {
        let err = fails(
            &d,
            &format!(
                "{light}\n[material.white]\ncolour = [1, 1, 1]\n[[object]]\nkind = \"box\"\nmaterial = \"white\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n"
            ),
        );
        says(&err, &file, line, col, words);
    }
}
