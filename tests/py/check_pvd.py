"""Independent check of a .pvd written by sc-export from a results file.

usage: check_pvd.py RESULTS.pvd
Parses the collection, reads every .vtu it lists with meshio and asserts the fields
ParaView users rely on: point data displacement (n,3), stress (n,9), von_mises,
principal_max >= principal_min; cell data body and stress. When the results carry
contact (point data contact_status), every step must have the four contact fields,
pressure >= 0, pressure only where status = 1, status in {-2, -1, 0, 1}; with
friction (contact_stick_slip) also the traction and slip vectors, stick/slip only on
active nodes, no traction elsewhere. Prints one
JSON line with the number of steps, the time values and max |u| of the last step per
component, and for contact the last step's slave pressures (status >= -1), active
count and min/max gap.
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np


def main():
    pvd = sys.argv[1]
    root = ET.parse(pvd).getroot()
    assert root.attrib["type"] == "Collection", "not a VTK collection"
    entries = [(float(d.attrib["timestep"]), d.attrib["file"]) for d in root.iter("DataSet")]
    assert entries, "empty collection"
    times = [t for t, _ in entries]
    assert times == sorted(times), f"time steps not increasing: {times}"
    last = None
    contact = None
    for t, f in entries:
        m = meshio.read(os.path.join(os.path.dirname(pvd), f))
        n = len(m.points)
        u = np.asarray(m.point_data["displacement"])
        assert u.shape == (n, 3), f"{f}: displacement shape {u.shape}"
        s = np.asarray(m.point_data["stress"])
        assert s.shape == (n, 9), f"{f}: stress shape {s.shape}"
        vm = np.asarray(m.point_data["von_mises"]).ravel()
        pmax = np.asarray(m.point_data["principal_max"]).ravel()
        pmin = np.asarray(m.point_data["principal_min"]).ravel()
        assert np.all(vm >= 0) and np.all(pmax >= pmin - 1e-12 * (1 + abs(pmin))), f"{f}: stress measures inconsistent"
        for key in ("body", "stress", "von_mises"):
            assert key in m.cell_data, f"{f}: cell data {key} missing"
        if t == 0.0:
            assert np.all(u == 0.0), "step 0 must be the undeformed state"
        last = u
        if "contact_status" in m.point_data or contact is not None:
            fields = {k: np.asarray(m.point_data[k]).ravel() for k in ("contact_pressure", "contact_gap", "contact_lambda_n", "contact_status")}
            st, p = fields["contact_status"], fields["contact_pressure"]
            assert set(np.unique(st)) <= {-2.0, -1.0, 0.0, 1.0}, f"{f}: status values {np.unique(st)}"
            assert np.all(p >= 0.0), f"{f}: negative contact pressure"
            assert np.all(p[st != 1.0] == 0.0), f"{f}: pressure on a node that is not active"
            slave = st >= -1.0
            friction = None
            if "contact_stick_slip" in m.point_data:
                ss = np.asarray(m.point_data["contact_stick_slip"]).ravel()
                tt = np.asarray(m.point_data["contact_tangential_traction"])
                assert tt.shape == (n, 3) and np.asarray(m.point_data["contact_slip"]).shape == (n, 3), f"{f}: friction vector shapes"
                assert set(np.unique(ss)) <= {-2.0, 0.0, 1.0, 2.0}, f"{f}: stick/slip values {np.unique(ss)}"
                assert np.all(tt[ss <= 0.0] == 0.0), f"{f}: tangential traction on a node not in contact"
                assert np.all((ss >= 1.0) <= (st == 1.0)), f"{f}: stick/slip on a node that is not active"
                friction = {"stick": int(np.sum(ss == 1.0)), "slip": int(np.sum(ss == 2.0)), "max_traction": float(np.linalg.norm(tt, axis=1).max())}
            contact = {
                "friction": friction,
                "slave_pressures": p[slave].tolist(),
                "active": int(np.sum(st == 1.0)),
                "gap_min": float(np.nanmin(fields["contact_gap"][slave])) if t > 0 else None,
                "gap_max": float(np.nanmax(fields["contact_gap"][slave])) if t > 0 else None,
            }
    out = {"steps": len(entries), "times": times, "max_abs_u": np.abs(last).max(axis=0).tolist()}
    if contact is not None:
        out["contact"] = contact
    print(json.dumps(out))


if __name__ == "__main__":
    main()
