//! Streaming MCAP reading in log-time order with bounded memory, in the `mcap` crate's
//! sans-I/O manner: the parts that decide are functions of bytes, and [`SessionLog`] is the
//! thin shell that opens the file and feeds them.
//!
//! - `records`: pure record parsing over `&[u8]` — opcodes, explicit bounds checks (not
//!   `binrw`), so a corrupt length gives an error but never a huge allocation or a panic.
//! - `chunk`: chunk decompression as a stream that keeps only the wanted records, and CRCs
//!   (rosbags writes 0 = not computed).
//! - `index`: what opening learns — the summary section, or one linear pass without one.
//! - `merge`: the time-ordered k-way merge of chunks behind [`MessageStream`]; chunks are
//!   decompressed lazily and freed when consumed, equal log times keep file order.
//! - `io`: bounded reads at an offset.
//! - `source`: a local file or (feature `s3`) an object in a store, read with range requests:
//!   opening fetches the footer and summary section, a stream only the chunks it needs.

mod chunk;
mod index;
mod io;
mod merge;
mod records;
mod source;

use std::collections::BTreeSet;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::error::{LogError, LogErrorKind};

pub use index::LogSummary;
pub use merge::{Message, MessageStream, Payload};
use source::Source;

pub use records::{ChannelInfo, ChunkInfo, MetadataRecord, SchemaInfo, Statistics};

/// How many of a log's chunks carry a CRC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CrcCoverage {
    pub chunks: usize,
    pub with_crc: usize,
    /// Messages outside chunks carry no CRC at all.
    pub unchunked_messages: bool,
}

impl CrcCoverage {
    /// One line for `inspect`: whether corruption can be detected.
    pub fn describe(&self) -> String {
        let mut s = if self.chunks == 0 {
            "no chunks".to_string()
        } else if self.with_crc == self.chunks {
            format!("all {} chunks carry a CRC", self.chunks)
        } else if self.with_crc == 0 {
            format!(
                "none of the {} chunks carries a CRC (0 = not computed): corruption cannot be detected",
                self.chunks
            )
        } else {
            format!(
                "{} of {} chunks carry no CRC: corruption in them cannot be detected",
                self.chunks - self.with_crc,
                self.chunks
            )
        };
        if self.unchunked_messages {
            s.push_str("; messages outside chunks carry no CRC: corruption cannot be detected");
        }
        s
    }

    /// True when some data cannot be checked for corruption.
    pub fn incomplete(&self) -> bool {
        self.with_crc < self.chunks || self.unchunked_messages
    }
}

/// An open session log (a file, or an `s3://` URL with the `s3` feature). Cheap to share;
/// each [`SessionLog::messages`] call opens its own handle.
#[derive(Debug, Clone)]
pub struct SessionLog {
    path: PathBuf,
    summary: LogSummary,
}

/// The file at `path`, its length, and the read position after its MCAP magic (else
/// [`LogErrorKind::NotMcap`]).
fn open_mcap(path: &Path) -> Result<(PathBuf, Source, u64), LogError> {
    let path = path.to_path_buf();
    let err = |k: LogErrorKind| LogError::new(&path, k);
    let (mut file, file_len) = Source::open(&path).map_err(|e| err(e.into()))?;
    let mut magic = [0u8; 8];
    if file_len < 8 || file.read_exact(&mut magic).is_err() || &magic != records::MAGIC {
        return Err(err(LogErrorKind::NotMcap));
    }
    Ok((path, file, file_len))
}

impl SessionLog {
    /// Open a log and read its index (summary section, or one linear pass without one).
    pub fn open(path: impl AsRef<Path>) -> Result<SessionLog, LogError> {
        let (path, mut file, file_len) = open_mcap(path.as_ref())?;
        let err = |k: LogErrorKind| LogError::new(&path, k);
        let summary = match index::read_summary_section(&mut file, file_len).map_err(err)? {
            Some(s) if index::summary_is_complete(&s) => s,
            Some(claimed) => {
                // no chunk index: the statistics alone are not believed over the data
                let mut found = index::linear_index(&mut file, file_len).map_err(err)?;
                let count = |s: &LogSummary| s.statistics.as_ref().map_or(0, |st| st.message_count);
                if count(&claimed) != count(&found) {
                    found.warnings.push(format!(
                        "the summary section says {} messages and has no chunk index; a linear \
                         scan of the data found {}, and the index was rebuilt from the data",
                        count(&claimed),
                        count(&found)
                    ));
                }
                found
            }
            None => index::linear_index(&mut file, file_len).map_err(err)?,
        };
        Ok(SessionLog { path, summary })
    }

