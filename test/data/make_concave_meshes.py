#!/usr/bin/env python3
"""Writes the concave sample meshes (binary STL) for the static-mesh URDFs.

bin.stl: an open bin 0.4 x 0.3 x 0.2 m with 5 mm walls and floor, centred on
the z axis with its underside at z = 0, one watertight surface (28
triangles): the outside, the rim, and the cavity's walls and floor facing
inwards. table.stl: a 1.0 x 0.8 m top from z = 0.27 to 0.30 m on four 5 cm
square legs, each a closed box (60 triangles).

Run from any directory: python3 test/data/make_concave_meshes.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
URDF_MESHES = os.path.join(HERE, "..", "..", "urdf", "meshes")


def quad(tris, a, b, c, d):
    """Two triangles of the quad a b c d, counter-clockwise from outside."""
    tris.append((a, b, c))
    tris.append((a, c, d))


def box(vertices, tris, lower, upper):
    base = len(vertices)
    for i in range(8):
        vertices.append((upper[0] if i & 1 else lower[0], upper[1] if i & 2 else lower[1],
                         upper[2] if i & 4 else lower[2]))
    for q in ((0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)):
        quad(tris, *(base + i for i in q))


def open_bin(size, wall):
    hx, hy, h = size[0] / 2, size[1] / 2, size[2]
    ix, iy = hx - wall, hy - wall
    # Outer corners 0-7, inner corners 8-15, same numbering (bit 0: +x, bit 1: +y, bit 2: top).
    vertices = []
    for (x, y, bottom) in ((hx, hy, 0.0), (ix, iy, wall)):
        for i in range(8):
            vertices.append((x if i & 1 else -x, y if i & 2 else -y, h if i & 4 else bottom))
    tris = []
    quad(tris, 0, 2, 3, 1)  # outer bottom, facing -z
    for q in ((0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3)):
        quad(tris, *q)  # outer sides
    quad(tris, 8, 9, 11, 10)  # cavity floor, facing +z
    for q in ((8, 10, 14, 12), (9, 13, 15, 11), (8, 12, 13, 9), (10, 11, 15, 14)):
        quad(tris, *q)  # cavity walls, facing inwards
    for q in ((4, 5, 13, 12), (5, 7, 15, 13), (7, 6, 14, 15), (6, 4, 12, 14)):
        quad(tris, *q)  # rim, facing +z
    return vertices, tris


def table(top, thickness, leg):
    vertices, tris = [], []
    hx, hy, height = top[0] / 2, top[1] / 2, top[2]
    box(vertices, tris, (-hx, -hy, height - thickness), (hx, hy, height))
    for sx in (-1, 1):
        for sy in (-1, 1):
            cx, cy = sx * (hx - leg / 2), sy * (hy - leg / 2)
            box(vertices, tris, (cx - leg / 2, cy - leg / 2, 0.0),
                (cx + leg / 2, cy + leg / 2, height - thickness))
    return vertices, tris


def write_binary_stl(path, vertices, tris, writer="make_concave_meshes.py"):
    with open(path, "wb") as f:
        f.write(("binary STL written by " + writer).encode().ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for tri in tris:
            a, b, c = (vertices[i] for i in tri)
            u = [b[k] - a[k] for k in range(3)]
            v = [c[k] - a[k] for k in range(3)]
            n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            length = sum(x * x for x in n) ** 0.5
            f.write(struct.pack("<3f", *(x / length for x in n)))
            for i in tri:
                f.write(struct.pack("<3f", *vertices[i]))
            f.write(struct.pack("<H", 0))


if __name__ == "__main__":
    write_binary_stl(os.path.join(URDF_MESHES, "bin.stl"), *open_bin((0.4, 0.3, 0.2), 0.005))
    write_binary_stl(os.path.join(URDF_MESHES, "table.stl"), *table((1.0, 0.8, 0.3), 0.03, 0.05))
