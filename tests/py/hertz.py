"""Plane-strain Hertz check of a solved pipelines/hertz.yaml (cylinder on a flat block).

usage: hertz.py RESULTS.pvd|RESULTS.vtu [--scres FILE] [--csv FILE] [--load-set cyl_load]
                [--R 8] [--E1 200 --nu1 0.3] [--E2 2e5 --nu2 0.3]

Reads the last increment's .vtu (of the .pvd, or the .vtu given), the reaction of the
loaded set from the .scres (default: the results' stem + .scres, dumped with
`sc-export --format yaml`; sc-export from $SC_EXPORT or PATH) and the convergence CSV
(default: <stem>.convergence.csv). Prints one JSON line.

Definitions (the mesh: half cylinder x >= 0, one element layer in z, thickness t):
- P = 2 |R_y(load set)| / t, the load per unit length of the FULL cylinder (the
  symmetry half carries half of it). P_contact: the same from the contact pair's force.
- E*: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (cylinder and block).
- Closed form (Johnson, Contact Mechanics, 5.3) for the measured P:
  b_hertz = sqrt(4 P R / (pi E*)), p0_hertz = 2 P / (pi b_hertz).
- Contact line: the slave nodes (contact_status > -2) on the face z = 0, ordered by
  their reference x. contact_pressure is t_N, a force per REFERENCE area (the solver's
  tributary areas are reference ones), so the consistent abscissa is the cylinder's
  reference x (then the integral of p dx is P): b_* are measured on it. The *_current
  values use the current x + u_x, where the (nearly rigid) block sees the contact;
  the two differ by the surface's inward u_x (~1.7 % of b at P = 10), a
  finite-displacement effect that linear (Hertz) theory does not resolve.
  Active: contact_pressure > 0.
- p0_fe = max contact_pressure (the node on the symmetry plane).
- Half-width: the pressure is nodal, so the edge lies between the last active node
  (x_lo) and the first open node (x_hi): b_fe = (x_lo + x_hi)/2 with the bracket
  b_bracket = [x_lo, x_hi] (an O(h) measure: b_hertz_in_bracket says whether the
  closed form lies in it). b_fit, p0_fit: least-squares fit of the Hertz ellipse
  p^2 = p0^2 (1 - x^2/b^2) (linear in x^2) to the active nodes (uses them all).
- h_slave: the slave (cylinder) node spacing at x = 0 (arc length of its first
  element); h_master: the master (block_top) element length at x = 0.
- newton: Newton corrections (linear solves) summed over increments, from the CSV;
  augmentations: augmentation passes summed over increments.
- Profile error (the whole pressure distribution, not just p0 and b): on the same
  slave line and the same REFERENCE x (the abscissa on which the nodal pressures
  integrate to P, and the undeformed coordinate of Hertz's linear theory), the
  nodal error e_i = (p_fe(x_i) - p_hertz(x_i)) / p0_hertz with
  p_hertz(x) = p0_hertz sqrt(1 - x^2/b_hertz^2) for x < b_hertz, 0 beyond (b_hertz,
  p0_hertz of the measured P). Over the window x <= 2 b_hertz (the contact zone and as
  much of the open zone next to it, the same physical window at every refinement):
  profile_rms_err = sqrt(mean_i e_i^2) over its nodes, profile_l2_err =
  sqrt(int e^2 dx / x_last) over [x_0 = 0, x_last] (the window's first and last
  node), by the trapezoid rule on the nodal errors (weights the graded nodes by their
  spacing); profile_max_err = max |e_i| over all the line's
  nodes and profile_max_x its x; profile_nodes: the window's node count;
  profile_interior_max_err = max |e_i| over x <= 0.8 b_hertz (away from the edge,
  where the closed form is smooth).
- integration: the pair's `integration` (node or mortar, from the setup in the
  .scres). With mortar, contact_pressure at a slave node is the multiplier t_s, the
  nodal value of the traction field sum_r t_r N_r; the slave node's contact force is
  f_s = sum_r t_r int N_r N_s dA (a consistent "mass" M), while node-to-surface's is
  t_s A_s. profile_force_*_err: the same errors for the nodal force per tributary
  area, f_s / A_s = (M t)_s / (M 1)_s (M of the line's linear elements on the
  reference chords: the faces are bilinear and t is the same at z = 0 and z = t, so
  the z direction cancels); for node-to-surface this is t_s itself.
"""
import argparse
import json
import math
import os
import sys

