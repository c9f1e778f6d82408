//! The built-in scenes: scene files embedded in the binary (`scenes/*.toml`), each calling for
//! different effects.

use crate::scene::Scene;
use crate::scene::file::{self, SceneFileError};

/// A scene that ships with raytty.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// The name `--scene` takes.
    pub name: &'static str,
    /// One line: what it shows.
    pub description: &'static str,
    /// How many triangles it has (checked by a test).
    pub triangles: usize,
    /// The scene file's text.
    pub source: &'static str,
}

/// All built-in scenes; the first is the default.
pub const BUILTINS: [Builtin; 7] = [
    Builtin {
        name: "cornell",
        description: "the seed's Cornell box: one light, no mirrors (the default)",
        triangles: 30,
        source: include_str!("../../scenes/cornell.toml"),
    },
    Builtin {
        name: "mirror",
        description: "the Cornell box with a mirror for its tall block: reflection rays",
        triangles: 30,
        source: include_str!("../../scenes/mirror.toml"),
    },
    Builtin {
        name: "lights",
        description: "a white Cornell box lit by red, green and blue lights: a shadow ray per light",
        triangles: 30,
        source: include_str!("../../scenes/lights.toml"),
    },
    Builtin {
        name: "sphere",
        description: "a displaced icosphere of 1,003,520 triangles in the Cornell room",
        triangles: 1_003_530,
        source: include_str!("../../scenes/sphere.toml"),
    },
    Builtin {
        name: "area",
        description: "the Cornell box lit by a square area light in the ceiling: soft shadows",
        triangles: 32,
        source: include_str!("../../scenes/area.toml"),
    },
    Builtin {
        name: "glass",
        description: "a smooth glass ball and a frosted glass block under an area light: refraction",
        triangles: 2904,
        source: include_str!("../../scenes/glass.toml"),
    },
    Builtin {
        name: "plates",
        description: "metal plates of four roughnesses under four lights of four sizes (after Veach): MIS",
        triangles: 732,
        source: include_str!("../../scenes/plates.toml"),
    },
];

/// The built-in scene called `name`.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The names of the built-in scenes, in order.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|b| b.name).collect()
}

impl Builtin {
    /// Builds the scene (the large ones generate their meshes here).
    pub fn load(&self) -> Result<Scene, SceneFileError> {
        file::parse(
            self.source,
            &format!("{}.toml (built in)", self.name),
            self.name,
            &file::no_meshes,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cornell_box;

    #[test]
    fn cornell_file_is_the_built_in_box_bit_for_bit() {
        let from_file = find("cornell").unwrap().load().unwrap();
        // Debug prints every f32 in its shortest round-trip form (and -0 as -0), and includes
        // the acceleration structure: equal text is equal bits.
        assert_eq!(format!("{from_file:?}"), format!("{:?}", cornell_box()));
    }

    #[test]
    fn small_built_ins_load_with_their_stated_triangle_counts() {
        for b in BUILTINS.iter().filter(|b| b.triangles < 10_000) {
            let scene = b.load().unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert_eq!(scene.triangles.len(), b.triangles, "{}", b.name);
            assert_eq!(scene.name, b.name);
        }
        assert_eq!(names()[0], "cornell");
    }
}
