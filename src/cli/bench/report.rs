//! The bench's text outputs: where and when it ran (the stamp), the Markdown tables (accuracy,
//! throughput, a scene's frames), CSV, and the report file (docs/performance.md).

use std::fmt::Write as _;
use std::process::Command;

use raytty::bench::ReferenceInfo;
use raytty::bench::estimators::EstimatorRow;
use raytty::bench::scene::SceneBench;
use raytty::bench::throughput::Throughput;
use raytty::bench::timing::ms;
use raytty::bench::{BenchReport, Environment, GI_BOUNCES, Row, RowKind};
use raytty::shading::{GI_MAX_BOUNCES, Stage};

use super::table::{Align, Table};

/// The columns of the Markdown table, in order.
pub const COLUMNS: [&str; 14] = [
    "size",
    "row",
    "spp",
    "bounces",
    "median ms",
    "min–max ms (runs)",
    "primary",
    "shadow",
    "bounce",
    "reflection",
    "M rays/s",
    "RMSE",
    "PSNR dB",
    "ANSI bytes",
];

/// The accuracy table, followed by how each reference was made and where it is cached, and a
/// few figures read off the rows.
pub fn markdown(report: &BenchReport) -> String {
    let mut s = String::new();
    let mut table = Table::new(COLUMNS.iter().map(|&c| {
        let align = match c {
            "size" | "row" => Align::Left,
            _ => Align::Right,
        };
        (c, align)
    }));
    for r in &report.rows {
        table.row(cells(r));
    }
    s.push_str(&table.to_markdown());
    s.push('\n');
    for info in &report.references {
        let _ = writeln!(s, "- {}", info.describe());
    }
    for (w, h) in sizes(report) {
        let denoised: Vec<&Row> = report
            .rows
            .iter()
            .filter(|r| (r.width, r.height) == (w, h) && matches!(r.kind, RowKind::Denoised { .. }))
            .collect();
        if denoised.is_empty() {
            continue;
        }
        let each: Vec<String> = denoised
            .iter()
            .map(|r| {
                format!(
                    "{} spp {:.1} ms RMSE {:.4}",
                    r.kind.spp(),
                    r.median_ms,
                    r.rmse
                )
            })
            .collect();
        let goal = denoised
            .iter()
            .find(|r| r.median_ms <= GOAL_MS && r.rmse <= GOAL_RMSE)
            .map_or("not met".to_string(), |r| {
                format!("met at {} spp", r.kind.spp())
            });
        let _ = writeln!(
            s,
            "- GI + denoiser at {w}x{h}: {}; the goal of a frame in ≤ {GOAL_MS} ms at RMSE ≤ \
             {GOAL_RMSE}: {goal}",
            each.join(", ")
        );
    }
    for (w, h) in sizes(report) {
        let pairs: Vec<String> = report
            .rows
            .iter()
            .filter(|r| (r.width, r.height) == (w, h))
            .filter_map(|i| {
                let RowKind::Independent { spp } = i.kind else {
                    return None;
                };
                let own = report.rows.iter().find(|r| {
                    (r.width, r.height) == (w, h)
                        && r.kind
                            == RowKind::Gi {
                                bounces: GI_MAX_BOUNCES,
                                spp,
                            }
                })?;
                Some(format!(
                    "{spp} spp RMSE {:.4} in {:.1} ms against {:.4} in {:.1} ms",
                    own.rmse, own.median_ms, i.rmse, i.median_ms
                ))
            })
            .collect();
        if !pairs.is_empty() {
            let _ = writeln!(
                s,
                "- stage 6 raw at {w}x{h}, the scene's sampler against independent numbers: {}",
                pairs.join(", ")
            );
        }
    }
    for seed in report
        .rows
        .iter()
        .filter(|r| r.kind == RowKind::Stage(Stage::Indirect))
    {
        let _ = writeln!(
            s,
            "- the seed's constant N = 0.5 at {}x{}: RMSE {:.4}, PSNR {} dB against the reference",
            seed.width,
            seed.height,
            seed.rmse,
            psnr(seed.psnr)
        );
        let rate: Vec<String> = GI_BOUNCES
            .iter()
            .filter_map(|&b| {
                report
                    .rows
                    .iter()
                    .filter(|r| {
                        (r.width, r.height) == (seed.width, seed.height)
                            && r.kind.raw_bounces() == Some(b)
                    })
                    .max_by_key(|r| r.kind.spp())
            })
            .map(|r| {
                let samples = f64::from(r.width) * f64::from(r.height) * f64::from(r.kind.spp());
                format!(
                    "{:.2} M/s with {} bounce{} ({} spp)",
                    samples / (r.median_ms * 1e-3).max(1e-9) / 1e6,
                    r.kind.bounces().unwrap_or(0),
                    if r.kind.bounces() == Some(1) { "" } else { "s" },
                    r.kind.spp()
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "- at {}x{} the seed's frame takes {:.1} ms; GI samples per second: {}",
            seed.width,
            seed.height,
            seed.median_ms,
            rate.join(", ")
        );
    }
    s
}

/// Stage 6's goal for a frame while keys are held (issue 12): this long at most…
pub const GOAL_MS: f64 = 33.0;
/// …at this RMSE at most.
pub const GOAL_RMSE: f64 = 0.03;

/// The sizes of a report's rows, in order of appearance.
pub fn sizes(report: &BenchReport) -> Vec<(u32, u32)> {
    let mut sizes: Vec<(u32, u32)> = Vec::new();
    for r in &report.rows {
        if !sizes.contains(&(r.width, r.height)) {
            sizes.push((r.width, r.height));
        }
    }
    sizes
}

/// The table's cells of one row.
fn cells(r: &Row) -> Vec<String> {
    vec![
        format!("{}x{}", r.width, r.height),
        r.kind.label(),
        r.kind.spp().to_string(),
        r.kind.bounces().map_or(String::new(), |b| b.to_string()),
        format!("{:.1}", r.median_ms),
        format!("{:.1}–{:.1} ({})", r.min_ms, r.max_ms, r.runs),
        r.rays.primary.to_string(),
        r.rays.shadow.to_string(),
        r.rays.bounce.to_string(),
        r.rays.reflection.to_string(),
        format!("{:.1}", r.mrays_per_s),
        format!("{:.4}", r.rmse),
        psnr(r.psnr),
        r.ansi_bytes.to_string(),
    ]
}

fn psnr(p: f64) -> String {
    if p.is_finite() {
        format!("{p:.1}")
    } else {
        "inf".into()
    }
}

/// CSV: a header, then one line per row, with width and height in separate columns and the
/// times split into median, min and max. No field needs quoting.
pub fn csv(report: &BenchReport) -> String {
    let mut s = String::from(
        "width,height,row,spp,bounces,runs,median_ms,min_ms,max_ms,primary,shadow,bounce,reflection,\
         mrays_per_s,rmse,psnr_db,ansi_bytes\n",
    );
    for r in &report.rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.3},{:.3},{:.3},{},{},{},{},{:.3},{:.6},{},{}",
            r.width,
            r.height,
            r.kind.label().replace(',', ";"),
            r.kind.spp(),
            r.kind.bounces().map_or(String::new(), |b| b.to_string()),
            r.runs,
            r.median_ms,
            r.min_ms,
            r.max_ms,
            r.rays.primary,
            r.rays.shadow,
            r.rays.bounce,
            r.rays.reflection,
            r.mrays_per_s,
            r.rmse,
            if r.psnr.is_finite() {
                format!("{:.3}", r.psnr)
            } else {
                "inf".into()
            },
            r.ansi_bytes
        );
    }
    s
}

