//! `sensor_msgs`: laser scans, images, camera calibration, IMU.

use nalgebra::{Quaternion, Vector3};

use super::super::value::{Value, record};
use super::{
    Header, Result, RosMessage, field, quaternion_from, quaternion_value, vector_from, xyz_value,
};

/// `sensor_msgs/msg/LaserScan`. Ranges keep the driver's no-return markers (NaN, ±inf, 0.0).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LaserScan {
    pub header: Header,
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
    pub intensities: Vec<f32>,
}

impl LaserScan {
    /// Bearing of beam `i` in the scan frame (rad, counter-clockwise from x).
    pub fn angle(&self, i: usize) -> f64 {
        f64::from(self.angle_min) + i as f64 * f64::from(self.angle_increment)
    }

    /// True if `r` is a real return: finite and inside `(range_min, range_max)` (bounds
    /// inclusive, as drivers clamp to them).
    pub fn is_valid_range(&self, r: f32) -> bool {
        r.is_finite() && r >= self.range_min && r <= self.range_max && r > 0.0
    }
}

impl RosMessage for LaserScan {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/LaserScan";

    fn from_value(mut v: Value) -> Result<Self> {
        let f32_field = |v: &mut Value, n: &str| field(v, n, |x| x.as_f64().map(|f| f as f32));
        Ok(LaserScan {
            header: field(&mut v, "header", Header::from_value)?,
            angle_min: f32_field(&mut v, "angle_min")?,
            angle_max: f32_field(&mut v, "angle_max")?,
            angle_increment: f32_field(&mut v, "angle_increment")?,
            time_increment: f32_field(&mut v, "time_increment")?,
            scan_time: f32_field(&mut v, "scan_time")?,
            range_min: f32_field(&mut v, "range_min")?,
            range_max: f32_field(&mut v, "range_max")?,
            ranges: field(&mut v, "ranges", Value::into_f32s)?,
            intensities: field(&mut v, "intensities", Value::into_f32s)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("angle_min", Value::F32(self.angle_min)),
            ("angle_max", Value::F32(self.angle_max)),
            ("angle_increment", Value::F32(self.angle_increment)),
            ("time_increment", Value::F32(self.time_increment)),
            ("scan_time", Value::F32(self.scan_time)),
            ("range_min", Value::F32(self.range_min)),
            ("range_max", Value::F32(self.range_max)),
            ("ranges", Value::F32s(self.ranges.clone())),
            ("intensities", Value::F32s(self.intensities.clone())),
        ])
    }
}

/// `sensor_msgs/msg/Image` (raw pixels; see [`super::image`] for decoding).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Image {
    pub header: Header,
    pub height: u32,
    pub width: u32,
    pub encoding: String,
    pub is_bigendian: u8,
    pub step: u32,
    pub data: Vec<u8>,
}

impl RosMessage for Image {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/Image";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(Image {
            header: field(&mut v, "header", Header::from_value)?,
            height: field(&mut v, "height", |x| x.as_u32())?,
            width: field(&mut v, "width", |x| x.as_u32())?,
            encoding: field(&mut v, "encoding", Value::into_string)?,
            is_bigendian: field(&mut v, "is_bigendian", |x| x.as_u8())?,
            step: field(&mut v, "step", |x| x.as_u32())?,
            data: field(&mut v, "data", Value::into_bytes)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("height", Value::U32(self.height)),
            ("width", Value::U32(self.width)),
            ("encoding", Value::String(self.encoding.clone())),
            ("is_bigendian", Value::U8(self.is_bigendian)),
            ("step", Value::U32(self.step)),
            ("data", Value::Bytes(self.data.clone())),
        ])
    }
}

/// `sensor_msgs/msg/CompressedImage` (`format` names the codec: `jpeg`, `png`, or the
/// `image_transport` form `rgb8; jpeg compressed bgr8`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CompressedImage {
    pub header: Header,
    pub format: String,
    pub data: Vec<u8>,
}

impl RosMessage for CompressedImage {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/CompressedImage";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(CompressedImage {
            header: field(&mut v, "header", Header::from_value)?,
            format: field(&mut v, "format", Value::into_string)?,
            data: field(&mut v, "data", Value::into_bytes)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("format", Value::String(self.format.clone())),
            ("data", Value::Bytes(self.data.clone())),
        ])
    }
}

/// `sensor_msgs/msg/RegionOfInterest`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RegionOfInterest {
    pub x_offset: u32,
    pub y_offset: u32,
    pub height: u32,
    pub width: u32,
    pub do_rectify: bool,
}

