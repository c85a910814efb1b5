//! Foxglove protobuf channels: the schema record holds a binary `FileDescriptorSet`; messages
//! are decoded dynamically with `prost-reflect` into the same [`Value`] tree as CDR, and the
//! Foxglove schemas the pipelines need convert into the typed ROS-shaped messages
//! (`foxglove.LaserScan` → [`LaserScan`], `foxglove.RawImage` → [`Image`], ...).
//!
//! Unset protobuf fields read as their defaults (proto3 semantics), so every field of the
//! descriptor appears in the tree.

use prost_reflect::{
    DescriptorPool, DynamicMessage, MessageDescriptor, ReflectMessage, Value as Pv,
};

use super::cdr::tree_budget;
use super::msgs::{
    self, CameraInfo, CompressedImage, Header, Image, LaserScan, PoseStamped, RegionOfInterest,
    TfMessage, Time, Transform, TransformStamped, field,
};
use super::ros2msg::MAX_NESTING;
use super::value::{FieldError, Value};
use nalgebra::{Quaternion, Vector3};
use std::sync::Arc;

/// The message descriptor named by a schema record, from its `FileDescriptorSet` bytes.
///
/// The set is decoded here first and each file's `syntax` checked: `prost-reflect` 0.16.5
/// panics (index out of bounds while labelling the error) on a syntax other than `proto2` or
/// `proto3`, found by the `protobuf_decode` fuzz target.
pub fn descriptor(schema_name: &str, descriptor_set: &[u8]) -> Result<MessageDescriptor, String> {
    use prost_reflect::prost::Message as _;
    use prost_reflect::prost_types::FileDescriptorSet;
    let invalid = |e: &dyn std::fmt::Display| {
        format!("schema `{schema_name}` is not a valid FileDescriptorSet: {e}")
    };
    let set = FileDescriptorSet::decode(descriptor_set).map_err(|e| invalid(&e))?;
    if let Some(f) = set
        .file
        .iter()
        .find(|f| !matches!(f.syntax.as_deref(), None | Some("proto2") | Some("proto3")))
    {
        let why = format!("file `{}` has unknown syntax {:?}", f.name(), f.syntax());
        return Err(invalid(&why));
    }
    let pool = DescriptorPool::from_file_descriptor_set(set).map_err(|e| invalid(&e))?;
    pool.get_message_by_name(schema_name)
        .ok_or_else(|| format!("FileDescriptorSet has no message named `{schema_name}`"))
}

/// Decode one protobuf message into a value tree.
///
/// Bounded for hostile schemas and payloads: `prost` refuses payloads nested over 100 deep,
/// the tree is refused past [`MAX_NESTING`] levels, an unset message field of a type already
/// being expanded (a recursive type) reads as an empty message instead of expanding its
/// defaults forever, and the tree's size is held to [`tree_budget`].
pub fn decode(desc: &MessageDescriptor, data: &[u8]) -> Result<Value, String> {
    let msg = DynamicMessage::decode(desc.clone(), data)
        .map_err(|e| format!("protobuf decode failed: {e}"))?;
    let mut tree = Tree {
        nodes_left: tree_budget(data.len()) / std::mem::size_of::<(Arc<str>, Value)>(),
        open: Vec::new(),
        budget: tree_budget(data.len()),
    };
    tree.message(&msg)
}

/// The conversion of one decoded message into a [`Value`] tree, with its bounds.
struct Tree {
    /// Values that may still be made.
    nodes_left: usize,
    /// Full names of the message types being converted, outermost first.
    open: Vec<String>,
    budget: usize,
}

impl Tree {
    fn charge(&mut self, nodes: usize) -> Result<(), String> {
        self.nodes_left = self.nodes_left.checked_sub(nodes).ok_or_else(|| {
            format!(
                "protobuf message would take more than {} bytes as a value tree ({})",
                self.budget,
                super::cdr::RAISE_HINT
            )
        })?;
        Ok(())
    }

    fn message(&mut self, msg: &DynamicMessage) -> Result<Value, String> {
        if self.open.len() >= MAX_NESTING {
            return Err(format!(
                "protobuf message nests more than {MAX_NESTING} deep"
            ));
        }
        let desc = msg.descriptor();
        self.open.push(desc.full_name().to_string());
        let mut fields = Vec::with_capacity(desc.fields().len());
        for fd in desc.fields() {
            self.charge(1)?;
            let recursive_default = !msg.has_field(&fd)
                && !fd.is_list()
                && !fd.is_map()
                && fd
                    .kind()
                    .as_message()
                    .is_some_and(|m| self.open.iter().any(|n| n == m.full_name()));
            let v = if recursive_default {
                Value::Struct(Vec::new())
            } else {
                self.value(&msg.get_field(&fd))?
            };
            fields.push((Arc::from(fd.name()), v));
        }
        self.open.pop();
        Ok(Value::Struct(fields))
    }

