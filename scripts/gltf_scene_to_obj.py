#!/usr/bin/env python3
"""A .glb scene as one OBJ, as a free model site exports a multi-part model: every mesh
instance placed by its node's world transform (a mesh several nodes name appears once per
node), TRIANGLES primitives only, positions welded where they are bit-identical, nothing else
(no attributes, no materials). Used for the messy multi-part models of docs/realworld.md;
`tinydecimate` itself reads each glTF mesh in its own frame (`simplify` keeps the file's
structure), which is not what such an export looks like.

Usage: python3 scripts/gltf_scene_to_obj.py IN.glb OUT.obj   (needs numpy)
"""
import json
import struct
import sys

import numpy as np

COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
             5125: np.uint32, 5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def load(path):
    b = open(path, "rb").read()
    magic, _, _ = struct.unpack("<4sII", b[:12])
    if magic != b"glTF":
        sys.exit(f"{path}: not a .glb file")
    off, doc, blob = 12, None, None
    while off < len(b):
        n, kind = struct.unpack("<II", b[off:off + 8])
        data = b[off + 8:off + 8 + n]
        off += 8 + n
        if kind == 0x4E4F534A:
            doc = json.loads(data)
        elif kind == 0x004E4942:
            blob = data
    return doc, blob


def accessor(doc, blob, i):
    a = doc["accessors"][i]
    view = doc["bufferViews"][a["bufferView"]]
    n, dt, count = WIDTH[a["type"]], np.dtype(COMPONENT[a["componentType"]]), a["count"]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = view.get("byteStride", 0) or n * dt.itemsize
    raw = np.frombuffer(blob, dtype=np.uint8, count=stride * (count - 1) + n * dt.itemsize,
                        offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, (count, n * dt.itemsize), (stride, 1))
    return rows.copy().view(dt).reshape(count, n)


def local(node):
    if "matrix" in node:
        return np.array(node["matrix"], float).reshape(4, 4).T
    t = np.eye(4)
    t[:3, 3] = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    r = np.eye(4)
    r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return t @ r @ np.diag(list(node.get("scale", [1, 1, 1])) + [1])


def main(src, dst):
    doc, blob = load(src)
    nodes, meshes = doc.get("nodes", []), doc.get("meshes", [])
    positions, triangles, base = [], [], 0

    def walk(i, parent, seen):
        nonlocal base
        if i in seen:
            return
        seen = seen | {i}
        node = nodes[i]
        world = parent @ local(node)
        for p in meshes[node["mesh"]]["primitives"] if "mesh" in node else []:
            if p.get("mode", 4) != 4:
                continue
            x = accessor(doc, blob, p["attributes"]["POSITION"]).astype(np.float64)
            idx = (accessor(doc, blob, p["indices"]).reshape(-1).astype(np.int64)
                   if "indices" in p else np.arange(len(x)))
            placed = np.c_[x, np.ones(len(x))] @ world.T
            positions.append(placed[:, :3].astype(np.float32))
            triangles.append(idx[: len(idx) // 3 * 3].reshape(-1, 3) + base)
            base += len(x)
        for c in node.get("children", []):
            walk(c, world, seen)

    scenes = doc.get("scenes", [])
    children = {c for n in nodes for c in n.get("children", [])}
    roots = (scenes[doc.get("scene", 0)]["nodes"] if scenes
             else [i for i in range(len(nodes)) if i not in children])
    for r in roots:
        walk(r, np.eye(4), frozenset())
    p, t = np.concatenate(positions), np.concatenate(triangles)
    welded, inverse = np.unique(p, axis=0, return_inverse=True)
    t = inverse.reshape(-1)[t]
    with open(dst, "w") as f:
        f.write(f"# {src.split('/')[-1]}: every mesh instance placed by its node transform, "
                "bit-identical positions welded\n")
        for q in welded:
            f.write("v %.7g %.7g %.7g\n" % tuple(q))
        for tri in t:
            f.write("f %d %d %d\n" % tuple(tri + 1))
    print(f"{dst}: {len(welded)} vertices, {len(t)} triangles")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
