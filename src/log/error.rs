//! The one error type of the `log` module. Every error names the file, and where known the
//! topic, the message's log time and the byte offset, so a user can find the bad spot.

use std::fmt;
use std::path::PathBuf;

use crate::time::Nanos;

use super::cdr::CdrError;
use super::ros2msg::SchemaError;
use super::value::FieldError;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum LogErrorKind {
    // no `#[from]`: a source would be printed twice in an error chain (`From` is below)
    #[error("{0}")]
    Io(std::io::Error),
    #[error("not an MCAP file (the first bytes are not the MCAP magic)")]
    NotMcap,
    #[error("file is truncated: {what} at byte {offset} needs {needed} bytes but the file ends at byte {file_len}{}",
        last.as_ref().map(|(t, at)| format!("; the last complete message is {t} at {at} s")).unwrap_or_default())]
    Truncated {
        what: &'static str,
        offset: u64,
        needed: u64,
        file_len: u64,
        last: Option<(String, Nanos)>,
    },
    #[error("corrupt {record} record at byte {offset}: {reason}")]
    BadRecord {
        record: &'static str,
        offset: u64,
        reason: String,
    },
    #[error(
        "chunk at byte {offset} (messages {start}..{end} s on {topics}) fails its CRC check: stored 0x{stored:08x}, computed 0x{computed:08x}"
    )]
    ChunkCrc {
        offset: u64,
        start: Nanos,
        end: Nanos,
        topics: String,
        stored: u32,
        computed: u32,
    },
    #[error(
        "chunk at byte {offset} (messages {start}..{end} s on {topics}) does not decompress ({compression}): {reason}"
    )]
    Decompress {
        offset: u64,
        start: Nanos,
        end: Nanos,
        topics: String,
        compression: String,
        reason: String,
    },
    #[error("chunk at byte {offset} uses compression `{compression}`; supported: zstd, lz4, none")]
    UnsupportedCompression { offset: u64, compression: String },
    #[error("message at byte {offset} refers to channel {channel}, which the file never defines")]
    UnknownChannel { offset: u64, channel: u16 },
    #[error(
        "the summary section fails its CRC check (stored 0x{stored:08x}, computed 0x{computed:08x})"
    )]
    SummaryCrc { stored: u32, computed: u32 },
    #[error(
        "messages are not in log-time order ({previous} s, then {this} s) and the file has no chunk index to sort them by; rewrite it with `mcap sort` or `mcap recover`"
    )]
    NotTimeOrdered { previous: Nanos, this: Nanos },
    #[error(
        "chunk at byte {offset} declares its messages start at {start} s but holds one at {this} s, before messages already read at {previous} s: the chunk index lies, so log-time order cannot be kept while trusting it; `peopletrack run` re-reads such a log with a linear scan of the data by itself, `cat --recover` does so too, or rewrite the file with `mcap sort`"
    )]
    ChunkStartsEarlier {
        offset: u64,
        start: Nanos,
        this: Nanos,
        previous: Nanos,
    },
    // `error`, not `source`: a source would be printed twice in an error chain
    #[error("schema `{schema}` does not parse: {error}")]
    Schema { schema: String, error: SchemaError },
    #[error(transparent)]
    Cdr(#[from] CdrError),
    #[error("{0}")]
    Protobuf(String),
    #[error("JSON message does not parse: {0}")]
    Json(String),
    #[error(transparent)]
    Field(#[from] FieldError),
    #[error(
        "no decoder for message encoding `{message_encoding}` with schema encoding `{schema_encoding}` (supported: cdr/ros2msg, protobuf/protobuf, json/jsonschema or none)"
    )]
    UnsupportedEncoding {
        message_encoding: String,
        schema_encoding: String,
    },
    #[error("channel carries `{found}`, not `{expected}`")]
    WrongType { expected: String, found: String },
    #[error("no topic `{0}` in the log")]
    MissingTopic(String),
    #[error(
        "no topic `{topic}` in the part of the log that could be read (its topics: {present}): its channel record was in what is lost ({lost}), or the log never had it"
    )]
    MissingTopicInRecovered {
        topic: String,
        present: String,
        lost: String,
    },
    #[error("{0}")]
    Write(String),
}

impl From<std::io::Error> for LogErrorKind {
    fn from(e: std::io::Error) -> Self {
        LogErrorKind::Io(e)
    }
}

/// A log error with its context.
#[derive(Debug)]
pub struct LogError {
    pub path: PathBuf,
    pub topic: Option<String>,
    pub log_time: Option<Nanos>,
    /// Boxed so `Result<_, LogError>` stays small on the hot path.
    pub kind: Box<LogErrorKind>,
}

impl LogError {
    pub fn new(path: impl Into<PathBuf>, kind: impl Into<LogErrorKind>) -> Self {
        LogError {
            path: path.into(),
            topic: None,
            log_time: None,
            kind: Box::new(kind.into()),
        }
    }

    pub fn on_topic(mut self, topic: &str) -> Self {
        self.topic = Some(topic.to_string());
        self
    }

    pub fn at(mut self, log_time: Nanos) -> Self {
        self.log_time = Some(log_time);
        self
    }
}

impl fmt::Display for LogError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(t) = &self.topic {
            write!(f, ": topic {t}")?;
        }
        if let Some(t) = self.log_time {
            write!(f, " at log time {t} s")?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl std::error::Error for LogError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.kind.source()
    }
}
