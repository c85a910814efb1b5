//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// `../shared/real/<rel>` beside the project, or `None` (with a clear message on stderr) when
/// that folder is absent. The real data is read in place, never copied into the project.
pub fn real(rel: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/real")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: {} is absent; this test needs the real data in ../shared/real beside the project",
            p.display()
        );
        None
    }
}

pub fn laser_log(name: &str) -> Option<PathBuf> {
    real(&format!("laser/{name}/{name}.mcap"))
}

pub mod raw_mcap;
