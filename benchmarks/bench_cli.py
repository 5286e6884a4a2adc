"""Time ``explaindrive --help`` and every subcommand's ``--help`` in fresh processes.

Each figure is the median wall time of ``--runs`` runs of ``python -m explaindrive.cli
<command> --help``, printed against the 0.5 s target with their ratio, and the median CPU
time (user + system) of those runs, which other load on the machine does not inflate. Run
with the interpreter of the install to measure::

    python benchmarks/bench_cli.py [--runs 5]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import time

TARGET_S = 0.5
COMMANDS: tuple[tuple[str, ...], ...] = (
    (),
    ("demo",),
    ("train",),
    ("evaluate",),
    ("report",),
    ("ride",),
    ("interpret",),
    ("explain",),
    ("transcribe",),
    ("serve",),
    ("scenario",),
    ("scenario", "build"),
    ("scenario", "random"),
    ("scenario", "plot"),
    ("score",),
    ("score", "intents"),
    ("score", "decisions"),
)


def help_time_s(args: tuple[str, ...]) -> tuple[float, float]:
    """Wall and CPU time of one ``explaindrive <args> --help`` in a fresh interpreter [s].

    Raises:
        RuntimeError: if the command fails.
    """
    cmd = [sys.executable, "-m", "explaindrive.cli", *args, "--help"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall_s = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {done.stderr.strip()}")
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall_s, cpu_s


def main() -> int:
    """Print each command's median help time against the target; 1 if one misses it."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="runs per command (median)")
    runs = parser.parse_args().runs
    worst = 0.0
    print(f"explaindrive --help, median of {runs} fresh processes (target {TARGET_S} s)")
    for args in COMMANDS:
        times = [help_time_s(args) for _ in range(runs)]
        wall_s = statistics.median(t[0] for t in times)
        cpu_s = statistics.median(t[1] for t in times)
        worst = max(worst, wall_s)
        label = " ".join(["explaindrive", *args, "--help"])
        print(f"{label:<40} {wall_s:6.3f} s  ratio {wall_s / TARGET_S:4.2f}  (cpu {cpu_s:5.3f} s)")
    print(f"slowest {worst:.3f} s: {'within' if worst <= TARGET_S else 'over'} the target")
    return 0 if worst <= TARGET_S else 1


if __name__ == "__main__":
    sys.exit(main())
