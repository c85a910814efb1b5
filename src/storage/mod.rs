//! Logs and outputs addressed by URL as well as by path: `s3://bucket/prefix/...` through the
//! `object_store` crate (the version polars already locks, so one copy is compiled), behind
//! the `s3` cargo feature (`make build-s3`); a build without it says so when given a URL.
//!
//! - **Logs** are read in place with range requests ([`RemoteObject::read_at`]): the MCAP
//!   reader asks for the footer, then the summary section, then only the chunks that hold the
//!   wanted topics, so a one-topic read fetches a fraction of the file ([`bytes_fetched`]
//!   counts it). A remote log's content key is its ETag and size (hashing its bytes would
//!   download all of it); a store without ETags is hashed by reading it once.
//! - **Sessions** are found by listing the prefix before a glob's first wildcard and matching
//!   the full URL against the glob ([`list_matching`]).
//! - **Outputs** (`--out s3://...`) go through a local mirror ([`mirror::Mirror`]): the
//!   pipeline's folder is fetched, the run works on local files exactly as it does without a
//!   store (atomic renames, locks), and every file that changed is then written back with one
//!   put each, a session's `key.txt` after its tables.
//!
//! Written by hand: the glue is small and no crate maps "a path or a URL" onto both our
//! synchronous reader and `object_store`'s async API.

pub mod mirror;
#[cfg(feature = "s3")]
mod remote;

use std::io;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

#[cfg(feature = "s3")]
pub use remote::{RemoteObject, get, list, list_matching, put};

/// The URL schemes read through an object store.
pub const SCHEMES: [&str; 1] = ["s3://"];

/// Whether `p` names an object in a store (`s3://...`) rather than a local file.
pub fn is_url(p: &Path) -> bool {
    p.to_str()
        .is_some_and(|s| SCHEMES.iter().any(|scheme| s.starts_with(scheme)))
}

static FETCHED: AtomicU64 = AtomicU64::new(0);

/// Bytes fetched from object stores by this process so far (range reads and whole gets).
pub fn bytes_fetched() -> u64 {
    FETCHED.load(Ordering::Relaxed)
}

#[cfg_attr(not(feature = "s3"), allow(dead_code))]
fn count_fetched(n: u64) {
    FETCHED.fetch_add(n, Ordering::Relaxed);
}

/// The error of a build without the `s3` feature given a URL.
pub fn unsupported(url: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::Unsupported,
        format!(
            "{url}: this build reads no object storage; build with `make build-s3` \
             (cargo build --release --features s3)"
        ),
    )
}

/// A remote object opened for range reads (stand-in without the `s3` feature: never built).
#[cfg(not(feature = "s3"))]
#[derive(Debug)]
pub struct RemoteObject {
    pub size: u64,
}

#[cfg(not(feature = "s3"))]
impl RemoteObject {
    pub fn open(url: &str) -> io::Result<RemoteObject> {
        Err(unsupported(url))
    }
    pub fn read_at(&self, _offset: u64, _len: u64) -> io::Result<Vec<u8>> {
        unreachable!("a RemoteObject cannot be built without the s3 feature")
    }
    pub fn content_hash(&self) -> io::Result<u128> {
        unreachable!("a RemoteObject cannot be built without the s3 feature")
    }
}

#[cfg(not(feature = "s3"))]
pub fn get(url: &str) -> io::Result<Option<Vec<u8>>> {
    Err(unsupported(url))
}

#[cfg(not(feature = "s3"))]
pub fn put(url: &str, _bytes: Vec<u8>) -> io::Result<()> {
    Err(unsupported(url))
}

#[cfg(not(feature = "s3"))]
pub fn list(prefix: &str) -> io::Result<Vec<String>> {
    Err(unsupported(prefix))
}

#[cfg(not(feature = "s3"))]
pub fn list_matching(pattern: &str) -> io::Result<Vec<String>> {
    Err(unsupported(pattern))
}

/// `(bucket URL, key)` of an `s3://bucket/key` URL.
pub fn split_url(url: &str) -> io::Result<(String, String)> {
    let scheme = SCHEMES
        .iter()
        .find(|s| url.starts_with(**s))
        .ok_or_else(|| bad_url(url, "it does not start with s3://"))?;
    let rest = &url[scheme.len()..];
    let (bucket, key) = rest.split_once('/').unwrap_or((rest, ""));
    if bucket.is_empty() {
        return Err(bad_url(url, "it names no bucket"));
    }
    Ok((
        format!("{scheme}{bucket}"),
        key.trim_start_matches('/').to_string(),
    ))
}

fn bad_url(url: &str, why: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{url}: not an object URL: {why}"),
    )
}

/// The part of a glob before its first wildcard, cut back to a `/`: what to list.
pub fn glob_prefix(pattern: &str) -> &str {
    let wild = pattern.find(['*', '?', '[']).unwrap_or(pattern.len());
    match pattern[..wild].rfind('/') {
        Some(i) => &pattern[..=i],
        None => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_split_and_globs_list_their_fixed_prefix() {
        assert!(is_url(Path::new("s3://b/x.mcap")));
        assert!(!is_url(Path::new("datasets/s3:/x.mcap")));
        assert_eq!(
            split_url("s3://logs/park/a.mcap").expect("url"),
            ("s3://logs".to_string(), "park/a.mcap".to_string())
        );
        assert_eq!(
            split_url("s3://logs").expect("url"),
            ("s3://logs".to_string(), String::new())
        );
        assert!(split_url("s3:///a.mcap").is_err());
        assert_eq!(glob_prefix("s3://b/park/*.mcap"), "s3://b/park/");
        assert_eq!(glob_prefix("s3://b/p*/x/*.mcap"), "s3://b/");
        assert_eq!(glob_prefix("s3://b/park/a.mcap"), "s3://b/park/");
    }

    #[cfg(not(feature = "s3"))]
    #[test]
    fn a_build_without_object_storage_says_how_to_get_one() {
        let e = crate::log::SessionLog::open("s3://bucket/a.mcap")
            .expect_err("no object storage in this build")
            .to_string();
        assert!(
            e.contains("s3://bucket/a.mcap") && e.contains("make build-s3"),
            "{e}"
        );
        let e = crate::run::config::find_sessions(&["s3://bucket/*.mcap".into()], &[])
            .expect_err("cannot list")
            .to_string();
        assert!(e.contains("make build-s3"), "{e}");
    }
}
