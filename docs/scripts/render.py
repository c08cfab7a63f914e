"""Render a results series (.pvd from sc-export) with ParaView, headless.

    xvfb-run -a pvbatch docs/scripts/render.py RESULT.pvd -o out.png \
        [--field von_mises|contact_pressure|FIELD] [--time last|first|T] \
        [--scale auto|S] [--size 800x600] [--title TEXT]

Loads the series with ParaView's PVD reader and steps through every time step
(reporting each one's largest displacement and the field's range), then shows the
chosen step: the outer surface of the bodies warped by `displacement` (times the
scale; `auto` magnifies displacements smaller than 5 % of the model's size up to
about that, with a round factor written on the picture), coloured by the point field
on a range fitted to that step. With a `contact_*` field the slave body is coloured
and the master body drawn faint grey, seen from the master's side (50° off the
contact normal), so the pressed face shows through it. Saves a PNG of the given size and prints one JSON line: the
time values, per step the largest |u| and the field's range, the step shown, the
scale and the image.

Needs ParaView's Python (Debian: `apt-get install paraview python3-paraview xvfb
xauth`); `pvbatch` needs a display, which `xvfb-run -a` gives it.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (AddLight, ColorBy, CreateView, ExtractSurface, GetColorTransferFunction, GetScalarBar,
                             PVDReader, Render, SaveScreenshot, Show, Text, Threshold, WarpByVector)
from vtkmodules.util.numpy_support import vtk_to_numpy


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("pvd", help="results series written by sc-export (RESULT.pvd)")
    p.add_argument("-o", "--output", required=True, help="PNG to write")
    p.add_argument("--field", default="von_mises", help="point field to colour by (default von_mises)")
    p.add_argument("--time", default="last", help="last (default), first, or a time value (the nearest step)")
    p.add_argument("--scale", default="auto", help="displacement magnification: auto (default) or a number")
    p.add_argument("--size", default="800x600", help="image size WxH (default 800x600)")
    p.add_argument("--title", default=None, help="text at the top left (default: the file's name)")
    return p.parse_args(argv)


def fetch(source, t):
    """The unstructured grid `source` produces at time t, on this process."""
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    if data.IsA("vtkMultiBlockDataSet"):
        data = data.GetBlock(0)
    return data


def point_array(data, name):
    a = data.GetPointData().GetArray(name)
    if a is None:
        names = [data.GetPointData().GetArrayName(i) for i in range(data.GetPointData().GetNumberOfArrays())]
        sys.exit(f"render.py: no point field '{name}' (the series has: {', '.join(names)})")
    return vtk_to_numpy(a)


def nice(x):
    """The round number (1, 2 or 5 × 10^k) at or below x."""
    e = 10 ** math.floor(math.log10(x))
    return max(m * e for m in (1, 2, 5) if m * e <= x)


def main(argv):
    args = parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))
    reader = PVDReader(FileName=os.path.abspath(args.pvd))
    reader.UpdatePipelineInformation()
    times = [float(t) for t in reader.TimestepValues] or [0.0]

    # every step: loads, and what it holds
    steps = []
    for t in times:
        d = fetch(reader, t)
        u = point_array(d, "displacement")
        f = point_array(d, args.field)
        f = np.linalg.norm(f, axis=1) if f.ndim == 2 else f
        finite = f[np.isfinite(f)]
        steps.append({"time": t, "points": d.GetNumberOfPoints(), "cells": d.GetNumberOfCells(),
                      "max_u": float(np.linalg.norm(u, axis=1).max()),
                      "range": [float(finite.min()), float(finite.max())] if finite.size else None})

    if args.time == "last":
        shown = len(times) - 1
    elif args.time == "first":
        shown = 0
    else:
        shown = min(range(len(times)), key=lambda k: abs(times[k] - float(args.time)))
    t = times[shown]
    data = fetch(reader, t)
    bounds = data.GetBounds()
    diag = math.dist(bounds[0::2], bounds[1::2])
    max_u = steps[shown]["max_u"]
    if args.scale == "auto":
        scale = 1.0 if max_u == 0.0 or max_u >= 0.05 * diag else nice(0.05 * diag / max_u)
    else:
        scale = float(args.scale)

    view = CreateView("RenderView")
    view.ViewSize = [width, height]
    view.ViewTime = t
    view.OrientationAxesVisibility = 1
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    # a headlight only: every face turned to the camera is lit, whichever way it faces
    view.UseLight = 0
    light = AddLight(view=view)
    light.Coords = "Camera"  # directional, along the camera's view: a headlight

    surface = ExtractSurface(Input=reader)
    warp = WarpByVector(Input=surface)
    warp.Vectors = ["POINTS", "displacement"]
    warp.ScaleFactor = scale

    lo, hi = steps[shown]["range"] or [0.0, 1.0]
    if hi <= lo:
        hi = lo + 1.0
    lut = GetColorTransferFunction(args.field)
    lut.ApplyPreset("Jet", True)
    lut.RescaleTransferFunction(lo, hi)
    if hasattr(lut, "AutomaticRescaleRangeMode"):
        lut.AutomaticRescaleRangeMode = "Never"

    # the camera looks from the front (−y), a little from the side and above (z up)
    look = np.array([-0.55, 1.0, -0.6])
    up_hint = np.array([0.0, 0.0, 1.0])
    coloured = warp
    if args.field.startswith("contact_"):
        # the slave body (cells around slave nodes, contact_status >= -1) coloured, the
        # rest grey and translucent, seen from the master's side
        status = point_array(data, "contact_status")
        body = vtk_to_numpy(data.GetCellData().GetArray("body"))
        conn = vtk_to_numpy(data.GetCells().GetConnectivityArray()).reshape(-1, 8)
        slave_cells = (status[conn] >= -1).any(axis=1)
        slave_bodies = sorted(set(body[slave_cells].tolist()))
        others = sorted(set(body.tolist()) - set(slave_bodies))
        pts = vtk_to_numpy(data.GetPoints().GetData())
        if others:
            master_c = pts[np.isin(np.arange(len(pts)), conn[np.isin(body, others)].ravel())].mean(axis=0)
            # the contact normal: across the plane fitted to the slave nodes, towards the master
            slave_nodes = pts[status >= -1]
            n = np.linalg.svd(slave_nodes - slave_nodes.mean(axis=0))[2][-1]
            if n.dot(master_c - slave_nodes.mean(axis=0)) < 0:
                n = -n
            # look at the slave body from the master's side, 50° off the normal, turned
            # about the model's longest axis across the normal (it stays horizontal)
            extent = pts.max(axis=0) - pts.min(axis=0)
            long_axis = np.eye(3)[int(np.argmax(extent * (1.0 - np.abs(n))))]
            side = np.cross(n, long_axis)
            side /= np.linalg.norm(side)
            if side[2] < 0:
                side = -side
            look = -(math.cos(math.radians(50)) * n + math.sin(math.radians(50)) * side)
            up_hint = np.cross(long_axis, look)
            rest = Threshold(Input=warp)
            rest.Scalars = ["CELLS", "body"]
            rest.LowerThreshold, rest.UpperThreshold = min(others), max(others)
            if hasattr(rest, "ThresholdMethod"):
                rest.ThresholdMethod = "Between"
            grey = Show(rest, view)
            ColorBy(grey, None)
            grey.DiffuseColor = grey.AmbientColor = [0.55, 0.55, 0.55]
            grey.Opacity = 0.12
            coloured = Threshold(Input=warp)
            coloured.Scalars = ["CELLS", "body"]
            coloured.LowerThreshold, coloured.UpperThreshold = min(slave_bodies), max(slave_bodies)
            if hasattr(coloured, "ThresholdMethod"):
                coloured.ThresholdMethod = "Between"
    shown_display = Show(coloured, view)
    ColorBy(shown_display, ("POINTS", args.field))
    shown_display.LookupTable = lut
    shown_display.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = args.field
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    bar.TitleFontSize = bar.LabelFontSize = 14
    bar.RangeLabelFormat = "%.4g"

    title = args.title or os.path.splitext(os.path.basename(args.pvd))[0]
    label = f"{title}\nt = {t:g} (step {shown} of {len(times) - 1}), displacement x {scale:g}"
    text = Show(Text(Text=label), view)
    text.Color = [0.0, 0.0, 0.0]
    text.FontSize = 14
    text.WindowLocation = "Upper Left Corner"
    text.Justification = "Left"

    Render(view)  # the first render resets the camera: render once, then place it
    warped = vtk_to_numpy(fetch(warp, t).GetPoints().GetData())
    look = look / np.linalg.norm(look)
    up = up_hint - up_hint.dot(look) * look
    if up[2] < 0 or (up[2] == 0 and up[1] < 0):
        up = -up
    up /= np.linalg.norm(up)
    right = np.cross(look, up)
    # parallel projection, centred on the warped surface's outline on the screen and
    # fitted to it (with room for the text above and the colour bar on the right)
    sx, sy = warped @ right, warped @ up
    centre = ((sx.max() + sx.min()) / 2) * right + ((sy.max() + sy.min()) / 2) * up + (warped @ look).mean() * look
    half_w, half_h = (sx.max() - sx.min()) / 2, (sy.max() - sy.min()) / 2
    scale_view = 1.1 * max(half_h / 0.85, half_w * height / (0.8 * width))
    centre = centre + 0.08 * scale_view * up  # room for the text above
    view.CameraFocalPoint = centre.tolist()
    view.CameraPosition = (centre - 3.0 * diag * look).tolist()
    view.CameraViewUp = up.tolist()
    view.CameraParallelProjection = 1
    view.CameraParallelScale = scale_view
    Render(view)
    SaveScreenshot(args.output, view, ImageResolution=[width, height], TransparentBackground=0)
    print(json.dumps({"pvd": args.pvd, "field": args.field, "times": times, "steps": steps, "shown": shown,
                      "time": t, "scale": scale, "image": args.output, "size": [width, height]}))


if __name__ == "__main__":
    main(sys.argv[1:])
