//! The dimensions of a VertiAdaptor network: its pose change, embeddings and field inputs.
//! Below both `model` (the card and plain evaluation) and `fields` (the fast field kernel,
//! which `model` calls), so neither imports the other for them. Public through `crate::model`.

/// Heading-frame pose change: forward, left, up, yaw, roll, pitch (verti-kino's order).
pub const POSE_DIM: usize = 6;
/// Width of each compressed embedding (paper: 8).
pub const EMBED: usize = 8;
/// Inputs of a field: roll, pitch, two embeddings, speed, steering.
pub const FIELD_INPUT: usize = 2 + 2 * EMBED + 2;
/// Hidden widths of the embedding compressions (64 → 32 → 16 → 8, tanh at the end).
pub const EMBED_HIDDEN: [usize; 2] = [32, 16];
