#!/usr/bin/env python3
"""Writes the tiny mesh fixtures of tests/mesh/mesh_io_test.cpp into this folder.

The files are committed; rerun this only to change them. Valid files all describe the box
[0,2] x [0,3] x [0,4] (8 vertices, 12 triangles, volume 24, outward winding) in every format;
malformed/ holds one file per defect and format.
"""
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
V = [(0, 0, 0), (2, 0, 0), (2, 3, 0), (0, 3, 0), (0, 0, 4), (2, 0, 4), (2, 3, 4), (0, 3, 4)]
# Outward quads (counter-clockwise seen from outside).
Q = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (0, 4, 7, 3)]
T = [t for q in Q for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]


def write(name, data):
    path = os.path.join(HERE, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def normal(t, vertices=V):
    a, b, c = (vertices[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    length = sum(x * x for x in n) ** 0.5 or 1.0
    return tuple(x / length for x in n)


def off(vertices=V, faces=T, counts=None):
    counts = counts or (len(vertices), len(faces))
    return ("OFF\n%d %d 0\n" % counts + "".join("%g %g %g\n" % v for v in vertices) +
            "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces))


def ply_ascii(vertices=V, faces=Q, face_count=None):
    return ("ply\nformat ascii 1.0\ncomment box with normals\nelement vertex %d\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
            % (len(vertices), face_count if face_count is not None else len(faces)) +
            "".join("%s %s %s 0 0 1\n" % tuple(v) for v in vertices) +
            "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces))


def ply_binary(vertices=V, faces=T, endian="<", face_count=None):
    name = "binary_little_endian" if endian == "<" else "binary_big_endian"
    header = ("ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nelement face %d\nproperty list uchar int vertex_indices\n"
              "end_header\n" % (name, len(vertices),
                                face_count if face_count is not None else len(faces))).encode()
    body = b"".join(struct.pack(endian + "3f", *v) for v in vertices)
    body += b"".join(struct.pack(endian + "B%di" % len(f), len(f), *f) for f in faces)
    return header + body


def stl_ascii(vertices=V, faces=T):
    text = "solid box\n"
    for t in faces:
        text += "  facet normal %g %g %g\n    outer loop\n" % normal(t, vertices)
        text += "".join("      vertex %s %s %s\n" % tuple(vertices[i]) for i in t)
        text += "    endloop\n  endfacet\n"
    return text + "endsolid box\n"


def stl_binary(vertices=V, faces=T, count=None):
    data = b"csgrt test box".ljust(80, b" ") + struct.pack("<I", count if count is not None else len(faces))
    for t in faces:
        data += struct.pack("<3f", *normal(t, vertices))
        data += b"".join(struct.pack("<3f", *vertices[i]) for i in t) + b"\0\0"
    return data


def obj_quads():
    text = "# box made of quads\nmtllib box.mtl\no box\n"
    text += "".join("v %g %g %g\n" % v for v in V)
    text += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng sides\ns off\n"
    for k, q in enumerate(Q):
        if k == 0:  # corners with texture and normal indices
            text += "f " + " ".join("%d/%d/1" % (i + 1, j + 1) for j, i in enumerate(q)) + "\n"
        elif k == 1:  # relative (negative) indices
            text += "f " + " ".join(str(i - len(V)) for i in q) + "  # top\n"
        else:
            text += "f " + " ".join("%d//1" % (i + 1) for i in q) + "\n"
    return text


generator = random.Random(1)
garbage = bytes(generator.randrange(256) for _ in range(300))
NAN_V = [V[0], (float("nan"), 0, 0)] + V[2:]

write("box.off", off(faces=T[:10] + [Q[5]]))  # ten triangles and one quad
write("box_quads.obj", obj_quads())
write("box_ascii.ply", ply_ascii())
write("box_binary.ply", ply_binary())
write("box_big_endian.ply", ply_binary(endian=">"))
write("box_ascii.stl", stl_ascii())
write("box_binary.stl", stl_binary())
# A flat L-shaped hexagon of area 3, counter-clockwise seen from +z: a fan from its first
# corner would cover ground outside the L.
write("l_shape.obj", "v 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nf 1 2 3 4 5 6\n")

bad = "malformed/"
write(bad + "truncated.off", off()[:-9])
write(bad + "wrong_counts.off", off(counts=(8, 13)))
write(bad + "extra_faces.off", off(counts=(8, 11)))
write(bad + "nan.off", off(vertices=NAN_V))
write(bad + "out_of_range.off", off(faces=T[:11] + [(0, 1, 8)]))
write(bad + "empty.off", "")
write(bad + "garbage.off", garbage)
write(bad + "degenerate.off", "OFF\n3 2 0\n0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n3 0 0 1\n")

write(bad + "truncated.obj", obj_quads() + "f 1 2\n")
write(bad + "nan.obj", obj_quads().replace("v 2 0 0\n", "v nan 0 0\n"))
write(bad + "out_of_range.obj", obj_quads() + "f 1 2 9\n")
write(bad + "zero_index.obj", obj_quads() + "f 0 1 2\n")
write(bad + "empty.obj", "")
write(bad + "garbage.obj", garbage)
write(bad + "no_faces.obj", "".join("v %g %g %g\n" % v for v in V))

write(bad + "truncated_ascii.ply", ply_ascii()[:-6])
write(bad + "truncated_binary.ply", ply_binary()[:-7])
write(bad + "wrong_counts_ascii.ply", ply_ascii(face_count=7))
write(bad + "wrong_counts_binary.ply", ply_binary(face_count=11))
write(bad + "nan_ascii.ply", ply_ascii(vertices=NAN_V))
write(bad + "nan_binary.ply", ply_binary(vertices=NAN_V))
write(bad + "out_of_range_binary.ply", ply_binary(faces=T[:11] + [(0, 1, 42)]))
write(bad + "empty.ply", "")
write(bad + "garbage.ply", garbage)

write(bad + "truncated_binary.stl", stl_binary()[:-30])
write(bad + "wrong_count_binary.stl", stl_binary(count=13))
write(bad + "truncated_ascii.stl", stl_ascii()[:-40])
write(bad + "nan_ascii.stl", stl_ascii(vertices=NAN_V))
write(bad + "nan_binary.stl", stl_binary(vertices=NAN_V))
write(bad + "empty.stl", "")
write(bad + "garbage.stl", garbage)
write(bad + "degenerate.stl", stl_binary(vertices=[(0, 0, 0), (1, 1, 1), (2, 2, 2)], faces=[(0, 1, 2)]))
write(bad + "repeated_corners.stl", stl_ascii(vertices=[(0, 0, 0), (1, 1, 1)], faces=[(0, 1, 1)]))
