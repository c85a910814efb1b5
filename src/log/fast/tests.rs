use super::super::cdr;
use super::super::msgs::RosMessage;
use super::*;
use crate::log::cdr::CdrErrorKind;
use nalgebra::Vector3;
use std::borrow::Cow;

/// A CDR writer for hand-made payloads: byte order and maximum alignment chosen by the test
/// (8 = XCDR1, 4 = plain XCDR2).
struct W {
    buf: Vec<u8>,
    big: bool,
    max_align: usize,
}

impl W {
    fn new(big: bool, max_align: usize) -> W {
        let id: u16 = match (big, max_align) {
            (true, 8) => 0x0000,
            (false, 8) => 0x0001,
            (true, _) => 0x0006,
            (false, _) => 0x0007,
        };
        let mut buf = id.to_be_bytes().to_vec();
        buf.extend([0, 0]);
        W {
            buf,
            big,
            max_align,
        }
    }
    fn align(&mut self, n: usize) {
        let a = n.min(self.max_align);
        while !(self.buf.len() - 4).is_multiple_of(a) {
            self.buf.push(0xAA); // padding bytes are not read
        }
    }
    fn raw(&mut self, le: &[u8]) {
        self.align(le.len());
        if self.big {
            self.buf.extend(le.iter().rev());
        } else {
            self.buf.extend(le);
        }
    }
    fn u8(&mut self, x: u8) -> &mut Self {
        self.buf.push(x);
        self
    }
    fn u32(&mut self, x: u32) -> &mut Self {
        self.raw(&x.to_le_bytes());
        self
    }
    fn i32(&mut self, x: i32) -> &mut Self {
        self.raw(&x.to_le_bytes());
        self
    }
    fn f32(&mut self, x: f32) -> &mut Self {
        self.raw(&x.to_le_bytes());
        self
    }
    fn f64(&mut self, x: f64) -> &mut Self {
        self.raw(&x.to_le_bytes());
        self
    }
    fn f64s(&mut self, xs: &[f64]) -> &mut Self {
        for x in xs {
            self.f64(*x);
        }
        self
    }
    fn str(&mut self, s: &[u8]) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend(s);
        self.buf.push(0);
        self
    }
    fn header(&mut self, sec: i32, nanosec: u32, frame: &[u8]) -> &mut Self {
        self.i32(sec).u32(nanosec).str(frame)
    }
}

fn generic<T: RosMessage>(data: &[u8]) -> std::result::Result<T, String> {
    let reg = definitions::registry(T::TYPE_NAME).expect("canonical definition");
    let v = cdr::decode(&reg, data).map_err(|e| e.to_string())?;
    T::from_value(v).map_err(|e| e.to_string())
}

/// The fast path equals the dynamic decoder on `data`, and every shorter prefix is an error
/// for both (never a panic).
fn agrees<T: RosMessage + FastCdr + Default + PartialEq + std::fmt::Debug>(data: &[u8]) -> T {
    let fast: T = decode(data).expect("fast path decodes");
    assert_eq!(
        Ok(&fast),
        generic::<T>(data).as_ref(),
        "fast path = dynamic decoder"
    );
    for cut in 0..data.len() {
        assert!(decode::<T>(&data[..cut]).is_err(), "prefix of {cut} bytes");
        assert!(generic::<T>(&data[..cut]).is_err(), "prefix of {cut} bytes");
    }
    fast
}

const ENCODINGS: [(bool, usize); 4] = [(false, 8), (true, 8), (false, 4), (true, 4)];

#[test]
fn every_kind_has_a_canonical_layout() {
    for kind in ALL_KINDS {
        let name = kind.type_name();
        let reg = definitions::registry(name).expect("canonical definition");
        assert_eq!(FastKind::for_registry(&reg), Some(kind), "{name}");
    }
}

#[test]
fn a_different_layout_of_the_same_name_takes_the_dynamic_path() {
    // an extra field at the end: same type name, other wire layout
    let text = definitions::full_definition("sensor_msgs/msg/CompressedImage")
        .expect("known")
        .replacen("uint8[] data", "uint8[] data\nuint32 extra", 1);
    let reg = Registry::parse("sensor_msgs/msg/CompressedImage", &text).expect("parses");
    assert_eq!(FastKind::for_registry(&reg), None);
    let other = definitions::registry("geometry_msgs/msg/PoseStamped").expect("known");
    assert_eq!(FastKind::for_registry(&other), None);
}

