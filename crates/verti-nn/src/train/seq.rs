//! A burn module built from the same layer list that `verti-nn` evaluates, so a network
//! trained here exports to a model card and weight file by copying its tensors, and the
//! exported network computes the same function (checked by the tests).

use crate::{LayerSpec, Shape};
use burn::module::Module;
use burn::module::Param;
use burn::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d, ConvTranspose2dConfig};
use burn::nn::{Linear, LinearConfig, PaddingConfig2d};
use burn::tensor::activation::{leaky_relu, relu, tanh};
use burn::tensor::{Device, Tensor, TensorData};

/// The layers of a fully connected network: `inputs` → each of `hidden` (followed by
/// `activation`) → `outputs`, no activation after the last layer.
pub fn mlp_layers(
    inputs: usize,
    hidden: &[usize],
    outputs: usize,
    activation: LayerSpec,
) -> Vec<LayerSpec> {
    let mut layers = Vec::new();
    let mut width = inputs;
    for &h in hidden {
        layers.push(LayerSpec::Linear {
            inputs: width,
            outputs: h,
        });
        layers.push(activation.clone());
        width = h;
    }
    layers.push(LayerSpec::Linear {
        inputs: width,
        outputs,
    });
    layers
}

/// A batch of activations: flat `[batch, n]` or images `[batch, c, h, w]`.
#[derive(Clone, Debug)]
pub enum Act {
    Flat(Tensor<2>),
    Image(Tensor<4>),
}

impl Act {
    pub fn flat(self) -> Tensor<2> {
        match self {
            Act::Flat(t) => t,
            Act::Image(t) => {
                let [b, c, h, w] = t.dims();
                t.reshape([b, c * h * w])
            }
        }
    }
    pub fn image(self) -> Tensor<4> {
        match self {
            Act::Image(t) => t,
            Act::Flat(_) => panic!("expected an image activation"),
        }
    }
}

/// A feed-forward network of [`LayerSpec`]s. Parameterised layers live in one vector per
/// kind; `layers` says in which order to apply them.
#[derive(Module, Debug)]
pub struct SeqNet {
    linears: Vec<Linear>,
    convs: Vec<Conv2d>,
    deconvs: Vec<ConvTranspose2d>,
    #[module(skip)]
    layers: Vec<LayerSpec>,
    #[module(skip)]
    input: Shape,
}

impl SeqNet {
    /// Initialises the layers (burn's default initialisers) after checking the shapes.
    pub fn new(input: Shape, layers: &[LayerSpec], device: &Device) -> Result<SeqNet, String> {
        let mut shape = input;
        let (mut linears, mut convs, mut deconvs) = (vec![], vec![], vec![]);
        for (i, l) in layers.iter().enumerate() {
            shape = l
                .output_shape(shape)
                .map_err(|e| format!("layer {i}: {e}"))?;
            match *l {
                LayerSpec::Linear { inputs, outputs } => {
                    linears.push(LinearConfig::new(inputs, outputs).init(device))
                }
                LayerSpec::Conv2d {
                    in_channels,
                    out_channels,
                    kernel,
                    stride,
                    padding,
                } => convs.push(
                    Conv2dConfig::new([in_channels, out_channels], [kernel, kernel])
                        .with_stride([stride, stride])
                        .with_padding(PaddingConfig2d::Explicit(
                            padding, padding, padding, padding,
                        ))
                        .init(device),
                ),
                LayerSpec::ConvTranspose2d {
                    in_channels,
                    out_channels,
                    kernel,
                    stride,
                    padding,
                    output_padding,
                } => deconvs.push(
                    ConvTranspose2dConfig::new([in_channels, out_channels], [kernel, kernel])
                        .with_stride([stride, stride])
                        .with_padding([padding, padding])
                        .with_padding_out([output_padding, output_padding])
                        .init(device),
                ),
                _ => {}
            }
        }
        Ok(SeqNet {
            linears,
            convs,
            deconvs,
            layers: layers.to_vec(),
            input,
        })
    }

    pub fn layers(&self) -> &[LayerSpec] {
        &self.layers
    }
    pub fn input_shape(&self) -> Shape {
        self.input
    }

