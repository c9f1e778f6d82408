//! Layers point down: a module of the library uses only modules of its own layer or below
//! (ARCHITECTURE.md, "Invariants"). Reads every `src/` file's `use crate::…` and `crate::…::`
//! paths outside comments and `#[cfg(test)]` modules, and fails on one that points up, naming
//! the file, the line and both layers. The binary (`main.rs`, `cli/`, `tui/`) sits on top and
//! reaches the library as `raytty::`, so it is not read.

use std::fs;
use std::path::{Path, PathBuf};

/// The library's top-level modules, lowest layer first; modules on one line share a layer and
/// may use each other.
const LAYERS: &[&[&str]] = &[
    &["text", "simd", "geometry", "rng", "image"],
    &["sampler", "camera"],
    &["accel"],
    &["light"],
    &["scene"],
    &["material"],
    &["shading"],
    &["denoise"],
    &["render"],
    &["frame"],
    &["bench"],
];

/// Known exceptions, each until the change named: (module, what it uses).
const NOT_YET: &[(&str, &str)] = &[];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The files of `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`src/accel/bvh.rs` → `accel`).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_str()
        .unwrap();
    first.trim_end_matches(".rs").to_string()
}

/// The modules that the non-test code of `text` names as `crate::MODULE`, with their lines.
fn uses(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    let mut in_tests = false;
    let mut test_depth = 0i32;
    let mut depth = 0i32;
    let mut next_is_test = false;
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap();
        if line.trim_start().starts_with("#[cfg(test)]") {
            next_is_test = true;
            continue;
        }
        if next_is_test && !in_tests && code.contains('{') {
            in_tests = true;
            test_depth = depth;
        }
        if !code.trim().is_empty() && !code.trim_start().starts_with("#[") {
            next_is_test = false;
        }
        if !in_tests {
            let mut rest = code;
            while let Some(at) = rest.find("crate::") {
                let after = &rest[at + "crate::".len()..];
                let name: String = after
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    found.push((i + 1, name));
                }
                rest = after;
            }
        }
        depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
        if in_tests && depth <= test_depth {
            in_tests = false;
        }
    }
    found
}

#[test]
fn layers_point_down() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let binary = ["main", "cli", "tui", "lib"];
    let mut wrong = Vec::new();
    for file in &files {
        let module = module_of(&src, file);
        if binary.contains(&module.as_str()) || file.file_name().unwrap() == "tests.rs" {
            continue;
        }
        let Some(own) = layer_of(&module) else {
            wrong.push(format!(
                "{}: module `{module}` has no layer: add it to LAYERS in tests/layers.rs and ARCHITECTURE.md",
                file.display()
            ));
            continue;
        };
        for (line, used) in uses(&fs::read_to_string(file).unwrap()) {
            // Items re-exported at the crate root (`crate::Scene`) are not modules.
            if used.chars().next().is_some_and(|c| c.is_uppercase()) || used == module {
                continue;
            }
            match layer_of(&used) {
                Some(l) if l <= own => {}
                Some(_) if NOT_YET.contains(&(module.as_str(), used.as_str())) => {}
                Some(l) => wrong.push(format!(
                    "{}:{line}: `{module}` (layer {own}) uses `{used}` (layer {l}): layers point down",
                    file.display()
                )),
                None => {}
            }
        }
    }
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}

/// The reader itself: a use in a test module is skipped, one outside is seen.
#[test]
fn the_reader_skips_test_modules_only() {
    let text = "use crate::scene::Scene;\n\
                // use crate::bench::x;\n\
                #[cfg(test)]\n\
                mod tests {\n    use crate::render::x;\n    fn f() { crate::bench::y(); }\n}\n\
                fn g() { crate::frame::z(); }\n";
    let names = uses(text);
    assert_eq!(
        names,
        vec![(1, "scene".to_string()), (8, "frame".to_string())]
    );
}
