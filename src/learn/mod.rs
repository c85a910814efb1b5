//! Learned models: the appearance-model network of seed 000 ([`mlp`]) and the random forest
//! of the learned laser leg detector ([`forest`]).

pub mod forest;
pub mod mlp;
