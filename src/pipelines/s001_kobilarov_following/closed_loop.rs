//! The closed loop's own tracker output, as the robot logged it on `/follower/state`
//! (`peopletrack.FollowerState`, odometry frame), moved into `map` through TF: the estimates
//! that actually drove the robot (figs. 4, 5 and 7 and the `rst` events come from these, not
//! from a replay). A log without the topic (an open-loop log) gives no rows.

use nalgebra::{Point3, Vector3};

use super::replay::largest_sd;
use super::tables::LoopRow;
use crate::groundtruth::FollowerState;
use crate::log::{SessionLog, TfBuffer};
use crate::time::Nanos;

/// Every logged state, in log order; `t0` is the session's first scan stamp.
pub fn rows(
    tf: &TfBuffer,
    log: &SessionLog,
    topic: &str,
    t0: Nanos,
) -> anyhow::Result<Vec<LoopRow>> {
    let mut out = Vec::new();
    if log.summary().channel(topic).is_none() {
        return Ok(out);
    }
    for m in log.messages_on(&[topic])? {
        let m = m?;
        let st: FollowerState = serde_json::from_slice(&m.data).map_err(|e| {
            anyhow::anyhow!(
                "{}: {topic} at log time {} ns: {e}",
                log.path().display(),
                m.log_time.0
            )
        })?;
        let at = Nanos(st.stamp_ns);
        let map_from_odom = tf.lookup("map", &st.frame_id, at).ok();
        let pos = st
            .position
            .zip(map_from_odom)
            .map(|(q, m)| m * Point3::new(q[0], q[1], 0.0));
        let vel = st
            .velocity
            .zip(map_from_odom)
            .map(|(v, m)| m.rotation * Vector3::new(v[0], v[1], 0.0));
        out.push(LoopRow {
            t_s: (st.stamp_ns as f64 - t0.0 as f64) * 1e-9,
            x: pos.map(|q| q.x),
            y: pos.map(|q| q.y),
            vx: vel.map(|v| v.x),
            vy: vel.map(|v| v.y),
            cov_norm: st.covariance.as_ref().map(largest_sd),
            reset: st.reset,
            controller: st.controller.clone(),
            cmd_v: st.command_v,
            cmd_w: st.command_w,
            desired_m: st.desired_distance,
            avoided: st.avoided,
            contact: st.contact,
        });
    }
    Ok(out)
}
