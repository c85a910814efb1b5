//! Atomic file output: every file under `out/` is written to a scratch file and renamed into
//! place, so a run killed midway leaves either the old complete file or the new complete file
//! — never a partial one.
//!
//! Each process has its own scratch folder per output root, `<root>/.tmp/run-<pid>-<n>/`,
//! held by an advisory lock on its `lock` file (`std::fs::File::try_lock`, `flock` on Unix)
//! for as long as the process lives. Runs that share an output root — two runs started
//! together, or the shards of one pipeline on a cluster writing into one shared folder —
//! never touch each other's scratch files: [`sweep_scratch`] removes only the folders whose
//! lock is free (their process is gone; the kernel releases a dead process's locks), and a
//! folder takes its `run-` name only once its lock is held (it is set up as `.new-<pid>-<n>`
//! and renamed), so no sweep can take a folder that is being set up. Where the file system
//! has no locks (`flock` unsupported), other processes' folders are left alone.
//!
//! Errors name the path and what was being done (`creating folder out/.tmp: …`), with the
//! operating system's error once.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

/// Name of the scratch folder inside an output root.
pub const SCRATCH_DIR: &str = ".tmp";
/// Prefix of a run's scratch folder in [`SCRATCH_DIR`] (`run-<pid>-<n>`).
const RUN_PREFIX: &str = "run-";
/// Prefix of a run's scratch folder while it is set up, before its lock is held.
const NEW_PREFIX: &str = ".new-";
/// The lock file inside a run's scratch folder.
const LOCK_FILE: &str = "lock";

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

/// An I/O error that names what was being done and the path: `creating folder PATH: …`.
/// The operating system's text (with its `(os error N)`) appears once: the result carries
/// the text, not the original error as a source.
pub fn io_error(action: &str, path: &Path, e: &io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{action} {}: {e}", path.display()))
}

/// `map_err` adapter for [`io_error`].
pub fn at<'a>(action: &'a str, path: &'a Path) -> impl Fn(io::Error) -> io::Error + 'a {
    move |e| io_error(action, path, &e)
}

/// This process's scratch folder in one output root, with its lock held.
struct RunScratch {
    root: PathBuf,
    dir: PathBuf,
    /// Held (locked) for the life of the process; `None` where the file system has no locks.
    _lock: Option<fs::File>,
}

static HELD: Mutex<Vec<RunScratch>> = Mutex::new(Vec::new());

/// This process's scratch folder under `<root>/.tmp/`, made (and its lock taken) on first
/// use. Scratch files of atomic writes and staged cache folders go here.
pub fn scratch_dir(root: &Path) -> io::Result<PathBuf> {
    let mut held = HELD.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(i) = held.iter().position(|s| s.root == root) {
        if held[i].dir.is_dir() {
            return Ok(held[i].dir.clone());
        }
        // removed from under us (by hand): set up a new one
        held.swap_remove(i);
    }
    let s = new_run_scratch(root)?;
    let dir = s.dir.clone();
    held.push(s);
    Ok(dir)
}

/// Set up a run's scratch folder: `.new-<pid>-<n>` with its lock taken, then renamed to
/// `run-<pid>-<n>` (a name another process's leftover holds is skipped).
fn new_run_scratch(root: &Path) -> io::Result<RunScratch> {
    let base = root.join(SCRATCH_DIR);
    fs::create_dir_all(&base).map_err(at("creating folder", &base))?;
    let pid = std::process::id();
    for _ in 0..1000 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let staging = base.join(format!("{NEW_PREFIX}{pid}-{n}"));
        match fs::create_dir(&staging) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            // another process's release removed the (then empty) `.tmp` just now
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                fs::create_dir_all(&base).map_err(at("creating folder", &base))?;
                continue;
            }
            Err(e) => return Err(io_error("creating folder", &staging, &e)),
        }
        let lock_path = staging.join(LOCK_FILE);
        let lock = fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&lock_path)
            .map_err(at("creating lock file", &lock_path))?;
        let lock = match lock.try_lock() {
            Ok(()) => Some(lock),
            Err(fs::TryLockError::Error(e)) if e.kind() == io::ErrorKind::Unsupported => None,
            Err(fs::TryLockError::Error(e)) => return Err(io_error("locking", &lock_path, &e)),
            // a file this process just made: nobody else can hold it
            Err(fs::TryLockError::WouldBlock) => {
                return Err(io_error(
                    "locking",
                    &lock_path,
                    &io::Error::from(io::ErrorKind::WouldBlock),
                ));
            }
        };
        let dir = base.join(format!("{RUN_PREFIX}{pid}-{n}"));
        match fs::rename(&staging, &dir) {
            Ok(()) => {
                return Ok(RunScratch {
                    root: root.to_path_buf(),
                    dir,
                    _lock: lock,
                });
            }
            // a dead process with this pid left a folder of this name: take the next one
            Err(_) if dir.is_dir() => {
                let _ = fs::remove_dir_all(&staging);
            }
            Err(e) => return Err(io_error("renaming", &staging, &e)),
        }
    }
    Err(io::Error::other(format!(
        "no free scratch folder name in {}",
        base.display()
    )))
}

