//! The paper's estimator in the closed loop: [`crate::laser::follow::FollowTracker`] in its
//! paper configuration (coordinated-turn PDAF with the colour likelihood), fed the scan placed
//! with the robot's odometry pose and the latest omni frame. A filter error (a non-finite
//! input) drops the track as `rst` does: the robot stops and the tracker re-initialises.

use super::{Estimate, Follower, FollowerOutput, ScanInput};
use crate::geometry::camera::CameraModel;
use crate::laser::follow::{FollowSpec, FollowTracker, OmniFrame, ScanObs};
use crate::laser::points;
use crate::track::pdaf::{AssociationKind, ModelKind};

/// The paper's follower behind the closed loop's interface.
pub struct PdafFollower {
    tracker: FollowTracker,
}

impl PdafFollower {
    pub fn new(spec: &FollowSpec, init: [f64; 2]) -> PdafFollower {
        PdafFollower {
            tracker: FollowTracker::new(
                &spec.params(ModelKind::Ct, AssociationKind::Pdaf, true),
                init,
            ),
        }
    }
}

impl Follower for PdafFollower {
    fn on_scan(&mut self, input: &ScanInput<'_>) -> FollowerOutput {
        let pts = points::project(input.ranges, &input.geometry, Some(&input.laser_pose));
        let omni = input.omni.as_ref().and_then(|o| match o.model {
            CameraModel::Paracatadioptric(m) => Some(OmniFrame {
                image: o.image,
                camera_from_fixed: o.camera_pose.inverse(),
                model: m,
            }),
            _ => None,
        });
        let obs = ScanObs {
            t: input.t,
            points: &pts,
            omni,
            laser_pose: Some(&input.laser_pose),
        };
        match self.tracker.step(&obs) {
            Ok(out) => FollowerOutput {
                estimate: out.estimate.map(|e| Estimate {
                    position: e.position,
                    velocity: e.velocity,
                    covariance: e.covariance,
                }),
                reset: out.reset,
                look_at: out.look_at,
            },
            Err(_) => {
                self.tracker.drop_track(input.t);
                FollowerOutput {
                    estimate: None,
                    reset: true,
                    look_at: None,
                }
            }
        }
    }
}
