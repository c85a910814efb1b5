//! Drawing grouped bars and grids of panels (see [`GroupedBars`], [`Panels`]).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::draw::{DrawResult, caption_style, label_at};
use super::spec::{Figure, GroupedBars, Panels, color};

/// Share of a group's width covered by its bars.
const GROUP_WIDTH: f64 = 0.8;

impl Figure {
    pub(super) fn draw_grouped<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &GroupedBars,
    ) -> DrawResult<DB> {
        let n = p.groups.len().max(1);
        let k = p.series.len().max(1);
        let values = || {
            p.series
                .iter()
                .flat_map(|(_, v)| v.iter().flatten().copied())
                .filter(|v| v.is_finite())
        };
        let top = values().fold(0.0f64, f64::max);
        let bottom = values().fold(0.0f64, f64::min);
        let span = (top - bottom).max(1e-9);
        // room for the value labels, and above the bars for the legend
        let y0 = if bottom < 0.0 {
            bottom - 0.08 * span
        } else {
            0.0
        };
        let y1 = top + span * (0.1 + 0.07 * k as f64);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, caption_style())
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(62)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), y0..y1)?;
        let groups = p.groups.clone();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .y_desc(&p.y_label)
            .x_labels(n)
            .x_label_formatter(&|x| label_at(&groups, *x))
            .y_label_formatter(&|v| format!("{}", (v * 1000.0).round() / 1000.0 + 0.0))
            .light_line_style(RGBColor(246, 246, 246))
            .label_style(("sans-serif", 12))
            .draw()?;
        if bottom < 0.0 {
            chart.draw_series(LineSeries::new(
                vec![(-0.5, 0.0), (n as f64 - 0.5, 0.0)],
                BLACK.stroke_width(1),
            ))?;
        }
        let w = GROUP_WIDTH / k as f64;
        let label_font = |anchor: VPos| {
            ("sans-serif", 11)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, anchor))
        };
        for (j, (name, vals)) in p.series.iter().enumerate() {
            let c = color(j + 1);
            let left = |g: usize| g as f64 - GROUP_WIDTH / 2.0 + j as f64 * w;
            let bars: Vec<(usize, f64)> = vals
                .iter()
                .enumerate()
                .filter_map(|(g, v)| v.filter(|v| v.is_finite()).map(|v| (g, v)))
                .collect();
            chart
                .draw_series(bars.iter().map(|&(g, v)| {
                    Rectangle::new(
                        [(left(g) + 0.06 * w, 0.0), (left(g) + 0.94 * w, v)],
                        c.mix(0.85).filled(),
                    )
                }))?
                .label(name.clone())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.filled()));
            for &(g, v) in &bars {
                let Some(text) = p.labels.get(j).and_then(|l| l.get(g)) else {
                    continue;
                };
                if text.is_empty() {
                    continue;
                }
                let (y, anchor) = if v >= 0.0 {
                    (v + 0.01 * span, VPos::Bottom)
                } else {
                    (v - 0.01 * span, VPos::Top)
                };
                chart.draw_series(std::iter::once(Text::new(
                    text.clone(),
                    (left(g) + w / 2.0, y),
                    label_font(anchor),
                )))?;
            }
        }
        for (g, note) in p.group_notes.iter().enumerate() {
            if !note.is_empty() {
                chart.draw_series(std::iter::once(Text::new(
                    note.clone(),
                    (g as f64, 0.02 * span),
                    label_font(VPos::Bottom),
                )))?;
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", 13))
            .draw()?;
        Ok(())
    }

    pub(super) fn draw_panels<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &Panels,
        raster: bool,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, caption_style())?;
        let columns = p.columns.clamp(1, p.panels.len().max(1));
        let rows = p.panels.len().div_ceil(columns).max(1);
        let cells = area.split_evenly((rows, columns));
        for (cell, f) in cells.iter().zip(&p.panels) {
            f.draw(cell, raster)?;
        }
        Ok(())
    }
}
