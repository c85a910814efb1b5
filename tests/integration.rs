//! The integration tests, as one test binary (`cargo test --test integration [FILTER]`): one
//! module per file beside this one, sharing `common/`. One binary links the library once; as
//! 33 binaries of about 200 MB each they filled a CI runner's disk (`ld` died with SIGBUS) and
//! spent most of `make test` linking. The memory tests, which install a counting global
//! allocator, are the other binary, `memory_bounds.rs`.

mod common;

mod bad_config;
mod bad_input;
mod cdr_proptest;
mod cli;
mod concurrent_runs;
mod fast_paths;
mod foxglove;
mod fuzz_regressions;
mod gmm_synthetic;
mod gmm_wallflower;
mod hostile_logs;
mod hostile_mutations;
mod house_rules;
mod import_wildtrack;
mod io_errors;
mod laser_people;
mod mot_proptest;
mod mot_reference;
mod pipeline_runner;
mod real_logs;
mod roundtrip;
mod s000_cielniak_omni;
mod s001_kobilarov_following;
mod s003_biron_anchoring;
mod s003_zivkovic_background;
mod s004_mohedano_multicam;
mod s004_wildtrack;
mod score_cli;
mod shards;
mod skipped_sessions;
mod slurm;
mod synth;
mod synth_follow;
