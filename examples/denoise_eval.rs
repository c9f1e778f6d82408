//! Raw against denoised stage 6 at a few sample counts, against the cached bench reference:
//! `cargo run --release --example denoise_eval -- 200 100 [REF.pfm]`.

use std::time::Instant;

use raytty::bench::metrics::rmse;
use raytty::denoise::denoise;
use raytty::{HitCache, Options, Output, Stage, cornell_box};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("light") {
        return light_move();
    }
    if args.get(1).map(String::as_str) == Some("cpu") {
        return cpu_time();
    }
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
            let f = HitCache::new().render(
                &scene,
                &Options {
                    width: w,
                    height: h,
                    settings: Some(s),
                    output: Output::Guides,
                    ..Options::default()
                },
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

/// A light held down for `steps` key presses (0.1 each) after 16 passes: the last frame's
/// RMSE against 256 raw passes at the final light, starting fresh each step or keeping
/// `history` samples of the indirect light.
fn light_move() {
    use raytty::PointLight;
    let scene = cornell_box();
    let (w, h) = (200, 100);
    let gi = |frame| {
        let mut s = Stage::Gi.settings(scene.effects());
        s.frame = frame;
        s
    };
    let guides = |lights: &[PointLight], frame| {
        HitCache::new()
            .render(
                &scene,
                &Options {
                    width: w,
                    height: h,
                    settings: Some(gi(frame)),
                    lights: Some(lights),
                    output: Output::Guides,
                    ..Options::default()
                },
            )
            .guides
            .unwrap()
    };
    for steps in [1u32, 4] {
        let mut lights = scene.lights().to_vec();
        let mut history = guides(&lights, 0);
        for f in 1..16 {
            history.accumulate(&guides(&lights, f), u32::MAX);
        }
        let mut runs: Vec<(u32, raytty::denoise::Guides)> = [0u32, 1, 2, 4, 8, 16]
            .iter()
            .map(|&k| (k, history.clone()))
            .collect();
        for step in 0..steps {
            lights[0].position.x += 0.1;
            let new = guides(&lights, 100 + step);
            for (k, g) in &mut runs {
                if *k == 0 {
                    *g = new.clone();
                } else {
                    g.accumulate(&new, *k);
                }
            }
        }
        let mut sum = vec![glam::DVec3::ZERO; (w * h) as usize];
        for f in 0..256 {
            let img = scene
                .render(&Options {
                    width: w,
                    height: h,
                    settings: Some(gi(1000 + f)),
                    lights: Some(&lights),
                    ..Options::default()
                })
                .image;
            for (s, p) in sum.iter_mut().zip(&img.pixels) {
                *s += p.as_dvec3();
            }
        }
        let reference = raytty::Image {
            width: w,
            height: h,
            pixels: sum.iter().map(|s| (*s / 256.0).as_vec3()).collect(),
        };
        for (k, g) in &runs {
            println!(
                "{steps} step(s), history {k:>2}: denoised RMSE {:.4}",
                rmse(&denoise(g).image, &reference)
            );
        }
    }
}

/// CPU seconds this process has used (user + system, from /proc/self/stat; Linux).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
    let after = &stat[stat.rfind(')').unwrap() + 2..];
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 (utime, stime) are the 12th and 13th after the command name.
    let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// CPU time per 200×100 stage 6 frame, raw and denoised, over 200 frames each: on a loaded
/// machine wall time measures the neighbours, CPU time mostly this process.
fn cpu_time() {
    let scene = cornell_box();
    let (w, h) = (200, 100);
    for spp in [1, 4] {
        let mut s = Stage::Gi.settings(scene.effects());
        s.effects.samples = spp;
        let frames = 800 / spp;
        for denoised in [false, true] {
            let t = cpu_seconds();
            for f in 0..frames {
                s.frame = f;
                let fr = HitCache::new().render(
                    &scene,
                    &Options {
                        width: w,
                        height: h,
                        settings: Some(s),
                        output: Output::Guides,
                        ..Options::default()
                    },
                );
                if denoised {
                    std::hint::black_box(denoise(fr.guides.as_ref().unwrap()));
                }
            }
            let ms = (cpu_seconds() - t) * 1e3 / f64::from(frames);
            println!(
                "{w}x{h} {spp} spp {}: {ms:.1} ms of CPU per frame ({:.1} ms on 2 cores if evenly split)",
                if denoised { "denoised" } else { "raw" },
                ms / 2.0
            );
        }
    }
}
