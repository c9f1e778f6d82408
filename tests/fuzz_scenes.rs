//! A seeded mutation fuzzer over valid scene files and OBJ meshes: byte flips, insertions and
//! deletions, token swaps, numbers replaced by NaN, infinities, -0, 1e39 and huge integers,
//! truncation, duplicated lines, and the same for the mesh. Every input must either load into
//! a scene that renders a finite frame, or fail with an error that has a line and column. No
//! input may panic, and none is larger than [`MAX_INPUT`] bytes, so none can take long.
//!
//! Mutations cannot tell whether a file that loaded should have: generated scenes can. Each
//! value is drawn from in-range values (the limits included) or, now and then, out-of-range
//! ones, and the scene must load exactly when all of its values are in range.
//!
//! `cargo test` runs the regression corpus in `tests/fuzz_corpus/` (hostile inputs: files
//! named `ok_*.toml` must load, every other `.toml` must be refused with a position) and a
//! short run; the long run, a million inputs per parser, is ignored:
//!
//!     cargo test --release --test fuzz_scenes -- --ignored --nocapture

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::time::{Duration, Instant};

use raytty::rng::Rng;
use raytty::scene::builtin::BUILTINS;
use raytty::scene::file::{self, SceneFileError};
use raytty::{Options, Stage};

/// Largest mutated input: far above the seed files, small enough that every input is quick.
const MAX_INPUT: usize = 64 * 1024;

/// The name the mutated mesh is read under.
const MESH: &str = "mesh.obj";

/// Valid files to start from: the built-ins (the big sphere made small), the example, and a
/// scene that reads a mesh.
fn seeds() -> Vec<String> {
    let mut s: Vec<String> = BUILTINS
        .iter()
        .map(|b| b.source.replace("subdivisions = 224", "subdivisions = 6"))
        .collect();
    s.push(
        include_str!("../scenes/example.toml")
            .replace("path = \"tetrahedron.obj\"", "path = \"mesh.obj\""),
    );
    s.push(
        "name = \"m\"\n[camera]\nposition = [0, -0.5, -3]\npitch = 10\n[[light]]\nposition = [0, -2, -1]\npower = [10, 12, 14]\n[material.a]\ncolour = [0.5, 0.6, 0.7]\nmirror = 0.25\n[[object]]\nkind = \"obj\"\nmaterial = \"a\"\npath = \"mesh.obj\"\nscale = [1, 2, 1]\nrotate_y = -45\n[effects]\nindirect = { bounces = 2 }\nsamples = 2\n".to_string(),
    );
    s
}

const MESH_SEED: &str = include_str!("../scenes/tetrahedron.obj");

/// Replacement numbers: the values that break parsers and arithmetic.
const NUMBERS: [&str; 16] = [
    "nan",
    "-nan",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "-0",
    "-0.0",
    "0",
    "-1",
    "1e6",
    "1e-45",
    "18446744073709551616",
    "9223372036854775807",
    "-9223372036854775808",
    "3.4028236e38",
];

/// Characters a byte insertion draws from: TOML and OBJ punctuation, digits, and a few hostile ones.
const BYTES: &[u8] = b"[]{}=,.\"'#\n\r\t -+/0123456789eEfvnaix\x00\x1b\x7f\\";

