//! PIETRA and its baselines on burn: the losses ([`special`]), the networks ([`model`]), the
//! benchmark's data ([`data`]), one training run ([`fit`]) and the learning benchmark of the
//! paper's Tables I–II and Fig. 6 ([`bench`](mod@bench)). The plain-Rust half (bins, physics prior, maps,
//! dataset, CVaR) is `verti-pietra`.

pub mod bench;
pub mod data;
pub mod export;
pub mod fit;
pub mod model;
pub mod special;
