//! Layers and their forward pass, written as plain loops with a fixed summation order.
//!
//! Every output element is a sum whose terms are added in one documented order, with no fused
//! multiply-add (Rust never contracts `a * b + c`), no threads and no BLAS. The result is
//! therefore bit-identical on every machine, whatever its SIMD width: LLVM vectorises these
//! loops only across independent outputs, never by reassociating one output's sum. World
//! generation relies on this (the SWAE decoder makes terrain that must be byte-identical).
//!
//! Weight layouts follow burn's, so a trained burn module exports by copying its tensors:
//! `Linear` [inputs, outputs]; `Conv2d` [out, in, k, k]; `ConvTranspose2d` [in, out, k, k].

use serde::{Deserialize, Serialize};

/// One layer of a feed-forward network, as written in a model card.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum LayerSpec {
    /// y = x W + b.
    Linear {
        inputs: usize,
        outputs: usize,
    },
    /// Square kernel, zero padding.
    Conv2d {
        in_channels: usize,
        out_channels: usize,
        kernel: usize,
        stride: usize,
        padding: usize,
    },
    /// Transposed convolution: output side = (side - 1) stride - 2 padding + kernel + output_padding.
    ConvTranspose2d {
        in_channels: usize,
        out_channels: usize,
        kernel: usize,
        stride: usize,
        padding: usize,
        output_padding: usize,
    },
    Relu,
    /// max(x, slope x).
    LeakyRelu {
        slope: f32,
    },
    Tanh,
    /// Reinterprets a flat vector as [channels, height, width] (row-major, no copy).
    Reshape {
        shape: [usize; 3],
    },
    /// Reinterprets [channels, height, width] as a flat vector.
    Flatten,
}

/// The shape of an activation: a flat vector or [channels, height, width].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Shape {
    Flat(usize),
    Image([usize; 3]),
}

impl Shape {
    /// Number of values. Saturates at `usize::MAX` (a length no input can have) for a shape
    /// whose product overflows; a loaded [`crate::Network`] has none, since every shape of
    /// a card is checked with [`Shape::checked_len`].
    pub fn len(self) -> usize {
        self.checked_len().unwrap_or(usize::MAX)
    }
    /// Number of values, or None when the product overflows `usize` (a damaged or crafted
    /// card: the sizes come from the file).
    pub fn checked_len(self) -> Option<usize> {
        match self {
            Shape::Flat(n) => Some(n),
            Shape::Image([c, h, w]) => c.checked_mul(h)?.checked_mul(w),
        }
    }
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }
}

impl std::fmt::Display for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Shape::Flat(n) => write!(f, "[{n}]"),
            Shape::Image([c, h, w]) => write!(f, "[{c}, {h}, {w}]"),
        }
    }
}

