//! Session logs: reading and writing MCAP files, decoding their messages, transforms and
//! topic synchronisation. Everything else in peopletrack reads sessions through this module,
//! and only this module (with `report`) touches files.
//!
//! - [`reader`]: streaming, log-time-ordered message iteration with bounded memory.
//! - [`ros2msg`] + [`cdr`]: ROS 2 schemas and CDR for any type, custom ones included.
//! - [`protobuf`]: Foxglove protobuf schemas; JSON channels decode with `serde_json`.
//! - [`decode`]: which decoder reads which channel, and typed reads on top; [`fast`]: typed
//!   CDR fast paths for the high-rate standard types, skipping the value tree.
//! - [`msgs`]: typed forms of the ROS 2 messages pipelines consume; [`image`] decodes images.
//! - [`tf`]: the transform tree with interpolated lookups; [`sync`]: nearest-stamp joins.
//! - [`writer`]: sessions as `ros2 bag record` writes them; [`definitions`]: their schemas;
//!   [`copy`]: a copy of a log with messages added (tracks written back as markers);
//!   [`import`]: public datasets (WILDTRACK) written as session logs.

mod camera_info;
pub mod cdr;
pub mod copy;
pub mod decode;
pub mod definitions;
mod error;
pub mod fast;
pub mod image;
pub mod import;
pub mod msgs;
pub mod protobuf;
pub mod reader;
pub mod ros2msg;
pub mod stats;
pub mod sync;
pub mod tf;
pub mod value;
pub mod writer;

pub use decode::{Decoder, Decoders, read_topic};
pub use error::{LogError, LogErrorKind};
pub use reader::{ChannelInfo, CrcCoverage, LogSummary, Message, MessageStream, SessionLog};
pub use tf::TfBuffer;
pub use value::Value;
pub use writer::{ChannelId, Compression, SessionWriter, WriterOptions};
