//! Stage 6 and its denoiser, numerically: the raw path is unbiased (many raw frames average to
//! an independent roulette-free estimate within 1 %), the denoised frame is closer to a
//! high-sample reference than the raw one, and with many samples it is as right as the raw one
//! where noise averages away (10×10-pixel block means: the filter's bias would stay there), no
//! pixel's filtered light depends on another object's (silhouettes, mirrors), and the same
//! frame comes out on 1 or 2 threads.

use glam::{DVec3, Vec3};
use raytty::denoise::{Guides, denoise};
use raytty::geometry::{Ray, hit_point, offset_ray_origin};
use raytty::rng::Rng;
use raytty::sampler::Sampler;
use raytty::scene::builtin;
use raytty::shading::GI_MAX_BOUNCES;
use raytty::{
    HitCache, Image, Options, Output, RayCounts, Scene, Settings, Stage, Tracer, cornell_box,
};

fn gi(spp: u32, frame: u32) -> Settings {
    let scene = cornell_box();
    let mut s = Stage::Gi.settings(scene.effects());
    s.effects.samples = spp;
    s.frame = frame;
    s
}

fn guided(scene: &Scene, settings: &Settings, w: u32, h: u32) -> (Image, Guides) {
    let f = HitCache::new().render(
        scene,
        &Options {
            width: w,
            height: h,
            settings: Some(*settings),
            output: Output::Guides,
            ..Options::default()
        },
    );
    (f.image, f.guides.expect("a GI frame has guides"))
}

fn rmse(a: &Image, b: &Image) -> f64 {
    raytty::bench::metrics::rmse(a, b)
}

fn block_rmse(a: &Image, b: &Image) -> f64 {
    raytty::bench::metrics::block_rmse(a, b, 10)
}

/// Stage 6 of a built-in scene at `spp` samples, frame `frame`.
fn gi_of(scene: &Scene, spp: u32, frame: u32) -> Settings {
    let mut s = Stage::Gi.settings(scene.effects());
    s.effects.samples = spp;
    s.frame = frame;
    s
}

/// A raw reference of `spp` samples, anti-aliased like the judged frames, with independent
/// numbers (as the bench's references): a Sobol reference shares the judged frames' points. A
/// pixel's sequence has one scramble, and the frame number only moves the index: frame 2²⁰ of
/// 2048 samples starts at point 2³¹, which differs from point 0 in the last bit, and its
/// branches (point 2i + b) wrap round onto the judged frame's own. The raw frame then looked
/// closer to the truth than it was (area at 1024 spp: block RMSE 0.00014 against this
/// reference, 0.00023 against Mitsuba 3's 65,536-spp frame).
fn reference_of(scene: &Scene, w: u32, h: u32, spp: u32) -> Image {
    let mut s = gi_of(scene, spp, 1 << 20);
    s.effects.sampler = Sampler::Independent;
    scene
        .render(&Options {
            width: w,
            height: h,
            settings: Some(s),
            ..Options::default()
        })
        .image
}

/// Raw and denoised stage 6 at `spp`.
fn raw_and_denoised(scene: &Scene, w: u32, h: u32, spp: u32) -> [Image; 2] {
    let (raw, g) = guided(scene, &gi_of(scene, spp, 0), w, h);
    [raw, denoise(&g).image]
}

/// The bias the filter had: at 256 spp, the coloured lights' 10×10-block RMSE was 4.2× the raw
/// image's here (0.0140 against 0.0033; a luminance-only edge stop that blurred colour, and an
/// edge-stopping filter's pull towards one side at every edge), and its RMSE was worse than
/// raw's. Block means keep bias and average noise away, so the denoised blocks must be about
/// as right as raw's. (The bound, 1.25× at 160×100, is the ignored test below; 40
/// blocks at this size are a coarser measure, so the bound here is 1.5×.)
#[test]
fn with_many_samples_the_denoised_frame_is_as_right_as_the_raw_one_in_blocks() {
    let scene = builtin::find("lights").unwrap().load().unwrap();
    let reference = reference_of(&scene, 80, 50, 1024);
    let [raw, den] = raw_and_denoised(&scene, 80, 50, 256);
    let (b_raw, b_den) = (block_rmse(&raw, &reference), block_rmse(&den, &reference));
    let (e_raw, e_den) = (rmse(&raw, &reference), rmse(&den, &reference));
    eprintln!(
        "lights 80x50 256 spp: raw {e_raw:.4} / blocks {b_raw:.5}, denoised {e_den:.4} / blocks {b_den:.5}"
    );
    assert!(
        b_den <= 1.5 * b_raw,
        "denoised block RMSE {b_den:.5} is more than 1.5x raw's {b_raw:.5}"
    );
    assert!(e_den < e_raw, "denoised RMSE {e_den:.4} vs raw {e_raw:.4}");
}

