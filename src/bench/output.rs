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

/// Series colours of the GI polylines, by bounce count (1, 2, 4, 8, then cycling).
const COLOURS: [&str; 6] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
];

/// The denoised series' colour, apart from the raw ones'.
const DENOISED_COLOUR: &str = "#e6007e";

const PANEL_W: f64 = 520.0;
const PANEL_H: f64 = 400.0;
/// Vertical distance between two labels' baselines, in pixels (the font is 11 px).
const LABEL_GAP: f64 = 12.0;

/// Plot margins inside a panel: left (y labels), right, top (title), bottom (x labels).
const MARGIN: (f64, f64, f64, f64) = (64.0, 150.0, 36.0, 44.0);

/// The error against time, on log axes: one panel per size, one polyline per GI bounce count
/// (its points are the spp ladder), the seed's stages and anti-aliasing as labelled points.
pub fn svg(report: &BenchReport) -> String {
    let sizes = sizes(report);
    let width = PANEL_W * sizes.len().max(1) as f64;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{PANEL_H}" viewBox="0 0 {width} {PANEL_H}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(
        s,
        r#"<rect width="{width}" height="{PANEL_H}" fill="white"/>"#
    );
    for (i, &(w, h)) in sizes.iter().enumerate() {
        let rows: Vec<&Row> = report
            .rows
            .iter()
            .filter(|r| (r.width, r.height) == (w, h))
            .collect();
        panel(&mut s, i as f64 * PANEL_W, w, h, &rows);
    }
    s.push_str("</svg>\n");
    s
}

/// Powers of ten from just below `lo` to just above `hi` (log10 values).
fn decades(lo: f64, hi: f64) -> (f64, f64) {
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    if b > a { (a, b) } else { (a, a + 1.0) }
}

fn panel(s: &mut String, x0: f64, w: u32, h: u32, rows: &[&Row]) {
    let pos = |v: f64| v.max(1e-9);
    let (tx0, tx1) = decades(
        rows.iter()
            .map(|r| pos(r.median_ms))
            .fold(f64::INFINITY, f64::min),
        rows.iter().map(|r| pos(r.median_ms)).fold(0.0, f64::max),
    );
    let (ey0, ey1) = decades(
        rows.iter()
            .map(|r| pos(r.rmse))
            .fold(f64::INFINITY, f64::min),
        rows.iter().map(|r| pos(r.rmse)).fold(0.0, f64::max),
    );
    let (ml, mr, mt, mb) = MARGIN;
    let (px0, px1) = (x0 + ml, x0 + PANEL_W - mr);
    let (py0, py1) = (mt, PANEL_H - mb);
    let x = |ms: f64| px0 + (pos(ms).log10() - tx0) / (tx1 - tx0) * (px1 - px0);
    let y = |e: f64| py1 - (pos(e).log10() - ey0) / (ey1 - ey0) * (py1 - py0);

    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="20" font-size="13" font-weight="bold">{w}×{h}: error against time per frame</text>"#,
        px0
    );
    let _ = writeln!(
        s,
        r##"<rect x="{px0:.1}" y="{py0:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#444"/>"##,
        px1 - px0,
        py1 - py0
    );
    // Decade grid lines and labels.
    for k in tx0 as i32..=tx1 as i32 {
        let gx = x(10f64.powi(k));
        let _ = writeln!(
            s,
            r##"<line x1="{gx:.1}" y1="{py0:.1}" x2="{gx:.1}" y2="{py1:.1}" stroke="#ddd"/><text x="{gx:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            py1 + 14.0,
            tick(k)
        );
    }
    for k in ey0 as i32..=ey1 as i32 {
        let gy = y(10f64.powi(k));
        let _ = writeln!(
            s,
            r##"<line x1="{px0:.1}" y1="{gy:.1}" x2="{px1:.1}" y2="{gy:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            px0 - 4.0,
            gy + 4.0,
            tick(k)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">median ms per frame (log)</text>"#,
        (px0 + px1) / 2.0,
        PANEL_H - 8.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="middle">RMSE vs reference (log)</text>"#,
        x0 + 14.0,
        (py0 + py1) / 2.0
    );

    // One polyline per series: raw GI by bounce count, then GI + denoiser.
    let series = series(rows);
    for (i, (name, class, members)) in series.iter().enumerate() {
        let colour = if *class == "denoised" {
            DENOISED_COLOUR
        } else {
            COLOURS[i % COLOURS.len()]
        };
        let pts: Vec<String> = members
            .iter()
            .map(|r| format!("{:.1},{:.1}", x(r.median_ms), y(r.rmse)))
            .collect();
        let bounces = members.first().and_then(|r| r.kind.bounces()).unwrap_or(0);
        let _ = writeln!(
            s,
            r#"<polyline class="{class}" data-bounces="{bounces}" points="{}" fill="none" stroke="{colour}" stroke-width="1.5"/>"#,
            pts.join(" ")
        );
        for r in members {
            let _ = writeln!(
                s,
                r#"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="{colour}"><title>{}, {} spp: {:.1} ms, RMSE {:.4}</title></circle>"#,
                x(r.median_ms),
                y(r.rmse),
                escape(name),
                r.kind.spp(),
                r.median_ms,
                r.rmse
            );
        }
        let ly = py0 + 14.0 + 16.0 * i as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{colour}" stroke-width="2"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            px1 + 10.0,
            px1 + 30.0,
            px1 + 34.0,
            ly + 4.0,
            escape(name)
        );
    }
    // The seed's stages and anti-aliasing: labelled points. Labels that would overlap (points
    // close in time and error) are pushed down, top to bottom.
    let mut points: Vec<(f64, f64, String)> = rows
        .iter()
        .filter_map(|r| {
            let label = match r.kind {
                RowKind::Aa { spp } => format!("AA {spp} spp"),
                RowKind::Stage(st) => st.name().to_string(),
                RowKind::Gi { .. } | RowKind::Denoised { .. } => return None,
            };
            Some((x(r.median_ms), y(r.rmse), label))
        })
        .collect();
    points.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut placed: Vec<(f64, f64, f64)> = Vec::new(); // label x from, x to, baseline
    for (cx, cy, label) in points {
        let width = 6.0 * label.chars().count() as f64;
        // Right of the point, or left of it where the plot's right edge is near.
        let lx = if cx + 5.0 + width > px1 {
            cx - 5.0 - width
        } else {
            cx + 5.0
        };
        let mut ly = cy - 4.0;
        for &(x0, x1, y0) in &placed {
            if lx < x1 && x0 < lx + width && ly < y0 + LABEL_GAP {
                ly = y0 + LABEL_GAP;
            }
        }
        placed.push((lx, lx + width, ly));
        let _ = writeln!(
            s,
            r##"<rect class="stage" x="{:.1}" y="{:.1}" width="5" height="5" fill="#222"/><text x="{lx:.1}" y="{ly:.1}" fill="#222">{}</text>"##,
            cx - 2.5,
            cy - 2.5,
            escape(&label)
        );
    }
    let ly = py0 + 14.0 + 16.0 * series.len() as f64;
    let _ = writeln!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="5" height="5" fill="#222"/><text x="{:.1}" y="{:.1}">seed stages, AA</text>"##,
        px1 + 17.5,
        ly - 2.5,
        px1 + 34.0,
        ly + 4.0
    );
}

