#!/usr/bin/env python3
"""Writes the mesh files used by the io tests and the sample URDFs.

Test shape: a 0.5 x 0.25 x 0.125 m box centred at the origin whose
(+x, +y, +z) corner is cut off by the plane through the points 0.125, 0.0625
and 0.03125 m from that corner along -x, -y and -z. It has 10 vertices and 7
faces, volume 0.5*0.25*0.125 - 0.125*0.0625*0.03125/6 m^3, and no symmetry
that could hide a wrong axis or a mirror. All coordinates are dyadic, so they
survive float storage and the DAE node translation exactly and shared
vertices of sub-meshes join.

Run from any directory: python3 test/data/make_test_meshes.py
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
URDF_MESHES = os.path.join(HERE, "..", "..", "urdf", "meshes")

HALF = (0.25, 0.125, 0.0625)
CUT = (0.125, 0.0625, 0.03125)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def chamfered_box():
    """Vertices and faces (counter-clockwise seen from outside)."""
    corner = HALF
    vertices = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                if (sx, sy, sz) != (1, 1, 1):
                    vertices.append((sx * HALF[0], sy * HALF[1], sz * HALF[2]))
    cut_points = [
        (corner[0] - CUT[0], corner[1], corner[2]),
        (corner[0], corner[1] - CUT[1], corner[2]),
        (corner[0], corner[1], corner[2] - CUT[2]),
    ]
    vertices += cut_points
    planes = []
    for axis in range(3):
        for sign in (-1, 1):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = float(sign)
            planes.append((tuple(normal), HALF[axis]))
    cut_normal = cross(sub(cut_points[1], cut_points[0]), sub(cut_points[2], cut_points[0]))
    length = math.sqrt(dot(cut_normal, cut_normal))
    cut_normal = tuple(c / length for c in cut_normal)
    if dot(cut_normal, (1, 1, 1)) < 0:
        cut_normal = tuple(-c for c in cut_normal)
    planes.append((cut_normal, dot(cut_normal, cut_points[0])))
    faces = []
    for normal, offset in planes:
        on_plane = [i for i, v in enumerate(vertices) if abs(dot(normal, v) - offset) < 1e-12]
        center = tuple(sum(vertices[i][k] for i in on_plane) / len(on_plane) for k in range(3))
        u = sub(vertices[on_plane[0]], center)
        w = cross(normal, u)
        on_plane.sort(key=lambda i: math.atan2(dot(w, sub(vertices[i], center)),
                                               dot(u, sub(vertices[i], center))))
        faces.append(on_plane)
    return vertices, faces


def triangles(faces):
    return [(face[0], face[k], face[k + 1]) for face in faces for k in range(1, len(face) - 1)]


def normal_of(vertices, tri):
    n = cross(sub(vertices[tri[1]], vertices[tri[0]]), sub(vertices[tri[2]], vertices[tri[0]]))
    length = math.sqrt(dot(n, n))
    return tuple(c / length for c in n)


def write_ascii_stl(path, vertices, tris, name):
    with open(path, "w") as f:
        f.write("solid %s\n" % name)
        for tri in tris:
            f.write("  facet normal %.9g %.9g %.9g\n    outer loop\n" % normal_of(vertices, tri))
            for i in tri:
                f.write("      vertex %.9g %.9g %.9g\n" % vertices[i])
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid %s\n" % name)


def write_binary_stl(path, vertices, tris):
    with open(path, "wb") as f:
        f.write(b"binary STL written by make_test_meshes.py".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for tri in tris:
            normal = normal_of(vertices, tri)
            f.write(struct.pack("<3f", *normal))
            for i in tri:
                f.write(struct.pack("<3f", *vertices[i]))
            f.write(struct.pack("<H", 0))


def write_obj(path, vertices, faces):
    """Two objects sharing one vertex list, with polygonal faces."""
    half = len(faces) // 2
    with open(path, "w") as f:
        f.write("# chamfered box in two objects\n")
        for v in vertices:
            f.write("v %.9g %.9g %.9g\n" % v)
        for name, part in (("part_a", faces[:half]), ("part_b", faces[half:])):
            f.write("o %s\n" % name)
            for face in part:
                f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def write_ply(path, vertices, faces):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(vertices))
        f.write("property float x\nproperty float y\nproperty float z\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for v in vertices:
            f.write("%.9g %.9g %.9g\n" % v)
        for face in faces:
            f.write("%d %s\n" % (len(face), " ".join(str(i) for i in face)))


def write_off(path, vertices, faces):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(vertices), len(faces)))
        for v in vertices:
            f.write("%.9g %.9g %.9g\n" % v)
        for face in faces:
            f.write("%d %s\n" % (len(face), " ".join(str(i) for i in face)))


def dae_geometry(name, vertices, tris):
    coords = " ".join("%.9g" % c for v in vertices for c in v)
    indices = " ".join(str(i) for tri in tris for i in tri)
    return """    <geometry id="{n}" name="{n}">
      <mesh>
        <source id="{n}-positions">
          <float_array id="{n}-positions-array" count="{c}">{coords}</float_array>
          <technique_common>
            <accessor source="#{n}-positions-array" count="{v}" stride="3">
              <param name="X" type="float"/>
              <param name="Y" type="float"/>
              <param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="{n}-vertices">
          <input semantic="POSITION" source="#{n}-positions"/>
        </vertices>
        <triangles count="{t}">
          <input semantic="VERTEX" source="#{n}-vertices" offset="0"/>
          <p>{indices}</p>
        </triangles>
      </mesh>
    </geometry>
