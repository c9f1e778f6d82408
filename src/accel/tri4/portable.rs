//! The portable twin of the SIMD kernels, one lane at a time: the statement of what they
//! compute, and the path on CPUs without SSE2.

use super::{Candidates, LANES, RayLanes, Tri4};

/// The candidates among `block`'s lanes, one lane at a time: the portable twin of the SIMD
/// kernels and the statement of what they compute.
pub fn candidates_portable(block: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    let [kx, ky, kz] = r.axes;
    let [ox, oy, oz] = r.origin;
    let [sx, sy, sz] = r.shear;
    let mut out = Candidates {
        mask: 0,
        t: [0.0; 2 * LANES],
    };
    for lane in 0..LANES {
        let v = &block.v;
        let mut x = [0f32; 3];
        let mut y = [0f32; 3];
        let mut z = [0f32; 3];
        for i in 0..3 {
            let (a, b, c) = (
                v[i][kx][lane] - ox,
                v[i][ky][lane] - oy,
                v[i][kz][lane] - oz,
            );
            x[i] = a + sx * c;
            y[i] = b + sy * c;
            z[i] = c;
        }
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        if e[0] == 0.0 || e[1] == 0.0 || e[2] == 0.0 {
            out.mask |= 1 << lane;
            out.t[lane] = f32::NEG_INFINITY;
            continue;
        }
        if (e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0) && (e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0) {
            continue;
        }
        let det = e[0] + e[1] + e[2];
        if det == 0.0 || det.is_nan() {
            continue;
        }
        let z = z.map(|z| sz * z);
        let t_scaled = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
        let bound = t_max * det;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < bound) {
            continue;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > bound) {
            continue;
        }
        out.mask |= 1 << lane;
        out.t[lane] = t_scaled * (1.0 / det);
    }
    out
}

/// The candidates of two blocks (lanes 0-3 from `a`, 4-7 from `b`), one lane at a time.
pub fn candidates2_portable(a: &Tri4, b: &Tri4, r: &RayLanes, t_max: f32) -> Candidates {
    let (ca, cb) = (
        candidates_portable(a, r, t_max),
        candidates_portable(b, r, t_max),
    );
    let mut t = ca.t;
    t[LANES..].copy_from_slice(&cb.t[..LANES]);
    Candidates {
        mask: ca.mask | cb.mask << LANES,
        t,
    }
}
