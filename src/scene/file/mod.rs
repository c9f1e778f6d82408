//! Scene files: a TOML description of a camera, lights, materials, geometry and effects, read
//! with serde and checked value by value, so that every mistake comes back as a
//! [`SceneFileError`] naming the file, line and column, what was wrong and what would be right.
//! `scenes/example.toml` documents every key.
//!
//! A file that loads is a valid [`Scene`]: it goes through [`crate::SceneBuilder`], and everything
//! the builder would reject (degenerate triangles, bad lights) is caught first, here, with a
//! line.

mod build;
mod check;
mod error;
mod objects;
mod spec;

use std::io::Read;
use std::path::Path;

pub use error::{SceneFileError, did_you_mean, line_column, suggest};

use crate::scene::Scene;

/// Most triangles a scene may have, meshes included (about 200 MB of triangles and BVH).
pub const MAX_TRIANGLES: usize = 2_000_000;
/// Most vertices an OBJ mesh may define.
pub const MAX_MESH_VERTICES: usize = 3 * MAX_TRIANGLES;
/// Most point lights (each one costs a shadow ray per shaded point).
pub const MAX_LIGHTS: usize = 16;
/// Largest light power per channel.
pub const MAX_POWER: f64 = 1e12;
/// Largest emission per channel (in the image's units: 1 is a white a camera sees as 1).
pub const MAX_EMISSION: f64 = 1e6;
/// Largest samples per pixel.
pub const MAX_SAMPLES: i64 = 1024;
/// Largest number of path-traced bounces.
pub const MAX_BOUNCES: i64 = 16;
/// Largest constant indirect term N.
pub const MAX_CONSTANT: f64 = 100.0;
/// Largest icosphere subdivision: 20·316² = 1,996,480 triangles, just under [`MAX_TRIANGLES`].
pub const MAX_SUBDIVISIONS: i64 = 316;
/// Largest icosphere displacement amplitude (relative to its radius), so the surface never
/// folds through its centre.
pub const MAX_AMPLITUDE: f64 = 0.5;
/// Largest uniform or per-axis scale, and the smallest (a scale must be positive).
pub const SCALE_RANGE: (f64, f64) = (1e-6, 1e6);
/// Largest scene file read.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// Largest OBJ file read (a 2M-triangle mesh is about 100 MB of text).
pub const MAX_MESH_BYTES: u64 = 512 << 20;

/// Reads a mesh named in a scene file: given the path as written, returns the name to show in
/// messages and the bytes, or a message saying why it cannot be read.
pub type MeshReader<'a> = &'a dyn Fn(&str) -> Result<(String, Vec<u8>), String>;

/// Loads a scene file from disk. Meshes are read relative to the file's folder. The scene is
/// named by the file's `name` key, or else by the file's stem.
pub fn load(path: &Path) -> Result<Scene, SceneFileError> {
    let shown = path.display().to_string();
    let bytes = read_capped(path, MAX_SCENE_BYTES)
        .map_err(|e| SceneFileError::whole_file(&shown, format!("the scene file {e}")))?;
    let source = String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes());
        SceneFileError::at(
            &shown,
            &text,
            offset,
            "the file is not valid UTF-8 text: save it as UTF-8",
        )
    })?;
    let base = path.parent().unwrap_or(Path::new(""));
    let read_mesh = |p: &str| {
        let full = base.join(p);
        let bytes =
            read_capped(&full, MAX_MESH_BYTES).map_err(|e| format!("{} {e}", full.display()))?;
        Ok((full.display().to_string(), bytes))
    };
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| shown.clone());
    parse(&source, &shown, &stem, &read_mesh)
}

/// Parses and builds a scene from `source`. `file` names it in messages, `name` is the scene's
/// name unless the file sets one, and `read_mesh` reads the OBJ files it names.
pub fn parse(
    source: &str,
    file: &str,
    name: &str,
    read_mesh: MeshReader,
) -> Result<Scene, SceneFileError> {
    // A byte order mark (Windows editors write one) is not part of the first line.
    let source = source.strip_prefix('\u{FEFF}').unwrap_or(source);
    build::build(source, file, name, read_mesh)
}

/// A `read_mesh` for scenes that may not name mesh files (the built-in ones).
pub fn no_meshes(path: &str) -> Result<(String, Vec<u8>), String> {
    Err(format!(
        "`{path}`: this scene cannot read mesh files (only a scene loaded from a file can)"
    ))
}

/// Reads at most `limit` bytes of `path`. The error completes a sentence that starts with
/// what the file is: "cannot be read: ..." or "is larger than ...".
fn read_capped(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let unreadable = |e: std::io::Error| format!("cannot be read: {e}");
    let file = std::fs::File::open(path).map_err(unreadable)?;
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > limit {
        return Err(format!("is larger than {} MiB, the limit", limit >> 20));
    }
    Ok(bytes)
}
