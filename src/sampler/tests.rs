use super::*;

/// The pair `dimension` of points `0..n` of `pixel`'s sequence, as 32-bit fractions' top 24
/// bits (what `unit` keeps).
fn points(pixel: u64, dimension: u32, n: u32) -> Vec<[f32; 2]> {
    (0..n)
        .map(|i| Sobol::new(pixel, i).pair(dimension))
        .collect()
}

/// The smallest t for which `points` (2^m of them) form a (t, m, 2)-net: every box of size
/// 2^-a × 2^-(m-t-a) holds exactly 2^t points.
fn t_value(points: &[[f32; 2]], m: u32) -> u32 {
    (0..=m)
        .find(|&t| {
            (0..=m - t).all(|a| {
                let (bx, by) = (1u32 << a, 1u32 << (m - t - a));
                let mut count = vec![0u32; (bx * by) as usize];
                for p in points {
                    let (cx, cy) = ((p[0] * bx as f32) as u32, (p[1] * by as f32) as u32);
                    count[(cy * bx + cx) as usize] += 1;
                }
                count.iter().all(|&c| c == 1 << t)
            })
        })
        .unwrap_or(m)
}

/// The first 2^m points of every pair, in every pixel tried, form a (0, m, 2)-net: each of
/// the 2^m boxes of size 2^-a × 2^-(m-a) holds exactly one point. That is what makes 64 or 256
/// samples cover a pixel's pairs evenly; a broken scramble (one that let a digit depend on
/// lower digits) or a wrong direction number fails it. The second bounce's pair (Sobol
/// dimensions 2 and 3 of the first bounce's point) is a (2, m, 2)-net, the best those two
/// dimensions give, and each of its coordinates alone is stratified.
#[test]
fn every_power_of_two_prefix_is_a_net() {
    for pixel in [0, 1, 77, 12_345, u64::MAX] {
        for dimension in 0..6 {
            for m in 0..=10u32 {
                let pts = points(pixel, dimension, 1 << m);
                let t = t_value(&pts, m);
                let most = if dimension == FOUR_D_SECOND { 2 } else { 0 };
                assert!(
                    t <= most,
                    "pixel {pixel}, pair {dimension}, 2^{m} points: t = {t}"
                );
                for k in 0..2 {
                    let mut cells: Vec<u32> = pts
                        .iter()
                        .map(|p| (p[k] * pts.len() as f32) as u32)
                        .collect();
                    cells.sort_unstable();
                    cells.dedup();
                    assert_eq!(cells.len(), pts.len(), "pair {dimension} coordinate {k}");
                }
            }
        }
    }
}

/// The first two bounces' pairs are one 4D point, so they are stratified jointly: the first
/// coordinates of the two pairs form a (1, m, 2)-net (Sobol dimensions 0 and 2), where two
/// independently shuffled pairs would leave boxes empty.
#[test]
fn the_first_two_bounces_are_one_four_dimensional_point() {
    for pixel in [0, 5, 999] {
        for m in 2..=10u32 {
            let first = points(pixel, FOUR_D_SECOND - 1, 1 << m);
            let second = points(pixel, FOUR_D_SECOND, 1 << m);
            let joint: Vec<[f32; 2]> = first
                .iter()
                .zip(&second)
                .map(|(a, b)| [a[0], b[0]])
                .collect();
            assert!(t_value(&joint, m) <= 1, "pixel {pixel}, 2^{m} points");
        }
    }
    // The control: the pixel offset and the first bounce are shuffled apart.
    let apart: Vec<[f32; 2]> = points(3, PIXEL_DIMENSION, 256)
        .iter()
        .zip(&points(3, FOUR_D_SECOND - 1, 256))
        .map(|(a, b)| [a[0], b[0]])
        .collect();
    assert!(t_value(&apart, 8) > 1);
}

