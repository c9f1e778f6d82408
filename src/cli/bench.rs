//! `raytty bench`: the accuracy price list, or what one scene costs.

use std::io::{self, Write};

use super::args::*;
use super::progress::Bar;
use super::{Failure, Result, usage};

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
            (true, true) => raytty::bench::BenchOptions::quick().sizes,
            (true, false) => vec![(200, 100), (500, 500)],
        };
        raytty::bench::check_sizes(&sizes).map_err(bench_failure)?;
        let start = std::time::Instant::now();
        let scene = crate::cli::scene_arg::load_scene(Some(name), view)?;
        let load = start.elapsed();
        let runs = a.runs.unwrap_or(if a.quick { 2 } else { 5 });
        let report = raytty::bench::scene::bench_scene(&scene, &sizes, runs);
        let mut out = io::stdout().lock();
        writeln!(
            out,
            "Scene `{}` loaded in {:.0} ms (parse, generate, validate, build).\n",
            raytty::printable(name),
            load.as_secs_f64() * 1e3
        )?;
        out.write_all(report.to_markdown().as_bytes())?;
        return Ok(());
    }
    // The plot is written after the (long) run: a folder that does not exist fails now.
    if let Some(dir) = a.svg.as_deref().and_then(std::path::Path::parent)
        && !dir.as_os_str().is_empty()
        && !dir.is_dir()
    {
        usage!(
            "--svg {}: the folder {} does not exist",
            a.svg.as_deref().unwrap_or(dir).display(),
            dir.display()
        );
    }
    let request = raytty::bench::BenchRequest {
        quick: a.quick,
        sizes: a.sizes,
        runs: a.runs,
        max_spp: a.max_spp,
        ref_spp: a.ref_spp,
        ref_bounces: a.ref_bounces,
        csv: a.csv,
        plot: a.plot,
        svg: a.svg,
        readme: a.readme,
        command: std::iter::once("raytty".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
    };
    raytty::bench::run_command(
        &raytty::cornell_box(),
        &request,
        &mut io::stdout().lock(),
        &mut io::stderr().lock(),
        &mut Bar::default(),
    )
    .map_err(bench_failure)
}

fn bench_failure(e: raytty::bench::BenchError) -> Failure {
    match e {
        raytty::bench::BenchError::Usage(m) => Failure::Usage(m),
        // The I/O error as the cause, said once (BenchError's own text repeats it).
        raytty::bench::BenchError::Io { what, error } => {
            Failure::Run(anyhow::Error::new(error).context(what))
        }
    }
}
