//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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

/// Rows of a CSV table as column → value maps (naive split: for tables without quoted commas).
pub fn csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            head.iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}