/// The goal on every built-in scene, at the size: at 1024 spp
/// the denoised RMSE is no worse than raw, from 256 spp its block RMSE is at most 1.25× raw's
/// (against 4096-spp references of independent numbers; several minutes:
/// `cargo test --release --test denoise -- --ignored`). "No worse" allows `TIE`: on glass the filter leaves most of the noise alone
/// (the caustics are sharp light, kept apart from the filtered part), and what it changes
/// gains and loses about equally (160×100, 1024 spp, against Mitsuba's 16384-spp frame: the
/// squared error of the 9,020 pixels it changes −0.228 where better, +0.236 where worse; RMSE
/// 0.010158 raw, 0.010167 denoised).
#[test]
#[ignore]
fn the_denoised_frame_converges_to_the_raw_one_on_every_scene() {
    /// A denoised RMSE within 0.5 % of raw's is a tie, no worse.
    const TIE: f64 = 1.005;
    for name in ["cornell", "mirror", "lights", "area", "glass", "plates"] {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let reference = reference_of(&scene, 160, 100, 4096);
        for spp in [256, 1024] {
            let [raw, den] = raw_and_denoised(&scene, 160, 100, spp);
            let (b_raw, b_den) = (block_rmse(&raw, &reference), block_rmse(&den, &reference));
            let (e_raw, e_den) = (rmse(&raw, &reference), rmse(&den, &reference));
            eprintln!(
                "{name} {spp} spp: raw {e_raw:.6} / blocks {b_raw:.6}, denoised {e_den:.6} / \
                 blocks {b_den:.6}"
            );
            assert!(
                b_den <= 1.25 * b_raw,
                "{name} {spp}: blocks {b_den:.5} vs {b_raw:.5}"
            );
            if spp == 1024 {
                assert!(e_den <= e_raw * TIE, "{name}: {e_den:.6} vs {e_raw:.6}");
            }
        }
    }
}

/// The mean of `frames` one-sample frames (pixel centres), frame numbers from `first`.
fn mean_of_frames(scene: &Scene, w: u32, h: u32, first: u32, frames: u32) -> Image {
    let mut sum = vec![DVec3::ZERO; (w * h) as usize];
    for f in first..first + frames {
        let img = scene
            .render(&Options {
                width: w,
                height: h,
                settings: Some(gi(1, f)),
                ..Options::default()
            })
            .image;
        for (s, p) in sum.iter_mut().zip(&img.pixels) {
            *s += p.as_dvec3();
        }
    }
    Image {
        width: w,
        height: h,
        pixels: sum
            .iter()
            .map(|s| (*s / f64::from(frames)).as_vec3())
            .collect(),
    }
}

#[test]
fn guided_frames_are_the_plain_frames() {
    let scene = cornell_box();
    for spp in [1, 4] {
        let (img, g) = guided(&scene, &gi(spp, 3), 40, 30);
        let plain = scene
            .render(&Options {
                width: 40,
                height: 30,
                settings: Some(gi(spp, 3)),
                ..Options::default()
            })
            .image;
        assert_eq!(img, plain, "{spp} spp");
        assert_eq!(g.samples, spp);
        // The guides add up to the same image (up to the rounding of a mean of parts).
        for (a, b) in g.raw().iter().zip(&img.pixels) {
            assert!((*a - *b).abs().max_element() < 1e-5, "{a} vs {b}");
        }
    }
}

