//! Canonical ROS 2 message definitions (Humble/Jazzy `common_interfaces`, `vision_msgs` 4.x;
//! `visualization_msgs/Marker` in its Humble layout; files carry the text, so any reader decodes it)
//! for the types peopletrack writes, and the rosbag2-style full schema text built from them:
//! the type's own definition followed by each dependency, depth first in order of first use,
//! each after a line of 80 `=` and `MSG: pkg/Type` — the layout `ros2 bag record` and
//! `mcap-ros2-support` use.
//!
//! Comments are left out of the texts; field order, types and defaults are those of the
//! upstream `.msg` files.

use super::ros2msg::{BaseType, Registry};

/// `(full type name, own definition)` for every type we can write.
const DEFINITIONS: &[(&str, &str)] = &[
    ("builtin_interfaces/msg/Time", "int32 sec\nuint32 nanosec\n"),
    (
        "builtin_interfaces/msg/Duration",
        "int32 sec\nuint32 nanosec\n",
    ),
    (
        "std_msgs/msg/Header",
        "builtin_interfaces/Time stamp\nstring frame_id\n",
    ),
    ("std_msgs/msg/String", "string data\n"),
    (
        "geometry_msgs/msg/Point",
        "float64 x\nfloat64 y\nfloat64 z\n",
    ),
    (
        "geometry_msgs/msg/Vector3",
        "float64 x\nfloat64 y\nfloat64 z\n",
    ),
    (
        "geometry_msgs/msg/Quaternion",
        "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    ),
    (
        "geometry_msgs/msg/Pose",
        "Point position\nQuaternion orientation\n",
    ),
    (
        "geometry_msgs/msg/PoseWithCovariance",
        "Pose pose\nfloat64[36] covariance\n",
    ),
    (
        "geometry_msgs/msg/Twist",
        "Vector3 linear\nVector3 angular\n",
    ),
    (
        "geometry_msgs/msg/TwistWithCovariance",
        "Twist twist\nfloat64[36] covariance\n",
    ),
    (
        "geometry_msgs/msg/Transform",
        "Vector3 translation\nQuaternion rotation\n",
    ),
    (
        "geometry_msgs/msg/TransformStamped",
        "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
    ),
    (
        "geometry_msgs/msg/PoseStamped",
        "std_msgs/Header header\nPose pose\n",
    ),
    (
        "geometry_msgs/msg/PoseArray",
        "std_msgs/Header header\nPose[] poses\n",
    ),
    (
        "tf2_msgs/msg/TFMessage",
        "geometry_msgs/TransformStamped[] transforms\n",
    ),
    (
        "nav_msgs/msg/Odometry",
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n\
         geometry_msgs/TwistWithCovariance twist\n",
    ),
    (
        "sensor_msgs/msg/LaserScan",
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n\
         float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n\
         float32[] ranges\nfloat32[] intensities\n",
    ),
    (
        "sensor_msgs/msg/Image",
        "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n\
         uint32 step\nuint8[] data\n",
    ),
    (
        "sensor_msgs/msg/CompressedImage",
        "std_msgs/Header header\nstring format\nuint8[] data\n",
    ),
    (
        "sensor_msgs/msg/RegionOfInterest",
        "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n",
    ),
    (
        "sensor_msgs/msg/CameraInfo",
        "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\n\
         float64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\n\
         RegionOfInterest roi\n",
    ),
    (
        "sensor_msgs/msg/Imu",
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n\
         geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n\
         geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
    ),
    ("vision_msgs/msg/Point2D", "float64 x\nfloat64 y\n"),
    (
        "vision_msgs/msg/Pose2D",
        "vision_msgs/Point2D position\nfloat64 theta\n",
    ),
    (
        "vision_msgs/msg/BoundingBox2D",
        "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y\n",
    ),
    (
        "vision_msgs/msg/ObjectHypothesis",
        "string class_id\nfloat64 score\n",
    ),
    (
        "vision_msgs/msg/ObjectHypothesisWithPose",
        "ObjectHypothesis hypothesis\ngeometry_msgs/PoseWithCovariance pose\n",
    ),
    (
        "vision_msgs/msg/Detection2D",
        "std_msgs/Header header\nObjectHypothesisWithPose[] results\nBoundingBox2D bbox\nstring id\n",
    ),
    (
        "vision_msgs/msg/Detection2DArray",
        "std_msgs/Header header\nDetection2D[] detections\n",
    ),
    (
        "std_msgs/msg/ColorRGBA",
        "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    ),
    (
        "visualization_msgs/msg/Marker",
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
         int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
         int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\n\
         int32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\n\
         int32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\n\
         std_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\n\
         geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring text\n\
         string mesh_resource\nbool mesh_use_embedded_materials\n",
    ),
    ("visualization_msgs/msg/MarkerArray", "Marker[] markers\n"),
    // ros-drivers `audio_common` (the `audio_capture` layout; not the incompatible package of
    // the same name whose AudioData holds one array per sample type)
    ("audio_common_msgs/msg/AudioData", "uint8[] data\n"),
    (
        "audio_common_msgs/msg/AudioDataStamped",
        "std_msgs/Header header\naudio_common_msgs/AudioData audio\n",
    ),
    (
        "audio_common_msgs/msg/AudioInfo",
        "uint8 channels\nuint32 sample_rate\nstring sample_format\nuint32 bitrate\n\
         string coding_format\n",
    ),
    (
        "sensor_msgs/msg/JointState",
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n\
         float64[] effort\n",
    ),
];

const SEPARATOR: &str =
    "================================================================================";

fn own_text(name: &str) -> Option<&'static str> {
    DEFINITIONS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
}

/// Names of the types a definition refers to, in order of first use, resolved as the parser
/// resolves them (bare names within the package).
fn direct_dependencies(name: &str, text: &str) -> Vec<String> {
    let pkg = name.split('/').next().unwrap_or_default();
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(ty) = line.split_whitespace().next() else {
            continue;
        };
        let elem = ty.split('[').next().unwrap_or(ty);
        if super::ros2msg::is_primitive_or_string(elem) {
            continue;
        }
        let full = match elem.split('/').collect::<Vec<_>>().as_slice() {
            [p, t] => format!("{p}/msg/{t}"),
            [t] => format!("{pkg}/msg/{t}"),
            _ => elem.to_string(),
        };
        if !out.contains(&full) {
            out.push(full);
        }
    }
    out
}

