//! `out/REPORT.md`: one section per pipeline with its summary lines, every table inline (and
//! linked as CSV, Parquet, LaTeX), every figure, the sessions without results (skipped, failed,
//! panicked) with their reasons and a link to the pipeline's `skipped_sessions` table (a
//! section in every pipeline, saying "none" when none), and versions and timings. Pure: the
//! caller reads the table files and writes the result.

use std::collections::BTreeMap;
use std::fmt::Write;

use super::RunSummary;

/// Versions and totals printed at the top.
#[derive(Debug, Clone)]
pub struct Header {
    pub tool_version: String,
    pub git_commit: String,
    pub rustc: String,
    pub total_seconds: f64,
}

/// Render the report. `tables_md` maps a table's Markdown path (relative to `out/`) to its text.
pub fn render(runs: &[RunSummary], tables_md: &BTreeMap<String, String>, h: &Header) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "# peopletrack report\n");
    let _ = writeln!(
        o,
        "peopletrack {} (commit {}), built with {}; {} pipelines in {:.1} s. Timings vary between runs; tables do not.\n",
        h.tool_version,
        h.git_commit,
        h.rustc,
        runs.len(),
        h.total_seconds
    );
    let _ = writeln!(
        o,
        "| pipeline | sessions | computed | from cache | skipped | tables | figures | time (s) |"
    );
    let _ = writeln!(
        o,
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    for r in runs {
        let _ = writeln!(
            o,
            "| [{}](#{}) | {} | {} | {} | {} | {} | {} | {:.1} |",
            r.title,
            anchor(&r.title),
            r.sessions,
            r.computed,
            r.cached,
            r.skipped.len(),
            r.tables.len(),
            r.figures.len(),
            r.seconds
        );
    }
    for r in runs {
        let _ = writeln!(o, "\n## {}\n", r.title);
        let _ = writeln!(o, "Pipeline `{}` (`{}`).\n", r.pipeline, r.file);
        for line in &r.summary {
            let _ = writeln!(o, "- {line}");
        }
        for n in &r.notices {
            let _ = writeln!(o, "- **Warning**: {n}");
        }
        if !r.summary.is_empty() || !r.notices.is_empty() {
            o.push('\n');
        }
        for (title, path) in &r.tables {
            let stem = path.trim_end_matches(".md");
            let _ = writeln!(o, "### {title}\n");
            if let Some(md) = tables_md.get(path) {
                // the table file starts with its own bold caption; drop it here
                let body = md.split_once("\n\n").map_or(md.as_str(), |(_, rest)| rest);
                let _ = writeln!(o, "{}", body.trim_end());
            }
            let _ = writeln!(
                o,
                "\nFiles: [md]({path}) · [csv]({stem}.csv) · [parquet]({stem}.parquet) · [tex]({stem}.tex)\n"
            );
        }
        for (title, path) in &r.figures {
            let svg = path.trim_end_matches(".png");
            let _ = writeln!(o, "### {title}\n\n![{title}]({path})\n\n[svg]({svg}.svg)\n");
        }
        if !r.skipped.is_empty() || !r.skipped_table.is_empty() {
            let _ = writeln!(o, "### Skipped sessions ({})\n", r.skipped.len());
            if r.skipped.is_empty() {
                let _ = writeln!(o, "None: every session gave results.");
            }
            for (s, why) in &r.skipped {
                let status = super::skipped::status(why);
                let _ = writeln!(o, "- `{s}` ({status}): {why}");
            }
            if !r.warned.is_empty() {
                let _ = writeln!(
                    o,
                    "\nKept with warnings ({}; their results are in the tables):\n",
                    r.warned.len()
                );
                for (s, why) in &r.warned {
                    let status = super::skipped::warned_status(why);
                    let _ = writeln!(o, "- `{s}` ({status}): {why}");
                }
            }
            if !r.skipped_table.is_empty() {
                let stem = r.skipped_table.trim_end_matches(".md");
                let _ = writeln!(
                    o,
                    "\nTable: [md]({}) · [csv]({stem}.csv) · [parquet]({stem}.parquet)",
                    r.skipped_table
                );
            }
            o.push('\n');
        }
    }
    o
}

/// GitHub-style heading anchor.
fn anchor(title: &str) -> String {
    title
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            'a'..='z' | '0'..='9' | '-' | '_' => Some(c),
            ' ' => Some('-'),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_lists_tables_figures_and_skips() {
        let run = RunSummary {
            pipeline: "dataset_quality".into(),
            title: "Dataset quality".into(),
            file: "pipelines/dataset_quality.toml".into(),
            sessions: 3,
            computed: 2,
            cached: 0,
            skipped: vec![
                ("lab/broken".into(), "file is truncated".into()),
                ("lab/bug".into(), "panicked: index out of bounds".into()),
            ],
            warned: vec![("lab/cut".into(), "file cut at byte 900".into())],
            skipped_table: "dataset_quality/tables/skipped_sessions.md".into(),
            tables: vec![(
                "Sessions".into(),
                "dataset_quality/tables/sessions.md".into(),
            )],
            figures: vec![(
                "Rates".into(),
                "dataset_quality/figures/rates_lab.png".into(),
            )],
            summary: vec!["3 sessions.".into()],
            artifacts: Vec::new(),
            seconds: 1.25,
            plan: String::new(),
            notices: Vec::new(),
        };
        let md = BTreeMap::from([(
            "dataset_quality/tables/sessions.md".to_string(),
            "**Sessions**\n\n| a |\n| --- |\n| 1 |\n".to_string(),
        )]);
        let h = Header {
            tool_version: "0.1.0".into(),
            git_commit: "abc".into(),
            rustc: "rustc 1.95.0".into(),
            total_seconds: 1.5,
        };
        insta::assert_snapshot!(render(std::slice::from_ref(&run), &md, &h));
        // a run without skips still says so, with its (empty) table
        let clean = RunSummary {
            skipped: Vec::new(),
            warned: Vec::new(),
            ..run
        };
        let text = render(&[clean], &md, &h);
        assert!(
            text.contains("### Skipped sessions (0)\n\nNone: every session gave results.\n\nTable: [md](dataset_quality/tables/skipped_sessions.md)"),
            "{text}"
        );
    }
}
