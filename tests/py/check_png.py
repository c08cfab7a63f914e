"""Is a screenshot a picture? Reads a PNG with VTK's vtkPNGReader and prints one JSON
line: width, height, distinct colours, the share of pixels that differ from the
background (the corner pixel's colour) and the share of coloured pixels (channels
spread by more than 80 of 255: the colour map, not grey, black or white), and how
many of those fall in each fifth of the hue circle.

usage: check_png.py IMAGE.png
Exits non-zero when the image is blank (one colour).
"""
import colorsys
import json
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader


def main():
    r = vtkPNGReader()
    assert r.CanReadFile(sys.argv[1]), f"{sys.argv[1]}: not a PNG VTK can read"
    r.SetFileName(sys.argv[1])
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    px = vtk_to_numpy(img.GetPointData().GetScalars())[:, :3].astype(int)
    background = px[0]
    distinct = len(np.unique(px[:, 0] * 65536 + px[:, 1] * 256 + px[:, 2]))
    assert distinct > 1, f"{sys.argv[1]}: blank ({distinct} colour)"
    foreground = np.any(px != background, axis=1).mean()
    spread = px.max(axis=1) - px.min(axis=1)
    coloured = px[spread > 80]
    hues = np.array([colorsys.rgb_to_hsv(*(c / 255.0))[0] for c in coloured[:: max(1, len(coloured) // 5000)]])
    bins = np.histogram(hues, bins=5, range=(0.0, 1.0))[0] if len(hues) else np.zeros(5, int)
    print(json.dumps({"width": w, "height": h, "distinct_colours": distinct, "foreground": float(foreground),
                      "coloured": float(len(coloured) / len(px)), "hue_fifths": bins.tolist(),
                      "background": background.tolist()}))


if __name__ == "__main__":
    main()
