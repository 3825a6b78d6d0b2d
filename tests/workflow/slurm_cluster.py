"""A private one-node SLURM cluster on this machine, for testing the workflow's SLURM profile.

Needs Debian's `slurm-wlm` and `munge` (`apt-get install slurm-wlm munge`) and root. Everything the
cluster writes lives in one state directory: slurm.conf (this host as the only node, its CPUs from
`nproc`, RealMemory 90 % of MemTotal, cons_tres, no cgroups, no accounting), a fresh munge key and
socket, the daemons' state, spool, logs and PID files. Ports are picked free, so the cluster does
not clash with a real SLURM or munge on the machine, and nothing under /etc is touched.

The plugin's job step runs a nested `srun` after dropping every `SLURM_*` variable, SLURM_CONF
included, so that `srun` would read the compiled-in /etc/slurm/slurm.conf. Instead of writing
there, `bin/srun` in the state directory puts SLURM_CONF back and runs the real srun; `env()` puts
that directory first on PATH (sbatch jobs inherit the submitter's environment).

Python::

    with OneNodeCluster(state_dir) as cluster:
        subprocess.run([...], env=cluster.env())

Shell (the daemons outlive the command; `stop` ends exactly the PIDs `start` recorded)::

    python tests/workflow/slurm_cluster.py start /tmp/slurm   # prints the export lines
    python tests/workflow/slurm_cluster.py stop /tmp/slurm
    python tests/workflow/slurm_cluster.py run /tmp/slurm -- snakemake ...   # start, run, stop
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

DAEMONS = ("munged", "slurmctld", "slurmd")
CLIENTS = ("srun", "sbatch", "squeue", "sinfo", "scontrol", "scancel")


def missing_binaries() -> list[str]:
    """The SLURM and munge programs this cluster needs that are not installed (empty: all are)."""
    search = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/usr/bin"])
    return [name for name in (*DAEMONS, *CLIENTS) if shutil.which(name, path=search) is None]


def _binary(name: str) -> str:
    path = shutil.which(name, path=os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin",
                                                    "/usr/bin"]))
    if path is None:
        raise FileNotFoundError(f"{name} not found: apt-get install slurm-wlm munge")
    return path


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _real_memory_mb() -> int:
    """90 % of MemTotal: slurmd refuses a node that has less memory than RealMemory says."""
    with open("/proc/meminfo", encoding="ascii") as fh:
        for line in fh:
            if line.startswith("MemTotal:"):
                return int(int(line.split()[1]) / 1024 * 0.9)
    raise RuntimeError("no MemTotal in /proc/meminfo")


def process_start_time(pid: int) -> str | None:
    """The process's start time in clock ticks (field 22 of /proc/PID/stat), None if gone.

    Recorded with each PID so that `stop` never signals a PID that was reused by another process.
    """
    try:
        stat = Path(f"/proc/{pid}/stat").read_text(encoding="ascii")
    except OSError:
        return None
    return stat.rpartition(")")[2].split()[19]


class OneNodeCluster:
    """munged, slurmctld and slurmd for this host, all in `state_dir`; a context manager."""

    def __init__(self, state_dir: str | os.PathLike, *, cpus: int | None = None,
                 memory_mb: int | None = None, min_job_age: int = 600):
        self.dir = Path(state_dir).resolve()
        self.conf = self.dir / "slurm.conf"
        self.bin = self.dir / "bin"
        self.pid_file = self.dir / "daemons.json"
        self.node = socket.gethostname().split(".")[0]
        self.cpus = cpus or os.cpu_count()
        self.memory_mb = memory_mb or _real_memory_mb()
        # squeue forgets a finished job MinJobAge seconds after it ends; the plugin polls squeue at
        # most every 180 s and falls back to sacct (which fails without accounting) below 3 x its
        # first poll interval, so keep it well above both.
        self.min_job_age = min_job_age
        self._procs: dict[str, subprocess.Popen] = {}

    # -- configuration -----------------------------------------------------------------------
    def write_config(self) -> None:
        # slurmstepd makes sockets named <node>_<job>.<step> in the spool directory, munged one in
        # munge/: a Unix socket path has at most 107 bytes.
        if len(str(self.dir)) + len(self.node) + 40 > 107:
            raise ValueError(f"{self.dir}: too long a path for the cluster's Unix sockets; use a "
                             "short one such as tempfile.mkdtemp(prefix='slurm-')")
        for sub in ("munge", "ctld", "spool", "log"):
            (self.dir / sub).mkdir(parents=True, exist_ok=True)
        os.chmod(self.dir / "munge", 0o700)
        key = self.dir / "munge" / "munge.key"
        if not key.exists():
            key.write_bytes(os.urandom(128))
        os.chmod(key, 0o600)
        d = self.dir
        self.conf.write_text("\n".join([
            "# One-node test cluster written by tests/workflow/slurm_cluster.py",
            "ClusterName=suspsim-test",
            f"SlurmctldHost={self.node}(127.0.0.1)",
            f"SlurmctldPort={_free_port()}",
            f"SlurmdPort={_free_port()}",
            "SlurmUser=root",
            "SlurmdUser=root",
            "AuthType=auth/munge",
            "CredType=cred/munge",
            f"AuthInfo=socket={d}/munge/munge.socket",
            f"StateSaveLocation={d}/ctld",
            f"SlurmdSpoolDir={d}/spool",
            f"SlurmctldPidFile={d}/slurmctld.pid",
            f"SlurmdPidFile={d}/slurmd.pid",
            f"SlurmctldLogFile={d}/log/slurmctld.log",
            f"SlurmdLogFile={d}/log/slurmd.log",
            "SlurmctldDebug=info",
            "SlurmdDebug=info",
            # No cgroups (none to delegate inside a container): track processes by /proc.
            "ProctrackType=proctrack/linuxproc",
            "TaskPlugin=task/none",
            "SelectType=select/cons_tres",
            "SelectTypeParameters=CR_Core_Memory",
            "SchedulerType=sched/backfill",
            "MpiDefault=none",
            "ReturnToService=2",
            # No accounting daemon: sacct cannot answer, so the profile polls squeue.
            "AccountingStorageType=accounting_storage/none",
            "JobAcctGatherType=jobacct_gather/none",
            "JobCompType=jobcomp/none",
            f"MinJobAge={self.min_job_age}",
            "SlurmdTimeout=60",
            "InactiveLimit=0",
            "KillWait=5",
            f"NodeName={self.node} NodeAddr=127.0.0.1 CPUs={self.cpus} "
            f"RealMemory={self.memory_mb} State=UNKNOWN",
            f"PartitionName=debug Nodes={self.node} Default=YES MaxTime=INFINITE State=UP",
            "",
        ]), encoding="ascii")
        self.bin.mkdir(exist_ok=True)
        shim = self.bin / "srun"
        shim.write_text("#!/bin/sh\n"
                        "# The plugin's job step drops SLURM_CONF before its nested srun.\n"
                        f"SLURM_CONF={self.conf} exec {_binary('srun')} \"$@\"\n", encoding="ascii")
        shim.chmod(0o755)

    def env(self, base: dict | None = None) -> dict:
        """An environment whose SLURM commands talk to this cluster."""
        env = dict(os.environ if base is None else base)
        env["SLURM_CONF"] = str(self.conf)
        env["PATH"] = os.pathsep.join([str(self.bin), env.get("PATH", ""), "/usr/sbin"])
        return env

    # -- daemons -----------------------------------------------------------------------------
    def _spawn(self, name: str, args: list[str]) -> None:
        log = open(self.dir / "log" / f"{name}.out", "ab")
        # Own session: a Ctrl-C meant for the caller does not reach the daemons; stop() does.
        proc = subprocess.Popen([_binary(name), *args], stdin=subprocess.DEVNULL, stdout=log,
                                stderr=subprocess.STDOUT, env=self.env(), start_new_session=True)
        log.close()
        self._procs[name] = proc
        self._record()

    @property
    def daemons(self) -> dict[str, tuple[int, str | None]]:
        """{name: (PID, start time)} of the running daemons this object started."""
        return {name: (p.pid, process_start_time(p.pid)) for name, p in self._procs.items()
                if p.poll() is None}

    def _record(self) -> None:
        self.pid_file.write_text(json.dumps(self.daemons))

    def _wait(self, what: str, ready, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        while not ready():
            for name, proc in self._procs.items():
                if proc.poll() is not None:
                    raise RuntimeError(f"{name} exited with {proc.returncode} while waiting for "
                                       f"{what}; see {self.dir / 'log'}\n{self.logs_tail()}")
            if time.monotonic() > deadline:
                raise TimeoutError(f"no {what} after {timeout:.0f} s; see {self.dir / 'log'}\n"
                                   f"{self.logs_tail()}")
            time.sleep(0.2)

    def node_state(self) -> str:
        out = subprocess.run([_binary("sinfo"), "-h", "-N", "-n", self.node, "-o", "%T"],
                             capture_output=True, text=True, env=self.env())
        return out.stdout.strip() if out.returncode == 0 else ""

    def start(self, timeout: float = 60) -> "OneNodeCluster":
        if self.pid_file.exists():
            raise RuntimeError(f"{self.pid_file} exists: a cluster may be running; stop it first")
        self.write_config()
        started = time.monotonic()
        try:
            sock = self.dir / "munge" / "munge.socket"
            self._spawn("munged", ["--foreground", "--force",
                                   f"--socket={sock}",
                                   f"--key-file={self.dir / 'munge' / 'munge.key'}",
                                   f"--pid-file={self.dir / 'munge' / 'munged.pid'}",
                                   f"--seed-file={self.dir / 'munge' / 'munged.seed'}",
                                   f"--log-file={self.dir / 'log' / 'munged.log'}"])
            self._wait("munge socket", sock.exists, timeout)
            self._spawn("slurmctld", ["-D", "-c", "-f", str(self.conf)])
            self._spawn("slurmd", ["-D", "-f", str(self.conf)])
            self._wait(f"idle node {self.node}", lambda: self.node_state() == "idle", timeout)
        except BaseException:
            self.stop()
            raise
        self.start_seconds = time.monotonic() - started
        return self

    def stop(self, timeout: float = 30) -> None:
        """Cancel the cluster's jobs, then end exactly the daemons this object started."""
        if "slurmctld" in self._procs and self._procs["slurmctld"].poll() is None:
            subprocess.run([_binary("scancel"), "--user", str(os.getuid())],
                           capture_output=True, env=self.env())
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                out = subprocess.run([_binary("squeue"), "-h", "-t", "PD,R,CG", "-o", "%i"],
                                     capture_output=True, text=True, env=self.env())
                if out.returncode != 0 or not out.stdout.strip():
                    break
                time.sleep(0.5)
        for name in reversed(DAEMONS):  # slurmd, slurmctld, then munged they authenticate with
            proc = self._procs.get(name)
            if proc is None or proc.poll() is not None:
                continue
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        self._procs.clear()
        self.pid_file.unlink(missing_ok=True)

    def logs_tail(self, lines: int = 15) -> str:
        out = []
        for log in sorted((self.dir / "log").glob("*")):
            text = log.read_text(errors="replace").splitlines()[-lines:]
            out.append(f"--- {log.name}\n" + "\n".join(text))
        return "\n".join(out)

    def __enter__(self) -> "OneNodeCluster":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