/// The full `ros2msg` schema text of `name` (`pkg/msg/Type`), or `None` if we have no
/// definition for it or one of its dependencies.
pub fn full_definition(name: &str) -> Option<String> {
    let mut order: Vec<String> = Vec::new();
    fn visit(name: &str, order: &mut Vec<String>, is_root: bool) -> Option<()> {
        let text = own_text(name)?;
        if !is_root {
            if order.iter().any(|n| n == name) {
                return Some(());
            }
            order.push(name.to_string());
        }
        for dep in direct_dependencies(name, text) {
            visit(&dep, order, false)?;
        }
        Some(())
    }
    visit(name, &mut order, true)?;
    let mut text = own_text(name)?.to_string();
    for dep in &order {
        let short = dep.replacen("/msg/", "/", 1);
        text.push_str(SEPARATOR);
        text.push_str("\nMSG: ");
        text.push_str(&short);
        text.push('\n');
        text.push_str(own_text(dep)?);
    }
    Some(text)
}

/// The parsed registry of a type we can write.
pub fn registry(name: &str) -> Option<Registry> {
    let text = full_definition(name)?;
    Registry::parse(name, &text).ok()
}

/// True if the registry's root type has the same wire layout (field names, types, arrays,
/// recursively) as our canonical definition of the same name.
pub fn same_layout(a: &Registry, ai: usize, b: &Registry, bi: usize) -> bool {
    let (da, db) = (&a.defs[ai], &b.defs[bi]);
    da.fields.len() == db.fields.len()
        && da.fields.iter().zip(&db.fields).all(|(fa, fb)| {
            fa.name == fb.name
                && fa.array == fb.array
                && match (&fa.ty, &fb.ty) {
                    (BaseType::Msg(x), BaseType::Msg(y)) => same_layout(a, *x, b, *y),
                    (x, y) => x == y,
                }
        })
}

/// All type names with canonical definitions.
pub fn known_types() -> impl Iterator<Item = &'static str> {
    DEFINITIONS.iter().map(|(n, _)| *n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_definition_parses_with_its_dependencies() {
        for name in known_types() {
            let text =
                full_definition(name).unwrap_or_else(|| panic!("{name} has a full definition"));
            Registry::parse(name, &text).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    #[test]
    fn layout_matches_what_rosbags_wrote_for_tf() {
        // The TFMessage schema text as rosbags 0.11.9 wrote it into the real logs.
        let real = "geometry_msgs/TransformStamped[] transforms\n\
================================================================================\nMSG: geometry_msgs/TransformStamped\n\
std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n\
================================================================================\nMSG: std_msgs/Header\n\
builtin_interfaces/Time stamp\nstring frame_id\n\
================================================================================\nMSG: builtin_interfaces/Time\n\
int32 sec\nuint32 nanosec\n\
================================================================================\nMSG: geometry_msgs/Transform\n\
geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n\
================================================================================\nMSG: geometry_msgs/Vector3\n\
float64 x\nfloat64 y\nfloat64 z\n\
================================================================================\nMSG: geometry_msgs/Quaternion\n\
float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";
        let theirs = Registry::parse("tf2_msgs/msg/TFMessage", real).expect("parses");
        let ours = registry("tf2_msgs/msg/TFMessage").expect("known");
        assert!(same_layout(&theirs, theirs.root, &ours, ours.root));
        // and the dependency order is the same as rosbags' (depth first, first use)
        let text = full_definition("tf2_msgs/msg/TFMessage").expect("known");
        let msgs: Vec<&str> = text.lines().filter(|l| l.starts_with("MSG: ")).collect();
        let real_msgs: Vec<&str> = real.lines().filter(|l| l.starts_with("MSG: ")).collect();
        assert_eq!(msgs, real_msgs);
    }
}