fn mutate(rng: &mut Rng, input: &str) -> String {
    let mut b = input.as_bytes().to_vec();
    let pick = |rng: &mut Rng, n: usize| (rng.next_u64() % n.max(1) as u64) as usize;
    for _ in 0..1 + pick(rng, 3) {
        match pick(rng, 9) {
            0 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] ^= 1 << pick(rng, 8);
            }
            1 => {
                let i = pick(rng, b.len() + 1);
                b.insert(i, BYTES[pick(rng, BYTES.len())]);
            }
            2 if !b.is_empty() => {
                let i = pick(rng, b.len());
                let n = 1 + pick(rng, 16);
                b.drain(i..(i + n).min(b.len()));
            }
            3 => b.truncate(pick(rng, b.len() + 1)),
            4 | 5 => {
                // Replace a number with a hostile one.
                let text = String::from_utf8_lossy(&b).into_owned();
                let spans = numbers(&text);
                if !spans.is_empty() {
                    let (s, e) = spans[pick(rng, spans.len())];
                    let mut t = text;
                    t.replace_range(s..e, NUMBERS[pick(rng, NUMBERS.len())]);
                    b = t.into_bytes();
                }
            }
            6 => {
                // Swap two whitespace-separated tokens.
                let text = String::from_utf8_lossy(&b).into_owned();
                let mut tokens: Vec<&str> = text.split(' ').collect();
                if tokens.len() > 1 {
                    let (i, j) = (pick(rng, tokens.len()), pick(rng, tokens.len()));
                    tokens.swap(i, j);
                }
                b = tokens.join(" ").into_bytes();
            }
            7 => {
                // Duplicate a line.
                let text = String::from_utf8_lossy(&b).into_owned();
                let mut lines: Vec<&str> = text.split('\n').collect();
                let i = pick(rng, lines.len());
                lines.insert(i, lines[i]);
                b = lines.join("\n").into_bytes();
            }
            _ => {
                // Copy a random slice somewhere else.
                if !b.is_empty() {
                    let s = pick(rng, b.len());
                    let e = (s + 1 + pick(rng, 64)).min(b.len());
                    let chunk = b[s..e].to_vec();
                    let at = pick(rng, b.len());
                    b.splice(at..at, chunk);
                }
            }
        }
    }
    b.truncate(MAX_INPUT);
    String::from_utf8_lossy(&b).into_owned()
}

/// Byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let s = if i > 0 && bytes[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            while i < bytes.len() && (bytes[i].is_ascii_digit() || b".eE".contains(&bytes[i])) {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

/// What one input did.
#[derive(Debug, Default)]
struct Tally {
    inputs: u64,
    loaded: u64,
    errors: u64,
    slowest: Duration,
    /// The input that took longest (to replay it: the same seed, this many iterations + 1).
    slowest_input: String,
}

/// Loads `scene` (with `mesh` as the mesh file) and checks the outcome; panics on a finding.
fn check(scene: &str, mesh: &[u8], tally: &mut Tally) {
    let start = Instant::now();
    let read = |p: &str| {
        if p == MESH {
            Ok((MESH.to_string(), mesh.to_vec()))
        } else {
            Err(format!("cannot read {p}: no such file"))
        }
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let result = file::parse(scene, "fuzz.toml", "fuzz", &read);
        if let Ok(s) = &result {
            // A scene that loaded renders a finite frame (samples capped to keep it quick).
            let mut settings = Stage::Indirect.settings(s.effects());
            settings.effects.samples = settings.effects.samples.min(2);
            let frame = s.render(&Options {
                width: 6,
                height: 4,
                settings: Some(settings),
                ..Options::default()
            });
            assert!(frame.image.pixels.iter().all(|p| p.is_finite()));
        }
        result
    }));
    let result = outcome.unwrap_or_else(|_| {
        panic!(
            "panic on input:\n{scene:?}\nmesh:\n{:?}",
            String::from_utf8_lossy(mesh)
        )
    });
    match result {
        Ok(_) => tally.loaded += 1,
        Err(e) => {
            tally.errors += 1;
            positioned(&e, scene);
        }
    }
    tally.inputs += 1;
    if start.elapsed() > tally.slowest {
        tally.slowest = start.elapsed();
        tally.slowest_input = scene.chars().take(4000).collect();
    }
}

/// An error has a line and a column, a message, and no control characters.
fn positioned(e: &SceneFileError, input: &str) {
    assert!(
        e.line >= 1 && e.column >= 1 && !e.message.is_empty(),
        "error without a position: {e}\ninput: {input:?}"
    );
    let shown = e.to_string();
    // The message, then the line with a caret under the column: newlines, nothing else.
    assert!(
        !shown.chars().any(|c| c.is_control() && c != '\n'),
        "{shown:?}"
    );
    assert!(shown.starts_with(&format!("{}:{}:{}: ", e.file, e.line, e.column)));
    assert!(shown.lines().count() <= 3, "{shown}");
}

fn run(iterations: u64, seed: u64) -> Tally {
    let seeds = seeds();
    let mut rng = Rng::seeded(seed);
    let mut tally = Tally::default();
    for i in 0..iterations {
        let base = &seeds[(i % seeds.len() as u64) as usize];
        // Mostly mutate the scene; sometimes the mesh; sometimes both.
        let (scene, mesh) = match rng.next_u64() % 4 {
            0 => (base.clone(), mutate(&mut rng, MESH_SEED)),
            1 => (mutate(&mut rng, base), mutate(&mut rng, MESH_SEED)),
            _ => (mutate(&mut rng, base), MESH_SEED.to_string()),
        };
        check(&scene, mesh.as_bytes(), &mut tally);
    }
    tally
}

