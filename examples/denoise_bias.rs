//! The denoiser's bias: raw against denoised stage 6 at several sample counts, measured
//! against a high-sample raw reference (the bench's cached one) by RMSE and by the RMSE of
//! 10×10-pixel block means (noise averages away in a block, bias does not).
//!
//! `cargo run --release --example denoise_bias -- SCENE WxH REF_SPP SPP,SPP,...`
//! e.g. `-- lights 160x100 2048 64,256,1024`. The reference is rendered once (raw, path-traced,
//! up to 16 bounces, frame numbers far from the judged frames') and cached as the bench caches
//! its own; with `PFM=DIR` the judged frames are written there too.

use raytty::bench::metrics::{block_rmse, rmse};
use raytty::bench::{NoProgress, ReferenceSpec, reference};
use raytty::denoise::denoise;
use raytty::denoise::{GuidePixel, Guides};
use raytty::scene::builtin;
use raytty::shading::GI_MAX_BOUNCES;
use raytty::shading::GuideHit;
use raytty::{HitCache, Image, Options, Output, Scene, Settings, Stage};

fn guided(scene: &Scene, s: &Settings, w: u32, h: u32) -> Guides {
    HitCache::new()
        .render(
            scene,
            &Options {
                width: w,
                height: h,
                settings: Some(*s),
                output: Output::Guides,
                ..Options::default()
            },
        )
        .guides
        .unwrap()
}

/// Floats a pixel takes in a cached file.
const PIXEL_FLOATS: usize = 21;

/// Guides as raw little-endian floats (`GUIDES=DIR` caches them, so that changes to the
/// filter are measured on the same samples without rendering them again).
fn save(g: &Guides, path: &str) {
    let mut out: Vec<f32> = vec![g.width as f32, g.height as f32, g.samples as f32];
    for p in &g.pixels {
        out.extend(p.rest.to_array());
        out.extend(p.albedo.to_array());
        out.extend(p.indirect.to_array());
        out.extend(p.moments);
        match p.guide {
            Some(s) => {
                out.extend(s.position.to_array());
                out.extend(s.normal.to_array());
                out.extend([1.0, s.object as f32, s.reflections as f32]);
            }
            None => out.extend([0.0; 9]),
        }
        out.push(if p.mixed { 1.0 } else { 0.0 });
    }
    let bytes: Vec<u8> = out.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(path, bytes).unwrap();
}

fn load(path: &str) -> Option<Guides> {
    let bytes = std::fs::read(path).ok()?;
    let v: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let v3 = |s: &[f32]| glam::Vec3::new(s[0], s[1], s[2]);
    // A file of another layout is rendered again.
    if v.len() < 3 || v.len() != 3 + PIXEL_FLOATS * (v[0] * v[1]) as usize {
        return None;
    }
    let pixels = v[3..]
        .chunks_exact(PIXEL_FLOATS)
        .map(|c| GuidePixel {
            rest: v3(&c[0..]),
            albedo: v3(&c[3..]),
            indirect: v3(&c[6..]),
            moments: [c[9], c[10]],
            guide: (c[17] == 1.0).then(|| GuideHit {
                position: v3(&c[11..]),
                normal: v3(&c[14..]),
                object: c[18] as u32,
                reflections: c[19] as u32,
            }),
            mixed: c[20] == 1.0,
            seen: true,
        })
        .collect();
    Some(Guides {
        width: v[0] as u32,
        height: v[1] as u32,
        samples: v[2] as u32,
        pixels,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: denoise_bias SCENE WxH REF_SPP SPP,SPP,...";
    let name = args.get(1).expect(usage);
    let (w, h) = args
        .get(2)
        .and_then(|s| s.split_once('x'))
        .map(|(w, h)| (w.parse::<u32>().unwrap(), h.parse::<u32>().unwrap()))
        .expect(usage);
    let ref_spp: u32 = args.get(3).expect(usage).parse().unwrap();
    let spps: Vec<u32> = args
        .get(4)
        .expect(usage)
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    let scene = builtin::find(name)
        .expect("a built-in scene")
        .load()
        .unwrap();
    let spec = ReferenceSpec::new(&scene, w, h, ref_spp, GI_MAX_BOUNCES);
    let (reference, info) = reference::load_or_render(
        &scene,
        &spec,
        &reference::default_cache_dir(),
        &mut NoProgress,
    )
    .unwrap();
    eprintln!("{}", info.path.display());
    println!("| scene | spp | raw RMSE | denoised RMSE | raw block RMSE | denoised block RMSE |");
    println!("|---|---:|---:|---:|---:|---:|");
    for spp in spps {
        let mut s = Stage::Gi.settings(scene.effects());
        s.effects.samples = spp;
        let g = match std::env::var("GUIDES") {
            Ok(dir) => {
                let path = format!("{dir}/{name}-{w}x{h}-{spp}.bin");
                load(&path).unwrap_or_else(|| {
                    let g = guided(&scene, &s, w, h);
                    save(&g, &path);
                    g
                })
            }
            Err(_) => guided(&scene, &s, w, h),
        };
        let raw = Image {
            width: w,
            height: h,
            pixels: g.raw(),
        };
        let d = denoise(&g);
        println!(
            "| {name} | {spp} | {:.4} | {:.4} | {:.5} | {:.5} |",
            rmse(&raw, &reference),
            rmse(&d.image, &reference),
            block_rmse(&raw, &reference, 10),
            block_rmse(&d.image, &reference, 10),
        );
        if let Ok(dir) = std::env::var("PFM") {
            for (tag, img) in [("raw", &raw), ("den", &d.image)] {
                let path = format!("{dir}/{name}-{spp}-{tag}.pfm");
                img.write_pfm(std::fs::File::create(path).unwrap()).unwrap();
            }
        }
    }
}
