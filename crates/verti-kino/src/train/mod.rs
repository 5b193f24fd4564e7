//! Training the kinodynamic models on burn (feature `train`): the ensembles of MPPI-6 and
//! WMVCT ([`kino`]), TAL's attentive model ([`tal`]), TNT's traversability network ([`trav`]),
//! what they share (data rows, export to cards: [`kino_shared`]) and the `verti learn kino`
//! run with its validation and curve ([`kino_command`]). The trained cards run without burn
//! through the rest of this crate.

pub mod kino;
pub mod kino_command;
pub mod kino_shared;
pub mod tal;
pub mod trav;
