"""Rerun (https://rerun.io) recordings of verti trials: ``save_rrd`` turns a 3-D recording
(``verti replay --3d --out FILE.json`` or ``verti.replay(..., out="FILE.json")``) into a
``.rrd`` file for Rerun's viewer, with the same contents as the HTML page: terrain mesh
coloured by class, obstacles, path, start and goal, the trail, the vehicle body and wheels
(steer and suspension travel) on the ``time`` timeline, and scalar plots of speed, roll, pitch,
throttle, steering and wheel sinkage.

    python -m verti.rerun task.json task.rrd && rerun task.rrd

Needs ``pip install rerun-sdk`` (an optional dependency; about 670 MB with pyarrow).
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any, Dict, List, Tuple

import numpy as np


def _terrain(rec: Dict[str, Any]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    n, cell = rec["n"], rec["cell"]
    half = 0.5 * (n - 1) * cell
    cols, rows = np.meshgrid(np.arange(n), np.arange(n))
    h = np.asarray(rec["heights"], dtype=np.float32).reshape(n, n)
    pos = np.stack([-half + cols * cell, half - rows * cell, h], axis=-1).reshape(-1, 3)
    a = (rows[:-1, :-1] * n + cols[:-1, :-1]).ravel()
    tri = np.concatenate([np.stack([a, a + n, a + 1], 1), np.stack([a + 1, a + n, a + n + 1], 1)])
    colors = np.asarray(rec["colors"], dtype=np.uint8)
    return pos.astype(np.float32), tri.astype(np.uint32), colors


def _prisms(rec: Dict[str, Any]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    pos: List[Tuple[float, float, float]] = []
    tri: List[Tuple[int, int, int]] = []
    col: List[Tuple[int, int, int]] = []
    for o in rec["obstacles"]:
        p, m = o["polygon"], len(o["polygon"])
        base = len(pos)
        colour = (92, 69, 46) if o["tree"] else (140, 135, 128)
        for x, y in p:
            pos += [(x, y, o["z0"]), (x, y, o["z1"])]
            col += [colour, colour]
        for i in range(m):
            j = (i + 1) % m
            a, b, c, d = base + 2 * i, base + 2 * j, base + 2 * j + 1, base + 2 * i + 1
            tri += [(a, b, c), (a, c, d)]
        for i in range(1, m - 1):  # the top, fanned (footprints are convex)
            tri.append((base + 1, base + 2 * i + 1, base + 2 * (i + 1) + 1))
    return np.asarray(pos, np.float32), np.asarray(tri, np.uint32), np.asarray(col, np.uint8)


def _qmul(a, b):
    """Hamilton product of (w, x, y, z) quaternions."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def save_rrd(recording: str, out: str) -> None:
    """Writes the recording in ``recording`` (a JSON file) as a Rerun ``.rrd`` file ``out``."""
    import rerun as rr

    with open(recording, encoding="utf-8") as f:
        rec = json.load(f)
    stream = rr.RecordingStream("verti_replay")
    stream.save(out)
    stream.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    pos, tri, col = _terrain(rec)
    stream.log("world/terrain", rr.Mesh3D(vertex_positions=pos, triangle_indices=tri, vertex_colors=col), static=True)
    if rec["obstacles"]:
        pos, tri, col = _prisms(rec)
        stream.log("world/obstacles", rr.Mesh3D(vertex_positions=pos, triangle_indices=tri, vertex_colors=col), static=True)
    if rec["path"]:
        stream.log("world/path", rr.LineStrips3D([rec["path"]], colors=[(64, 190, 255)]), static=True)
    stream.log("world/start", rr.Points3D([rec["start"]], radii=1.0, colors=[(100, 255, 100)]), static=True)
    stream.log("world/goal", rr.Points3D([rec["goal"]], radii=rec["goal_radius"], colors=[(255, 90, 90)]), static=True)
    stream.log("info", rr.TextDocument(rec["title"]), static=True)
    half_size = [0.5 * s for s in rec["body_size"]]
    # a cylinder's axis is its local z; a wheel's axle is the chassis' y: turn z onto y
    to_axle = (math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0.0, 0.0)
    trail = []
    for f in rec["frames"]:
        stream.set_time("time", duration=f["t"])
        b = f["body"]
        q = (b[3], b[4], b[5], b[6])
        trail.append(b[:3])
        stream.log("world/vehicle/body", rr.Boxes3D(centers=[b[:3]], half_sizes=[half_size],
                                                    quaternions=[rr.Quaternion(xyzw=[q[1], q[2], q[3], q[0]])],
                                                    colors=[(200, 158, 64)]))
        quats, centres, radii, lengths = [], [], [], []
        for (x, y, z, steer, _comp, _sink), (radius, width) in zip(f["wheels"], rec["wheel_size"]):
            w = _qmul(_qmul(q, (math.cos(steer / 2), 0.0, 0.0, math.sin(steer / 2))), to_axle)
            quats.append(rr.Quaternion(xyzw=[w[1], w[2], w[3], w[0]]))
            centres.append((x, y, z))
            radii.append(radius)
            lengths.append(width)
        stream.log("world/vehicle/wheels", rr.Cylinders3D(lengths=lengths, radii=radii, centers=centres,
                                                          quaternions=quats, colors=[(40, 40, 44)]))
        stream.log("world/trail", rr.LineStrips3D([trail], colors=[(255, 230, 80)]))
        for name in ("speed", "roll", "pitch", "throttle", "steering"):
            stream.log(f"plots/{name}", rr.Scalars(f[name]))
        stream.log("plots/sinkage_cm", rr.Scalars(100.0 * max(w[5] for w in f["wheels"])))
        for i, w in enumerate(f["wheels"]):
            stream.log(f"plots/suspension_cm/wheel{i}", rr.Scalars(100.0 * w[4]))
    stream.flush()


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python -m verti.rerun RECORDING.json OUT.rrd")
    save_rrd(sys.argv[1], sys.argv[2])
    print(f"wrote {sys.argv[2]} (open it with: rerun {sys.argv[2]})")
