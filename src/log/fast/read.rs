//! The per-type readers of the fast paths, field by field in wire order.

use std::borrow::Cow;

use nalgebra::{Point3, Quaternion, Vector3};

use super::super::msgs::{
    CameraInfo, CompressedImage, Header, Image, Imu, LaserScan, Odometry, Pose, TfMessage, Time,
    Transform, TransformStamped,
};
use super::{Cursor, FastCdr, FastKind, Result, prefixed, within};

/// Smallest wire size of one `TransformStamped`: stamp (8), two string lengths (8), seven
/// `float64` (56). Bounds the element count of a `TFMessage` before anything is allocated.
const MIN_TRANSFORM_STAMPED: usize = 72;

fn header_into(c: &mut Cursor<'_>, h: &mut Header) -> Result<()> {
    h.stamp = within(time(c), "stamp")?;
    within(c.string_into(&mut h.frame_id), "frame_id")
}

fn quaternion(q: [f64; 4]) -> Quaternion<f64> {
    Quaternion::new(q[3], q[0], q[1], q[2])
}

fn transform_stamped_into(c: &mut Cursor<'_>, t: &mut TransformStamped) -> Result<()> {
    within(header_into(c, &mut t.header), "header")?;
    within(c.string_into(&mut t.child_frame_id), "child_frame_id")?;
    within(
        (|| {
            t.transform.translation = Vector3::from(c.xyz()?);
            t.transform.rotation = quaternion(c.xyzw()?);
            Ok(())
        })(),
        "transform",
    )
}

impl FastCdr for TfMessage {
    const KIND: FastKind = FastKind::Tf;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        let n = within(c.seq_len(MIN_TRANSFORM_STAMPED), "transforms")?;
        self.transforms.truncate(n);
        for i in 0..n {
            if i == self.transforms.len() {
                self.transforms.push(TransformStamped {
                    header: Header::default(),
                    child_frame_id: String::new(),
                    transform: Transform {
                        translation: Vector3::zeros(),
                        rotation: Quaternion::identity(),
                    },
                });
            }
            transform_stamped_into(c, &mut self.transforms[i])
                .map_err(|e| prefixed(e, &format!("transforms[{i}]")))?;
        }
        Ok(())
    }
}

impl Default for Odometry {
    fn default() -> Self {
        Odometry {
            header: Header::default(),
            child_frame_id: String::new(),
            pose: Pose::default(),
            pose_covariance: [0.0; 36],
            linear: Vector3::zeros(),
            angular: Vector3::zeros(),
            twist_covariance: [0.0; 36],
        }
    }
}

impl FastCdr for Odometry {
    const KIND: FastKind = FastKind::Odometry;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        within(header_into(c, &mut self.header), "header")?;
        within(c.string_into(&mut self.child_frame_id), "child_frame_id")?;
        within(
            (|| {
                self.pose.position = Point3::from(c.xyz()?);
                self.pose.orientation = quaternion(c.xyzw()?);
                c.f64_array(&mut self.pose_covariance)
            })(),
            "pose",
        )?;
        within(
            (|| {
                self.linear = Vector3::from(c.xyz()?);
                self.angular = Vector3::from(c.xyz()?);
                c.f64_array(&mut self.twist_covariance)
            })(),
            "twist",
        )
    }
}

impl Default for Imu {
    fn default() -> Self {
        Imu {
            header: Header::default(),
            orientation: Quaternion::identity(),
            orientation_covariance: [0.0; 9],
            angular_velocity: Vector3::zeros(),
            angular_velocity_covariance: [0.0; 9],
            linear_acceleration: Vector3::zeros(),
            linear_acceleration_covariance: [0.0; 9],
        }
    }
}

impl FastCdr for Imu {
    const KIND: FastKind = FastKind::Imu;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        within(header_into(c, &mut self.header), "header")?;
        self.orientation = quaternion(within(c.xyzw(), "orientation")?);
        within(
            c.f64_array(&mut self.orientation_covariance),
            "orientation_covariance",
        )?;
        self.angular_velocity = Vector3::from(within(c.xyz(), "angular_velocity")?);
        within(
            c.f64_array(&mut self.angular_velocity_covariance),
            "angular_velocity_covariance",
        )?;
        self.linear_acceleration = Vector3::from(within(c.xyz(), "linear_acceleration")?);
        within(
            c.f64_array(&mut self.linear_acceleration_covariance),
            "linear_acceleration_covariance",
        )
    }
}

impl FastCdr for LaserScan {
    const KIND: FastKind = FastKind::LaserScan;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        within(header_into(c, &mut self.header), "header")?;
        for (x, name) in [
            (&mut self.angle_min, "angle_min"),
            (&mut self.angle_max, "angle_max"),
            (&mut self.angle_increment, "angle_increment"),
            (&mut self.time_increment, "time_increment"),
            (&mut self.scan_time, "scan_time"),
            (&mut self.range_min, "range_min"),
            (&mut self.range_max, "range_max"),
        ] {
            *x = within(c.f32(), name)?;
        }
        within(c.f32_seq(&mut self.ranges), "ranges")?;
        within(c.f32_seq(&mut self.intensities), "intensities")
    }
}

