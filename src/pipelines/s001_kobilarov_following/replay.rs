//! The methods replayed on a log, open loop, one scan at a time: `laser::follow`'s follower
//! in each configuration, and the laser issue's multi-person tracker (`laser::tracker`, at its
//! defaults, leg model of seed 002) reduced to one target: the confirmed track nearest the
//! target's initial point is followed; when it ends, the confirmed track nearest its last
//! position within the follower's re-initialisation radius takes over.

use nalgebra::{Isometry3, Point2};

use super::params::{Method, Params};
use crate::laser::follow::{FollowTracker, OmniFrame, ScanObs, StepOutput};
use crate::laser::legs::{self, LegParams};
use crate::laser::points::ScanPoint;
use crate::laser::segment::{self, SegmentOptions};
use crate::laser::tracker::{PeopleTracker, TrackerParams};

/// One method's state over a session.
pub enum Runner {
    Follower(Box<FollowTracker>),
    Laser(Box<LaserSelect>),
}

/// The multi-person tracker and the track it follows.
pub struct LaserSelect {
    tracker: PeopleTracker,
    anchor: [f64; 2],
    id: Option<u64>,
    radius: f64,
}

impl Runner {
    pub fn new(method: Method, p: &Params, init: [f64; 2]) -> Runner {
        match method {
            Method::Follower(v) => {
                let mut fp = p.follower.params(v.model, v.association, v.colour);
                if v.update {
                    fp.template_update = p.template_update;
                }
                if v.printed {
                    fp.corr_form = crate::vision::cylinder::CorrForm::Printed;
                }
                if v.literal_rst {
                    fp.filter.reset_sigmas = crate::track::pdaf::RESET_SIGMAS_LITERAL;
                }
                if v.colour_watch {
                    fp.colour_watch_s = Some(p.colour_watch_s);
                }
                if v.ground {
                    fp.ground_below_m = Some(super::params::GROUND_BELOW_M);
                }
                if v.others {
                    fp.others = Some(crate::laser::follow::others::OthersParams::default());
                }
                Runner::Follower(Box::new(FollowTracker::new(&fp, init)))
            }
            Method::LaserTracker => Runner::Laser(Box::new(LaserSelect {
                tracker: PeopleTracker::new(TrackerParams::default()),
                anchor: init,
                id: None,
                radius: p.follower.reinit_radius_m,
            })),
        }
    }

    /// One scan. `beams` is the scan's beam count and `pose` the fixed-from-laser pose the
    /// points were placed with (the leg model needs both).
    pub fn step(
        &mut self,
        obs: &ScanObs<'_>,
        beams: usize,
        pose: Option<&Isometry3<f64>>,
    ) -> anyhow::Result<StepOutput> {
        match self {
            Runner::Follower(f) => Ok(f.step(obs)?),
            Runner::Laser(l) => Ok(l.step(obs.t, obs.points, beams, pose)),
        }
    }
}

impl LaserSelect {
    fn step(
        &mut self,
        t: f64,
        points: &[ScanPoint],
        beams: usize,
        pose: Option<&Isometry3<f64>>,
    ) -> StepOutput {
        let segs = segment::segment(points, &SegmentOptions::default());
        let d = legs::detect(points, &segs, beams, pose, &LegParams::default());
        let people: Vec<Point2<f64>> = d.people.iter().map(|p| p.fixed).collect();
        let single: Vec<Point2<f64>> = d
            .single_legs
            .iter()
            .filter_map(|&i| d.legs.get(i).map(|l| l.fixed))
            .collect();
        self.tracker.step(t, &people, &single);
        let mut out = StepOutput::empty(people.len());
        let current = self
            .id
            .and_then(|id| self.tracker.confirmed().find(|tr| tr.id == id));
        let track = match current {
            Some(tr) => Some(tr),
            None => {
                let a = Point2::new(self.anchor[0], self.anchor[1]);
                let pick = self
                    .tracker
                    .confirmed()
                    .filter(|tr| (tr.position() - a).norm() <= self.radius)
                    .min_by(|x, y| {
                        (x.position() - a)
                            .norm()
                            .total_cmp(&(y.position() - a).norm())
                    });
                if pick.is_some() {
                    out.initialised = true;
                } else if self.id.is_some() {
                    out.reset = true;
                }
                self.id = pick.map(|tr| tr.id);
                pick
            }
        };
        if let Some(tr) = track {
            let p = tr.position();
            let v = tr.velocity();
            let c = tr.filter.p;
            self.anchor = [p.x, p.y];
            let cov = [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]];
            out.estimate = Some(crate::laser::follow::Estimate {
                position: [p.x, p.y],
                velocity: [v.x, v.y],
                covariance: cov,
                covariance_norm: largest_sd(&cov),
                turn_rate: 0.0,
                modes: None,
            });
        }
        out
    }
}

/// √ of the largest eigenvalue of a symmetric 2×2 matrix.
pub fn largest_sd(c: &[[f64; 2]; 2]) -> f64 {
    let (a, b, d) = (c[0][0], c[0][1], c[1][1]);
    let m = 0.5 * (a + d);
    let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    (m + r).max(0.0).sqrt()
}

/// An omni frame for the follower, or none.
pub fn omni<'a>(
    image: Option<&'a image::RgbImage>,
    camera_from_fixed: Option<Isometry3<f64>>,
    model: Option<&'a crate::geometry::camera::Paracatadioptric>,
) -> Option<OmniFrame<'a>> {
    Some(OmniFrame {
        image: image?,
        camera_from_fixed: camera_from_fixed?,
        model: model?,
    })
}
