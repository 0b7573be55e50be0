#!/usr/bin/env python3
"""Writes the PLY files of the scene tests (run from this folder):

- pyramid.ply: pyramid.obj as ASCII PLY (its base as two triangles, since
  Mitsuba 3.9 reads triangle faces only), no normals: both loaders
  recompute them;
- tent-le.ply, tent-be.ply: a folded sheet of 3 x 2 vertices with normals
  and texture coordinates, binary little- and big-endian, float positions,
  a uchar colour and an int index list.
"""
import struct

pyramid = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0), (0, 0, 1)]
faces = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4), (3, 2, 1), (3, 1, 0)]
with open("pyramid.ply", "w") as f:
    f.write("ply\nformat ascii 1.0\ncomment pyramid.obj, base split in two\n")
    f.write(f"element vertex {len(pyramid)}\nproperty float x\nproperty float y\nproperty float z\n")
    f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    for v in pyramid:
        f.write("%g %g %g\n" % v)
    for t in faces:
        f.write("3 %d %d %d\n" % t)

# A sheet folded along x = 0: z = 0.5 |x| for x in {-1, 0, 1}, y in {0, 1}.
tent = []
for y in (0.0, 1.0):
    for x in (-1.0, 0.0, 1.0):
        n = {-1.0: (0.4472136, 0.0, 0.8944272), 0.0: (0.0, 0.0, 1.0), 1.0: (-0.4472136, 0.0, 0.8944272)}[x]
        tent.append(((x, y, 0.5 * abs(x)), n, ((x + 1) / 2, 1 - y)))
tris = [(0, 1, 4), (0, 4, 3), (1, 2, 5), (1, 5, 4)]
for name, order in (("tent-le.ply", "<"), ("tent-be.ply", ">")):
    fmt = "binary_little_endian" if order == "<" else "binary_big_endian"
    with open(name, "wb") as f:
        f.write((f"ply\nformat {fmt} 1.0\nelement vertex {len(tent)}\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "property float nx\nproperty float ny\nproperty float nz\n"
                 "property float s\nproperty float t\nproperty uchar red\n"
                 f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        for p, n, uv in tent:
            f.write(struct.pack(order + "8fB", *p, *n, *uv, 128))
        for t in tris:
            f.write(struct.pack(order + "B3i", 3, *t))
