use super::*;

#[test]
fn the_top_view_legend_goes_to_the_emptiest_corner() {
    let area = (0.0, 10.0, 0.0, 10.0);
    let with = |pts: Vec<(f64, f64)>| TopView {
        trajectories: vec![Series::line("a", pts, 0)],
        ..TopView::default()
    };
    let pos = |v: &TopView| format!("{:?}", emptiest_corner(v, area));
    // nothing anywhere: the first corner
    assert_eq!(pos(&with(vec![])), "UpperRight");
    // a track through the upper right: the next empty corner
    assert_eq!(pos(&with(vec![(9.0, 9.0), (8.0, 9.5)])), "LowerRight");
    // every corner but the lower left is crossed
    let crossed = vec![
        (9.0, 9.0),
        (9.0, 1.0),
        (1.0, 9.0),
        (1.0, 1.0),
        (2.0, 1.5),
        (9.5, 0.5),
        (8.5, 9.2),
    ];
    assert_eq!(pos(&with(crossed[..3].to_vec())), "LowerLeft");
    // all crossed: the least crossed (upper left, one point; the others two)
    assert_eq!(pos(&with(crossed)), "UpperLeft");
}

/// Render, decode the PNG back, and count pixels that are not white.
fn check(fig: &Figure) {
    let png = fig.to_png().expect("png renders");
    // Set PEOPLETRACK_FIGURE_DIR to look at the test figures.
    if let Some(dir) = std::env::var_os("PEOPLETRACK_FIGURE_DIR") {
        std::fs::write(
            std::path::Path::new(&dir).join(format!("{}.png", fig.name)),
            &png,
        )
        .expect("save");
    }
    let img = image::load_from_memory(&png).expect("valid png").to_rgb8();
    assert_eq!((img.width(), img.height()), fig.size, "{}", fig.name);
    let inked = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let total = (img.width() * img.height()) as usize;
    assert!(
        inked > total / 100,
        "{}: only {inked} of {total} pixels drawn",
        fig.name
    );
    let svg = fig.to_svg().expect("svg renders");
    assert!(
        svg.starts_with("<svg") && svg.contains("</svg>") && svg.len() > 1000,
        "{}",
        fig.name
    );
}

fn wave(phase: f64) -> Vec<(f64, f64)> {
    (0..50)
        .map(|i| (i as f64 * 0.2, (i as f64 * 0.2 + phase).sin()))
        .collect()
}

