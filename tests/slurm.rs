//! Real Slurm, no cluster needed: `munged`, `slurmctld` and `slurmd` start on 127.0.0.1 from a
//! private configuration in a temporary folder (no system-wide config, no root-only paths),
//! `peopletrack submit --slurm` sends a 3-task array and its `afterok` aggregate, and the tables
//! and figures they write must equal a single-machine run byte for byte.
//!
//! SKIPPED (with the reason) when Slurm's daemons are not installed; `.ci/run` installs the
//! Debian packages `slurmctld slurmd slurm-client munge`, so CI runs it.

use crate::common;

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn which(tool: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/sbin", "/usr/bin"].map(PathBuf::from))
        .map(|d| d.join(tool))
        .find(|p| p.is_file())
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port on 127.0.0.1")
}

fn output(cmd: &mut Command) -> String {
    let o = cmd.output().expect("runs");
    String::from_utf8_lossy(&o.stdout).trim().to_string()
}

/// A one-node Slurm cluster in `dir`: the daemons are children, killed on drop.
struct Cluster {
    conf: PathBuf,
    daemons: Vec<Child>,
    dir: PathBuf,
}

impl Cluster {
    /// Start the three daemons, or say why not (the test is then SKIPPED).
    fn start(dir: &Path) -> Result<Cluster, String> {
        let tools: Vec<PathBuf> = ["munged", "slurmctld", "slurmd", "sbatch", "squeue"]
            .iter()
            .map(|t| which(t).ok_or(format!("`{t}` is not installed")))
            .collect::<Result<_, _>>()?;
        let (munged, slurmctld, slurmd) = (&tools[0], &tools[1], &tools[2]);
        for sub in ["state", "spool", "log", "run"] {
            std::fs::create_dir_all(dir.join(sub)).expect("cluster folders");
        }
        // munge: a private key and socket
        let key = dir.join("munge.key");
        std::fs::write(
            &key,
            (0..1024u32)
                .map(|i| (i * 7919 % 251) as u8)
                .collect::<Vec<_>>(),
        )
        .expect("key");
        set_mode(&key, 0o600);
        set_mode(dir, 0o755);
        let sock = dir.join("run/munge.sock");
        let munge = Command::new(munged)
            .args(["--foreground", "--force"])
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--socket={}", sock.display()))
            .arg(format!(
                "--pid-file={}",
                dir.join("run/munged.pid").display()
            ))
            .arg(format!(
                "--log-file={}",
                dir.join("log/munged.log").display()
            ))
            .arg(format!(
                "--seed-file={}",
                dir.join("run/munged.seed").display()
            ))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| format!("munged does not start: {e}"))?;
        let mut cluster = Cluster {
            conf: dir.join("slurm.conf"),
            daemons: vec![munge],
            dir: dir.to_path_buf(),
        };
        wait_for(|| sock.exists(), "munged's socket")?;
        std::fs::write(&cluster.conf, config(dir, &sock)).expect("slurm.conf");
        std::fs::write(dir.join("plugstack.conf"), "").expect("plugstack.conf");
        for (daemon, args) in [
            (slurmctld, &["-D", "-i"][..]),
            (slurmd, &["-D", "-N", "ptnode"][..]),
        ] {
            let child = Command::new(daemon)
                .args(args)
                .env("SLURM_CONF", &cluster.conf)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .map_err(|e| format!("{} does not start: {e}", daemon.display()))?;
            cluster.daemons.push(child);
        }
        let sinfo = which("sinfo").ok_or("`sinfo` is not installed")?;
        let conf = cluster.conf.clone();
        wait_for(
            || {
                output(
                    Command::new(&sinfo)
                        .env("SLURM_CONF", &conf)
                        .args(["-h", "-o", "%t"]),
                )
                .starts_with("idle")
            },
            "the node to become idle",
        )
        .map_err(|e| format!("{e}; logs in {}", cluster.dir.join("log").display()))?;
        Ok(cluster)
    }

    fn cmd(&self, tool: &str) -> Command {
        let mut c = Command::new(which(tool).unwrap_or_else(|| tool.into()));
        c.env("SLURM_CONF", &self.conf);
        c
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for d in self.daemons.iter_mut().rev() {
            let _ = d.kill();
            let _ = d.wait();
        }
    }
}

fn set_mode(p: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode)).expect("chmod");
}

