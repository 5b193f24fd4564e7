//! Bicubic resampling of a square grid, as PIL's `Image.resize(..., BICUBIC)` does it (the
//! resampling Verti-Bench uses to turn its 128 x 128 SWAE output into a 129 x 129 map): the
//! Keys kernel with a = -0.5, pixel centres aligned ((i + 0.5) scale - 0.5), taps outside the
//! image dropped and the remaining weights renormalised. In f64, sequential: deterministic.

fn cubic(x: f64) -> f64 {
    const A: f64 = -0.5;
    let x = x.abs();
    if x < 1.0 {
        ((A + 2.0) * x - (A + 3.0)) * x * x + 1.0
    } else if x < 2.0 {
        (((x - 5.0) * x + 8.0) * x - 4.0) * A
    } else {
        0.0
    }
}

/// Taps (first index, weights) for each of `out` samples taken from `inp`.
fn taps(inp: usize, out: usize) -> Vec<(usize, Vec<f64>)> {
    let scale = inp as f64 / out as f64;
    // when shrinking, the kernel widens so every input contributes (PIL's support scaling)
    let support = 2.0 * scale.max(1.0);
    let stretch = scale.max(1.0);
    (0..out)
        .map(|i| {
            let centre = (i as f64 + 0.5) * scale;
            let lo = ((centre - support).floor().max(0.0)) as usize;
            let hi = ((centre + support).ceil() as usize).min(inp);
            let mut w: Vec<f64> = (lo..hi)
                .map(|j| cubic((j as f64 + 0.5 - centre) / stretch))
                .collect();
            let sum: f64 = w.iter().sum();
            for v in &mut w {
                *v /= sum;
            }
            (lo, w)
        })
        .collect()
}

/// Resizes an `inp` x `inp` row-major grid to `out` x `out`.
pub fn bicubic(src: &[f64], inp: usize, out: usize) -> Vec<f64> {
    assert_eq!(src.len(), inp * inp, "bicubic: grid is not {inp} x {inp}");
    let t = taps(inp, out);
    // rows first, then columns (PIL's order)
    let mut horizontal = vec![0.0; inp * out];
    for r in 0..inp {
        let row = &src[r * inp..(r + 1) * inp];
        for (c, (lo, w)) in t.iter().enumerate() {
            horizontal[r * out + c] = w.iter().enumerate().map(|(k, wk)| wk * row[lo + k]).sum();
        }
    }
    let mut dst = vec![0.0; out * out];
    for (r, (lo, w)) in t.iter().enumerate() {
        for c in 0..out {
            dst[r * out + c] = w
                .iter()
                .enumerate()
                .map(|(k, wk)| wk * horizontal[(lo + k) * out + c])
                .sum();
        }
    }
    dst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_and_ramps_survive_and_same_size_is_the_identity() {
        let flat = vec![0.3; 128 * 128];
        assert!(
            bicubic(&flat, 128, 129)
                .iter()
                .all(|v| (v - 0.3).abs() < 1e-12)
        );
        let ramp: Vec<f64> = (0..16 * 16).map(|i| (i % 16) as f64).collect();
        assert_eq!(bicubic(&ramp, 16, 16), ramp);
        // a linear ramp stays linear away from the borders (the cubic reproduces lines)
        let up = bicubic(&ramp, 16, 32);
        let (a, b) = (up[5 * 32 + 10], up[5 * 32 + 11]);
        assert!((b - a - 0.5).abs() < 1e-9, "{a} {b}");
    }
}
