//! The built-in scenes and scene files, seen through what a frame costs: each scene calls for
//! different effects, and the frame stats show only those being simulated.

use raytty::scene::builtin::{self, BUILTINS};
use raytty::scene::file;
use raytty::{FrameStats, Options, Scene, Stage};

fn load(name: &str) -> Scene {
    builtin::find(name).unwrap().load().unwrap()
}

/// The stats of one frame at the scene's own effects (the default stage).
fn stats(scene: &Scene, lights: &[raytty::PointLight]) -> FrameStats {
    let settings = Stage::Indirect.settings(scene.effects());
    scene
        .render(&Options {
            width: 64,
            height: 48,
            settings: Some(settings),
            lights: Some(lights),
            ..Options::default()
        })
        .stats
}

#[test]
fn scenes_without_mirrors_trace_no_reflection_rays() {
    for name in ["cornell", "lights"] {
        let scene = load(name);
        assert!(!scene.has_mirrors());
        let s = stats(&scene, scene.lights());
        assert_eq!(s.rays.reflection, 0, "{name}");
        assert!(s.rays.shadow > 0, "{name}");
    }
}

#[test]
fn the_mirror_scene_traces_reflection_rays() {
    let scene = load("mirror");
    assert!(scene.has_mirrors());
    let s = stats(&scene, scene.lights());
    // The tall block covers a good part of the view: about 190 of the 3072 pixels.
    assert!(s.rays.reflection > 100, "{:?}", s.rays);
}

#[test]
fn the_lights_scene_traces_shadow_rays_per_light() {
    let scene = load("lights");
    assert_eq!(scene.lights().len(), 3);
    let all = stats(&scene, scene.lights());
    // Each light's shadow rays are decided on their own: the three lights together trace
    // exactly what each one traces alone, summed.
    let alone: u64 = scene
        .lights()
        .iter()
        .map(|l| stats(&scene, std::slice::from_ref(l)).rays.shadow)
        .sum();
    assert_eq!(all.rays.shadow, alone);
    // Nearly every visible point faces all three lights: close to 3 per pixel that shows the
    // scene (the 64×48 view is wider than the box: some pixels see nothing).
    let rays = scene.camera().rays(64, 48);
    let hits = (0..48)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let ray = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            scene.intersect(&ray, f32::INFINITY).is_some()
        })
        .count();
    let per_pixel = all.rays.shadow as f64 / hits as f64;
    assert!(
        (2.7..=3.0).contains(&per_pixel),
        "{per_pixel} shadow rays per lit pixel"
    );
}

#[test]
fn the_example_file_loads_with_every_kind_of_object() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/example.toml");
    let scene = file::load(std::path::Path::new(path)).unwrap();
    // Two floor triangles, two boxes, the tetrahedron, and a k = 8 icosphere.
    assert_eq!(scene.triangles().len(), 2 + 12 + 12 + 4 + 20 * 64);
    assert_eq!(scene.name(), "example");
    assert_eq!(scene.lights().len(), 2);
    assert!(scene.has_mirrors());
    let s = stats(&scene, scene.lights());
    assert!(s.rays.reflection > 0);
}

#[test]
fn transforms_scale_then_rotate_then_translate() {
    let scene = file::parse(
        "[material.m]\ncolour = [0.5, 0.5, 0.5]\n[[object]]\nkind = \"box\"\nmaterial = \"m\"\nmin = [0, 0, 0]\nmax = [1, 1, 2]\nscale = 2\nrotate_y = 90\ntranslate = [10, 0, 0]\n",
        "t.toml",
        "t",
        &file::no_meshes,
    )
    .unwrap();
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    for v in scene.triangles().iter().flat_map(|t| t.v) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    // Scaled to 2×2×4; a quarter turn takes +z to +x; then moved 10 along x.
    let close = |a: glam::Vec3, b: glam::Vec3| (a - b).abs().max_element() < 1e-5;
    assert!(close(lo, glam::Vec3::new(10.0, 0.0, -2.0)), "{lo}");
    assert!(close(hi, glam::Vec3::new(14.0, 2.0, 0.0)), "{hi}");
    assert_eq!(scene.name(), "t");
}

