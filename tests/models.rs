//! Model files (glTF, GLB, OBJ with MTL, PLY, STL): each small cube in `tests/models/` loads as
//! the same geometry, the glTF node transforms, cameras and lights are applied, a camera frames
//! a model without one, a model without lights gets the default rig (and says so), and bad
//! files and views are refused through the binary with exit status 2.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::Vec3;
use raytty::scene::model::{self, View};

fn path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/models")
        .join(name)
}

fn load(name: &str) -> model::Loaded {
    model::load(&path(name), &View::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The triangles as sorted vertex triples (rounded), so that formats compare as sets.
fn triangles(s: &raytty::Scene) -> Vec<[[i32; 3]; 3]> {
    let mut t: Vec<[[i32; 3]; 3]> = s
        .triangles()
        .iter()
        .map(|t| {
            let mut v =
                t.v.map(|p| (p * 1000.0).round().to_array().map(|x| x as i32));
            v.sort();
            v
        })
        .collect();
    t.sort();
    t
}

#[test]
fn every_format_gives_the_same_cube() {
    let reference = triangles(&load("cube.obj").scene);
    assert_eq!(reference.len(), 12);
    for name in ["cube.ply", "cube_binary.ply", "cube.stl", "cube_binary.stl"] {
        assert_eq!(triangles(&load(name).scene), reference, "{name}");
    }
}

#[test]
fn obj_materials_come_from_the_mtl() {
    let s = load("cube.obj").scene;
    let colours: Vec<Vec3> = s.materials().iter().map(|m| m.colour).collect();
    assert!(colours.contains(&Vec3::new(0.8, 0.1, 0.1)), "{colours:?}");
    assert!(colours.contains(&Vec3::splat(0.8)), "{colours:?}");
    // The first three faces (six triangles) are red.
    let red = s
        .triangles()
        .iter()
        .filter(|t| s.materials()[t.material as usize].colour.y < 0.5)
        .count();
    assert_eq!(red, 6);
}

#[test]
fn gltf_nodes_are_transformed() {
    let s = load("two_nodes.gltf").scene;
    assert_eq!(s.triangles().len(), 24);
    // The parent is raised by 0.5 and turned 45° about y; its child is half size, 1.5 along
    // the parent's x: its centre is at 0.5 + 1.5·(cos 45°, 0, −sin 45°).
    let centre = |ts: &[raytty::geometry::Triangle]| {
        ts.iter().flat_map(|t| t.v).sum::<Vec3>() / (3 * ts.len()) as f32
    };
    let parent = centre(&s.triangles()[..12]);
    let child = centre(&s.triangles()[12..]);
    assert!(
        (parent - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-5,
        "{parent}"
    );
    let h = std::f32::consts::FRAC_1_SQRT_2 * 1.5;
    assert!((child - Vec3::new(h, 0.5, -h)).length() < 1e-4, "{child}");
    // Vertex colours times the base colour factor (1, 0.9, 0.8) give materials of their own:
    // the +x faces' red is the factor's full 1 (the default material's grey would give 0.8).
    assert!(s.materials().len() > 1);
    let reddest = s
        .triangles()
        .iter()
        .map(|t| s.materials()[t.material as usize].colour.x);
    assert_eq!(reddest.fold(0.0, f32::max), 1.0);
}

/// The Khronos sample Box (CC BY 4.0, its licence beside it): a red cube turned from z-up.
#[test]
fn the_khronos_box_is_red() {
    let s = load("khronos-box/Box.gltf").scene;
    assert_eq!(s.triangles().len(), 12);
    for t in s.triangles() {
        let c = s.materials()[t.material as usize].colour;
        assert!((c - Vec3::new(0.8, 0.0, 0.0)).length() < 1e-6, "{c}");
    }
}

#[test]
fn a_glb_camera_and_light_are_used() {
    let l = load("cube.glb");
    let s = &l.scene;
    let c = s.camera();
    assert_eq!(c.position, Vec3::new(0.5, 1.0, 4.0));
    assert!((c.forward() + Vec3::Z).length() < 1e-6);
    assert_eq!(c.fov, Some(0.7));
    assert!(!s.lights_are_default());
    assert_eq!(s.lights().len(), 1);
    assert_eq!(s.lights()[0].position, Vec3::new(1.0, 3.0, 2.0));
    assert!((s.lights()[0].power.x - 5.0 * 4.0 * std::f32::consts::PI).abs() < 1e-4);
}

#[test]
fn a_model_without_camera_or_light_is_framed_and_lit() {
    let s = load("cube.stl").scene;
    assert!(s.lights_are_default());
    let c = s.camera();
    // Looking at the centre from front-right and above, far enough to see all of it.
    let to_centre = (-c.position).normalize();
    assert!((c.forward() - to_centre).length() < 1e-5);
    assert!(c.position.x > 0.0 && c.position.y > 0.0 && c.position.z > 0.0);
    let half = c.fov.unwrap() * 0.5;
    assert!(c.position.length() * half.sin() > 3f32.sqrt() * 0.5);
    // The key light is above the model (+y is up) and lights it.
    assert!(s.lights()[0].position.y > 0.5);
    let view = View {
        look_from: Some(Vec3::new(0.0, 0.0, 5.0)),
        fov_degrees: Some(30.0),
        ..View::default()
    };
    let s = model::load(&path("cube.stl"), &view).unwrap().scene;
    assert_eq!(s.camera().position, Vec3::new(0.0, 0.0, 5.0));
    assert!((s.camera().forward() + Vec3::Z).length() < 1e-6);
    assert_eq!(s.camera().fov, Some(30f32.to_radians()));
}

fn raytty(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raytty"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

#[test]
fn every_command_takes_a_model() {
    let out = raytty(&[
        "render",
        "--scene",
        "tests/models/cube.glb",
        "--size",
        "20x10",
        "--stats",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = raytty(&[
        "tests/models/cube.ply",
        "--look-from",
        "2,2,2",
        "--fov",
        "40",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.stdout.is_empty());
    let out = raytty(&[
        "render",
        "--scene",
        "tests/models/cube.stl",
        "--stats",
        "--size",
        "8x4",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("lights: default"), "{err}");
}

#[test]
fn bad_files_and_views_are_refused() {
    for (args, needle) in [
        (
            &[
                "render",
                "--scene",
                "tests/fuzz_corpus/models/required_extension.gltf",
            ][..],
            "requires extension `KHR_draco_mesh_compression`",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/fuzz_corpus/models/index_out_of_range.ply",
            ],
            "index_out_of_range.ply:13:7: face 0: vertex index 3 is out of range",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/fuzz_corpus/models/count_mismatch.stl",
            ],
            "byte 80: the header says 2147483647 triangles",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/fuzz_corpus/models/accessor_past_buffer.gltf",
            ],
            "/meshes/0/primitives/0: /accessors/0: 1000 elements",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/models/cube.glb",
                "--camera-index",
                "1",
            ],
            "--camera-index 1: the file has 1 camera(s), 0 to 0",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/models/cube.obj",
                "--look-from",
                "1,1,1",
                "--look-at",
                "1,1,1",
            ],
            "--look-from and --look-at are the same point",
        ),
        (
            &["render", "--fov", "0"],
            "--fov 0: expected a vertical field of view",
        ),
        (
            &[
                "render",
                "--scene",
                "tests/fuzz_corpus/models/bad_texture_index.obj",
            ],
            "bad_texture_index.obj:5:7: texture coordinate index 2 is out of range",
        ),
    ] {
        let out = raytty(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

/// `lamp.gltf` and its twin `lamp.obj` + `lamp.mtl` (written by `make_lamp_twins.py`): a floor,
/// a red wall, a gold metal block and a ceiling panel that emits. The files' materials map onto
/// the same scene materials (metal, roughness, emission), the emitting panel stands for the
/// light (no default rig), light is path traced, and the two render the same to the bit.
#[test]
fn a_gltf_lamp_and_its_obj_twin_render_alike() {
    let (gltf, obj) = (load("lamp.gltf").scene, load("lamp.obj").scene);
    assert_eq!(triangles(&gltf), triangles(&obj));
    for s in [&gltf, &obj] {
        let m = s.materials();
        let gold = m.iter().find(|m| m.metal > 0.0).expect("a metal material");
        assert_eq!((gold.metal, gold.roughness), (1.0, 0.3));
        assert_eq!(gold.colour, Vec3::new(0.9, 0.7, 0.4));
        let panel = m
            .iter()
            .find(|m| m.emission != Vec3::ZERO)
            .expect("an emitter");
        assert_eq!(panel.emission, Vec3::new(5.0, 4.5, 4.0));
        assert!(
            m.iter()
                .filter(|m| m.emission == Vec3::ZERO && m.metal == 0.0)
                .all(|m| m.roughness == 0.0 && m.transmission == 0.0)
        );
        assert!(s.lights().is_empty() && !s.lights_are_default());
        assert!(s.area_lights().is_some());
    }
    let options = raytty::Options {
        width: 48,
        height: 36,
        ..Default::default()
    };
    let (a, b) = (gltf.render(&options), obj.render(&options));
    assert_eq!(a.image.pixels, b.image.pixels);
    assert!(
        a.stats.rays.shadow > 0 && a.stats.rays.bounce > 0,
        "{:?}",
        a.stats.rays
    );
    let lit = a
        .image
        .pixels
        .iter()
        .filter(|p| p.max_element() > 0.005)
        .count();
    assert!(lit > a.image.pixels.len() / 8, "only {lit} pixels lit");
}
