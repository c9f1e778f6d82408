//! The view: frame sizes, the status line's fields, tolerance under a byte budget.

use super::*;
use crate::tui::app::{Message, update};
use crate::tui::detect::Protocol;
use glam::Vec3;
use raytty::{ColorMode, cornell_box};

fn app(cols: u16, rows: u16) -> App {
    App::new(cornell_box(), ColorMode::TrueColor, (cols, rows))
}

#[test]
fn a_light_move_traces_no_primary_ray() {
    let mut a = app(40, 13);
    let mut s = Screen::new();
    s.render(&a);
    assert_eq!(s.stats.render.rays.primary, 40 * 24);
    let before = s.draw(&a);
    update(&mut a, Message::MoveLight(Vec3::new(0.1, 0.0, 0.0)));
    assert!(s.needs_render(&a));
    s.render(&a);
    let r = s.stats.render.rays;
    assert_eq!(r.primary, 0, "a light move re-traced primary rays");
    assert!(r.shadow > 0, "a light move traces shadow rays");
    let after = s.draw(&a);
    assert!(!after.is_empty() && after.len() < before.len());
    update(&mut a, Message::Walk(0.1));
    s.render(&a);
    assert_eq!(s.stats.render.rays.primary, 40 * 24);
}

#[test]
fn over_a_budget_a_move_is_approximate_then_refines_to_exact() {
    let mut a = app(60, 20);
    let mut s = Screen::new();
    s.render(&a);
    s.draw(&a);
    s.link = LinkView {
        budget: Some(1500),
        rate: Some(30_000.0),
    };
    update(&mut a, Message::MoveLight(Vec3::new(0.0, 0.0, 0.3)));
    s.render(&a);
    let first = s.draw(&a);
    assert!(s.approximate(), "a move over budget is sent approximately");
    assert!(first.len() < 1500 + 400, "{} bytes", first.len());
    let mut draws = 0;
    let target = CellGrid::from_image(&s.image, ColorMode::TrueColor);
    while s.approximate() {
        let before = s.shown.clone().unwrap();
        let bytes = s.draw(&a);
        assert!(
            !bytes.is_empty(),
            "an approximate screen always gets closer"
        );
        // The refinement goes straight to within REFINE_TOLERANCE: no image cell it sends is
        // further than that from the frame.
        let after = s.shown.as_ref().unwrap();
        for i in 0..target.cells.len() {
            if after.cells[i] != before.cells[i] {
                let d = distance(&after.cells[i], &target.cells[i]);
                assert!(d <= u16::from(REFINE_TOLERANCE), "cell {i}: {d} off");
            }
        }
        draws += 1;
        assert!(draws < 100, "never exact");
    }
    let exact = CellGrid::from_image(&s.image, ColorMode::TrueColor);
    let shown = s.shown.as_ref().unwrap();
    assert_eq!(shown.cells[..exact.cells.len()], exact.cells[..]);
}

#[test]
fn an_unchanged_app_draws_nothing_and_renders_nothing() {
    let a = app(30, 10);
    let mut s = Screen::new();
    s.render(&a);
    let first = s.draw(&a);
    assert!(first.starts_with(SYNC_BEGIN) && first.ends_with(SYNC_END));
    assert!(!s.needs_render(&a));
    assert!(s.draw(&a).is_empty());
}

#[test]
fn gi_refines_until_the_cap_then_stops_and_restarts_on_a_move() {
    let mut a = app(10, 3);
    update(&mut a, Message::SetStage(Stage::Gi));
    let mut s = Screen::new();
    let mut n = 0;
    while s.needs_render(&a) {
        s.render(&a);
        n += 1;
    }
    assert_eq!((n, s.passes()), (GI_MAX_PASSES, GI_MAX_PASSES));
    assert!(s.status(&a).contains("256/256spp"));
    assert_eq!(
        (fixed(-0.004, 2), fixed(-0.3, 0), fixed(-5.0, 0)),
        ("0.00".into(), "0".into(), "-5".into())
    );
    update(&mut a, Message::Turn(0.1));
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!(s.passes(), 1);
}

