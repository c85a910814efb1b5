//! Atomic file output: every file under `out/` is written to a scratch file in
//! `<out>/.tmp/` and renamed into place, so a run killed midway leaves either the old complete
//! file or the new complete file — never a partial one. The scratch folder is swept at the
//! start of each run.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Name of the scratch folder inside an output root.
pub const SCRATCH_DIR: &str = ".tmp";

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Crash-test hook: abort the process just before the N-th rename (0 = never). Set only by the
/// CLI's hidden `--debug-abort-after-writes` flag, to prove that a killed run leaves no
/// partial file.
static ABORT_AT: AtomicU64 = AtomicU64::new(0);
static RENAMES: AtomicU64 = AtomicU64::new(0);

pub fn abort_before_rename(n: u64) {
    ABORT_AT.store(n, Ordering::SeqCst);
}

/// The crash-test hook, for other atomic swaps (session result folders).
pub fn maybe_abort_hook() {
    maybe_abort();
}

fn maybe_abort() {
    let at = ABORT_AT.load(Ordering::SeqCst);
    if at > 0 && RENAMES.fetch_add(1, Ordering::SeqCst) + 1 >= at {
        std::process::abort();
    }
}

/// The scratch folder for `path`: `<root>/.tmp` where root is the nearest ancestor named by
/// the caller, or the file's own directory.
fn scratch_for(path: &Path, root: Option<&Path>) -> PathBuf {
    let base = root
        .map(Path::to_path_buf)
        .or_else(|| path.parent().map(Path::to_path_buf))
        .unwrap_or_else(|| PathBuf::from("."));
    base.join(SCRATCH_DIR)
}

/// Write `bytes` to `path` atomically (scratch file in the same file system, then rename).
/// `root` is the output root whose `.tmp/` folder holds scratch files (the file's own folder
/// when `None`).
pub fn write_atomic(path: &Path, bytes: &[u8], root: Option<&Path>) -> io::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir)?;
    }
    let scratch = scratch_for(path, root);
    fs::create_dir_all(&scratch)?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let tmp = scratch.join(format!("{}.{}.{name}", std::process::id(), n));
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        maybe_abort();
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Remove scratch files left by an interrupted run.
pub fn sweep_scratch(root: &Path) -> io::Result<()> {
    let scratch = root.join(SCRATCH_DIR);
    if scratch.exists() {
        fs::remove_dir_all(&scratch)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_replace_whole_files_and_leave_no_scratch_behind() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("a/b/table.csv");
        write_atomic(&p, b"one", Some(dir.path())).expect("write");
        write_atomic(&p, b"two", Some(dir.path())).expect("rewrite");
        assert_eq!(fs::read(&p).expect("read"), b"two");
        let scratch = dir.path().join(SCRATCH_DIR);
        assert_eq!(fs::read_dir(&scratch).expect("scratch exists").count(), 0);
        sweep_scratch(dir.path()).expect("sweep");
        assert!(!scratch.exists());
    }
}
