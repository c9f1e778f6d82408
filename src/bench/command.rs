//! `raytty bench` as a whole: options in, the table (or CSV) out, and the SVG and README files
//! written. The binary only parses the flags into a [`BenchRequest`].

use std::fmt;
use std::io::{self, Write};
use std::path::PathBuf;

use super::{BenchOptions, Progress, csv, markdown, rewrite_readme, run, svg};
use crate::image::MAX_PIXELS;
use crate::scene::Scene;

/// Refuses a bench size over [`MAX_PIXELS`], the cap every frame has, with a message that
/// names the flag.
pub fn check_sizes(sizes: &[(u32, u32)]) -> Result<(), BenchError> {
    for &(w, h) in sizes {
        if u64::from(w) * u64::from(h) > MAX_PIXELS {
            return Err(BenchError::Usage(format!(
                "--sizes {w}x{h} is too large: at most {MAX_PIXELS} pixels per size (e.g. 8192x8192)"
            )));
        }
    }
    Ok(())
}

/// What the user asked `raytty bench` for. `None` fields take the defaults of
/// [`BenchOptions::full`], or of [`BenchOptions::quick`] with `quick`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BenchRequest {
    /// Tiny sizes and few runs (for tests).
    pub quick: bool,
    /// Sizes in pixels (empty: the defaults).
    pub sizes: Vec<(u32, u32)>,
    /// Timed runs per row.
    pub runs: Option<u32>,
    /// Top of the GI samples ladder.
    pub max_spp: Option<u32>,
    /// The reference's samples per pixel.
    pub ref_spp: Option<u32>,
    /// The reference's maximum bounces.
    pub ref_bounces: Option<u32>,
    /// Print CSV instead of the Markdown table.
    pub csv: bool,
    /// Draw the error-against-time chart in the terminal after the table.
    pub plot: bool,
    /// Write the error-against-time plot here.
    pub svg: Option<PathBuf>,
    /// Rewrite the table between the bench markers of this README.
    pub readme: Option<PathBuf>,
    /// The command line, quoted in the table's heading.
    pub command: String,
}

impl BenchRequest {
    /// The options this request resolves to.
    pub fn options(&self) -> BenchOptions {
        let base = if self.quick {
            BenchOptions::quick()
        } else {
            BenchOptions::full()
        };
        BenchOptions {
            sizes: if self.sizes.is_empty() {
                base.sizes.clone()
            } else {
                self.sizes.clone()
            },
            runs: self.runs.unwrap_or(base.runs),
            max_spp: self.max_spp.unwrap_or(base.max_spp),
            ref_spp: self.ref_spp.unwrap_or(base.ref_spp),
            ref_bounces: self.ref_bounces.unwrap_or(base.ref_bounces),
            ..base
        }
    }
}

/// Why `raytty bench` failed.
#[derive(Debug)]
pub enum BenchError {
    /// The request itself is wrong (the user can fix it): exit status 2.
    Usage(String),
    /// Reading or writing a file failed.
    Io {
        /// What was being done, with the path.
        what: String,
        /// The error.
        error: io::Error,
    },
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BenchError::Usage(m) => f.write_str(m),
            BenchError::Io { what, error } => write!(f, "{what}: {error}"),
        }
    }
}

impl std::error::Error for BenchError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            BenchError::Usage(_) => None,
            BenchError::Io { error, .. } => Some(error),
        }
    }
}

fn io_error(what: impl Into<String>) -> impl FnOnce(io::Error) -> BenchError {
    let what = what.into();
    move |error| BenchError::Io { what, error }
}

/// Runs the bench on `scene`: the table (or CSV) goes to `out`, how each reference was made and
/// where it is cached to `log`, progress to `progress`, and the SVG and README to their files.
pub fn run_command(
    scene: &Scene,
    request: &BenchRequest,
    out: &mut dyn Write,
    log: &mut dyn Write,
    progress: &mut dyn Progress,
) -> Result<(), BenchError> {
    let options = request.options();
    check_sizes(&options.sizes)?;
    // Read the README before the long run, so that a wrong path fails at once.
    let readme = match &request.readme {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(io_error(format!("cannot read {}", path.display())))?;
            rewrite_readme(&text, "")
                .map_err(|m| BenchError::Usage(format!("{}: {m}", path.display())))?;
            Some((path, text))
        }
        None => None,
    };
    let report = run(scene, &options, progress).map_err(io_error(format!(
        "cannot cache the reference in {}",
        options.cache_dir.display()
    )))?;
    for r in &report.references {
        for note in &r.refused {
            writeln!(log, "raytty bench: {note}").map_err(io_error("stderr"))?;
        }
        writeln!(log, "raytty bench: {}", r.describe()).map_err(io_error("stderr"))?;
    }
    let mut table = markdown(&report, &request.command);
    if !request.csv {
        table.push('\n');
        table.push_str(&super::throughput::markdown(&throughputs(
            scene, request, &options,
        )));
    }
    if request.csv {
        out.write_all(csv(&report).as_bytes())
    } else {
        out.write_all(table.as_bytes())
    }
    .map_err(io_error("stdout"))?;
    if request.plot {
        writeln!(out)
            .and_then(|()| out.write_all(super::plot::plot(&report).as_bytes()))
            .map_err(io_error("stdout"))?;
    }
    if let Some(path) = &request.svg {
        std::fs::write(path, svg(&report))
            .map_err(io_error(format!("cannot write {}", path.display())))?;
    }
    if let Some((path, text)) = readme {
        let new = rewrite_readme(&text, &table)
            .map_err(|m| BenchError::Usage(format!("{}: {m}", path.display())))?;
        std::fs::write(path, new).map_err(io_error(format!("cannot write {}", path.display())))?;
    }
    Ok(())
}

/// The throughput section's measurements: `scene` at the first bench size, and (unless
/// `--quick`) the built-in 1M-triangle sphere at the same size.
fn throughputs(
    scene: &Scene,
    request: &BenchRequest,
    options: &BenchOptions,
) -> Vec<super::throughput::Throughput> {
    let (w, h) = options.sizes.first().copied().unwrap_or((500, 500));
    let mut out = vec![super::throughput::measure(scene, w, h, options.runs)];
    if !request.quick
        && let Some(Ok(sphere)) = crate::scene::builtin::find("sphere").map(|b| b.load())
    {
        out.push(super::throughput::measure(&sphere, w, h, options.runs));
    }
    out
}
