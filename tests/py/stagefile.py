"""A reader of our stage files (.scmesh, .sccontact, .scres) written from their
specification (docs/formats.md, "The container"), independent of the Rust code: the
numbers the VTK files are checked against.

- read(path): (format, records) with records a list, in file order, of
  ("META", dict) and ("ARRY", name, numpy array); segments end at END! records
  (a trailing incomplete segment is an error here: the tests read finished runs).
- mesh(records): {nodes, node_tags, hexes, hex_body, element_tags, bodies,
  node_sets {name: indices}} from the mesh records (prefix "" or "mesh/").
- results(path): {mesh, pairs [{name, slave_nodes, net (b, a), ...}],
  increments [{load_factor, u, stress, state [per pair], friction [per pair or None]}]}.
- contact(path): {mesh, pairs} of a .sccontact.
"""
import struct

import numpy as np
import yaml

DTYPES = {1: "<f8", 2: "<u4", 3: "<u8", 4: "<i4", 5: "u1"}


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    eol = data.index(b"\n")
    magic, fmt, version = data[:eol].decode("ascii").split(" ")
    assert magic == "splinecontact", f"{path}: not a stage file"
    pos, records, open_segment = eol + 1, [], False
    while pos < len(data):
        tag = data[pos:pos + 4]
        pos += 4
        if tag == b"META":
            (n,) = struct.unpack_from("<Q", data, pos)
            records.append(("META", yaml.safe_load(data[pos + 8:pos + 8 + n].decode("utf-8"))))
            pos += 8 + n
            open_segment = True
        elif tag == b"ARRY":
            (n,) = struct.unpack_from("<I", data, pos)
            pos += 4
            name = data[pos:pos + n].decode("utf-8")
            pos += n
            dtype, ndim = data[pos], data[pos + 1]
            pos += 2
            dims = struct.unpack_from(f"<{ndim}Q", data, pos)
            pos += 8 * ndim
            dt = np.dtype(DTYPES[dtype])
            count = int(np.prod(dims)) if ndim else 1
            a = np.frombuffer(data, dtype=dt, count=count, offset=pos).reshape(dims)
            pos += count * dt.itemsize
            records.append(("ARRY", name, a))
            open_segment = True
        elif tag == b"END!":
            pos += 16
            open_segment = False
        else:
            raise ValueError(f"{path}: unknown record tag {tag!r} at byte {pos - 4}")
    assert not open_segment, f"{path}: the last segment has no END! record"
    return fmt, records


def _arrays(records, prefix=""):
    return {r[1][len(prefix):]: r[2] for r in records if r[0] == "ARRY" and r[1].startswith(prefix)}


def _metas(records):
    return [r[1] for r in records if r[0] == "META"]


def mesh(records, prefix=""):
    a = _arrays(records, prefix)
    meta = next(m for m in _metas(records) if isinstance(m, dict) and "bodies" in m and "node_sets" in m)
    return {
        "nodes": a["nodes"], "node_tags": a["node_tags"], "hexes": a["hexes"],
        "hex_body": a["hex_body"], "element_tags": a["element_tags"],
        "bodies": [b["name"] for b in meta["bodies"]],
        "node_sets": {s["name"]: a[f"node_set/{i}"] for i, s in enumerate(meta["node_sets"])},
    }


def _pairs(records, metas):
    a = _arrays(records, "pair/")
    pairs = []
    for k, p in enumerate(metas):
        p = dict(p)
        # one-grid nets carry net + knots; several grids nodes + patch/<q>/net;
        # free quads nodes + faces (docs/formats.md, .sccontact 1.1)
        for key in ("slave_nodes", "net", "knots_1", "knots_2", "nodes", "faces"):
            if f"{k}/{key}" in a:
                p[key] = a[f"{k}/{key}"]
        for q in range(len(p.get("patches") or [])):
            p.setdefault("patch_nets", []).append(a[f"{k}/patch/{q}/net"])
        pairs.append(p)
    return pairs


def contact(path):
    fmt, records = read(path)
    assert fmt == "sccontact", f"{path}: a '{fmt}' file"
    pairs_meta = _metas(records)[0]["pairs"]
    return {"mesh": mesh(records, "mesh/"), "pairs": _pairs(records, pairs_meta)}


def results(path):
    fmt, records = read(path)
    assert fmt == "scres", f"{path}: a '{fmt}' file"
    metas = _metas(records)
    run = metas[0]
    pairs = _pairs(records, run.get("pairs") or [])
    incs = [m["increment"] for m in metas if isinstance(m, dict) and "increment" in m]
    a = _arrays(records, "inc/")
    increments = []
    for k, info in enumerate(incs):
        increments.append({
            "load_factor": float(info["load_factor"]),
            "info": info,
            "u": a[f"{k}/u"],
            "stress": a[f"{k}/stress"],
            "state": [a[f"{k}/pair/{p}/state"] for p in range(len(pairs))],
            "friction": [a.get(f"{k}/pair/{p}/friction") for p in range(len(pairs))],
        })
    return {"mesh": mesh(records, "mesh/"), "pairs": pairs, "increments": increments}
