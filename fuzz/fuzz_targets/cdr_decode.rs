//! CDR decoding against a parsed schema: the input is `name \n definition \0 payload`; the
//! schema is parsed as a schema record's would be, and when it parses the payload is decoded.
//! Seeds carry the real logs' schemas with their real payloads.
//!
//! Differential: `cat`'s wire-to-JSON writer (`cdr::write_json`) must accept exactly the
//! payloads the dynamic decoder accepts and write the same text as the value tree's JSON.
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
        let tree = cdr::decode(&reg, payload);
        let mut floats = cdr::FloatText::default();
        for max_array in [None, Some(3)] {
            let mut wire = Vec::new();
            let direct = cdr::write_json(&reg, payload, max_array, &mut floats, &mut wire);
            match (&tree, direct) {
                (Ok(v), Ok(())) => {
                    let want = serde_json::to_vec(&v.json(max_array)).expect("a value tree serialises");
                    assert_eq!(wire, want, "wire JSON differs from the value tree's");
                }
                (Err(_), Err(_)) => {}
                (t, d) => panic!("decoders disagree: tree {:?}, wire {:?}", t.is_ok(), d.is_ok()),
            }
        }
    }
});
