//! `peopletrack cat LOG --topic T`: decoded messages of one topic as JSON lines, any type
//! (ROS 2 CDR straight from the wire bytes, Foxglove protobuf and JSON through the value tree).
//!
//! Each line: `{"topic", "log_time_ns", "publish_time_ns", "sequence", "message"}`. Non-finite
//! floats are written `"NaN"`, `"Infinity"`, `"-Infinity"` (the protobuf JSON convention), so
//! lines stay valid JSON and no-returns stay visible.
//!
//! Lines are built in one reused buffer (no per-message allocation for CDR channels, whose
//! messages are written by [`peopletrack::log::cdr::write_json`] without a value tree) and
//! handed to the output some 64 KiB at a time.

use std::path::PathBuf;

use serde_json::ser::{CompactFormatter, Formatter};

use peopletrack::log::{Decoders, SessionLog};

/// Bytes of lines gathered before they are written out.
const WRITE_BATCH: usize = 1 << 16;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// MCAP session log to read.
    #[arg(value_name = "LOG")]
    pub log: PathBuf,
    /// Topic to print (as `inspect` lists it).
    #[arg(long, short)]
    pub topic: String,
    /// Print at most N messages.
    #[arg(long, short = 'n', value_name = "N")]
    pub limit: Option<usize>,
    /// Shorten arrays longer than N elements (the rest is counted, not printed).
    #[arg(long, value_name = "N")]
    pub max_array: Option<usize>,
    /// Read a damaged (cut or corrupt) log: print every complete message before the damage
    /// and skip chunks that do not open, saying on stderr what was lost.
    #[arg(long)]
    pub recover: bool,
}

pub fn run(args: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let log = if args.recover {
        SessionLog::open_recovering(&args.log)?
    } else {
        SessionLog::open(&args.log)?
    };
    for w in &log.summary().warnings {
        eprintln!("warning: {}: {w}", args.log.display());
    }
    let mut decoders = Decoders::new();
    let limit = args.limit.unwrap_or(usize::MAX);
    let mut buf = Vec::with_capacity(2 * WRITE_BATCH);
    let mut topic = Vec::new();
    serde_json::to_writer(&mut topic, &args.topic)?;
    for m in log.messages_on(&[args.topic.as_str()])?.take(limit) {
        let m = match m {
            Ok(m) => m,
            Err(e) => {
                // the complete lines before the damage are printed, as they always were
                out.write_all(&buf)?;
                return Err(e.into());
            }
        };
        let line_start = buf.len();
        // keys in this order: topic, log_time_ns, publish_time_ns, sequence, message
        buf.extend_from_slice(b"{\"topic\":");
        buf.extend_from_slice(&topic);
        buf.extend_from_slice(b",\"log_time_ns\":");
        CompactFormatter.write_u64(&mut buf, m.log_time.0)?;
        buf.extend_from_slice(b",\"publish_time_ns\":");
        CompactFormatter.write_u64(&mut buf, m.publish_time.0)?;
        buf.extend_from_slice(b",\"sequence\":");
        CompactFormatter.write_u32(&mut buf, m.sequence)?;
        buf.extend_from_slice(b",\"message\":");
        if let Err(e) = decoders.write_json(&log, &m, args.max_array, &mut buf) {
            out.write_all(&buf[..line_start])?;
            return Err(e.into());
        }
        buf.extend_from_slice(b"}\n");
        if buf.len() >= WRITE_BATCH {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    out.write_all(&buf)?;
    Ok(())
}