#[test]
fn every_seed_loads() {
    for (i, s) in seeds().iter().enumerate() {
        let read = |_: &str| Ok((MESH.to_string(), MESH_SEED.as_bytes().to_vec()));
        file::parse(s, "seed.toml", "seed", &read).unwrap_or_else(|e| panic!("seed {i}: {e}"));
    }
}

#[test]
fn regression_corpus() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            n += 1;
            let source = String::from_utf8_lossy(&std::fs::read(&path).unwrap()).into_owned();
            let outcome = catch_unwind(|| file::load(&path));
            let must_load = path
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("ok_");
            match outcome.unwrap_or_else(|_| panic!("{} panics", path.display())) {
                Ok(_) => assert!(must_load, "{} loads", path.display()),
                Err(e) => {
                    assert!(!must_load, "{}: {e}", path.display());
                    positioned(&e, &source);
                }
            }
        }
    }
    assert!(n >= 5, "the corpus has {n} files");
}

/// A value for a generated scene: its TOML text and whether it is within the key's range.
type Pick = (String, bool);

/// One of `valid` or `invalid` (one time in 50: a scene has about 35 values, so about half of
/// the scenes have a bad one), as TOML text.
fn pick(rng: &mut Rng, valid: &[&str], invalid: &[&str]) -> Pick {
    let bad = rng.next_u64().is_multiple_of(50) && !invalid.is_empty();
    let pool = if bad { invalid } else { valid };
    (
        pool[(rng.next_u64() % pool.len() as u64) as usize].to_string(),
        !bad,
    )
}

/// A scene whose every value is drawn from a pool of in-range values (the limits themselves
/// included) or, now and then, of out-of-range ones, with whether it should load.
fn generated(rng: &mut Rng) -> (String, bool) {
    let mut ok = true;
    let mut text = String::new();
    let mut put = |key: &str, (v, fine): Pick, text: &mut String| {
        ok &= fine;
        *text += &format!("{key} = {v}\n");
    };
    const COORD: [&str; 5] = ["0", "-1.5", "1e6", "-1e6", "0.25"];
    const BAD_COORD: [&str; 4] = ["1000001", "nan", "-inf", "1e300"];
    let triple = |rng: &mut Rng, valid: &[&str], invalid: &[&str]| -> Pick {
        let (mut ok, mut parts) = (true, Vec::new());
        for _ in 0..3 {
            let (v, fine) = pick(rng, valid, invalid);
            ok &= fine;
            parts.push(v);
        }
        (format!("[{}]", parts.join(", ")), ok)
    };
    text += "[camera]\n";
    put("position", triple(rng, &COORD, &BAD_COORD), &mut text);
    put(
        "yaw",
        pick(rng, &["0", "360", "-360", "12.5"], &["360.5", "nan", "1e9"]),
        &mut text,
    );
    put(
        "pitch",
        pick(rng, &["0", "90", "-90", "-30"], &["90.01", "-91", "inf"]),
        &mut text,
    );
    for _ in 0..1 + rng.next_u64() % 3 {
        text += "[[light]]\n";
        put("position", triple(rng, &COORD, &BAD_COORD), &mut text);
        let power = ["0", "14", "1e12", "[1, 0, 3]", "[0, 0, 1e12]"];
        put(
            "power",
            pick(
                rng,
                &power,
                &["-1", "1.1e12", "nan", "[1, -0.5, 1]", "[1, 2]"],
            ),
            &mut text,
        );
    }
    text += "[material.m]\n";
    put(
        "colour",
        triple(rng, &["0", "1", "0.75"], &["1.01", "-0.1", "nan"]),
        &mut text,
    );
    put(
        "mirror",
        pick(rng, &["0", "1", "0.5"], &["2", "-0.01", "nan"]),
        &mut text,
    );
    text += "[[object]]\nkind = \"box\"\nmaterial = \"m\"\ncentre = [0, 0, 0]\n";
    put(
        "size",
        triple(rng, &["1", "0.5", "2"], &["0", "-1", "nan"]),
        &mut text,
    );
    put(
        "scale",
        pick(
            rng,
            &["1e-3", "1e5", "1", "[1, 2, 3]"],
            &["0", "-1", "1e7", "[1, 0, 1]"],
        ),
        &mut text,
    );
    put(
        "rotate_y",
        pick(rng, &["0", "-360", "45", "360"], &["361", "nan"]),
        &mut text,
    );
    put(
        "translate",
        triple(rng, &["0", "-10", "3.5"], &["nan", "1e7"]),
        &mut text,
    );
    text += "[effects]\n";
    put(
        "shadows",
        pick(rng, &["true", "false"], &["1", "\"yes\""]),
        &mut text,
    );
    let indirect = [
        "\"none\"",
        "0",
        "0.5",
        "100",
        "{ bounces = 0 }",
        "{ bounces = 16 }",
    ];
    put(
        "indirect",
        pick(
            rng,
            &indirect,
            &[
                "101",
                "-1",
                "\"full\"",
                "{ bounces = 17 }",
                "{ bounces = -1 }",
            ],
        ),
        &mut text,
    );
    put(
        "samples",
        pick(rng, &["1", "4", "1024"], &["0", "1025", "-3", "1.5"]),
        &mut text,
    );
    (text, ok)
}

