"""Shared helpers of the contact validation scripts (hertz.py, curved.py).

- last_vtu(path): the last increment's .vtu of a results .pvd (or a .vtu as given).
- scres_summary(scres): the per-increment reactions and contact-pair summaries of a
  .scres, read from `sc-export FILE --format yaml -o -` (sc-export from $SC_EXPORT,
  else PATH). A small block-YAML reader parses the part of the dump we need (the
  `increment:` META records; the big `arrays` section is never parsed).
- convergence(csv): per increment, from <results>.convergence.csv: Newton
  corrections (rows with iteration >= 1, i.e. linear solves), augmentation passes,
  attempts (1 + cutbacks) and the contact-search/assembly/factor/solve seconds.
"""
import csv
import os
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET


def last_vtu(path):
    """The .vtu of the last DataSet of a .pvd, or `path` itself if it is a .vtu."""
    if not path.endswith(".pvd"):
        return path
    sets = ET.parse(path).getroot().iter("DataSet")
    last = max(sets, key=lambda d: float(d.get("timestep")))
    return os.path.join(os.path.dirname(path), last.get("file"))


def default_scres(path):
    """out/hertz_3.vtu or out/hertz.pvd -> out/hertz.scres."""
    stem = re.sub(r"(_\d+)?\.(pvd|vtu)$", "", path)
    return stem + ".scres"


def default_csv(scres):
    return re.sub(r"\.scres$", "", scres) + ".convergence.csv"


def _scalar(s):
    s = s.strip()
    if s in ("", "~", "null"):
        return None
    if s in ("true", "false"):
        return s == "true"
    if s in (".nan", ".NaN"):
        return float("nan")
    if s in (".inf", "-.inf"):
        return float(s.replace(".inf", "inf"))
    if len(s) >= 2 and s[0] == s[-1] and s[0] in "'\"":
        return s[1:-1]
    for conv in (int, float):
        try:
            return conv(s)
        except ValueError:
            pass
    return s


def _indent(line):
    return len(line) - len(line.lstrip(" "))


def _parse(lines, i, ind):
    """Block YAML as serde_yaml writes it (list items at their key's indent)."""
    if lines[i].lstrip().startswith("- ") or lines[i].strip() == "-":
        out = []
        while i < len(lines) and _indent(lines[i]) == ind and lines[i].lstrip().startswith("-"):
            rest = lines[i].lstrip()[1:].lstrip()
            if re.match(r"^[A-Za-z_][\w ]*:( |$)", rest):
                lines[i] = " " * (ind + 2) + rest          # "- key: v": a map at ind + 2
                val, i = _parse(lines, i, ind + 2)
            else:
                val, i = _scalar(rest), i + 1
            out.append(val)
        return out, i
    out = {}
    while i < len(lines) and _indent(lines[i]) == ind and not lines[i].lstrip().startswith("- "):
        key, _, rest = lines[i].strip().partition(":")
        rest = rest.strip()
        i += 1
        if rest == "|":                                     # literal block: skip it
            while i < len(lines) and (not lines[i].strip() or _indent(lines[i]) > ind):
                i += 1
            out[key] = None
        elif rest == "":
            if i < len(lines) and (_indent(lines[i]) > ind or
                                   (_indent(lines[i]) == ind and lines[i].lstrip().startswith("-"))):
                out[key], i = _parse(lines, i, _indent(lines[i]))
            else:
                out[key] = None
        else:
            out[key] = _scalar(rest)
    return out, i


def scres_summary(scres):
    """The increments' summaries of a .scres (list of dicts: load_factor, cutbacks,
    iterations, reactions [{set, force}], contact [{pair, force, active,
    max_penetration, ...}]): in scres 2.0 each increment's segment opens with a META
    `increment:` record, dumped as `meta_<r>:` / `  increment:` / its map at indent 4."""
    exe = os.environ.get("SC_EXPORT") or shutil.which("sc-export")
    if not exe:
        raise SystemExit("sc-export not found: put it on PATH or set SC_EXPORT")
    text = subprocess.run([exe, scres, "--format", "yaml", "-o", "-"], check=True,
                          capture_output=True, text=True).stdout
    lines = text.split("\n")
    incs = []
    for i, line in enumerate(lines[:-1]):
        if line.startswith("meta_") and lines[i + 1].rstrip() == "  increment:":
            end = i + 2
            while end < len(lines) and (not lines[end].strip() or _indent(lines[end]) >= 4):
                end += 1
            section = [l for l in lines[i + 2:end] if l.strip()]
            inc, _ = _parse(section, 0, 4)
            incs.append(inc)
    return incs


def contact_integration(scres, pair=None):
    """`integration` (node or mortar) of a contact pair (the first, or `pair`) in the
    solve setup recorded in the .scres (meta.setup; `node` when not given)."""
    exe = os.environ.get("SC_EXPORT") or shutil.which("sc-export")
    if not exe:
        raise SystemExit("sc-export not found: put it on PATH or set SC_EXPORT")
    text = subprocess.run([exe, scres, "--format", "yaml", "-o", "-"], check=True,
                          capture_output=True, text=True).stdout
    setup = text.split("\nmeta_1:")[0].split("  setup: |", 1)[-1]
    entries = re.split(r"\n\s*- pair: ", setup.split("\n    contact:", 1)[-1])[1:]
    for e in entries:
        name = e.split("\n", 1)[0].strip().strip("'\"")
        if pair is None or name == pair:
            m = re.search(r"\n\s*integration: (\w+)", e.split("\n    [a-z]", 1)[0])
            return m.group(1) if m else "node"
    return "node"


def reaction(inc, name):
    for r in inc.get("reactions") or []:
        if r["set"] == name:
            return [float(v) for v in r["force"]]
    raise KeyError(f"no reaction for set '{name}'")


def pair_summary(inc, name=None):
    pairs = inc.get("contact") or []
    for p in pairs:
        if name is None or p["pair"] == name:
            return p
    raise KeyError(f"no contact summary for pair '{name}'")


def convergence(path):
    """{increment: {...}} from the convergence CSV (only the attempt that converged,
    i.e. the last attempt of each increment, counts toward `corrections`)."""
    per = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            k = int(row["increment"])
            d = per.setdefault(k, {"load_factor": float(row["load_factor"]), "rows": [],
                                   "attempts": set()})
            d["rows"].append(row)
            d["attempts"].add(int(row["attempt"]))
    out = {}
    for k, d in sorted(per.items()):
        last = max(d["attempts"])
        rows = [r for r in d["rows"] if int(r["attempt"]) == last]
        secs = {c: sum(float(r[c]) for r in d["rows"])
                for c in ("seconds_contact", "seconds_assembly", "seconds_factor", "seconds_solve")
                if c in d["rows"][0]}
        out[k] = {
            "load_factor": float(rows[-1]["load_factor"]),
            "attempts": len(d["attempts"]),
            "corrections": sum(1 for r in rows if int(r["iteration"]) >= 1),
            "corrections_all_attempts": sum(1 for r in d["rows"] if int(r["iteration"]) >= 1),
            "augmentations": max(int(r["augmentation"]) for r in rows),
            "first_pass_corrections": sum(1 for r in rows
                                          if int(r["iteration"]) >= 1 and int(r["augmentation"]) == 0),
            "final_residual": float(rows[-1]["residual"]),
            **secs,
        }
    return out
