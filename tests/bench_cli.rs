//! `raytty bench --quick` end to end: the table's shape, the CSV, the SVG plot, the reference
//! cache, and the report file (stamped, holding what was printed).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh directory under the system's temporary directory, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("raytty-bench-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).expect("a temporary directory");
        TempDir(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn bench(cache: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytty"))
        .current_dir(cache)
        .arg("bench")
        .arg("--quick")
        .args(args)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .expect("raytty runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8(b.to_vec()).expect("UTF-8")
}

/// Rows per size: 5 seed stages, AA at 4 and 16 spp, GI at 4 bounce counts × the quick ladder
/// (1 and 4 spp), then stage 6 raw, raw with independent numbers, and denoised at 1 and 4 spp.
const ROWS_PER_SIZE: usize = 5 + 2 + 4 * 2 + 3 * 2;
const SIZES: usize = 2;

/// The estimators' rows: 3 scenes × 3 estimators at the quick bench's one count (4 spp), raw
/// and denoised.
const ESTIMATOR_ROWS: usize = 3 * 3 * 2;

/// The throughput section's table: header, alignment, and one row per ray kind (the quick
/// bench measures the Cornell box only).
const THROUGHPUT_LINES: usize = 2 + 4;

#[test]
fn the_table_has_every_row_and_column_and_the_reference_is_cached() {
    let dir = TempDir::new("table");
    let out = bench(&dir.0, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let (accuracy, throughput) = stdout
        .split_once("Ray throughput")
        .expect("a throughput section");
    let (accuracy, estimators) = accuracy
        .split_once("The physically based effects")
        .expect("an estimators section");
    // The estimators' table: each physically based scene by each estimator, at the quick
    // bench's 4 spp, raw and denoised, each with an error.
    let est: Vec<&str> = estimators.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(est.len(), 2 + ESTIMATOR_ROWS, "{stdout}");
    for row in &est[2..] {
        let cells: Vec<&str> = row.trim_matches('|').split('|').map(str::trim).collect();
        assert!(["area", "plates", "glass"].contains(&cells[0]), "{row}");
        assert!(["light", "bsdf", "mis"].contains(&cells[2]), "{row}");
        assert_eq!(cells[3], "4", "{row}");
        assert!(["no", "yes"].contains(&cells[4]), "{row}");
        let rmse: f64 = cells[8].parse().expect("RMSE is a number");
        assert!(rmse.is_finite() && rmse > 0.0, "{row}");
    }
    let table: Vec<&str> = accuracy.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(table.len(), 2 + SIZES * ROWS_PER_SIZE, "{stdout}");
    let rates: Vec<&str> = throughput.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(rates.len(), THROUGHPUT_LINES, "{stdout}");
    for (row, kind) in rates[2..]
        .iter()
        .zip(["primary", "shadow", "bounce", "reflection"])
    {
        let cells: Vec<&str> = row.trim_matches('|').split('|').map(str::trim).collect();
        assert_eq!(cells[0], "cornell", "{row}");
        assert_eq!(cells[4], kind, "{row}");
        for rate in &cells[6..] {
            assert!(rate.parse::<f64>().is_ok_and(|r| r > 0.0), "{row}");
        }
    }
    assert_eq!(
        table
            .iter()
            .filter(|l| l.contains("| GI + denoiser |"))
            .count(),
        2 * SIZES
    );
    assert_eq!(stdout.matches("\n- GI + denoiser at ").count(), SIZES);
    assert_eq!(
        table
            .iter()
            .filter(|l| l.contains("| GI, independent numbers |"))
            .count(),
        2 * SIZES
    );
    assert_eq!(
        stdout
            .matches("the scene's sampler against independent numbers: 1 spp RMSE ")
            .count(),
        SIZES
    );
    let header: Vec<&str> = table[0]
        .trim_matches('|')
        .split('|')
        .map(str::trim)
        .collect();
    assert_eq!(
        header,
        [
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
            "ANSI bytes"
        ]
    );
    for row in &table[2..] {
        let cells: Vec<&str> = row.trim_matches('|').split('|').map(str::trim).collect();
        assert_eq!(cells.len(), header.len(), "{row}");
        let rmse: f64 = cells[11].parse().expect("RMSE is a number");
        assert!(rmse.is_finite() && rmse > 0.0, "{row}");
        let primary: u64 = cells[6].parse().expect("a count");
        let spp: u64 = cells[2].parse().expect("spp");
        let (w, h) = cells[0].split_once('x').expect("WxH");
        let pixels = w.parse::<u64>().unwrap() * h.parse::<u64>().unwrap();
        assert_eq!(primary, spp * pixels, "{row}");
        assert!(cells[13].parse::<u64>().expect("bytes") > pixels, "{row}");
    }
    for name in [
        "flat",
        "light",
        "direct",
        "shadows",
        "indirect (seed, N = 0.5)",
    ] {
        assert_eq!(
            table
                .iter()
                .filter(|l| l.contains(&format!("| {name} |")))
                .count(),
            SIZES,
            "{name}"
        );
    }
    let gi_bounces: Vec<&str> = table
        .iter()
        .filter(|l| l.contains("| GI |"))
        .map(|l| l.split('|').nth(4).unwrap().trim())
        .collect();
    for b in ["1", "2", "4", "8"] {
        assert_eq!(gi_bounces.iter().filter(|&&x| x == b).count(), 2 * SIZES);
    }
    // The output says how the reference was made and where it is cached, and it is there.
    let cache = dir.0.join("raytty");
    assert!(stdout.contains("rendered in"), "{stdout}");
    assert!(stdout.contains(&cache.display().to_string()), "{stdout}");
    assert!(stdout.contains("the seed's constant N = 0.5 at 40x40: RMSE"));
    let cached = std::fs::read_dir(&cache).expect("the cache").count();
    assert_eq!(
        cached,
        SIZES + 3,
        "the Cornell box's at each size, the estimators' scenes'"
    );
    // The second run reads it back.
    let again = bench(&dir.0, &[]);
    assert!(again.status.success());
    assert!(text(&again.stdout).contains("read from the cache"));
    assert!(text(&again.stderr).contains("read from the cache"));
    // A corrupt cache file (a header whose size overflows) is refused with a message on
    // stderr, and rendered again.
    let file = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().contains("reference-cornell-40x40"))
        .expect("the Cornell box's 40x40 reference");
    std::fs::write(&file, "PF\n4294967295 4294967295\n-1.0\n\0\0\0\0").unwrap();
    let repaired = bench(&dir.0, &[]);
    let stderr = text(&repaired.stderr);
    assert!(repaired.status.success(), "{stderr}");
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        stderr
            .lines()
            .any(|l| l.contains(&name) && l.contains("refused") && l.contains("bytes of pixels")),
        "{stderr}"
    );
    assert!(stderr.contains("rendered in"), "{stderr}");
    assert!(std::fs::metadata(&file).unwrap().len() > 40 * 16 * 12);
}

#[test]
fn the_plot_draws_each_size_in_braille_with_every_series_marked() {
    let dir = TempDir::new("plot");
    let out = bench(&dir.0, &["--plot"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let (_, chart) = stdout
        .split_once("\n40x40: RMSE")
        .expect("a panel per size");
    assert!(chart.contains("\n32x16: RMSE"), "{chart}");
    assert!(
        chart
            .chars()
            .any(|c| ('\u{2801}'..='\u{28ff}').contains(&c)),
        "{chart}"
    );
    for mark in [
        "1 GI, 1 bounce",
        "D GI + denoiser",
        "I GI, independent numbers",
        "R GI, roulette",
        "+ goal",
    ] {
        assert_eq!(chart.matches(mark).count(), SIZES, "{mark}: {chart}");
    }
    // Every row's letter is drawn: the denoised rows (1 and 4 spp) per size at least.
    let plot_lines: Vec<&str> = chart.lines().filter(|l| l.contains('│')).collect();
    let ds: usize = plot_lines.iter().map(|l| l.matches('D').count()).sum();
    assert!(ds >= SIZES, "{chart}");
    assert!(
        plot_lines.iter().all(|l| l.chars().count() <= 80),
        "{chart}"
    );
}

#[test]
fn csv_has_a_header_and_one_line_per_row() {
    let dir = TempDir::new("csv");
    let out = bench(&dir.0, &["--csv"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1 + SIZES * ROWS_PER_SIZE);
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(header.len(), 17);
    assert_eq!(header[..3], ["width", "height", "row"]);
    for line in &lines[1..] {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 17, "{line}");
        for (name, v) in header.iter().zip(&f) {
            if !matches!(*name, "row" | "bounces" | "psnr_db") {
                assert!(v.parse::<f64>().is_ok(), "{name} = {v} in {line}");
            }
        }
    }
}

/// Checks that `svg` is well-formed XML as far as this writer goes: every tag closed in order,
/// attributes quoted, no stray `<` or `&` in text. Returns the element names in order.
fn elements(svg: &str) -> Vec<String> {
    let mut stack: Vec<String> = Vec::new();
    let mut names = Vec::new();
    let mut rest = svg;
    while let Some(open) = rest.find('<') {
        let text = &rest[..open];
        assert!(!text.contains('>'), "stray > in text {text:?}");
        for (i, _) in text.match_indices('&') {
            let t = &text[i..];
            assert!(
                ["&amp;", "&lt;", "&gt;"].iter().any(|e| t.starts_with(e)),
                "bare & in {text:?}"
            );
        }
        let close = rest[open..].find('>').expect("an unclosed tag") + open;
        let tag = &rest[open + 1..close];
        assert!(
            tag.matches('"').count().is_multiple_of(2),
            "unbalanced quotes in <{tag}>"
        );
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name), "mismatched </{name}>");
        } else {
            let name: String = tag
                .chars()
                .take_while(|c| !c.is_whitespace() && *c != '/')
                .collect();
            names.push(name.clone());
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        rest = &rest[close + 1..];
    }
    assert!(stack.is_empty(), "unclosed {stack:?}");
    assert!(rest.trim().is_empty());
    names
}

#[test]
fn the_svg_is_well_formed_with_one_polyline_per_bounce_count() {
    let dir = TempDir::new("svg");
    let path = dir.0.join("plot.svg");
    let out = bench(&dir.0, &["--svg", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let svg = std::fs::read_to_string(&path).expect("the SVG was written");
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    let names = elements(&svg);
    assert_eq!(names[0], "svg");
    // Raw GI at 1, 2, 4, 8 and stage 6's roulette cap (16) bounces, stage 6 with independent
    // numbers, and GI + denoiser.
    assert_eq!(names.iter().filter(|n| *n == "polyline").count(), 7 * SIZES);
    assert_eq!(svg.matches("polyline class=\"denoised\"").count(), SIZES);
    assert_eq!(svg.matches("polyline class=\"independent\"").count(), SIZES);
    for b in [1, 2, 4, 8, 16] {
        let tag = format!("class=\"gi\" data-bounces=\"{b}\" points=\"");
        let lines: Vec<&str> = svg.lines().filter(|l| l.contains(&tag)).collect();
        assert_eq!(lines.len(), SIZES, "{b} bounces");
        for l in lines {
            let points = l.split(&tag).nth(1).unwrap().split('"').next().unwrap();
            let pts: Vec<&str> = points.split(' ').collect();
            assert_eq!(pts.len(), 2, "the ladder 1, 4: {l}");
            for p in pts {
                let (x, y) = p.split_once(',').expect("x,y");
                assert!(x.parse::<f64>().unwrap().is_finite());
                assert!(y.parse::<f64>().unwrap().is_finite());
            }
        }
    }
    // The seed's stages are points: 5 stages + 2 AA rows per size (+ one legend square each).
    assert_eq!(svg.matches("class=\"stage\"").count(), 7 * SIZES);
}

#[test]
fn the_report_is_stamped_and_holds_the_printed_tables() {
    let dir = TempDir::new("report");
    std::fs::create_dir(dir.0.join("docs")).unwrap();
    let path = dir.0.join("docs/performance.md");
    std::fs::write(&path, "an old report\n").unwrap();
    let out = bench(
        &dir.0,
        &["--report", "docs/performance.md", "--svg", "docs/bench.svg"],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = std::fs::read_to_string(&path).unwrap();
    let stdout = text(&out.stdout);
    assert!(report.starts_with("# Performance\n"), "{report}");
    assert!(!report.contains("an old report"));
    // The chart is linked from the report's folder, and the report ends with what was printed.
    assert!(report.contains("](bench.svg)"), "{report}");
    assert!(dir.0.join("docs/bench.svg").is_file());
    assert!(report.ends_with(&stdout), "{report}");
    assert_eq!(
        report.lines().filter(|l| l.starts_with('|')).count(),
        2 + SIZES * ROWS_PER_SIZE + 2 + ESTIMATOR_ROWS + THROUGHPUT_LINES
    );
    // The stamp: the date, the commit (no git checkout here: the crate's version), the machine
    // and the command.
    let stamp = |name: &str| {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(&format!("- {name}: ")))
            .unwrap_or_else(|| panic!("no {name} in {stdout}"))
            .to_string()
    };
    assert!(stamp("Date").ends_with(" UTC"));
    assert_eq!(
        stamp("Commit"),
        format!("raytty {}", env!("CARGO_PKG_VERSION"))
    );
    let machine = stamp("Machine");
    assert!(
        machine.contains(" cores, SIMD path ") && machine.ends_with(" threads"),
        "{machine}"
    );
    assert!(stamp("Command").contains("--report docs/performance.md"));
}

#[test]
fn a_report_in_a_missing_folder_or_a_bad_size_is_a_usage_error() {
    let dir = TempDir::new("bad");
    let out = bench(&dir.0, &["--report", "nowhere/performance.md"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("the folder nowhere does not exist"),
        "{}",
        text(&out.stderr)
    );
    // Nothing was rendered, so nothing was cached.
    assert!(!dir.0.join("raytty").exists());
    for bad in [
        &["--sizes", "0x10"][..],
        &["--sizes", "10"],
        &["--runs", "0"],
        &["--max-spp", "x"],
        &["--report", "r.md", "--csv"],
    ] {
        let out = bench(&dir.0, bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(!text(&out.stderr).contains("panicked"), "{bad:?}");
    }
}