#[test]
fn the_denoised_frame_is_closer_to_the_reference_than_the_raw_one() {
    let scene = cornell_box();
    let (w, h) = (64, 48);
    let reference = mean_of_frames(&scene, w, h, 1 << 20, 512);
    for spp in [1, 4] {
        let (raw, g) = guided(&scene, &gi(spp, 0), w, h);
        // Multi-sample frames are anti-aliased and the reference is not: compare 1 spp frames
        // at pixel centres, and 4 spp only for the gain.
        let d = denoise(&g);
        let (e_raw, e_den) = (rmse(&raw, &reference), rmse(&d.image, &reference));
        eprintln!("{spp} spp: raw {e_raw:.4}, denoised {e_den:.4}");
        assert!(
            e_den < 0.4 * e_raw,
            "{spp} spp: denoised {e_den:.4} is not well below raw {e_raw:.4}"
        );
        // The filter hands back what it took where that is systematic (so that it converges
        // to the raw image): at one sample a little of the noise comes back with it (the
        // bound was 0.04, with a bias that did not fade as samples grew).
        if spp == 1 {
            assert!(e_den < 0.045, "1 spp denoised RMSE {e_den:.4}");
        }
        // The raw error estimate from the variance is in the right range.
        let est = f64::from(d.raw_error);
        assert!(
            est > 0.5 * e_raw && est < 1.5 * e_raw,
            "estimate {est:.4} vs measured {e_raw:.4}"
        );
        assert!(d.error < d.raw_error);
    }
}

/// The physically based path's noisy light (the area light's soft shadows and the bounces off
/// diffuse first hits) goes to the denoiser too: on the area-lit box the denoised frame is
/// much closer to a reference than the raw one at a few samples, and a glass or metal first
/// hit is left as it is (the denoised frame equals the raw one there).
#[test]
fn the_area_lit_box_is_denoised() {
    let scene = builtin::find("area").unwrap().load().unwrap();
    let (w, h) = (48, 30);
    // Values clamped to 0..1, as a display shows them: the light's own edge (emission ~10,
    // anti-aliased differently at 2 and 512 samples) would otherwise outweigh the room.
    let clamped = |i: &Image| Image {
        width: i.width,
        height: i.height,
        pixels: i
            .pixels
            .iter()
            .map(|p| p.clamp(Vec3::ZERO, Vec3::ONE))
            .collect(),
    };
    let reference = clamped(&reference_of(&scene, w, h, 512));
    let [raw, den] = raw_and_denoised(&scene, w, h, 2).map(|i| clamped(&i));
    let (e_raw, e_den) = (rmse(&raw, &reference), rmse(&den, &reference));
    eprintln!("area {w}x{h} 2 spp (clamped): raw {e_raw:.4}, denoised {e_den:.4}");
    // Raw 0.0747 and denoised 0.0390 while a sample traced one path; since a diffuse first
    // hit sends two on (in frames of several samples), raw 0.0541 and denoised 0.0340: both
    // better, the raw frame most.
    assert!(
        e_den < 0.7 * e_raw,
        "denoised {e_den:.4} is not well below raw {e_raw:.4}"
    );
    let glass = builtin::find("glass").unwrap().load().unwrap();
    let (raw, g) = guided(&glass, &gi_of(&glass, 1, 0), w, h);
    let den = denoise(&g).image;
    let unfiltered = g.pixels.iter().filter(|p| p.albedo == Vec3::ZERO).count();
    assert!(unfiltered > 0, "the glass scene has glass in view");
    for ((p, r), d) in g.pixels.iter().zip(&raw.pixels).zip(&den.pixels) {
        if p.albedo == Vec3::ZERO {
            assert!((*r - *d).abs().max_element() < 1e-5, "{r} vs {d}");
        }
    }
}