/// Where, when and from what the numbers came.
pub struct Stamp<'a> {
    /// The measurements' environment.
    pub environment: &'a Environment,
    /// `git rev-parse --short HEAD` where the bench ran, or else the crate's version.
    pub commit: String,
    /// The command line.
    pub command: &'a str,
}

impl<'a> Stamp<'a> {
    /// The stamp of a bench that just ran: the commit asked of git now.
    pub fn now(environment: &'a Environment, command: &'a str) -> Stamp<'a> {
        let git = Command::new("git")
            .args(["rev-parse", "--short", "HEAD"])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty());
        Stamp {
            environment,
            commit: git.unwrap_or_else(|| format!("raytty {}", env!("CARGO_PKG_VERSION"))),
            command,
        }
    }

    /// The stamp as a Markdown list.
    pub fn markdown(&self) -> String {
        let e = self.environment;
        let load = e.load.map_or("not reported".to_string(), |(a, b)| {
            format!("{a:.2} at the start, {b:.2} at the end")
        });
        format!(
            "- Date: {}\n- Commit: {}\n- Machine: {}, {} cores, SIMD path {}, {} threads\n\
             - Load average: {load}\n- Command: `{}`\n",
            e.date, self.commit, e.machine, e.cores, e.simd, e.threads, self.command
        )
    }
}

