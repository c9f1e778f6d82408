//! The bench's outputs: a Markdown table, CSV, an SVG plot of error against time, and the
//! README block between its markers.

use std::fmt::Write as _;

use super::table::{Align, Table};
use super::{BenchReport, Row, RowKind};

/// The README's markers: [`rewrite_readme`] replaces what lies between them.
pub const README_START: &str = "<!-- bench:start -->";
/// See [`README_START`].
pub const README_END: &str = "<!-- bench:end -->";

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

/// The Markdown table, preceded by where and when it was measured (`command` is what produced
/// it) and followed by how each reference was made and where it is cached.
pub fn markdown(report: &BenchReport, command: &str) -> String {
    let env = &report.environment;
    let mut s = String::new();
    let load = env.load.map_or(String::new(), |(a, b)| {
        format!(", load average {a:.2} at the start and {b:.2} at the end")
    });
    let _ = writeln!(
        s,
        "Measured {} on {}, {} threads{load}, with `{command}`.\n",
        env.date, env.machine, env.threads
    );
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
                                bounces: crate::shading::GI_MAX_BOUNCES,
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
        .filter(|r| r.kind == RowKind::Stage(crate::shading::Stage::Indirect))
    {
        let _ = writeln!(
            s,
            "- the seed's constant N = 0.5 at {}x{}: RMSE {:.4}, PSNR {} dB against the reference",
            seed.width,
            seed.height,
            seed.rmse,
            psnr(seed.psnr)
        );
        let rate: Vec<String> = crate::bench::GI_BOUNCES
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

/// Replaces what lies between the README's markers with `block`, keeping the markers and
/// everything outside them byte for byte. An error says which marker is missing or misplaced.
pub fn rewrite_readme(readme: &str, block: &str) -> Result<String, String> {
    let start = readme
        .find(README_START)
        .ok_or_else(|| format!("no {README_START} marker"))?;
    let end = readme
        .find(README_END)
        .ok_or_else(|| format!("no {README_END} marker"))?;
    let inner = start + README_START.len();
    if end < inner {
        return Err(format!("{README_END} comes before {README_START}"));
    }
    if readme[end + README_END.len()..].contains(README_START)
        || readme[inner..].contains(README_START)
    {
        return Err(format!("more than one {README_START} marker"));
    }
    Ok(format!(
        "{}\n{}\n{}",
        &readme[..inner],
        block.trim_end(),
        &readme[end..]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readme_changes_only_between_the_markers() {
        let before =
            "# Title\n\ntext\n<!-- bench:start -->\nold table\n<!-- bench:end -->\nafter\n";
        let after = rewrite_readme(before, "new | table\n").unwrap();
        assert_eq!(
            after,
            "# Title\n\ntext\n<!-- bench:start -->\nnew | table\n<!-- bench:end -->\nafter\n"
        );
        assert_eq!(rewrite_readme(&after, "new | table").unwrap(), after);
        assert!(rewrite_readme("no markers", "x").is_err());
        assert!(rewrite_readme("<!-- bench:end --> <!-- bench:start -->", "x").is_err());
        assert!(
            rewrite_readme(
                "<!-- bench:start --><!-- bench:end --><!-- bench:start -->",
                "x"
            )
            .is_err()
        );
    }
}
