//! The pixel modes' frames: the image's size on screen, the resolution it is rendered at
//! (lower while the view moves, when rendering or the link could not keep up), and the
//! escapes that put it on screen. Pure: no terminal I/O.

use std::time::Duration;

use raytty::frame::{Placement, Precision, encode_kitty_placed, encode_sixel};

use super::detect::{Protocol, tmux_passthrough};

/// The kitty image (and placement) id of the frame: each frame replaces the last in place.
pub const IMAGE_ID: u32 = 1;

/// The coarsest resolution while moving: one rendered pixel for this many screen pixels
/// across (and down).
pub const MAX_SCALE: u32 = 8;

/// While the view moves, a frame's render should take at most this long (about the key
/// repeat interval), so a held key is followed; its resolution is lowered until it does.
pub const MOVE_RENDER: Duration = Duration::from_millis(40);

/// With nothing changed for this long after a reduced frame, the keys are taken to have
/// stopped and the frame is rendered at full resolution. Longer than a key repeat's interval
/// (25-40 ms in xterm, kitty, VTE), so a held key does not start a full render between
/// repeats.
pub const SETTLE: Duration = Duration::from_millis(80);

/// The longest wait for an exact frame (see [`exact_settle`]): an exact frame holds a
/// 1 Mbit/s link for about a second (1200×780: 130 kB), so it waits until the keys have
/// surely stopped (a held key repeats every 25-40 ms; `examples/slow_link` presses every
/// 100 ms), and by then the near frame is through the link.
pub const EXACT_SETTLE: Duration = Duration::from_millis(300);

/// On a slow link (one the writer gave a frame budget), kitty's frames are sent within
/// [`NEAR_LEVELS`](raytty::frame::NEAR_LEVELS) while the view moves and in the first full
/// frame after it stopped (a fifth of an exact frame's bytes); the exact frame goes once
/// nothing has changed for as long as it will hold the link (by the measured `costs` of an
/// exact frame of `full` size and the link's `rate`): a key pressed while it is on the link
/// then waits at most as long as the keys had been still. At least [`SETTLE`], at most
/// [`EXACT_SETTLE`] (also when unmeasured).
pub fn exact_settle(full: (u32, u32), costs: Costs, rate: Option<f64>) -> Duration {
    match (costs.bytes, rate) {
        (Some(per), Some(rate)) if rate > 0.0 => {
            let bytes = per * f64::from(full.0) * f64::from(full.1);
            Duration::from_secs_f64((bytes / rate).min(1e3)).clamp(SETTLE, EXACT_SETTLE)
        }
        _ => EXACT_SETTLE,
    }
}

/// Before anything was measured: a first frame is rendered at most this many pixels, so it
/// shows at once, and refined when it has.
pub const FIRST_PIXELS: u64 = 200_000;

/// The size in pixels of the image on a `cols × rows` terminal of `cell`-pixel cells, the
/// last row being the status line. Sixel draws one to one, so a sixel image larger than the
/// terminal's `sixel_max` (xterm draws nothing of one) is shrunk to fit it, the same view
/// over fewer pixels; and as it draws six rows a band, and some terminals clear a whole band,
/// its height is cut to a multiple of six so it never reaches the status line.
pub fn full_size(
    protocol: Protocol,
    size: (u16, u16),
    cell: (u32, u32),
    sixel_max: Option<(u32, u32)>,
) -> (u32, u32) {
    let (cols, rows) = (u32::from(size.0), u32::from(size.1).saturating_sub(1));
    let (w, h) = (cols * cell.0, rows * cell.1);
    match protocol {
        Protocol::Kitty => (w, h),
        Protocol::Sixel => {
            let (mw, mh) = sixel_max.unwrap_or((u32::MAX, u32::MAX));
            let (w, h) = if w > mw || h > mh {
                // The larger of the two shrink factors, w·mh vs h·mw (exact in u64).
                if u64::from(w) * u64::from(mh) >= u64::from(h) * u64::from(mw) {
                    (mw, (u64::from(h) * u64::from(mw) / u64::from(w)) as u32)
                } else {
                    ((u64::from(w) * u64::from(mh) / u64::from(h)) as u32, mh)
                }
            } else {
                (w, h)
            };
            (w.max(1), (h / 6 * 6).max(6))
        }
    }
}

/// The size rendered at `scale` (one rendered pixel for `scale × scale` screen pixels).
pub fn scaled(full: (u32, u32), scale: u32) -> (u32, u32) {
    (full.0.div_ceil(scale).max(1), full.1.div_ceil(scale).max(1))
}

/// What the last frames cost, per rendered pixel: render time, and bytes sent.
#[derive(Clone, Copy, Debug, Default)]
pub struct Costs {
    /// Render time per pixel in seconds, once measured.
    pub seconds: Option<f64>,
    /// Bytes per rendered pixel of an exact frame, once measured.
    pub bytes: Option<f64>,
    /// Bytes per rendered pixel of a frame within [`NEAR_LEVELS`](raytty::frame::NEAR_LEVELS),
    /// once measured (the moving frames on a slow link).
    pub near_bytes: Option<f64>,
}

/// The finest scale (1 = full) at which a moving frame of `full` size renders within
/// [`MOVE_RENDER`] and fits `budget` bytes, by the measured `costs` (of a near frame: a budget
/// is a slow link's, where moving frames are near; of an exact one until a near one was
/// measured); before any measurement, the finest at most [`FIRST_PIXELS`].
pub fn moving_scale(full: (u32, u32), costs: Costs, budget: Option<usize>) -> u32 {
    (1..=MAX_SCALE)
        .find(|&s| {
            let (w, h) = scaled(full, s);
            let px = f64::from(w) * f64::from(h);
            let time_ok = match costs.seconds {
                Some(t) => px * t <= MOVE_RENDER.as_secs_f64(),
                None => px <= FIRST_PIXELS as f64,
            };
            let bytes_ok = match (budget, costs.near_bytes.or(costs.bytes)) {
                (Some(b), Some(per)) => px * per <= b as f64,
                _ => true,
            };
            time_ok && bytes_ok
        })
        .unwrap_or(MAX_SCALE)
}