/// Write `bytes` to `path` atomically (scratch file in the same file system, then rename).
/// `root` is the output root whose `.tmp/` folder holds this process's scratch folder (the
/// file's own folder when `None`). Errors name the path and the step.
pub fn write_atomic(path: &Path, bytes: &[u8], root: Option<&Path>) -> io::Result<()> {
    let parent = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = parent {
        fs::create_dir_all(dir).map_err(at("creating folder", dir))?;
    }
    let base = root.or(parent).unwrap_or(Path::new("."));
    let scratch = scratch_dir(base)?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let tmp = scratch.join(format!("{n}.{name}"));
    let result = (|| {
        let mut f = fs::File::create(&tmp).map_err(at("creating scratch file", &tmp))?;
        f.write_all(bytes)
            .map_err(at("writing scratch file", &tmp))?;
        f.sync_all().map_err(at("writing scratch file", &tmp))?;
        maybe_abort();
        fs::rename(&tmp, path).map_err(|e| {
            io_error(
                &format!("moving scratch file {} into place at", tmp.display()),
                path,
                &e,
            )
        })
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Whether the scratch folder `dir` (a `run-` folder) belongs to a process that is gone: its
/// lock is free (then it is held, in the returned file, while the folder is removed). `None`
/// while its process runs, or where the file system cannot say (no locks).
fn abandoned(dir: &Path) -> Option<Option<fs::File>> {
    let lock_path = dir.join(LOCK_FILE);
    let f = match fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&lock_path)
    {
        Ok(f) => f,
        // a folder without its lock is being removed by another sweep, or is broken
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Some(None),
        Err(_) => return None,
    };
    match f.try_lock() {
        Ok(()) => Some(Some(f)),
        Err(_) => None,
    }
}

/// Remove a file or folder; already gone is fine (another sweep took it).
fn remove_entry(path: &Path) -> io::Result<()> {
    let result = if path.is_dir() {
        fs::remove_dir_all(path)
    } else {
        fs::remove_file(path)
    };
    match result {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(io_error("removing", path, &e)),
        _ => Ok(()),
    }
}

/// Remove the scratch folders of runs that are gone (killed midway) from `<root>/.tmp/`, and
/// the loose scratch files of earlier versions; the folders of runs still going (their lock
/// is held) and this process's own are left alone.
pub fn sweep_scratch(root: &Path) -> io::Result<()> {
    let base = root.join(SCRATCH_DIR);
    let entries = match fs::read_dir(&base) {
        Ok(d) => d,
        // nothing to sweep (a root that is not a folder is said by whatever writes there)
        Err(e)
            if matches!(
                e.kind(),
                io::ErrorKind::NotFound | io::ErrorKind::NotADirectory
            ) =>
        {
            return Ok(());
        }
        Err(e) => return Err(io_error("reading folder", &base, &e)),
    };
    let own: Vec<PathBuf> = HELD
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .iter()
        .map(|s| s.dir.clone())
        .collect();
    for entry in entries {
        let entry = entry.map_err(at("reading folder", &base))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with(NEW_PREFIX) || own.contains(&path) {
            // being set up by a live process (or left by one killed in those microseconds)
            continue;
        }
        if name.starts_with(RUN_PREFIX) {
            if let Some(_lock) = abandoned(&path) {
                remove_entry(&path)?;
            }
        } else {
            // a loose scratch file or folder of a version before per-run folders
            remove_entry(&path)?;
        }
    }
    Ok(())
}

/// Give up this process's scratch folders (at the end of a command): each is removed (it
/// holds only its lock once every write is done) and its lock released, and `<root>/.tmp`
/// too when nothing else is left in it. Best effort: a folder left behind is swept by the
/// next run.
pub fn release_scratch() {
    release_where(|_| true);
}

fn release_where(mut which: impl FnMut(&Path) -> bool) {
    let released: Vec<RunScratch> = {
        let mut held = HELD.lock().unwrap_or_else(PoisonError::into_inner);
        let (go, keep) = std::mem::take(&mut *held)
            .into_iter()
            .partition(|s| which(&s.root));
        *held = keep;
        go
    };
    for s in released {
        let _ = fs::remove_dir_all(&s.dir);
        let base = s.root.join(SCRATCH_DIR);
        drop(s);
        // only an empty folder goes: another run's scratch keeps it
        let _ = fs::remove_dir(&base);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .expect("folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_replace_whole_files_and_leave_no_scratch_behind() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("a/b/table.csv");
        write_atomic(&p, b"one", Some(dir.path())).expect("write");
        write_atomic(&p, b"two", Some(dir.path())).expect("rewrite");
        assert_eq!(fs::read(&p).expect("read"), b"two");
        // one scratch folder for this process, holding only its lock
        let scratch = dir.path().join(SCRATCH_DIR);
        let runs = names(&scratch);
        assert_eq!(runs.len(), 1, "{runs:?}");
        assert!(runs[0].starts_with(&format!("run-{}-", std::process::id())));
        assert_eq!(names(&scratch.join(&runs[0])), [LOCK_FILE]);
        // this process's own folder survives a sweep; released, nothing is left
        sweep_scratch(dir.path()).expect("sweep");
        assert_eq!(names(&scratch), runs);
        release_where(|r| r == dir.path());
        assert!(!scratch.exists());
    }

    /// Another run's folder whose lock is held stays; one whose lock is free (its process is
    /// gone), one without a lock and an earlier version's loose scratch file go.
    #[test]
    fn a_sweep_removes_only_what_no_live_run_holds() {
        let dir = tempfile::tempdir().expect("tempdir");
        let scratch = dir.path().join(SCRATCH_DIR);
        let folder = |name: &str, lock: bool| {
            let d = scratch.join(name);
            fs::create_dir_all(&d).expect("mkdir");
            fs::write(d.join("7.table.csv"), b"partial").expect("write");
            if lock {
                fs::write(d.join(LOCK_FILE), b"").expect("write");
            }
        };
        folder("run-1-0", true);
        folder("run-2-0", true);
        folder("run-3-0", false);
        folder(".new-4-0", true);
        fs::write(scratch.join("123.4.table.csv"), b"old layout").expect("write");
        let live = fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(scratch.join("run-1-0").join(LOCK_FILE))
            .expect("open");
        live.try_lock().expect("lock");
        sweep_scratch(dir.path()).expect("sweep");
        assert_eq!(names(&scratch), [".new-4-0", "run-1-0"]);
        drop(live);
        sweep_scratch(dir.path()).expect("sweep");
        assert_eq!(names(&scratch), [".new-4-0"]);
    }

    /// Errors say what was done to which path, with the system's error once.
    #[test]
    fn errors_name_the_path_and_the_step() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("plain");
        fs::write(&file, b"x").expect("write");
        let target = file.join("tables/t.csv");
        let e = write_atomic(&target, b"y", Some(dir.path())).expect_err("a file is no folder");
        let text = e.to_string();
        assert_eq!(
            text,
            format!(
                "creating folder {}: Not a directory (os error 20)",
                file.join("tables").display()
            )
        );
        // nothing to sweep below a file: whatever writes there says it
        sweep_scratch(&file).expect("nothing to sweep");
        // disk full, as the kernel says it: one "(os error 28)"
        let full = io_error(
            "writing scratch file",
            Path::new("out/.tmp/run-1-0/3.t.csv"),
            &io::Error::from_raw_os_error(28),
        );
        assert_eq!(
            full.to_string(),
            "writing scratch file out/.tmp/run-1-0/3.t.csv: No space left on device (os error 28)"
        );
    }
}
