//! VertiAdaptor (`verti learn va`): the function-encoder kinodynamic model and its MLP,
//! first-order MAML and neural-ODE baselines, trained on random-exploration datasets; the
//! trained networks export to `verti_va` model cards that adapt and predict without burn.

pub mod adapt;
pub mod batch;
pub mod bench;
pub mod command;
pub mod export;
pub mod fit;
pub mod net;
pub mod report;
