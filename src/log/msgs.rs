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

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    pub position: Point3<f64>,
    pub orientation: Quaternion<f64>,
}

impl Default for Pose {
    fn default() -> Self {
        Pose {
            position: Point3::origin(),
            orientation: Quaternion::identity(),
        }
    }
}

impl Pose {
    pub(crate) fn from_value(mut v: Value) -> Result<Self> {
        Ok(Pose {
            position: field(&mut v, "position", point_from)?,
            orientation: field(&mut v, "orientation", quaternion_from)?,
        })
    }

    pub(crate) fn to_value(&self) -> Value {
        let p = &self.position;
        record([
            ("position", xyz_value(p.x, p.y, p.z)),
            ("orientation", quaternion_value(&self.orientation)),
        ])
    }
}

/// `geometry_msgs/msg/Transform`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    pub translation: Vector3<f64>,
    pub rotation: Quaternion<f64>,
}

/// `geometry_msgs/msg/TransformStamped`: the transform maps points in `child_frame_id` into
/// `header.frame_id` (the parent).
#[derive(Debug, Clone, PartialEq)]
pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    pub transform: Transform,
}

impl RosMessage for TransformStamped {
    const TYPE_NAME: &'static str = "geometry_msgs/msg/TransformStamped";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(TransformStamped {
            header: field(&mut v, "header", Header::from_value)?,
            child_frame_id: field(&mut v, "child_frame_id", Value::into_string)?,
            transform: field(&mut v, "transform", |mut t| {
                Ok(Transform {
                    translation: field(&mut t, "translation", vector_from)?,
                    rotation: field(&mut t, "rotation", quaternion_from)?,
                })
            })?,
        })
    }

    fn to_value(&self) -> Value {
        let t = &self.transform.translation;
        record([
            ("header", self.header.to_value()),
            ("child_frame_id", Value::String(self.child_frame_id.clone())),
            (
                "transform",
                record([
                    ("translation", xyz_value(t.x, t.y, t.z)),
                    ("rotation", quaternion_value(&self.transform.rotation)),
                ]),
            ),
        ])
    }
}

/// Converts each element of an array of messages, naming the index in errors.
pub(crate) fn each<T>(v: Value, f: impl Fn(Value) -> Result<T>) -> Result<Vec<T>> {
    v.into_array()?
        .into_iter()
        .enumerate()
        .map(|(i, x)| f(x).map_err(|e| e.within(&format!("[{i}]"))))
        .collect()
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TfMessage {
    pub transforms: Vec<TransformStamped>,
}

impl RosMessage for TfMessage {
    const TYPE_NAME: &'static str = "tf2_msgs/msg/TFMessage";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(TfMessage {
            transforms: field(&mut v, "transforms", |a| {
                each(a, TransformStamped::from_value)
            })?,
        })
    }

    fn to_value(&self) -> Value {
        record([(
            "transforms",
            Value::Array(self.transforms.iter().map(RosMessage::to_value).collect()),
        )])
    }
}

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

/// `nav_msgs/msg/Odometry`: pose in `header.frame_id`, twist in `child_frame_id`.
#[derive(Debug, Clone, PartialEq)]
pub struct Odometry {
    pub header: Header,
    pub child_frame_id: String,
    pub pose: Pose,
    pub pose_covariance: [f64; 36],
    pub linear: Vector3<f64>,
    pub angular: Vector3<f64>,
    pub twist_covariance: [f64; 36],
}

impl RosMessage for Odometry {
    const TYPE_NAME: &'static str = "nav_msgs/msg/Odometry";

    fn from_value(mut v: Value) -> Result<Self> {
        let header = field(&mut v, "header", Header::from_value)?;
        let child_frame_id = field(&mut v, "child_frame_id", Value::into_string)?;
        let (pose, pose_covariance) = field(&mut v, "pose", |mut p| {
            Ok((
                field(&mut p, "pose", Pose::from_value)?,
                field(&mut p, "covariance", Value::into_f64_array)?,
            ))
        })?;
        let (linear, angular, twist_covariance) = field(&mut v, "twist", |mut t| {
            let (linear, angular) = field(&mut t, "twist", |mut tw| {
                Ok((
                    field(&mut tw, "linear", vector_from)?,
                    field(&mut tw, "angular", vector_from)?,
                ))
            })?;
            Ok((
                linear,
                angular,
                field(&mut t, "covariance", Value::into_f64_array)?,
            ))
        })?;
        Ok(Odometry {
            header,
            child_frame_id,
            pose,
            pose_covariance,
            linear,
            angular,
            twist_covariance,
        })
    }