/// `rgb` (`w × h`) scaled up to `full` by repeating pixels (nearest).
pub fn upscale(rgb: &[[u8; 3]], w: u32, h: u32, full: (u32, u32)) -> Vec<[u8; 3]> {
    if (w, h) == full {
        return rgb.to_vec();
    }
    let col: Vec<usize> = (0..full.0)
        .map(|x| (u64::from(x) * u64::from(w) / u64::from(full.0)) as usize)
        .collect();
    let mut out = Vec::with_capacity(full.0 as usize * full.1 as usize);
    for y in 0..full.1 {
        let sy = (u64::from(y) * u64::from(h) / u64::from(full.1)) as usize;
        let row = &rgb[sy * w as usize..(sy + 1) * w as usize];
        out.extend(col.iter().map(|&x| row[x]));
    }
    out
}

/// The bytes that show `rgb` (`w × h`) over the image area, from the top-left cell: kitty
/// scales it to `cells` (columns, rows) and replaces the last frame in place, sent at
/// `precision`; sixel gets it scaled up to `full` screen pixels first (it draws one to one;
/// its palette is its only precision). Through tmux's passthrough if `tmux`, with the cursor
/// placed inside it (tmux does not know where an image goes).
#[allow(clippy::too_many_arguments)]
pub fn frame_bytes(
    protocol: Protocol,
    rgb: &[[u8; 3]],
    (w, h): (u32, u32),
    full: (u32, u32),
    cells: (u32, u32),
    precision: Precision,
    tmux: bool,
    out: &mut Vec<u8>,
) {
    let mut image = b"\x1b[H".to_vec();
    match protocol {
        Protocol::Kitty => {
            let place = Placement {
                id: IMAGE_ID,
                cells,
            };
            encode_kitty_placed(rgb, w, h, place, precision, &mut image);
        }
        Protocol::Sixel => {
            let big = upscale(rgb, w, h, full);
            encode_sixel(&big, full.0, full.1, &mut image);
        }
    }
    if tmux && protocol == Protocol::Kitty {
        tmux_passthrough(&image, out);
    } else {
        out.extend_from_slice(&image);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixel_keeps_whole_bands_above_the_status_line() {
        let limit = Some((1000, 1000));
        assert_eq!(
            full_size(Protocol::Kitty, (120, 40), (10, 21), limit),
            (1200, 819)
        );
        assert_eq!(
            full_size(Protocol::Sixel, (120, 40), (10, 21), None),
            (1200, 816)
        );
        // Over xterm's limit: the same view, shrunk to fit.
        assert_eq!(
            full_size(Protocol::Sixel, (120, 40), (10, 21), limit),
            (1000, 678)
        );
        assert_eq!(
            full_size(Protocol::Sixel, (50, 101), (10, 20), limit),
            (250, 1000 / 6 * 6)
        );
        assert_eq!(scaled((1200, 816), 3), (400, 272));
        assert_eq!(scaled((5, 5), 8), (1, 1));
    }

    #[test]
    fn a_moving_frame_fits_the_render_time_and_the_budget() {
        let full = (1200, 800);
        let none = Costs::default();
        assert_eq!(
            moving_scale(full, none, None),
            3,
            "960k px: a first frame at 1/3"
        );
        let fast = Costs {
            seconds: Some(1e-8),
            bytes: Some(1.0),
            near_bytes: None,
        };
        assert_eq!(moving_scale(full, fast, None), 1);
        assert_eq!(moving_scale(full, fast, Some(100_000)), 4);
        // Near frames measured at a fifth of the bytes: at 1/2 rather than 1/4.
        let near = Costs {
            near_bytes: Some(0.2),
            ..fast
        };
        assert_eq!(moving_scale(full, near, Some(100_000)), 2);
        let slow = Costs {
            seconds: Some(1e-5),
            ..Costs::default()
        };
        assert_eq!(moving_scale(full, slow, None), MAX_SCALE);
    }

    #[test]
    fn the_exact_frame_waits_as_long_as_it_holds_the_link() {
        let full = (1200, 780);
        let costs = Costs {
            bytes: Some(0.14),
            ..Costs::default()
        };
        // 131 kB: 1.05 s at 1 Mbit/s (the most: 300 ms), 105 ms at 10, 10 ms at 100 (SETTLE).
        assert_eq!(exact_settle(full, costs, Some(125e3)), EXACT_SETTLE);
        let ten = exact_settle(full, costs, Some(1.25e6));
        assert!((ten.as_secs_f64() - 0.105).abs() < 1e-3, "{ten:?}");
        assert_eq!(exact_settle(full, costs, Some(12.5e6)), SETTLE);
        assert_eq!(
            exact_settle(full, Costs::default(), Some(125e3)),
            EXACT_SETTLE
        );
        assert_eq!(exact_settle(full, costs, None), EXACT_SETTLE);
    }

    #[test]
    fn upscaling_repeats_pixels() {
        let rgb = [[1, 1, 1], [2, 2, 2], [3, 3, 3], [4, 4, 4]];
        let big = upscale(&rgb, 2, 2, (4, 3));
        let v: Vec<u8> = big.iter().map(|p| p[0]).collect();
        assert_eq!(v, [1, 1, 2, 2, 1, 1, 2, 2, 3, 3, 4, 4]);
    }
}