/// `sensor_msgs/msg/CameraInfo`. Omnidirectional cameras use `distortion_model`
/// `paracatadioptric` or `conical_mirror` with the parameters documented in `geometry`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CameraInfo {
    pub header: Header,
    pub height: u32,
    pub width: u32,
    pub distortion_model: String,
    pub d: Vec<f64>,
    pub k: [f64; 9],
    pub r: [f64; 9],
    pub p: [f64; 12],
    pub binning_x: u32,
    pub binning_y: u32,
    pub roi: RegionOfInterest,
}

impl RosMessage for CameraInfo {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/CameraInfo";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(CameraInfo {
            header: field(&mut v, "header", Header::from_value)?,
            height: field(&mut v, "height", |x| x.as_u32())?,
            width: field(&mut v, "width", |x| x.as_u32())?,
            distortion_model: field(&mut v, "distortion_model", Value::into_string)?,
            d: field(&mut v, "d", Value::into_f64s)?,
            k: field(&mut v, "k", Value::into_f64_array)?,
            r: field(&mut v, "r", Value::into_f64_array)?,
            p: field(&mut v, "p", Value::into_f64_array)?,
            binning_x: field(&mut v, "binning_x", |x| x.as_u32())?,
            binning_y: field(&mut v, "binning_y", |x| x.as_u32())?,
            roi: field(&mut v, "roi", |mut r| {
                Ok(RegionOfInterest {
                    x_offset: field(&mut r, "x_offset", |x| x.as_u32())?,
                    y_offset: field(&mut r, "y_offset", |x| x.as_u32())?,
                    height: field(&mut r, "height", |x| x.as_u32())?,
                    width: field(&mut r, "width", |x| x.as_u32())?,
                    do_rectify: field(&mut r, "do_rectify", |x| x.as_bool())?,
                })
            })?,
        })
    }

    fn to_value(&self) -> Value {
        let roi = &self.roi;
        record([
            ("header", self.header.to_value()),
            ("height", Value::U32(self.height)),
            ("width", Value::U32(self.width)),
            (
                "distortion_model",
                Value::String(self.distortion_model.clone()),
            ),
            ("d", Value::F64s(self.d.clone())),
            ("k", Value::F64s(self.k.to_vec())),
            ("r", Value::F64s(self.r.to_vec())),
            ("p", Value::F64s(self.p.to_vec())),
            ("binning_x", Value::U32(self.binning_x)),
            ("binning_y", Value::U32(self.binning_y)),
            (
                "roi",
                record([
                    ("x_offset", Value::U32(roi.x_offset)),
                    ("y_offset", Value::U32(roi.y_offset)),
                    ("height", Value::U32(roi.height)),
                    ("width", Value::U32(roi.width)),
                    ("do_rectify", Value::Bool(roi.do_rectify)),
                ]),
            ),
        ])
    }
}

/// `sensor_msgs/msg/Imu`.
#[derive(Debug, Clone, PartialEq)]
pub struct Imu {
    pub header: Header,
    pub orientation: Quaternion<f64>,
    pub orientation_covariance: [f64; 9],
    pub angular_velocity: Vector3<f64>,
    pub angular_velocity_covariance: [f64; 9],
    pub linear_acceleration: Vector3<f64>,
    pub linear_acceleration_covariance: [f64; 9],
}

impl RosMessage for Imu {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/Imu";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(Imu {
            header: field(&mut v, "header", Header::from_value)?,
            orientation: field(&mut v, "orientation", quaternion_from)?,
            orientation_covariance: field(&mut v, "orientation_covariance", Value::into_f64_array)?,
            angular_velocity: field(&mut v, "angular_velocity", vector_from)?,
            angular_velocity_covariance: field(
                &mut v,
                "angular_velocity_covariance",
                Value::into_f64_array,
            )?,
            linear_acceleration: field(&mut v, "linear_acceleration", vector_from)?,
            linear_acceleration_covariance: field(
                &mut v,
                "linear_acceleration_covariance",
                Value::into_f64_array,
            )?,
        })
    }

    fn to_value(&self) -> Value {
        let (w, a) = (&self.angular_velocity, &self.linear_acceleration);
        record([
            ("header", self.header.to_value()),
            ("orientation", quaternion_value(&self.orientation)),
            (
                "orientation_covariance",
                Value::F64s(self.orientation_covariance.to_vec()),
            ),
            ("angular_velocity", xyz_value(w.x, w.y, w.z)),
            (
                "angular_velocity_covariance",
                Value::F64s(self.angular_velocity_covariance.to_vec()),
            ),
            ("linear_acceleration", xyz_value(a.x, a.y, a.z)),
            (
                "linear_acceleration_covariance",
                Value::F64s(self.linear_acceleration_covariance.to_vec()),
            ),
        ])
    }
}
