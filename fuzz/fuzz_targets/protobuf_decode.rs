//! Protobuf decoding as for Foxglove channels: the input is `message name \0`, a little-endian
//! u32 length, that many bytes of `FileDescriptorSet` (a schema record's data), then the
//! payload. Seeds carry the Foxglove descriptor sets with real messages.
#![no_main]

use libfuzzer_sys::fuzz_target;
use peopletrack::log::protobuf;

fuzz_target!(|data: &[u8]| {
    let Some(nul) = data.iter().position(|&b| b == 0) else {
        return;
    };
    let Ok(name) = std::str::from_utf8(&data[..nul]) else {
        return;
    };
    let rest = &data[nul + 1..];
    let Some((len, rest)) = rest.split_first_chunk::<4>() else {
        return;
    };
    let len = u32::from_le_bytes(*len) as usize;
    if len > rest.len() {
        return;
    }
    let (set, payload) = rest.split_at(len);
    if let Ok(desc) = protobuf::descriptor(name, set) {
        let _ = protobuf::decode(&desc, payload);
    }
});
