//! The side-by-side pictures in `docs/`: stage 6 raw (1 sample per pixel), the same frame
//! denoised, and a reference (many samples, raw), for a built-in scene:
//! `cargo run --release --example denoise_sheet -- mirror docs/denoise-mirror.png [REF_SPP]`.

use glam::Vec3;
use raytty::denoise::denoise;
use raytty::scene::builtin;
use raytty::{HitCache, Image, Options, Output, Stage};

/// Each panel's size in pixels.
const W: u32 = 240;
const H: u32 = 180;
/// White between panels.
const GAP: u32 = 4;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("cornell", String::as_str);
    let out = args
        .get(2)
        .cloned()
        .unwrap_or_else(|| format!("docs/denoise-{name}.png"));
    let ref_spp: u32 = args.get(3).map_or(1024, |s| s.parse().expect("REF_SPP"));
    let scene = builtin::find(name)
        .expect("a built-in scene")
        .load()
        .expect("loads");
    let mut s = Stage::Gi.settings(scene.effects());
    let f = HitCache::new().render(
        &scene,
        &Options {
            width: W,
            height: H,
            settings: Some(s),
            output: Output::Guides,
            ..Options::default()
        },
    );
    let raw = f.image;
    let denoised = denoise(&f.guides.expect("GI guides")).image;
    s.effects.samples = ref_spp;
    s.frame = 0x2000_0000;
    let reference = scene
        .render(&Options {
            width: W,
            height: H,
            settings: Some(s),
            ..Options::default()
        })
        .image;
    println!(
        "{name}: RMSE against the reference: raw {:.4}, denoised {:.4}",
        raytty::bench::metrics::rmse(&raw, &reference),
        raytty::bench::metrics::rmse(&denoised, &reference)
    );
    let mut sheet = Image {
        width: 3 * W + 2 * GAP,
        height: H,
        pixels: vec![Vec3::ONE; ((3 * W + 2 * GAP) * H) as usize],
    };
    for (i, img) in [raw, denoised, reference].iter().enumerate() {
        let x0 = i as u32 * (W + GAP);
        for y in 0..H {
            for x in 0..W {
                sheet.pixels[(y * sheet.width + x0 + x) as usize] = img.get(x, y);
            }
        }
    }
    sheet
        .write_png(std::fs::File::create(&out).expect("create the PNG"))
        .expect("write the PNG");
    println!("{out}: raw 1 spp | denoised | {ref_spp} spp");
}