    fn value(&mut self, v: &Pv) -> Result<Value, String> {
        Ok(match v {
            Pv::Bool(b) => Value::Bool(*b),
            Pv::I32(x) | Pv::EnumNumber(x) => Value::I32(*x),
            Pv::I64(x) => Value::I64(*x),
            Pv::U32(x) => Value::U32(*x),
            Pv::U64(x) => Value::U64(*x),
            Pv::F32(x) => Value::F32(*x),
            Pv::F64(x) => Value::F64(*x),
            Pv::String(s) => Value::String(s.clone()),
            Pv::Bytes(b) => Value::Bytes(b.to_vec()),
            Pv::Message(m) => self.message(m)?,
            Pv::List(items) => match pack_list(items) {
                Some(packed) => packed,
                None => {
                    self.charge(items.len())?;
                    Value::Array(
                        items
                            .iter()
                            .map(|x| self.value(x))
                            .collect::<Result<_, _>>()?,
                    )
                }
            },
            Pv::Map(map) => {
                self.charge(map.len())?;
                let mut entries = Vec::with_capacity(map.len());
                for (k, v) in map {
                    entries.push((format!("{k:?}"), self.value(v)?));
                }
                entries.sort_by(|a, b| a.0.cmp(&b.0));
                Value::Struct(
                    entries
                        .into_iter()
                        .map(|(k, v)| (Arc::from(k.as_str()), v))
                        .collect(),
                )
            }
        })
    }
}

/// Repeated scalars become packed arrays, like CDR sequences (`None`: not all one scalar).
fn pack_list(items: &[Pv]) -> Option<Value> {
    macro_rules! all {
        ($pat:ident, $variant:ident) => {
            if items.iter().all(|x| matches!(x, Pv::$pat(_))) {
                return Some(Value::$variant(
                    items
                        .iter()
                        .filter_map(|x| if let Pv::$pat(v) = x { Some(*v) } else { None })
                        .collect(),
                ));
            }
        };
    }
    if !items.is_empty() {
        all!(F64, F64s);
        all!(F32, F32s);
        all!(I32, I32s);
        all!(U32, U32s);
        all!(I64, I64s);
        all!(U64, U64s);
        all!(Bool, Bools);
    }
    None
}

type FResult<T> = std::result::Result<T, FieldError>;

/// Take the first of `names` that the structure has (descriptors differ in case and naming).
fn field_any<T>(v: &mut Value, names: &[&str], f: impl FnOnce(Value) -> FResult<T>) -> FResult<T> {
    let name = names
        .iter()
        .find(|n| v.get(n).is_ok())
        .ok_or_else(|| FieldError::new("missing").within(names[0]))?;
    field(v, name, f)
}

/// `google.protobuf.Timestamp` (`seconds`, `nanos`) or `foxglove.Time` (`sec`, `nsec`).
fn timestamp(v: Value) -> FResult<Time> {
    let mut v = v;
    let seconds = field_any(&mut v, &["seconds", "sec"], |x| x.as_i128())?;
    let nanos = field_any(&mut v, &["nanos", "nsec"], |x| x.as_i128())?;
    let sec = i32::try_from(seconds)
        .map_err(|_| FieldError::new(format!("{seconds} s does not fit a ROS stamp")))?;
    let nanosec =
        u32::try_from(nanos).map_err(|_| FieldError::new(format!("nanos {nanos} is negative")))?;
    Ok(Time { sec, nanosec })
}

fn header(v: &mut Value, frame_field: &str) -> FResult<Header> {
    Ok(Header {
        stamp: field(v, "timestamp", timestamp)?,
        frame_id: field(v, frame_field, Value::into_string)?,
    })
}

fn is_identity_pose(mut pose: Value) -> FResult<bool> {
    if pose == Value::Null {
        return Ok(true);
    }
    let p = field(&mut pose, "position", msgs::xyz)?;
    let q = field(&mut pose, "orientation", msgs::quaternion_from)?;
    Ok(p == [0.0; 3] && (q == Quaternion::identity() || q == Quaternion::new(0.0, 0.0, 0.0, 0.0)))
}

/// A typed message readable from a Foxglove protobuf schema.
pub trait FoxgloveMessage: Sized {
    /// Foxglove schema names this type reads from.
    const FOXGLOVE_NAMES: &'static [&'static str];
    fn from_foxglove(schema_name: &str, v: Value) -> FResult<Self>;
}

impl FoxgloveMessage for LaserScan {
    const FOXGLOVE_NAMES: &'static [&'static str] = &["foxglove.LaserScan"];

    /// Foxglove scans give start and end angles; the increment is their span over n − 1 beams.
    /// A scan whose origin `pose` is not the identity is refused rather than silently moved.
    fn from_foxglove(_: &str, mut v: Value) -> FResult<Self> {
        let header = header(&mut v, "frame_id")?;
        if !field(&mut v, "pose", is_identity_pose)? {
            return Err(FieldError::new(
                "scan origin is not at the frame origin; add it as a transform instead",
            )
            .within("pose"));
        }
        let start = field(&mut v, "start_angle", |x| x.as_f64())?;
        let end = field(&mut v, "end_angle", |x| x.as_f64())?;
        let ranges = field(&mut v, "ranges", Value::into_f32s)?;
        let intensities = field(&mut v, "intensities", Value::into_f32s)?;
        let n = ranges.len();
        let increment = if n > 1 {
            (end - start) / (n - 1) as f64
        } else {
            0.0
        };
        let finite_max = ranges
            .iter()
            .copied()
            .filter(|r| r.is_finite())
            .fold(0.0f32, f32::max);
        Ok(LaserScan {
            header,
            angle_min: start as f32,
            angle_max: end as f32,
            angle_increment: increment as f32,
            time_increment: 0.0,
            scan_time: 0.0,
            range_min: 0.0,
            // Foxglove scans carry no range limits; use the largest return.
            range_max: finite_max,
            ranges,
            intensities,
        })
    }
}

