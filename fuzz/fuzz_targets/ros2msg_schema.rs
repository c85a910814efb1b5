//! The ROS 2 `.msg` schema parser (`ros2msg`) on arbitrary text: the first line is the schema
//! name, the rest the concatenated definition as an MCAP schema record holds it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use peopletrack::log::ros2msg::Registry;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (name, body) = text.split_once('\n').unwrap_or(("pkg/msg/T", text));
    if let Ok(reg) = Registry::parse(name, body) {
        let _ = reg.root_def();
    }
});
