//! `sensor_msgs/CameraInfo` ↔ the camera models of [`crate::geometry::camera`]: pinhole uses
//! `plumb_bob`; the omni models use `distortion_model` `paracatadioptric` and `conical_mirror`
//! with their parameters in `D`.

use crate::geometry::camera::{CameraError, CameraModel, ConicalMirror, Paracatadioptric, Pinhole};

use super::msgs::{CameraInfo, Header};

impl CameraInfo {
    /// The `CameraInfo` that describes a camera model.
    pub fn from_model(model: &CameraModel, header: Header) -> CameraInfo {
        let (width, height) = model.size();
        let (model, d, (fx, fy, cx, cy)) = match model {
            CameraModel::Pinhole(c) => ("plumb_bob", c.dist.to_vec(), (c.fx, c.fy, c.cx, c.cy)),
            CameraModel::Paracatadioptric(c) => (
                "paracatadioptric",
                vec![c.xc, c.yc, c.f, c.r_min, c.r_max],
                (c.f, c.f, c.xc, c.yc),
            ),
            CameraModel::ConicalMirror(c) => (
                "conical_mirror",
                vec![c.xc, c.yc, c.f, c.d, c.alpha, c.z_top],
                (c.f, c.f, c.xc, c.yc),
            ),
        };
        CameraInfo {
            header,
            height,
            width,
            distortion_model: model.to_string(),
            d,
            k: [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0],
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
            ..Default::default()
        }
    }

    /// The camera model this `CameraInfo` describes.
    pub fn model(&self) -> Result<CameraModel, CameraError> {
        let info = self;
        let need = |n: usize| {
            if info.d.len() < n {
                Err(CameraError::Coefficients {
                    model: info.distortion_model.clone(),
                    need: n,
                    have: info.d.len(),
                })
            } else {
                Ok(())
            }
        };
        if info.width == 0 || info.height == 0 || info.k[0] == 0.0 {
            return Err(CameraError::Degenerate);
        }
        let (width, height) = (info.width, info.height);
        match info.distortion_model.as_str() {
            "plumb_bob" | "" => {
                let mut dist = [0.0; 5];
                for (slot, v) in dist.iter_mut().zip(&info.d) {
                    *slot = *v;
                }
                Ok(CameraModel::Pinhole(Pinhole {
                    width,
                    height,
                    fx: info.k[0],
                    fy: info.k[4],
                    cx: info.k[2],
                    cy: info.k[5],
                    dist,
                }))
            }
            "paracatadioptric" => {
                need(3)?;
                Ok(CameraModel::Paracatadioptric(Paracatadioptric {
                    width,
                    height,
                    xc: info.d[0],
                    yc: info.d[1],
                    f: info.d[2],
                    r_min: info.d.get(3).copied().unwrap_or(0.0),
                    r_max: info.d.get(4).copied().unwrap_or(f64::INFINITY),
                }))
            }
            "conical_mirror" => {
                need(6)?;
                Ok(CameraModel::ConicalMirror(ConicalMirror {
                    width,
                    height,
                    xc: info.d[0],
                    yc: info.d[1],
                    f: info.d[2],
                    d: info.d[3],
                    alpha: info.d[4],
                    z_top: info.d[5],
                }))
            }
            other => Err(CameraError::UnknownModel(other.to_string())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::tests::{cone, para, pinhole};

    #[test]
    fn camera_info_round_trip() {
        for m in [
            CameraModel::Pinhole(pinhole()),
            CameraModel::Paracatadioptric(para()),
            CameraModel::ConicalMirror(cone()),
        ] {
            let info = CameraInfo::from_model(&m, Header::default());
            assert_eq!(info.model().expect("reads"), m);
        }
        let mut bad = CameraInfo::from_model(&CameraModel::Pinhole(pinhole()), Header::default());
        bad.distortion_model = "fisheye".into();
        assert!(matches!(bad.model(), Err(CameraError::UnknownModel(_))));
    }
}