/// The plotted series of one size's rows, in order: raw GI by bounce count (its points are
/// the spp ladder), then GI + denoiser. Each is (legend, SVG class, rows).
pub fn series<'a>(rows: &[&'a Row]) -> Vec<(String, &'static str, Vec<&'a Row>)> {
    let mut out: Vec<(String, &'static str, Vec<&'a Row>)> = Vec::new();
    let mut bounces: Vec<u32> = rows.iter().filter_map(|r| r.kind.raw_bounces()).collect();
    bounces.sort_unstable();
    bounces.dedup();
    for b in bounces {
        let members = rows
            .iter()
            .filter(|r| r.kind.raw_bounces() == Some(b))
            .copied()
            .collect();
        let name = if b == crate::shading::GI_MAX_BOUNCES {
            format!("GI, roulette, ≤ {b} bounces")
        } else {
            format!("GI, {b} bounce{}", if b == 1 { "" } else { "s" })
        };
        out.push((name, "gi", members));
    }
    let denoised: Vec<&Row> = rows
        .iter()
        .filter(|r| matches!(r.kind, RowKind::Denoised { .. }))
        .copied()
        .collect();
    if !denoised.is_empty() {
        out.push(("GI + denoiser".into(), "denoised", denoised));
    }
    out
}

/// A decade's label: 10^k written out for small k, else as 1e±k.
fn tick(k: i32) -> String {
    match k {
        0..=5 => format!("{}", 10u64.pow(k as u32)),
        -3..=-1 => format!("{}", 10f64.powi(k)),
        _ => format!("1e{k}"),
    }
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
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

    #[test]
    fn ticks() {
        assert_eq!(tick(0), "1");
        assert_eq!(tick(3), "1000");
        assert_eq!(tick(-2), "0.01");
        assert_eq!(tick(-5), "1e-5");
    }
}
