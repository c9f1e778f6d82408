//! Raw against denoised stage 6 at a few sample counts, against the cached bench reference:
//! `cargo run --release --example denoise_eval -- 200 100 [REF.pfm]`.

use std::time::Instant;

use raytty::bench::metrics::rmse;
use raytty::denoise::denoise;
use raytty::{HitCache, Stage, cornell_box, render_guided};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let w: u32 = args.get(1).map_or(200, |s| s.parse().unwrap());
    let h: u32 = args.get(2).map_or(100, |s| s.parse().unwrap());
    let path = args.get(3).cloned().unwrap_or_else(|| {
        format!(
            "{}/.cache/raytty/reference-cornell-{w}x{h}-4096spp-16b-v1.pfm",
            std::env::var("HOME").unwrap()
        )
    });
    let reference = raytty::Image::read_pfm(&std::fs::read(&path).unwrap()).unwrap();
    let scene = cornell_box();
    for spp in [1, 4, 16] {
        let mut s = Stage::Gi.settings(scene.effects());
        s.effects.samples = spp;
        let mut times = Vec::new();
        let mut dtimes = Vec::new();
        let mut out = None;
        for _ in 0..7 {
            let t = Instant::now();
            let f = render_guided(
                &scene,
                &scene.camera(),
                scene.lights(),
                &s,
                w,
                h,
                &mut HitCache::new(),
            );
            times.push(t.elapsed().as_secs_f64() * 1e3);
            let t = Instant::now();
            let d = denoise(f.guides.as_ref().unwrap());
            dtimes.push(t.elapsed().as_secs_f64() * 1e3);
            out = Some((f, d));
        }
        times.sort_by(f64::total_cmp);
        dtimes.sort_by(f64::total_cmp);
        let (f, d) = out.unwrap();
        println!(
            "{w}x{h} {spp:>2} spp: raw {:.4} ({:.1} ms)  denoised {:.4} (+{:.1} ms)  est raw {:.4} den {:.4}",
            rmse(&f.image, &reference),
            times[3],
            rmse(&d.image, &reference),
            dtimes[3],
            d.raw_error,
            d.error
        );
        if std::env::var("PNG").is_ok() {
            f.image
                .write_png(std::fs::File::create(format!("/tmp/raw{spp}.png")).unwrap())
                .unwrap();
            d.image
                .write_png(std::fs::File::create(format!("/tmp/den{spp}.png")).unwrap())
                .unwrap();
        }
    }
}
