//! The error-against-time plot as a hand-written SVG: one panel per size, log axes, a polyline
//! per bounce count and the seed's stages as points.

use std::fmt::Write as _;

use super::report::sizes;
use raytty::bench::{BenchReport, Row, RowKind};

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
                RowKind::Gi { .. } | RowKind::Independent { .. } | RowKind::Denoised { .. } => {
                    return None;
                }
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
/// the spp ladder), stage 6 raw with independent numbers, then GI + denoiser. Each is
/// (legend, SVG class, rows).
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
        let name = if b == raytty::shading::GI_MAX_BOUNCES {
            format!("GI, roulette, ≤ {b} bounces")
        } else {
            format!("GI, {b} bounce{}", if b == 1 { "" } else { "s" })
        };
        out.push((name, "gi", members));
    }
    let independent: Vec<&Row> = rows
        .iter()
        .filter(|r| matches!(r.kind, RowKind::Independent { .. }))
        .copied()
        .collect();
    if !independent.is_empty() {
        out.push(("GI, independent numbers".into(), "independent", independent));
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
pub(super) fn tick(k: i32) -> String {
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
    fn ticks() {
        assert_eq!(tick(0), "1");
        assert_eq!(tick(3), "1000");
        assert_eq!(tick(-2), "0.01");
        assert_eq!(tick(-5), "1e-5");
    }
}
