//! `--out s3://bucket/prefix`: the run works on a local copy of the pipeline's folder and
//! writes back what changed. Pulling fetches every object below `<out>/<pipeline>/` (the
//! per-session cache, shard records, the last tables); the run then reads and writes local
//! files exactly as it does without a store; pushing puts each file that is new or whose
//! bytes changed, one put per file (an object appears whole or not at all), every session's
//! `key.txt` after the rest of its folder, so that a reader that finds a key finds its tables.
//! Lock files stay local: on a cluster the scheduler orders the aggregate after the shards.
//!
//! Two shards pushing into one prefix write disjoint session folders; two runs that compute
//! the same session write the same bytes (the cache is content-addressed), so whichever put
//! lands last leaves a complete entry.

use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};

use xxhash_rust::xxh3::xxh3_128;

/// What a push wrote.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Pushed {
    pub files: usize,
    pub bytes: u64,
    /// Files unchanged since the pull, not written again.
    pub unchanged: usize,
}

/// A local working copy of `<remote>/<folder>/`.
#[derive(Debug)]
pub struct Mirror {
    remote: String,
    local: PathBuf,
    /// Relative path → hash of the bytes pulled.
    pulled: BTreeMap<String, u128>,
}

impl Mirror {
    /// Fetch every object below `<remote>/<folder>/` into a fresh local folder.
    pub fn pull(remote: &str, folder: &str) -> io::Result<Mirror> {
        let remote = remote.trim_end_matches('/').to_string();
        let local = scratch_folder()?;
        let mut mirror = Mirror {
            remote,
            local,
            pulled: BTreeMap::new(),
        };
        let prefix = format!("{}/{folder}/", mirror.remote);
        for url in super::list(&prefix)? {
            let rel = url[mirror.remote.len() + 1..].to_string();
            if !safe_relative(&rel) {
                continue; // a key with `..` or an empty component would escape the folder
            }
            let Some(bytes) = super::get(&url)? else {
                continue; // deleted between the listing and the get
            };
            let path = mirror.local.join(&rel);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
            std::fs::write(&path, &bytes)?;
            mirror.pulled.insert(rel, xxh3_128(&bytes));
        }
        Ok(mirror)
    }

    /// The local folder standing for the remote prefix.
    pub fn local(&self) -> &Path {
        &self.local
    }

    /// The URL a local path below [`Mirror::local`] stands for.
    pub fn url_of(&self, local: &Path) -> String {
        match local.strip_prefix(&self.local) {
            Ok(rel) => format!("{}/{}", self.remote, rel.to_string_lossy()),
            Err(_) => local.display().to_string(),
        }
    }

    /// Put every file that is new or changed since the pull; `key.txt` files last. Files
    /// whose name starts with one of `local_only` (lock files) are not written.
    pub fn push(&self, local_only: &[&str]) -> io::Result<Pushed> {
        let mut out = Pushed::default();
        for rel in push_order(&self.local, local_only)? {
            let bytes = std::fs::read(self.local.join(&rel))?;
            if self.pulled.get(&rel) == Some(&xxh3_128(&bytes)) {
                out.unchanged += 1;
                continue;
            }
            out.files += 1;
            out.bytes += bytes.len() as u64;
            super::put(&format!("{}/{rel}", self.remote), bytes)?;
        }
        Ok(out)
    }
}

impl Drop for Mirror {
    fn drop(&mut self) {
        // best effort: a scratch folder left behind is harmless and named as ours
        let _ = std::fs::remove_dir_all(&self.local);
    }
}

fn scratch_folder() -> io::Result<PathBuf> {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let dir =
        std::env::temp_dir().join(format!("peopletrack-mirror-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// The files below `root` (relative, `/`-joined, names starting with one of `local_only` left
/// out) in the order a push writes them: a session's `key.txt` after everything else.
fn push_order(root: &Path, local_only: &[&str]) -> io::Result<Vec<String>> {
    let mut files = Vec::new();
    walk(root, root, local_only, &mut files)?;
    files.sort_by_key(|rel| (rel.ends_with("/key.txt"), rel.clone()));
    Ok(files)
}

fn safe_relative(rel: &str) -> bool {
    rel.split('/')
        .all(|c| !c.is_empty() && c != "." && c != "..")
}

/// Relative `/`-joined paths of the files below `dir`, leaving out names that start with one
/// of `local_only`.
fn walk(root: &Path, dir: &Path, local_only: &[&str], out: &mut Vec<String>) -> io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        if entry.file_type()?.is_dir() {
            walk(root, &path, local_only, out)?;
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        if local_only.iter().any(|p| name.starts_with(p)) {
            continue;
        }
        if let Ok(rel) = path.strip_prefix(root) {
            let parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            out.push(parts.join("/"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pushes_keys_last_and_skips_locks_and_escapes() {
        let dir = tempfile::tempdir().expect("tempdir");
        let root = dir.path();
        let session = root.join("p/sessions/dataset=d/session=s");
        std::fs::create_dir_all(&session).expect("mkdir");
        for f in ["key.txt", "a.parquet", "source.txt"] {
            std::fs::write(session.join(f), f).expect("write");
        }
        std::fs::write(root.join("p/.lock"), "held").expect("write");
        assert_eq!(
            push_order(root, &[".lock"]).expect("walk"),
            [
                "p/sessions/dataset=d/session=s/a.parquet",
                "p/sessions/dataset=d/session=s/source.txt",
                "p/sessions/dataset=d/session=s/key.txt",
            ]
        );
        assert!(safe_relative("p/sessions/x.parquet"));
        assert!(!safe_relative("p/../x") && !safe_relative("p//x") && !safe_relative("./x"));
    }
}