/// Loads `n` generated scenes from `seed`, checking each against the generator's verdict;
/// returns how many loaded and how many were refused.
fn run_generated(n: u64, seed: u64) -> (u64, u64) {
    let mut rng = Rng::seeded(seed);
    let (mut loaded, mut refused) = (0, 0);
    for _ in 0..n {
        let (text, ok) = generated(&mut rng);
        match file::parse(&text, "gen.toml", "gen", &file::no_meshes) {
            Ok(_) if ok => loaded += 1,
            Err(e) if !ok => {
                positioned(&e, &text);
                refused += 1;
            }
            Ok(_) => panic!("loaded, but a value is out of range:\n{text}"),
            Err(e) => panic!("refused, but every value is in range: {e}\n{text}"),
        }
    }
    (loaded, refused)
}

#[test]
fn generated_scenes_load_exactly_when_every_value_is_in_range() {
    let (loaded, refused) = run_generated(400, 11);
    assert!(
        loaded > 100 && refused > 100,
        "{loaded} loaded, {refused} refused"
    );
}

/// A short run in every `cargo test`: a few hundred inputs, well under a second.
#[test]
fn short_run() {
    let t = run(300, 7);
    assert_eq!(t.inputs, 300);
    assert!(t.loaded > 0 && t.errors > 0, "{t:?}");
}

// Model files: the same mutations over the small models in `tests/models/` (text formats as
// text; binary ones byte by byte, with 32-bit counts and offsets overwritten by hostile
// values). Every input must load into a scene that renders a finite frame, or be refused with
// an error that names the file and says what is wrong; none may panic.

mod models {
    use super::*;
    use raytty::scene::model::{self, Format, View};

    /// A parser the long run fuzzes on its own, with the models it starts from.
    #[derive(Clone, Copy, Debug)]
    pub(super) enum Parser {
        /// OBJ (its MTL kept valid).
        Obj,
        /// MTL (its OBJ kept valid).
        Mtl,
        /// glTF JSON with embedded buffers.
        GltfJson,
        /// GLB: the header, the JSON chunk and the binary chunk.
        Glb,
        /// PLY, ASCII: header and body.
        PlyAscii,
        /// PLY, binary little-endian: header and body.
        PlyBinary,
        /// STL, ASCII.
        StlAscii,
        /// STL, binary.
        StlBinary,
    }

    impl Parser {
        pub(super) const ALL: [Parser; 8] = [
            Parser::Obj,
            Parser::Mtl,
            Parser::GltfJson,
            Parser::Glb,
            Parser::PlyAscii,
            Parser::PlyBinary,
            Parser::StlAscii,
            Parser::StlBinary,
        ];

        /// The seed files: models, and for OBJ and MTL the material library each one reads.
        fn files(self) -> &'static [(&'static str, &'static str)] {
            match self {
                Parser::Obj | Parser::Mtl => &[("cube.obj", "cube.mtl"), ("lamp.obj", "lamp.mtl")],
                Parser::GltfJson => &[("two_nodes.gltf", ""), ("lamp.gltf", "")],
                Parser::Glb => &[("cube.glb", ""), ("checker.glb", "")],
                Parser::PlyAscii => &[("cube.ply", "")],
                Parser::PlyBinary => &[("cube_binary.ply", "")],
                Parser::StlAscii => &[("cube.stl", "")],
                Parser::StlBinary => &[("cube_binary.stl", "")],
            }
        }

