#!/usr/bin/env python3
"""Writes the concave moving-body meshes (binary STL) of the decomposition tests.

mug.stl: a cup around the z axis, outer radius 4 cm, inner radius 3.5 cm,
10 cm tall with a 1 cm floor (the cavity from z = 0.01 to 0.10), circles of
32 vertices; one watertight surface (256 triangles): outside, rim, cavity
wall, cavity floor and base.
mug_thin.stl: the same with 4 mm walls (inner radius 3.6 cm) and a 5 mm
floor: its volume is 0.23 of its hull's.
l_bracket.stl: an L of profile (x, z) (0,0) (0.3,0) (0.3,0.05) (0.05,0.05)
(0.05,0.3) (0,0.3) extruded over y in [0, 0.1] (20 triangles): two legs
30 cm long and 5 cm thick.

Run from any directory: python3 test/data/make_decomposition_meshes.py
"""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from make_concave_meshes import quad, write_binary_stl  # noqa: E402




def mug(outer, inner, height, floor, segments):
    vertices, tris = [], []

    def ring(radius, z):
        first = len(vertices)
        for i in range(segments):
            angle = 2.0 * math.pi * i / segments
            vertices.append((radius * math.cos(angle), radius * math.sin(angle), z))
        return first

    outer_bottom, outer_top = ring(outer, 0.0), ring(outer, height)
    inner_top, inner_bottom = ring(inner, height), ring(inner, floor)
    bottom_centre = len(vertices)
    vertices += [(0.0, 0.0, 0.0), (0.0, 0.0, floor)]
    floor_centre = bottom_centre + 1
    for i in range(segments):
        j = (i + 1) % segments
        quad(tris, outer_bottom + i, outer_bottom + j, outer_top + j, outer_top + i)
        quad(tris, outer_top + i, outer_top + j, inner_top + j, inner_top + i)
        quad(tris, inner_top + i, inner_top + j, inner_bottom + j, inner_bottom + i)
        tris.append((floor_centre, inner_bottom + i, inner_bottom + j))
        tris.append((bottom_centre, outer_bottom + j, outer_bottom + i))
    return vertices, tris


def l_bracket(length, height, thickness, depth):
    profile = [(0, 0), (length, 0), (length, thickness), (thickness, thickness),
               (thickness, height), (0, height)]
    vertices = [(x, y, z) for y in (0.0, depth) for (x, z) in profile]
    tris = []
    # The profile is star-shaped from (0, 0): fans from vertex 0; seen from
    # -y it runs counter-clockwise.
    for i in range(1, 5):
        tris.append((0, i, i + 1))
        tris.append((6, 6 + i + 1, 6 + i))
    for i in range(6):
        quad(tris, i, 6 + i, 6 + (i + 1) % 6, (i + 1) % 6)
    return vertices, tris


if __name__ == "__main__":
    writer = "make_decomposition_meshes.py"
    write_binary_stl(os.path.join(HERE, "mug.stl"), *mug(0.04, 0.035, 0.10, 0.01, 32), writer)
    write_binary_stl(os.path.join(HERE, "mug_thin.stl"), *mug(0.04, 0.036, 0.10, 0.005, 32),
                     writer)
    write_binary_stl(os.path.join(HERE, "l_bracket.stl"), *l_bracket(0.3, 0.3, 0.05, 0.1), writer)