impl LayerSpec {
    /// The layer's kind as the model card spells it.
    pub fn kind(&self) -> &'static str {
        match self {
            LayerSpec::Linear { .. } => "linear",
            LayerSpec::Conv2d { .. } => "conv2d",
            LayerSpec::ConvTranspose2d { .. } => "conv_transpose2d",
            LayerSpec::Relu => "relu",
            LayerSpec::LeakyRelu { .. } => "leaky_relu",
            LayerSpec::Tanh => "tanh",
            LayerSpec::Reshape { .. } => "reshape",
            LayerSpec::Flatten => "flatten",
        }
    }

    /// Number of parameters (weights, then biases). Saturates at `usize::MAX` (a count no
    /// weight file matches) for sizes whose product overflows; a loaded [`crate::Network`]
    /// has none, since its card is checked with [`LayerSpec::checked_parameter_count`].
    pub fn parameter_count(&self) -> usize {
        self.checked_parameter_count().unwrap_or(usize::MAX)
    }

    /// Number of parameters, or None when it overflows `usize`: the sizes come from a file,
    /// and a wrapped count could match a small weight file and pass its size and digest checks.
    pub fn checked_parameter_count(&self) -> Option<usize> {
        match *self {
            LayerSpec::Linear { inputs, outputs } => {
                inputs.checked_mul(outputs)?.checked_add(outputs)
            }
            LayerSpec::Conv2d {
                in_channels: i,
                out_channels: o,
                kernel: k,
                ..
            }
            | LayerSpec::ConvTranspose2d {
                in_channels: i,
                out_channels: o,
                kernel: k,
                ..
            } => i
                .checked_mul(o)?
                .checked_mul(k)?
                .checked_mul(k)?
                .checked_add(o),
            _ => Some(0),
        }
    }

    /// Values of the largest buffer [`LayerSpec::forward`] allocates besides its output (the
    /// column phases of a strided convolution), or None when that overflows `usize`. With a
    /// large stride it can be far bigger than the input, so a card's strides are bounded
    /// through it.
    pub fn scratch_len(&self, input: Shape) -> Option<usize> {
        match (self, input) {
            (&LayerSpec::Conv2d { stride, .. }, Shape::Image([c, h, w])) if stride > 0 => c
                .checked_mul(h)?
                .checked_mul(stride)?
                .checked_mul(w.div_ceil(stride)),
            _ => Some(0),
        }
    }

    /// The output shape for an input of shape `input`, or why the layer cannot take it.
    pub fn output_shape(&self, input: Shape) -> Result<Shape, String> {
        let image = |what: &str| match input {
            Shape::Image(s) => Ok(s),
            Shape::Flat(_) => Err(format!("{what} needs an image input, got {input}")),
        };
        match *self {
            LayerSpec::Linear { inputs, outputs } => match input {
                Shape::Flat(n) if n == inputs => Ok(Shape::Flat(outputs)),
                _ => Err(format!("linear layer takes [{inputs}], got {input}")),
            },
            LayerSpec::Conv2d {
                in_channels,
                out_channels,
                kernel,
                stride,
                padding,
            } => {
                let [c, h, w] = image("conv2d")?;
                if c != in_channels {
                    return Err(format!("conv2d takes {in_channels} channels, got {input}"));
                }
                // checked: every size comes from the file
                let side = |n: usize| {
                    let padded = padding.checked_mul(2)?.checked_add(n)?;
                    Some(padded.checked_sub(kernel)?.checked_div(stride)? + 1)
                };
                match (side(h), side(w)) {
                    (Some(oh), Some(ow)) if kernel > 0 => Ok(Shape::Image([out_channels, oh, ow])),
                    _ => Err(format!(
                        "conv2d kernel {kernel} stride {stride} padding {padding} does not fit {input}"
                    )),
                }
            }
            LayerSpec::ConvTranspose2d {
                in_channels,
                out_channels,
                kernel,
                stride,
                padding,
                output_padding,
            } => {
                let [c, h, w] = image("conv_transpose2d")?;
                if c != in_channels {
                    return Err(format!(
                        "conv_transpose2d takes {in_channels} channels, got {input}"
                    ));
                }
                // checked: every size comes from the file (and a side of 0 has no n - 1)
                let side = |n: usize| {
                    n.checked_sub(1)?
                        .checked_mul(stride)?
                        .checked_add(kernel)?
                        .checked_add(output_padding)?
                        .checked_sub(padding.checked_mul(2)?)
                };
                match (stride, kernel, side(h), side(w)) {
                    (1.., 1.., Some(oh @ 1..), Some(ow @ 1..)) => {
                        Ok(Shape::Image([out_channels, oh, ow]))
                    }
                    _ => Err(format!(
                        "conv_transpose2d kernel {kernel} stride {stride} padding {padding} does not fit {input}"
                    )),
                }
            }
            LayerSpec::LeakyRelu { slope } if !slope.is_finite() => {
                Err(format!("leaky_relu slope {slope} is not finite"))
            }
            LayerSpec::Relu | LayerSpec::LeakyRelu { .. } | LayerSpec::Tanh => Ok(input),
            LayerSpec::Reshape { shape } => {
                let out = Shape::Image(shape);
                match (out.checked_len(), input.checked_len()) {
                    (Some(a), Some(b)) if a == b => Ok(out),
                    _ => Err(format!("cannot reshape {input} to {out}")),
                }
            }
            LayerSpec::Flatten => input
                .checked_len()
                .map(Shape::Flat)
                .ok_or_else(|| format!("cannot flatten {input}: its length overflows")),
        }
    }

    /// Applies the layer. `params` holds exactly `parameter_count()` values (weights, then
    /// biases); `input` has the shape `shape` that [`LayerSpec::output_shape`] accepted.
    pub fn forward(&self, params: &[f32], shape: Shape, input: Vec<f32>) -> Vec<f32> {
        match *self {
            LayerSpec::Linear { inputs, outputs } => {
                let (w, b) = params.split_at(inputs * outputs);
                linear(w, b, &input)
            }
            LayerSpec::Conv2d {
                in_channels,
                out_channels,
                kernel,
                stride,
                padding,
            } => {
                let Shape::Image([_, h, w]) = shape else {
                    unreachable!("shape checked when the network was built")
                };
                let (wt, b) = params.split_at(in_channels * out_channels * kernel * kernel);
                conv2d(
                    &input,
                    [in_channels, h, w],
                    wt,
                    b,
                    out_channels,
                    kernel,
                    stride,
                    padding,
                )
            }
            LayerSpec::ConvTranspose2d {
                in_channels,
                out_channels,
                kernel,
                stride,
                padding,
                output_padding,
            } => {
                let Shape::Image([_, h, w]) = shape else {
                    unreachable!("shape checked when the network was built")
                };
                let (wt, b) = params.split_at(in_channels * out_channels * kernel * kernel);
                conv_transpose2d(
                    &input,
                    [in_channels, h, w],
                    wt,
                    b,
                    out_channels,
                    kernel,
                    stride,
                    padding,
                    output_padding,
                )
            }
            LayerSpec::Relu => map(input, |x| x.max(0.0)),
            LayerSpec::LeakyRelu { slope } => map(input, |x| if x >= 0.0 { x } else { slope * x }),
            LayerSpec::Tanh => map(input, libm::tanhf),
            LayerSpec::Reshape { .. } | LayerSpec::Flatten => input,
        }
    }
}

