//! Copying a session log with messages added: every metadata record, schema, channel and
//! message of the input goes to the output unchanged (same bytes, same log times, same order),
//! and the added messages — one or more new ROS 2 topics of one type, e.g. tracks as
//! `visualization_msgs/msg/MarkerArray` for Foxglove — are interleaved by log time. Written
//! through [`SessionWriter`], so the copy appears complete or not at all.
//!
//! This is how pipelines write results back into a log (`peopletrack run … --write-tracks`);
//! it does not decode the copied messages and does not change the input's topics.

use std::collections::BTreeMap;
use std::path::Path;

use super::error::{LogError, LogErrorKind};
use super::msgs::RosMessage;
use super::reader::SessionLog;
use super::writer::{ChannelId, SessionWriter, WriterOptions};
use crate::time::Nanos;

/// Copy `input` to `output` with `added` on new channels, one per entry of `topics`: each
/// added item is `(log time, index into topics, message)`, in non-decreasing log time. An
/// added message goes before the input's messages of the same log time. Returns the number of
/// messages added. Added items out of time order, or naming no topic, are an error (nothing is
/// left under `output`).
pub fn copy_with_messages<T: RosMessage>(
    input: &Path,
    output: &Path,
    topics: &[&str],
    added: impl IntoIterator<Item = (Nanos, usize, T)>,
) -> Result<usize, LogError> {
    let log = SessionLog::open(input)?;
    let mut w = SessionWriter::create(output, &WriterOptions::default())?;
    for m in &log.summary().metadata {
        w.metadata(&m.name, m.entries.clone())?;
    }
    let mut channels: BTreeMap<u16, ChannelId> = BTreeMap::new();
    for (id, ch) in &log.summary().channels {
        let schema = ch
            .schema
            .as_deref()
            .map(|s| (s.name.as_str(), s.encoding.as_str(), s.data.as_slice()));
        channels.insert(*id, w.add_raw(&ch.topic, schema, &ch.message_encoding)?);
    }
    let new: Vec<ChannelId> = topics
        .iter()
        .map(|t| w.add_ros2::<T>(t))
        .collect::<Result<_, _>>()?;
    let mut added = added.into_iter().peekable();
    let mut count = 0usize;
    let mut last = Nanos(0);
    let mut put = |w: &mut SessionWriter, (t, k, msg): (Nanos, usize, T)| {
        let bad = |why: String| LogError::new(output, LogErrorKind::Write(why));
        if t < last {
            return Err(bad(format!(
                "added messages are not in log-time order ({last} s, then {t} s)"
            )));
        }
        let ch = *new
            .get(k)
            .ok_or_else(|| bad(format!("added message names topic {k} of {}", topics.len())))?;
        last = t;
        count += 1;
        w.write(ch, t, &msg)
    };
    for m in log.messages()? {
        let m = m?;
        while let Some(item) = added.next_if(|(t, _, _)| *t <= m.log_time) {
            put(&mut w, item)?;
        }
        let ch = channels.get(&m.channel.id).ok_or_else(|| {
            LogError::new(
                input,
                LogErrorKind::Write(format!("channel {} is not in the summary", m.channel.id)),
            )
        })?;
        w.write_bytes(*ch, m.log_time, &m.data)?;
    }
    for item in added {
        put(&mut w, item)?;
    }
    w.finish()?;
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::msgs::{Header, Marker, MarkerArray};
    use crate::log::read_topic;

    fn array(id: i32) -> MarkerArray {
        MarkerArray {
            markers: vec![Marker {
                header: Header::new(Nanos(7), "laser"),
                id,
                ..Default::default()
            }],
        }
    }

    /// A two-message log copied with three markers on two topics: the original bytes and
    /// times unchanged, the markers on their topics at their times, ties before the original.
    #[test]
    fn a_copy_keeps_every_message_and_adds_the_new_ones_in_time_order() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (input, output) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
        let mut w = SessionWriter::create(&input, &WriterOptions::default()).expect("create");
        let ch = w
            .add_raw("/raw", Some(("x/Raw", "none", b"")), "bytes")
            .expect("raw");
        w.write_bytes(ch, Nanos(10), &[1, 2]).expect("m1");
        w.write_bytes(ch, Nanos(20), &[3]).expect("m2");
        w.finish().expect("finish");
        let added = vec![
            (Nanos(5), 0, array(1)),
            (Nanos(20), 1, array(2)),
            (Nanos(30), 0, array(3)),
        ];
        let n = copy_with_messages(&input, &output, &["/a", "/b"], added).expect("copy");
        assert_eq!(n, 3);
        let log = SessionLog::open(&output).expect("open copy");
        let got: Vec<(String, u64, Vec<u8>)> = log
            .messages()
            .expect("messages")
            .map(|m| {
                let m = m.expect("message");
                (m.channel.topic.clone(), m.log_time.0, m.data.to_vec())
            })
            .filter(|(t, _, _)| t == "/raw")
            .collect();
        assert_eq!(
            got,
            vec![
                ("/raw".into(), 10, vec![1, 2]),
                ("/raw".into(), 20, vec![3])
            ]
        );
        let order: Vec<(String, u64)> = log
            .messages()
            .expect("messages")
            .map(|m| {
                let m = m.expect("message");
                (m.channel.topic.clone(), m.log_time.0)
            })
            .collect();
        let want = [
            ("/a", 5),
            ("/raw", 10),
            ("/b", 20),
            ("/raw", 20),
            ("/a", 30),
        ];
        assert_eq!(order, want.map(|(t, n)| (t.to_string(), n as u64)).to_vec());
        let ids: Vec<i32> = read_topic::<MarkerArray>(&log, "/a")
            .expect("read /a")
            .map(|r| r.expect("decodes").1.markers[0].id)
            .collect();
        assert_eq!(ids, [1, 3]);
        // out of order: an error, no file left
        let bad = vec![(Nanos(9), 0, array(1)), (Nanos(8), 0, array(2))];
        let out2 = dir.path().join("bad.mcap");
        let e = copy_with_messages(&input, &out2, &["/a"], bad).expect_err("out of order");
        assert!(e.to_string().contains("not in log-time order"), "{e}");
        assert!(!out2.exists());
    }
}