/// What `raytty bench` prints: the stamp, the accuracy table, the estimators' table and the
/// throughput table.
pub fn body(
    report: &BenchReport,
    estimators: &(Vec<EstimatorRow>, Vec<ReferenceInfo>),
    rates: &[Throughput],
    stamp: &Stamp,
) -> String {
    let mut s = stamp.markdown();
    s.push('\n');
    s.push_str(&markdown(report));
    s.push('\n');
    s.push_str(&estimator_markdown(&estimators.0, &estimators.1));
    s.push('\n');
    s.push_str(&throughput_markdown(rates));
    s
}

/// The price of the physically based effects: a heading line, a table of each scene,
/// estimator and sample count (raw and denoised), and how the references were made.
pub fn estimator_markdown(rows: &[EstimatorRow], refs: &[ReferenceInfo]) -> String {
    let mut s = String::new();
    let Some(first) = rows.first() else {
        return s;
    };
    let _ = writeln!(
        s,
        "The physically based effects, each by light sampling alone, BSDF sampling alone and \
         MIS (the hidden `render --estimator`), raw and denoised, at {}x{}, against each scene's reference \
         (values clamped to 0..1, as a display shows them: the lights' own pixels, ~20, \
         would otherwise outweigh the rest; block RMSE: of 10x10-pixel means; time × RMSE²: \
         lower is more accuracy per second):\n",
        first.width, first.height
    );
    let mut table = Table::new([
        ("scene", Align::Left),
        ("effects", Align::Left),
        ("estimator", Align::Left),
        ("spp", Align::Right),
        ("denoised", Align::Left),
        ("median ms (runs)", Align::Right),
        ("shadow", Align::Right),
        ("bounce", Align::Right),
        ("RMSE", Align::Right),
        ("block RMSE", Align::Right),
        ("time × RMSE²", Align::Right),
    ]);
    for r in rows {
        // (The estimator has its own column: "area lights (mis)" is said as "area lights".)
        let effects: Vec<&str> = r
            .effects
            .iter()
            .filter(|e| **e != "path")
            .map(|e| {
                if e.starts_with("area lights") {
                    "area lights"
                } else {
                    e
                }
            })
            .collect();
        table.row([
            r.scene.clone(),
            effects.join(", "),
            r.estimator.name().to_string(),
            r.spp.to_string(),
            (if r.denoised { "yes" } else { "no" }).to_string(),
            format!("{:.1} ({})", r.median_ms, r.runs),
            r.rays.shadow.to_string(),
            r.rays.bounce.to_string(),
            format!("{:.4}", r.rmse),
            format!("{:.5}", r.block_rmse),
            format!("{:.2e}", r.efficiency()),
        ]);
    }
    s.push_str(&table.to_markdown());
    s.push('\n');
    for r in refs {
        let _ = writeln!(s, "- {}", r.describe());
    }
    s
}

