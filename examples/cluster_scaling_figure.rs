//! The scaling figure of `docs/cluster.md` (issue 34): wall time, aggregate time and the
//! aggregate's peak memory against the number of sessions, from the measurements
//! `tools/scale/run.sh` printed, kept in `tools/scale/results.csv` (one row per run and
//! session count). Draws with the project's own figure code.
//!
//! Usage: `cargo run --release --example cluster_scaling_figure [-- CSV OUT.png]` (defaults:
//! `tools/scale/results.csv`, `docs/cluster_scaling.png`).

use peopletrack::report::figure::{Figure, FigureKind, LinePlot, Mark, Panels, Series};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// One measured row: (run, sessions, wall s, aggregate s, aggregate peak MiB).
type Row = (u32, f64, f64, f64, f64);

fn read(path: &str) -> Res<Vec<Row>> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("reading {path}: {e}"))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| -> Res<f64> {
            let s = f
                .get(k)
                .ok_or_else(|| format!("{path}:{}: too few columns", i + 1))?;
            Ok(s.parse::<f64>()
                .map_err(|e| format!("{path}:{}: column {}: {e}", i + 1, k + 1))?)
        };
        rows.push((num(0)? as u32, num(1)?, num(2)?, num(3)?, num(4)?));
    }
    Ok(rows)
}

/// One line per run of `value` against log10(sessions).
fn panel(name: &str, title: &str, y: &str, rows: &[Row], value: fn(&Row) -> f64) -> Figure {
    let mut runs: Vec<u32> = rows.iter().map(|r| r.0).collect();
    runs.dedup();
    let series = runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            let pts = rows
                .iter()
                .filter(|r| r.0 == *run)
                .map(|r| (r.1.log10(), value(r)))
                .collect();
            Series::line(format!("run {run}"), pts, i).with_mark(Mark::LinePoints)
        })
        .collect();
    let plot = LinePlot {
        x_label: "log10 sessions (10, 100, 1,000)".into(),
        y_label: y.into(),
        series,
        y_range: Some((0.0, rows.iter().map(value).fold(0.0, f64::max) * 1.15)),
        ..LinePlot::default()
    };
    let mut f = Figure::new(name, title, FigureKind::Lines(plot));
    f.size = (520, 380);
    f
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let csv = args
        .first()
        .map_or("tools/scale/results.csv", String::as_str);
    let out = args
        .get(1)
        .map_or("docs/cluster_scaling.png", String::as_str);
    let rows = read(csv)?;
    let panels = vec![
        panel(
            "wall",
            "wall time, submit to empty queue",
            "s",
            &rows,
            |r| r.2,
        ),
        panel("aggregate", "aggregate job", "s", &rows, |r| r.3),
        panel("memory", "aggregate peak RSS", "MiB", &rows, |r| r.4),
    ];
    let fig = Figure::new(
        "cluster_scaling",
        "8-way Slurm array on one 2-core node (tools/scale)",
        FigureKind::Panels(Panels { columns: 3, panels }),
    );
    std::fs::write(out, fig.to_png()?).map_err(|e| format!("writing {out}: {e}"))?;
    println!("wrote {out}");
    Ok(())
}