fn map(mut v: Vec<f32>, f: impl Fn(f32) -> f32) -> Vec<f32> {
    for x in &mut v {
        *x = f(*x);
    }
    v
}

/// y[o] = b[o] + x[0] W[0, o] + x[1] W[1, o] + ... (inputs in ascending order).
fn linear(w: &[f32], b: &[f32], x: &[f32]) -> Vec<f32> {
    let outputs = b.len();
    let mut y = b.to_vec();
    for (xi, row) in x.iter().zip(w.chunks_exact(outputs)) {
        for (yo, wio) in y.iter_mut().zip(row) {
            *yo += xi * wio;
        }
    }
    y
}

/// Each output is its bias plus the terms in the order (input channel, kernel row, kernel
/// column), all ascending; taps in the padding add nothing (they are skipped, not added as
/// zeros).
///
/// Each input row is first split into its `stride` column phases (phase r holds columns r,
/// r + stride, ...), so that for one kernel tap the inputs of consecutive outputs are
/// consecutive and the loop over an output row has no branch and no stride: it vectorises.
/// Every output still adds its terms in the order above, so the bits are those of the direct
/// loops (tested against them).
#[allow(clippy::too_many_arguments)]
fn conv2d(
    x: &[f32],
    [cin, h, w]: [usize; 3],
    wt: &[f32],
    b: &[f32],
    cout: usize,
    k: usize,
    stride: usize,
    pad: usize,
) -> Vec<f32> {
    let oh = (h + 2 * pad - k) / stride + 1;
    let ow = (w + 2 * pad - k) / stride + 1;
    let pw = w.div_ceil(stride);
    let mut phased = vec![0.0f32; cin * h * stride * pw];
    for (r, row) in x.chunks_exact(w).enumerate() {
        for (c, v) in row.iter().enumerate() {
            phased[(r * stride + c % stride) * pw + c / stride] = *v;
        }
    }
    // for each kernel column: the outputs whose tap lies inside the row, lo..hi, and where
    // the first of them reads (phase, index within the phase)
    let columns: Vec<(usize, usize, usize, usize)> = (0..k)
        .map(|kx| {
            let (kx, pad, stride, w) = (kx as isize, pad as isize, stride as isize, w as isize);
            // ix = ox·stride + kx − pad must lie in [0, w)
            let lo = if kx >= pad {
                0
            } else {
                (pad - kx + stride - 1) / stride
            };
            let hi = if w - 1 + pad - kx < 0 {
                0
            } else {
                (w - 1 + pad - kx) / stride + 1
            };
            let hi = hi.min(ow as isize).max(lo);
            let ix = lo * stride + kx - pad;
            let ix = ix.max(0);
            (
                lo as usize,
                hi as usize,
                (ix % stride) as usize,
                (ix / stride) as usize,
            )
        })
        .collect();
    let mut y = vec![0.0f32; cout * oh * ow];
    for (o, plane) in y.chunks_exact_mut(oh * ow).enumerate() {
        plane.fill(b[o]);
        for i in 0..cin {
            for ky in 0..k {
                for (kx, &(lo, hi, phase, start)) in columns.iter().enumerate() {
                    let wv = wt[((o * cin + i) * k + ky) * k + kx];
                    for oy in 0..oh {
                        let iy = (oy * stride + ky) as isize - pad as isize;
                        if iy < 0 || iy >= h as isize {
                            continue;
                        }
                        let src = &phased[((i * h + iy as usize) * stride + phase) * pw + start..];
                        let out = &mut plane[oy * ow + lo..oy * ow + hi];
                        for (yv, xv) in out.iter_mut().zip(src) {
                            *yv += xv * wv;
                        }
                    }
                }
            }
        }
    }
    y
}

