//! What a model's vertices carry, drawn: base-colour textures (glTF's `baseColorTexture`, PNG
//! by file name and JPEG in a buffer view; OBJ's `vt` with MTL's `map_Kd`), vertex colours
//! (PLY's), and vertex normals as shading normals. A texture that cannot be read is a warning
//! and the material's own colour. The checker models are written by
//! `tests/models/make_texture_twins.py`.

use std::path::{Path, PathBuf};

use glam::Vec3;
use raytty::accel::Isa;
use raytty::scene::model::{self, View};
use raytty::{Options, Scene, Stage};

fn path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/models")
        .join(name)
}

/// Seen head-on from +z, 3 units away: the square from (-1, -1) to (1, 1) fills the middle
/// 80 % of a square frame.
fn front_view() -> View {
    View {
        look_from: Some(Vec3::new(0.0, 0.0, 3.0)),
        look_at: Some(Vec3::ZERO),
        fov_degrees: Some(45.0),
        ..View::default()
    }
}

fn load_at(path: &Path) -> model::Loaded {
    model::load(path, &front_view()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The frame of `stage` at `size` × `size` pixels.
fn render(scene: &Scene, stage: Stage, size: u32) -> raytty::Image {
    scene
        .render(&Options {
            width: size,
            height: size,
            settings: Some(stage.settings(scene.effects())),
            ..Options::default()
        })
        .image
}

/// The pixel of a 64-pixel frame where the square's point (x, y) is seen.
fn at(image: &raytty::Image, x: f32, y: f32) -> Vec3 {
    // Half the frame's height is 3·tan(22.5°) units.
    let half = 3.0 * (22.5f32).to_radians().tan();
    let col = ((x / half + 1.0) * 0.5 * image.width as f32) as u32;
    let row = ((1.0 - y / half) * 0.5 * image.height as f32) as u32;
    image.pixels[(row * image.width + col) as usize]
}

fn near(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// The quarters' centres (texel centres of the 2x2 texture) show its texels: red and green on
/// top, blue and white below, in the flat stage (the base colour alone, linear). The PNG by
/// file name (glTF and OBJ) and the JPEG in a buffer view agree; the OBJ twin gives the
/// glTF's frame to the bit, lit and shaded.
#[test]
fn a_checker_texture_shows_its_colours_in_its_quarters() {
    let quarters = [
        (-0.5, 0.5, Vec3::X),
        (0.5, 0.5, Vec3::Y),
        (-0.5, -0.5, Vec3::Z),
        (0.5, -0.5, Vec3::ONE),
    ];
    for (name, tolerance) in [
        ("checker.gltf", 0.05),
        ("checker.obj", 0.05),
        ("checker_jpeg.gltf", 0.05),
    ] {
        let loaded = load_at(&path(name));
        assert!(loaded.notes.is_empty(), "{name}: {:?}", loaded.notes);
        assert!(loaded.scene.colour_varies(), "{name}");
        let image = render(&loaded.scene, Stage::Flat, 64);
        for (x, y, want) in quarters {
            let got = at(&image, x, y);
            assert!(
                near(got, want, tolerance),
                "{name} at ({x}, {y}): {got}, want {want}"
            );
        }
        // Across the middle the texture is blended (bilinear), not one texel.
        let middle = at(&image, 0.0, 0.5);
        assert!(middle.x > 0.2 && middle.y > 0.2, "{name}: {middle}");
    }
    let (gltf, obj) = (
        load_at(&path("checker.gltf")).scene,
        load_at(&path("checker.obj")).scene,
    );
    for stage in [Stage::Flat, Stage::Indirect] {
        assert_eq!(
            render(&gltf, stage, 48).pixels,
            render(&obj, stage, 48).pixels,
            "{stage:?}"
        );
    }
}

/// A folder of its own for a test's files.
fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raytty-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `checker.gltf` with its image and base colour factor replaced.
fn checker_with(image: &str, factor: [f32; 3]) -> String {
    let text = std::fs::read_to_string(path("checker.gltf")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["images"][0]["uri"] = image.into();
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] =
        serde_json::json!([factor[0], factor[1], factor[2], 1.0]);
    doc.to_string()
}

/// A texture file that is missing, or is not an image, is a warning naming the texture and
/// why; the material's base colour factor is drawn instead (glTF), or its `Kd` (OBJ).
#[test]
fn a_texture_that_cannot_be_read_is_a_warning_and_the_factor_is_drawn() {
    let dir = folder("missing-texture");
    std::fs::write(dir.join("garbage.png"), b"not an image at all").unwrap();
    let factor = [0.25, 0.5, 0.75];
    for (image, why) in [
        ("missing.png", "cannot be read"),
        ("garbage.png", "not a PNG or JPEG"),
    ] {
        let file = dir.join(format!("{image}.gltf"));
        std::fs::write(&file, checker_with(image, factor)).unwrap();
        let loaded = load_at(&file);
        let warning = loaded
            .notes
            .iter()
            .find(|n| n.starts_with("warning: texture"))
            .unwrap_or_else(|| panic!("{image}: no warning in {:?}", loaded.notes));
        assert!(
            warning.contains(image) && warning.contains(why),
            "{warning}"
        );
        assert!(warning.contains("/materials/0/pbrMetallicRoughness/baseColorTexture"));
        assert!(!loaded.scene.colour_varies());
        let image = render(&loaded.scene, Stage::Flat, 64);
        assert_eq!(at(&image, 0.3, -0.4), Vec3::from(factor));
    }
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl m\nKd 0.25 0.5 0.75\nmap_Kd -s 1 1 1 nowhere.jpg\n",
    )
    .unwrap();
    let obj = std::fs::read_to_string(path("checker.obj"))
        .unwrap()
        .replace("checker.mtl", "m.mtl")
        .replace("usemtl checker", "usemtl m");
    std::fs::write(dir.join("m.obj"), obj).unwrap();
    let loaded = load_at(&dir.join("m.obj"));
    assert!(
        loaded
            .notes
            .iter()
            .any(|n| n.starts_with("warning: texture `nowhere.jpg`")
                && n.contains("map_Kd of material `m`")
                && n.contains("cannot be read")),
        "{:?}",
        loaded.notes
    );
    assert_eq!(
        at(&render(&loaded.scene, Stage::Flat, 64), -0.6, 0.2),
        Vec3::from(factor)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PLY's vertex colours (sRGB bytes) are interpolated across its triangles: each corner's
/// colour near it, their mean in the middle, and a triangle's colour changes across it (times
/// the default material's grey, 0.8).
#[test]
fn ply_vertex_colours_are_interpolated() {
    let dir = folder("ply-colours");
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0 0 0 255\n1 -1 0 255 255 255\n1 1 0 0 255 0\n-1 1 0 255 0 0\n4 0 1 2 3\n";
    let file = dir.join("quad.ply");
    std::fs::write(&file, ply).unwrap();
    let scene = load_at(&file).scene;
    assert!(scene.colour_varies());
    let image = render(&scene, Stage::Flat, 64);
    for (x, y, want) in [
        (-0.95, 0.95, Vec3::X),
        (0.95, 0.95, Vec3::Y),
        (-0.95, -0.95, Vec3::Z),
        (0.95, -0.95, Vec3::ONE),
    ] {
        // (A pixel's centre is up to a pixel from the point: 0.04 units.)
        let got = at(&image, x, y);
        assert!(
            near(got, want * 0.8, 0.25),
            "({x}, {y}): {got}, want {want}"
        );
    }
    // The fan's first triangle (corners 0, 1, 2) at its middle: the mean of blue, white and
    // green.
    let got = at(&image, 1.0 / 3.0, -1.0 / 3.0);
    assert!(
        near(got, Vec3::new(1.0, 2.0, 2.0) / 3.0 * 0.8, 0.05),
        "{got}"
    );
    let other = at(&image, 0.5, -0.2);
    assert!(!near(got, other, 0.05), "{got} {other}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A model without textures, vertex colours or normals holds no vertex data: it shades as
/// every built-in scene does.
#[test]
fn a_bare_model_holds_no_vertex_data() {
    for name in ["cube.stl", "cube_binary.stl", "lamp.gltf", "lamp.obj"] {
        let scene = model::load(&path(name), &View::default()).unwrap().scene;
        assert!(scene.vertex_data().is_none(), "{name}");
    }
    for b in raytty::scene::builtin::BUILTINS {
        assert!(b.load().unwrap().vertex_data().is_none(), "{}", b.name);
    }
}

/// A sphere of `rings` × `segments` quads (poles as triangles), as OBJ text, with each
/// vertex's normal (`vn`, its direction from the centre) when `normals`.
fn sphere_obj(rings: u32, segments: u32, normals: bool) -> String {
    let mut out = String::new();
    let vertex = |i: u32, j: u32| -> glam::Vec3 {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * j as f32 / segments as f32;
        glam::Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            -theta.sin() * phi.sin(),
        )
    };
    for i in 0..=rings {
        for j in 0..segments {
            let v = vertex(i, j);
            out += &format!("v {} {} {}\n", v.x, v.y, v.z);
            if normals {
                out += &format!("vn {} {} {}\n", v.x, v.y, v.z);
            }
        }
    }
    let id = |i: u32, j: u32| i * segments + j % segments + 1;
    let corner = |k: u32| match normals {
        true => format!("{k}//{k}"),
        false => format!("{k}"),
    };
    for i in 0..rings {
        for j in 0..segments {
            // Counter-clockwise seen from outside.
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            out += &format!(
                "f {} {} {} {}\n",
                corner(a),
                corner(b),
                corner(c),
                corner(d)
            );
        }
    }
    out
}

/// The largest change in brightness between neighbouring pixels along the middle row, inside
/// the sphere's outline (pixels that are lit on both sides).
fn largest_step(image: &raytty::Image) -> f32 {
    let row = image.height / 2;
    let lum: Vec<f32> = (0..image.width)
        .map(|x| image.pixels[(row * image.width + x) as usize].element_sum())
        .collect();
    lum.windows(3)
        .filter(|w| w.iter().all(|&l| l > 0.05))
        .map(|w| (w[1] - w[0]).abs().max((w[2] - w[1]).abs()))
        .fold(0.0, f32::max)
}

/// A coarse sphere with vertex normals renders smooth: along a row across it, no neighbouring
/// pixels differ by the steps its flat facets make without them (the same triangles).
#[test]
fn vertex_normals_shade_a_coarse_sphere_smooth() {
    let dir = folder("smooth-sphere");
    let view = View {
        look_from: Some(Vec3::new(0.0, 0.4, 3.2)),
        look_at: Some(Vec3::ZERO),
        fov_degrees: Some(45.0),
        ..View::default()
    };
    let mut steps = vec![];
    for normals in [false, true] {
        let file = dir.join(format!("sphere_{normals}.obj"));
        std::fs::write(&file, sphere_obj(8, 12, normals)).unwrap();
        let scene = model::load(&file, &view).unwrap().scene;
        assert_eq!(scene.has_normals(), normals);
        let image = render(&scene, Stage::Indirect, 96);
        steps.push(largest_step(&image));
    }
    let (faceted, smooth) = (steps[0], steps[1]);
    assert!(
        smooth * 3.0 < faceted,
        "largest step: {faceted} faceted, {smooth} smooth"
    );
    // Smooth and gold (path traced: the shading frame about the shading normal): one lane and
    // eight shade alike, on every SIMD path, diffuse and metal, in every stage.
    std::fs::write(
        dir.join("gold.mtl"),
        "newmtl gold\nKd 0.9 0.7 0.4\nPm 1\nPr 0.3\n",
    )
    .unwrap();
    for material in ["", "mtllib gold.mtl\nusemtl gold\n"] {
        let file = dir.join("smooth.obj");
        std::fs::write(&file, format!("{material}{}", sphere_obj(8, 12, true))).unwrap();
        let scene = model::load(&file, &view).unwrap().scene;
        for stage in Stage::ALL {
            let frame = |s: &Scene| render(s, stage, 40).pixels;
            let want = frame(&scene.clone().with_isa(Isa::Portable).unwrap());
            assert!(want.iter().all(|p| p.is_finite()));
            assert!(want.iter().any(|p| p.max_element() > 0.05), "{stage:?}");
            for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                let s = scene.clone().with_isa(isa).unwrap();
                assert_eq!(frame(&s), want, "{material:?} {stage:?} {isa:?}");
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A shading normal tilted toward a light that is below the triangle itself does not let the
/// light through: the surface stays dark (stage `light`, no shadow rays to hide a leak),
/// though a light above it, which the tilted normal also sees, lights it.
#[test]
fn a_tilted_shading_normal_does_not_leak_light_from_below() {
    let dir = folder("no-leak");
    // A square in y = 0 facing +y, every vertex normal tilted 60 degrees toward +x.
    let obj = "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nvn 0.866 0.5 0\nf 1//1 2//1 3//1 4//1\n";
    let file = dir.join("tilted.obj");
    std::fs::write(&file, obj).unwrap();
    let view = View {
        look_from: Some(Vec3::new(0.0, 3.0, 0.01)),
        look_at: Some(Vec3::ZERO),
        fov_degrees: Some(45.0),
        ..View::default()
    };
    let scene = model::load(&file, &view).unwrap().scene;
    assert!(scene.has_normals());
    let lit = |light: Vec3| {
        let lights = [raytty::PointLight {
            position: light,
            power: Vec3::splat(50.0),
        }];
        let frame = scene.render(&Options {
            width: 16,
            height: 16,
            settings: Some(Stage::Light.settings(scene.effects())),
            lights: Some(&lights),
            ..Options::default()
        });
        frame.image.pixels[8 * 16 + 8]
    };
    // Far off along +x, a little below the plane: the tilted normal sees it, the plane not.
    assert_eq!(lit(Vec3::new(20.0, -1.0, 0.0)), Vec3::ZERO);
    assert!(lit(Vec3::new(20.0, 1.0, 0.0)).x > 0.0);
    std::fs::remove_dir_all(&dir).unwrap();
}
