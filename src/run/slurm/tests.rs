use std::collections::HashMap;
use std::path::PathBuf;

use super::*;

fn submission() -> Submission {
    Submission {
        exe: PathBuf::from("/opt/pt/peopletrack"),
        workdir: PathBuf::from("/home/lab/proj"),
        pipeline: PathBuf::from("pipelines/dataset_quality.toml"),
        name: "dataset_quality".into(),
        out: PathBuf::from("/scratch/out dir"),
        shards: 8,
        throttle: Some(4),
        partition: Some("cpu".into()),
        time: "2:00:00".into(),
        mem: "4G".into(),
        cpus: 2,
        run_args: vec!["--sessions".into(), "logs/*.mcap".into()],
    }
}

#[test]
fn array_script_is_the_expected_text() {
    let want = "#!/bin/sh
#SBATCH --job-name=dataset_quality-shards
#SBATCH --chdir=/home/lab/proj
#SBATCH --partition=cpu
#SBATCH --time=2:00:00
#SBATCH --mem=4G
#SBATCH --cpus-per-task=2
#SBATCH --ntasks=1
#SBATCH --array=1-8%4
#SBATCH --output='/scratch/out dir/dataset_quality/slurm/shard-%a.log'
exec /opt/pt/peopletrack -j 2 run pipelines/dataset_quality.toml --out '/scratch/out dir' --sessions 'logs/*.mcap' --shard-from-env
";
    assert_eq!(submission().array_script(), want);
}

#[test]
fn aggregate_script_expects_every_shard() {
    let mut s = submission();
    s.partition = None;
    s.throttle = None;
    let text = s.aggregate_script();
    assert!(!text.contains("--partition"), "{text}");
    assert!(!text.contains("--array"), "{text}");
    assert!(
        text.ends_with("--sessions 'logs/*.mcap' --aggregate-only --expect-shards 8\n"),
        "{text}"
    );
    assert!(
        text.contains("#SBATCH --output='/scratch/out dir/dataset_quality/slurm/aggregate.log'\n")
    );
}

#[test]
fn shell_quote_survives_the_shell() {
    assert_eq!(shell_quote("plain/path-1.toml"), "plain/path-1.toml");
    assert_eq!(shell_quote(""), "''");
    assert_eq!(shell_quote("a b"), "'a b'");
    assert_eq!(shell_quote("it's"), r"'it'\''s'");
    // and /bin/sh reads each back as the one word it was
    for w in ["a b", "it's", "*.mcap", "$HOME", "x\"y", "back\\slash", ""] {
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("printf %s {}", shell_quote(w)))
            .output()
            .expect("sh runs");
        assert_eq!(String::from_utf8_lossy(&out.stdout), w);
    }
}

fn env(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
    let m: HashMap<String, String> = pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    move |k| m.get(k).cloned()
}

#[test]
fn shard_from_slurm_and_kubernetes_environments() {
    let slurm = env(&[
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_COUNT", "8"),
    ]);
    assert_eq!(shard_from_env(slurm).expect("a shard"), (3, 8));
    // an array numbered 0-7: task 0 is shard 1
    let zero = env(&[
        ("SLURM_ARRAY_TASK_ID", "0"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_COUNT", "8"),
    ]);
    assert_eq!(shard_from_env(zero).expect("a shard"), (1, 8));
    let k8s = env(&[("JOB_COMPLETION_INDEX", "7"), ("PEOPLETRACK_SHARDS", "8")]);
    assert_eq!(shard_from_env(k8s).expect("a shard"), (8, 8));
}

#[test]
fn shard_from_env_names_what_is_missing_or_wrong() {
    let msg = |e: anyhow::Result<(usize, usize)>| format!("{:#}", e.expect_err("an error"));
    assert!(msg(shard_from_env(env(&[]))).contains("SLURM_ARRAY_TASK_ID"));
    assert!(
        msg(shard_from_env(env(&[("SLURM_ARRAY_TASK_ID", "2")])))
            .contains("SLURM_ARRAY_TASK_COUNT")
    );
    assert!(
        msg(shard_from_env(env(&[("JOB_COMPLETION_INDEX", "2")]))).contains("PEOPLETRACK_SHARDS")
    );
    assert!(
        msg(shard_from_env(env(&[
            ("SLURM_ARRAY_TASK_ID", "x"),
            ("SLURM_ARRAY_TASK_COUNT", "2")
        ])))
        .contains("SLURM_ARRAY_TASK_ID=\"x\"")
    );
    assert!(
        msg(shard_from_env(env(&[
            ("SLURM_ARRAY_TASK_ID", "9"),
            ("SLURM_ARRAY_TASK_COUNT", "8")
        ])))
        .contains("out of range")
    );
}