    fn to_value(&self) -> Value {
        let (l, a) = (&self.linear, &self.angular);
        record([
            ("header", self.header.to_value()),
            ("child_frame_id", Value::String(self.child_frame_id.clone())),
            (
                "pose",
                record([
                    ("pose", self.pose.to_value()),
                    ("covariance", Value::F64s(self.pose_covariance.to_vec())),
                ]),
            ),
            (
                "twist",
                record([
                    (
                        "twist",
                        record([
                            ("linear", xyz_value(l.x, l.y, l.z)),
                            ("angular", xyz_value(a.x, a.y, a.z)),
                        ]),
                    ),
                    ("covariance", Value::F64s(self.twist_covariance.to_vec())),
                ]),
            ),
        ])
    }
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

impl RosMessage for PoseStamped {
    const TYPE_NAME: &'static str = "geometry_msgs/msg/PoseStamped";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(PoseStamped {
            header: field(&mut v, "header", Header::from_value)?,
            pose: field(&mut v, "pose", Pose::from_value)?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("pose", self.pose.to_value()),
        ])
    }
}

/// `geometry_msgs/msg/PoseArray`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PoseArray {
    pub header: Header,
    pub poses: Vec<Pose>,
}

impl RosMessage for PoseArray {
    const TYPE_NAME: &'static str = "geometry_msgs/msg/PoseArray";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(PoseArray {
            header: field(&mut v, "header", Header::from_value)?,
            poses: field(&mut v, "poses", |a| each(a, Pose::from_value))?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            (
                "poses",
                Value::Array(self.poses.iter().map(Pose::to_value).collect()),
            ),
        ])
    }
}

/// One box of `vision_msgs/msg/Detection2D`: centre, size (pixels) and the best hypothesis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Detection2D {
    pub header: Header,
    /// `(class_id, score)` of each hypothesis; poses are not kept.
    pub results: Vec<(String, f64)>,
    pub center_x: f64,
    pub center_y: f64,
    pub theta: f64,
    pub size_x: f64,
    pub size_y: f64,
    pub id: String,
}

/// `vision_msgs/msg/Detection2DArray` (vision_msgs 4.x, ROS 2 Humble and later).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Detection2DArray {
    pub header: Header,
    pub detections: Vec<Detection2D>,
}

impl RosMessage for Detection2DArray {
    const TYPE_NAME: &'static str = "vision_msgs/msg/Detection2DArray";

    fn from_value(mut v: Value) -> Result<Self> {
        let detection = |mut d: Value| -> Result<Detection2D> {
            let header = field(&mut d, "header", Header::from_value)?;
            let results = field(&mut d, "results", |a| {
                each(a, |mut r| {
                    field(&mut r, "hypothesis", |mut h| {
                        Ok((
                            field(&mut h, "class_id", Value::into_string)?,
                            field(&mut h, "score", |x| x.as_f64())?,
                        ))
                    })
                })
            })?;
            let (center_x, center_y, theta, size_x, size_y) = field(&mut d, "bbox", |mut b| {
                let (cx, cy, th) = field(&mut b, "center", |mut c| {
                    let (x, y) = field(&mut c, "position", |mut p| {
                        Ok((
                            field(&mut p, "x", |x| x.as_f64())?,
                            field(&mut p, "y", |x| x.as_f64())?,
                        ))
                    })?;
                    Ok((x, y, field(&mut c, "theta", |x| x.as_f64())?))
                })?;
                Ok((
                    cx,
                    cy,
                    th,
                    field(&mut b, "size_x", |x| x.as_f64())?,
                    field(&mut b, "size_y", |x| x.as_f64())?,
                ))
            })?;
            Ok(Detection2D {
                header,
                results,
                center_x,
                center_y,
                theta,
                size_x,
                size_y,
                id: field(&mut d, "id", Value::into_string)?,
            })
        };
        Ok(Detection2DArray {
            header: field(&mut v, "header", Header::from_value)?,
            detections: field(&mut v, "detections", |a| each(a, detection))?,
        })
    }

    fn to_value(&self) -> Value {
        let detection = |d: &Detection2D| {
            record([
                ("header", d.header.to_value()),
                (
                    "results",
                    Value::Array(
                        d.results
                            .iter()
                            .map(|(class_id, score)| {
                                record([
                                    (
                                        "hypothesis",
                                        record([
                                            ("class_id", Value::String(class_id.clone())),
                                            ("score", Value::F64(*score)),
                                        ]),
                                    ),
                                    ("pose", record([("pose", Pose::default().to_value())])),
                                ])
                            })
                            .collect(),
                    ),
                ),
                (
                    "bbox",
                    record([
                        (
                            "center",
                            record([
                                (
                                    "position",
                                    record([
                                        ("x", Value::F64(d.center_x)),
                                        ("y", Value::F64(d.center_y)),
                                    ]),
                                ),
                                ("theta", Value::F64(d.theta)),
                            ]),
                        ),
                        ("size_x", Value::F64(d.size_x)),
                        ("size_y", Value::F64(d.size_y)),
                    ]),
                ),
                ("id", Value::String(d.id.clone())),
            ])
        };
        record([
            ("header", self.header.to_value()),
            (
                "detections",
                Value::Array(self.detections.iter().map(detection).collect()),
            ),
        ])
    }
}