        /// Whether the mutated file is text (mutated as text half of the time).
        fn text(self) -> bool {
            matches!(
                self,
                Parser::Obj | Parser::Mtl | Parser::GltfJson | Parser::PlyAscii | Parser::StlAscii
            )
        }
    }

    /// A seed model: its name, format, bytes, and its MTL's name and bytes (empty if none).
    struct Seed {
        name: &'static str,
        format: Format,
        bytes: Vec<u8>,
        mtl_name: &'static str,
        mtl: Vec<u8>,
    }

    fn seeds(parser: Parser) -> Vec<Seed> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models");
        let read = |n: &str| std::fs::read(dir.join(n)).unwrap();
        parser
            .files()
            .iter()
            .map(|&(name, mtl_name)| Seed {
                name,
                format: Format::of(Path::new(name)).unwrap(),
                bytes: read(name),
                mtl_name,
                mtl: if mtl_name.is_empty() {
                    Vec::new()
                } else {
                    read(mtl_name)
                },
            })
            .collect()
    }

    fn mtl() -> Vec<u8> {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/cube.mtl")).unwrap()
    }

    /// 32-bit values that break counts, lengths and offsets.
    const WORDS: [u32; 8] = [
        0,
        1,
        3,
        0x7fff_ffff,
        0x8000_0000,
        0xffff_ffff,
        0xffff,
        1 << 24,
    ];

    fn mutate_bytes(rng: &mut Rng, input: &[u8]) -> Vec<u8> {
        let mut b = input.to_vec();
        let pick = |rng: &mut Rng, n: usize| (rng.next_u64() % n.max(1) as u64) as usize;
        for _ in 0..1 + pick(rng, 3) {
            match pick(rng, 5) {
                0 if !b.is_empty() => {
                    let i = pick(rng, b.len());
                    b[i] ^= 1 << pick(rng, 8);
                }
                1 if b.len() >= 4 => {
                    let i = pick(rng, b.len() - 3) & !3;
                    b[i..i + 4].copy_from_slice(&WORDS[pick(rng, WORDS.len())].to_le_bytes());
                }
                2 if !b.is_empty() => {
                    let i = pick(rng, b.len());
                    let n = 1 + pick(rng, 16);
                    b.drain(i..(i + n).min(b.len()));
                }
                3 => b.truncate(pick(rng, b.len() + 1)),
                _ => {
                    let i = pick(rng, b.len() + 1);
                    b.insert(i, pick(rng, 256) as u8);
                }
            }
        }
        b.truncate(MAX_INPUT);
        b
    }

    /// Loads `bytes` as a model of `format` (the file `mtl_name` reads as `mtl`) and checks
    /// the outcome; panics on a finding. A model that loaded is rendered if `render`. Returns
    /// whether it loaded.
    fn check(
        name: &str,
        format: Format,
        bytes: &[u8],
        (mtl_name, mtl): (&str, &[u8]),
        render: bool,
    ) -> bool {
        let read = |p: &str| {
            if p == mtl_name {
                Ok((mtl_name.to_string(), mtl.to_vec()))
            } else {
                Err(format!("cannot read {p}: no such file"))
            }
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let loaded = model::parse(format, bytes, name, &read)
                .and_then(|m| m.into_scene(name, "fuzz", &View::default()));
            if let (Ok(l), true) = (&loaded, render) {
                let s = &l.scene;
                let settings = Stage::Indirect.settings(s.effects());
                let frame = s.render(&Options {
                    width: 6,
                    height: 4,
                    settings: Some(settings),
                    ..Options::default()
                });
                assert!(frame.image.pixels.iter().all(|p| p.is_finite()));
            }
            loaded
        }));
        let result = outcome.unwrap_or_else(|_| {
            panic!(
                "panic on {name}:\n{:?}\nmtl:\n{:?}",
                String::from_utf8_lossy(bytes),
                String::from_utf8_lossy(mtl)
            )
        });
        match result {
            Ok(_) => true,
            Err(e) => {
                assert!(!e.message.is_empty() && !e.file.is_empty(), "{e}");
                let shown = e.to_string();
                assert!(shown.starts_with(&e.file), "{shown}");
                assert!(
                    !shown.chars().any(|c| c.is_control() && c != '\n'),
                    "{shown:?}"
                );
                false
            }
        }
    }

    /// Feeds `parser` `iterations` mutated inputs from `seed`, rendering one loaded model in
    /// `render_every`; returns how many loaded and how many were refused.
    pub(super) fn run(parser: Parser, iterations: u64, seed: u64, render_every: u64) -> (u64, u64) {
        let seeds = seeds(parser);
        let mut rng = Rng::seeded(seed);
        let (mut loaded, mut refused) = (0, 0);
        for i in 0..iterations {
            let s = &seeds[(i % seeds.len() as u64) as usize];
            let mutated = |rng: &mut Rng, b: &[u8]| {
                if parser.text() && rng.next_u64().is_multiple_of(2) {
                    super::mutate(rng, &String::from_utf8_lossy(b)).into_bytes()
                } else {
                    mutate_bytes(rng, b)
                }
            };
            let (bytes, mtl) = match parser {
                Parser::Mtl => (s.bytes.clone(), mutated(&mut rng, &s.mtl)),
                _ => (mutated(&mut rng, &s.bytes), s.mtl.clone()),
            };
            let render = i.is_multiple_of(render_every);
            if check(s.name, s.format, &bytes, (s.mtl_name, &mtl), render) {
                loaded += 1;
            } else {
                refused += 1;
            }
        }
        (loaded, refused)
    }

    #[test]
    fn every_seed_model_loads() {
        for parser in Parser::ALL {
            for s in seeds(parser) {
                let mtl = (s.mtl_name, s.mtl.as_slice());
                assert!(check(s.name, s.format, &s.bytes, mtl, true), "{}", s.name);
            }
        }
    }

    /// `tests/fuzz_corpus/models/`: hostile model files, each refused (`ok_*` must load).
    #[test]
    fn model_corpus() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus/models");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let Some(format) = Format::of(&path) else {
                continue;
            };
            n += 1;
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = std::fs::read(&path).unwrap();
            let loaded = check(&name, format, &bytes, ("cube.mtl", &mtl()), true);
            assert_eq!(loaded, name.starts_with("ok_"), "{name}");
        }
        assert!(n >= 8, "the corpus has {n} model files");
    }

    /// A short run in every `cargo test`: a hundred inputs a parser, each model that loads
    /// rendered.
    #[test]
    fn short_model_run() {
        for parser in Parser::ALL {
            let (loaded, refused) = run(parser, 100, 11, 1);
            assert_eq!(loaded + refused, 100);
            assert!(
                refused > 0,
                "{parser:?}: {loaded} loaded, {refused} refused"
            );
        }
    }
}

