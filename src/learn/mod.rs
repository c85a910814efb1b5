//! Learned models: the appearance-model network of seed 000 ([`mlp`]).

pub mod mlp;