#[test]
fn every_kind_renders_to_png_and_svg() {
    let lines = LinePlot {
        x_label: "time (s)".into(),
        y_label: "height (m)".into(),
        series: vec![
            Series::line("estimate", wave(0.0), 5).with_band(
                wave(0.0)
                    .iter()
                    .map(|(x, y)| (*x, y - 0.3, y + 0.3))
                    .collect(),
            ),
            Series::line("truth", wave(0.2), 0).with_mark(Mark::Dashed),
        ],
        events: vec![Event {
            x: 4.0,
            label: "occlusion".into(),
            color: 6,
        }],
        ..Default::default()
    };
    check(&Figure::new(
        "lines",
        "Height over time (±3σ)",
        FigureKind::Lines(lines),
    ));
    let scatter = ScatterPlot {
        x_label: "true distance (m)".into(),
        y_label: "person width (px)".into(),
        series: vec![Series::points(
            "",
            (1..40)
                .map(|i| (i as f64 * 0.1, 40.0 / (i as f64 * 0.1)))
                .collect(),
            5,
        )],
        annotation: "r = -0.87".into(),
        fit_line: true,
    };
    check(&Figure::new(
        "scatter",
        "Width vs distance",
        FigureKind::Scatter(scatter),
    ));
    let top = TopView {
        outline: vec![(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (0.0, 5.0)],
        obstacles: vec![vec![(2.0, 1.0), (4.0, 1.0), (4.0, 1.8), (2.0, 1.8)]],
        sensors: vec![Sensor {
            x: 5.0,
            y: 0.0,
            heading: Some(std::f64::consts::FRAC_PI_2),
            label: "omnicam".into(),
        }],
        trajectories: vec![Series::line(
            "truth",
            (0..30)
                .map(|i| (1.0 + i as f64 * 0.25, 2.5 + (i as f64 * 0.3).sin()))
                .collect(),
            0,
        )],
        circles: vec![Circle {
            x: 7.0,
            y: 3.0,
            r: 0.3,
            color: 6,
        }],
    };
    check(&Figure::new(
        "top",
        "Tracked path",
        FigureKind::TopView(top),
    ));
    let bars = BarPlot {
        y_label: "error (m)".into(),
        bars: vec![
            Bar {
                label: "general".into(),
                value: 0.16,
                error: 0.1,
            },
            Bar {
                label: "specific".into(),
                value: 0.12,
                error: 0.08,
            },
        ],
        significance: vec![Significance {
            i: 0,
            j: 1,
            label: "p = 0.003".into(),
        }],
    };
    check(&Figure::new(
        "bars",
        "Person-specific models",
        FigureKind::Bars(bars),
    ));
    let roc = LinePlot {
        x_label: "false positives (%)".into(),
        y_label: "true positives (%)".into(),
        series: vec![Series::line(
            "adaptive",
            vec![(0.0, 0.0), (1.0, 60.0), (5.0, 90.0), (100.0, 100.0)],
            5,
        )],
        x_range: Some((0.0, 100.0)),
        y_range: Some((0.0, 100.0)),
        ..Default::default()
    };
    check(&Figure::new("roc", "ROC", FigureKind::Lines(roc)));
    let mut img = RgbImage::new(160, 120);
    for (x, y, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb([(x % 256) as u8, (y * 2 % 256) as u8, 90]);
    }
    let overlay = ImageOverlay {
        image: img,
        shapes: vec![
            Overlay::Box {
                x0: 20.0,
                y0: 20.0,
                x1: 60.0,
                y1: 100.0,
                label: "1".into(),
                color: 1,
            },
            Overlay::Ellipse {
                cx: 100.0,
                cy: 60.0,
                a: 20.0,
                b: 10.0,
                angle: 0.4,
                color: 2,
            },
            Overlay::Polyline {
                points: vec![(10.0, 10.0), (150.0, 110.0)],
                closed: false,
                color: 3,
            },
            Overlay::Point {
                x: 80.0,
                y: 30.0,
                color: 4,
            },
        ],
    };
    check(&Figure::new(
        "overlay",
        "Camera 1",
        FigureKind::Overlay(overlay),
    ));
}

#[test]
fn rendering_is_deterministic() {
    let fig = Figure::new(
        "d",
        "same",
        FigureKind::Lines(LinePlot {
            series: vec![Series::line("a", wave(0.0), 1)],
            ..Default::default()
        }),
    );
    assert_eq!(fig.to_png().expect("a"), fig.to_png().expect("b"));
    assert_eq!(fig.to_svg().expect("a"), fig.to_svg().expect("b"));
}

#[test]
fn least_squares_known_answer() {
    let (a, b) = least_squares(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).expect("line");
    assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
    assert_eq!(least_squares(&[(1.0, 1.0), (1.0, 2.0)]), None);
}

/// The colour a fill of `c` at opacity `a` leaves on white (how the bitmap backend blends).
fn on_white(c: plotters::style::RGBColor, a: f64) -> [u8; 3] {
    let mix = |v: u8| (f64::from(v) * a + 255.0 * (1.0 - a)) as u8;
    [mix(c.0), mix(c.1), mix(c.2)]
}

fn count(png: &[u8], rgb: [u8; 3]) -> usize {
    let img = image::load_from_memory(png).expect("valid png").to_rgb8();
    img.pixels()
        .filter(|p| p.0.iter().zip(rgb).all(|(a, b)| a.abs_diff(b) <= 1))
        .count()
}

/// Grouped bars in a grid beside a top view with faint dots: the grid has its cells' size,
/// series with values leave bars of their (85 % opaque) colour, a series without values
/// leaves none (only its legend swatch, fully opaque), and the dots are there, faded.
#[test]
fn grouped_bars_and_dots_in_panels() {
    let bars = GroupedBars {
        y_label: "MOTA".into(),
        groups: vec!["real_1".into(), "synthetic_00".into()],
        series: vec![
            ("legs".into(), vec![Some(0.8), Some(-0.4)]),
            ("nearest".into(), vec![Some(0.5), None]),
            ("absent".into(), vec![None, None]),
        ],
        labels: vec![vec!["0.80".into(), "-0.40".into()]],
        group_notes: vec![String::new(), "one SKIPPED".into()],
    };
    let bars = Figure::new("bars", "MOTA", FigureKind::GroupedBars(bars));
    let dots: Vec<(f64, f64)> = (0..400)
        .map(|i| (f64::from(i % 20) * 0.5, f64::from(i / 20) * 0.5))
        .collect();
    let top = Figure {
        size: (500, 500),
        ..Figure::new(
            "top",
            "returns",
            FigureKind::TopView(TopView {
                trajectories: vec![Series::points("returns", dots, 0).with_mark(Mark::Dots)],
                ..TopView::default()
            }),
        )
    };
    let grid = Figure::new(
        "grid",
        "Grid",
        FigureKind::Panels(Panels {
            columns: 2,
            panels: vec![bars.clone(), top],
        }),
    );
    assert_eq!(grid.size, (800 * 2, 500 + 30));
    check(&grid);
    check(&bars);
    let png = bars.to_png().expect("png");
    assert!(count(&png, on_white(color(1), 0.85)) > 500);
    assert!(count(&png, on_white(color(2), 0.85)) > 500);
    assert_eq!(count(&png, on_white(color(3), 0.85)), 0);
    assert!(count(&png, on_white(color(3), 1.0)) > 50, "legend swatch");
    let png = grid.to_png().expect("png");
    assert!(count(&png, on_white(color(0), 0.45)) >= 300, "faint dots");
}
