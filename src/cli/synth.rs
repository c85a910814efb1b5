//! `peopletrack synth SCENARIO.toml`: render a synthetic dataset's sessions as MCAP logs, and
//! its preview sheet.

use std::path::PathBuf;

use peopletrack::report::preview;
use peopletrack::synth::{self, SynthOptions};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scenario files, e.g. datasets/omni_lab/scenario.toml.
    #[arg(required = true, value_name = "SCENARIO")]
    pub scenarios: Vec<PathBuf>,
    /// Profile: `quick` (small, the default datasets) or `full` (paper-sized).
    #[arg(long, default_value = "quick")]
    pub profile: String,
    /// Folder for the logs (default: the scenario's folder; `full/` below it for `full`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Folder for preview sheets (`<dir>/<name>/preview.png`).
    #[arg(long, default_value = "out/datasets")]
    pub preview: PathBuf,
    /// Skip scenarios whose logs already exist and were rendered from this scenario file by
    /// this generator (a log's `peopletrack.scenario` metadata records both); stale logs are
    /// rendered again.
    #[arg(long)]
    pub if_absent: bool,
    /// Render only the sessions whose log is absent (to finish an interrupted render: each
    /// session depends only on its index and seed, so the logs equal one whole render's).
    #[arg(long, conflicts_with = "if_absent")]
    pub missing_only: bool,
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    for scenario in &a.scenarios {
        let dir = a
            .out
            .clone()
            .unwrap_or_else(|| synth::default_out(scenario, &a.profile));
        if a.if_absent
            && std::fs::read_dir(&dir).is_ok_and(|mut d| {
                d.any(|e| e.is_ok_and(|e| e.path().extension().is_some_and(|x| x == "mcap")))
            })
        {
            match synth::stale_logs(scenario, &a.profile, &dir)? {
                None => {
                    writeln!(
                        out,
                        "{}: logs exist in {}, skipped",
                        scenario.display(),
                        dir.display()
                    )?;
                    continue;
                }
                Some(why) => writeln!(
                    out,
                    "{}: stale ({why}), rendering again",
                    scenario.display()
                )?,
            }
        }
        let started = std::time::Instant::now();
        let s = synth::synthesize_sessions(
            scenario,
            &SynthOptions {
                profile: a.profile.clone(),
                out: a.out.clone(),
                progress: super::progress::shared(super::stderr_is_terminal()),
            },
            a.missing_only,
        )?;
        let sheet = match &s.preview {
            Some(data) => Some(preview::write(&a.preview, &s.name, data)?),
            None => None,
        };
        writeln!(
            out,
            "{}: {} sessions in {:.1} s",
            s.name,
            s.sessions.len(),
            started.elapsed().as_secs_f64()
        )?;
        for p in &s.sessions {
            writeln!(out, "  {}", p.display())?;
        }
        if let Some(p) = &sheet {
            writeln!(out, "  preview {}", p.display())?;
        }
    }
    Ok(())
}
