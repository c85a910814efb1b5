//! `audio_common_msgs` (ros-drivers `audio_common`, as `audio_capture` publishes them) and
//! `sensor_msgs/JointState` (a pan-tilt unit's angles).

use super::{Header, Result, RosMessage, field};
use crate::log::value::{Value, record};

/// `audio_common_msgs/msg/AudioDataStamped`: a chunk of encoded audio (here S16LE,
/// interleaved channels, as [`AudioInfo`] says) with its capture stamp.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AudioDataStamped {
    pub header: Header,
    pub data: Vec<u8>,
}

impl RosMessage for AudioDataStamped {
    const TYPE_NAME: &'static str = "audio_common_msgs/msg/AudioDataStamped";

    fn from_value(mut v: Value) -> Result<Self> {
        let header = field(&mut v, "header", Header::from_value)?;
        let data = field(&mut v, "audio", |mut a| {
            field(&mut a, "data", Value::into_bytes)
        })?;
        Ok(AudioDataStamped { header, data })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("audio", record([("data", Value::Bytes(self.data.clone()))])),
        ])
    }
}

/// `audio_common_msgs/msg/AudioInfo` (published once, latched).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AudioInfo {
    pub channels: u8,
    pub sample_rate: u32,
    /// e.g. `S16LE`.
    pub sample_format: String,
    /// bits per second.
    pub bitrate: u32,
    /// e.g. `wave`.
    pub coding_format: String,
}

impl RosMessage for AudioInfo {
    const TYPE_NAME: &'static str = "audio_common_msgs/msg/AudioInfo";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(AudioInfo {
            channels: field(&mut v, "channels", |x| x.as_u8())?,
            sample_rate: field(&mut v, "sample_rate", |x| x.as_u32())?,
            sample_format: field(&mut v, "sample_format", Value::into_string)?,
            bitrate: field(&mut v, "bitrate", |x| x.as_u32())?,
            coding_format: field(&mut v, "coding_format", Value::into_string)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("channels", Value::U8(self.channels)),
            ("sample_rate", Value::U32(self.sample_rate)),
            ("sample_format", Value::String(self.sample_format.clone())),
            ("bitrate", Value::U32(self.bitrate)),
            ("coding_format", Value::String(self.coding_format.clone())),
        ])
    }
}

/// `sensor_msgs/msg/JointState`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointState {
    pub header: Header,
    pub name: Vec<String>,
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub effort: Vec<f64>,
}

impl RosMessage for JointState {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/JointState";

    fn from_value(mut v: Value) -> Result<Self> {
        let names = |x: Value| -> Result<Vec<String>> {
            x.into_array()?
                .into_iter()
                .map(Value::into_string)
                .collect()
        };
        Ok(JointState {
            header: field(&mut v, "header", Header::from_value)?,
            name: field(&mut v, "name", names)?,
            position: field(&mut v, "position", Value::into_f64s)?,
            velocity: field(&mut v, "velocity", Value::into_f64s)?,
            effort: field(&mut v, "effort", Value::into_f64s)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            (
                "name",
                Value::Array(self.name.iter().cloned().map(Value::String).collect()),
            ),
            ("position", Value::F64s(self.position.clone())),
            ("velocity", Value::F64s(self.velocity.clone())),
            ("effort", Value::F64s(self.effort.clone())),
        ])
    }
}
