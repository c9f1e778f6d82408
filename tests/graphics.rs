//! The pixel protocols, decoded: the kitty graphics escapes (keys, chunks, base64, zlib) and
//! sixel (palette, bands, repeats) rebuild the frame they were made from. Also through the
//! command line: `raytty render --format kitty|sixel --pixels WxH`.

use std::process::Command;

use raytty::frame::{encode_kitty, encode_sixel};
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

fn unbase64(text: &[u8]) -> Vec<u8> {
    let value = |b: u8| match b {
        b'A'..=b'Z' => b - b'A',
        b'a'..=b'z' => b - b'a' + 26,
        b'0'..=b'9' => b - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {b}"),
    };
    assert_eq!(text.len() % 4, 0, "base64 comes in fours");
    let mut out = Vec::new();
    for q in text.chunks(4) {
        let pad = q.iter().filter(|&&b| b == b'=').count();
        let n = q[..4 - pad]
            .iter()
            .fold(0u32, |n, &b| n << 6 | u32::from(value(b)))
            << (6 * pad);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The image a stream of kitty graphics escapes transmits: width, height, RGB.
fn decode_kitty(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut rest = bytes;
    let mut keys_first = None;
    let mut data = Vec::new();
    let mut more = true;
    while !rest.is_empty() && rest != b"\n" {
        assert!(more, "no escape after the last chunk (m=0)");
        let body = rest.strip_prefix(b"\x1b_G").expect("an APC G escape");
        let end = body.windows(2).position(|w| w == b"\x1b\\").expect("ST");
        let (control, payload) =
            body[..end].split_at(body.iter().position(|&b| b == b';').unwrap());
        let payload = &payload[1..];
        assert!(payload.len() <= 4096, "a chunk of {} bytes", payload.len());
        let keys: Vec<(String, String)> = std::str::from_utf8(control)
            .unwrap()
            .split(',')
            .map(|kv| {
                let (k, v) = kv.split_once('=').unwrap();
                (k.to_string(), v.to_string())
            })
            .collect();
        let m = keys.iter().find(|(k, _)| k == "m").map(|(_, v)| v.as_str());
        more = m == Some("1");
        if keys_first.is_none() {
            keys_first = Some(keys);
        } else {
            assert_eq!(keys.len(), 1, "later chunks carry only m");
            // Every chunk but the last is full (a multiple of 4, so no padding mid-stream).
        }
        data.extend_from_slice(payload);
        rest = &body[end + 2..];
    }
    assert!(!more, "the last chunk says m=0");
    let keys = keys_first.expect("one escape at least");
    let get = |k: &str| {
        keys.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.clone())
            .unwrap_or_else(|| panic!("no {k}"))
    };
    assert_eq!(get("a"), "T");
    assert_eq!(get("f"), "24");
    assert_eq!(get("o"), "z");
    let raw = miniz_oxide::inflate::decompress_to_vec_zlib(&unbase64(&data)).expect("zlib");
    (get("s").parse().unwrap(), get("v").parse().unwrap(), raw)
}

#[test]
fn kitty_escapes_carry_the_frame_exactly() {
    for (w, h) in [(1, 1), (37, 23), (200, 150)] {
        let rgb = frame(w, h);
        let mut out = Vec::new();
        encode_kitty(&rgb, w, h, &mut out);
        let (dw, dh, raw) = decode_kitty(&out);
        assert_eq!((dw, dh), (w, h));
        assert_eq!(raw, rgb.iter().flatten().copied().collect::<Vec<u8>>());
        if w == 200 {
            assert!(
                out.windows(4).filter(|w| *w == b"\x1b_Gm").count() > 1,
                "chunked"
            );
        }
    }
}

/// The pixels a sixel DCS string paints (`None`: never painted), with its raster size.
fn decode_sixel(bytes: &[u8]) -> (usize, usize, Vec<Option<[u8; 3]>>) {
    let body = bytes.strip_prefix(b"\x1bP").expect("DCS");
    let q = body.iter().position(|&b| b == b'q').unwrap();
    let end = body.windows(2).position(|w| w == b"\x1b\\").expect("ST");
    let s = &body[q + 1..end];
    let mut i = 0;
    let number = |i: &mut usize| {
        let start = *i;
        while *i < s.len() && s[*i].is_ascii_digit() {
            *i += 1;
        }
        std::str::from_utf8(&s[start..*i])
            .unwrap()
            .parse::<usize>()
            .unwrap()
    };
    assert_eq!(s[0], b'"', "raster attributes first");
    i += 1;
    let attrs: Vec<usize> = (0..4)
        .map(|k| {
            if k > 0 {
                assert_eq!(s[i], b';');
                i += 1;
            }
            number(&mut i)
        })
        .collect();
    assert_eq!(&attrs[..2], &[1, 1], "square pixels");
    let (w, h) = (attrs[2], attrs[3]);
    let mut pixels = vec![None; w * h];
    let mut palette = std::collections::HashMap::new();
    let (mut x, mut band, mut colour) = (0, 0, 0);
    while i < s.len() {
        match s[i] {
            b'#' => {
                i += 1;
                colour = number(&mut i);
                if s.get(i) == Some(&b';') {
                    i += 1;
                    assert_eq!(number(&mut i), 2, "RGB colour");
                    let pct: Vec<usize> = (0..3)
                        .map(|_| {
                            i += 1;
                            number(&mut i)
                        })
                        .collect();
                    assert!(pct.iter().all(|&p| p <= 100));
                    palette.insert(colour, pct.map_to_rgb());
                }
            }
            b'$' => {
                x = 0;
                i += 1;
            }
            b'-' => {
                x = 0;
                band += 1;
                i += 1;
            }
            b'!' | b'?'..=b'~' => {
                let mut run = 1;
                if s[i] == b'!' {
                    i += 1;
                    run = number(&mut i);
                }
                let bits = s[i] - b'?';
                i += 1;
                let c = *palette.get(&colour).expect("a colour set before use");
                for _ in 0..run {
                    for dy in 0..6 {
                        let y = band * 6 + dy;
                        if bits >> dy & 1 == 1 {
                            assert!(x < w && y < h, "paints outside the raster");
                            pixels[y * w + x] = Some(c);
                        }
                    }
                    x += 1;
                }
            }
            b => panic!("unexpected byte {b} in sixel data"),
        }
    }
    (w, h, pixels)
}

trait ToRgb {
    fn map_to_rgb(&self) -> [u8; 3];
}

impl ToRgb for Vec<usize> {
    /// Percent to 8 bits, as a terminal reads it.
    fn map_to_rgb(&self) -> [u8; 3] {
        [0, 1, 2].map(|c| ((self[c] * 255 + 50) / 100) as u8)
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
                let (w, h, raw) = decode_kitty(body);
                assert_eq!(raw.len(), 64 * 48 * 3);
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