#[test]
fn gi_shows_its_price_and_the_denoiser_switch_refilters_without_a_new_pass() {
    let mut a = app(200, 16);
    update(&mut a, Message::SetStage(Stage::Gi));
    let mut s = Screen::new();
    for _ in 0..4 {
        s.render(&a);
    }
    let status = s.status(&a);
    assert!(status.contains("6:gi 4/256spp"), "{status}");
    assert!(
        status.contains("N:denoised") && status.contains(" raw ±"),
        "{status}"
    );
    let denoised = s.image.clone();
    let (raw_error, error) = s.error;
    assert!(error < raw_error && raw_error > 0.0, "{:?}", s.error);
    // Off: the passes so far, raw, plus the next one.
    update(&mut a, Message::ToggleDenoise);
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!(s.passes(), 5);
    update(&mut a, Message::ToggleDenoise);
    s.render(&a);
    assert_ne!(s.image, denoised, "passes were added");
    let mut capped = Screen::new();
    let mut b = app(80, 4);
    update(&mut b, Message::SetStage(Stage::Gi));
    while capped.needs_render(&b) {
        capped.render(&b);
    }
    let before = capped.image.clone();
    update(&mut b, Message::ToggleDenoise);
    assert!(capped.needs_render(&b));
    capped.render(&b);
    assert_eq!(capped.passes(), GI_MAX_PASSES, "no pass past the cap");
    assert_ne!(capped.image, before);
    assert!(capped.status(&b).contains("N:raw"));
    assert!(!capped.needs_render(&b));
}

#[test]
fn a_light_move_in_gi_keeps_a_bounded_history_and_a_camera_move_none() {
    let mut a = app(40, 13);
    update(&mut a, Message::SetStage(Stage::Gi));
    let mut s = Screen::new();
    for _ in 0..10 {
        s.render(&a);
    }
    assert_eq!(s.guides.as_ref().unwrap().samples, 10);
    update(&mut a, Message::MoveLight(Vec3::new(0.1, 0.0, 0.0)));
    s.render(&a);
    assert_eq!(s.passes(), 1);
    assert_eq!(s.guides.as_ref().unwrap().samples, LIGHT_MOVE_HISTORY + 1);
    update(&mut a, Message::Walk(0.1));
    s.render(&a);
    assert_eq!(s.guides.as_ref().unwrap().samples, 1);
}

#[test]
fn the_status_line_fits_the_width_keeping_the_most_useful_fields() {
    let mut s = Screen::new();
    let wide = app(200, 10);
    s.render(&wide);
    s.draw(&wide);
    let full = s.status(&wide);
    for part in [
        "cornell",
        "5:indirect",
        "cam ",
        "light ",
        "render ",
        "encode ",
        "B  ",
    ] {
        assert!(full.contains(part), "{part:?} missing from {full:?}");
    }
    assert!(full.ends_with("truecolor  H:help"), "{full:?}");
    let at80 = s.status(&app(80, 24));
    assert!(at80.chars().count() <= 80, "{at80:?}");
    for part in [
        "cornell",
        "5:indirect",
        "render ",
        "H:help",
        "cam 0.00,0.00,-3.00 0°",
        "truecolor",
    ] {
        assert!(
            at80.contains(part),
            "{part:?} missing at 80 columns: {at80:?}"
        );
    }
    assert!(!at80.contains("encode"), "{at80:?}");
    let narrow = s.status(&app(24, 10));
    assert!(narrow.starts_with(" cornell  5:indirect"), "{narrow:?}");
    assert!(narrow.chars().count() <= 24, "{narrow:?}");
}

#[test]
fn fit_status_takes_fields_by_rank_while_they_fit_in_their_order() {
    let f = |t: &str, r| (t.to_string(), r);
    let fields = [f("a", 0), f("bbbb", 2), f("cc", 1), f("dddd", 3)];
    assert_eq!(fit_status(&fields, 100), " a  bbbb  cc  dddd");
    assert_eq!(fit_status(&fields, 12), " a  bbbb  cc");
    assert_eq!(fit_status(&fields, 8), " a  cc");
    assert_eq!(fit_status(&fields, 1), " a");
    // A field too long to fit does not stop a shorter, later-ranked one.
    let fields = [f("a", 0), f("bbbbbbbb", 1), f("c", 2)];
    assert_eq!(fit_status(&fields, 8), " a  c");
}

