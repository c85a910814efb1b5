//! Slurm job arrays for one pipeline: one array task per shard (`run --shard-from-env`), then one
//! aggregate job (`run --aggregate-only --expect-shards N`) that waits for the whole array with
//! `--dependency=afterok`. Slurm does all scheduling, throttling and retries; this module only
//! writes the two batch scripts and calls `sbatch --parsable` (the `slurm-client` tools must be
//! on `PATH` and `SLURM_CONF` point at the cluster, as for any Slurm user).
//!
//! The scripts are plain text, rendered by [`Submission::array_script`] and
//! [`Submission::aggregate_script`]; `peopletrack submit --dry-run` prints them. Each shard's
//! output (and Slurm's log of it) goes under `<out>/<pipeline>/slurm/`.
//!
//! Written by hand: no maintained crate writes sbatch scripts; this is string formatting plus one
//! process call per job.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

use crate::report::atomic::write_atomic;

/// The options of one submission (`peopletrack submit --slurm --help`).
#[derive(Debug, Clone, PartialEq)]
pub struct Submission {
    /// The `peopletrack` binary the jobs run (absolute path; the submitting binary by default).
    pub exe: PathBuf,
    /// Working directory of every job (the pipeline's relative paths resolve from it).
    pub workdir: PathBuf,
    /// Pipeline file, as given (relative to `workdir` or absolute).
    pub pipeline: PathBuf,
    /// The pipeline's name (`[pipeline] name`), which names its output folder.
    pub name: String,
    /// Output root (`--out`).
    pub out: PathBuf,
    /// Number of shards = array tasks.
    pub shards: usize,
    /// At most this many array tasks at once (`--array=1-N%T`); `None` leaves it to Slurm.
    pub throttle: Option<usize>,
    /// `--partition`; `None` is the cluster's default partition.
    pub partition: Option<String>,
    /// `--time` of each job (Slurm's format, e.g. `1:00:00`).
    pub time: String,
    /// `--mem` of each job (Slurm's format, e.g. `4G`).
    pub mem: String,
    /// `--cpus-per-task`: worker threads of each shard (passed on as `-j`).
    pub cpus: usize,
    /// Extra `run` arguments for every job (e.g. `--sessions GLOB`), in order.
    pub run_args: Vec<String>,
}

/// The job ids `sbatch` answered.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Submitted {
    pub array: String,
    pub aggregate: String,
}