    /// Open a log indexing it from the data alone: one linear pass that decompresses every
    /// chunk and learns each chunk's real time range, ignoring the summary section. For a log
    /// whose chunk index lies about time ranges ([`LogErrorKind::ChunkStartsEarlier`]), where
    /// trusting the index cannot keep log-time order; what the pass found is said in
    /// [`LogSummary::warnings`].
    pub fn open_scanning(path: impl AsRef<Path>) -> Result<SessionLog, LogError> {
        let (path, mut file, file_len) = open_mcap(path.as_ref())?;
        let err = |k: LogErrorKind| LogError::new(&path, k);
        let mut summary = index::linear_index(&mut file, file_len).map_err(err)?;
        summary.warnings.insert(
            0,
            "indexed by a linear scan of the data (the chunk index's time ranges were not used)"
                .to_string(),
        );
        Ok(SessionLog { path, summary })
    }

    /// Open a damaged log (`--recover`): index it front to back, leaving out chunks that do
    /// not open and stopping where the file is cut or its records lose their framing. What
    /// was lost is said in [`LogSummary::warnings`]; the messages read are the complete ones
    /// before the damage (and in any good chunk after a bad one).
    pub fn open_recovering(path: impl AsRef<Path>) -> Result<SessionLog, LogError> {
        let (path, mut file, file_len) = open_mcap(path.as_ref())?;
        let err = |k: LogErrorKind| LogError::new(&path, k);
        let summary = index::recovering_index(&mut file, file_len).map_err(err)?;
        Ok(SessionLog { path, summary })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn summary(&self) -> &LogSummary {
        &self.summary
    }

    /// Whether the log can detect corruption: of its chunks, how many carry a CRC (rosbags
    /// writes 0 = "not computed"). Reads each chunk's fixed header only.
    pub fn crc_coverage(&self) -> Result<CrcCoverage, LogError> {
        let err = |k: LogErrorKind| LogError::new(&self.path, k);
        let (mut file, _) = Source::open(&self.path).map_err(|e| err(e.into()))?;
        let mut out = CrcCoverage {
            chunks: self.summary.chunks.len(),
            with_crc: 0,
            unchunked_messages: self.summary.unchunked_messages,
        };
        for c in &self.summary.chunks {
            // opcode + length, then start, end, uncompressed size (u64 each) and the CRC
            let head = io::read_at(&mut file, c.offset, 9 + 28, self.summary.file_len, "chunk")
                .map_err(err)?;
            if head[9 + 24..9 + 28] != [0, 0, 0, 0] {
                out.with_crc += 1;
            }
        }
        Ok(out)
    }

    /// Every message, in log-time order.
    pub fn messages(&self) -> Result<MessageStream, LogError> {
        self.stream(None)
    }

    /// Messages of the named topics, in log-time order. A topic absent from the log is an
    /// error (a typo must not give an empty result).
    pub fn messages_on(&self, topics: &[&str]) -> Result<MessageStream, LogError> {
        for t in topics {
            if self.summary.channel(t).is_none() {
                let kind = if self.summary.lost.is_empty() {
                    LogErrorKind::MissingTopic((*t).to_string())
                } else {
                    missing_in_recovered(&self.summary, t)
                };
                return Err(LogError::new(&self.path, kind).on_topic(t));
            }
        }
        self.stream(Some(topics.iter().map(|t| (*t).to_string()).collect()))
    }

    fn stream(&self, topics: Option<BTreeSet<String>>) -> Result<MessageStream, LogError> {
        let (mut file, _) = Source::open(&self.path).map_err(|e| LogError::new(&self.path, e))?;
        file.seek(SeekFrom::Start(8))
            .map_err(|e| LogError::new(&self.path, e))?;
        Ok(MessageStream::new(
            self.path.clone(),
            &self.summary,
            topics,
            file,
        ))
    }
}

/// A topic absent from what `--recover` could read: its channel record may be in what was
/// lost (a log cut inside its first chunk has no channels left at all).
fn missing_in_recovered(summary: &LogSummary, topic: &str) -> LogErrorKind {
    let topics = summary.topics();
    let lost: Vec<String> = summary
        .lost
        .iter()
        .map(|&(a, b)| {
            if a < b {
                format!("bytes {a}..{b}")
            } else {
                format!("everything after byte {a}, never written")
            }
        })
        .collect();
    LogErrorKind::MissingTopicInRecovered {
        topic: topic.to_string(),
        present: if topics.is_empty() {
            "none".to_string()
        } else {
            topics.join(", ")
        },
        lost: lost.join(", "),
    }
}
