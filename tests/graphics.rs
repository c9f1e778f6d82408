//! The pixel protocols, decoded: the kitty graphics escapes (keys, chunks, base64, zlib) and
//! sixel (palette, bands, repeats) rebuild the frame they were made from. Also through the
//! command line: `raytty render --format kitty|sixel --pixels WxH`.

use std::process::Command;

#[path = "support/graphics.rs"]
mod graphics;

use graphics::{decode_kitty, decode_sixel};
use raytty::frame::{Precision, encode_kitty, encode_sixel};
use raytty::{Options, Stage, cornell_box};

fn frame(w: u32, h: u32) -> Vec<[u8; 3]> {
    let scene = cornell_box();
    let settings = Stage::Indirect.settings(scene.effects());
    scene
        .render(&Options {
            width: w,
            height: h,
            settings: Some(settings),
            ..Options::default()
        })
        .image
        .to_rgb8()
}

#[test]
fn kitty_escapes_carry_the_frame_exactly() {
    for (w, h) in [(1, 1), (37, 23), (200, 150)] {
        let rgb = frame(w, h);
        let mut out = Vec::new();
        encode_kitty(&rgb, w, h, &mut out);
        let k = decode_kitty(&out);
        assert_eq!((k.key("f"), k.key("o")), (Some("24"), Some("z")));
        let (dw, dh, px) = k.image();
        assert_eq!((dw, dh), (w, h));
        assert_eq!(px, rgb);
        if w == 200 {
            assert!(
                out.windows(4).filter(|w| *w == b"\x1b_Gm").count() > 1,
                "chunked"
            );
        }
    }
}

#[test]
fn sixel_paints_every_pixel_near_the_frame() {
    for (w, h) in [(1, 1), (33, 13), (240, 180)] {
        let rgb = frame(w, h);
        let mut out = Vec::new();
        encode_sixel(&rgb, w, h, &mut out);
        let (dw, dh, pixels) = decode_sixel(&out);
        assert_eq!((dw, dh), (w as usize, h as usize));
        let mut total = 0.0;
        for (p, q) in pixels.iter().zip(&rgb) {
            let p = p.expect("every pixel painted");
            total += (0..3)
                .map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2))
                .sum::<f64>();
        }
        let mse = total / (rgb.len() * 3) as f64;
        let psnr = 10.0 * (255.0f64.powi(2) / mse.max(1e-9)).log10();
        assert!(psnr > 35.0, "{w}x{h}: {psnr:.1} dB");
    }
}