""".format(n=name, c=3 * len(vertices), coords=coords, v=len(vertices), t=len(tris),
           indices=indices)


def write_dae(path, unit_meter, up_axis, geometries, nodes):
    """geometries: [(name, vertices, tris)]; nodes: [(name, translate or None)]."""
    with open(path, "w") as f:
        f.write('<?xml version="1.0" encoding="utf-8"?>\n')
        f.write('<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">\n')
        f.write('  <asset>\n    <unit name="unit" meter="%g"/>\n    <up_axis>%s</up_axis>\n'
                '  </asset>\n' % (unit_meter, up_axis))
        f.write("  <library_geometries>\n")
        for name, vertices, tris in geometries:
            f.write(dae_geometry(name, vertices, tris))
        f.write("  </library_geometries>\n")
        f.write('  <library_visual_scenes>\n    <visual_scene id="scene" name="scene">\n')
        for name, translate in nodes:
            f.write('      <node id="node_%s" name="node_%s">\n' % (name, name))
            if translate is not None:
                f.write("        <translate>%.9g %.9g %.9g</translate>\n" % translate)
            f.write('        <instance_geometry url="#%s"/>\n      </node>\n' % name)
        f.write("    </visual_scene>\n  </library_visual_scenes>\n")
        f.write('  <scene>\n    <instance_visual_scene url="#scene"/>\n  </scene>\n</COLLADA>\n')


def compact(vertices, tris):
    used = sorted({i for tri in tris for i in tri})
    index = {old: new for new, old in enumerate(used)}
    return [vertices[i] for i in used], [tuple(index[i] for i in tri) for tri in tris]


def ellipsoid(semi_axes, rings, segments):
    """UV ellipsoid: poles plus rings x segments vertices, outward triangles."""
    a, b, c = semi_axes
    vertices = [(0.0, 0.0, c)]
    for r in range(1, rings):
        polar = math.pi * r / rings
        for s in range(segments):
            azimuth = 2.0 * math.pi * s / segments
            vertices.append((a * math.sin(polar) * math.cos(azimuth),
                             b * math.sin(polar) * math.sin(azimuth), c * math.cos(polar)))
    vertices.append((0.0, 0.0, -c))
    bottom = len(vertices) - 1

    def ring_vertex(r, s):
        return 1 + (r - 1) * segments + s % segments

    tris = []
    for s in range(segments):
        tris.append((0, ring_vertex(1, s), ring_vertex(1, s + 1)))
        tris.append((bottom, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s)))
    for r in range(1, rings - 1):
        for s in range(segments):
            p, q = ring_vertex(r, s), ring_vertex(r, s + 1)
            p2, q2 = ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1)
            tris.append((p, p2, q2))
            tris.append((p, q2, q))
    return vertices, tris


def main():
    vertices, faces = chamfered_box()
    tris = triangles(faces)
    out = lambda name: os.path.join(HERE, name)
    write_ascii_stl(out("chamfered_box_ascii.stl"), vertices, tris, "chamfered_box")
    write_binary_stl(out("chamfered_box_binary.stl"), vertices, tris)
    write_obj(out("chamfered_box.obj"), vertices, faces)
    write_ply(out("chamfered_box.ply"), vertices, faces)
    write_off(out("chamfered_box.off"), vertices, faces)

    # Z_UP in metres, split into two geometries; the second is stored shifted
    # by -offset and placed back by its node's <translate>.
    offset = (0.25, -0.5, 1.0)
    half = len(faces) // 2
    part_a = compact(vertices, triangles(faces[:half]))
    verts_b, tris_b = compact(vertices, triangles(faces[half:]))
    verts_b = [sub(v, offset) for v in verts_b]
    write_dae(out("chamfered_box_zup.dae"), 1.0, "Z_UP",
              [("part_a", part_a[0], part_a[1]), ("part_b", verts_b, tris_b)],
              [("part_a", None), ("part_b", offset)])

    # Y_UP in centimetres: the file's +y is up, so a point (x, y, z) of the
    # z-up shape is stored as 100 * (x, z, -y).
    yup_cm = [(100.0 * x, 100.0 * z, -100.0 * y) for x, y, z in vertices]
    write_dae(out("chamfered_box_yup_cm.dae"), 0.01, "Y_UP", [("box", yup_cm, tris)],
              [("box", None)])

    with open(out("empty.stl"), "w") as f:
        f.write("solid empty\nendsolid empty\n")
    nan_vertices = list(vertices)
    nan_vertices[0] = (float("nan"), nan_vertices[0][1], nan_vertices[0][2])
    write_binary_stl(out("nan_vertex.stl"), nan_vertices, tris)

    # Sample mesh for urdf/mesh_object.urdf: an ellipsoidal pebble with
    # semi-axes 0.08 x 0.05 x 0.03 m.
    pebble_vertices, pebble_tris = ellipsoid((0.08, 0.05, 0.03), 10, 20)
    write_binary_stl(os.path.join(URDF_MESHES, "pebble.stl"), pebble_vertices, pebble_tris)


if __name__ == "__main__":
    main()