#[test]
fn tf_known_answer_in_every_byte_order_and_alignment() {
    for (big, a) in ENCODINGS {
        let mut w = W::new(big, a);
        w.u32(2);
        // child frame names of 5 bytes + NUL put the first float64 at 4 mod 8: XCDR1 pads to
        // 8, XCDR2 does not
        w.header(7, 9, b"odom").str(b"base1");
        w.f64s(&[1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0]);
        w.header(-1, 5, b"").str(b"laser");
        w.f64s(&[-0.5, 0.25, 1e-300, 0.5, 0.5, 0.5, 0.5]);
        let tf: TfMessage = agrees(&w.buf);
        assert_eq!(tf.transforms.len(), 2);
        let t = &tf.transforms[0];
        assert_eq!((t.header.stamp.sec, t.header.stamp.nanosec), (7, 9));
        assert_eq!(
            (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
            ("odom", "base1")
        );
        assert_eq!(t.transform.translation, Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(t.transform.rotation.w, 1.0);
        assert_eq!(tf.transforms[1].header.stamp.sec, -1);
        assert_eq!(tf.transforms[1].transform.translation.z, 1e-300);
    }
}

#[test]
fn odometry_and_imu_agree_with_the_dynamic_decoder() {
    let cov: Vec<f64> = (0..36).map(|i| i as f64 * 0.5 - 3.0).collect();
    for (big, a) in ENCODINGS {
        let mut w = W::new(big, a);
        w.header(1, 2, b"odom").str(b"base_link");
        w.f64s(&[1.0, 2.0, 3.0, 0.1, 0.2, 0.3, 0.9]).f64s(&cov);
        w.f64s(&[4.0, 5.0, 6.0, -1.0, -2.0, -3.0]).f64s(&cov);
        let o: Odometry = agrees(&w.buf);
        assert_eq!(o.pose.orientation.w, 0.9);
        assert_eq!(o.twist_covariance[35], 14.5);
        assert_eq!(o.angular.z, -3.0);

        let mut w = W::new(big, a);
        w.header(3, 4, b"imu");
        w.f64s(&[0.0, 0.0, 0.6, 0.8]).f64s(&cov[..9]);
        w.f64s(&[0.1, 0.2, 0.3]).f64s(&cov[9..18]);
        w.f64s(&[9.0, 8.0, 7.0]).f64s(&cov[18..27]);
        let imu: Imu = agrees(&w.buf);
        assert_eq!(imu.orientation.w, 0.8);
        assert_eq!(imu.linear_acceleration.x, 9.0);
        assert_eq!(imu.linear_acceleration_covariance[8], cov[26]);
    }
}

#[test]
fn laser_scan_keeps_no_return_markers() {
    for (big, a) in ENCODINGS {
        let mut w = W::new(big, a);
        w.header(5, 6, b"laser");
        for x in [-1.5f32, 1.5, 0.25, 0.0, 0.1, 0.05, 30.0] {
            w.f32(x);
        }
        let ranges = [1.0f32, f32::INFINITY, 0.0, 2.5];
        w.u32(4);
        for r in ranges {
            w.f32(r);
        }
        w.u32(0);
        let s: LaserScan = agrees(&w.buf);
        assert_eq!(s.ranges, ranges);
        assert!(s.intensities.is_empty());
        assert_eq!((s.angle_min, s.range_max), (-1.5, 30.0));
    }
    // NaN is not equal to itself: compare bits
    let mut w = W::new(false, 8);
    w.header(0, 0, b"");
    for _ in 0..7 {
        w.f32(0.0);
    }
    w.u32(1).f32(f32::NAN).u32(1).f32(-0.0);
    let s: LaserScan = decode(&w.buf).expect("decodes");
    assert!(s.ranges[0].is_nan());
    assert_eq!(s.intensities[0].to_bits(), (-0.0f32).to_bits());
}

#[test]
fn camera_info_with_empty_and_full_distortion() {
    for (big, a) in ENCODINGS {
        for d in [&[][..], &[0.1, -0.2, 0.0, 0.0, 0.05][..]] {
            let mut w = W::new(big, a);
            w.header(1, 0, b"cam").u32(480).u32(640).str(b"plumb_bob");
            w.u32(d.len() as u32).f64s(d);
            w.f64s(&[500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0]);
            w.f64s(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
            w.f64s(&[
                500.0, 0.0, 320.0, 0.0, 0.0, 500.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0,
            ]);
            w.u32(2).u32(3).u32(10).u32(20).u32(100).u32(200).u8(1);
            let ci: CameraInfo = agrees(&w.buf);
            assert_eq!(ci.d, d);
            assert_eq!((ci.k[2], ci.p[6], ci.binning_y), (320.0, 240.0, 3));
            assert!(ci.roi.do_rectify);
            assert_eq!(ci.roi.width, 200);
        }
    }
}

#[test]
fn images_borrow_their_pixels_from_the_payload() {
    for (big, a) in ENCODINGS {
        let mut w = W::new(big, a);
        w.header(8, 9, b"cam_0")
            .u32(2)
            .u32(3)
            .str(b"rgb8")
            .u8(0)
            .u32(9);
        w.u32(18);
        w.buf.extend(0..18u8);
        let owned: Image = agrees(&w.buf);
        let view = ImageRef::decode(&w.buf).expect("decodes");
        assert_eq!(view.to_owned(), owned);
        assert_eq!(view.data, &(0..18u8).collect::<Vec<_>>()[..]);
        // the pixels are the payload's own bytes, not a copy
        let at = w.buf.len() - 18;
        assert!(std::ptr::eq(view.data.as_ptr(), w.buf[at..].as_ptr()));

        let mut w = W::new(big, a);
        w.header(1, 2, b"cam_0").str(b"jpeg").u32(3);
        w.buf.extend([0xff, 0xd8, 0xff]);
        let owned: CompressedImage = agrees(&w.buf);
        let view = CompressedImageRef::decode(&w.buf).expect("decodes");
        assert_eq!(view.to_owned(), owned);
        assert_eq!(view.format, "jpeg");
        assert!(matches!(view.header.frame_id, Cow::Borrowed("cam_0")));
    }
}

#[test]
fn invalid_utf8_and_missing_nul_read_as_the_dynamic_decoder_reads_them() {
    let mut w = W::new(false, 8);
    w.i32(1).u32(2).u32(3);
    w.buf.extend([b'a', 0xff, b'b']); // no NUL, one invalid byte
    w.str(b"jpeg").u32(0);
    let c: CompressedImage = agrees(&w.buf);
    assert_eq!(c.header.frame_id, "a\u{fffd}b");
}

#[test]
fn hostile_lengths_are_errors_before_any_allocation() {
    let mut w = W::new(false, 8);
    w.u32(u32::MAX); // transforms
    assert!(matches!(
        decode::<TfMessage>(&w.buf).map_err(|e| e.kind),
        Err(CdrErrorKind::LengthTooLarge { .. })
    ));
    let mut w = W::new(true, 4);
    w.header(0, 0, b"").str(b"x").u32(1 << 30);
    let e = decode::<CompressedImage>(&w.buf).expect_err("too long");
    assert_eq!(e.path, "data");
    assert!(
        Cursor::new(&[0x00, 0x02, 0, 0]).is_err(),
        "parameter list refused"
    );
}

#[test]
fn reused_buffers_give_the_same_message_as_a_fresh_decode() {
    let mut big = W::new(false, 8);
    big.u32(3);
    for i in 0..3 {
        big.header(i, 0, b"a_long_frame_name").str(b"child");
        big.f64s(&[f64::from(i); 7]);
    }
    let mut small = W::new(false, 8);
    small.u32(1).header(9, 9, b"b").str(b"c").f64s(&[2.0; 7]);
    let mut reused = TfMessage::default();
    decode_into(&big.buf, &mut reused).expect("decodes");
    decode_into(&small.buf, &mut reused).expect("decodes");
    assert_eq!(reused, decode::<TfMessage>(&small.buf).expect("decodes"));
}

#[test]
fn scratch_tf_buffers_per_count_give_each_message_as_a_fresh_decode() {
    // sets of 3 and 1 transforms interleaved; a set of 3 with other names (one of them
    // invalid UTF-8, one the very text its lossy reading gives) shares the 3-buffer
    let tf = |names: &[&[u8]]| {
        let mut w = W::new(false, 8);
        w.u32(names.len() as u32);
        for (i, name) in names.iter().enumerate() {
            w.header(i as i32, 7, name).str(b"child");
            w.f64s(&[i as f64 + 0.5; 7]);
        }
        w.buf
    };
    let three = tf(&[b"odom", b"base_link", b"laser"]);
    let one = tf(&[b"map"]);
    let other = tf(&[b"odom", &[b'a', 0xff, b'b'], "a\u{fffd}b".as_bytes()]);
    let lossy = tf(&[b"odom", "a\u{fffd}b".as_bytes(), &[b'a', 0xff, b'b']]);
    let mut scratch = Scratch::default();
    for data in [&three, &one, &three, &other, &lossy, &one, &three, &lossy] {
        let want = decode::<TfMessage>(data).expect("decodes");
        match scratch.decode(FastKind::Tf, data).expect("decodes") {
            Decoded::Tf(got) => assert_eq!(got, &want),
            d => panic!("{d:?}"),
        }
    }
    assert_eq!(scratch.tf.len(), 2, "one buffer per transform count");
    let short = &three[..three.len() - 1];
    assert!(scratch.decode(FastKind::Tf, short).is_err());
    assert!(scratch.decode(FastKind::Tf, &three[..2]).is_err());
}

#[test]
fn decode_as_gives_only_the_kinds_own_type() {
    let mut w = W::new(false, 8);
    w.header(1, 2, b"cam").str(b"png").u32(1).u8(9);
    let c = decode_as::<CompressedImage>(FastKind::CompressedImage, &w.buf)
        .expect("its own type")
        .expect("decodes");
    assert_eq!(c.data, [9]);
    assert!(decode_as::<Image>(FastKind::CompressedImage, &w.buf).is_none());
    assert!(decode_as::<String>(FastKind::Tf, &w.buf).is_none());
}
