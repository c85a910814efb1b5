//! The preview sheet of a dataset (`out/datasets/<name>/preview.png`): one frame of every
//! camera with the ground truth drawn over it (boxes, head points, ids), and the laser scan
//! from above with the room, obstacles, sensors and people — so a person can see what was made.
//!
//! The synthesizer only returns the data ([`PreviewData`], one instant of a dataset's first
//! session); drawing and writing it is this module's job.

use std::path::{Path, PathBuf};

use image::{RgbImage, imageops};

use super::atomic;
use super::figure::{
    Circle, Figure, FigureError, FigureKind, ImageOverlay, Mark, Overlay, Sensor, Series, TopView,
};
use crate::synth::session::PreviewData;

fn decode(png: &[u8]) -> Option<RgbImage> {
    image::load_from_memory(png).ok().map(|i| i.to_rgb8())
}

/// Where the sheet of dataset `name` goes under `root`: `<root>/<name>/preview.png`.
pub fn path(root: &Path, name: &str) -> PathBuf {
    root.join(name).join("preview.png")
}

/// Compose the sheet of dataset `name` and write it atomically to [`path`]; returns the path.
pub fn write(root: &Path, name: &str, p: &PreviewData) -> Result<PathBuf, FigureError> {
    let path = path(root, name);
    let png = sheet(name, p)?;
    atomic::write_atomic(&path, &png, Some(root)).map_err(|e| FigureError::io(name, &path, &e))?;
    Ok(path)
}

/// Compose the sheet as PNG bytes.
pub fn sheet(name: &str, p: &PreviewData) -> Result<Vec<u8>, FigureError> {
    let mut tiles: Vec<RgbImage> = Vec::new();
    for (cam, img, views) in &p.cameras {
        let mut shapes = Vec::new();
        for (id, v) in views {
            if let Some([x0, y0, x1, y1]) = v.bbox {
                shapes.push(Overlay::Box {
                    x0,
                    y0,
                    x1,
                    y1,
                    label: format!("{id} ({:.0}%)", 100.0 * v.visibility),
                    color: 1 + *id as usize % 7,
                });
            }
            if let Some([x, y]) = v.head_px {
                shapes.push(Overlay::Point { x, y, color: 6 });
            }
        }
        let fig = Figure::new(
            format!("{name}_{cam}"),
            format!("{cam} at t = {:.1} s", p.t),
            FigureKind::Overlay(ImageOverlay {
                image: img.clone(),
                shapes,
            }),
        );
        if let Some(t) = decode(&fig.to_png()?) {
            tiles.push(t);
        }
    }
    // top view
    let w = &p.world;
    let outline = if w.outdoor {
        vec![]
    } else {
        vec![
            (0.0, 0.0),
            (w.size[0], 0.0),
            (w.size[0], w.size[1]),
            (0.0, w.size[1]),
        ]
    };
    let obstacles: Vec<Vec<(f64, f64)>> = w.obstacles.iter().map(|o| o.outline()).collect();
    let mut circles: Vec<Circle> = p
        .people
        .iter()
        .map(|q| Circle {
            x: q.x,
            y: q.y,
            r: q.radius,
            color: 1 + q.id as usize % 7,
        })
        .collect();
    for q in &p.people {
        for [x, y] in q.legs {
            circles.push(Circle {
                x,
                y,
                r: q.leg_radius,
                color: 0,
            });
        }
    }
    let mut sensors: Vec<Sensor> = p
        .sensors
        .iter()
        .map(|(n, xyz)| Sensor {
            x: xyz[0],
            y: xyz[1],
            heading: None,
            label: n.clone(),
        })
        .collect();
    sensors.push(Sensor {
        x: p.robot[0],
        y: p.robot[1],
        heading: Some(p.robot[2]),
        label: "robot".into(),
    });
    let scan = Series::points(
        "laser returns",
        p.scan_points.iter().map(|q| (q[0], q[1])).collect(),
        6,
    )
    .with_mark(Mark::Points);
    let fig = Figure::new(
        format!("{name}_top"),
        format!("{name}: top view at t = {:.1} s", p.t),
        FigureKind::TopView(TopView {
            outline,
            obstacles,
            sensors,
            trajectories: if p.scan_points.is_empty() {
                vec![]
            } else {
                vec![scan]
            },
            circles,
        }),
    );
    if let Some(t) = decode(&fig.to_png()?) {
        tiles.push(t);
    }
    // grid: rows of at most 1600 px
    let max_w = 1600u32;
    let mut rows: Vec<Vec<RgbImage>> = vec![Vec::new()];
    let mut row_w = 0;
    for t in tiles {
        if row_w + t.width() > max_w && !rows.last().is_none_or(Vec::is_empty) {
            rows.push(Vec::new());
            row_w = 0;
        }
        row_w += t.width();
        if let Some(r) = rows.last_mut() {
            r.push(t);
        }
    }
    let width = rows
        .iter()
        .map(|r| r.iter().map(RgbImage::width).sum::<u32>())
        .max()
        .unwrap_or(1)
        .max(1);
    let height = rows
        .iter()
        .map(|r| r.iter().map(RgbImage::height).max().unwrap_or(0))
        .sum::<u32>()
        .max(1);
    let mut canvas = RgbImage::from_pixel(width, height, image::Rgb([255, 255, 255]));
    let mut y = 0i64;
    for r in &rows {
        let mut x = 0i64;
        for t in r {
            imageops::overlay(&mut canvas, t, x, y);
            x += i64::from(t.width());
        }
        y += i64::from(r.iter().map(RgbImage::height).max().unwrap_or(0));
    }
    let mut out = Vec::new();
    canvas
        .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .map_err(|e| FigureError {
            name: name.into(),
            reason: e.to_string(),
            path: None,
        })?;
    Ok(out)
}