/// A pixel whose samples saw two surfaces (an edge or a silhouette runs through it) takes no
/// part in the restore and goes back towards its raw value as samples grow: the spread of its
/// samples is the edge more than noise, and filtered like the rest it was pulled towards one
/// side and the difference handed to its neighbours, a bias along every edge that more
/// samples did not take away.
#[test]
fn a_pixel_an_edge_runs_through_goes_back_to_its_raw_value() {
    let scene = builtin::find("area").unwrap().load().unwrap();
    let (w, h) = (48, 30);
    let (raw, mut g) = guided(&scene, &gi_of(&scene, 4, 0), w, h);
    let mixed = g.pixels.iter().filter(|p| p.mixed).count();
    // The room's creases and the box's edges: a few pixels in a hundred.
    assert!(
        mixed > w as usize && mixed < g.pixels.len() / 5,
        "{mixed} mixed pixels of {}",
        g.pixels.len()
    );
    let differs = |g: &Guides, den: &Image| {
        let (mut mixed, mut whole) = (0, 0);
        for ((p, r), d) in g.pixels.iter().zip(&raw.pixels).zip(&den.pixels) {
            if (*r - *d).abs().max_element() > 1e-4 {
                *(if p.mixed { &mut mixed } else { &mut whole }) += 1;
            }
        }
        (mixed, whole)
    };
    // At 4 samples the edges are filtered too.
    let (m, _) = differs(&g, &denoise(&g).image);
    assert!(m > mixed / 2, "{m} of {mixed} mixed pixels filtered");
    // The same guides as if they held very many samples of the same spread (the moments
    // scaled so that each pixel's variance of the mean stays as it was, and the filter as
    // strong): the mixed pixels are raw, the others still filtered.
    let k = (1u32 << 24) as f32 / g.samples as f32;
    g.samples = 1 << 24;
    for p in &mut g.pixels {
        let [m1, m2] = p.moments;
        p.moments[1] = m1 * m1 + (m2 - m1 * m1) * k;
    }
    let (m, whole) = differs(&g, &denoise(&g).image);
    assert_eq!(m, 0, "mixed pixels not raw");
    assert!(whole > g.pixels.len() / 10, "{whole} pixels filtered");
    // One sample a pixel sees one surface.
    let (_, g) = guided(&scene, &gi_of(&scene, 1, 0), w, h);
    assert!(g.pixels.iter().all(|p| !p.mixed));
}

/// Replaces the indirect light of every pixel whose guide is not on `object` (seen through
/// `reflections` mirrors) by a large, noisy value; returns how many pixels are on it.
fn scramble_all_but(g: &mut Guides, object: u32, reflections: u32, seed: u64) -> usize {
    let mut rng = Rng::seeded(seed);
    let mut kept = 0;
    for p in &mut g.pixels {
        match p.guide {
            Some(s) if s.object == object && s.reflections == reflections => kept += 1,
            _ => {
                let v = 10.0 * rng.next_f32();
                p.indirect = p.albedo * v;
                p.moments = [v, v * v];
            }
        }
    }
    kept
}

#[test]
fn no_light_crosses_a_silhouette_or_a_mirror() {
    for (name, w, h) in [("cornell", 64, 48), ("mirror", 64, 48)] {
        let scene = builtin::find(name).unwrap().load().unwrap();
        let (_, g) = guided(&scene, &gi(1, 0), w, h);
        let clean = denoise(&g);
        let mut surfaces: Vec<(u32, u32)> = g
            .pixels
            .iter()
            .filter_map(|p| p.guide.map(|s| (s.object, s.reflections)))
            .collect();
        surfaces.sort();
        surfaces.dedup();
        assert!(surfaces.len() >= 5, "{name}: {surfaces:?}");
        if name == "mirror" {
            assert!(
                surfaces.iter().any(|s| s.1 > 0),
                "no pixel guided by a reflection"
            );
        }
        for (i, &(object, reflections)) in surfaces.iter().enumerate() {
            let mut other = g.clone();
            let kept = scramble_all_but(&mut other, object, reflections, i as u64);
            let d = denoise(&other);
            let mut changed_elsewhere = 0;
            for (k, p) in g.pixels.iter().enumerate() {
                let on = p
                    .guide
                    .is_some_and(|s| (s.object, s.reflections) == (object, reflections));
                if on {
                    assert_eq!(
                        d.image.pixels[k], clean.image.pixels[k],
                        "{name}: pixel {k} of object {object} ({reflections} mirrors) took \
                         light from another surface"
                    );
                } else if d.image.pixels[k] != clean.image.pixels[k] {
                    changed_elsewhere += 1;
                }
            }
            // The scramble did reach the other pixels: the test can fail.
            assert!(kept > 0 && changed_elsewhere > 0, "{name}: {object}");
        }
    }
}

/// Stage 6's model (direct light with shadows plus diffuse interreflection, at most
/// `GI_MAX_BOUNCES` bounces), estimated without Russian roulette: every path goes the full
/// depth, so no `1/q` weight can be wrong. Written apart from the tracer's path code.
struct Unrouletted<'a> {
    scene: &'a Scene,
    tracer: Tracer<'a>,
}

