//! The Slurm path for real: a single-node Slurm cluster on 127.0.0.1 (Debian's slurmctld,
//! slurmd, slurm-client and munge, installed with apt-get when missing), the committed
//! job-array and merge scripts (`scripts/slurm/`), a shard killed mid-run and reported by the
//! merge, its resubmission with `--resume`, and the merged result checked byte for byte
//! against a local run. The daemons are stopped by PID in a `Drop` guard, so nothing is left
//! running even when an assertion fails; the test then checks with `ps`.
//!
//! Needs root (to install packages and start the daemons). Set `WHIRLMAP_SKIP_SLURM=1` to
//! skip it on a machine where that is impossible; it says so on stderr.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_whirlmap");
/// Ports away from a site's real Slurm (6817/6818).
const CTLD_PORT: u16 = 16817;
const SLURMD_PORT: u16 = 16818;
/// CPUs the node advertises: more than the array's throttle, so the throttle is what limits
/// the tasks running at once (`config_overrides` lets slurmd accept more than the hardware).
const NODE_CPUS: usize = 4;
/// Hard limit for each wait on the queue.
const QUEUE_TIMEOUT: Duration = Duration::from_secs(240);

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn run(cmd: &mut Command) -> Output {
    let desc = format!("{cmd:?}");
    cmd.output()
        .unwrap_or_else(|e| panic!("cannot run {desc}: {e}"))
}

