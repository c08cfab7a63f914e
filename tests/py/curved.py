"""Convergence and pressure smoothness of solved curved-master runs (pipelines/curved*.yaml).

usage: curved.py RESULTS.pvd [RESULTS.pvd ...] [--y 5] [--profile]

For each results .pvd (or .vtu; its .scres and <stem>.convergence.csv beside it, or
just the .scres of a solve that stopped before its export), prints one JSON line:

- newton: per increment (as numbered in the CSV), Newton corrections (linear
  solves, CSV rows with iteration >= 1) of the attempt that converged (all its
  sub-steps after a cutback), those spent in failed attempts, augmentation passes,
  cutbacks; the total over all attempts; the last converged load factor and
  whether the solve completed.
- contact: contact force (the pair summary of the last increment), active slave
  nodes, largest penetration.
- centreline (the slave nodes of the pad's bottom with reference y = --y, ordered by
  reference x; pressure = contact_pressure of the last increment):
  * d2 = second difference of p along x, for non-uniform spacing
    d2_i = h_i^2 * 2 [(p_{i+1}-p_i)/(x_{i+1}-x_i) - (p_i-p_{i-1})/(x_i-x_{i-1})] / (x_{i+1}-x_{i-1}),
    h_i = (x_{i+1}-x_{i-1})/2 (= p_{i-1} - 2 p_i + p_{i+1} on a uniform line),
    relative to the line's max pressure: rms and max over the interior of the contact
    zone (i-1, i, i+1 all active: `interior`), over its core (i-2 .. i+2 all active:
    `core`, which leaves out the steep last active node at each edge), and over the
    whole line (`all`, which includes the kink where p drops to 0 at the edge);
  * unimodal: p rises (non-strictly) to its maximum and falls after it (tolerance
    1e-9 p_max) — "bell-like"; unimodal_violation: the largest step against that
    shape / p_max (0 when unimodal); peak_x: where the maximum is;
  * symmetry: max |p(x) - p(-x)| / p_max over the mirrored node pairs.
- rows: the same rms/max interior d2 over every slave row y = const (all rows).
With --profile the centreline (x, p, status) is included.
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import meshio
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scresults as sr  # noqa: E402


def second_differences(x, p):
    d2 = np.full(len(p), np.nan)
    for i in range(1, len(p) - 1):
        hl, hr = x[i] - x[i - 1], x[i + 1] - x[i]
        h = 0.5 * (hl + hr)
        d2[i] = h * h * 2.0 * ((p[i + 1] - p[i]) / hr - (p[i] - p[i - 1]) / hl) / (hl + hr)
    return d2


def line_metrics(x, p, active):
    pmax = float(p.max()) if len(p) else 0.0
    out = {"p_max": pmax, "active": int(active.sum())}
    if pmax <= 0:
        return out
    d2 = second_differences(x, p) / pmax
    inner = np.array([i for i in range(1, len(p) - 1) if active[i - 1] and active[i] and active[i + 1]], dtype=int)
    core = np.array([i for i in range(2, len(p) - 2) if active[i - 2:i + 3].all()], dtype=int)
    allin = np.arange(1, len(p) - 1)
    out["d2_interior_rms"] = float(np.sqrt(np.mean(d2[inner] ** 2))) if len(inner) else None
    out["d2_interior_max"] = float(np.abs(d2[inner]).max()) if len(inner) else None
    out["d2_interior_n"] = int(len(inner))
    out["d2_core_rms"] = float(np.sqrt(np.mean(d2[core] ** 2))) if len(core) else None
    out["d2_core_max"] = float(np.abs(d2[core]).max()) if len(core) else None
    out["d2_core_n"] = int(len(core))
    out["d2_all_rms"] = float(np.sqrt(np.mean(d2[allin] ** 2)))
    out["d2_all_max"] = float(np.abs(d2[allin]).max())
    k = int(np.argmax(p))
    tol = 1e-9 * pmax
    up, down = np.diff(p[:k + 1]), np.diff(p[k:])
    out["unimodal"] = bool(np.all(up >= -tol) and np.all(down <= tol))
    # the largest step against the bell shape (a dip), relative to p_max
    out["unimodal_violation"] = float(max([0.0] + list(-up) + list(down)) / pmax)
    out["peak_x"] = float(x[k])
    pairs = [(i, j) for i in range(len(x)) for j in range(len(x)) if i < j and abs(x[i] + x[j]) < 1e-6]
    out["symmetry"] = float(max(abs(p[i] - p[j]) for i, j in pairs) / pmax) if pairs else None
    return out


def results_vtu(path):
    """The last .vtu of `path` (.pvd/.vtu), exporting the .scres to a temp dir if the
    .pvd is missing (a solve that stopped before its export stage)."""
    if os.path.exists(path):
        return sr.last_vtu(path), None
    scres = sr.default_scres(path)
    if not os.path.exists(scres):
        raise FileNotFoundError(path)
    exe = os.environ.get("SC_EXPORT") or "sc-export"
    tmp = tempfile.mkdtemp()
    pvd = os.path.join(tmp, "r.pvd")
    subprocess.run([exe, scres, "-o", pvd], check=True, capture_output=True)
    vtus = sorted(glob.glob(os.path.join(tmp, "r_*.vtu")), key=lambda f: int(f.rsplit("_", 1)[1][:-4]))
    return (vtus[-1] if len(vtus) > 1 else None), tmp


def analyse(path, yc, profile):
    scres = sr.default_scres(path)
    out = {"results": path}
    incs = sr.scres_summary(scres)
    csv_path = sr.default_csv(scres)
    conv = sr.convergence(csv_path) if os.path.exists(csv_path) else {}
    out["states_converged"] = len(incs)  # increments, plus one per extra cutback sub-step
    out["last_load_factor"] = float(incs[-1]["load_factor"]) if incs else 0.0
    out["completed"] = bool(incs) and abs(out["last_load_factor"] - 1.0) < 1e-12
    # the increments (as numbered in the CSV) that reached their load factor; a solve
    # that stopped has one more CSV increment, which did not
    converged = [c for c in conv.values() if c["load_factor"] <= out["last_load_factor"] + 1e-12]
    out["newton_per_increment"] = [c["corrections"] for c in converged]
    out["failed_attempt_newton_per_increment"] = [c["corrections_all_attempts"] - c["corrections"] for c in converged]
    out["augmentations_per_increment"] = [c["augmentations"] for c in converged]
    out["cutbacks_per_increment"] = [c["attempts"] - 1 for c in converged]
    out["newton_total"] = sum(c["corrections_all_attempts"] for c in conv.values())
    out["solver_seconds"] = round(sum(sum(v for k, v in c.items() if k.startswith("seconds_")) for c in conv.values()), 3)
    if not incs:
        out["error"] = "no converged increment"
        return out
    pair = sr.pair_summary(incs[-1])
    out["contact_force"] = [float(v) for v in pair["force"]]
    out["active"] = int(pair["active"])
    out["max_penetration"] = float(pair["max_penetration"])
    out["augmentations_last"] = int(pair.get("augmentations", 0))

    vtu, _ = results_vtu(path)
    m = meshio.read(vtu)
    X = np.asarray(m.points)
    status = np.asarray(m.point_data["contact_status"])
    p = np.asarray(m.point_data["contact_pressure"])
    slave = np.where(status > -2)[0]
    ys = np.unique(np.round(X[slave, 1], 9))
    yline = ys[np.argmin(np.abs(ys - yc))]
    line = slave[np.isclose(X[slave, 1], yline)]
    line = line[np.argsort(X[line, 0])]
    out["centreline_y"] = float(yline)
    out["centreline"] = line_metrics(X[line, 0], p[line], status[line] == 1)
    if profile:
        out["centreline"]["profile"] = [[round(float(X[i, 0]), 6), round(float(p[i]), 6), int(status[i])] for i in line]
    rows = []
    for y in ys:
        r = slave[np.isclose(X[slave, 1], y)]
        r = r[np.argsort(X[r, 0])]
        lm = line_metrics(X[r, 0], p[r], status[r] == 1)
        if lm.get("d2_interior_n"):
            rows.append(lm)
    if rows:
        allv = [lm["d2_interior_rms"] ** 2 * lm["d2_interior_n"] for lm in rows]
        out["rows"] = {
            "n_rows": len(rows),
            "d2_interior_rms": float(np.sqrt(sum(allv) / sum(lm["d2_interior_n"] for lm in rows))),
            "d2_interior_max": float(max(lm["d2_interior_max"] for lm in rows)),
            "all_unimodal": all(lm["unimodal"] for lm in rows),
        }
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--y", type=float, default=5.0, help="centreline y (reference)")
    ap.add_argument("--profile", action="store_true")
    a = ap.parse_args()
    for path in a.results:
        try:
            print(json.dumps(analyse(path, a.y, a.profile)))
        except (FileNotFoundError, subprocess.CalledProcessError) as e:
            print(json.dumps({"results": path, "error": str(e)}))


if __name__ == "__main__":
    main()
