"""3D Hertz check of a solved ball-on-block run (meshes/hertz3d.py, pipelines/hertz3d.yaml).

usage: hertz3d.py RESULTS.scres [--R 8] [--E1 200 --nu1 0.3] [--E2 2e5 --nu2 0.3]
                  [--load-set ball_cap] [--pair 0]

Reads the last increment of the .scres with tests/py/stagefile.py (our own reader of
the stage format, independent of the Rust code) and prints one JSON line.

- F = |R_z(load set)|, the force pressing the ball on the block.
- E*: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2; closed form (Johnson, Contact
  Mechanics, 4.2) for the measured F: a = (3 F R / (4 E*))^(1/3), p0 = 3 F / (2 pi a^2),
  p(r) = p0 sqrt(1 - r^2/a^2).
- The slave is the block's flat top; its nodes carry t_N (a force per REFERENCE area,
  the solver's tributary areas are reference ones), so r is the slave node's reference
  distance from the first contact point (the origin). Pressure p = -t_N.
- p0_fe: the largest nodal pressure. a_fe: the mean of the largest radius of an active
  node and the smallest radius of an open node beyond it (an O(h) measure), with its
  bracket. a_fit, p0_fit: least-squares fit of p^2 = p0^2 (1 - r^2/a^2) (linear in
  r^2) over the active nodes.
- profile_rms_err: RMS over the slave nodes with r <= 1.5 a of (p_fe - p_hertz)/p0.
- h_slave: the slave node spacing at the origin.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tests", "py"))
import stagefile  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scres")
    ap.add_argument("--R", type=float, default=8.0)
    ap.add_argument("--E1", type=float, default=200.0)
    ap.add_argument("--nu1", type=float, default=0.3)
    ap.add_argument("--E2", type=float, default=2.0e5)
    ap.add_argument("--nu2", type=float, default=0.3)
    ap.add_argument("--load-set", default="ball_cap")
    ap.add_argument("--pair", type=int, default=0)
    a = ap.parse_args()
    res = stagefile.results(a.scres)
    inc = res["increments"][-1]
    F = abs(next(float(r["force"][2]) for r in inc["info"]["reactions"] if r["set"] == a.load_set))
    e_star = 1.0 / ((1 - a.nu1 ** 2) / a.E1 + (1 - a.nu2 ** 2) / a.E2)
    a_h = (3 * F * a.R / (4 * e_star)) ** (1 / 3)
    p0_h = 3 * F / (2 * math.pi * a_h ** 2)
    pair = res["pairs"][a.pair]
    slaves = np.asarray(pair["slave_nodes"], dtype=int)
    X = np.asarray(res["mesh"]["nodes"])[slaves]
    r = np.hypot(X[:, 0], X[:, 1])
    state = np.asarray(inc["state"][a.pair])
    p = np.maximum(-state[:, 1], 0.0)
    active = p > 0
    r_act = r[active].max()
    beyond = r[(~active) & (r > r_act)]
    r_open = beyond.min() if beyond.size else float("nan")
    # ellipse fit over the active nodes: p^2 = c0 + c1 r^2
    A = np.vstack([np.ones(active.sum()), r[active] ** 2]).T
    c0, c1 = np.linalg.lstsq(A, p[active] ** 2, rcond=None)[0]
    p0_fit = math.sqrt(max(c0, 0.0))
    a_fit = math.sqrt(-c0 / c1) if c1 < 0 else float("nan")
    win = r <= 1.5 * a_h
    p_h = p0_h * np.sqrt(np.clip(1 - (r / a_h) ** 2, 0.0, None))
    rms = float(np.sqrt(np.mean(((p - p_h)[win] / p0_h) ** 2)))
    d = np.sort(r[r > 1e-12])
    out = {
        "F": F, "E_star": e_star, "a_hertz": a_h, "p0_hertz": p0_h,
        "p0_fe": float(p.max()), "p0_err": float(p.max() / p0_h - 1),
        "a_fe": float(0.5 * (r_act + r_open)), "a_bracket": [float(r_act), float(r_open)],
        "a_err": float(0.5 * (r_act + r_open) / a_h - 1),
        "p0_fit": p0_fit, "a_fit": a_fit, "p0_fit_err": p0_fit / p0_h - 1, "a_fit_err": a_fit / a_h - 1,
        "profile_rms_err": rms, "active": int(active.sum()), "h_slave": float(d[0]) if d.size else float("nan"),
    }
    print(json.dumps(out))


if __name__ == "__main__":
    main()
