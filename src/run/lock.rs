//! The advisory lock on an output folder whose products (tables, figures, REPORT.md) one run
//! writes: `out/<pipeline>/.lock` for a run that aggregates (a full run or
//! `--aggregate-only`), `out/.lock` for `peopletrack eval`. A second run into a folder in use
//! fails at once, naming the folder and the other run's process id and host; runs that write disjoint
//! things (the shards of one pipeline, which only store sessions, and runs of different
//! pipelines) take no common lock and go on side by side.
//!
//! The lock is `std::fs::File::try_lock` (`flock` on Unix; on NFS, Linux maps it to a POSIX
//! lock the server knows, so it holds across machines), released by the kernel when the
//! process ends, however it ends: a killed run leaves no stale lock. The holder writes its
//! process id and host name ([`holder_id`]: `4242 on node07`; a process id alone is ambiguous
//! when shards of a cluster share the folder) into the lock file while it holds a short-lived
//! second lock (`.lock.guard`),
//! under which a run that finds the folder in use reads it, so the id it reports is always
//! complete. Where the file system has no locks the run goes on unexcluded and says so.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Read, Seek, Write};
use std::path::{Path, PathBuf};

use crate::report::atomic::{at, io_error};

/// The lock file in a locked folder (it holds the holder's process id).
pub const LOCK_FILE: &str = ".lock";
/// The short-lived lock taken while the holder's id is written or read.
const GUARD_FILE: &str = ".lock.guard";

/// This machine's host name: the kernel's (`/proc/sys/kernel/hostname`), else `$HOSTNAME`,
/// else `an unknown host`. Read by hand: one file, no crate needed.
pub fn host_name() -> String {
    fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "an unknown host".to_string())
}

/// What a holder writes into its lock file: `<process id> on <host>`.
pub fn holder_id() -> String {
    format!("{} on {}", std::process::id(), host_name())
}

/// Why a folder could not be locked.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds it.
    #[error(
        "{} is in use by another run (process {holder}, holding {}): wait for it to finish, or give this run another --out",
        folder.display(), lock.display()
    )]
    InUse {
        folder: PathBuf,
        lock: PathBuf,
        /// The holder's process id and host as its lock file says them ([`holder_id`]).
        holder: String,
    },
    /// The lock file could not be made or locked (the message names the path).
    #[error("locking {}: {error}", folder.display())]
    Io { folder: PathBuf, error: io::Error },
}

/// A folder held for writing its products; the lock is released when this is dropped (or
/// the process ends).
#[derive(Debug)]
pub struct FolderLock {
    /// `None` where the file system has no locks.
    _file: Option<File>,
    /// Said when the folder could not be locked because the file system has no locks.
    pub unsupported: Option<String>,
}

fn open_rw(path: &Path) -> io::Result<File> {
    OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .map_err(at("opening lock file", path))
}

/// How long a lock that names this very process as its holder is waited for: an `flock`
/// this process released stays held while a child process, forked by another thread in that
/// instant, has not yet reached `exec` (which closes its copy of the descriptor).
const OWN_LOCK_WAIT: std::time::Duration = std::time::Duration::from_secs(2);

impl FolderLock {
    /// Lock `folder` (made if absent) for this process, or say who holds it. A lock held in
    /// this process's own name is tried again for up to [`OWN_LOCK_WAIT`] first.
    pub fn acquire(folder: &Path) -> Result<FolderLock, LockError> {
        let started = std::time::Instant::now();
        loop {
            match FolderLock::try_acquire(folder) {
                Err(LockError::InUse { holder, .. })
                    if holder == holder_id() && started.elapsed() < OWN_LOCK_WAIT =>
                {
                    std::thread::sleep(std::time::Duration::from_millis(10));
                }
                result => return result,
            }
        }
    }

    fn try_acquire(folder: &Path) -> Result<FolderLock, LockError> {
        let io = |error: io::Error| LockError::Io {
            folder: folder.to_path_buf(),
            error,
        };
        fs::create_dir_all(folder)
            .map_err(at("creating folder", folder))
            .map_err(io)?;
        let lock_path = folder.join(LOCK_FILE);
        let guard_path = folder.join(GUARD_FILE);
        let guard = open_rw(&guard_path).map_err(io)?;
        // the guard is held for microseconds: while a holder writes its id or a loser reads it
        match guard.lock() {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::Unsupported => {
                return Ok(FolderLock {
                    _file: None,
                    unsupported: Some(format!(
                        "{}: the file system does not support locks ({e}), so runs into this folder are not kept apart",
                        folder.display()
                    )),
                });
            }
            Err(e) => return Err(io(io_error("locking", &guard_path, &e))),
        }
        let mut file = open_rw(&lock_path).map_err(io)?;
        match file.try_lock() {
            Ok(()) => {
                let holder = holder_id();
                file.set_len(0)
                    .and_then(|()| file.rewind())
                    .and_then(|()| file.write_all(format!("{holder}\n").as_bytes()))
                    .map_err(at("writing lock file", &lock_path))
                    .map_err(io)?;
                drop(guard);
                Ok(FolderLock {
                    _file: Some(file),
                    unsupported: None,
                })
            }
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                file.read_to_string(&mut holder)
                    .map_err(at("reading lock file", &lock_path))
                    .map_err(io)?;
                drop(guard);
                Err(LockError::InUse {
                    folder: folder.to_path_buf(),
                    lock: lock_path,
                    holder: holder.trim().to_string(),
                })
            }
            Err(TryLockError::Error(e)) => Err(io(io_error("locking", &lock_path, &e))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_folder_is_refused_with_the_holder_named_then_free_again() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = dir.path().join("out/pipeline");
        let held = FolderLock::acquire(&folder).expect("first");
        assert!(held.unsupported.is_none());
        let e = FolderLock::acquire(&folder).expect_err("in use");
        assert_eq!(
            e.to_string(),
            format!(
                "{} is in use by another run (process {}, holding {}): wait for it to finish, or give this run another --out",
                folder.display(),
                holder_id(),
                folder.join(LOCK_FILE).display()
            )
        );
        drop(held);
        let again = FolderLock::acquire(&folder).expect("released with its holder");
        drop(again);
    }

    #[test]
    fn a_folder_that_cannot_be_made_is_named() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("plain");
        std::fs::write(&file, b"x").expect("write");
        let e = FolderLock::acquire(&file.join("p")).expect_err("no folder");
        let text = e.to_string();
        assert_eq!(
            text,
            format!(
                "locking {0}/p: creating folder {0}/p: Not a directory (os error 20)",
                file.display()
            )
        );
    }
}
