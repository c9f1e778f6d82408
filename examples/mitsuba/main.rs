//! Writes a raytty scene for Mitsuba 3: its triangles as one Wavefront OBJ per material, and
//! `scene.json` with the camera, the materials and the lights (point, directional, spot, the
//! environment) in raytty's units (see
//! `compare.py`, which renders the result with Mitsuba and compares it with raytty's frame).
//!
//! `cargo run --release --example mitsuba -- SCENE OUT_DIR` (SCENE: a built-in name or a
//! scene file).

use std::fmt::Write as _;
use std::path::Path;

use raytty::scene::builtin;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(name), Some(out)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: mitsuba SCENE OUT_DIR");
        std::process::exit(2);
    };
    let path = Path::new(name);
    let scene = match builtin::find(name) {
        Some(b) => b.load().map_err(|e| e.to_string()),
        None if raytty::scene::model::Format::of(path).is_some() => {
            raytty::scene::model::load(path, &raytty::scene::model::View::default())
                .map(|l| l.scene)
                .map_err(|e| e.to_string())
        }
        None => raytty::scene::file::load(path).map_err(|e| e.to_string()),
    }
    .unwrap_or_else(|e| {
        eprintln!("{name}: {e}");
        std::process::exit(1);
    });
    let out = Path::new(out);
    std::fs::create_dir_all(out).unwrap();
    let mut materials = String::new();
    for (m, mat) in scene.materials().iter().enumerate() {
        let mut obj = String::new();
        let mut count = 0;
        for tri in scene
            .triangles()
            .iter()
            .filter(|t| t.material as usize == m)
        {
            for v in tri.v {
                writeln!(obj, "v {} {} {}", v.x, v.y, v.z).unwrap();
            }
            count += 1;
        }
        for k in 0..count {
            // Winding kept: an OBJ face's normal is the counter-clockwise one,
            // `Triangle::front`, the side raytty's emitters emit on and its glass has air on.
            writeln!(obj, "f {} {} {}", 3 * k + 1, 3 * k + 2, 3 * k + 3).unwrap();
        }
        if count == 0 {
            continue;
        }
        let file = format!("material{m}.obj");
        std::fs::write(out.join(&file), obj).unwrap();
        let (c, e) = (mat.colour, mat.emission);
        if !materials.is_empty() {
            materials.push_str(",\n");
        }
        write!(
            materials,
            "    {{\"obj\": \"{file}\", \"colour\": [{}, {}, {}], \"mirror\": {}, \"metal\": {}, \
             \"roughness\": {}, \"transmission\": {}, \"ior\": {}, \"emission\": [{}, {}, {}], \
             \"triangles\": {count}}}",
            c.x,
            c.y,
            c.z,
            mat.mirror,
            mat.metal,
            mat.roughness,
            mat.transmission,
            mat.ior,
            e.x,
            e.y,
            e.z
        )
        .unwrap();
    }
    let lights: Vec<String> = scene
        .lights()
        .iter()
        .map(|l| {
            format!(
                "    {{\"position\": [{}, {}, {}], \"power\": [{}, {}, {}]}}",
                l.position.x, l.position.y, l.position.z, l.power.x, l.power.y, l.power.z
            )
        })
        .collect();
    let directional: Vec<String> = scene
        .directional_lights()
        .iter()
        .map(|l| {
            let (d, e) = (l.direction, l.irradiance);
            format!(
                "    {{\"direction\": [{}, {}, {}], \"irradiance\": [{}, {}, {}]}}",
                d.x, d.y, d.z, e.x, e.y, e.z
            )
        })
        .collect();
    let spots: Vec<String> = scene
        .spot_lights()
        .iter()
        .map(|l| {
            let (p, d, w) = (l.position, l.direction, l.power);
            format!(
                "    {{\"position\": [{}, {}, {}], \"direction\": [{}, {}, {}], \"power\": [{}, {}, {}], \"inner\": {}, \"outer\": {}}}",
                p.x, p.y, p.z, d.x, d.y, d.z, w.x, w.y, w.z, l.inner, l.outer
            )
        })
        .collect();
    let env = scene.environment();
    let cam = scene.camera();
    let (p, f, d) = (cam.position, cam.forward(), cam.down());
    let json = format!(
        "{{\n  \"scene\": \"{name}\",\n  \"camera\": {{\"origin\": [{}, {}, {}], \"forward\": [{}, {}, {}], \
         \"down\": [{}, {}, {}], \"fov_degrees\": {}, \"fov_axis\": \"{}\"}},\n  \"materials\": [\n{materials}\n  ],\n  \
         \"lights\": [\n{}\n  ],\n  \"directional\": [\n{}\n  ],\n  \"spots\": [\n{}\n  ],\n  \
         \"environment\": [{}, {}, {}]\n}}\n",
        p.x,
        p.y,
        p.z,
        f.x,
        f.y,
        f.z,
        d.x,
        d.y,
        d.z,
        // The seed's focal length is the shorter side in pixels: 2·atan(1/2) across it; a
        // model's camera has a vertical field of view.
        cam.fov
            .map_or(2.0 * 0.5f64.atan().to_degrees(), |f| f64::from(f)
                .to_degrees()),
        if cam.fov.is_some() { "y" } else { "smaller" },
        lights.join(",\n"),
        directional.join(",\n"),
        spots.join(",\n"),
        env.x,
        env.y,
        env.z
    );
    std::fs::write(out.join("scene.json"), json).unwrap();
    eprintln!(
        "{}: {} triangles, {} lights",
        out.display(),
        scene.triangles().len(),
        scene.lights().len()
    );
}
