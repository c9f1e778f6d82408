//! Flat object list against BVH: on the Cornell box (30 triangles: which one the scene should
//! use) and on the 1M-triangle displaced icosphere in the Cornell room (build time, frame times,
//! ray throughput, peak memory).
//!
//! Run: `cargo run --release --example accel_bench [-- K]` (K = icosphere subdivision, default
//! 224: 20·K² = 1,003,520 triangles). Numbers depend on the machine; nothing here is asserted.

use std::time::{Duration, Instant};

use glam::Vec3;
use raytty::bench::scene::{SceneBench, bench_scene};
use raytty::scene::cornell::colours;
use raytty::scene::procedural::displaced_icosphere;
use raytty::{AccelKind, Camera, Effects, Material, Scene, SceneBuilder, cornell_box};

/// Timed runs per size.
const RUNS: u32 = 11;

/// This thread's CPU time (Linux, /proc/thread-self/schedstat, in ns); wall-clock time elsewhere.
/// On a loaded machine the thread's own time is what the work cost.
fn thread_time() -> Duration {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .map(Duration::from_nanos)
        .unwrap_or_else(|| Instant::now().duration_since(*EPOCH.get_or_init(Instant::now)))
}

static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();

/// A line per size: median frame time and M rays/s.
fn frames(b: &SceneBench) -> String {
    let mut s = format!("built in {:.1} ms\n", b.accel.build.as_secs_f64() * 1e3);
    for z in &b.sizes {
        s += &format!(
            "- {}×{}: {:.2} ms median of {} frames, {:.2} M rays/s\n",
            z.width,
            z.height,
            z.median.as_secs_f64() * 1e3,
            z.runs,
            z.mrays_per_s()
        );
    }
    s
}

/// Closest-hit queries per second of this thread's time (best of 5), for the camera rays of a
/// `w`×`h` frame.
fn trace_rate(scene: &Scene, w: u32, h: u32) -> f64 {
    let camera_rays = scene.camera().rays(w, h);
    let rays: Vec<_> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| camera_rays.ray(x as f32 + 0.5, y as f32 + 0.5))
        .collect();
    let mut best = Duration::MAX;
    let mut hits = 0;
    for _ in 0..5 {
        let start = thread_time();
        hits = rays
            .iter()
            .filter(|r| scene.intersect(r, f32::INFINITY).is_some())
            .count();
        best = best.min(thread_time() - start);
    }
    std::hint::black_box(hits);
    rays.len() as f64 / best.as_secs_f64() / 1e6
}

/// CPU time of this process so far (all threads, user + system), from /proc (Linux): on a
/// loaded machine it says what the work costs where wall-clock time does not.
fn cpu_time() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    let ticks: u64 = fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
    // The kernel's USER_HZ is 100 on every Linux target we run on.
    Some(Duration::from_millis(ticks * 10))
}

/// Peak resident memory of this process, from /proc (Linux), in MiB.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// The built-in `sphere` scene's layout: the Cornell room's five walls and a displaced
/// icosphere of radius 0.6 resting above the floor.
fn sphere_scene(k: u32) -> (Scene, Duration, Duration, Option<Duration>) {
    let start = Instant::now();
    let mesh = displaced_icosphere(k, 0.08);
    let generate = start.elapsed();
    let mut b = SceneBuilder::new();
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let walls = [
        (
            colours::GREEN,
            [v(-1., 1., 1.), v(1., 1., -1.), v(-1., 1., -1.)],
            [v(-1., 1., 1.), v(1., 1., 1.), v(1., 1., -1.)],
        ),
        (
            colours::PURPLE,
            [v(-1., 1., -1.), v(-1., -1., -1.), v(-1., 1., 1.)],
            [v(-1., 1., 1.), v(-1., -1., -1.), v(-1., -1., 1.)],
        ),
        (
            colours::YELLOW,
            [v(1., -1., -1.), v(1., 1., -1.), v(1., 1., 1.)],
            [v(1., -1., 1.), v(1., -1., -1.), v(1., 1., 1.)],
        ),
        (
            colours::CYAN,
            [v(-1., -1., -1.), v(1., -1., -1.), v(-1., -1., 1.)],
            [v(1., -1., -1.), v(1., -1., 1.), v(-1., -1., 1.)],
        ),
        (
            colours::WHITE,
            [v(-1., -1., 1.), v(1., 1., 1.), v(-1., 1., 1.)],
            [v(-1., -1., 1.), v(1., -1., 1.), v(1., 1., 1.)],
        ),
    ];
    for (colour, a, c) in walls {
        let m = b.material(Material::diffuse(colour));
        b.object([a, c], m);
    }
    let gold = b.material(Material::diffuse(Vec3::new(0.75, 0.6, 0.2)));
    let offset = Vec3::new(0.0, 0.3, 0.1);
    b.object(mesh.into_iter().map(|t| t.map(|p| p * 0.6 + offset)), gold);
    b.light(raytty::scene::cornell::LIGHT);
    let (start, cpu) = (Instant::now(), cpu_time());
    let scene = b
        .build("sphere", Camera::default(), Effects::SEED)
        .expect("the sphere scene is valid");
    let wall = start.elapsed();
    let cpu = cpu.zip(cpu_time()).map(|(a, b)| b - a);
    (scene, generate, wall, cpu)
}

