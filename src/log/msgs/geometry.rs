//! Geometry and transforms: `geometry_msgs` poses and transforms, `tf2_msgs/msg/TFMessage`,
//! `nav_msgs/msg/Odometry`.

use nalgebra::{Point3, Quaternion, Vector3};

use super::super::value::{Value, record};
use super::{
    Header, Result, RosMessage, each, field, point_from, quaternion_from, quaternion_value,
    vector_from, xyz_value,
};

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