/// Quote a word for a POSIX shell (single quotes; a quote inside is closed, escaped, reopened).
pub fn shell_quote(s: &str) -> String {
    let plain = !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_./=:,+%@".contains(&b));
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

impl Submission {
    /// `<out>/<pipeline>/slurm`: the scripts and Slurm's per-task logs.
    pub fn dir(&self) -> PathBuf {
        self.out.join(&self.name).join("slurm")
    }

    /// The `#SBATCH` lines every job shares.
    fn header(&self, s: &mut String, job: &str) {
        let _ = writeln!(s, "#!/bin/sh");
        let _ = writeln!(s, "#SBATCH --job-name={}", shell_quote(job));
        let _ = writeln!(s, "#SBATCH --chdir={}", shell_quote(&path(&self.workdir)));
        if let Some(p) = &self.partition {
            let _ = writeln!(s, "#SBATCH --partition={}", shell_quote(p));
        }
        let _ = writeln!(s, "#SBATCH --time={}", shell_quote(&self.time));
        let _ = writeln!(s, "#SBATCH --mem={}", shell_quote(&self.mem));
        let _ = writeln!(s, "#SBATCH --cpus-per-task={}", self.cpus);
        let _ = writeln!(s, "#SBATCH --ntasks=1");
    }

    /// The `peopletrack -j C run PIPELINE --out OUT [run_args]` words.
    fn run_words(&self) -> String {
        let mut w = vec![
            path(&self.exe),
            "-j".into(),
            self.cpus.to_string(),
            "run".into(),
            path(&self.pipeline),
            "--out".into(),
            path(&self.out),
        ];
        w.extend(self.run_args.iter().cloned());
        w.iter()
            .map(|x| shell_quote(x))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The array job: task `k` of `1..=N` runs shard `k/N` (read from Slurm's environment).
    pub fn array_script(&self) -> String {
        let mut s = String::new();
        self.header(&mut s, &format!("{}-shards", self.name));
        let throttle = self.throttle.map(|t| format!("%{t}")).unwrap_or_default();
        let _ = writeln!(s, "#SBATCH --array=1-{}{throttle}", self.shards);
        let log = self.dir().join("shard-%a.log");
        let _ = writeln!(s, "#SBATCH --output={}", shell_quote(&path(&log)));
        let _ = writeln!(s, "exec {} --shard-from-env", self.run_words());
        s
    }

    /// The aggregate job: the tables and figures from the shards' cached sessions; a shard that
    /// did not finish is named in its report (`--expect-shards`).
    pub fn aggregate_script(&self) -> String {
        let mut s = String::new();
        self.header(&mut s, &format!("{}-aggregate", self.name));
        let log = self.dir().join("aggregate.log");
        let _ = writeln!(s, "#SBATCH --output={}", shell_quote(&path(&log)));
        let _ = writeln!(
            s,
            "exec {} --aggregate-only --expect-shards {}",
            self.run_words(),
            self.shards
        );
        s
    }

    /// Write both scripts under [`Submission::dir`] and submit them: the array, then the
    /// aggregate with `--dependency=afterok:<array>`.
    pub fn submit(&self) -> anyhow::Result<Submitted> {
        let dir = self.dir();
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let array_path = dir.join("array.sbatch");
        let aggregate_path = dir.join("aggregate.sbatch");
        for (p, text) in [
            (&array_path, self.array_script()),
            (&aggregate_path, self.aggregate_script()),
        ] {
            write_atomic(p, text.as_bytes(), Some(&self.out))
                .with_context(|| format!("writing {}", p.display()))?;
        }
        let array = sbatch(&[], &array_path)?;
        let dep = format!("--dependency=afterok:{array}");
        let aggregate = sbatch(&[dep.as_str(), "--kill-on-invalid-dep=no"], &aggregate_path)?;
        Ok(Submitted { array, aggregate })
    }
}

fn path(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// `sbatch --parsable ARGS SCRIPT`, answering the job id (`id` or `id;cluster`).
fn sbatch(args: &[&str], script: &Path) -> anyhow::Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .arg(script)
        .output()
        .with_context(|| {
            format!(
                "running sbatch for {} (is Slurm's client installed and SLURM_CONF set?)",
                script.display()
            )
        })?;
    if !out.status.success() {
        bail!(
            "sbatch refused {}: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!(
            "sbatch answered no job id for {}: {text:?}",
            script.display()
        );
    }
    Ok(id)
}

/// Shard `K/N` of an array task from the scheduler's environment: Slurm's
/// `SLURM_ARRAY_TASK_ID` (with `SLURM_ARRAY_TASK_MIN`, default 1) and `SLURM_ARRAY_TASK_COUNT`,
/// or Kubernetes' indexed jobs' `JOB_COMPLETION_INDEX` (0-based) with `PEOPLETRACK_SHARDS`.
pub fn shard_from_env(var: impl Fn(&str) -> Option<String>) -> anyhow::Result<(usize, usize)> {
    let num = |name: &str| -> anyhow::Result<Option<usize>> {
        match var(name) {
            None => Ok(None),
            Some(v) => v
                .trim()
                .parse::<usize>()
                .map(Some)
                .with_context(|| format!("{name}={v:?} is not a whole number")),
        }
    };
    let (k, n) = if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
        let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(1);
        let n = num("SLURM_ARRAY_TASK_COUNT")?
            .context("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not")?;
        let k = (id + 1).checked_sub(min).with_context(|| {
            format!("SLURM_ARRAY_TASK_ID {id} is below the array's first {min}")
        })?;
        (k, n)
    } else if let Some(i) = num("JOB_COMPLETION_INDEX")? {
        let n = num("PEOPLETRACK_SHARDS")?.context(
            "JOB_COMPLETION_INDEX is set: give the job's completions as PEOPLETRACK_SHARDS",
        )?;
        (i + 1, n)
    } else {
        bail!(
            "--shard-from-env: neither SLURM_ARRAY_TASK_ID (a Slurm array task) nor \
             JOB_COMPLETION_INDEX (a Kubernetes indexed job) is set"
        );
    };
    if n == 0 || k == 0 || k > n {
        bail!("--shard-from-env: shard {k} of {n} is out of range (need 1 <= K <= N)");
    }
    Ok((k, n))
}

#[cfg(test)]
mod tests;
