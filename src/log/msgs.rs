//! Typed messages for the ROS 2 types the pipelines consume, converted from and to the generic
//! [`Value`] tree. Converting by field name (not by byte layout) means a log whose definition
//! adds or reorders fields still reads; packed arrays move out of the tree without copying.
//!
//! Foxglove protobuf equivalents (`foxglove.LaserScan`, `foxglove.RawImage`, ...) convert into
//! the same types in [`super::protobuf`], so pipelines never care which encoding a log used.

use nalgebra::{Point3, Quaternion, Vector3};

use super::value::{FieldError, Value, record};
use crate::time::Nanos;

type Result<T> = std::result::Result<T, FieldError>;

/// A ROS 2 message type with a typed Rust form.
pub trait RosMessage: Sized {
    /// Full ROS 2 type name, e.g. `sensor_msgs/msg/LaserScan`.
    const TYPE_NAME: &'static str;
    /// Read from a decoded value of this type.
    fn from_value(v: Value) -> Result<Self>;
    /// The value tree the CDR encoder writes.
    fn to_value(&self) -> Value;
}

/// Take field `name` out of `v` and convert it, adding the field name to any error's path.
pub(crate) fn field<T>(v: &mut Value, name: &str, f: impl FnOnce(Value) -> Result<T>) -> Result<T> {
    let x = v.take(name)?;
    f(x).map_err(|e| e.within(name))
}

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    pub fn from_nanos(t: Nanos) -> Time {
        let (sec, nanosec) = t.to_stamp();
        Time { sec, nanosec }
    }

    /// As nanoseconds since the epoch; `None` before the epoch.
    pub fn nanos(&self) -> Option<Nanos> {
        Nanos::from_stamp(self.sec, self.nanosec)
    }

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(Time {
            sec: field(&mut v, "sec", |x| x.as_i32())?,
            nanosec: field(&mut v, "nanosec", |x| x.as_u32())?,
        })
    }

    fn to_value(self) -> Value {
        record([
            ("sec", Value::I32(self.sec)),
            ("nanosec", Value::U32(self.nanosec)),
        ])
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

impl Header {
    pub fn new(stamp: Nanos, frame_id: impl Into<String>) -> Header {
        Header {
            stamp: Time::from_nanos(stamp),
            frame_id: frame_id.into(),
        }
    }

    pub(crate) fn from_value(mut v: Value) -> Result<Self> {
        Ok(Header {
            stamp: field(&mut v, "stamp", Time::from_value)?,
            frame_id: field(&mut v, "frame_id", Value::into_string)?,
        })
    }

    pub(crate) fn to_value(&self) -> Value {
        record([
            ("stamp", self.stamp.to_value()),
            ("frame_id", Value::String(self.frame_id.clone())),
        ])
    }
}

pub(crate) fn xyz(mut v: Value) -> Result<[f64; 3]> {
    Ok([
        field(&mut v, "x", |x| x.as_f64())?,
        field(&mut v, "y", |x| x.as_f64())?,
        field(&mut v, "z", |x| x.as_f64())?,
    ])
}

pub(crate) fn point_from(v: Value) -> Result<Point3<f64>> {
    xyz(v).map(Point3::from)
}

pub(crate) fn vector_from(v: Value) -> Result<Vector3<f64>> {
    xyz(v).map(Vector3::from)
}

pub(crate) fn xyz_value(x: f64, y: f64, z: f64) -> Value {
    record([
        ("x", Value::F64(x)),
        ("y", Value::F64(y)),
        ("z", Value::F64(z)),
    ])
}

pub(crate) fn quaternion_from(mut v: Value) -> Result<Quaternion<f64>> {
    let x = field(&mut v, "x", |x| x.as_f64())?;
    let y = field(&mut v, "y", |x| x.as_f64())?;
    let z = field(&mut v, "z", |x| x.as_f64())?;
    let w = field(&mut v, "w", |x| x.as_f64())?;
    Ok(Quaternion::new(w, x, y, z))
}

pub(crate) fn quaternion_value(q: &Quaternion<f64>) -> Value {
    record([
        ("x", Value::F64(q.i)),
        ("y", Value::F64(q.j)),
        ("z", Value::F64(q.k)),
        ("w", Value::F64(q.w)),
    ])
}

/// Converts each element of an array of messages, naming the index in errors.
pub(crate) fn each<T>(v: Value, f: impl Fn(Value) -> Result<T>) -> Result<Vec<T>> {
    v.into_array()?
        .into_iter()
        .enumerate()
        .map(|(i, x)| f(x).map_err(|e| e.within(&format!("[{i}]"))))
        .collect()
}

mod audio;
mod geometry;
mod sensors;
mod vision;

pub use audio::{AudioDataStamped, AudioInfo, JointState};
pub use geometry::{
    Odometry, Pose, PoseArray, PoseStamped, TfMessage, Transform, TransformStamped,
};
pub use sensors::{CameraInfo, CompressedImage, Image, Imu, LaserScan, RegionOfInterest};
pub use vision::{Detection2D, Detection2DArray, Marker, MarkerArray};

#[cfg(test)]
mod tests;