/// Transposed convolution as a gather: output (oy, ox) takes input (iy, ix) through kernel tap
/// (ky, kx) where oy = iy stride - pad + ky. Each output is its bias plus the terms in the
/// order (input channel, kernel row, kernel column), all ascending.
#[allow(clippy::too_many_arguments)]
fn conv_transpose2d(
    x: &[f32],
    [cin, h, w]: [usize; 3],
    wt: &[f32],
    b: &[f32],
    cout: usize,
    k: usize,
    stride: usize,
    pad: usize,
    out_pad: usize,
) -> Vec<f32> {
    let oh = (h - 1) * stride + k + out_pad - 2 * pad;
    let ow = (w - 1) * stride + k + out_pad - 2 * pad;
    let mut y = vec![0.0f32; cout * oh * ow];
    for (o, plane) in y.chunks_exact_mut(oh * ow).enumerate() {
        plane.fill(b[o]);
        for i in 0..cin {
            let xin = &x[i * h * w..(i + 1) * h * w];
            for ky in 0..k {
                for kx in 0..k {
                    let wv = wt[((i * cout + o) * k + ky) * k + kx];
                    for oy in 0..oh {
                        // oy + pad - ky must be a non-negative multiple of the stride
                        let ny = oy as isize + pad as isize - ky as isize;
                        if ny < 0 || ny % stride as isize != 0 {
                            continue;
                        }
                        let iy = (ny / stride as isize) as usize;
                        if iy >= h {
                            continue;
                        }
                        let row = &xin[iy * w..(iy + 1) * w];
                        let out = &mut plane[oy * ow..(oy + 1) * ow];
                        for (ox, yv) in out.iter_mut().enumerate() {
                            let nx = ox as isize + pad as isize - kx as isize;
                            if nx >= 0 && nx % stride as isize == 0 {
                                let ix = (nx / stride as isize) as usize;
                                if ix < w {
                                    *yv += row[ix] * wv;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_matches_a_hand_computation() {
        // W = [[1, 2], [3, 4], [5, 6]] (3 inputs, 2 outputs), b = [0.5, -1]
        let spec = LayerSpec::Linear {
            inputs: 3,
            outputs: 2,
        };
        let p = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 0.5, -1.0];
        let y = spec.forward(&p, Shape::Flat(3), vec![1.0, 0.0, -1.0]);
        assert_eq!(y, vec![1.0 - 5.0 + 0.5, 2.0 - 6.0 - 1.0]);
    }

    #[test]
    fn conv2d_with_a_centre_tap_kernel_is_the_identity_and_stride_subsamples() {
        let mut w = vec![0.0; 9];
        w[4] = 1.0;
        let p: Vec<f32> = w.into_iter().chain([0.0]).collect();
        let x: Vec<f32> = (0..16).map(|v| v as f32).collect();
        let s1 = LayerSpec::Conv2d {
            in_channels: 1,
            out_channels: 1,
            kernel: 3,
            stride: 1,
            padding: 1,
        };
        assert_eq!(s1.forward(&p, Shape::Image([1, 4, 4]), x.clone()), x);
        let s2 = LayerSpec::Conv2d {
            in_channels: 1,
            out_channels: 1,
            kernel: 3,
            stride: 2,
            padding: 1,
        };
        assert_eq!(
            s2.output_shape(Shape::Image([1, 4, 4])),
            Ok(Shape::Image([1, 2, 2]))
        );
        assert_eq!(
            s2.forward(&p, Shape::Image([1, 4, 4]), x),
            vec![0.0, 2.0, 8.0, 10.0]
        );
    }

    /// The direct loops [`conv2d`] must equal bit for bit.
    #[allow(clippy::too_many_arguments)]
    fn conv2d_direct(
        x: &[f32],
        [cin, h, w]: [usize; 3],
        wt: &[f32],
        b: &[f32],
        cout: usize,
        k: usize,
        stride: usize,
        pad: usize,
    ) -> Vec<f32> {
        let oh = (h + 2 * pad - k) / stride + 1;
        let ow = (w + 2 * pad - k) / stride + 1;
        let mut y = vec![0.0f32; cout * oh * ow];
        for (o, plane) in y.chunks_exact_mut(oh * ow).enumerate() {
            plane.fill(b[o]);
            for i in 0..cin {
                let xin = &x[i * h * w..(i + 1) * h * w];
                for ky in 0..k {
                    for kx in 0..k {
                        let wv = wt[((o * cin + i) * k + ky) * k + kx];
                        for oy in 0..oh {
                            let iy = (oy * stride + ky) as isize - pad as isize;
                            if iy < 0 || iy >= h as isize {
                                continue;
                            }
                            let row = &xin[iy as usize * w..(iy as usize + 1) * w];
                            let out = &mut plane[oy * ow..(oy + 1) * ow];
                            for (ox, yv) in out.iter_mut().enumerate() {
                                let ix = (ox * stride + kx) as isize - pad as isize;
                                if ix >= 0 && ix < w as isize {
                                    *yv += row[ix as usize] * wv;
                                }
                            }
                        }
                    }
                }
            }
        }
        y
    }

    #[test]
    fn conv2d_equals_the_direct_loops_bit_for_bit() {
        let mut seed = 1u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        for &(cin, cout, k, stride, pad, h, w) in &[
            (1, 8, 3, 2, 1, 64, 64),
            (3, 2, 3, 1, 1, 5, 7),
            (2, 3, 5, 2, 2, 9, 6),
            (1, 1, 1, 3, 0, 7, 8),
            (2, 2, 3, 3, 2, 4, 5),
            (1, 2, 4, 2, 1, 6, 6),
            (1, 1, 3, 2, 1, 1, 1),
        ] {
            let x: Vec<f32> = (0..cin * h * w).map(|_| next()).collect();
            let wt: Vec<f32> = (0..cout * cin * k * k).map(|_| next()).collect();
            let b: Vec<f32> = (0..cout).map(|_| next()).collect();
            let fast = conv2d(&x, [cin, h, w], &wt, &b, cout, k, stride, pad);
            let direct = conv2d_direct(&x, [cin, h, w], &wt, &b, cout, k, stride, pad);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&fast),
                bits(&direct),
                "{cin} {cout} {k} {stride} {pad} {h} {w}"
            );
        }
    }

    #[test]
    fn conv_transpose_is_the_adjoint_of_conv() {
        // <conv(x), y> = <x, conv_t(y)> for the same weights (no bias): the definition of
        // the transposed convolution, checked on random-ish values.
        let (cin, cout, k, s, p) = (2, 3, 3, 2, 1);
        let n = |i: usize| ((i * 7919 % 101) as f32 - 50.0) / 50.0;
        let wt: Vec<f32> = (0..cout * cin * k * k).map(n).collect();
        let x: Vec<f32> = (0..cin * 6 * 6).map(|i| n(i + 13)).collect();
        let cx = conv2d(&x, [cin, 6, 6], &wt, &[0.0; 3], cout, k, s, p);
        let y: Vec<f32> = (0..cx.len()).map(|i| n(i + 31)).collect();
        // conv weights [out, in, k, k] read as a transposed conv from `cout` to `cin`
        // channels are [in = cout, out = cin, k, k]: the same array
        let ty = conv_transpose2d(&y, [cout, 3, 3], &wt, &[0.0; 2], cin, k, s, p, 1);
        assert_eq!(ty.len(), x.len());
        let lhs: f64 = cx.iter().zip(&y).map(|(a, b)| f64::from(a * b)).sum();
        let rhs: f64 = x.iter().zip(&ty).map(|(a, b)| f64::from(a * b)).sum();
        assert!((lhs - rhs).abs() < 1e-4, "{lhs} vs {rhs}");
    }

    #[test]
    fn shapes_are_checked_with_clear_messages() {
        let l = LayerSpec::Linear {
            inputs: 4,
            outputs: 2,
        };
        assert!(l.output_shape(Shape::Flat(3)).unwrap_err().contains("[4]"));
        let r = LayerSpec::Reshape { shape: [2, 2, 2] };
        assert_eq!(r.output_shape(Shape::Flat(8)), Ok(Shape::Image([2, 2, 2])));
        assert!(r.output_shape(Shape::Flat(7)).is_err());
        let t = LayerSpec::ConvTranspose2d {
            in_channels: 4,
            out_channels: 2,
            kernel: 3,
            stride: 2,
            padding: 1,
            output_padding: 1,
        };
        assert_eq!(
            t.output_shape(Shape::Image([4, 4, 4])),
            Ok(Shape::Image([2, 8, 8]))
        );
    }
}