import meshio
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scresults as sr  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results")
    ap.add_argument("--scres")
    ap.add_argument("--csv")
    ap.add_argument("--load-set", default="cyl_load")
    ap.add_argument("--master-set", default="block_top")
    ap.add_argument("--R", type=float, default=8.0)
    ap.add_argument("--E1", type=float, default=200.0)
    ap.add_argument("--nu1", type=float, default=0.3)
    ap.add_argument("--E2", type=float, default=2.0e5)
    ap.add_argument("--nu2", type=float, default=0.3)
    a = ap.parse_args()

    vtu = sr.last_vtu(a.results)
    scres = a.scres or sr.default_scres(a.results)
    csv_path = a.csv or sr.default_csv(scres)
    m = meshio.read(vtu)
    X = np.asarray(m.points)
    u = np.asarray(m.point_data["displacement"])
    x = X + u
    status = np.asarray(m.point_data["contact_status"])
    p = np.asarray(m.point_data["contact_pressure"])
    t = X[:, 2].max() - X[:, 2].min()
    z0 = X[:, 2].min()

    slave = np.where((status > -2) & np.isclose(X[:, 2], z0))[0]
    slave = slave[np.argsort(X[slave, 0])]
    other = np.where((status > -2) & ~np.isclose(X[:, 2], z0))[0]
    other = other[np.argsort(X[other, 0])]
    z_mismatch = float(np.abs(p[slave] - p[other]).max()) if len(other) == len(slave) else None

    ps, xr, xc = p[slave], X[slave, 0], x[slave, 0]
    active = ps > 0
    if not active.any():
        raise SystemExit("no active slave node")
    n_act = int(np.argmax(~active)) if (~active).any() else len(ps)
    if not active[:n_act].all() or active[n_act:].any():
        print("warning: active set is not contiguous from x = 0", file=sys.stderr)
    p0_fe = float(ps.max())

    def half_width(xs):
        """(midpoint, [last active, first open], b_fit, p0_fit) on abscissa xs."""
        lo = float(xs[n_act - 1])
        hi = float(xs[n_act]) if n_act < len(xs) else float("nan")
        # Hertz ellipse fit: p^2 = c0 - c1 x^2 over the active nodes
        A = np.vstack([np.ones(n_act), -xs[:n_act] ** 2]).T
        (c0, c1), *_ = np.linalg.lstsq(A, ps[:n_act] ** 2, rcond=None)
        b_fit = math.sqrt(c0 / c1) if c0 > 0 and c1 > 0 else float("nan")
        p0_fit = math.sqrt(c0) if c0 > 0 else float("nan")
        return 0.5 * (lo + hi), [lo, hi], b_fit, p0_fit

    b_fe, bracket, b_fit, p0_fit = half_width(xr)
    b_fe_cur, bracket_cur, b_fit_cur, _ = half_width(xc)

    incs = sr.scres_summary(scres)
    inc = incs[-1]
    ry = sr.reaction(inc, a.load_set)[1]
    P = 2.0 * abs(ry) / t
    pair = sr.pair_summary(inc)
    P_contact = 2.0 * abs(float(pair["force"][1])) / t

    Estar = 1.0 / ((1 - a.nu1 ** 2) / a.E1 + (1 - a.nu2 ** 2) / a.E2)
    b_h = math.sqrt(4.0 * P * a.R / (math.pi * Estar))
    p0_h = 2.0 * P / (math.pi * b_h)

    h_slave = float(np.linalg.norm(X[slave[1]] - X[slave[0]]))
    master = np.where((np.asarray(m.point_data["set:" + a.master_set]) > 0)
                      & np.isclose(X[:, 2], z0))[0] if "set:" + a.master_set in m.point_data else []
    h_master = float(np.sort(X[master, 0])[1] - np.sort(X[master, 0])[0]) if len(master) > 1 else None

    # profile error against the closed form, on the reference x (see the docstring)
    p_h = np.where(xr < b_h, p0_h * np.sqrt(np.clip(1.0 - (xr / b_h) ** 2, 0.0, None)), 0.0)
    e = (ps - p_h) / p0_h
    win = xr <= 2.0 * b_h
    e_w, x_w = e[win], xr[win]
    prof_rms = float(np.sqrt(np.mean(e_w ** 2)))
    prof_l2 = float(np.sqrt(np.sum(0.5 * (e_w[1:] ** 2 + e_w[:-1] ** 2) * np.diff(x_w)) / (x_w[-1] - x_w[0])))
    i_max = int(np.argmax(np.abs(e)))
    integration = sr.contact_integration(scres)
    if integration == "mortar":
        L = np.linalg.norm(np.diff(X[slave][:, :2], axis=0), axis=1)   # reference chords
        Mt, M1 = np.zeros_like(ps), np.zeros_like(ps)
        for k, Lk in enumerate(L):
            Mt[k] += Lk / 6 * (2 * ps[k] + ps[k + 1]); Mt[k + 1] += Lk / 6 * (ps[k] + 2 * ps[k + 1])
            M1[k] += Lk / 2; M1[k + 1] += Lk / 2
        pf = Mt / M1
    else:
        pf = ps
    ef = (pf - p_h) / p0_h
    ef_w = ef[win]
    i_fmax = int(np.argmax(np.abs(ef)))

    conv = sr.convergence(csv_path) if os.path.exists(csv_path) else {}
    out = {
        "vtu": vtu,
        "nodes": int(len(X)),
        "increments": len(incs),
        "h_slave": round(h_slave, 5),
        "h_master": None if h_master is None else round(h_master, 5),
        "E_star": round(Estar, 3),
        "P": P, "P_contact": P_contact,
        "b_hertz": b_h, "p0_hertz": p0_h,
        "b_fe": b_fe, "b_bracket": bracket, "b_err": b_fe / b_h - 1.0,
        "b_hertz_in_bracket": bool(bracket[0] <= b_h <= bracket[1]),
        "b_fit": b_fit, "b_fit_err": b_fit / b_h - 1.0,
        "p0_fe": p0_fe, "p0_err": p0_fe / p0_h - 1.0,
        "p0_fit": p0_fit, "p0_fit_err": p0_fit / p0_h - 1.0,
        "b_fe_current": b_fe_cur, "b_bracket_current": bracket_cur, "b_err_current": b_fe_cur / b_h - 1.0,
        "b_fit_current": b_fit_cur, "b_fit_err_current": b_fit_cur / b_h - 1.0,
        "active_nodes_line": n_act,
        "profile_rms_err": prof_rms, "profile_l2_err": prof_l2,
        "profile_max_err": float(abs(e[i_max])), "profile_max_x": float(xr[i_max]),
        "profile_nodes": int(win.sum()),
        "profile_interior_max_err": float(np.abs(e[xr <= 0.8 * b_h]).max()),
        "integration": integration,
        "profile_force_rms_err": float(np.sqrt(np.mean(ef_w ** 2))),
        "profile_force_l2_err": float(np.sqrt(np.sum(0.5 * (ef_w[1:] ** 2 + ef_w[:-1] ** 2) * np.diff(x_w))
                                              / (x_w[-1] - x_w[0]))),
        "profile_force_max_err": float(abs(ef[i_fmax])), "profile_force_max_x": float(xr[i_fmax]),
        "pressure_z0_z1_mismatch": z_mismatch,
        "max_penetration": float(pair["max_penetration"]),
        "newton": sum(c["corrections"] for c in conv.values()) if conv else None,
        "newton_per_increment": [c["corrections"] for c in conv.values()] if conv else None,
        "augmentations": sum(c["augmentations"] for c in conv.values()) if conv else None,
        "cutbacks": sum(c["attempts"] - 1 for c in conv.values()) if conv else None,
        "solver_seconds": round(sum(sum(v for k, v in c.items() if k.startswith("seconds_"))
                                    for c in conv.values()), 3) if conv else None,
    }
    print(json.dumps(out))


if __name__ == "__main__":
    main()
