//! Bounded reads from a log file: a read never reaches past the file's end, so a corrupt
//! offset or length gives a [`LogErrorKind::Truncated`] error, never a huge allocation.

use super::source::Source;
use std::io::{Read, Seek, SeekFrom};

use super::super::error::LogErrorKind;

/// Read `len` bytes at `offset`, or say that the file ends first (`what` names the record).
pub(super) fn read_at(
    file: &mut Source,
    offset: u64,
    len: u64,
    file_len: u64,
    what: &'static str,
) -> Result<Vec<u8>, LogErrorKind> {
    if offset.checked_add(len).is_none_or(|end| end > file_len) {
        return Err(LogErrorKind::Truncated {
            what,
            offset,
            needed: len,
            file_len,
            last: None,
        });
    }
    file.seek(SeekFrom::Start(offset))?;
    let mut buf = vec![0u8; len as usize];
    file.read_exact(&mut buf)?;
    Ok(buf)
}
