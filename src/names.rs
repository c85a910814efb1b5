//! Names made safe for files: what a topic, camera or dataset name becomes in a file name.

/// `s` with every character other than ASCII letters, digits, `_` and `-` replaced by `_`
/// (`/cam_0/image` → `_cam_0_image`).
pub fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn only_letters_digits_underscore_and_dash_survive() {
        assert_eq!(
            super::sanitize("/cam_0/image raw.Ü-1"),
            "_cam_0_image_raw__-1"
        );
        assert_eq!(super::sanitize(""), "");
    }
}
