//! Pipeline files: the TOML text parsed and validated as its `pipeline.kind` (every kind's
//! parameter types, range checks with key paths and lines, `[topics]` keys, stage plan),
//! exactly what `run` checks before it looks for sessions.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = peopletrack::pipelines::check_text(Path::new("fuzz.toml"), text);
});
