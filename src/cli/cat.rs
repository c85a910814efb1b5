//! `peopletrack cat LOG --topic T`: decoded messages of one topic as JSON lines, any type
//! (ROS 2 CDR through the dynamic decoder, Foxglove protobuf, JSON).
//!
//! Each line: `{"topic", "log_time_ns", "publish_time_ns", "sequence", "message"}`. Non-finite
//! floats are written `"NaN"`, `"Infinity"`, `"-Infinity"` (the protobuf JSON convention), so
//! lines stay valid JSON and no-returns stay visible.

use std::path::PathBuf;

use peopletrack::log::value::Json;
use peopletrack::log::{Decoders, SessionLog};

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
    for m in log.messages_on(&[args.topic.as_str()])?.take(limit) {
        let m = m?;
        let v = decoders.value(&log, &m)?;
        let line = Line {
            topic: m.topic(),
            log_time_ns: m.log_time.0,
            publish_time_ns: m.publish_time.0,
            sequence: m.sequence,
            message: v.json(args.max_array),
        };
        serde_json::to_writer(&mut *out, &line)?;
        out.write_all(b"\n")?;
    }
    Ok(())
}

/// One output line, streamed by `serde_json` (no JSON tree is built; keys in this order).
#[derive(serde::Serialize)]
struct Line<'a> {
    topic: &'a str,
    log_time_ns: u64,
    publish_time_ns: u64,
    sequence: u32,
    message: Json<'a>,
}