/// `visualization_msgs/msg/Marker` (Humble layout): shapes a 3-D view draws, e.g. the
/// cylinders of tracked people. Only what peopletrack writes is typed.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    pub header: Header,
    pub ns: String,
    pub id: i32,
    /// `Marker::CYLINDER`, `Marker::TEXT_VIEW_FACING`, ...
    pub kind: i32,
    /// `Marker::ADD`, `Marker::DELETE`, `Marker::DELETEALL`.
    pub action: i32,
    pub pose: Pose,
    pub scale: Vector3<f64>,
    /// RGBA in [0, 1].
    pub color: [f32; 4],
    /// How long the marker stays without an update (zero: forever).
    pub lifetime: Time,
    pub frame_locked: bool,
    pub points: Vec<Point3<f64>>,
    pub colors: Vec<[f32; 4]>,
    pub text: String,
    pub mesh_resource: String,
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    pub const CUBE: i32 = 1;
    pub const SPHERE: i32 = 2;
    pub const CYLINDER: i32 = 3;
    pub const LINE_STRIP: i32 = 4;
    pub const TEXT_VIEW_FACING: i32 = 9;
    pub const ADD: i32 = 0;
    pub const DELETE: i32 = 2;
    pub const DELETEALL: i32 = 3;
}

impl Default for Marker {
    fn default() -> Self {
        Marker {
            header: Header::default(),
            ns: String::new(),
            id: 0,
            kind: Marker::CUBE,
            action: Marker::ADD,
            pose: Pose::default(),
            scale: Vector3::new(1.0, 1.0, 1.0),
            color: [1.0, 1.0, 1.0, 1.0],
            lifetime: Time::default(),
            frame_locked: false,
            points: Vec::new(),
            colors: Vec::new(),
            text: String::new(),
            mesh_resource: String::new(),
            mesh_use_embedded_materials: false,
        }
    }
}

fn rgba_from(mut v: Value) -> Result<[f32; 4]> {
    Ok([
        field(&mut v, "r", |x| x.as_f64().map(|f| f as f32))?,
        field(&mut v, "g", |x| x.as_f64().map(|f| f as f32))?,
        field(&mut v, "b", |x| x.as_f64().map(|f| f as f32))?,
        field(&mut v, "a", |x| x.as_f64().map(|f| f as f32))?,
    ])
}

fn rgba_value(c: &[f32; 4]) -> Value {
    record([
        ("r", Value::F32(c[0])),
        ("g", Value::F32(c[1])),
        ("b", Value::F32(c[2])),
        ("a", Value::F32(c[3])),
    ])
}

impl RosMessage for Marker {
    const TYPE_NAME: &'static str = "visualization_msgs/msg/Marker";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(Marker {
            header: field(&mut v, "header", Header::from_value)?,
            ns: field(&mut v, "ns", Value::into_string)?,
            id: field(&mut v, "id", |x| x.as_i32())?,
            kind: field(&mut v, "type", |x| x.as_i32())?,
            action: field(&mut v, "action", |x| x.as_i32())?,
            pose: field(&mut v, "pose", Pose::from_value)?,
            scale: field(&mut v, "scale", vector_from)?,
            color: field(&mut v, "color", rgba_from)?,
            lifetime: field(&mut v, "lifetime", Time::from_value)?,
            frame_locked: field(&mut v, "frame_locked", |x| x.as_bool())?,
            points: field(&mut v, "points", |a| each(a, point_from))?,
            colors: field(&mut v, "colors", |a| each(a, rgba_from))?,
            text: field(&mut v, "text", Value::into_string)?,
            mesh_resource: field(&mut v, "mesh_resource", Value::into_string)?,
            mesh_use_embedded_materials: field(&mut v, "mesh_use_embedded_materials", |x| {
                x.as_bool()
            })?,
        })
    }

    fn to_value(&self) -> Value {
        record([
            ("header", self.header.to_value()),
            ("ns", Value::String(self.ns.clone())),
            ("id", Value::I32(self.id)),
            ("type", Value::I32(self.kind)),
            ("action", Value::I32(self.action)),
            ("pose", self.pose.to_value()),
            ("scale", xyz_value(self.scale.x, self.scale.y, self.scale.z)),
            ("color", rgba_value(&self.color)),
            ("lifetime", self.lifetime.to_value()),
            ("frame_locked", Value::Bool(self.frame_locked)),
            (
                "points",
                Value::Array(
                    self.points
                        .iter()
                        .map(|p| xyz_value(p.x, p.y, p.z))
                        .collect(),
                ),
            ),
            (
                "colors",
                Value::Array(self.colors.iter().map(rgba_value).collect()),
            ),
            ("text", Value::String(self.text.clone())),
            ("mesh_resource", Value::String(self.mesh_resource.clone())),
            (
                "mesh_use_embedded_materials",
                Value::Bool(self.mesh_use_embedded_materials),
            ),
        ])
    }
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MarkerArray {
    pub markers: Vec<Marker>,
}