/// Sobol dimensions 2 and 3 from their direction numbers are the Sobol sequence's: its first
/// eight points (index i in Gray-code order g = i ⊕ i/2, as tables list them).
#[test]
fn dimensions_two_and_three_are_sobols() {
    let listed = [
        [0.0, 0.0],
        [0.5, 0.5],
        [0.25, 0.25],
        [0.75, 0.75],
        [0.625, 0.875],
        [0.125, 0.375],
        [0.875, 0.625],
        [0.375, 0.125],
    ];
    for (n, want) in listed.iter().enumerate() {
        let g = (n ^ (n >> 1)) as u32;
        let got = [sobol_reversed(&SOBOL_2, g), sobol_reversed(&SOBOL_3, g)]
            .map(|x| f64::from(x.reverse_bits()) / 4_294_967_296.0);
        assert_eq!(got, *want, "point {n}");
    }
}

/// A point and its successor in the next power-of-two block: the second block of 2^m points
/// is a net too, so a frame of 64 samples after a frame of 64 keeps the spread.
#[test]
fn later_blocks_are_nets_too() {
    let pts: Vec<[f32; 2]> = (64..128).map(|i| Sobol::new(9, i).pair(3)).collect();
    let mut seen = [false; 64];
    for p in &pts {
        let cell = (p[1] * 8.0) as usize * 8 + (p[0] * 8.0) as usize;
        assert!(!seen[cell]);
        seen[cell] = true;
    }
}

/// Each number is uniform over pixels (the estimator's expectation is unchanged): the mean
/// and the mean square of one point over 20 000 pixels are those of U(0, 1), for the pixel
/// pair and a path's first draws, and the two coordinates of a pair are uncorrelated.
#[test]
fn each_number_is_uniform_over_pixels() {
    const N: usize = 20_000;
    for index in [0u32, 1, 5, 200] {
        for dimension in 0..4 {
            let v: Vec<[f32; 2]> = (0..N as u64)
                .map(|p| Sobol::new(p, index).pair(dimension))
                .collect();
            for k in 0..2 {
                let mean = v.iter().map(|p| f64::from(p[k])).sum::<f64>() / N as f64;
                let sq = v.iter().map(|p| f64::from(p[k]).powi(2)).sum::<f64>() / N as f64;
                // Standard errors: 0.29/√N ≈ 0.002 and 0.3/√N ≈ 0.002.
                assert!(
                    (mean - 0.5).abs() < 0.01,
                    "index {index} dim {dimension}: {mean}"
                );
                assert!(
                    (sq - 1.0 / 3.0).abs() < 0.01,
                    "index {index} dim {dimension}: {sq}"
                );
            }
            let xy = v
                .iter()
                .map(|p| f64::from(p[0]) * f64::from(p[1]))
                .sum::<f64>()
                / N as f64;
            assert!(
                (xy - 0.25).abs() < 0.01,
                "index {index} dim {dimension}: {xy}"
            );
        }
    }
}

/// Two pairs of one point are unrelated (each pair has its own shuffle and scrambles): over
/// the 256 points of a pixel, the correlation of a coordinate of pair d with one of pair d + 1
/// averages to about 0 over pixels and is never large. (Pairs sharing a shuffle would give
/// |r| near 1; unrelated numbers give |r| about 1/16, these nets slightly more.)
#[test]
fn pairs_are_decorrelated() {
    let mut sum = 0.0;
    let mut sum_sq = 0.0;
    let mut count = 0.0;
    for pixel in 0..200u64 {
        for d in 0..4 {
            let a = points(pixel, d, 256);
            let b = points(pixel, d + 1, 256);
            for i in 0..2 {
                for j in 0..2 {
                    let x: Vec<f64> = a.iter().map(|p| f64::from(p[i])).collect();
                    let y: Vec<f64> = b.iter().map(|p| f64::from(p[j])).collect();
                    let (mx, my) = (x.iter().sum::<f64>() / 256.0, y.iter().sum::<f64>() / 256.0);
                    let cov: f64 = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum();
                    let vx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
                    let vy: f64 = y.iter().map(|y| (y - my).powi(2)).sum();
                    let r = cov / (vx * vy).sqrt();
                    assert!(r.abs() < 0.5, "pixel {pixel}, pairs {d}/{}: r = {r}", d + 1);
                    sum += r;
                    sum_sq += r * r;
                    count += 1.0;
                }
            }
        }
    }
    let (mean, sd) = (sum / count, (sum_sq / count).sqrt());
    assert!(mean.abs() < 0.02, "mean r = {mean}");
    assert!(sd < 0.1, "rms r = {sd}");
}