impl FastCdr for CameraInfo {
    const KIND: FastKind = FastKind::CameraInfo;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        within(header_into(c, &mut self.header), "header")?;
        self.height = within(c.u32(), "height")?;
        self.width = within(c.u32(), "width")?;
        within(
            c.string_into(&mut self.distortion_model),
            "distortion_model",
        )?;
        within(c.f64_seq(&mut self.d), "d")?;
        within(c.f64_array(&mut self.k), "k")?;
        within(c.f64_array(&mut self.r), "r")?;
        within(c.f64_array(&mut self.p), "p")?;
        self.binning_x = within(c.u32(), "binning_x")?;
        self.binning_y = within(c.u32(), "binning_y")?;
        let roi = &mut self.roi;
        within(
            (|| {
                roi.x_offset = c.u32()?;
                roi.y_offset = c.u32()?;
                roi.height = c.u32()?;
                roi.width = c.u32()?;
                roi.do_rectify = c.u8()? != 0;
                Ok(())
            })(),
            "roi",
        )
    }
}

/// `std_msgs/msg/Header` with the frame borrowed from the payload.
#[derive(Debug, Clone, PartialEq)]
pub struct HeaderRef<'a> {
    pub stamp: Time,
    pub frame_id: Cow<'a, str>,
}

impl<'a> HeaderRef<'a> {
    fn read(c: &mut Cursor<'a>) -> Result<Self> {
        Ok(HeaderRef {
            stamp: within(time(c), "stamp")?,
            frame_id: within(c.str(), "frame_id")?,
        })
    }

    pub fn to_owned(&self) -> Header {
        Header {
            stamp: self.stamp,
            frame_id: self.frame_id.to_string(),
        }
    }
}

/// `sensor_msgs/msg/Image` with the pixels borrowed from the payload.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageRef<'a> {
    pub header: HeaderRef<'a>,
    pub height: u32,
    pub width: u32,
    pub encoding: Cow<'a, str>,
    pub is_bigendian: u8,
    pub step: u32,
    pub data: &'a [u8],
}

impl<'a> ImageRef<'a> {
    /// Decode a whole CDR payload (encapsulation header included).
    pub fn decode(data: &'a [u8]) -> Result<Self> {
        Self::read(&mut Cursor::new(data)?)
    }

    fn read(c: &mut Cursor<'a>) -> Result<Self> {
        Ok(ImageRef {
            header: within(HeaderRef::read(c), "header")?,
            height: within(c.u32(), "height")?,
            width: within(c.u32(), "width")?,
            encoding: within(c.str(), "encoding")?,
            is_bigendian: within(c.u8(), "is_bigendian")?,
            step: within(c.u32(), "step")?,
            data: within(c.bytes(), "data")?,
        })
    }
}

/// `sensor_msgs/msg/CompressedImage` with the encoded bytes borrowed from the payload.
#[derive(Debug, Clone, PartialEq)]
pub struct CompressedImageRef<'a> {
    pub header: HeaderRef<'a>,
    pub format: Cow<'a, str>,
    pub data: &'a [u8],
}

impl<'a> CompressedImageRef<'a> {
    /// Decode a whole CDR payload (encapsulation header included).
    pub fn decode(data: &'a [u8]) -> Result<Self> {
        Self::read(&mut Cursor::new(data)?)
    }

    fn read(c: &mut Cursor<'a>) -> Result<Self> {
        Ok(CompressedImageRef {
            header: within(HeaderRef::read(c), "header")?,
            format: within(c.str(), "format")?,
            data: within(c.bytes(), "data")?,
        })
    }
}

fn header_from(h: &mut Header, r: &HeaderRef<'_>) {
    h.stamp = r.stamp;
    h.frame_id.clear();
    h.frame_id.push_str(&r.frame_id);
}

fn string_from(s: &mut String, r: &str) {
    s.clear();
    s.push_str(r);
}

fn bytes_from(v: &mut Vec<u8>, r: &[u8]) {
    v.clear();
    v.extend_from_slice(r);
}

impl FastCdr for Image {
    const KIND: FastKind = FastKind::Image;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        let r = ImageRef::read(c)?;
        header_from(&mut self.header, &r.header);
        self.height = r.height;
        self.width = r.width;
        string_from(&mut self.encoding, &r.encoding);
        self.is_bigendian = r.is_bigendian;
        self.step = r.step;
        bytes_from(&mut self.data, r.data);
        Ok(())
    }
}

impl FastCdr for CompressedImage {
    const KIND: FastKind = FastKind::CompressedImage;
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()> {
        let r = CompressedImageRef::read(c)?;
        header_from(&mut self.header, &r.header);
        string_from(&mut self.format, &r.format);
        bytes_from(&mut self.data, r.data);
        Ok(())
    }
}

/// `builtin_interfaces/msg/Time`.
fn time(c: &mut Cursor<'_>) -> Result<Time> {
    Ok(Time {
        sec: c.i32()?,
        nanosec: c.u32()?,
    })
}