def stop_recorded(state_dir: str | os.PathLike, timeout: float = 30) -> list[str]:
    """Stop the daemons a `start` command recorded in state_dir (by PID and start time)."""
    cluster = OneNodeCluster(state_dir)
    if not cluster.pid_file.exists():
        return []
    recorded = json.loads(cluster.pid_file.read_text())
    subprocess.run([_binary("scancel"), "--user", str(os.getuid())],
                   capture_output=True, env=cluster.env())
    stopped = []
    for name in reversed(DAEMONS):
        if name not in recorded:
            continue
        pid, started = recorded[name]
        if process_start_time(pid) != started:  # gone, or the PID now belongs to someone else
            continue
        os.kill(pid, signal.SIGTERM)
        deadline = time.monotonic() + timeout
        while process_start_time(pid) == started and time.monotonic() < deadline:
            time.sleep(0.2)
        if process_start_time(pid) == started:
            os.kill(pid, signal.SIGKILL)
        stopped.append(f"{name} {pid}")
    cluster.pid_file.unlink()
    return stopped


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=("start", "stop", "run"))
    parser.add_argument("state_dir")
    parser.add_argument("command", nargs=argparse.REMAINDER,
                        help="run: the command to run with the cluster up (after --)")
    args = parser.parse_args(argv)
    missing = missing_binaries()
    if missing:
        print(f"not installed: {', '.join(missing)} (apt-get install slurm-wlm munge)",
              file=sys.stderr)
        return 2
    if args.action == "stop":
        print("stopped:", ", ".join(stop_recorded(args.state_dir)) or "nothing")
        return 0
    cluster = OneNodeCluster(args.state_dir).start()
    print(f"# cluster up in {cluster.start_seconds:.1f} s: node {cluster.node}, "
          f"{cluster.cpus} CPUs, {cluster.memory_mb} MB", file=sys.stderr)
    if args.action == "start":
        env = cluster.env()
        print(f"export SLURM_CONF={env['SLURM_CONF']}\nexport PATH={env['PATH']}")
        # Leave the daemons running; `stop` finds them through daemons.json.
        cluster._procs.clear()
        return 0
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    try:
        return subprocess.run(command, env=cluster.env()).returncode
    finally:
        cluster.stop()


if __name__ == "__main__":
    sys.exit(main())
