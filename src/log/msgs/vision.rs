//! Detections and markers: `vision_msgs/msg/Detection2DArray`, `visualization_msgs` markers.

use nalgebra::{Point3, Vector3};

use super::super::value::{Value, record};
use super::geometry::Pose;
use super::{Header, Result, RosMessage, Time, each, field, point_from, vector_from, xyz_value};

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