fn wait_for(mut ready: impl FnMut() -> bool, what: &str) -> Result<(), String> {
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60) {
        if ready() {
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Err(format!("gave up waiting for {what} after 60 s"))
}

/// slurm.conf of a one-node cluster on 127.0.0.1, run by the current user.
fn config(dir: &Path, munge_socket: &Path) -> String {
    let user = output(Command::new("id").arg("-un"));
    let host = output(Command::new("hostname").arg("-s"));
    let cpus = std::thread::available_parallelism().map_or(2, |n| n.get());
    let d = dir.display();
    format!(
        "ClusterName=peopletrack-test
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={ctl}
SlurmdPort={node}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmUser={user}
SlurmdUser={user}
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/run/slurmctld.pid
SlurmdPidFile={d}/run/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
PlugStackConfig={d}/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
MailProg=/bin/true
NodeName=ptnode NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes=ptnode Default=YES MaxTime=INFINITE State=UP
",
        ctl = free_port(),
        node = free_port(),
        sock = munge_socket.display(),
    )
}

fn peopletrack() -> Command {
    Command::new(env!("CARGO_BIN_EXE_peopletrack"))
}

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

#[test]
fn slurm_array_and_aggregate_equal_a_single_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let cluster = match Cluster::start(&tmp.path().join("slurm")) {
        Ok(c) => c,
        Err(why) => {
            eprintln!("SKIPPED: no private Slurm cluster here: {why}");
            return;
        }
    };
    let sessions = common::runner_sessions(&tmp.path().join("data"));
    let single = tmp.path().join("single");
    let one = peopletrack()
        .arg("run")
        .arg(pipeline())
        .args(["--sessions", &sessions, "--out"])
        .arg(&single)
        .output()
        .expect("runs");
    assert!(
        one.status.success(),
        "{}",
        String::from_utf8_lossy(&one.stderr)
    );

    let out = tmp.path().join("cluster-out");
    let submitted = peopletrack()
        .env("SLURM_CONF", &cluster.conf)
        .env("PATH", path_with_slurm())
        .args(["submit", "--slurm"])
        .arg(pipeline())
        .args(["--shards", "3", "--time", "0:10:00", "--mem", "200M"])
        .args(["--sessions", &sessions, "--out"])
        .arg(&out)
        .output()
        .expect("submit runs");
    let text = String::from_utf8_lossy(&submitted.stdout).to_string();
    assert!(
        submitted.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&submitted.stderr)
    );
    let id_after = |label: &str| -> String {
        let rest = text
            .split(label)
            .nth(1)
            .unwrap_or_else(|| panic!("{label}: {text}"));
        rest.chars().take_while(char::is_ascii_digit).collect()
    };
    let (array, aggregate) = (id_after("array job "), id_after("aggregate job "));
    assert!(!array.is_empty() && !aggregate.is_empty(), "{text}");
    // wait until the queue is empty, then check how each job ended
    wait_for(
        || output(cluster.cmd("squeue").args(["-h", "-o", "%i"])).is_empty(),
        "the jobs to leave the queue",
    )
    .expect("jobs finish");
    let logs = out.join("dataset_quality/slurm");
    for (job, id) in [("array", &array), ("aggregate", &aggregate)] {
        let state = output(cluster.cmd("scontrol").args(["show", "job", id]));
        let states: Vec<&str> = state
            .split_whitespace()
            .filter(|w| w.starts_with("JobState="))
            .collect();
        let want = if job == "array" { 3 } else { 1 };
        assert!(
            states.len() == want && states.iter().all(|s| *s == "JobState=COMPLETED"),
            "{job} job {id}: {state}\nlogs in {}: {:?}",
            logs.display(),
            std::fs::read_dir(&logs).map(|d| d.count())
        );
    }
    assert_eq!(
        common::products(&single, "dataset_quality"),
        common::products(&out, "dataset_quality"),
        "the cluster's tables and figures differ from the single run's"
    );
    for k in 1..=3 {
        assert!(
            logs.join(format!("shard-{k}.log")).is_file(),
            "shard {k}'s log"
        );
    }
    drop(cluster);
}

/// `PATH` with the folders of Slurm's client tools first (they live in /usr/bin on Debian).
fn path_with_slurm() -> std::ffi::OsString {
    let mut dirs: Vec<PathBuf> = which("sbatch")
        .and_then(|p| p.parent().map(Path::to_path_buf))
        .into_iter()
        .collect();
    dirs.extend(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    ));
    std::env::join_paths(dirs).expect("PATH")
}
