//! `raytty bench`: the accuracy price list, or what one scene costs. The library measures
//! (`raytty::bench`); this writes what it measured: the Markdown table or CSV on stdout, the
//! terminal chart, the SVG plot and the report file (docs/performance.md).

mod plot;
mod report;
mod svg;
mod table;

use std::io::{self, Write};
use std::path::Path;

use anyhow::Context;
use raytty::bench::{BenchOptions, throughput};
use raytty::image::MAX_PIXELS;

use super::args::*;
use super::progress::Bar;
use super::{Result, usage};

/// `raytty bench`: with no `--scene`, the accuracy price list of the Cornell box; with
/// `--scene`, what that scene costs (load and acceleration build, frame times, M rays/s).
pub(super) fn run_bench(
    a: BenchArgs,
    scene: Option<&str>,
    view: &raytty::scene::model::View,
) -> Result<()> {
    if let Some(name) = scene {
        // The flags that shape the accuracy bench only conflict with --scene (args.rs).
        let sizes = match (a.sizes.is_empty(), a.quick) {
            (false, _) => a.sizes,
            (true, true) => BenchOptions::quick().sizes,
            (true, false) => vec![(200, 100), (500, 500)],
        };
        check_sizes(&sizes)?;
        let start = std::time::Instant::now();
        let (scene, _watch) = crate::cli::scene_arg::load_scene(Some(name), view)?;
        let load = start.elapsed();
        let runs = a.runs.unwrap_or(if a.quick { 2 } else { 5 });
        let bench = raytty::bench::scene::bench_scene(&scene, &sizes, runs);
        let mut out = io::stdout().lock();
        writeln!(
            out,
            "Scene `{}` loaded in {:.0} ms (parse, generate, validate, build).\n",
            raytty::printable(name),
            load.as_secs_f64() * 1e3
        )?;
        out.write_all(report::scene_markdown(&bench).as_bytes())?;
        return Ok(());
    }
    let options = options(&a);
    check_sizes(&options.sizes)?;
    // The files are written after the (long) run: a folder that does not exist fails now.
    for (flag, path) in [("--svg", &a.svg), ("--report", &a.report)] {
        if let Some(dir) = path.as_deref().and_then(Path::parent)
            && !dir.as_os_str().is_empty()
            && !dir.is_dir()
        {
            usage!(
                "{flag} {}: the folder {} does not exist",
                path.as_deref().unwrap_or(dir).display(),
                dir.display()
            );
        }
    }
    let command = std::iter::once("raytty".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    let scene = raytty::cornell_box();
    let bench = raytty::bench::run(&scene, &options, &mut Bar::default()).with_context(|| {
        format!(
            "cannot cache the reference in {}",
            options.cache_dir.display()
        )
    })?;
    let mut log = io::stderr().lock();
    for r in &bench.references {
        for note in &r.refused {
            writeln!(log, "raytty bench: {note}")?;
        }
        writeln!(log, "raytty bench: {}", r.describe())?;
    }
    let mut out = io::stdout().lock();
    if a.csv {
        out.write_all(report::csv(&bench).as_bytes())?;
    } else {
        let estimators = raytty::bench::estimators::run(&options, &mut Bar::default())
            .with_context(|| {
                format!(
                    "cannot cache the references in {}",
                    options.cache_dir.display()
                )
            })?;
        for r in &estimators.1 {
            for note in &r.refused {
                writeln!(log, "raytty bench: {note}")?;
            }
            writeln!(log, "raytty bench: {}", r.describe())?;
        }
        let rates = throughputs(&scene, a.quick, &options);
        let stamp = report::Stamp::now(&bench.environment, &command);
        let body = report::body(&bench, &estimators, &rates, &stamp);
        out.write_all(body.as_bytes())?;
        if let Some(path) = &a.report {
            let chart = a.svg.as_deref().and_then(|svg| chart_link(path, svg));
            let text = report::document(&body, chart.as_deref());
            std::fs::write(path, text)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    if a.plot {
        writeln!(out)?;
        out.write_all(plot::plot(&bench).as_bytes())?;
    }
    if let Some(path) = &a.svg {
        std::fs::write(path, svg::svg(&bench))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The options the flags resolve to: [`BenchOptions::full`]'s (or with `--quick`
/// [`BenchOptions::quick`]'s), with what the flags give instead.
fn options(a: &BenchArgs) -> BenchOptions {
    let base = if a.quick {
        BenchOptions::quick()
    } else {
        BenchOptions::full()
    };
    BenchOptions {
        sizes: if a.sizes.is_empty() {
            base.sizes.clone()
        } else {
            a.sizes.clone()
        },
        runs: a.runs.unwrap_or(base.runs),
        max_spp: a.max_spp.unwrap_or(base.max_spp),
        ref_spp: a.ref_spp.unwrap_or(base.ref_spp),
        ref_bounces: a.ref_bounces.unwrap_or(base.ref_bounces),
        ..base
    }
}

/// Refuses a bench size over [`MAX_PIXELS`], the cap every frame has, with a message that
/// names the flag.
fn check_sizes(sizes: &[(u32, u32)]) -> Result<()> {
    for &(w, h) in sizes {
        if u64::from(w) * u64::from(h) > MAX_PIXELS {
            usage!(
                "--sizes {w}x{h} is too large: at most {MAX_PIXELS} pixels per size (e.g. 8192x8192)"
            );
        }
    }
    Ok(())
}

/// The SVG's path as the report links it: relative to the report's folder when it is in that
/// folder or below, else as given (absolute paths stay absolute).
fn chart_link(report: &Path, svg: &Path) -> Option<String> {
    let dir = report.parent().unwrap_or(Path::new(""));
    let link = svg.strip_prefix(dir).unwrap_or(svg);
    link.to_str().map(str::to_string)
}

/// The throughput section's measurements: `scene` at the first bench size, and (unless
/// `--quick`) the built-in 1M-triangle sphere at the same size.
fn throughputs(
    scene: &raytty::Scene,
    quick: bool,
    options: &BenchOptions,
) -> Vec<throughput::Throughput> {
    let (w, h) = options.sizes.first().copied().unwrap_or((500, 500));
    let mut out = vec![throughput::measure(scene, w, h, options.runs)];
    if !quick && let Some(Ok(sphere)) = raytty::scene::builtin::find("sphere").map(|b| b.load()) {
        out.push(throughput::measure(&sphere, w, h, options.runs));
    }
    out
}
