#!/usr/bin/env python3
"""Median phase times of sc-solve runs from SC_TIMELINE=1, for one or two variants.

    timeline_ab.py -n 21 --dir LEVEL_DIR -- ARGS...               one binary
    timeline_ab.py -n 21 --a BIN_A --b BIN_B --dir DIR -- ARGS...  A and B in turn
    timeline_ab.py -n 21 --a BIN --a-env X=1 --b BIN --dir DIR -- ARGS...

ARGS are sc-solve's (input, --setup, -o ...). Each run's timeline (stderr) is
parsed; per phase (in the order of its median start) the median of its summed length,
and the median whole run (the end of the last span: main's own wall time,
without exec and exit) are printed side by side. The runs alternate A B A B so that a drift of the
machine's speed moves both alike. No timing is asserted anywhere: this is a bench.
"""
import argparse
import os
from pathlib import Path
import statistics
import subprocess
import sys
from collections import defaultdict


def run(binary, env_extra, args, cwd):
    env = dict(os.environ, SC_TIMELINE="1")
    for kv in env_extra:
        k, _, v = kv.partition("=")
        env[k] = v
    p = subprocess.run([binary, "-q", *args], cwd=cwd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{binary} failed ({p.returncode}):\n{p.stderr}")
    phases = defaultdict(float)
    first = {}
    end = 0.0
    started = False
    for line in p.stderr.splitlines():
        if line.startswith("timeline"):
            started = True
            continue
        if not started:
            continue
        parts = line.split(None, 4)
        if len(parts) < 5:
            continue
        start, stop, length, _thread, name = parts
        phases[name] += float(length)
        first.setdefault(name, float(start))
        end = max(end, float(stop))
    phases["(main: whole run)"] = end
    first["(main: whole run)"] = float("inf")
    return phases, first


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-n", type=int, default=21)
    ap.add_argument("--a", default=str(Path(__file__).resolve().parents[2] / "target" / "release" / "sc-solve"))
    ap.add_argument("--b")
    ap.add_argument("--a-env", action="append", default=[])
    ap.add_argument("--b-env", action="append", default=[])
    ap.add_argument("--dir", default=".")
    ap.add_argument("args", nargs=argparse.REMAINDER)
    o = ap.parse_args()
    args = o.args[1:] if o.args[:1] == ["--"] else o.args
    variants = [("A", o.a, o.a_env)] + ([("B", o.b or o.a, o.b_env)] if o.b or o.b_env else [])
    runs = {name: [] for name, _, _ in variants}
    for _ in range(o.n):
        for name, binary, env in variants:
            runs[name].append(run(binary, env, args, o.dir))
    # phases in the order of their median first start
    starts = defaultdict(list)
    for name, _, _ in variants:
        for _, first in runs[name]:
            for k, t in first.items():
                starts[k].append(t)
    names = sorted(starts, key=lambda k: statistics.median(starts[k]))
    header = "phase (median ms of %d runs)" % o.n
    print(f"{header:<58}" + "".join(f"{v[0]:>10}" for v in variants) + ("     B/A" if len(variants) == 2 else ""))
    for k in names:
        meds = [statistics.median(r.get(k, 0.0) for r, _ in runs[v[0]]) for v in variants]
        ratio = f"{meds[1] / meds[0]:8.2f}" if len(meds) == 2 and meds[0] > 0 else ""
        print(f"{k[:58]:<58}" + "".join(f"{m:>10.2f}" for m in meds) + ratio)


if __name__ == "__main__":
    main()
