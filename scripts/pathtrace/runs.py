"""Running the two renderers as separate, timed processes.

Each run is a child process timed by `/usr/bin/time` (wall seconds, user
and system CPU seconds, peak resident memory), so the path tracer's
figures include its start-up, reading the model and building the BVH,
as the radiosity program's include reading, meshing and solving.
"""

import json
import os
import platform
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
TIME_FORMAT = "%e %U %S %M"


def timed(cmd, log=None):
    """Runs `cmd` under /usr/bin/time; returns (stdout text, times dict).
    stderr goes to `log` (a path) when given. Raises on failure."""
    with tempfile.NamedTemporaryFile("r", suffix=".time", delete=False) as tf:
        tpath = tf.name
    err = open(log, "w") if log else subprocess.DEVNULL
    try:
        p = subprocess.run(["/usr/bin/time", "-f", TIME_FORMAT, "-o", tpath, *cmd],
                           stdout=subprocess.PIPE, stderr=err, text=True)
        with open(tpath) as f:
            last = [ln for ln in f.read().splitlines() if ln.strip()][-1]
    finally:
        if log:
            err.close()
        os.unlink(tpath)
    if p.returncode != 0:
        raise SystemExit(f"failed ({p.returncode}): {' '.join(cmd)}"
                         + (f"; see {log}" if log else ""))
    wall, user, sys_, rss = last.split()
    return p.stdout, {"wall": float(wall), "cpu": float(user) + float(sys_),
                      "rss_mb": int(rss) / 1024}


def radiosity(binary, model, camera, size, out_pfm, options, log=None, stats=None):
    """The program's picture of `model` (linear radiosity, PFM) and its
    times. `options`: the lighting and solver options as a list."""
    cmd = [binary, model, "--camera", camera, "--size", f"{size[0]}x{size[1]}",
           "-o", out_pfm, "--no-window", "-q", *options]
    if stats:
        cmd += ["--stats", stats]
    _, t = timed(cmd, log)
    return t


def reference(model, camera, size, out, spp, options, batches=1, seed=1, extra=(), log=None):
    """Mitsuba's picture through reference.py; returns (its own timings
    JSON, the process times)."""
    cmd = [sys.executable, os.path.join(HERE, "reference.py"), model, "--camera", camera,
           "--size", f"{size[0]}x{size[1]}", "--spp", str(spp), "--batches", str(batches),
           "--seed", str(seed), "-o", out, *options, *extra]
    stdout, t = timed(cmd, log)
    return json.loads(stdout.strip().splitlines()[-1]), t


def machine():
    """nproc, the CPU model and the load average now."""
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    return {"nproc": os.cpu_count(), "cpu": cpu, "load": round(load, 2)}


def version(binary):
    try:
        return subprocess.run([binary, "--version"], capture_output=True, text=True,
                              timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