impl Unrouletted<'_> {
    fn radiance(&self, ray: &Ray, depth: u32, rng: &mut Rng, n: &mut RayCounts) -> Vec3 {
        let Some(hit) = self.scene.intersect(ray, f32::INFINITY) else {
            return Vec3::ZERO;
        };
        let tri = &self.scene.triangles()[hit.triangle as usize];
        let rho = self.scene.materials()[tri.material as usize].colour;
        let (p, err) = hit_point(&tri.v, hit.b);
        let normal = if tri.normal.dot(ray.dir) > 0.0 {
            -tri.normal
        } else {
            tri.normal
        };
        let direct = self.tracer.direct(p, err, normal, n);
        let mut indirect = Vec3::ZERO;
        if depth < GI_MAX_BOUNCES {
            // Cosine-weighted: the estimator of the irradiance is the incoming radiance itself.
            let (u1, u2) = (rng.next_f64(), rng.next_f64());
            let (r, phi) = (u1.sqrt(), std::f64::consts::TAU * u2);
            let n64 = normal.as_dvec3();
            let a = if n64.x.abs() > 0.5 {
                DVec3::Y
            } else {
                DVec3::X
            };
            let t = n64.cross(a).normalize();
            let b = n64.cross(t);
            let dir = (t * (r * phi.cos()) + b * (r * phi.sin()) + n64 * (1.0 - u1).sqrt())
                .normalize()
                .as_vec3();
            let origin = offset_ray_origin(p, err, normal, dir);
            indirect = self.radiance(&Ray::new(origin, dir), depth + 1, rng, n);
        }
        rho * (direct + indirect)
    }
}

#[test]
fn the_raw_path_is_unbiased() {
    let scene = cornell_box();
    let (w, h) = (32, 24);
    let frames = 512;
    let raw = mean_of_frames(&scene, w, h, 0, frames);
    // The direct part, exact at pixel centres: what is left is the indirect light alone.
    let shadows = Stage::Shadows.settings(scene.effects());
    let direct = scene
        .render(&Options {
            width: w,
            height: h,
            settings: Some(shadows),
            ..Options::default()
        })
        .image
        .pixels
        .iter()
        .map(|p| p.as_dvec3())
        .sum::<DVec3>()
        / f64::from(w * h);
    let settings = gi(1, 0);
    let u = Unrouletted {
        scene: &scene,
        tracer: Tracer::new(&scene, scene.lights(), settings),
    };
    let rays = scene.camera().rays(w, h);
    let mut sum = DVec3::ZERO;
    let mut n = RayCounts::default();
    for y in 0..h {
        for x in 0..w {
            let ray = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            for s in 0..frames {
                let mut rng = Rng::for_sample(u64::from(y * w + x), s, 0x7000_0000);
                sum += u.radiance(&ray, 0, &mut rng, &mut n).as_dvec3();
            }
        }
    }
    let expected = sum / f64::from(frames * w * h);
    let got = raw.pixels.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / f64::from(w * h);
    let rel = (got - expected).abs() / expected;
    let rel_indirect = (got - expected).abs() / (expected - direct);
    eprintln!(
        "raw mean {got}, roulette-free {expected}, relative {rel}, of the indirect light \
         {rel_indirect}"
    );
    assert!(
        rel.max_element() < 0.01,
        "the mean of {frames} raw frames {got} is not within 1% of {expected}"
    );
    // The noise of both means is about 0.5 % of the indirect light (the exact direct light is
    // the same on both sides); a dropped 1/q in the roulette is 2 % or more of it.
    assert!(
        rel_indirect.max_element() < 0.015,
        "the indirect light of {frames} raw frames {got} is not within 1.5% of {expected}"
    );
}

#[test]
fn the_denoised_frame_is_the_same_on_one_thread_and_two() {
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let scene = builtin::find("mirror").unwrap().load().unwrap();
                let (_, g) = guided(&scene, &gi(2, 5), 48, 32);
                let d = denoise(&g);
                (d.image, d.raw_error.to_bits(), d.error.to_bits())
            })
    };
    assert_eq!(run(1), run(2));
}
