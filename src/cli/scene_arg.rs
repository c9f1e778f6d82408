//! `--scene PATH|NAME`: a scene file if the path exists or ends in `.toml`, else a built-in
//! scene's name. Every failure is a [`Failure::Usage`] (exit status 2) that says what would work.

use std::path::Path;

use raytty::scene::builtin::{self, BUILTINS};
use raytty::scene::file;
use raytty::{Scene, printable};

use crate::cli::{Failure, Result, usage};

/// The scene `arg` names; the Cornell box when there is none.
pub fn load_scene(arg: Option<&str>) -> Result<Scene> {
    let Some(arg) = arg else {
        return Ok(raytty::cornell_box());
    };
    let path = Path::new(arg);
    let builtins = || builtin::names().join(", ");
    if path.is_dir() {
        usage!(
            "--scene {}: is a folder: give the path of a .toml scene file (or a built-in scene: {})",
            printable(arg),
            builtins()
        );
    }
    if !path.exists() && arg.ends_with(".toml") {
        usage!(
            "--scene {}: no such file: give the path of an existing .toml scene file (or a built-in scene: {})",
            printable(arg),
            builtins()
        );
    }
    if arg.to_ascii_lowercase().ends_with(".obj") {
        usage!(
            "--scene {}: an OBJ mesh is not a scene: write a .toml scene with an [[object]] of kind = \"obj\" and path = \"{}\" (scenes/example.toml shows one)",
            printable(arg),
            printable(
                &path
                    .file_name()
                    .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
            )
        );
    }
    if path.exists() {
        return file::load(path).map_err(|e| Failure::Usage(e.to_string()));
    }
    match builtin::find(arg) {
        Some(b) => b.load().map_err(|e| Failure::Usage(e.to_string())),
        None => usage!(
            "--scene {}: no such file and no built-in scene of that name{} (built-in scenes: {}; or give the path of a .toml scene file)",
            printable(arg),
            file::did_you_mean(arg, &builtin::names()),
            builtins()
        ),
    }
}

/// `raytty scenes`: the built-in scenes, one a line, with their triangle counts.
pub fn list() -> String {
    let width = BUILTINS.iter().map(|b| b.name.len()).max().unwrap_or(0);
    let mut out = String::new();
    for b in &BUILTINS {
        out += &format!(
            "{:<width$}  {:>9} triangles  {}\n",
            b.name,
            group_thousands(b.triangles),
            b.description
        );
    }
    out
}

/// 1003530 → "1,003,530".
fn group_thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_are_grouped() {
        assert_eq!(group_thousands(30), "30");
        assert_eq!(group_thousands(1_003_530), "1,003,530");
        assert_eq!(group_thousands(100_000), "100,000");
    }
}
