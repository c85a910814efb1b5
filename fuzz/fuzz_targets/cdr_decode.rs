//! CDR decoding against a parsed schema: the input is `name \n definition \0 payload`; the
//! schema is parsed as a schema record's would be, and when it parses the payload is decoded.
//! Seeds carry the real logs' schemas with their real payloads.
#![no_main]

use libfuzzer_sys::fuzz_target;
use peopletrack::log::{cdr, ros2msg::Registry};

fuzz_target!(|data: &[u8]| {
    let Some(nul) = data.iter().position(|&b| b == 0) else {
        return;
    };
    let (schema, payload) = (&data[..nul], &data[nul + 1..]);
    let Ok(text) = std::str::from_utf8(schema) else {
        return;
    };
    let Some((name, body)) = text.split_once('\n') else {
        return;
    };
    if let Ok(reg) = Registry::parse(name, body) {
        let _ = cdr::decode(&reg, payload);
    }
});
