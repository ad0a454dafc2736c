#!/usr/bin/env python3
"""compare_f3d.py - `viewer render` with its defaults against F3D, side by side.

For each model it runs both programs alternately --runs times (default 5; ours first in odd
runs, F3D first in even ones), each in a fresh child process that renders the file at the same
size into a PNG, and prints the medians of wall time and peak memory and the ratios ours / F3D
(goal: <= 0.5 for both).

What is timed: from starting the process to its exit (start-up, loading the file, rendering,
writing the PNG). Peak memory: the process's maximum resident set (wait4's ru_maxrss). F3D needs
an X display: one Xvfb is started before the first run and stopped after the last, not timed,
and both programs get its DISPLAY (ours does not use it). F3D runs with its built-in defaults
(--dry-run: no configuration file is read), --resolution=W,H and --output=FILE; ours as
`viewer render FILE --size WxH --out FILE` plus --viewer-args.

Without f3d on PATH it says so and exits 0. Also prints `bench: scene=S what=W ours=X ref=Y
ratio=R` lines, so scripts/bench-median.sh can take the medians of several runs.

  bench/f3d/compare_f3d.py [--runs 5] [--size 1280x720] [--models Box,bunny,SheenCloth,igea]
                           [--viewer build/release/app/viewer] [--testdata DIR] [--viewer-args '--backend gl']
  cmake --build build/release --target bench_f3d     # the same, with the build's viewer
"""

import argparse
import os
import shlex
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The models of the F3D comparison, relative to shared/testdata (MANIFEST.md there).
MODELS = {
    "Box": "gltf/Box/glTF/Box.gltf",
    "bunny": "meshes/common-3d-test-models/stanford-bunny/stanford-bunny.obj",
    "SheenCloth": "gltf/SheenCloth/glTF/SheenCloth.gltf",
    "igea": "meshes/common-3d-test-models/igea/igea.ply",
}


def fail(msg):
    print(f"compare_f3d: error: {msg}", file=sys.stderr)
    sys.exit(1)