/// The report file: a title, what it is and how to read it, the chart (`chart`, the SVG's path
/// relative to the report) and `body`.
pub fn document(body: &str, chart: Option<&str>) -> String {
    let mut s = String::from(
        "# Performance\n\n\
         Written by `raytty bench --report` (the command is below): run it again rather than \
         edit this file.\n\n\
         Each row renders the Cornell box at one size with one set of effects, once as a \
         warm-up and then at least 5 timed times (fast rows until they add up to 0.5 s), and \
         compares the image with a path-traced reference, rendered once and cached. The ray \
         counts and the errors are exact and do not depend on the machine; the times do.\n\n",
    );
    if let Some(path) = chart {
        let _ = writeln!(s, "![Error against time, log axes]({path})\n");
    }
    s.push_str(body);
    s
}

/// The throughput section: a heading line and one Markdown table, a row per scene and kind.
pub fn throughput_markdown(results: &[Throughput]) -> String {
    let mut s = String::new();
    let Some(first) = results.first() else {
        return s;
    };
    let _ = writeln!(
        s,
        "Ray throughput (tracing only, no shading; SIMD path: {}; `all` = {} threads):\n",
        first.isa.name(),
        first.threads
    );
    let mut table = Table::new([
        ("scene", Align::Left),
        ("triangles", Align::Right),
        ("structure", Align::Left),
        ("rays from", Align::Left),
        ("kind", Align::Left),
        ("rays", Align::Right),
        ("M rays/s, 1 thread", Align::Right),
        ("M rays/s, all", Align::Right),
    ]);
    for t in results {
        for k in &t.kinds {
            table.row([
                t.scene.clone(),
                t.triangles.to_string(),
                t.accel.to_string(),
                format!("{}×{}", t.width, t.height),
                k.kind.to_string(),
                k.rays.to_string(),
                format!("{:.2}", k.one_thread),
                format!("{:.2}", k.all_threads),
            ]);
        }
    }
    s.push_str(&table.to_markdown());
    s
}

/// `raytty bench --scene`'s report: one line on the structure, a table of frame times.
pub fn scene_markdown(b: &SceneBench) -> String {
    let a = &b.accel;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Scene `{}`: {} triangles, {} ({} nodes, depth {}), built in {:.1} ms; {} threads.\n",
        b.scene,
        a.triangles,
        a.kind.name(),
        a.nodes,
        a.depth,
        ms(a.build),
        b.threads
    );
    let mut table = Table::new([
        ("size", Align::Left),
        ("runs", Align::Right),
        ("median ms", Align::Right),
        ("min ms", Align::Right),
        ("max ms", Align::Right),
        ("rays/frame", Align::Right),
        ("M rays/s", Align::Right),
    ]);
    for z in &b.sizes {
        table.row([
            format!("{}×{}", z.width, z.height),
            z.runs.to_string(),
            format!("{:.2}", ms(z.median)),
            format!("{:.2}", ms(z.min)),
            format!("{:.2}", ms(z.max)),
            z.rays.to_string(),
            format!("{:.2}", z.mrays_per_s()),
        ]);
    }
    s.push_str(&table.to_markdown());
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_report_has_a_line_per_size() {
        let b = raytty::bench::scene::bench_scene(&raytty::cornell_box(), &[(8, 4), (16, 8)], 3);
        let md = scene_markdown(&b);
        assert!(
            md.contains("| 8×4 | 3 |") && md.contains("| 16×8 | 3 |"),
            "{md}"
        );
        assert!(md.starts_with("Scene `cornell`: 30 triangles"), "{md}");
    }

    #[test]
    fn the_document_links_the_chart_and_keeps_the_body() {
        let doc = document("- Date: x\n", Some("bench.svg"));
        assert!(doc.starts_with("# Performance\n"));
        assert!(doc.contains("](bench.svg)"));
        assert!(doc.ends_with("- Date: x\n"));
        assert!(!document("b", None).contains("]("));
    }
}