fn ok(cmd: &mut Command) -> String {
    let desc = format!("{cmd:?}");
    let o = run(cmd);
    assert!(
        o.status.success(),
        "{desc} failed: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn have(program: &str) -> bool {
    Path::new("/usr/sbin").join(program).exists() || Path::new("/usr/bin").join(program).exists()
}

fn is_root() -> bool {
    run(Command::new("id").arg("-u")).stdout == b"0\n"
}

/// Installs the Slurm and munge packages if a program is missing (apt-get, as root).
fn install() {
    if ["slurmctld", "slurmd", "sbatch", "munged"]
        .iter()
        .all(|p| have(p))
    {
        return;
    }
    let pkgs = ["slurmctld", "slurmd", "slurm-client", "munge"];
    let install = || {
        run(Command::new("apt-get")
            .args(["install", "-y", "--no-install-recommends"])
            .args(pkgs)
            .env("DEBIAN_FRONTEND", "noninteractive"))
    };
    if !install().status.success() {
        ok(Command::new("apt-get").arg("update").arg("-q"));
        let o = install();
        assert!(
            o.status.success(),
            "apt-get install {pkgs:?} failed: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// Slurm and munge processes now running: (pid, command name).
fn slurm_processes() -> Vec<(u32, String)> {
    let out = ok(Command::new("ps").args(["-eo", "pid=,stat=,comm="]));
    out.lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let pid = f.next()?.parse().ok()?;
            let stat = f.next()?;
            let comm = f.next()?.to_string();
            let ours = comm.starts_with("slurm") || comm.starts_with("munge");
            (ours && !stat.starts_with('Z')).then_some((pid, comm))
        })
        .collect()
}

/// A running single-node cluster; dropping it cancels the jobs and stops the daemons.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<(&'static str, Child)>,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        let _ = std::fs::remove_dir_all(dir);
        for d in ["state", "spool", "munge", "log"] {
            std::fs::create_dir_all(dir.join(d)).unwrap();
        }
        ok(Command::new("chown")
            .arg("munge:munge")
            .arg(dir.join("munge")));
        let host = ok(Command::new("hostname").arg("-s")).trim().to_string();
        let socket = dir.join("munge/munge.socket");
        let d = dir.display();
        let conf = dir.join("slurm.conf");
        std::fs::write(
            &conf,
            format!(
                "ClusterName=whirlmaptest
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={CTLD_PORT}
SlurmdPort={SLURMD_PORT}
AuthType=auth/munge
AuthInfo=socket={socket}
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1
SlurmdParameters=config_overrides
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName={host} NodeAddr=127.0.0.1 CPUs={NODE_CPUS} State=UNKNOWN
PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP
",
                socket = socket.display()
            ),
        )
        .unwrap();
        let mut c = Cluster {
            dir: dir.to_path_buf(),
            conf: conf.clone(),
            daemons: Vec::new(),
        };
        let log = |name: &str| std::fs::File::create(dir.join("log").join(name)).unwrap();
        // munged refuses to run as root; setpriv execs it (no fork), so the child is munged.
        let m = dir.join("munge");
        let munged = Command::new("setpriv")
            .args(["--reuid=munge", "--regid=munge", "--init-groups"])
            .arg("/usr/sbin/munged")
            .arg("--foreground")
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--pid-file={}", m.join("munged.pid").display()))
            .arg(format!("--log-file={}", m.join("munged.log").display()))
            .arg(format!("--seed-file={}", m.join("munged.seed").display()))
            .stdout(log("munged.out"))
            .stderr(log("munged.err"))
            .spawn()
            .expect("starts munged");
        c.daemons.push(("munged", munged));
        c.wait_for(Duration::from_secs(20), "munged's socket", || {
            socket.exists()
        });
        for (name, prog) in [
            ("slurmctld", "/usr/sbin/slurmctld"),
            ("slurmd", "/usr/sbin/slurmd"),
        ] {
            let child = Command::new(prog)
                .arg("-D")
                .arg("-f")
                .arg(&conf)
                .stdout(log(&format!("{name}.out")))
                .stderr(log(&format!("{name}.err")))
                .spawn()
                .unwrap_or_else(|e| panic!("cannot start {prog}: {e}"));
            c.daemons.push((name, child));
        }
        c.wait_for(Duration::from_secs(60), "the node to be idle", || {
            let o = run(Command::new("sinfo")
                .env("SLURM_CONF", &conf)
                .args(["-h", "-o", "%t"]));
            String::from_utf8_lossy(&o.stdout).trim() == "idle"
        });
        c
    }

    /// A Slurm client command talking to this cluster.
    fn cmd(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf).current_dir(&self.dir);
        c
    }

    /// Polls `ready` every 200 ms; panics with the daemons' logs after `timeout`, or when a
    /// daemon has died.
    fn wait_for(&mut self, timeout: Duration, what: &str, mut ready: impl FnMut() -> bool) {
        let start = Instant::now();
        loop {
            if ready() {
                return;
            }
            let dead = self
                .daemons
                .iter_mut()
                .find_map(|(name, child)| Some((*name, child.try_wait().ok()??)));
            if let Some((name, status)) = dead {
                panic!(
                    "{name} exited ({status}) while waiting for {what}:\n{}",
                    self.logs()
                );
            }
            if start.elapsed() > timeout {
                panic!(
                    "timed out after {timeout:?} waiting for {what}:\n{}",
                    self.logs()
                );
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    fn logs(&self) -> String {
        let mut s = String::new();
        if let Ok(rd) = std::fs::read_dir(self.dir.join("log")) {
            for e in rd.flatten() {
                let text = std::fs::read_to_string(e.path()).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(15).collect();
                s.push_str(&format!("--- {}\n", e.path().display()));
                for l in tail.iter().rev() {
                    s.push_str(l);
                    s.push('\n');
                }
            }
        }
        s
    }

    /// Waits until none of `jobs` is queued or running.
    fn wait_jobs(&mut self, jobs: &[&str]) {
        let list = jobs.join(",");
        let conf = self.conf.clone();
        self.wait_for(QUEUE_TIMEOUT, &format!("jobs {list}"), || {
            let o = run(Command::new("squeue")
                .env("SLURM_CONF", &conf)
                .args(["-h", "-j", &list, "-o", "%i"]));
            o.status.success() && o.stdout.is_empty()
        });
    }

    /// `(JobState, ExitCode)` of a job (or array task `ID_I`) from `scontrol show job`.
    fn job_state(&self, id: &str) -> (String, String) {
        let out = ok(self.cmd("scontrol").args(["show", "job", id]));
        let field = |k: &str| {
            out.split_whitespace()
                .find_map(|w| w.strip_prefix(&format!("{k}=")))
                .unwrap_or("?")
                .to_string()
        };
        (field("JobState"), field("ExitCode"))
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Cancel whatever is left, give the steps a moment to end, then stop the daemons by
        // PID (slurmd, slurmctld, munged), politely first.
        let _ = self.cmd("scancel").args(["--quiet", "-u", "root"]).status();
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(15) {
            let busy = self
                .cmd("squeue")
                .args(["-h", "-o", "%i"])
                .output()
                .map(|o| o.status.success() && !o.stdout.is_empty())
                .unwrap_or(false);
            if !busy {
                break;
            }
            std::thread::sleep(Duration::from_millis(200));
        }
        for (_, child) in self.daemons.iter_mut().rev() {
            let _ = Command::new("kill").arg(child.id().to_string()).status();
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(10) {
                if let Ok(Some(_)) = child.try_wait() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// Only one run of this test at a time on a machine (two `cargo test` runs, e.g. in two
/// checkouts, would share the ports and the folder): a lock file holding the owner's PID,
/// taken over when that process is gone, removed on drop.
struct MachineLock(PathBuf);

impl MachineLock {
    fn take() -> MachineLock {
        let path = std::env::temp_dir().join("whirlmap-slurm-test.lock");
        let start = Instant::now();
        loop {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    write!(f, "{}", std::process::id()).unwrap();
                    return MachineLock(path);
                }
                Err(_) => {
                    let owner = std::fs::read_to_string(&path).unwrap_or_default();
                    let alive =
                        !owner.trim().is_empty() && Path::new("/proc").join(owner.trim()).exists();
                    if !alive {
                        let _ = std::fs::remove_file(&path);
                        continue;
                    }
                    assert!(
                        start.elapsed() < QUEUE_TIMEOUT,
                        "another run of this test (pid {owner}) holds {}",
                        path.display()
                    );
                    std::thread::sleep(Duration::from_millis(500));
                }
            }
        }
    }
}

impl Drop for MachineLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Byte-compares the deterministic outputs of two result folders.
fn assert_same_outputs(local: &Path, merged: &Path) {
    let mut names = vec![
        "points.jsonl".to_string(),
        "summary.csv".to_string(),
        "critical.json".to_string(),
    ];
    for sub in ["orbits", "charts"] {
        let mut files: Vec<String> = std::fs::read_dir(local.join(sub))
            .unwrap()
            .map(|e| format!("{sub}/{}", e.unwrap().file_name().to_string_lossy()))
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{sub}/ is empty");
        names.extend(files);
    }
    for n in &names {
        let (a, b) = (std::fs::read(local.join(n)), std::fs::read(merged.join(n)));
        assert!(
            a.is_ok() && a.ok() == b.ok(),
            "{n} differs between the local run and the Slurm merge"
        );
    }
}

#[test]
fn slurm_job_array_shards_merge_to_the_local_run() {
    if std::env::var_os("WHIRLMAP_SKIP_SLURM").is_some_and(|v| v == "1") {
        eprintln!("slurm test SKIPPED: WHIRLMAP_SKIP_SLURM=1");
        return;
    }
    assert!(
        is_root(),
        "the Slurm test needs root to install and start slurmctld/slurmd/munged; run as root \
         or set WHIRLMAP_SKIP_SLURM=1 to skip it"
    );
    let _lock = MachineLock::take();
    install();
    let before = slurm_processes();
    let dir = std::env::temp_dir().join("whirlmap-slurm-test");
    let spec = repo().join("sweeps/nightly.json");
    let out = dir.join("work/result");
    {
        let mut cluster = Cluster::start(&dir);
        let work = dir.join("work");
        std::fs::create_dir_all(&work).unwrap();
        // The binary as the jobs see it: it logs each task's start and end, and the first
        // attempt of task 2 is killed (SIGKILL) once its first records are written, as a node
        // failure or a time limit would.
        let wrapper = work.join("whirlmap.sh");
        let events = work.join("events.log");
        std::fs::write(
            &wrapper,
            format!(
                r#"#!/usr/bin/env bash
set -u
log={events}
task=${{SLURM_ARRAY_TASK_ID:-merge}}
echo "start $task $(date +%s.%N)" >> "$log"
out=""; prev=""
for a in "$@"; do [ "$prev" = --out ] && out=$a; prev=$a; done
if [ "$task" = 2 ] && mkdir {work}/killed-once 2>/dev/null; then
    {bin} "$@" & pid=$!
    while [ ! -s "$out/points.jsonl" ] && kill -0 $pid 2>/dev/null; do sleep 0.005; done
    kill -KILL $pid; wait $pid
    echo "end $task $(date +%s.%N) killed" >> "$log"
    exit 137
fi
{bin} "$@"; rc=$?
echo "end $task $(date +%s.%N)" >> "$log"
exit $rc
"#,
                events = events.display(),
                work = work.display(),
                bin = BIN
            ),
        )
        .unwrap();
        ok(Command::new("chmod").arg("+x").arg(&wrapper));

        // The 4-task array, at most 2 at once, and the dependent merge.
        let submit = repo().join("scripts/slurm/submit.sh");
        let ids = ok(cluster
            .cmd("bash")
            .arg(&submit)
            .args([s(&spec), "4", s(&out), "--throttle", "2", "--cpus", "1"])
            .env("WHIRLMAP", &wrapper));
        let ids: Vec<String> = ids.split_whitespace().map(str::to_string).collect();
        assert_eq!(ids.len(), 2, "{ids:?}");
        let (array, merge) = (&ids[0], &ids[1]);
        cluster.wait_jobs(&[array, merge]);

        // Task 2 failed, the others ran, at most 2 at once; the merge ran anyway (afterany)
        // and refused, naming the shard.
        for t in 0..4 {
            let (state, code) = cluster.job_state(&format!("{array}_{t}"));
            if t == 2 {
                assert_eq!(state, "FAILED", "task 2: {code}");
            } else {
                assert_eq!(
                    (state.as_str(), code.as_str()),
                    ("COMPLETED", "0:0"),
                    "task {t}"
                );
            }
        }
        let log = std::fs::read_to_string(&events).unwrap();
        let mut running = 0i32;
        let mut peak = 0;
        let mut marks: Vec<(f64, i32)> = log
            .lines()
            .filter(|l| !l.contains(" merge "))
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                (
                    f[2].parse::<f64>().unwrap(),
                    if f[0] == "start" { 1 } else { -1 },
                )
            })
            .collect();
        marks.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (_, d) in &marks {
            running += d;
            peak = peak.max(running);
        }
        assert_eq!(marks.len(), 8, "{log}");
        assert!(
            peak <= 2,
            "the throttle %2 let {peak} tasks run at once:\n{log}"
        );
        let (state, code) = cluster.job_state(merge);
        assert_eq!((state.as_str(), code.as_str()), ("FAILED", "2:0"), "merge");
        let merge_out =
            std::fs::read_to_string(out.join("shards").join(format!("slurm-{merge}-merge.out")))
                .unwrap();
        assert!(
            merge_out.contains("merge refused") && merge_out.contains("shard 2/4"),
            "{merge_out}"
        );
        assert!(merge_out.contains("did not finish"), "{merge_out}");

        // Resubmit task 2 alone (it resumes its folder) and merge again.
        let sbatch = |c: &Cluster, args: &[&str]| {
            let id = ok(c
                .cmd("sbatch")
                .arg("--parsable")
                .args(args)
                .env("WHIRLMAP", &wrapper));
            id.trim().split(';').next().unwrap().to_string()
        };
        let shards = out.join("shards");
        let task_log = format!("{}/slurm-%A_%a.out", shards.display());
        let again = sbatch(
            &cluster,
            &[
                "--array=2",
                "--cpus-per-task=1",
                &format!("--output={task_log}"),
                "--export=ALL,WHIRLMAP_SHARDS=4",
                s(&repo().join("scripts/slurm/sweep-array.sbatch")),
                s(&spec),
                s(&shards),
            ],
        );
        let merge2 = sbatch(
            &cluster,
            &[
                &format!("--dependency=afterok:{again}"),
                &format!("--output={}/slurm-%j-merge.out", shards.display()),
                s(&repo().join("scripts/slurm/merge.sbatch")),
                s(&shards),
                "4",
                s(&out),
            ],
        );
        cluster.wait_jobs(&[&again, &merge2]);
        let task_out =
            std::fs::read_to_string(shards.join(format!("slurm-{again}_2.out"))).unwrap();
        assert!(
            task_out.contains("shard 2/4") && task_out.contains("resumed)"),
            "{task_out}"
        );
        assert_eq!(
            cluster.job_state(&merge2),
            ("COMPLETED".to_string(), "0:0".to_string()),
            "{}",
            std::fs::read_to_string(shards.join(format!("slurm-{merge2}-merge.out")))
                .unwrap_or_default()
        );
    } // the cluster is stopped here

    // Nothing of ours is left running.
    let after = slurm_processes();
    let left: Vec<_> = after.iter().filter(|p| !before.contains(p)).collect();
    assert!(left.is_empty(), "left running: {left:?}");

    // The merged result equals a local run of the same spec.
    let local = dir.join("local");
    ok(Command::new(BIN).args(["sweep", s(&spec), "--out", s(&local), "--no-progress"]));
    assert_same_outputs(&local, &out);
    std::fs::remove_dir_all(&dir).unwrap();
}
