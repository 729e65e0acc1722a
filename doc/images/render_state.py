#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Render a state that palpate wrote as VTU (Effects / VTU export = true)
into a PNG: the deformed surface coloured by displacement, the rest surface
as a wire frame, the fixed nodes and the force on the probe.

    python3 doc/images/render_state.py STATE.vtu OUT.png ["title"]

Needs Python 3 with numpy and matplotlib (Debian: python3-matplotlib)."""
import base64, re, sys, zlib
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

TYPES = {"Float32": "<f4", "Float64": "<f8", "Int32": "<i4", "Int64": "<i8",
         "UInt8": "u1", "UInt32": "<u4", "UInt64": "<u8"}

def decode(text, dtype, compressed):
    """A base64 binary DataArray as deal.II writes it: zlib blocks, the
    header encoded separately from the data."""
    text = "".join(text.split())
    if not compressed:
        raw = base64.b64decode(text)
        n = np.frombuffer(raw[:4], "<u4")[0]
        return np.frombuffer(raw[4:4 + n], dtype)
    first = base64.b64decode(text[:16])
    nblocks = np.frombuffer(first[:4], "<u4")[0]
    hlen = 4 * (3 + nblocks)
    hchars = 4 * ((hlen + 2) // 3)
    header = np.frombuffer(base64.b64decode(text[:hchars])[:hlen], "<u4")
    data = base64.b64decode(text[hchars:])
    out, pos = b"", 0
    for size in header[3:]:
        out += zlib.decompress(data[pos:pos + size])
        pos += size
    return np.frombuffer(out, dtype)

def read_vtu(path):
    xml = open(path).read()
    compressed = "vtkZLibDataCompressor" in xml
    arrays = {}
    for m in re.finditer(r'<DataArray([^>]*)>(.*?)</DataArray>', xml, re.S):
        attributes, body = m.group(1), m.group(2)
        name = re.search(r'Name="([^"]*)"', attributes)
        kind = re.search(r'type="([^"]*)"', attributes).group(1)
        n = re.search(r'NumberOfComponents="(\d+)"', attributes)
        values = decode(body, TYPES[kind], compressed)
        if n and int(n.group(1)) > 1:
            values = values.reshape(-1, int(n.group(1)))
        arrays[name.group(1) if name else "points"] = values
    return arrays

def main():
    vtu, png = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else ""
    a = read_vtu(vtu)
    points, u = a["points"].astype(float), a["displacement"].astype(float)
    cells = a["connectivity"].reshape(-1, 4)
    # deal.II writes every cell with its own copies of its vertices: merge
    # them, then the surface is the faces that belong to one cell only.
    keys = np.round(points, 9)
    _, index, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    cells = inverse[cells]
    x, disp = points[index], u[index]
    faces = {}
    for c in cells:
        for f in ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)):
            tri = tuple(c[list(f)])
            key = tuple(sorted(tri))
            faces[key] = None if key in faces else tri
    surface = np.array([t for t in faces.values() if t is not None])
    deformed = x + disp
    magnitude = np.linalg.norm(disp, axis=1)

    fig = plt.figure(figsize=(7.5, 5.6), dpi=110)
    ax = fig.add_subplot(projection="3d")
    face_colour = plt.cm.viridis(magnitude[surface].mean(axis=1) / max(magnitude.max(), 1e-12))
    ax.add_collection3d(Poly3DCollection(x[surface], facecolors=(0, 0, 0, 0),
                                         edgecolors=(0.6, 0.6, 0.6, 0.25), linewidths=0.3))
    ax.add_collection3d(Poly3DCollection(deformed[surface], facecolors=face_colour,
                                         edgecolors=(0, 0, 0, 0.15), linewidths=0.2))
    fixed = a["fixed"][index] > 0.5
    active = np.argmax(a["active"][index])
    ax.scatter(*deformed[fixed].T, color="black", s=14, depthshade=False,
               label="fixed nodes", zorder=10)
    force = a["reaction"].astype(float)[index][active]
    tip = deformed[active]
    scale = 0.08 / max(np.linalg.norm(force), 1e-12)
    ax.quiver(*tip, *(force * scale), color="red", linewidth=2,
              label="force on the probe (%.2f N)" % np.linalg.norm(force))
    ax.scatter(*tip, color="red", s=30)
    lo, hi = np.minimum(x.min(0), deformed.min(0)), np.maximum(x.max(0), deformed.max(0))
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=28, azim=120)
    ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
    mappable = plt.cm.ScalarMappable(cmap="viridis")
    mappable.set_array(magnitude * 1000)
    fig.colorbar(mappable, ax=ax, shrink=0.6, label="displacement [mm]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png)

if __name__ == "__main__":
    main()
