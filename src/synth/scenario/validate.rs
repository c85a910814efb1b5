//! Range checks of a parsed scenario that types cannot express (`Scenario::validate`): each
//! names the key path of the first problem.

use super::*;

impl Scenario {
    /// Range checks that types cannot express: `(key path, reason)` of the first problem.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let bad = |k: &str, r: String| Err((k.to_string(), r));
        let m = &self.scenario;
        if !(m.duration_s > 0.0 && m.duration_s < 86_400.0) {
            return bad(
                "scenario.duration_s",
                format!("{} is not in (0, 86400)", m.duration_s),
            );
        }
        if m.sessions == 0 {
            return bad("scenario.sessions", "must be at least 1".into());
        }
        if m.first_session.saturating_add(m.sessions) > 10_000 {
            return bad(
                "scenario.first_session",
                format!(
                    "sessions {}..{} reach past 10000",
                    m.first_session,
                    u64::from(m.first_session) + u64::from(m.sessions)
                ),
            );
        }
        if !(self.world.size[0] > 0.0 && self.world.size[1] > 0.0) {
            return bad("world.size", "both extents must be positive".into());
        }
        let mut ids = std::collections::BTreeSet::new();
        for (i, p) in self.people.iter().enumerate() {
            if !ids.insert(p.id) {
                return bad(
                    &format!("people[{i}].id"),
                    format!("id {} is used twice", p.id),
                );
            }
            if !(1.0..=2.4).contains(&p.height) {
                return bad(
                    &format!("people[{i}].height"),
                    format!("{} m is not a person's height", p.height),
                );
            }
            if let Some(h) = &p.heights
                && (h.is_empty() || h.iter().any(|x| !(1.0..=2.4).contains(x)))
            {
                return bad(
                    &format!("people[{i}].heights"),
                    format!("{h:?}: give one or more heights, each in [1.0, 2.4] m"),
                );
            }
            if let Motion::Waypoints { points, speed, .. } = &p.motion
                && (points.is_empty() || !(*speed > 0.0 && *speed <= 4.0))
            {
                return bad(
                    &format!("people[{i}].motion"),
                    "needs at least one point and a speed in (0, 4] m/s".into(),
                );
            }
            if let Some(r) = jog_problem(&p.motion) {
                return bad(&format!("people[{i}].motion"), r);
            }
        }
        for (i, s) in self.sensors.iter().enumerate() {
            if !(s.rate_hz() > 0.0 && s.rate_hz() <= 1000.0) {
                return bad(
                    &format!("sensors[{i}].rate_hz"),
                    format!("{} is not in (0, 1000]", s.rate_hz()),
                );
            }
            if let SensorSpec::Laser {
                fov_deg,
                resolution_deg,
                range_min,
                range_max,
                ..
            } = s
                && !(*fov_deg > 0.0
                    && *fov_deg <= 360.0
                    && *resolution_deg > 0.0
                    && range_min < range_max)
            {
                return bad(
                    &format!("sensors[{i}]"),
                    "laser needs 0 < fov <= 360, resolution > 0, range_min < range_max".into(),
                );
            }
        }
        match self.robot.mode {
            RobotMode::Follow => {
                let Some(f) = &self.robot.follow else {
                    return bad(
                        "robot.follow",
                        "mode = \"follow\" needs a [robot.follow] table".into(),
                    );
                };
                if !self.people.iter().any(|p| p.id == f.target) {
                    return bad(
                        "robot.follow.target",
                        format!("no person with id {}", f.target),
                    );
                }
                if let Some((key, reason)) = follow_problem(f, &self.sensors) {
                    return bad(&format!("robot.follow.{key}"), reason);
                }
            }
            RobotMode::Tour => {
                if self.robot.tour.as_ref().is_none_or(|t| t.stops.is_empty()) {
                    return bad(
                        "robot.tour",
                        "mode = \"tour\" needs [robot.tour] with stops".into(),
                    );
                }
            }
            RobotMode::Static => {}
        }
        if let Some((key, reason)) = self.biron.as_ref().and_then(BironSpec::problem) {
            return bad(&format!("biron.{key}"), reason);
        }
        if let Some(v) = &self.variation
            && (v.absent[0] > v.absent[1] || v.absent[1] as usize >= self.people.len().max(1))
        {
            return bad(
                "variation.absent",
                format!(
                    "{:?} must be [least, most] with most below the {} scripted people",
                    v.absent,
                    self.people.len()
                ),
            );
        }
        if let Some(c) = &self.calibration
            && !self.people.iter().any(|p| p.id == c.person)
        {
            return bad(
                "calibration.person",
                format!("no person with id {}", c.person),
            );
        }
        Ok(())
    }
}

/// The first problem of a `jog` motion's values.
fn jog_problem(m: &Motion) -> Option<String> {
    let Motion::Jog {
        area,
        speed,
        stretch_m,
        max_turn_deg,
        lateral_accel,
        accel,
        clearance_m,
        ..
    } = m
    else {
        return None;
    };
    let ok = area[0] < area[2]
        && area[1] < area[3]
        && speed[0] > 0.0
        && speed[0] <= speed[1]
        && speed[1] <= 6.0
        && stretch_m[0] > 0.0
        && stretch_m[0] <= stretch_m[1]
        && *max_turn_deg > 0.0
        && *max_turn_deg <= 180.0
        && *lateral_accel > 0.0
        && *accel > 0.0
        && *clearance_m >= 0.0;
    (!ok).then(|| {
        "jog needs an area [x0, y0, x1, y1], 0 < speed[0] <= speed[1] <= 6 m/s, 0 < stretch_m[0] <= stretch_m[1], 0 < max_turn_deg <= 180, positive lateral_accel and accel, clearance_m >= 0".into()
    })
}
