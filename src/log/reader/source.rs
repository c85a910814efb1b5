//! What a log is read from: a local file, or (feature `s3`) an object read with one range
//! request per read ([`crate::storage::RemoteObject`]). Both are `Read + Seek`, so the
//! record parsing above is the same for both.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::Arc;

use crate::storage::{self, RemoteObject};

pub(crate) enum Source {
    File(File),
    Remote { object: Arc<RemoteObject>, pos: u64 },
}

impl Source {
    /// Open `path` (a file, or an `s3://` URL) and say its length.
    pub(crate) fn open(path: &Path) -> io::Result<(Source, u64)> {
        if storage::is_url(path) {
            let url = path.to_string_lossy();
            let object = Arc::new(RemoteObject::open(&url)?);
            let len = object.size;
            return Ok((Source::Remote { object, pos: 0 }, len));
        }
        let file = File::open(path)?;
        let len = file.metadata()?.len();
        Ok((Source::File(file), len))
    }
}

impl Read for Source {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Source::File(f) => f.read(buf),
            Source::Remote { object, pos } => {
                let n = (buf.len() as u64).min(object.size.saturating_sub(*pos));
                if n == 0 {
                    return Ok(0);
                }
                let bytes = object.read_at(*pos, n)?;
                buf[..bytes.len()].copy_from_slice(&bytes);
                *pos += bytes.len() as u64;
                Ok(bytes.len())
            }
        }
    }
}

impl Seek for Source {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        match self {
            Source::File(f) => f.seek(to),
            Source::Remote { object, pos } => {
                let target = match to {
                    SeekFrom::Start(n) => Some(n),
                    SeekFrom::End(d) => object.size.checked_add_signed(d),
                    SeekFrom::Current(d) => pos.checked_add_signed(d),
                };
                *pos = target.ok_or_else(|| {
                    io::Error::new(
                        io::ErrorKind::InvalidInput,
                        "seek before the object's start",
                    )
                })?;
                Ok(*pos)
            }
        }
    }
}
