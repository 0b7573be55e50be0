#!/usr/bin/env python3
"""Writes curtain.obj: a pleated curtain for paper-scene3.xml.

A sheet hanging in the plane x = const, z from Z0 to Z1, y from Y0 (hem) to
Y1 (rail), folded by a sine in x whose amplitude grows towards the hem, so
that the sheet is concave in places and faces itself (paper §5: curved
surfaces that can see themselves). NU x NV quads, each split into two
triangles, counter-clockwise seen from +x (the room side); no vertex normals
(flat triangles in Mitsuba and in trilux). Deterministic: no randomness.

Run: python3 make_curtain.py   (writes curtain.obj beside this script)
"""
import math
import os

NU, NV = 48, 16          # along z (across the folds), along y (height)
X0 = 0.35                # mean distance from the wall x = 0
Z0, Z1 = 0.3, 3.2
Y0, Y1 = 0.25, 2.9
FOLDS = 5.0              # full sine periods across the curtain
AMP_TOP, AMP_HEM = 0.08, 0.16

def vertex(i, j):
    s = i / NU            # across
    t = j / NV            # up: 0 at the hem, 1 at the rail
    z = Z0 + (Z1 - Z0) * s
    y = Y0 + (Y1 - Y0) * t
    amp = AMP_HEM + (AMP_TOP - AMP_HEM) * t
    x = X0 + amp * math.sin(2.0 * math.pi * FOLDS * s)
    return (x, y, z)

here = os.path.dirname(os.path.abspath(__file__))
lines = ["# pleated curtain for paper-scene3.xml, made by make_curtain.py",
         f"# {NU}x{NV} quads, {2 * NU * NV} triangles"]
for j in range(NV + 1):
    for i in range(NU + 1):
        x, y, z = vertex(i, j)
        lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
def idx(i, j):
    return j * (NU + 1) + i + 1
for j in range(NV):
    for i in range(NU):
        a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
        # Seen from +x, with z to the left... choose the order whose normal has +x.
        lines.append(f"f {a} {d} {c}")
        lines.append(f"f {a} {c} {b}")
with open(os.path.join(here, "curtain.obj"), "w") as f:
    f.write("\n".join(lines) + "\n")
print("wrote curtain.obj:", 2 * NU * NV, "triangles")