fn main() {
    let k: u32 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("K must be a positive integer"))
        .unwrap_or(224);
    let sizes = [(200, 100), (500, 500)];
    println!("{} rayon threads\n", rayon::current_num_threads());

    println!("## Cornell box: flat list against BVH\n");
    for kind in [AccelKind::Flat, AccelKind::Bvh] {
        let scene = cornell_box().with_accel(kind);
        println!("### {}\n", kind.name());
        print!("{}", frames(&bench_scene(&scene, &sizes, RUNS)));
        println!(
            "\nclosest hit, camera rays 500×500, one thread's time: {:.2} M rays/s\n",
            trace_rate(&scene, 500, 500)
        );
    }
    println!(
        "default for 30 triangles: {}\n",
        cornell_box().accel_stats().kind.name()
    );

    println!("## Where the BVH starts to win: the room and a small icosphere (one object)\n");
    println!("| triangles | flat M rays/s | BVH M rays/s |\n| ---: | ---: | ---: |");
    for small_k in [1, 2, 3, 4, 6] {
        let (scene, ..) = sphere_scene(small_k);
        let n = scene.triangles().len();
        let flat = trace_rate(&scene.clone().with_accel(AccelKind::Flat), 300, 300);
        let bvh = trace_rate(&scene.with_accel(AccelKind::Bvh), 300, 300);
        println!("| {n} | {flat:.2} | {bvh:.2} |");
    }
    println!(
        "\n(one thread, camera rays 300×300; the default switches at {} triangles)\n",
        raytty::accel::BVH_THRESHOLD
    );

    println!("## Displaced icosphere in the Cornell room (k = {k})\n");
    let (scene, generate, build, build_cpu) = sphere_scene(k);
    let stats = scene.accel_stats();
    println!(
        "{} triangles: mesh generated in {:.1} ms; SceneBuilder::build (validation + {}) {:.1} ms, of which the BVH {:.1} ms ({} nodes, depth {})",
        scene.triangles().len(),
        generate.as_secs_f64() * 1e3,
        stats.kind.name(),
        build.as_secs_f64() * 1e3,
        stats.build.as_secs_f64() * 1e3,
        stats.nodes,
        stats.depth
    );
    if let Some(cpu) = build_cpu {
        println!(
            "SceneBuilder::build CPU time, all threads: {:.0} ms",
            cpu.as_secs_f64() * 1e3
        );
    }
    if let Some(mib) = peak_rss_mib() {
        println!("peak RSS after building: {mib:.0} MiB\n");
    }
    print!("{}", frames(&bench_scene(&scene, &sizes, RUNS)));
    println!(
        "\nclosest hit, camera rays 500×500, one thread's time: BVH {:.2} M rays/s",
        trace_rate(&scene, 500, 500)
    );
    let flat = scene.with_accel(AccelKind::Flat);
    println!(
        "closest hit, camera rays 16×8, one thread's time: flat list {:.4} M rays/s",
        trace_rate(&flat, 16, 8)
    );
    if let Some(mib) = peak_rss_mib() {
        println!("peak RSS at the end: {mib:.0} MiB");
    }
}