impl RosMessage for MarkerArray {
    const TYPE_NAME: &'static str = "visualization_msgs/msg/MarkerArray";

    fn from_value(mut v: Value) -> Result<Self> {
        Ok(MarkerArray {
            markers: field(&mut v, "markers", |a| each(a, Marker::from_value))?,
        })
    }

    fn to_value(&self) -> Value {
        record([(
            "markers",
            Value::Array(self.markers.iter().map(Marker::to_value).collect()),
        )])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::cdr::{self, Endian};
    use crate::log::definitions;

    fn round_trip<T: RosMessage + PartialEq + std::fmt::Debug>(msg: &T) {
        let reg = definitions::registry(T::TYPE_NAME).expect("canonical definition");
        let bytes = cdr::encode(&reg, &msg.to_value(), Endian::Little).expect("encodes");
        let back = T::from_value(cdr::decode(&reg, &bytes).expect("decodes")).expect("converts");
        assert_eq!(&back, msg);
    }

    #[test]
    fn typed_messages_round_trip_through_cdr() {
        let header = Header::new(Nanos(1_700_000_000_123_456_789), "laser");
        round_trip(&LaserScan {
            header: header.clone(),
            angle_min: -1.0,
            angle_max: 1.0,
            angle_increment: 0.5,
            range_max: 10.0,
            ranges: vec![1.0, 2.0, 0.0, 4.0, 5.0],
            ..Default::default()
        });
        round_trip(&Image {
            header: header.clone(),
            height: 1,
            width: 2,
            encoding: "rgb8".into(),
            step: 6,
            data: vec![1, 2, 3, 4, 5, 6],
            ..Default::default()
        });
        round_trip(&CameraInfo {
            header: header.clone(),
            distortion_model: "plumb_bob".into(),
            d: vec![0.1, -0.2, 0.0, 0.0, 0.0],
            k: [500.0, 0.0, 160.0, 0.0, 500.0, 120.0, 0.0, 0.0, 1.0],
            ..Default::default()
        });
        round_trip(&TfMessage {
            transforms: vec![TransformStamped {
                header: header.clone(),
                child_frame_id: "base_link".into(),
                transform: Transform {
                    translation: Vector3::new(1.0, 2.0, 3.0),
                    rotation: Quaternion::new(0.5, 0.5, 0.5, 0.5),
                },
            }],
        });
        round_trip(&Odometry {
            header: header.clone(),
            child_frame_id: "base_link".into(),
            pose: Pose::default(),
            pose_covariance: [0.5; 36],
            linear: Vector3::new(1.0, 0.0, 0.0),
            angular: Vector3::new(0.0, 0.0, 0.1),
            twist_covariance: [0.0; 36],
        });
        round_trip(&MarkerArray {
            markers: vec![
                Marker {
                    header: header.clone(),
                    ns: "people".into(),
                    id: 7,
                    kind: Marker::CYLINDER,
                    scale: Vector3::new(0.4, 0.4, 1.8),
                    color: [0.0, 0.5, 1.0, 0.6],
                    lifetime: Time {
                        sec: 0,
                        nanosec: 80_000_000,
                    },
                    ..Default::default()
                },
                Marker {
                    kind: Marker::LINE_STRIP,
                    points: vec![Point3::new(1.0, 2.0, 0.0), Point3::new(1.5, 2.0, 0.0)],
                    colors: vec![[1.0, 0.0, 0.0, 1.0]; 2],
                    text: "7".into(),
                    ..Default::default()
                },
            ],
        });
        round_trip(&Detection2DArray {
            header: header.clone(),
            detections: vec![Detection2D {
                header,
                results: vec![("person".into(), 0.9)],
                center_x: 10.0,
                center_y: 20.0,
                size_x: 5.0,
                size_y: 8.0,
                id: "3".into(),
                ..Default::default()
            }],
        });
    }
}