    /// Runs a batch through the layers in order.
    pub fn forward(&self, x: Act) -> Act {
        let (mut li, mut ci, mut di) = (0, 0, 0);
        let mut x = x;
        for l in &self.layers {
            x = match *l {
                LayerSpec::Linear { .. } => {
                    li += 1;
                    Act::Flat(self.linears[li - 1].forward(x.flat()))
                }
                LayerSpec::Conv2d { .. } => {
                    ci += 1;
                    Act::Image(self.convs[ci - 1].forward(x.image()))
                }
                LayerSpec::ConvTranspose2d { .. } => {
                    di += 1;
                    Act::Image(self.deconvs[di - 1].forward(x.image()))
                }
                LayerSpec::Relu => match x {
                    Act::Flat(t) => Act::Flat(relu(t)),
                    Act::Image(t) => Act::Image(relu(t)),
                },
                LayerSpec::LeakyRelu { slope } => match x {
                    Act::Flat(t) => Act::Flat(leaky_relu(t, f64::from(slope))),
                    Act::Image(t) => Act::Image(leaky_relu(t, f64::from(slope))),
                },
                LayerSpec::Tanh => match x {
                    Act::Flat(t) => Act::Flat(tanh(t)),
                    Act::Image(t) => Act::Image(tanh(t)),
                },
                LayerSpec::Reshape { shape: [c, h, w] } => {
                    let t = x.flat();
                    let [b, _] = t.dims();
                    Act::Image(t.reshape([b, c, h, w]))
                }
                LayerSpec::Flatten => Act::Flat(x.flat()),
            };
        }
        x
    }

    /// Replaces the parameters of a network of linear layers (and activations) with
    /// `params` in `verti-nn`'s order and layout, the inverse of [`SeqNet::export_params`]
    /// (resuming training from an exported checkpoint).
    pub fn import_params(mut self, params: &[f32], device: &Device) -> Result<SeqNet, String> {
        let mut at = 0;
        let mut li = 0;
        for l in &self.layers {
            match *l {
                LayerSpec::Linear { inputs, outputs } => {
                    let (w, b) = (inputs * outputs, outputs);
                    if at + w + b > params.len() {
                        return Err(format!(
                            "{} parameters given, layer {li} needs more",
                            params.len()
                        ));
                    }
                    let m = &mut self.linears[li];
                    m.weight = Param::from_tensor(Tensor::from_data(
                        TensorData::new(params[at..at + w].to_vec(), [inputs, outputs]),
                        device,
                    ));
                    m.bias = Some(Param::from_tensor(Tensor::from_data(
                        TensorData::new(params[at + w..at + w + b].to_vec(), [outputs]),
                        device,
                    )));
                    at += w + b;
                    li += 1;
                }
                LayerSpec::Relu | LayerSpec::Tanh | LayerSpec::LeakyRelu { .. } => {}
                ref other => {
                    return Err(format!(
                        "importing parameters into a {} layer is not supported",
                        other.kind()
                    ));
                }
            }
        }
        if at != params.len() {
            return Err(format!(
                "{} parameters given, the network has {at}",
                params.len()
            ));
        }
        Ok(self)
    }

    /// Every parameter in `verti-nn`'s order and layout (per layer: weights, then biases).
    pub fn export_params(&self) -> Vec<f32> {
        let (mut li, mut ci, mut di) = (0, 0, 0);
        let mut out = Vec::new();
        let mut push = |w: Vec<f32>, b: Option<Vec<f32>>| {
            out.extend(w);
            out.extend(b.expect("layers are built with biases"));
        };
        for l in &self.layers {
            match l {
                LayerSpec::Linear { .. } => {
                    let m = &self.linears[li];
                    li += 1;
                    push(
                        values(m.weight.val()),
                        m.bias.as_ref().map(|b| values(b.val())),
                    );
                }
                LayerSpec::Conv2d { .. } => {
                    let m = &self.convs[ci];
                    ci += 1;
                    push(
                        values(m.weight.val()),
                        m.bias.as_ref().map(|b| values(b.val())),
                    );
                }
                LayerSpec::ConvTranspose2d { .. } => {
                    let m = &self.deconvs[di];
                    di += 1;
                    push(
                        values(m.weight.val()),
                        m.bias.as_ref().map(|b| values(b.val())),
                    );
                }
                _ => {}
            }
        }
        out
    }
}

/// A tensor's values in row-major order.
pub fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data()
        .convert::<f32>()
        .try_to_vec::<f32>()
        .expect("float tensors convert to f32")
}