impl FoxgloveMessage for Image {
    const FOXGLOVE_NAMES: &'static [&'static str] = &["foxglove.RawImage"];

    fn from_foxglove(_: &str, mut v: Value) -> FResult<Self> {
        Ok(Image {
            header: header(&mut v, "frame_id")?,
            width: field(&mut v, "width", |x| x.as_u32())?,
            height: field(&mut v, "height", |x| x.as_u32())?,
            encoding: field(&mut v, "encoding", Value::into_string)?,
            is_bigendian: 0,
            step: field(&mut v, "step", |x| x.as_u32())?,
            data: field(&mut v, "data", Value::into_bytes)?,
        })
    }
}

impl FoxgloveMessage for CompressedImage {
    const FOXGLOVE_NAMES: &'static [&'static str] = &["foxglove.CompressedImage"];

    fn from_foxglove(_: &str, mut v: Value) -> FResult<Self> {
        Ok(CompressedImage {
            header: header(&mut v, "frame_id")?,
            format: field(&mut v, "format", Value::into_string)?,
            data: field(&mut v, "data", Value::into_bytes)?,
        })
    }
}

impl FoxgloveMessage for CameraInfo {
    const FOXGLOVE_NAMES: &'static [&'static str] = &["foxglove.CameraCalibration"];

    fn from_foxglove(_: &str, mut v: Value) -> FResult<Self> {
        let header = header(&mut v, "frame_id")?;
        let width = field(&mut v, "width", |x| x.as_u32())?;
        let height = field(&mut v, "height", |x| x.as_u32())?;
        Ok(CameraInfo {
            header,
            height,
            width,
            distortion_model: field(&mut v, "distortion_model", Value::into_string)?,
            d: field_any(&mut v, &["D", "d"], Value::into_f64s)?,
            k: field_any(&mut v, &["K", "k"], Value::into_f64_array)?,
            r: field_any(&mut v, &["R", "r"], Value::into_f64_array)?,
            p: field_any(&mut v, &["P", "p"], Value::into_f64_array)?,
            binning_x: 0,
            binning_y: 0,
            roi: RegionOfInterest::default(),
        })
    }
}

fn frame_transform(mut v: Value) -> FResult<TransformStamped> {
    let header = header(&mut v, "parent_frame_id")?;
    Ok(TransformStamped {
        header,
        child_frame_id: field(&mut v, "child_frame_id", Value::into_string)?,
        transform: Transform {
            translation: field(&mut v, "translation", |t| {
                if t == Value::Null {
                    Ok(Vector3::zeros())
                } else {
                    msgs::vector_from(t)
                }
            })?,
            rotation: field(&mut v, "rotation", |q| {
                if q == Value::Null {
                    Ok(Quaternion::identity())
                } else {
                    msgs::quaternion_from(q)
                }
            })?,
        },
    })
}

impl FoxgloveMessage for TfMessage {
    const FOXGLOVE_NAMES: &'static [&'static str] =
        &["foxglove.FrameTransforms", "foxglove.FrameTransform"];

    fn from_foxglove(schema_name: &str, mut v: Value) -> FResult<Self> {
        let transforms = if schema_name == "foxglove.FrameTransform" {
            vec![frame_transform(v)?]
        } else {
            field(&mut v, "transforms", |a| msgs::each(a, frame_transform))?
        };
        Ok(TfMessage { transforms })
    }
}

impl FoxgloveMessage for PoseStamped {
    const FOXGLOVE_NAMES: &'static [&'static str] = &["foxglove.PoseInFrame"];

    fn from_foxglove(_: &str, mut v: Value) -> FResult<Self> {
        Ok(PoseStamped {
            header: header(&mut v, "frame_id")?,
            pose: field(&mut v, "pose", msgs::Pose::from_value)?,
        })
    }
}

/// Types with no Foxglove schema: only their ROS 2 form is accepted.
macro_rules! ros_only {
    ($($t:ty),*) => {$(
        impl FoxgloveMessage for $t {
            const FOXGLOVE_NAMES: &'static [&'static str] = &[];
            fn from_foxglove(schema_name: &str, _: Value) -> FResult<Self> {
                Err(FieldError::new(format!("no conversion from `{schema_name}`")))
            }
        }
    )*};
}

ros_only!(
    msgs::Odometry,
    msgs::Imu,
    msgs::PoseArray,
    msgs::Detection2DArray,
    msgs::MarkerArray,
    msgs::AudioDataStamped,
    msgs::AudioInfo,
    msgs::JointState,
    TransformStamped
);