/// The long run: `RAYTTY_FUZZ_ITERATIONS` inputs (default a million) from `RAYTTY_FUZZ_SEED`
/// for each parser, the parsers in parallel threads: mutated scene files (with their OBJ
/// mesh), generated scene files, and each model parser on its own. Every loaded scene file
/// is rendered, and one loaded model in `RAYTTY_FUZZ_RENDER_EVERY` (default 100: the
/// render, not the parser, would take most of the time).
///
///     cargo test --release --test fuzz_scenes -- --ignored --nocapture
#[test]
#[ignore]
fn million_per_parser() {
    let var = |name: &str, default: u64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let (n, seed) = (
        var("RAYTTY_FUZZ_ITERATIONS", 1_000_000),
        var("RAYTTY_FUZZ_SEED", 1),
    );
    let render_every = var("RAYTTY_FUZZ_RENDER_EVERY", 100).max(1);
    let start = Instant::now();
    std::thread::scope(|scope| {
        scope.spawn(|| {
            let t = run(n, seed);
            eprintln!(
                "scene TOML: {} inputs from seed {seed} in {:.1?}: {} loaded, {} refused with a position; slowest input {:.1?}",
                t.inputs,
                start.elapsed(),
                t.loaded,
                t.errors,
                t.slowest
            );
            eprintln!("the slowest scene input:\n{}", t.slowest_input);
        });
        scope.spawn(|| {
            let (loaded, refused) = run_generated(n, seed);
            eprintln!(
                "generated scene TOML: {n} inputs from seed {seed} in {:.1?}: {loaded} loaded and {refused} refused, each as its values said",
                start.elapsed()
            );
        });
        for parser in models::Parser::ALL {
            scope.spawn(move || {
                let (loaded, refused) = models::run(parser, n, seed, render_every);
                eprintln!(
                    "{parser:?}: {n} inputs from seed {seed} in {:.1?}: {loaded} loaded, {refused} refused",
                    start.elapsed()
                );
            });
        }
    });
    eprintln!("all parsers: {:.1?}, no panic", start.elapsed());
}