#[test]
fn the_too_small_message_is_worded_to_fit() {
    let text = |c: u16, r: u16| {
        let a = app(c, r);
        let mut s = Screen::new();
        s.draw(&a);
        let g = s.shown.as_ref().unwrap();
        (0..g.rows)
            .map(|row| {
                let line: String = g.cells[row * g.cols..(row + 1) * g.cols]
                    .iter()
                    .map(|c| c.ch)
                    .collect();
                line.trim_end().to_string()
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(text(8, 3), ["small", "Esc:quit", ""]);
    assert_eq!(text(9, 3), ["too small", "Esc quits", ""]);
    assert_eq!(text(40, 2), ["raytty: terminal too small", "Esc quits"]);
}

#[test]
fn a_tiny_terminal_gets_a_message_not_a_panic() {
    for (c, r) in [(0, 0), (1, 1), (9, 40), (200, 2), (10, 3)] {
        let a = app(c, r);
        let mut s = Screen::new();
        if s.needs_render(&a) {
            s.render(&a);
        }
        let out = s.draw(&a);
        assert_eq!(out.is_empty(), c == 0 || r == 0, "{c}x{r}");
    }
}

/// An app showing a one-box scene called `name`.
fn named(name: &str, cols: u16, rows: u16) -> App {
    let source = format!(
        "name = \"{name}\"\n[material.m]\ncolour = [1, 1, 1]\n[[object]]\nkind = \"box\"\nmaterial = \"m\"\ncentre = [0, 0, 0]\nsize = [1, 1, 1]\n"
    );
    let scene = raytty::scene::file::parse(&source, "t.toml", "t", &raytty::scene::file::no_meshes)
        .unwrap();
    App::new(scene, ColorMode::TrueColor, (cols, rows))
}

#[test]
fn a_wide_name_is_measured_in_columns() {
    let a = named(&"漢".repeat(200), 40, 5);
    let s = Screen::new();
    let line = s.status(&a);
    assert!(line.starts_with(" 漢漢"), "{line:?}");
    // Only the rank-0 fields: the name is clipped when drawn, never wrapped.
    assert!(!line.contains("H:help"), "{line:?}");
    let a = named("漢字", 40, 5);
    let line = s.status(&a);
    assert!(
        text_width(&line) <= 40 && line.contains("H:help"),
        "{line:?}"
    );
    assert!(text_width(&line) > line.chars().count());
}

#[test]
fn the_status_line_starts_with_the_scene_name_without_control_characters() {
    let source = "name = \"evil\\u001b[2J\\u0007box\"\n[material.m]\ncolour = [1, 1, 1]\n[[object]]\nkind = \"box\"\nmaterial = \"m\"\ncentre = [0, 0, 0]\nsize = [1, 1, 1]\n";
    let scene =
        raytty::scene::file::parse(source, "t.toml", "t", &raytty::scene::file::no_meshes).unwrap();
    let a = App::new(scene, ColorMode::Ascii, (40, 5));
    let mut s = Screen::new();
    assert!(
        s.status(&a).starts_with(" evil[2Jbox  5:indirect"),
        "{}",
        s.status(&a)
    );
    s.render(&a);
    let bytes = s.draw(&a);
    assert!(
        !bytes.windows(4).any(|w| w == b"\x1b[2J"),
        "the name's escape reached the terminal"
    );
    assert!(!bytes.contains(&0x07));
    let shown = String::from_utf8_lossy(&bytes);
    assert!(
        shown.contains("evil[2Jbox"),
        "the scene's name is not shown"
    );
}

fn pixel_app(protocol: Protocol) -> App {
    let mut a = app(40, 13);
    a.protocol = Some(protocol);
    a.pixels = true;
    a.cell_pixels = (4, 8);
    a
}

fn contains(bytes: &[u8], part: &[u8]) -> bool {
    bytes.windows(part.len()).any(|w| w == part)
}

/// kitty: the frame is one image at the terminal's pixels, placed over the cells above the
/// status line under one id (so the next replaces it), the status line as text; a move
/// renders lower while moving and full again once settled; the help is text and deletes it.
#[test]
fn kitty_frames_replace_one_image_and_refine_to_full_resolution() {
    let mut a = pixel_app(Protocol::Kitty);
    let mut s = Screen::new();
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!((s.image.width, s.image.height), (160, 96));
    let first = s.draw(&a);
    assert!(contains(
        &first,
        b"\x1b[H\x1b_Ga=T,f=24,o=z,q=2,s=160,v=96,i=1,p=1,c=40,r=12,C=1"
    ));
    assert!(contains(&first, "kitty 160x96".as_bytes()));
    assert!(
        !contains(&s.draw(&a), b"\x1b_G"),
        "the image did not change: not sent again"
    );
    // Measured as too slow at full resolution: a move renders at a lower one...
    s.costs.seconds = Some(1e-5);
    update(&mut a, Message::Walk(0.1));
    assert!(s.needs_render(&a));
    s.render(&a);
    assert!(s.image.width < 160, "{}", s.image.width);
    let moved = s.draw(&a);
    assert!(
        contains(&moved, b"c=40,r=12"),
        "scaled up to the same cells"
    );
    assert!(s.upgrade_in(&a).is_some());
    // ... and once nothing changes for SETTLE, at full resolution again.
    s.changed_at -= SETTLE;
    assert_eq!(s.upgrade_in(&a), Some(Duration::ZERO));
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!((s.image.width, s.image.height), (160, 96));
    assert_eq!(s.upgrade_in(&a), None);
    assert!(!s.draw(&a).is_empty());
    // The help is text: the image is deleted, and comes back whole when the help closes.
    update(&mut a, Message::ToggleHelp);
    s.render(&a);
    let help = s.draw(&a);
    assert!(contains(&help, raytty::frame::KITTY_DELETE_ALL));
    assert!(contains(&help, b"raytty keys"));
    update(&mut a, Message::ToggleHelp);
    s.render(&a);
    assert!(contains(&s.draw(&a), b"\x1b_Ga=T"));
}

/// kitty over a slow link (a frame budget): a move is sent within 8 levels (PNG), then at
/// full resolution still within 8 levels ("approximate") once settled, then the same image
/// exactly (zlib RGB), sent again without rendering again.
#[test]
fn kitty_over_a_slow_link_sends_near_frames_then_the_exact_one() {
    let mut a = pixel_app(Protocol::Kitty);
    let mut s = Screen::new();
    s.render(&a);
    assert!(
        contains(&s.draw(&a), b"\x1b_Ga=T,f=24,o=z"),
        "unmeasured: exact"
    );
    s.link = LinkView {
        budget: Some(8_000),
        rate: Some(125e3),
    };
    s.costs.seconds = Some(1e-5);
    update(&mut a, Message::Walk(0.1));
    s.render(&a);
    assert!(s.image.width < 160, "{}", s.image.width);
    let moved = s.draw(&a);
    assert!(
        contains(&moved, b"\x1b_Ga=T,f=100,q=2"),
        "a moving frame is near"
    );
    assert!(contains(&moved, b"approximate"));
    s.changed_at -= SETTLE;
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!((s.image.width, s.image.height), (160, 96));
    let settled = s.draw(&a);
    assert!(contains(&settled, b"f=100,q=2,s=160,v=96"), "full and near");
    assert!(s.upgrade_in(&a).is_some_and(|t| t > Duration::ZERO));
    let rendered = s.stats.render.elapsed;
    s.changed_at -= pixels::EXACT_SETTLE;
    assert_eq!(s.upgrade_in(&a), Some(Duration::ZERO));
    assert!(s.needs_render(&a));
    s.render(&a);
    assert_eq!(s.stats.render.elapsed, rendered, "not rendered again");
    let exact = s.draw(&a);
    assert!(
        contains(&exact, b"f=24,o=z,q=2,s=160,v=96"),
        "full and exact"
    );
    assert!(!contains(&exact, b"approximate"));
    assert_eq!(s.upgrade_in(&a), None);
    assert!(!s.needs_render(&a));
}

/// sixel: the image is drawn one to one at the terminal's pixels (whole bands of six rows),
/// and pixels off (G) goes back to text cells over a cleared screen.
#[test]
fn sixel_frames_are_full_size_and_g_goes_back_to_text() {
    let mut a = pixel_app(Protocol::Sixel);
    a.cell_pixels = (5, 9);
    let mut s = Screen::new();
    s.render(&a);
    assert_eq!((s.image.width, s.image.height), (200, 108));
    let first = s.draw(&a);
    assert!(contains(&first, b"\x1b[H\x1bP0;1;0q\"1;1;200;108"));
    assert!(contains(&first, "sixel 200x108".as_bytes()));
    update(&mut a, Message::ToggleGraphics);
    assert!(s.needs_render(&a));
    s.render(&a);
    let text = s.draw(&a);
    assert!(contains(&text, b"\x1b[2J") && !contains(&text, b"\x1bP"));
    assert_eq!(s.image.width, 40);
}
