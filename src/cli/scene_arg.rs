//! `--scene PATH|NAME` (or `raytty FILE`): a model file (`.gltf`, `.glb`, `.obj`, `.ply`,
//! `.stl`), a scene file if the path exists or ends in `.toml`, else a built-in scene's name;
//! then the view flags (`--look-from`, `--look-at`, `--up`, `--fov`, `--camera-index`) over its
//! camera. Every failure is a [`Failure::Usage`] (exit status 2) that says what would work.

use std::path::Path;

use raytty::scene::builtin::{self, BUILTINS};
use raytty::scene::file;
use raytty::scene::model::{self, Format, View};
use raytty::{Scene, printable};

use crate::cli::loading::Watch;
use crate::cli::{Failure, Result, usage};

/// The scene `arg` names (the Cornell box when there is none), seen through `view`. A model's
/// notes (what the file has that is not drawn) go to stderr, one line each. A model's load is
/// watched (a progress bar, Ctrl-C): the [`Watch`] keeps watching the signals until dropped.
pub fn load_scene(arg: Option<&str>, view: &View) -> Result<(Scene, Option<Watch>)> {
    let mut watch = None;
    let scene = find_scene(arg, view, &mut watch)?;
    if Format::of(Path::new(arg.unwrap_or_default())).is_some() {
        return Ok((scene, watch));
    }
    let camera = view
        .apply(scene.camera())
        .map_err(|e| Failure::Usage(e.to_string()))?;
    Ok((scene.with_camera(camera), watch))
}

fn find_scene(arg: Option<&str>, view: &View, watch: &mut Option<Watch>) -> Result<Scene> {
    let Some(arg) = arg else {
        return Ok(raytty::cornell_box());
    };
    let path = Path::new(arg);
    let builtins = || builtin::names().join(", ");
    if path.is_dir() {
        usage!(
            "--scene {}: is a folder: give the path of a model (.gltf, .glb, .obj, .ply, .stl) or a .toml scene file (or a built-in scene: {})",
            printable(arg),
            builtins()
        );
    }
    if !path.exists() && (arg.ends_with(".toml") || Format::of(path).is_some()) {
        usage!(
            "--scene {}: no such file: give the path of an existing model (.gltf, .glb, .obj, .ply, .stl) or .toml scene file (or a built-in scene: {})",
            printable(arg),
            builtins()
        );
    }
    if Format::of(path).is_some() {
        let name = path
            .file_name()
            .map_or_else(|| printable(arg), |n| printable(&n.to_string_lossy()));
        let w = watch.insert(Watch::start(&name));
        let loaded = model::load_with(path, view, w.progress());
        w.loaded();
        let loaded = loaded.map_err(|e| Failure::Usage(e.to_string()))?;
        for note in &loaded.notes {
            eprintln!("raytty: {}: {}", printable(arg), printable(note));
        }
        return Ok(loaded.scene);
    }
    if path.exists() {
        return file::load(path).map_err(|e| Failure::Usage(e.to_string()));
    }
    match builtin::find(arg) {
        Some(b) => b.load().map_err(|e| Failure::Usage(e.to_string())),
        None => usage!(
            "--scene {}: no such file and no built-in scene of that name{} (built-in scenes: {}; or give the path of a model or a .toml scene file)",
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