#[test]
fn render_writes_one_picture_in_each_protocol() {
    let bin = env!("CARGO_BIN_EXE_raytty");
    for format in ["kitty", "sixel"] {
        let out = Command::new(bin)
            .args(["render", "--format", format, "--pixels", "64x48"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let body = out.stdout.strip_suffix(b"\n").expect("ends in a newline");
        let (w, h) = match format {
            "kitty" => {
                let (w, h, px) = decode_kitty(body).image();
                assert_eq!(px.len(), 64 * 48);
                (w as usize, h as usize)
            }
            _ => {
                let (w, h, px) = decode_sixel(body);
                assert!(px.iter().all(Option::is_some));
                (w, h)
            }
        };
        assert_eq!((w, h), (64, 48));
    }
    let out = Command::new(bin)
        .args(["render", "--format", "png", "--cells", "octant"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--cells"));
}

#[test]
fn a_terminal_reading_the_escapes_in_pieces_shows_each_picture_whole() {
    // Text, a kitty image placed at row 2 column 3 over 4×2 cells, text, an APC that is not
    // kitty's, a sixel at the top left: read in pieces of every size from 1 byte, the far end's screen gets the text
    // unchanged and each picture whole, where the cursor was.
    let (w, h) = (8, 6);
    let rgb = frame(w, h);
    let mut kitty = Vec::new();
    let place = raytty::frame::Placement {
        id: 1,
        cells: (4, 2),
    };
    raytty::frame::encode_kitty_placed(&rgb, w, h, place, Precision::Exact, &mut kitty);
    let mut sixel = Vec::new();
    encode_sixel(&rgb, w, h, &mut sixel);
    let mut stream = b"\x1b[2J\x1b[3;4Hab".to_vec();
    stream.extend_from_slice(b"\x1b[3;4H");
    stream.extend_from_slice(&kitty);
    stream.extend_from_slice(b"\x1b[1;1Hcd\x1b_Xnot kitty's\x1b\\\x1b[H");
    stream.extend_from_slice(&sixel);
    stream.extend_from_slice(b"\x1b[m");
    for piece in [1, 2, 3, 5, 64, stream.len()] {
        let mut splitter = graphics::Splitter::default();
        let n = |v| std::num::NonZeroU16::new(v).expect("non-zero");
        let mut vt = vt100::Parser::new(n(10), n(20), 0);
        let mut screen = graphics::PixelScreen::new(20, 10, (2, 3));
        let mut text = Vec::new();
        let mut pictures = 0;
        for bytes in stream.chunks(piece) {
            for p in splitter.split(bytes) {
                match p {
                    graphics::Piece::Text(t) => {
                        text.extend_from_slice(t);
                        vt.process(t);
                    }
                    graphics::Piece::Graphics(g) => {
                        pictures += usize::from(screen.apply(&g, vt.screen().cursor_position()));
                    }
                }
            }
        }
        assert_eq!(
            text, b"\x1b[2J\x1b[3;4Hab\x1b[3;4H\x1b[1;1Hcd\x1b[H\x1b[m",
            "{piece}"
        );
        assert_eq!(pictures, 2, "{piece}");
        assert_eq!(vt.screen().contents_between(0, 0, 0, 2), "cd");
        // The sixel one to one at the top left; the kitty image over cells 3-6 of rows 2-3
        // (pixels 6-13 across, 6-11 down), its 8×6 pixels scaled to them: the same here.
        let shown = screen.shown(14, 12);
        let sixel_px = graphics::decode_sixel(&sixel).2;
        for y in 0..12 {
            for x in 0..14 {
                let p = shown[y * 14 + x];
                if (6..14).contains(&x) && (6..12).contains(&y) {
                    assert_eq!(p, Some(rgb[(y - 6) * 8 + x - 6]), "kitty at {x},{y}");
                } else if x < 8 && y < 6 {
                    assert_eq!(p, sixel_px[y * 8 + x], "sixel at {x},{y}");
                } else {
                    assert_eq!(p, None, "nothing at {x},{y}");
                }
            }
        }
    }
}

#[test]
fn a_near_kitty_frame_is_within_8_levels_in_a_fraction_of_the_bytes() {
    let (w, h) = (300, 200);
    let rgb = frame(w, h);
    let place = raytty::frame::Placement {
        id: 1,
        cells: (30, 10),
    };
    let mut sizes = Vec::new();
    for precision in [Precision::Exact, Precision::Near] {
        let mut out = Vec::new();
        raytty::frame::encode_kitty_placed(&rgb, w, h, place, precision, &mut out);
        let k = decode_kitty(&out);
        let (dw, dh, px) = k.image();
        assert_eq!((dw, dh), (w, h));
        let worst = px
            .iter()
            .zip(&rgb)
            .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
            .max()
            .unwrap();
        match precision {
            Precision::Exact => assert_eq!((k.key("f"), worst), (Some("24"), 0)),
            Precision::Near => {
                assert_eq!(k.key("f"), Some("100"), "PNG");
                assert!(worst <= raytty::frame::NEAR_LEVELS, "{worst} levels off");
                assert!(worst > 0, "rounded");
            }
        }
        sizes.push(out.len());
    }
    assert!(
        sizes[1] * 3 < sizes[0],
        "near {} B, exact {} B",
        sizes[1],
        sizes[0]
    );
}