/// Sample s of frame f in batches of n is point f·n + s: one batch of 8, two of 4 and eight
/// frames of 1 draw the same numbers, dimension by dimension.
#[test]
fn batches_and_passes_draw_the_same_points() {
    let draws = |mut s: Stream| {
        let o = s.pixel_offset().unwrap();
        [o, s.next_2d(), [s.next_1d(), 0.0], s.next_2d()]
    };
    for i in 0..8u32 {
        let one = draws(Stream::for_sample(Sampler::Sobol, 42, i, 8, 0));
        let two = draws(Stream::for_sample(Sampler::Sobol, 42, i % 4, 4, i / 4));
        let pass = draws(Stream::for_sample(Sampler::Sobol, 42, 0, 1, i));
        assert_eq!(one, two);
        assert_eq!(one, pass);
    }
}

/// The independent sampler is the old generator, draw for draw (the bench's cached references
/// depend on it), and leaves the pixel offset to the render loop.
#[test]
fn the_independent_stream_is_the_old_generator() {
    let mut s = Stream::for_sample(Sampler::Independent, 5, 3, 16, 9);
    let mut r = Rng::for_sample(5, 3, 9);
    assert_eq!(s.pixel_offset(), None);
    for _ in 0..10 {
        assert_eq!(s.next_1d().to_bits(), r.next_f32().to_bits());
        let [a, b] = s.next_2d();
        assert_eq!(a.to_bits(), r.next_f32().to_bits());
        assert_eq!(b.to_bits(), r.next_f32().to_bits());
    }
}

#[test]
fn names_round_trip() {
    for s in Sampler::ALL {
        assert_eq!(Sampler::from_name(s.name()), Some(s));
    }
    assert_eq!(Sampler::from_name("halton"), None);
}

/// The superset sum is the Sobol sequence's second dimension as its direction numbers define
/// it (2⁻¹, then `v ← v ⊕ (v ≫ 1)`), checked bit by bit against the XOR of the direction
/// numbers of each index's set bits.
#[test]
fn the_second_dimension_follows_its_direction_numbers() {
    let by_definition = |index: u32| {
        let mut v = 1u32 << 31;
        let mut x = 0;
        for k in 0..32 {
            if index >> k & 1 != 0 {
                x ^= v;
            }
            v ^= v >> 1;
        }
        x
    };
    let mut r = Rng::seeded(11);
    for index in (0..4096).chain((0..4096).map(|_| r.next_u64() as u32)) {
        assert_eq!(
            sobol_1_reversed(index).reverse_bits(),
            by_definition(index),
            "{index}"
        );
    }
}

/// Branch b of k of point i draws, from its first draw on, what point i·k + b draws: the
/// branches of a pixel's N samples are the first kN points, every pair of them a net.
#[test]
fn branches_are_the_points_between() {
    let (pixel, k) = (77, 2);
    let mut branches = vec![];
    for i in 0..32 {
        for b in 0..k {
            let mut branch = Sobol::new(pixel, i).branch(b, k);
            let mut point = Sobol::new(pixel, i * k + b);
            for _ in 0..6 {
                let p = branch.next_2d();
                assert_eq!(p, point.next_2d());
                assert_eq!(branch.next_1d(), point.next_1d());
            }
            branches.push(Sobol::new(pixel, i).branch(b, k).next_2d());
        }
    }
    assert_eq!(t_value(&branches, 6), 0);
    // Independent numbers: each branch a stream of its own, none the path's.
    let r = Rng::for_sample(3, 4, 5);
    let [a, b] = [0, 1].map(|b| r.branch(b, 2).next_f32());
    assert!(a != b && a != r.clone().next_f32() && b != r.clone().next_f32());
}