def png_size(path):
    """(width, height) from a PNG's IHDR, or None when it is not a PNG."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
    except OSError:
        return None
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", head[16:24])


def run_once(cmd, env):
    """Runs cmd in a fresh child; returns (wall seconds, peak RSS in MB, exit status, output)."""
    out = tempfile.TemporaryFile()
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)   # reaped here: keep Popen from waiting again
    out.seek(0)
    text = out.read().decode(errors="replace")
    return wall, usage.ru_maxrss / 1024.0, p.returncode, text


def start_xvfb(width, height):
    """Starts Xvfb on a free display; returns (process, ':N')."""
    xvfb = shutil.which("Xvfb")
    if not xvfb:
        return None, None
    r, w = os.pipe()
    proc = subprocess.Popen([xvfb, "-displayfd", str(w), "-screen", "0", f"{max(width, 1280)}x{max(height, 1024)}x24", "-nolisten", "tcp"],
                            pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    number = b""
    deadline = time.time() + 20
    while time.time() < deadline:
        chunk = os.read(r, 16)
        if not chunk:
            break
        number += chunk
        if number.endswith(b"\n"):
            break
    os.close(r)
    if not number.strip().isdigit():
        proc.kill()
        fail("Xvfb did not start (no display number)")
    return proc, ":" + number.strip().decode()


def main():
    ap = argparse.ArgumentParser(description="viewer render vs F3D: wall time and peak memory, medians and ratios")
    ap.add_argument("--runs", type=int, default=5, help="runs of each program per model (default 5)")
    ap.add_argument("--size", default="1280x720", help="image size WxH (default 1280x720)")
    ap.add_argument("--models", default=",".join(MODELS), help="comma-separated names from: " + ", ".join(MODELS))
    ap.add_argument("--viewer", default=os.environ.get("VIEWER_EXE", os.path.join(ROOT, "build/release/app/viewer")),
                    help="the viewer executable (default: $VIEWER_EXE or build/release/app/viewer)")
    ap.add_argument("--testdata", default=os.environ.get("VIEWER_TESTDATA", os.path.join(ROOT, "..", "shared", "testdata")),
                    help="shared/testdata (default: $VIEWER_TESTDATA or ../shared/testdata)")
    ap.add_argument("--f3d", default="f3d", help="the f3d executable (default: f3d on PATH)")
    ap.add_argument("--viewer-args", default="", help="extra arguments for viewer render, e.g. '--backend gl'")
    ap.add_argument("--out", default="", help="folder for the images (default: a temporary folder, removed)")
    a = ap.parse_args()

    f3d = shutil.which(a.f3d)
    if not f3d:
        print(f"compare_f3d: f3d is not installed ('{a.f3d}' not found; Debian: apt-get install f3d): nothing compared")
        return 0
    if a.runs < 1:
        fail(f"--runs {a.runs}: expected 1 or more")
    try:
        width, height = (int(v) for v in a.size.lower().split("x"))
        if width < 1 or height < 1:
            raise ValueError
    except ValueError:
        fail(f"--size '{a.size}': expected WIDTHxHEIGHT, e.g. 1280x720")
    names = [m for m in a.models.split(",") if m]
    for m in names:
        if m not in MODELS:
            fail(f"--models: unknown model '{m}' (known: {', '.join(MODELS)})")
    if not os.access(a.viewer, os.X_OK):
        fail(f"{a.viewer}: no viewer executable (build it, or pass --viewer / set VIEWER_EXE)")
    files = {m: os.path.join(a.testdata, MODELS[m]) for m in names}
    for m, path in files.items():
        if not os.path.isfile(path):
            fail(f"{path}: missing ({m}); pass --testdata or set VIEWER_TESTDATA to shared/testdata")

    f3d_version = subprocess.run([f3d, "--version"], capture_output=True, text=True).stdout.split("\n")[0].strip()
    xvfb, display = start_xvfb(width, height)
    if not xvfb:
        display = os.environ.get("DISPLAY")
        if not display:
            fail("F3D needs an X display: no Xvfb (Debian: apt-get install xvfb) and no DISPLAY")
    env = dict(os.environ, DISPLAY=display)
    outdir = a.out or tempfile.mkdtemp(prefix="compare_f3d.")
    os.makedirs(outdir, exist_ok=True)
    load_before = os.getloadavg()
    rows, notes = [], set()
    try:
        for m in names:
            ours_png, f3d_png = os.path.join(outdir, f"{m}-viewer.png"), os.path.join(outdir, f"{m}-f3d.png")
            ours_cmd = [a.viewer, "render", files[m], "--size", f"{width}x{height}", "--overwrite", "--out", ours_png] + shlex.split(a.viewer_args)
            f3d_cmd = [f3d, "--dry-run", f"--resolution={width},{height}", f"--output={f3d_png}", files[m]]
            samples = {"ours": [], "f3d": []}
            for i in range(a.runs):
                order = [("ours", ours_cmd, ours_png), ("f3d", f3d_cmd, f3d_png)]
                if i % 2:
                    order.reverse()
                for who, cmd, png in order:
                    if os.path.exists(png):
                        os.remove(png)
                    wall, peak, status, text = run_once(cmd, env)
                    if status != 0:
                        fail(f"{m}: {shlex.join(cmd)} exited with {status}:\n{text.strip()}")
                    if png_size(png) != (width, height):
                        fail(f"{m}: {shlex.join(cmd)} wrote no {width}x{height} PNG (got {png_size(png)})")
                    if who == "ours":
                        for line in text.splitlines():
                            if "backend" in line and line.startswith(png):
                                notes.add("rendered with the " + line.split(", ")[1])
                            elif line.startswith("viewer: note: "):
                                notes.add(line[len("viewer: note: "):])
                    samples[who].append((wall, peak))
            med = {w: (statistics.median(s[0] for s in v), statistics.median(s[1] for s in v)) for w, v in samples.items()}
            rows.append((m, med["ours"], med["f3d"]))
            for what, k in (("wall_s", 0), ("peak_rss_mb", 1)):
                print(f"bench: scene={m} what={what} ours={med['ours'][k]:.3f} ref={med['f3d'][k]:.3f} ratio={med['ours'][k] / med['f3d'][k]:.3f}",
                      flush=True)
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
        if not a.out:
            shutil.rmtree(outdir, ignore_errors=True)
    load_after = os.getloadavg()

    print()
    print(f"viewer render{(' ' + a.viewer_args) if a.viewer_args else ''} vs {f3d_version} --dry-run, {width}x{height}, "
          f"median of {a.runs} runs each, alternated")
    for n in sorted(notes):
        print(f"  ours: {n}")
    print("  timed: process start to exit (load, render, PNG write); peak: the process's max RSS; "
          f"one Xvfb ({display}) for the whole run, not timed, DISPLAY set for both")
    print(f"  load average (1 min) {load_before[0]:.2f} before, {load_after[0]:.2f} after, on {os.cpu_count()} CPUs")
    print()
    print("| model | ours s | F3D s | time ours/F3D | ours MB | F3D MB | memory ours/F3D | goal <= 0.5 |")
    print("|---|---|---|---|---|---|---|---|")
    for m, (ow, om), (fw, fm) in rows:
        rt, rm = ow / fw, om / fm
        print(f"| {m} | {ow:.3f} | {fw:.3f} | {rt:.2f} | {om:.0f} | {fm:.0f} | {rm:.2f} | {'met' if rt <= 0.5 and rm <= 0.5 else 'not met'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
