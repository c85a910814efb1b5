use super::*;

const LASER_SCAN: &str = "std_msgs/Header header\nfloat32 angle_min\nfloat32[] ranges\n\
================================================================================\n\
MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\
================================================================================\n\
MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";

#[test]
fn parses_rosbag2_layout_and_resolves_nested_types() {
    let reg = Registry::parse("sensor_msgs/msg/LaserScan", LASER_SCAN).expect("parses");
    assert_eq!(reg.defs.len(), 3);
    let root = reg.root_def();
    assert_eq!(root.name, "sensor_msgs/msg/LaserScan");
    assert_eq!(root.fields.len(), 3);
    let BaseType::Msg(h) = root.fields[0].ty else {
        panic!("header is a message")
    };
    assert_eq!(reg.defs[h].name, "std_msgs/msg/Header");
    assert_eq!(root.fields[2].array, ArrayKind::Unbounded);
    assert_eq!(root.fields[2].ty, BaseType::Prim(Prim::F32));
}

#[test]
fn parses_arrays_bounds_defaults_and_constants() {
    let text = "int8 MODE_A=1\nstring NAME = \"a # b\" # comment\nuint8[<=4] b [1, 2]\n\
                float64[3] v [0.5, -1, 2e3]\nstring<=5 s 'hi'\nbool flag true\nwstring w\nint32 x -7 # c";
    let reg = Registry::parse("p/T", text).expect("parses");
    let d = reg.root_def();
    assert_eq!(d.constants.len(), 2);
    assert_eq!(d.constants[0].value, Literal::Int(1));
    assert_eq!(d.constants[1].value, Literal::Str("a # b".into()));
    assert_eq!(d.fields[0].array, ArrayKind::Bounded(4));
    assert_eq!(
        d.fields[0].default,
        Some(Literal::Array(vec![Literal::Int(1), Literal::Int(2)]))
    );
    assert_eq!(d.fields[1].array, ArrayKind::Fixed(3));
    assert_eq!(
        d.fields[1].default,
        Some(Literal::Array(vec![
            Literal::Float(0.5),
            Literal::Float(-1.0),
            Literal::Float(2000.0)
        ]))
    );
    assert_eq!(d.fields[2].ty, BaseType::String { bound: Some(5) });
    assert_eq!(d.fields[2].default, Some(Literal::Str("hi".into())));
    assert_eq!(d.fields[3].default, Some(Literal::Bool(true)));
    assert_eq!(d.fields[4].ty, BaseType::WString { bound: None });
    assert_eq!(d.fields[5].default, Some(Literal::Int(-7)));
}

#[test]
fn bare_names_resolve_within_the_package_and_header_to_std_msgs() {
    let text =
        "Header header\nInner i\n===\nMSG: p/Inner\nint8 a\n===\nMSG: std_msgs/Header\nuint32 seq";
    let reg = Registry::parse("p/msg/Outer", text).expect("parses");
    assert_eq!(reg.defs.len(), 3);
}

fn check_err(text: &str, line: usize, needle: &str) {
    let e = Registry::parse("p/T", text).expect_err("must not parse");
    assert_eq!(e.line, line, "{e}");
    assert!(e.reason.contains(needle), "{e}");
}

#[test]
fn reports_the_line_of_each_kind_of_mistake() {
    check_err("int32 a\nflot32 b", 2, "flot32");
    check_err("int32", 1, "no name");
    check_err("int32[ a", 1, "closing");
    check_err("int32[x] a", 1, "bound");
    check_err("uint8 a 300", 1, "does not fit");
    check_err("bool b maybe", 1, "not a bool");
    check_err("float64[2] v [1]", 1, "elements");
    check_err("string s \"open", 1, "unterminated");
    check_err("int32 9a", 1, "valid");
    check_err("int8 a\n===\nNOPE", 3, "MSG:");
}

#[test]
fn rejects_recursive_types() {
    let e = Registry::parse("p/T", "p/T self").expect_err("recursive");
    assert!(e.reason.contains("itself"));
}