#[test]
fn the_scene_name_comes_from_the_file_and_keeps_its_characters() {
    let scene = file::parse(
        "name = \"box\\u001b[2J\"\n[material.m]\ncolour = [1, 1, 1]\n[[object]]\nkind = \"box\"\nmaterial = \"m\"\ncentre = [0, 0, 0]\nsize = [1, 1, 1]\n",
        "n.toml",
        "n",
        &file::no_meshes,
    )
    .unwrap();
    // The scene keeps the name as written; the app shows it through `printable`.
    assert_eq!(scene.name(), "box\x1b[2J");
    assert_eq!(raytty::printable(scene.name()), "box[2J");
}

/// The million-triangle scene loads (the mesh generated, the BVH built) and renders: it is the
/// one built-in that needs the BVH, a second or two in all.
#[test]
fn the_large_mesh_scene_loads_and_renders() {
    let b = builtin::find("sphere").unwrap();
    let scene = b.load().unwrap();
    assert_eq!(scene.triangles().len(), b.triangles);
    assert!(scene.triangles().len() > 1_000_000);
    let s = stats(&scene, scene.lights());
    assert_eq!(s.rays.primary, 64 * 48);
    assert_eq!(s.rays.reflection, 0);
    assert!(s.rays.shadow > 0);
}

#[test]
fn the_command_line_lists_scenes_and_takes_a_name_or_a_file() {
    let raytty = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_raytty"))
            .args(args)
            .output()
            .unwrap()
    };
    let out = raytty(&["scenes"]);
    assert!(out.status.success());
    let list = String::from_utf8(out.stdout).unwrap();
    for b in &BUILTINS {
        assert!(
            list.lines()
                .any(|l| l.starts_with(b.name) && l.contains(b.description))
        );
    }
    assert!(list.contains("1,003,530 triangles"), "{list}");
    // The bare command (stdout is not a terminal: one frame) and `render` both take --scene,
    // before or after the subcommand; a built-in name and its file give the same frame.
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/mirror.toml");
    let a = raytty(&["--color", "ascii", "--scene", "mirror"]);
    let b = raytty(&["render", "--format", "ascii", "--scene", file]);
    let c = raytty(&["--scene", "mirror", "render", "--format", "ascii"]);
    let d = raytty(&["render", "--format", "ascii"]);
    assert!(a.status.success() && b.status.success() && c.status.success());
    assert_eq!(a.stdout, b.stdout);
    assert_eq!(b.stdout, c.stdout);
    assert_ne!(
        a.stdout, d.stdout,
        "the mirror scene looks like the Cornell box"
    );
}

#[test]
fn a_camera_in_a_file_is_the_same_camera_as_on_the_command_line() {
    let dir = std::env::temp_dir().join(format!("raytty-scenes-camera-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("turned.toml");
    let source = builtin::find("cornell").unwrap().source.replace(
        "position = [0, 0, -3]\nyaw = 0",
        "position = [0.3, -0.1, -2.5]\nyaw = 15",
    );
    std::fs::write(&file, source).unwrap();
    let raytty = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_raytty"))
            .args(["render", "--format", "pfm", "--pixels", "40x30"])
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let from_file = raytty(&["--scene", file.to_str().unwrap()]);
    let from_flag = raytty(&["--camera", "0.3,-0.1,-2.5,15"]);
    assert_eq!(from_file, from_flag, "the two cameras differ");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_sky_and_spots_files_load_with_their_lights() {
    let load = |name: &str| {
        let path = format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
        file::load(std::path::Path::new(&path)).unwrap()
    };
    let sky = load("sky.toml");
    assert_eq!(sky.directional_lights().len(), 1);
    assert_eq!(sky.environment(), glam::Vec3::new(0.25, 0.3, 0.4));
    let spots = load("spots.toml");
    assert_eq!((spots.spot_lights().len(), spots.lights().len()), (2, 1));
    let s = stats(&spots, spots.lights());
    assert_eq!(s.effect_names(), ["spot lights"]);
}
